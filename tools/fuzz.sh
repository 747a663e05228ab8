#!/usr/bin/env bash
# Runs every libFuzzer target of fuzz/ for SECONDS each (default 60) and prints a table: target,
# seconds, inputs tried, result. Builds build/fuzz first (scripts/setup.sh --fuzz, clang).
# The corpus grows in build/fuzz/corpus/<target> across runs (seeds: fuzz/make_seeds.py from the
# test fixtures' formats and configs/); a crashing input lands in build/fuzz/artifacts/<target>/.
# Exit status 1 when any target found a crash, leak, UB or timeout.
# ADEMONO_FUZZ_SEED=N fixes libFuzzer's random seed (-seed=N), so a run on the same corpus tries
# the same inputs in the same order (CI: scripts/test.sh sets 1); unset or 0, libFuzzer draws one.
# Usage: tools/fuzz.sh [SECONDS] [TARGET...]     e.g. tools/fuzz.sh 600 trajectory_tum camera_yaml
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
[ $# -gt 0 ] && shift
seed="${ADEMONO_FUZZ_SEED:-0}"
case "$seed" in
  ''|*[!0-9]*) echo "tools/fuzz.sh: ADEMONO_FUZZ_SEED must be a non-negative integer, got '$seed'" >&2; exit 2 ;;
esac
build="$here/build/fuzz"
"$here/scripts/setup.sh" --fuzz >/dev/null

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for f in "$here"/fuzz/*_fuzz.cpp; do
    name="$(basename "$f" .cpp)"; targets+=("${name%_fuzz}")
  done
fi

rm -rf "$build/seeds"
/usr/bin/python3 "$here/fuzz/make_seeds.py" "$build/seeds"
# ONNX Runtime's own start-up allocation is the only suppressed leak (as for the tests).
export LSAN_OPTIONS="suppressions=$here/tools/lsan_onnxruntime.supp"
export UBSAN_OPTIONS="print_stacktrace=1"

failed=0
if [ "$seed" = 0 ]; then echo "seed: libFuzzer's own (set ADEMONO_FUZZ_SEED to fix it)"; else echo "seed: $seed"; fi
printf '%-22s %8s %12s  %s\n' target seconds inputs result
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t" artifacts="$build/artifacts/$t/" log="$build/logs/$t.log"
  mkdir -p "$corpus" "$artifacts" "$(dirname "$log")"
  seeds="$build/seeds/$t"; mkdir -p "$seeds"
  start=$(date +%s)
  status=ok
  # -timeout: one input taking over 10 s is a hang; -rss_limit_mb: a 2 GB input is a bug too.
  if ! "$build/fuzz/fuzz_$t" -seed="$seed" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -max_len=4096 -print_final_stats=1 -artifact_prefix="$artifacts" \
      "$corpus" "$seeds" >"$log" 2>&1; then
    status="FAILED (see $log, input in $artifacts)"
    failed=1
  fi
  end=$(date +%s)
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  [ -n "$execs" ] || execs=$(grep -o '^#[0-9]*' "$log" | tail -1 | tr -d '#')
  printf '%-22s %8s %12s  %s\n' "$t" "$((end - start))" "${execs:-?}" "$status"
done
exit "$failed"
