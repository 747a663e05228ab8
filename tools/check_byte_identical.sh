#!/usr/bin/env bash
# Acceptance check for refactorings that must not change results: builds OLD_REV in a temporary
# git worktree (same build flags as scripts/setup.sh, so ccache serves unchanged files), runs the
# README-quoted commands with the old and the current binary, and compares their outputs:
#   1. `ademono run` on 7-Scenes seq-a (README "Measured"),
#   2. the demo (scripts/demo.sh): `ademono synth` office, 2 persons, seed 7, 300 frames (the
#      rendered sequences are compared too), then `ademono run` with simulated depth and the
#      ground-truth boxes,
#   3. a short `ademono ablate` on that office (all five variants, frames 0:60).
# trajectory.tum, trajectory.kitti, keyframes.tum, map.ply and ablation.md must be byte-identical;
# summary.json and ablation.json are compared field by field, apart from timing and the
# documented summary schema change ("ademono.run/1", docs/slam.md), see compare_runs.py below.
#
# Usage: tools/check_byte_identical.sh OLD_REV [--new-bin BIN] [--work DIR] [--keep]
#   --new-bin  the binary to check (default: build/release/bin/ademono, built first)
#   --work     where the old worktree and the outputs go (default: out/byte-check; keep it under
#              /work so ccache's base_dir makes the old build's compiler calls cache hits)
#   --keep     keep the old worktree and its build (default: removed at the end)
# Exit code 0 when everything matches, 1 on a difference, 2 on a usage or build error.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
old_rev="" new_bin="" work="$here/out/byte-check" keep=0
while [ $# -gt 0 ]; do
  case "$1" in
    --new-bin) new_bin="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --keep) keep=1; shift ;;
    -*) echo "check_byte_identical: unknown option '$1'" >&2; exit 2 ;;
    *) [ -z "$old_rev" ] || { echo "check_byte_identical: one OLD_REV only" >&2; exit 2; }
       old_rev="$1"; shift ;;
  esac
done
[ -n "$old_rev" ] || { sed -n '2,18p' "$0" >&2; exit 2; }
old_sha="$(git -C "$here" rev-parse --verify "$old_rev^{commit}")" || exit 2
shared="$(cd "$here/../shared" && pwd)"
mkdir -p "$work"
work="$(cd "$work" && pwd)"
old_tree="$work/old-${old_sha:0:7}"
log() { echo "== $(date -u +%H:%M:%S) $*"; }

# --- binaries ---
if [ -z "$new_bin" ]; then
  log "building the current tree (ademono_cli)"
  cmake --build "$here/build/release" -j2 --target ademono_cli >"$work/build-new.log" 2>&1 ||
    { tail -20 "$work/build-new.log" >&2; exit 2; }
  new_bin="$here/build/release/bin/ademono"
fi
new_bin="$(cd "$(dirname "$new_bin")" && pwd)/$(basename "$new_bin")"
if [ ! -d "$old_tree" ]; then
  log "worktree of $old_rev ($old_sha) in $old_tree"
  git -C "$here" worktree add --detach "$old_tree" "$old_sha" >/dev/null
fi
mkdir -p "$old_tree/.deps"
ln -sfn "$(readlink -f "$here/.deps/onnxruntime")" "$old_tree/.deps/onnxruntime"
log "building $old_rev (ademono_cli)"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
if ! { cmake -S "$old_tree" -B "$old_tree/build/release" -G Ninja -DCMAKE_BUILD_TYPE=Release \
         -DADEMONO_SANITIZE=OFF -DONNXRUNTIME_ROOT="$old_tree/.deps/onnxruntime" "${launcher[@]}" &&
       cmake --build "$old_tree/build/release" -j2 --target ademono_cli; } >"$work/build-old.log" 2>&1; then
  tail -20 "$work/build-old.log" >&2
  exit 2
fi
old_bin="$old_tree/build/release/bin/ademono"
cleanup() {
  if [ "$keep" = 0 ]; then git -C "$here" worktree remove --force "$old_tree" >/dev/null 2>&1 || true; fi
}
trap cleanup EXIT

# --- runs: each binary from its own tree, so each finds its own configs/ ---
out="$work/runs"
rm -rf "$out"
mkdir -p "$out/old" "$out/new"
run_both() {  # run_both NAME ARGS... (the output folder is appended as --out)
  local name="$1"; shift
  for side in old new; do
    local bin tree
    if [ "$side" = old ]; then bin="$old_bin"; tree="$old_tree"; else bin="$new_bin"; tree="$here"; fi
    log "$side: ademono $* --out .../$side/$name"
    (cd "$tree" && "$bin" --log-level warn "$@" --out "$out/$side/$name") \
      >"$out/$side/$name.stdout" 2>"$out/$side/$name.stderr" ||
      { echo "ademono $* failed ($side), see $out/$side/$name.stderr" >&2; exit 1; }
  done
}

run_both 7scenes run --dataset "7scenes:$shared/data/7scenes-seq-a"
# The demo's sequence: rendered by both binaries and compared; both then run on the old one.
run_both office synth --scene office --motion xyz --persons 2 --frames 300 --seed 7
office="$out/old/office"
run_both demo run --dataset "tum:$office" --depth simulated --detector "cache:$office/detections.jsonl"
run_both ablate ablate --dataset "tum:$office" --depth simulated \
  --detector "cache:$office/detections.jsonl" --frames 0:60

# --- comparison ---
log "comparing"
status=0
if diff -r -q "$out/old/office" "$out/new/office" >/dev/null; then
  echo "same     synth office (every file)"
else
  echo "DIFFERS  synth office:"; diff -r -q "$out/old/office" "$out/new/office" | head; status=1
fi
if cmp -s "$out/old/ablate.stdout" "$out/new/ablate.stdout"; then
  echo "same     ablate stdout (the table)"
else
  echo "DIFFERS  ablate stdout"; status=1
fi
python3 "$here/tools/compare_runs.py" "$out/old" "$out/new" 7scenes demo \
  ablate/full ablate/no_dynamic ablate/no_distant ablate/no_dynamic_no_distant \
  ablate/no_enhancement --ablation ablate || status=1
if [ "$status" = 0 ]; then
  log "OK: outputs of $old_rev and the current binary agree"
else
  log "DIFFERENCES between $old_rev and the current binary (outputs kept in $out)"
fi
exit "$status"
