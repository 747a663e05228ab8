#!/usr/bin/env bash
# Speed outdoors (issue 29): whole runs of PyDNet + YOLOX-nano on ../shared/data/kitti-00, side
# by side in one invocation, with the networks in the prefetch stage and with `ademono infer`
# caches. Cases (extra arguments after -- go to every run):
#   prefetch1   --prefetch-frames 1: frame k+1 prepared (decode, PyDNet, YOLOX, ORB) while k is
#               tracked: PyDNet on one core is the critical path
#   prefetch2   the default with a depth network: k+1 and k+2 prepared at once, so two PyDNet
#               runs share both cores; must give the same trajectory as prefetch1 (checked)
#   infer       `ademono infer` of both networks into a cache (its frames/s: inference alone)
#   cache       the same run from the cache (--depth cache:DIR --detector cache:FILE)
# Prints frames/s (wall), the load average around each run, tracked frames, keyframes, ATE and
# the per-stage medians from each summary.json. Measure on an idle machine: other jobs inflate
# every figure (the load average says how busy it was).
# Usage: tools/bench_kitti.sh [--out DIR] [--frames A:B] [-- RUN_ARGS...]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$here/build/release/bin/ademono"
out="$here/out/bench_kitti" frames="" extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    *) echo "bench_kitti: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$bin" ] || { echo "bench_kitti: $bin not built (bash scripts/setup.sh)" >&2; exit 2; }
seq="$here/../shared/data/kitti-00/sequences/00"
models="$here/../shared/models"
[ -d "$seq" ] || { echo "bench_kitti: $seq: not found" >&2; exit 2; }
mkdir -p "$out"
depth="model:$models/pydnet_kitti.onnx,spec=$here/configs/models/pydnet_kitti.yaml"
detector="model:$models/yolox_nano.onnx"
range=()
[ -n "$frames" ] && range=(--frames "$frames")

load() { cut -d' ' -f1 /proc/loadavg; }
run_case() {
  local name="$1"; shift
  echo "== $(date -u +%H:%M:%S) $name" >&2
  local before; before=$(load)
  "$bin" run --overwrite --dataset "kitti:$seq" "${range[@]}" "$@" "${extra[@]}" \
      --out "$out/$name" > "$out/$name.log" 2>&1 ||
    { echo "bench_kitti: case $name failed, see $out/$name.log" >&2; exit 1; }
  echo "$before $(load)" > "$out/$name.load"
}
run_case prefetch1 --depth "$depth" --detector "$detector" --prefetch-frames 1
run_case prefetch2 --depth "$depth" --detector "$detector"
echo "== $(date -u +%H:%M:%S) infer" >&2
before=$(load)
start=$(date +%s.%N)
"$bin" infer --dataset "kitti:$seq" "${range[@]}" --depth-model "$depth" --detector "$detector" \
    --out "$out/cache" > "$out/infer.log" 2>&1 ||
  { echo "bench_kitti: infer failed, see $out/infer.log" >&2; exit 1; }
end=$(date +%s.%N)
echo "$before $(load) $start $end" > "$out/infer.load"
# A cache is no `model:` to `run`: give it the settings the model runs got (network_outdoor.yaml
# and the spec's error model), so the three runs differ only in where depth comes from.
rel=$(sed -n 's/^  relative: //p' "$here/configs/models/pydnet_kitti.yaml")
per=$(sed -n 's/^  per_metre: //p' "$here/configs/models/pydnet_kitti.yaml")
run_case cache --config "$here/configs/network_outdoor.yaml" --set "depth.error_relative=$rel" \
    --set "depth.error_per_metre=$per" \
    --depth "cache:$out/cache/depth" --detector "cache:$out/cache/detections.jsonl"
if cmp -s "$out/prefetch1/trajectory.tum" "$out/prefetch2/trajectory.tum"; then
  echo "prefetch1 and prefetch2 trajectories: byte-identical"
else
  echo "prefetch1 and prefetch2 trajectories: DIFFER" >&2
  exit 1
fi
/usr/bin/python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
cases = ["prefetch1", "prefetch2", "cache"]
runs = {c: json.load(open(f"{out}/{c}/summary.json")) for c in cases}
load = {c: open(f"{out}/{c}.load").read().split() for c in cases}
print("| case | frames/s (wall) | wall s | load avg before / after | tracked | keyframes | ATE se3 (m) | sim3 (m) | tracking thread CPU median (ms) | prefetch CPU median (ms) |")
print("|---|---|---|---|---|---|---|---|---|---|")
for c, s in runs.items():
    t = s["timing"]
    acc = s.get("accuracy") or {}
    se3, sim3 = acc.get("ate_se3_rmse_m"), acc.get("ate_sim3_rmse_m")
    f = lambda x: "n/a" if x is None else f"{x:.3f}"
    print(f"| {c} | {s['fps']:.2f} | {s['wall_seconds']:.1f} | {load[c][0]} / {load[c][1]} | "
          f"{s['tracked']}/{s['frames']} | {s['keyframes']} | {f(se3)} | {f(sim3)} | "
          f"{t['tracking_thread']['median_ms']:.1f} | {t['prefetch_thread']['median_ms']:.1f} |")
b, a, start, end = open(f"{out}/infer.load").read().split()
frames = runs["cache"]["frames"]
print(f"| infer (both networks, no SLAM) | {frames / (float(end) - float(start)):.2f} | "
      f"{float(end) - float(start):.1f} | {b} / {a} | | | | | | |")
print()
stages = ["decode", "depth", "detection", "extraction", "keypoint_depth", "filter", "tracking",
          "prefetch_wait", "local_mapping"]
print("Stage medians, wall ms (thread in brackets):")
print()
print("| case | " + " | ".join(stages) + " |")
print("|---|" + "---|" * len(stages))
for c, s in runs.items():
    t = s["timing"]
    cells = [f"{t[k]['median_ms']:.1f} ({t[k]['thread']})" if k in t else "" for k in stages]
    print(f"| {c} | " + " | ".join(cells) + " |")
PY
