#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh), builds, and runs the whole test suite through CTest
# (C++ GoogleTest suites and the Python tests of tools/). Extra arguments go to ctest.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$here/scripts/setup.sh" --build-type Release
ctest --test-dir "$here/build/release" --output-on-failure -j "$(nproc)" "$@"
