#!/usr/bin/env bash
# Issue 28's real-data soak: 7-Scenes seq-a played forward and backward (frame k is seq-a frame
# k mod 1198, folded back at 599) with FastDepth from an `ademono infer` cache, run for 1,000
# and for FRAMES frames. Prints keyframes, map points, peak RSS and sim3 of both runs and the two
# checks: keyframes at FRAMES at most 1.1x those at 1,000, peak RSS growth at most 10 MB.
# Usage: tools/soak_fastdepth.sh [--frames N] [--out DIR] [--cache DIR] [--bin B] [--shared DIR]
#   --cache: an existing seq-a depth cache (e.g. tools/geometry_acceptance.py's OUT/cache/seqa/depth);
#   without it the cache is made under OUT with `ademono infer` (FastDepth, about a minute).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
frames=3000 out=/tmp/soak_fastdepth cache="" bin="$here/build/release/bin/ademono"
shared="$here/../shared"
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --cache) cache="$2"; shift 2 ;;
    --bin) bin="$2"; shift 2 ;;
    --shared) shared="$2"; shift 2 ;;
    *) echo "soak_fastdepth.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[[ "$frames" =~ ^[0-9]+$ ]] && [ "$frames" -gt 1000 ] ||
  { echo "soak_fastdepth.sh: --frames must be an integer above 1000, got '$frames'" >&2; exit 2; }
seqa="$shared/data/7scenes-seq-a" model="$shared/models/fastdepth_nyu_320.onnx"
spec="$here/configs/models/fastdepth_nyu.yaml"
for f in "$bin" "$seqa/camera-intrinsics.txt" "$model" "$spec"; do
  [ -e "$f" ] || { echo "soak_fastdepth.sh: $f: not found" >&2; exit 2; }
done
n=$(find "$seqa" -maxdepth 1 -name 'frame-*.color.*' | wc -l)
[ "$n" -gt 1 ] || { echo "soak_fastdepth.sh: $seqa: no frames" >&2; exit 2; }

mkdir -p "$out"
if [ -z "$cache" ]; then
  cache="$out/cache/depth"
  if [ ! -d "$cache" ]; then
    "$bin" infer --dataset "7scenes:$seqa" --depth-model "model:$model,spec=$spec" \
      --out "$out/cache" > "$out/infer.log" 2>&1 ||
      { echo "soak_fastdepth.sh: ademono infer failed, see $out/infer.log" >&2; exit 1; }
  fi
fi
[ -d "$cache" ] || { echo "soak_fastdepth.sh: $cache: no depth cache" >&2; exit 2; }

# The folded sequence and its cache, as symlinks named as a 7-Scenes folder of FRAMES frames.
seq="$out/seq" fcache="$out/fcache"
rm -rf "$seq" "$fcache"
mkdir -p "$seq" "$fcache"
ln -s "$seqa/camera-intrinsics.txt" "$seq/"
period=$((2 * n - 2))
for ((k = 0; k < frames; ++k)); do
  i=$((k % period)); [ "$i" -lt "$n" ] || i=$((period - i))
  src=$(printf 'frame-%06d' "$i") dst=$(printf 'frame-%06d' "$k")
  for f in "$seqa/$src".*; do ln -s "$f" "$seq/$dst${f#"$seqa/$src"}"; done
  for f in "$cache/$src".*; do ln -s "$f" "$fcache/$dst${f#"$cache/$src"}"; done
done

run() {  # run NAME FRAMES
  local dir="$out/run_$1"
  /usr/bin/time -v -o "$dir.time" "$bin" run --dataset "7scenes:$seq" \
    --depth "cache:$fcache,model=$model,spec=$spec" --frames "0:$2" --out "$dir" --overwrite \
    > "$dir.log" 2>&1
}
run 1000 1000
run "$frames" "$frames"

/usr/bin/python3 - "$out" "$frames" <<'EOF'
import json, re, sys
out, frames = sys.argv[1], int(sys.argv[2])
rows = []
for name in ("1000", str(frames)):
    s = json.load(open("%s/run_%s/summary.json" % (out, name)))
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)",
                        open("%s/run_%s.time" % (out, name)).read()).group(1)) / 1024
    acc = s.get("accuracy", {})
    rows.append((name, s["tracked"], s["frames"], s["keyframes"], s["map_points"], rss,
                 acc.get("ate_sim3_rmse_m", float("nan")), s["fps"]))
print("| frames | tracked | keyframes | map points | peak RSS (MB) | ATE sim3 (m) | frames/s |")
print("|---|---|---|---|---|---|---|")
for r in rows:
    print("| %s | %d/%d | %d | %d | %.1f | %.4f | %.1f |" % r)
ratio = rows[1][3] / rows[0][3]
growth = rows[1][5] - rows[0][5]
print("keyframes %d/%d = %.2fx (at most 1.1x): %s" % (rows[1][3], rows[0][3], ratio,
      "yes" if ratio <= 1.1 else "NO"))
print("peak RSS growth %.1f MB (at most 10 MB): %s" % (growth, "yes" if growth <= 10 else "NO"))
EOF
