#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh), builds, and runs the whole test suite through CTest
# (C++ GoogleTest suites and the Python tests of tools/). Extra arguments go to the release ctest.
# Then, always (CI too): clang's thread-safety analysis over the slam sources
# (tools/thread_safety.sh, -fsyntax-only: about 35 s of CPU); the tests of the parsers and of the feature filter under ASan + UBSan
# (build/asan, only those three test binaries and the modules they need; docs/reliability.md
# says why this subset fits CI's 20 minutes and the whole sanitized suite does not).
# With ADEMONO_RELIABILITY=1, then the longer reliability checks (docs/reliability.md):
#   - the whole suite again under ASan + UBSan (build/asan);
#   - the threaded mapping tests under ThreadSanitizer (build/tsan, test_slam only);
#   - every fuzz target for ADEMONO_FUZZ_SECONDS (default 10) seconds (build/fuzz, clang).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$here/scripts/setup.sh" --build-type Release
ctest --test-dir "$here/build/release" --output-on-failure -j "$(nproc)" "$@"

echo "== clang thread-safety analysis of the slam module (the map's lock contract)"
"$here/tools/thread_safety.sh" "$here/build/release"

echo "== ASan + UBSan: test_core, test_io, test_filter"
sanitized=(test_core test_io test_filter)
"$here/scripts/setup.sh" --sanitize $(printf -- '--target %s ' "${sanitized[@]}")
for t in "${sanitized[@]}"; do
  LSAN_OPTIONS="suppressions=$here/tools/lsan_onnxruntime.supp" "$here/build/asan/$t" --gtest_brief=1
done

# The rest is not in CI: cold, the whole sanitized suite, the TSan build and the fuzz build take
# far longer than the suite's 20-minute budget on 2 cores (docs/reliability.md).
[ "${ADEMONO_RELIABILITY:-0}" = 1 ] || exit 0

echo "== sanitized suite (ASan + UBSan)"
"$here/scripts/setup.sh" --sanitize
ctest --test-dir "$here/build/asan" --output-on-failure -j "$(nproc)"

echo "== threaded mapping under ThreadSanitizer"
"$here/scripts/setup.sh" --tsan
ctest --test-dir "$here/build/tsan" --output-on-failure -R 'ThreadedMapping'

echo "== fuzzing, ${ADEMONO_FUZZ_SECONDS:-10} s per target"
"$here/tools/fuzz.sh" "${ADEMONO_FUZZ_SECONDS:-10}"
