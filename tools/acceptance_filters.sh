#!/usr/bin/env bash
# Acceptance experiments of the three filters on synthetic sequences with exact ground truth
# (docs/ablation.md). Usage: tools/acceptance_filters.sh [ADEMONO_BINARY] [WORK_DIR]
#   office: 300 frames, 3 walking persons + the static mannequin, xyz motion, simulated depth,
#           ground-truth boxes; all five ablation variants.
#   street: 150 frames x 5 seeds, simulated depth on the float depth maps, ground-truth boxes,
#           configs/street.yaml; the distant filter on/off with dynamic removal on (full vs
#           no_distant) and off (no_dynamic vs no_dynamic_no_distant): median ATE over the seeds,
#           realised drop rate.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="${1:-$here/build/release/bin/ademono}"
work="${2:-/tmp/ademono_acceptance}"
mkdir -p "$work"

office="$work/office_s7"
[ -d "$office/rgb" ] || "$bin" synth --scene office --motion xyz --persons 3 --frames 300 --seed 7 \
  --out "$office" >/dev/null
if [ "${SKIP_OFFICE:-0}" != 1 ]; then
rm -rf "$work/office_ablate"
"$bin" ablate --dataset "tum:$office" --depth simulated \
  --detector "cache:$office/detections.jsonl" --out "$work/office_ablate"
fi

for seed in 1 2 3 4 5; do
  street="$work/street_s$seed"
  [ -d "$street/rgb" ] || "$bin" synth --scene street --frames 150 --seed "$seed" \
    --out "$street" >/dev/null
  [ "${SKIP_STREET_RUNS:-0}" = 1 ] || rm -rf "$work/street_ablate_s$seed"
  [ "${SKIP_STREET_RUNS:-0}" = 1 ] || "$bin" ablate --dataset "tum:$street" --config "$here/configs/street.yaml" \
    --depth "simulated:gt=$street/depth_full" --detector "cache:$street/detections.jsonl" \
    --variants full,no_distant,no_dynamic,no_dynamic_no_distant --out "$work/street_ablate_s$seed"
done
python3 - "$work" <<'PY'
import json, statistics, sys
work = sys.argv[1]
pairs = [("full", "no_distant"), ("no_dynamic", "no_dynamic_no_distant")]
ate = {v: [] for p in pairs for v in p}
dropped = cand = 0
for seed in range(1, 6):
    v = {x["variant"]: x for x in json.load(open(f"{work}/street_ablate_s{seed}/ablation.json"))["variants"]}
    for name in ate:  # no ATE (fewer than 3 tracked frames) ranks as infinitely bad
        a = v[name]["ate_se3_rmse_m"]
        ate[name].append(float("inf") if a is None else a)
    for name in ("full", "no_dynamic"):
        dropped += v[name]["filter_counts"]["removed_distant"]
        cand += v[name]["filter_counts"]["distant_candidates"]
    print(f"street seed {seed}: " + ", ".join(
        f"{n} {ate[n][-1]:.4f} m ({v[n]['tracked']}/{v[n]['frames']})" for n in ate))
for on, off in pairs:
    print(f"street median ATE se3: {on} {statistics.median(ate[on]):.4f} m vs {off} "
          f"{statistics.median(ate[off]):.4f} m")
print(f"street distant drop rate: {dropped}/{cand} = {dropped / cand:.3f}")
PY
