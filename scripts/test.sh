#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh), builds, and runs the whole test suite through CTest
# (C++ GoogleTest suites and the Python tests of tools/). Extra arguments go to the release ctest.
# With ADEMONO_RELIABILITY=1, then the reliability checks (docs/reliability.md):
#   - the whole suite again under ASan + UBSan (build/asan);
#   - the threaded mapping tests under ThreadSanitizer (build/tsan, test_slam only);
#   - every fuzz target for ADEMONO_FUZZ_SECONDS (default 10) seconds (build/fuzz, clang).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$here/scripts/setup.sh" --build-type Release
ctest --test-dir "$here/build/release" --output-on-failure -j "$(nproc)" "$@"
# Not in CI by default yet: cold, the three instrumented builds take far longer than the suite's
# 20-minute budget on 2 cores (docs/reliability.md); run them with ADEMONO_RELIABILITY=1.
[ "${ADEMONO_RELIABILITY:-0}" = 1 ] || exit 0

echo "== sanitized suite (ASan + UBSan)"
"$here/scripts/setup.sh" --sanitize
ctest --test-dir "$here/build/asan" --output-on-failure -j "$(nproc)"

echo "== threaded mapping under ThreadSanitizer"
"$here/scripts/setup.sh" --tsan
ctest --test-dir "$here/build/tsan" --output-on-failure -R 'ThreadedMapping'

echo "== fuzzing, ${ADEMONO_FUZZ_SECONDS:-10} s per target"
"$here/tools/fuzz.sh" "${ADEMONO_FUZZ_SECONDS:-10}"
