#!/usr/bin/env bash
# ATE against keyframe count on 7-Scenes seq-a, sensor depth (issue 13 item 2): one full
# `ademono run` per variant of the keyframe policy / local BA / mapping schedule (`--set SECTION.KEY=VALUE`
# on top of configs/7scenes.yaml), then a Markdown table for docs/slam.md.
# Usage: tools/keyframe_table.sh [--out DIR] [--jobs N]   (N runs at a time, default 1)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$here/build/release/bin/ademono"
out="$here/out/keyframe_table" jobs=1
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    *) echo "keyframe_table: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$bin" ] || { echo "keyframe_table: $bin not built" >&2; exit 2; }
seq="$here/../shared/data/7scenes-seq-a"
mkdir -p "$out"
# name|--set arguments (space separated)
variants=(
  "default|"
  "previous|tracking.min_keyframe_spacing=0 mapping.ba_max_keyframes=20 mapping.ba_max_fixed_keyframes=0 mapping.ba_linear_solver=sparse_schur"
  "spacing0|tracking.min_keyframe_spacing=0"
  "spacing6|tracking.min_keyframe_spacing=6"
  "spacing7|tracking.min_keyframe_spacing=7"
  "spacing10|tracking.min_keyframe_spacing=10"
  "spacing12|tracking.min_keyframe_spacing=12"
  "window20|mapping.ba_max_keyframes=20"
  "fixed_all|mapping.ba_max_fixed_keyframes=0"
  "handoff0|mapping.handoff_frames=0"
  "close180_red080|tracking.min_keyframe_spacing=0 tracking.close_tracked_min=180 mapping.redundant_ratio=0.8"
)
for v in "${variants[@]}"; do
  name="${v%%|*}" sets="${v#*|}" args=()
  for s in $sets; do args+=(--set "$s"); done
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 1; done
  echo "== $(date -u +%H:%M:%S) $name: $sets" >&2
  "$bin" run --overwrite --dataset "7scenes:$seq" "${args[@]}" --out "$out/$name" > "$out/$name.log" 2>&1 &
done
wait
python3 - "$out" "${variants[@]}" <<'PY'
import json, sys
out = sys.argv[1]
print("| variant (`--set` on configs/7scenes.yaml) | keyframes (made) | tracked | ATE se3 (m) | ATE sim3 (m) | mapping ms per frame |")
print("|---|---|---|---|---|---|")
for v in sys.argv[2:]:
    name, sets = v.split("|", 1)
    s = json.load(open(f"{out}/{name}/summary.json"))
    a = s["accuracy"]
    made = sum(1 for f in s["per_frame"] if f["keyframe"])
    # Mapping work (structure, BA solve, merge) over the run, per frame: what it costs a core.
    mapping = sum(f["ms"].get("mapping", 0) for f in s["per_frame"]) / len(s["per_frame"])
    desc = {"default": "**none: configs/7scenes.yaml as shipped**",
            "previous": f"the previous default (ORB-SLAM's rules, 20-keyframe window, every "
                        f"fixed keyframe, sparse Schur): {sets}"}.get(name, sets)
    print(f"| {desc} | {s['keyframes']} ({made}) | {s['tracked']}/{s['frames']} | "
          f"{a['ate_se3_rmse_m']:.4f} | {a['ate_sim3_rmse_m']:.4f} | {mapping:.1f} |")
PY
