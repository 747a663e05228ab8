#!/usr/bin/env bash
# Faster drives from the one we have: ../shared/data/kitti-00 with every STRIDE-th frame kept
# (stride 2: about 1.5 m a frame, KITTI 04's speed at 10 frames/s; stride 3: about 2.2 m, the
# highway of KITTI 01). Builds each strided copy as symlinks (images, calib, every STRIDE-th
# ground-truth pose, times 0.1 s apart as the reader expects), caches PyDNet over it with
# `ademono infer`, then runs `--depth none` and PyDNet (the shipped spec, no other flag) over
# several distant-filter/initialiser seeds and prints one table: tracked frames, keyframes,
# ATE se3 and sim3. Nothing here is tuned: it shows where the shipped outdoor settings stop.
# Usage: tools/kitti_stride.sh [--out DIR] [--strides "2 3"] [--seeds "42 1 2 3"]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$here/build/release/bin/ademono"
out="$here/out/kitti_stride" strides="2 3" seeds="42 1 2 3"
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --strides) strides="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    *) echo "kitti_stride: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$bin" ] || { echo "kitti_stride: $bin not built (bash scripts/setup.sh)" >&2; exit 2; }
src="$(cd "$here/../shared/data/kitti-00" 2>/dev/null && pwd)" ||
  { echo "kitti_stride: $here/../shared/data/kitti-00: not found" >&2; exit 2; }
model="$here/../shared/models/pydnet_kitti.onnx"
spec="$here/configs/models/pydnet_kitti.yaml"
mkdir -p "$out"

for s in $strides; do
  seq="$out/stride$s/sequences/00"
  if [ ! -f "$seq/times.txt" ]; then
    rm -rf "$out/stride$s"
    mkdir -p "$seq/image_2" "$out/stride$s/poses"
    ln -s "$src/sequences/00/calib.txt" "$seq/calib.txt"
    n=0
    total=$(wc -l < "$src/poses/00.txt")
    for ((i = 0; i < total; i += s)); do
      ln -s "$src/sequences/00/image_2/$(printf %06d "$i").jpg" "$seq/image_2/$(printf %06d "$n").jpg"
      printf '%e\n' "$(awk -v n="$n" 'BEGIN { print n * 0.1 }')" >> "$seq/times.txt"
      sed -n "$((i + 1))p" "$src/poses/00.txt" >> "$out/stride$s/poses/00.txt"
      n=$((n + 1))
    done
  fi
  if [ ! -d "$out/stride$s/cache/depth" ]; then
    echo "== $(date -u +%H:%M:%S) stride $s: ademono infer (PyDNet)" >&2
    "$bin" infer --dataset "kitti:$seq" --depth-model "model:$model,spec=$spec" \
      --out "$out/stride$s/cache" > "$out/stride$s/infer.log" 2>&1 ||
      { echo "kitti_stride: infer failed, see $out/stride$s/infer.log" >&2; exit 1; }
  fi
  for depth in none pydnet; do
    for seed in $seeds; do
      name="stride${s}_${depth}_seed$seed"
      echo "== $(date -u +%H:%M:%S) $name" >&2
      d=none
      [ "$depth" = pydnet ] && d="cache:$out/stride$s/cache/depth,model=$model,spec=$spec"
      "$bin" run --overwrite --dataset "kitti:$seq" --depth "$d" --seed "$seed" \
        --out "$out/$name" > "$out/$name.log" 2>&1 ||
        { echo "kitti_stride: $name failed, see $out/$name.log" >&2; exit 1; }
    done
  done
done

python3 - "$out" "$strides" "$seeds" <<'PY'
import json, sys
out, strides, seeds = sys.argv[1], sys.argv[2].split(), sys.argv[3].split()
print("| stride | depth | seed | tracked | keyframes | ATE se3 (m) | ATE sim3 (m) | sim3 scale |")
print("|---|---|---|---|---|---|---|---|")
for s in strides:
    for depth in ("none", "pydnet"):
        for seed in seeds:
            r = json.load(open(f"{out}/stride{s}_{depth}_seed{seed}/summary.json"))
            a = r.get("accuracy", {})
            print(f"| {s} | {depth} | {seed} | {r['tracked']}/{r['frames']} | {r['keyframes']} | "
                  f"{a.get('ate_se3_rmse_m', float('nan')):.3f} | "
                  f"{a.get('ate_sim3_rmse_m', float('nan')):.3f} | {a.get('sim3_scale', float('nan')):.3f} |")
PY
