#!/usr/bin/env bash
# Throughput of the mapping schedules on 7-Scenes seq-a, side by side in one invocation (issue 13):
# runs `ademono run` once per case, one after the other on the same binary, and prints wall
# frames/s, keyframes, ATE se3, tracked frames and the per-frame stage medians (ms) from each
# run's summary.json. Cases (extra arguments go to every run):
#   default       configs/7scenes.yaml as shipped (concurrent mapping, fixed hand-off)
#   synchronous   --set mapping.handoff_frames=0 (BA merged before the next frame, old default)
#   inline        --set mapping.threaded=false (same schedule, BA solved on the tracking thread:
#                 same outputs as default, shows what the mapping thread buys)
#   network       FastDepth + YOLOX-nano, default schedule (issue 13 item 5); --no-network skips it
# "tracking thread" = extraction + filter + tracking medians (decode, depth, detection excluded).
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
cases=(default synchronous inline)
run_case default
run_case synchronous --set mapping.handoff_frames=0
run_case inline --set mapping.threaded=false
if [ "$network" = 1 ]; then
  run_case network \
    --depth "model:$models/fastdepth_nyu_320.onnx,spec=$here/configs/models/fastdepth_nyu.yaml" \
    --detector "model:$models/yolox_nano.onnx"
  cases+=(network)
fi
python3 - "$out" "${cases[@]}" <<'PY'
import json, sys
out, cases = sys.argv[1], sys.argv[2:]
print("| case | frames/s (wall) | wall s | tracked | keyframes | ATE se3 (m) | extraction | filter | tracking | tracking thread | depth | detection | local mapping p95 |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for c in cases:
    s = json.load(open(f"{out}/{c}/summary.json"))
    t = s["timing"]
    med = lambda k: t[k]["median_ms"]
    thread = med("extraction") + med("filter") + med("tracking")
    ate = s.get("accuracy", {}).get("ate_se3_rmse_m")
    print(f"| {c} | {s['fps']:.1f} | {s['wall_seconds']:.1f} | {s['tracked']}/{s['frames']} | "
          f"{s['keyframes']} | {ate if ate is None else f'{ate:.4f}'} | {med('extraction'):.1f} | {med('filter'):.2f} | "
          f"{med('tracking'):.1f} | {thread:.1f} | {med('depth'):.1f} | {med('detection'):.1f} | "
          f"{t['local_mapping']['p95_ms']:.0f} |")
PY
