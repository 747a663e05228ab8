#!/usr/bin/env bash
# Ablation of the network-depth design (docs/slam.md, "Network depth"): on one sequence with
# network depth, the full method and each piece turned off in turn, plus the old sensor-style path
# fed the same depth. Prints one markdown table (ATE se3 / sim3, sim3 scale, tracked, keyframes).
#   tools/ablation_network_depth.sh BIN DATASET DEPTH OUT [NETWORK_CONFIG] [SENSOR_CONFIG] [-- extra run args]
# e.g. tools/ablation_network_depth.sh build/release/bin/ademono 7scenes:../shared/data/7scenes-seq-a \
#        cache:/tmp/fd/depth /tmp/abl configs/network_indoor.yaml configs/7scenes.yaml
set -euo pipefail
bin=$1 dataset=$2 depth=$3 out=$4
net_config=${5:-configs/network_indoor.yaml}
sensor_config=${6:-configs/7scenes.yaml}
shift $(( $# < 6 ? $# : 6 ))
[ "${1:-}" = "--" ] && shift
extra=("$@")
mkdir -p "$out"
run() {  # name, args...
  local name=$1; shift
  rm -rf "$out/$name"
  "$bin" run --overwrite --dataset "$dataset" --depth "$depth" --out "$out/$name" "${extra[@]}" "$@" \
    > "$out/$name.log" 2>&1 || echo "(run $name failed: see $out/$name.log)" >&2
}
run full --config "$net_config"
run no_uncertainty_weighting --config "$net_config" --set depth.uncertainty_weighting=false
run no_triangulation --config "$net_config" --set mapping.triangulation=false
run no_scale_correction --config "$net_config" --set depth.scale_correction=false \
    --set depth.anchor_scale=false
# The sensor path as it was: Kinect edge test (raised to 0.15 so that the map initialises),
# virtual-baseline weighting, no scale correction, no triangulation.
run sensor_style_path --config "$sensor_config" --set depth.edge_relative_jump=0.15 \
    --set tracking.min_init_points=100
echo "| variant | tracked | keyframes | ATE se3 (m) | ATE sim3 (m) | sim3 scale |"
echo "|---|---|---|---|---|---|"
for name in full no_uncertainty_weighting no_triangulation no_scale_correction sensor_style_path; do
  /usr/bin/python3 - "$out/$name/summary.json" "$name" <<'PY'
import json, sys
try:
    s = json.load(open(sys.argv[1]))
except OSError:
    print("| %s | failed | | | | |" % sys.argv[2]); sys.exit(0)
a = s.get("accuracy") or {}
f = lambda k, spec: spec % a[k] if k in a else "-"
print("| %s | %d/%d | %d | %s | %s | %s |" % (sys.argv[2], s["tracked"], s["frames"], s["keyframes"],
      f("ate_se3_rmse_m", "%.4f"), f("ate_sim3_rmse_m", "%.4f"), f("sim3_scale", "%.3f")))
PY
done
