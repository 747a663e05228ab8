#!/usr/bin/env bash
# ATE against keyframe count on 7-Scenes seq-a, sensor depth (issue 13 item 2): one full
# `ademono run` per variant of the keyframe policy / mapping schedule (`--set SECTION.KEY=VALUE`
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
  "handoff0|mapping.handoff_frames=0"
  "handoff4|mapping.handoff_frames=4"
  "handoff8|mapping.handoff_frames=8"
  "close150|mapping.handoff_frames=4 tracking.close_tracked_min=150"
  "close120_red080|mapping.handoff_frames=4 tracking.close_tracked_min=120 mapping.redundant_ratio=0.8"
  "red070|mapping.handoff_frames=4 mapping.redundant_ratio=0.7"
  "close180_red080|mapping.handoff_frames=4 tracking.close_tracked_min=180 mapping.redundant_ratio=0.8"
  "close200_red080|mapping.handoff_frames=4 tracking.close_tracked_min=200 mapping.redundant_ratio=0.8"
  "close150_red085|mapping.handoff_frames=4 tracking.close_tracked_min=150 mapping.redundant_ratio=0.85"
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
print("| variant (`--set`) | keyframes | tracked | ATE se3 (m) | ATE sim3 (m) |")
print("|---|---|---|---|---|")
for v in sys.argv[2:]:
    name, sets = v.split("|", 1)
    s = json.load(open(f"{out}/{name}/summary.json"))
    a = s["accuracy"]
    print(f"| {sets} | {s['keyframes']} | {s['tracked']}/{s['frames']} | "
          f"{a['ate_se3_rmse_m']:.4f} | {a['ate_sim3_rmse_m']:.4f} |")
PY
