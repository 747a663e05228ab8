#!/usr/bin/env bash
# Loop-closing acceptance (docs/loops.md): synthetic loops (office, street) with the simulated
# network's scale drift, loop closing on and off (ATE se3 / sim3 against exact ground truth), and
# sequences that never revisit a place (office forward, street forward) over three seeds, which
# must close no loop, and 7-Scenes seq-a (sensor depth, default config) with the same seeds.
# Prints a markdown table. Usage:
#   tools/loop_acceptance.sh [WORKDIR]     (default /tmp/ademono_loops; sequences are reused)
# With the loop closed it also runs loop.global_ba=true twice (the repeat must be byte-identical),
# and each loop again with --depth none (the geometric core, its loop closed by Sim(3)).
# The street runs get the rig's camera height (1.65 m, as a KITTI drive gets it without a flag), so
# local and global BA hold the road (depth.ground_in_ba).
# Env: ADEMONO (the CLI, default build/release/bin/ademono), OFFICE_FRAMES (600),
# STREET_FRAMES (300), FORWARD_FRAMES (150), SEEDS ("1 2 3"), SCENES ("office street"), SEQ_A
# (../shared/data/7scenes-seq-a; empty: skipped).
set -euo pipefail
cd "$(dirname "$0")/.."
B=${ADEMONO:-build/release/bin/ademono}
W=${1:-/tmp/ademono_loops}
OFFICE_FRAMES=${OFFICE_FRAMES:-600}
STREET_FRAMES=${STREET_FRAMES:-300}
FORWARD_FRAMES=${FORWARD_FRAMES:-150}
SEEDS=${SEEDS:-1 2 3}
SEQ_A=${SEQ_A-../shared/data/7scenes-seq-a}
SCENES=${SCENES:-office street}
mkdir -p "$W"

synth() {  # name scene motion frames seed
  local out="$W/seq_$1"
  [ -f "$out/groundtruth.txt" ] || "$B" synth --scene "$2" --motion "$3" --frames "$4" \
    --seed "$5" --persons 1 --out "$out" >/dev/null 2>&1
  echo "$out"
}

run() {  # seq scene loop_enabled out [global_ba] [depth: the simulated network unless given]
  local seq=$1 scene=$2 loop=$3 out=$4 gba=${5:-false} depth config height=()
  if [ "$scene" = street ]; then
    config=configs/network_outdoor.yaml
    depth="simulated:gt=$seq/depth_full,scale=0.88,jitter=0.16,jitter_frames=200"
    height=(--set depth.camera_height=1.65)
  else
    config=configs/network_indoor.yaml
    depth="simulated:scale=0.88,jitter=0.16,jitter_frames=200"
  fi
  [ -n "${6:-}" ] && depth=$6
  rm -rf "$out"
  "$B" run --overwrite --dataset "tum:$seq" --config "$config" --depth "$depth" \
    --detector "cache:$seq/detections.jsonl" --set "loop.enabled=$loop" --set "loop.global_ba=$gba" \
    "${height[@]}" --out "$out" >"$out.log" 2>&1
}

row() {  # label summary.json
  python3 - "$1" "$2" <<'PY'
import json, sys
s = json.load(open(sys.argv[2]))
a = s.get("accuracy", {})
loops = s.get("loops", [])
first = loops[0] if loops else None
desc = (f"{len(loops)} (frame {first['query_frame']} -> {first['match_frame']}, "
        f"{first['correction_m']:.3f} m {first['correction_deg']:.2f} deg, {first['ms']:.0f} ms)"
        if first else "0")
se3, sim3 = a.get("ate_se3_rmse_m"), a.get("ate_sim3_rmse_m")
print(f"| {sys.argv[1]} | {s['tracked']}/{s['frames']} | {se3:.4f} | {sim3:.4f} | {desc} |")
PY
}

echo "| run | tracked | ATE se3 (m) | ATE sim3 (m) | loops |"
echo "|---|---|---|---|---|"
for scene in $SCENES; do
  frames=$OFFICE_FRAMES
  [ "$scene" = street ] && frames=$STREET_FRAMES
  seq=$(synth "${scene}_loop" "$scene" loop "$frames" 1)
  for loop in false true; do
    run "$seq" "$scene" "$loop" "$W/run_${scene}_loop_$loop"
    row "$scene loop, loop.enabled=$loop" "$W/run_${scene}_loop_$loop/summary.json"
  done
  # The optional global BA after the loop, run twice: the trajectories must be byte-identical.
  for rep in a b; do run "$seq" "$scene" true "$W/run_${scene}_loop_gba_$rep" true; done
  same=no
  cmp -s "$W/run_${scene}_loop_gba_a/trajectory.tum" "$W/run_${scene}_loop_gba_b/trajectory.tum" &&
    same=yes
  row "$scene loop, loop.global_ba=true (repeat byte-identical: $same)" \
    "$W/run_${scene}_loop_gba_a/summary.json"
  # The geometric core alone (issue 28): its map has no scale of its own indoors, and the loop's
  # Sim(3) corrects the scale drift as well as the pose.
  for loop in false true; do
    run "$seq" "$scene" "$loop" "$W/run_${scene}_loop_none_$loop" false none
    row "$scene loop, --depth none, loop.enabled=$loop" "$W/run_${scene}_loop_none_$loop/summary.json"
  done
done
for seed in $SEEDS; do
  for scene in $SCENES; do
    seq=$(synth "${scene}_forward_$seed" "$scene" forward "$FORWARD_FRAMES" "$seed")
    run "$seq" "$scene" true "$W/run_${scene}_forward_$seed"
    row "$scene forward seed $seed (no revisit)" "$W/run_${scene}_forward_$seed/summary.json"
  done
done
if [ -n "$SEQ_A" ]; then
  for seed in $SEEDS; do
    out="$W/run_seq_a_$seed"
    rm -rf "$out"
    "$B" run --overwrite --dataset "7scenes:$SEQ_A" --seed "$seed" --out "$out" >"$out.log" 2>&1
    row "7-Scenes seq-a seed $seed" "$out/summary.json"
  done
fi
