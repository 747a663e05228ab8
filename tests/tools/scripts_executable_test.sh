#!/usr/bin/env bash
# Every script in scripts/ and tools/ that starts with a #! line is executable, since README and
# docs/ invoke them by path (tools/geometry_acceptance.py ...). Fails listing the ones that are not;
# `git update-index --chmod=+x FILE` fixes one.
set -euo pipefail
root="${1:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
bad=0
while IFS= read -r -d '' f; do
  [ "$(head -c 2 "$f")" = '#!' ] || continue
  if [ ! -x "$f" ]; then
    echo "not executable: ${f#"$root"/}" >&2
    bad=1
  fi
done < <(find "$root/scripts" "$root/tools" -type f -not -path '*/__pycache__/*' -not -path '*/node_modules/*' -print0)
exit "$bad"
