#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh), builds, and runs the main job on an embedded default:
#   1. renders a synthetic office sequence with walking persons and exact ground truth,
#   2. runs the full ADEmono pipeline on it: simulated network depth (never a real network,
#      see docs/synth.md), ground-truth boxes as the detector cache, all three filters on,
#   3. evaluates the trajectory against ground truth and prints ATE.
# With real model files, the same command uses them instead of the simulation and the boxes:
#   scripts/demo.sh [--depth-model FILE.onnx[,spec=SPEC.yaml]] [--detector-model FILE.onnx[,arch=yolox]]
#                   [--dataset KIND:PATH] [--out DIR]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
depth_model="" detector_model="" dataset="" out="$here/out/demo"
while [ $# -gt 0 ]; do
  case "$1" in
    --depth-model) depth_model="$2"; shift 2 ;;
    --detector-model) detector_model="$2"; shift 2 ;;
    --dataset) dataset="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *) echo "demo.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
"$here/scripts/setup.sh" --build-type Release
bin="$here/build/release/bin/ademono"

if [ -z "$dataset" ]; then
  seq_dir="$out/office"
  rm -rf "$seq_dir"
  echo "== 1/3 rendering a synthetic office sequence with walking persons -> $seq_dir"
  "$bin" synth --scene office --motion xyz --persons 2 --frames 300 --seed 7 --out "$seq_dir"
  dataset="tum:$seq_dir"
  gt="$seq_dir/groundtruth.txt"
  depth="simulated"
  detector="cache:$seq_dir/detections.jsonl"
else
  gt=""
  depth="sensor"
  detector="none"
fi
[ -n "$depth_model" ] && depth="model:$depth_model"
[ -n "$detector_model" ] && detector="model:$detector_model"

echo "== 2/3 ademono run --dataset $dataset --depth $depth --detector $detector"
"$bin" run --dataset "$dataset" --depth "$depth" --detector "$detector" --out "$out/run" --overwrite

if [ -n "$gt" ]; then
  echo "== 3/3 evaluation against ground truth"
  "$bin" eval --gt "$gt" --est "$out/run/trajectory.tum" --format tum --align se3 \
    --json "$out/run/ate.json" --plot "$out/run/trajectory.svg"
fi
echo "outputs: $out/run (trajectory.tum, trajectory.kitti, keyframes.tum, map.ply, summary.json)"
