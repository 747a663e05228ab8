#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh), builds, and runs the whole test suite through CTest
# (C++ GoogleTest suites and the Python tests of tools/). Extra arguments go to the release ctest.
# Then, always (CI too; docs/reliability.md says what and why, and what it costs):
#   - clang's thread-safety analysis over the slam sources (tools/thread_safety.sh, -fsyntax-only);
#   - one clang tree (build/fuzz: ASan + UBSan + coverage) that builds the libFuzzer targets and
#     the parser and feature-filter tests: test_core, test_io and test_filter run under ASan + UBSan;
#   - the threaded mapping tests under ThreadSanitizer (build/tsan: the modules that run on
#     several threads instrumented, the others as in build/release, from ccache);
#   - every fuzz target for ADEMONO_CI_FUZZ_SECONDS (default 5) seconds, with a fixed seed
#     (ADEMONO_FUZZ_SEED, default 1): a clean clone tries the same inputs every time.
# With ADEMONO_RELIABILITY=1, then the longer checks, beyond CI's 20 minutes on 2 cores:
#   - the whole suite again under ASan + UBSan (GCC, build/asan);
#   - the threaded mapping tests under TSan with every module instrumented (build/tsan-all);
#   - every fuzz target for ADEMONO_FUZZ_SECONDS (default 60) seconds.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$here/scripts/setup.sh" --build-type Release
ctest --test-dir "$here/build/release" --output-on-failure -j "$(nproc)" "$@"

echo "== clang thread-safety analysis of the slam module (the map's lock contract)"
"$here/tools/thread_safety.sh" "$here/build/release"

echo "== ASan + UBSan (clang): test_core, test_io, test_filter; building the fuzz targets"
sanitized=(test_core test_io test_filter)
"$here/scripts/setup.sh" --fuzz --target fuzz_all $(printf -- '--target %s ' "${sanitized[@]}")
for t in "${sanitized[@]}"; do
  LSAN_OPTIONS="suppressions=$here/tools/lsan_onnxruntime.supp" "$here/build/fuzz/$t" --gtest_brief=1
done

echo "== threaded mapping under ThreadSanitizer"
"$here/scripts/setup.sh" --tsan
# A report fails the test binary (TSan's exit code 66), as does a failed assertion.
TSAN_OPTIONS="suppressions=$here/tools/tsan.supp" "$here/build/tsan/test_threaded_mapping" --gtest_brief=1

echo "== fuzzing, ${ADEMONO_CI_FUZZ_SECONDS:-5} s per target"
ADEMONO_FUZZ_SEED="${ADEMONO_FUZZ_SEED:-1}" "$here/tools/fuzz.sh" "${ADEMONO_CI_FUZZ_SECONDS:-5}"

[ "${ADEMONO_RELIABILITY:-0}" = 1 ] || exit 0

echo "== sanitized suite (ASan + UBSan, GCC)"
"$here/scripts/setup.sh" --sanitize
ctest --test-dir "$here/build/asan" --output-on-failure -j "$(nproc)"

echo "== threaded mapping under ThreadSanitizer, every module instrumented"
"$here/scripts/setup.sh" --tsan-all
TSAN_OPTIONS="suppressions=$here/tools/tsan.supp" "$here/build/tsan-all/test_threaded_mapping" --gtest_brief=1

echo "== fuzzing, ${ADEMONO_FUZZ_SECONDS:-60} s per target"
"$here/tools/fuzz.sh" "${ADEMONO_FUZZ_SECONDS:-60}"
