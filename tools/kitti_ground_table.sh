#!/usr/bin/env bash
# The ground-plane table of docs/kitti.md: every estimator of `ademono ground` on every frame of
# ../shared/data/kitti-00 from an `ademono infer` cache of PyDNet and YOLOX-nano (made first if
# DIR has none), one row each: frames with an estimate, median height, share of the frames
# within 3/5/10 % of that median, the normal's pitch.
# Usage: tools/kitti_ground_table.sh [--cache DIR]   (default out/kitti_cache)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$here/build/release/bin/ademono"
cache="$here/out/kitti_cache"
[ "${1:-}" = "--cache" ] && cache="$2"
seq="kitti:$here/../shared/data/kitti-00/sequences/00"
if [ ! -d "$cache/depth" ] || [ ! -f "$cache/detections.jsonl" ]; then
  "$bin" infer --dataset "$seq" \
    --depth-model "model:$here/../shared/models/pydnet_kitti.onnx,spec=$here/configs/models/pydnet_kitti.yaml" \
    --detector "model:$here/../shared/models/yolox_nano.onnx" --out "$cache"
fi
work="$cache/ground"
mkdir -p "$work"
S=(--dataset "$seq" --depth "cache:$cache/depth")
B=(--detector "cache:$cache/detections.jsonl")
T=(--min-depth 0 --max-depth 25 --max-lateral 4 --max-tilt 15)  # tracking's corridor
g() { local name="$1"; shift; "$bin" ground "${S[@]}" "$@" --json "$work/$name.json" > /dev/null; }
g kp_track --from keypoints "${T[@]}"
g kp_track_boxes "${B[@]}" --from keypoints "${T[@]}"
g dense_track --from dense "${T[@]}"
g dense_lane "${B[@]}" --from dense
g dense_near3 "${B[@]}" --from dense --max-tilt 3 --max-depth 12
g level "${B[@]}" --from level
g level_near "${B[@]}" --from level --min-depth 5 --max-depth 9
g tv1 "${B[@]}" --from two-view --gap 1
g tv2 "${B[@]}" --from two-view --gap 2
g tv2_fixed "${B[@]}" --from two-view --gap 2 --fixed-normal
/usr/bin/python3 - "$work" <<'PY'
import json, sys
import numpy as np
work = sys.argv[1]
rows = [("kp_track", "ORB keypoints with PyDNet depth, tracking's corridor (4 m, 25 m, 15 deg)", False),
        ("kp_track_boxes", "the same off YOLOX-nano's boxes", False),
        ("dense_track", "dense PyDNet, tracking's corridor", False),
        ("dense_lane", "dense PyDNet, lane corridor (2 m, 3-20 m), boxes", False),
        ("dense_near3", "dense PyDNet, 2 m, 3-12 m, normal within 3 deg, boxes", False),
        ("level", "PyDNet along the camera's up axis, lane corridor, boxes", True),
        ("level_near", "PyDNet along the up axis, 5-9 m, boxes", True),
        ("tv1", "two views (k, k+1), ground-truth motion, boxes", False),
        ("tv2", "two views (k, k+2), ground-truth motion, boxes", False),
        ("tv2_fixed", "two views (k, k+2), level normal held, boxes", False)]
print("| estimator | frames with an estimate | median height (m) | median / 1.65 | within 3 % of the median | within 5 % | within 10 % | median pitch (deg) | pitch p10-p90 |")
print("|---|---|---|---|---|---|---|---|---|")
for name, label, any_height in rows:
    frames = json.load(open(f"{work}/{name}.json"))["frames"]
    sel = [f for f in frames if f["valid"] or (any_height and f["height_m"] > 0)]
    h = np.array([f["height_m"] for f in sel])
    p = np.array([f["pitch_deg"] for f in sel])
    m = np.median(h)
    w = lambda q: 100.0 * np.sum(np.abs(h / m - 1) <= q) / len(frames)
    print(f"| {label} | {len(sel)}/{len(frames)} | {m:.3f} | {m / 1.65:.3f} | {w(.03):.0f} % | "
          f"{w(.05):.0f} % | {w(.10):.0f} % | {np.median(p):.2f} | "
          f"{np.percentile(p, 10):.2f} to {np.percentile(p, 90):.2f} |")
PY
