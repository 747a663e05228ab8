#!/usr/bin/env bash
# The soak benchmark (bench/soak_bench.cpp), one variant per process so each peak RSS is its own:
# a synthetic office run for FRAMES frames (default 10,000), back and forth over its path.
# Usage: tools/soak.sh [FRAMES] [VARIANT...]   (variants: Plain Detections NetworkDepth; default all,
# run one after the other; pass one per call to run them side by side)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
frames="${1:-10000}"; shift || true
variants=("$@"); [ ${#variants[@]} -gt 0 ] || variants=(Plain Detections NetworkDepth)
bin="${ADEMONO_BENCH:-$here/build/release/bench/bench_soak}"
for v in "${variants[@]}"; do
  ADEMONO_SOAK_FRAMES="$frames" "$bin" --benchmark_filter="Soak/$v/" --benchmark_counters_tabular=true
done
