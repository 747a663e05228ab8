#!/usr/bin/env bash
# Kills `ademono run` with SIGKILL at random moments, many times, and checks every output it left:
# each file must be absent or complete (byte-identical to an uninterrupted run's, the run being
# deterministic; summary.json a complete run's), never partial (issue 16 part 4; the test
# tests/cli/kill_cli_test.cpp does 20 of these in CI).
# Usage: tools/kill_runs.sh [KILLS] [FRAMES]      (default 200 kills, frames 0:30 of 7-Scenes seq-a)
# Even kills go into a fresh folder, odd ones over a complete earlier run with --overwrite.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
kills="${1:-200}" frames="${2:-0:30}"
bin="${ADEMONO_BIN:-$here/build/release/bin/ademono}"
dataset="7scenes:$here/../shared/data/7scenes-seq-a"
work="$(mktemp -d /tmp/ademono_kill_runs.XXXXXX)"
trap 'rm -rf "$work"' EXIT
args=(--log-level warn run --dataset "$dataset" --config "$here/configs/7scenes.yaml" --frames "$frames")

start=$(date +%s.%N)
"$bin" "${args[@]}" --out "$work/ref" >/dev/null 2>&1
full=$(python3 -c "print(round($(date +%s.%N) - $start, 2))")
echo "uninterrupted run: ${full} s; killing $kills runs at uniform random moments in [0, 1.1 x that]"
stable="trajectory.tum trajectory.kitti keyframes.tum map.ply groundtruth.tum config.resolved.yaml"
killed=0 finished=0 bad=0 with_summary=0 empty=0
for ((k = 0; k < kills; k++)); do
  out="$work/k"
  rm -rf "$out"
  extra=()
  if ((k % 2 == 1)); then cp -r "$work/ref" "$out"; extra=(--overwrite); fi
  # The binary itself in the background (not a function: its subshell would take the kill).
  "$bin" "${args[@]}" --out "$out" "${extra[@]}" >/dev/null 2>&1 &
  pid=$!
  sleep "$(python3 -c "import random; print(random.uniform(0, 1.1 * $full))")"
  kill -KILL "$pid" 2>/dev/null || true
  if wait "$pid" 2>/dev/null; then finished=$((finished + 1)); else killed=$((killed + 1)); fi
  [ -d "$out" ] || { empty=$((empty + 1)); continue; }
  for f in $stable; do
    if [ -e "$out/$f" ] && ! cmp -s "$out/$f" "$work/ref/$f"; then
      echo "kill $k: $f is partial or differs"; bad=$((bad + 1))
    fi
  done
  if [ -e "$out/summary.json" ]; then
    with_summary=$((with_summary + 1))
    python3 - "$out" <<'EOF' || { echo "kill $k: summary.json incomplete"; bad=$((bad + 1)); }
import json, os, sys
d = sys.argv[1]
s = json.load(open(os.path.join(d, "summary.json")))
assert s["partial"] is False and s["frames"] == len(s["per_frame"])
for f in ["trajectory.tum", "trajectory.kitti", "keyframes.tum", "map.ply", "config.resolved.yaml"]:
    assert os.path.exists(os.path.join(d, f)), f  # summary.json is committed last
EOF
  fi
  for entry in "$out"/* "$out"/.[!.]*; do
    [ -e "$entry" ] || continue
    name=$(basename "$entry")
    case " $stable summary.json report.html " in *" $name "*) continue ;; esac
    case "$name" in .staging.*) continue ;; esac
    echo "kill $k: stray file $name"; bad=$((bad + 1))
  done
done
echo "kills: $kills ($killed killed mid-run, $finished had finished), folders with a summary.json: $with_summary, no folder yet: $empty"
echo "bad outputs: $bad"
[ "$bad" = 0 ]
