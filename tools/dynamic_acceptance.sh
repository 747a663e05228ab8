#!/usr/bin/env bash
# Acceptance runs of dynamic-scene handling on real data (issue 17, docs/filters.md "Movers
# without a box"): bonn-crowd-a (464 frames, three people walking through an office) with sensor
# depth and with FastDepth, with YOLOX-nano and with no detector, the geometric test on and off;
# 7-Scenes seq-a (static) as the no-regression check. Prints one markdown table.
#   tools/dynamic_acceptance.sh [ADEMONO_BINARY] [WORK_DIR]
# YOLOX-nano runs once: `ademono infer` caches its detections under WORK_DIR (reused when
# present) and every run replays them (--detector cache:, the same boxes as the model inline).
# FastDepth runs inline (`--depth model:...`), as a user would run it: that is what picks
# configs/network_indoor.yaml and the spec's depth error model.
# REUSE=1 keeps the runs whose summary.json exists and only prints the table.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="${1:-$here/build/release/bin/ademono}"
work="${2:-$here/out/dynamic_acceptance}"
shared="$here/../shared"
bonn="tum:$shared/data/bonn-crowd-a"
seqa="7scenes:$shared/data/7scenes-seq-a"
yolox="model:$shared/models/yolox_nano.onnx"
fastdepth="model:$shared/models/fastdepth_nyu_320.onnx,spec=$here/configs/models/fastdepth_nyu.yaml"
mkdir -p "$work"
cd "$here"

if [ ! -f "$work/bonn-infer/detections.jsonl" ]; then
  "$bin" infer --dataset "$bonn" --detector "$yolox" \
    --out "$work/bonn-infer" > "$work/bonn-infer.log" 2>&1
fi
if [ ! -f "$work/seqa-infer/detections.jsonl" ]; then
  "$bin" infer --dataset "$seqa" --detector "$yolox" --out "$work/seqa-infer" \
    > "$work/seqa-infer.log" 2>&1
fi
bonn_det="cache:$work/bonn-infer/detections.jsonl"
seqa_det="cache:$work/seqa-infer/detections.jsonl"

rows=()
run() {  # name, dataset, depth label, detector label, removal label, run args...
  local name=$1 dataset=$2 depth_label=$3 det_label=$4 mode=$5; shift 5
  if [ "${REUSE:-0}" = 1 ] && [ -f "$work/$name/summary.json" ]; then
    :
  elif rm -rf "${work:?}/$name" && ! "$bin" run --overwrite --dataset "$dataset" --out "$work/$name" "$@" > "$work/$name.log" 2>&1; then
    echo "(run $name failed: see $work/$name.log)" >&2
    return
  fi
  rows+=("$(python3 - "$work/$name/summary.json" "$name" "$depth_label" "$det_label" "$mode" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
name, depth, det, mode = sys.argv[2:6]
a = s.get("accuracy", {})
fc = s.get("filter_counts", {})
g = s.get("geometric_test", {})
w = s.get("weak_poses", {})
removed_box = fc.get("removed_dynamic", 0)
print(f"| {name} | {depth} | {det} | {mode} | {a.get('ate_se3_rmse_m', float('nan')):.4f} | "
      f"{a.get('ate_sim3_rmse_m', float('nan')):.4f} x{a.get('sim3_scale', float('nan')):.3f} | "
      f"{s['untracked']} / {s['frames']} | {w.get('few_static_points', 0)} + {w.get('motion_model', 0)} | "
      f"{removed_box} | {g.get('matches_judged_dynamic', 0)} |")
PY
)")
}

run bonn_sensor_yolox "$bonn" sensor YOLOX-nano "boxes + geometry" --detector "$bonn_det"
run bonn_sensor_yolox_twostage "$bonn" sensor YOLOX-nano "boxes (the paper's rule alone)" \
    --detector "$bonn_det" --set tracking.static_test=false --set filter.judge_small_boxes=false
run bonn_sensor_yolox_judged "$bonn" sensor YOLOX-nano "boxes + geometry, small boxes judged" \
    --detector "$bonn_det" --set filter.judge_small_boxes=true
run bonn_sensor_geometry "$bonn" sensor none "geometry only"
run bonn_sensor_none "$bonn" sensor none "none" --set tracking.static_test=false
run bonn_fastdepth_yolox "$bonn" FastDepth YOLOX-nano "boxes + geometry" --depth "$fastdepth" \
    --detector "$bonn_det"
run seqa_sensor_yolox "$seqa" sensor YOLOX-nano "boxes + geometry" --detector "$seqa_det"

# The same comparison through `ademono ablate` (docs/ablation.md): the real detector with boxes and
# geometry (full), the paper's two-stage rule alone (boxes_only), the geometric test with no
# detector (geometry_only), and no dynamic handling at all (no_dynamic).
if ! { [ "${REUSE:-0}" = 1 ] && [ -f "$work/bonn_ablate/ablation.md" ]; }; then
  rm -rf "${work:?}/bonn_ablate"
  "$bin" ablate --dataset "$bonn" --detector "$bonn_det" \
    --variants full,boxes_only,geometry_only,no_dynamic --out "$work/bonn_ablate" \
    > "$work/bonn_ablate.log" 2>&1 || echo "(ablate failed: see $work/bonn_ablate.log)" >&2
fi

echo "| run | depth | detector | removal | ATE se3 (m) | ATE sim3 (m) x scale | untracked | weak poses (few static + motion model) | keypoints removed by boxes | matches judged moving by geometry |"
echo "|---|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
echo
echo "ademono ablate --dataset $bonn --detector $bonn_det --variants full,boxes_only,geometry_only,no_dynamic:"
cat "$work/bonn_ablate/ablation.md" 2>/dev/null || true
