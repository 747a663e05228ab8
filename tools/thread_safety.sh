#!/usr/bin/env bash
# Checks the map's lock contract (core/thread_annotations.h): compiles the slam module with
# clang's thread-safety analysis, -fsyntax-only (no objects, a few seconds a file), every warning
# an error. Flags come from build/release/compile_commands.json (scripts/setup.sh), with GCC's
# compiler swapped for clang. Exit 0: no violation; 1: the analysis found one (printed).
# Usage: tools/thread_safety.sh [BUILD_DIR]   (ADEMONO_TS_ONLY=REGEX: only the matching files)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$here/build/release}"
clang="${ADEMONO_CLANG:-$(command -v clang++-14 || command -v clang++ || true)}"
[ -n "$clang" ] || { echo "thread_safety.sh: clang++ not found (apt-get install clang-14)" >&2; exit 2; }
[ -f "$build/compile_commands.json" ] || { echo "thread_safety.sh: $build/compile_commands.json missing (run scripts/setup.sh)" >&2; exit 2; }
python3 - "$build/compile_commands.json" "$here/src/ademono/slam/" > "$build/thread_safety.cmds" <<'PY'
import json, shlex, sys
commands, prefix = json.load(open(sys.argv[1])), sys.argv[2]
for e in commands:
    if not e["file"].startswith(prefix):
        continue
    args = shlex.split(e["command"])[1:]
    keep, skip = [], False
    for a in args:  # drop the output and the input; keep defines, includes and -std
        if skip:
            skip = False
            continue
        if a in ("-o", "-c"):
            skip = True
            continue
        if a.startswith("-O") or a.startswith("-f") and a != "-fPIC":
            continue
        keep.append(a)
    print(e["directory"] + "\t" + " ".join(shlex.quote(a) for a in keep) + "\t" + e["file"])
PY
[ -s "$build/thread_safety.cmds" ] || { echo "thread_safety.sh: no slam sources in $build/compile_commands.json" >&2; exit 2; }
# First, that the analysis is on at all: a member read without its mutex must be rejected.
probe="$build/thread_safety_probe.cpp"
cat > "$probe" <<'CPP'
#include "ademono/core/thread_annotations.h"
struct Probe {
  ademono::Mutex mutex;
  int value ADEMONO_GUARDED_BY(mutex) = 0;
  int Unlocked() { return value; }
  int Locked() { ademono::MutexLock lock(mutex); return value; }
};
CPP
if "$clang" -std=c++17 -I"$here/src" -fsyntax-only -Wthread-safety -Werror "$probe" 2>/dev/null; then
  echo "thread_safety.sh: the analysis did not reject an unguarded read ($probe)" >&2; exit 1
fi
status=0 checked=0
while IFS=$'\t' read -r dir flags file; do
  [ -z "${ADEMONO_TS_ONLY:-}" ] || [[ "$file" =~ $ADEMONO_TS_ONLY ]] || continue
  eval "set -- $flags"
  checked=$((checked + 1))
  if ! (cd "$dir" && "$clang" "$@" -fsyntax-only -Wthread-safety -Wthread-safety-beta -Werror \
        -Wno-unknown-warning-option -Wno-unused-command-line-argument "$file"); then
    status=1
  fi
done < "$build/thread_safety.cmds"
[ $status -eq 0 ] && echo "thread_safety.sh: $checked slam sources, no thread-safety violation" \
  || echo "thread_safety.sh: violations above" >&2
exit $status
