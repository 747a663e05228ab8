#!/usr/bin/env bash
# Side-by-side cost of the levers of docs/performance.md, in one invocation (compare figures of
# one invocation only: on a loaded machine wall times are inflated, CPU times less so).
#   tools/profile_perf.sh [BUILD_DIR] [OUT_DIR]
# 1. bench_ba: one local BA on the recorded seq-a problem, auto-diff vs analytic, linear solvers.
# 2. bench_feature: ORB extraction and the gridded FAST, per-cell reference vs one pass.
# 3. seq-a sensor depth, analytic vs auto-diff Jacobians: CPU seconds, ATE se3, keyframes.
# 4. perf profile of ORB extraction (if perf is installed and allowed).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$here/build/release}"
out="${2:-/tmp/ademono-profile}"
mkdir -p "$out"
cd "$here"
"$build/bench/bench_ba" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true |
  grep -E "median|^Benchmark"
"$build/bench/bench_feature" --benchmark_filter='OrbExtract|GridFast' --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true | grep -E "median|^Benchmark"
for v in analytic autodiff; do
  extra=()
  [ "$v" = autodiff ] && extra=(--set mapping.ba_jacobians=autodiff --set mapping.ba_solver=ceres --set optimizer.pose_jacobians=autodiff --set optimizer.pose_solver=ceres)
  /usr/bin/time -f "$v: wall %e s, user CPU %U s" "$build/bin/ademono" run \
    --dataset 7scenes:../shared/data/7scenes-seq-a --depth sensor --overwrite --out "$out/$v" "${extra[@]}" \
    >"$out/$v.log" 2>&1
  tail -1 "$out/$v.log"
  "$build/bin/ademono" eval --gt "$out/$v/groundtruth.tum" --est "$out/$v/trajectory.tum" |
    grep "APE translation"
  python3 -c "import json,sys; s=json.load(open(sys.argv[1])); print('tracked', s['tracked'], 'keyframes', s['keyframes'], {k: round(v['median_ms'], 2) for k, v in s['timing'].items()})" "$out/$v/summary.json"
done
if command -v perf >/dev/null; then
  perf record -q -g -o "$out/orb.perf" "$build/bench/bench_feature" \
    --benchmark_filter='OrbExtract640x480/1000' --benchmark_min_time=3 >/dev/null 2>&1 &&
    perf report -i "$out/orb.perf" --no-children --sort dso,symbol 2>/dev/null | grep -v '^#' |
    grep '%' | head -15 || echo "perf: not allowed here (kernel.perf_event_paranoid)"
fi
