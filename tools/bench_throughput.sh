#!/usr/bin/env bash
# Throughput of the mapping schedules on 7-Scenes seq-a, side by side in one invocation (issue 13):
# runs `ademono run` once per case, one after the other on the same binary, and prints wall
# frames/s, keyframes, ATE se3, tracked frames and the per-frame stage medians (ms) from each
# run's summary.json. Cases (extra arguments go to every run):
#   default       configs/7scenes.yaml as shipped (concurrent mapping, fixed hand-off, frames
#                 k+1 and k+2 prepared at once)
#   prefetch1     --prefetch-frames 1: only frame k+1 prepared while k is tracked (same outputs)
#   synchronous   --set mapping.handoff_frames=0 (BA merged before the next frame, old default)
#   inline        --set mapping.threaded=false (same schedule, BA solved on the tracking thread:
#                 same outputs as default, shows what the mapping thread buys)
#   no-prefetch   --no-overlap (decode, extraction and depth on the tracking thread: same outputs
#                 as default, shows what the prefetch thread buys)
#   none          --depth none: the monocular core with no depth at all (network_indoor.yaml)
#   network       FastDepth + YOLOX-nano, default schedule (issue 13 item 5); --no-network skips it
# A second table gives the stage medians per thread, as summary.json's "timing" labels them
# (prefetch: decode, depth, detection, ORB extraction and keypoint depths of frame k+1 while
# frame k is tracked; tracking: filters, tracking, mapping's structure and merges; mapping: the
# BA solve). "tracking thread" is the tracking thread's own CPU time per frame (median), decode
# and the on_frame output excluded; "prefetch thread" the same for the prefetch work. A third
# table sums the per-frame records over the run (where the time goes in total).
# Usage: tools/bench_throughput.sh [--out DIR] [--frames A:B] [--no-network] [-- RUN_ARGS...]
# Measure on an idle machine: other jobs inflate every figure.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$here/build/release/bin/ademono"
out="$here/out/bench_throughput" frames="" network=1 extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --no-network) network=0; shift ;;
    --) shift; extra=("$@"); break ;;
    *) echo "bench_throughput: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$bin" ] || { echo "bench_throughput: $bin not built (bash scripts/setup.sh)" >&2; exit 2; }
seq="$here/../shared/data/7scenes-seq-a"
models="$here/../shared/models"
[ -d "$seq" ] || { echo "bench_throughput: $seq: not found" >&2; exit 2; }
mkdir -p "$out"
common=(--dataset "7scenes:$seq")
[ -n "$frames" ] && common+=(--frames "$frames")

run_case() {
  local name="$1"; shift
  echo "== $(date -u +%H:%M:%S) $name" >&2
  "$bin" run --overwrite "${common[@]}" "$@" "${extra[@]}" --out "$out/$name" > "$out/$name.log" 2>&1 ||
    { echo "bench_throughput: case $name failed, see $out/$name.log" >&2; exit 1; }
}
cases=(default prefetch1 synchronous inline no-prefetch none)
run_case default
run_case prefetch1 --prefetch-frames 1
run_case synchronous --set mapping.handoff_frames=0
run_case inline --set mapping.threaded=false
run_case no-prefetch --no-overlap
run_case none --depth none
if [ "$network" = 1 ]; then
  run_case network \
    --depth "model:$models/fastdepth_nyu_320.onnx,spec=$here/configs/models/fastdepth_nyu.yaml" \
    --detector "model:$models/yolox_nano.onnx"
  cases+=(network)
fi
python3 - "$out" "${cases[@]}" <<'PY'
import json, sys
out, cases = sys.argv[1], sys.argv[2:]
runs = {c: json.load(open(f"{out}/{c}/summary.json")) for c in cases}
print("| case | frames/s (wall) | wall s | tracked | keyframes | ATE se3 (m) | tracking thread CPU median (ms) | prefetch thread CPU median (ms) | local mapping p95 (ms) |")
print("|---|---|---|---|---|---|---|---|---|")
for c, s in runs.items():
    t = s["timing"]
    ate = s.get("accuracy", {}).get("ate_se3_rmse_m")
    print(f"| {c} | {s['fps']:.1f} | {s['wall_seconds']:.1f} | {s['tracked']}/{s['frames']} | "
          f"{s['keyframes']} | {ate if ate is None else f'{ate:.4f}'} | "
          f"{t['tracking_thread']['median_ms']:.1f} | {t['prefetch_thread']['median_ms']:.1f} | "
          f"{t['local_mapping']['p95_ms']:.0f} |")
print()
stages = ["decode", "depth", "detection", "extraction", "keypoint_depth", "filter", "tracking",
          "prefetch_wait", "local_mapping"]
print("Stage medians, wall ms (thread in brackets):")
print()
print("| case | " + " | ".join(stages) + " |")
print("|---|" + "---|" * len(stages))
for c, s in runs.items():
    t = s["timing"]
    cells = [f"{t[k]['median_ms']:.2f} ({t[k]['thread']})" for k in stages]
    print(f"| {c} | " + " | ".join(cells) + " |")
# Where a run's time goes in total: medians hide the keyframes. Sums over summary.json's
# per-frame records, in seconds: the tracking and prefetch threads' CPU, the tracking thread's
# wait for the prefetch, and local mapping (wall: each keyframe's structure step on the tracking
# thread plus its BA on the mapping thread, which overlaps the frames after it).
print()
print("Run totals, seconds (sums of summary.json per_frame[].ms):")
print()
totals = [("tracking thread CPU", "tracking_thread_cpu"), ("prefetch thread CPU", "prefetch_thread_cpu"),
          ("tracking", "tracking"), ("prefetch wait", "prefetch_wait"), ("local mapping (wall)", "mapping")]
print("| case | wall | " + " | ".join(name for name, _ in totals) + " |")
print("|---|---|" + "---|" * len(totals))
for c, s in runs.items():
    frames = s["per_frame"]
    sums = [sum(f["ms"].get(key, 0.0) for f in frames) / 1e3 for _, key in totals]
    print(f"| {c} | {s['wall_seconds']:.1f} | " + " | ".join(f"{v:.2f}" for v in sums) + " |")
PY
