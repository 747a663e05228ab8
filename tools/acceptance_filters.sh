#!/usr/bin/env bash
# Acceptance experiments of the three filters on synthetic sequences with exact ground truth
# (docs/ablation.md). Usage: tools/acceptance_filters.sh [ADEMONO_BINARY] [WORK_DIR]
#   office: 300 frames, 3 walking persons + the static mannequin, xyz motion, simulated depth,
#           ground-truth boxes; seeds 7, 5, 11 (OFFICE_SEEDS); all five ablation variants on the
#           first seed, full and no_dynamic on the others.
#   street: 150 frames x 5 seeds, simulated depth on the float depth maps, ground-truth boxes,
#           configs/street.yaml; the distant filter on/off with dynamic removal on (full vs
#           no_distant) and off (no_dynamic vs no_dynamic_no_distant): median ATE over the seeds,
#           realised drop rate.
# SKIP_OFFICE=1 / SKIP_STREET_RUNS=1 reuse earlier results in WORK_DIR.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="${1:-$here/build/release/bin/ademono}"
work="${2:-/tmp/ademono_acceptance}"
office_seeds="${OFFICE_SEEDS:-7 5 11}"
mkdir -p "$work"

first=1
for seed in $office_seeds; do
  office="$work/office_s$seed"
  [ -d "$office/rgb" ] || "$bin" synth --scene office --motion xyz --persons 3 --frames 300 \
    --seed "$seed" --out "$office" >/dev/null
  variants=full,no_dynamic
  [ "$first" = 1 ] && variants=full,no_dynamic,no_distant,no_dynamic_no_distant,no_enhancement
  first=0
  [ "${SKIP_OFFICE:-0}" = 1 ] && continue
  rm -rf "$work/office_ablate_s$seed"
  "$bin" ablate --dataset "tum:$office" --depth simulated --detector "cache:$office/detections.jsonl" \
    --variants "$variants" --out "$work/office_ablate_s$seed" >/dev/null
done

for seed in 1 2 3 4 5; do
  street="$work/street_s$seed"
  [ -d "$street/rgb" ] || "$bin" synth --scene street --frames 150 --seed "$seed" \
    --out "$street" >/dev/null
  [ "${SKIP_STREET_RUNS:-0}" = 1 ] && continue
  rm -rf "$work/street_ablate_s$seed"
  "$bin" ablate --dataset "tum:$street" --config "$here/configs/street.yaml" \
    --depth "simulated:gt=$street/depth_full" --detector "cache:$street/detections.jsonl" \
    --variants full,no_distant,no_dynamic,no_dynamic_no_distant --out "$work/street_ablate_s$seed" \
    >/dev/null
done

python3 - "$work" $office_seeds <<'PY'
import json, statistics, sys
work, office_seeds = sys.argv[1], sys.argv[2:]

def variants(path):
    return {x["variant"]: x for x in json.load(open(path))["variants"]}

def ate(v, key="ate_se3_rmse_m"):  # no ATE (fewer than 3 tracked frames) ranks as infinitely bad
    return float("inf") if v[key] is None else v[key]

print("| office seed | ATE se3 with removal | ATE se3 without | tracked | moving keypoints removed "
      "| static-person keypoints removed |")
print("|---|---|---|---|---|---|")
for seed in office_seeds:
    v = variants(f"{work}/office_ablate_s{seed}/ablation.json")
    full, off = v["full"], v["no_dynamic"]
    t = full["truth"]
    print(f"| {seed} | {ate(full):.4f} m | {ate(off):.4f} m | {full['tracked']}/{full['frames']} | "
          f"{100 * t['moving_removed_ratio']:.1f} % | {100 * t['static_person_removed_ratio']:.1f} % |")

pairs = [("full", "no_distant"), ("no_dynamic", "no_dynamic_no_distant")]
names = [n for p in pairs for n in p]
se3 = {n: [] for n in names}
sim3 = {n: [] for n in names}
dropped = cand = 0
print()
print("| street seed | " + " | ".join(f"{n} se3 / sim3 (tracked)" for n in names) + " |")
print("|---|" + "---|" * len(names))
for seed in range(1, 6):
    v = variants(f"{work}/street_ablate_s{seed}/ablation.json")
    cells = []
    for n in names:
        se3[n].append(ate(v[n]))
        sim3[n].append(ate(v[n], "ate_sim3_rmse_m"))
        cells.append(f"{se3[n][-1]:.4f} / {sim3[n][-1]:.4f} ({v[n]['tracked']}/{v[n]['frames']})")
    for n in ("full", "no_dynamic"):
        dropped += v[n]["filter_counts"]["removed_distant"]
        cand += v[n]["filter_counts"]["distant_candidates"]
    print(f"| {seed} | " + " | ".join(cells) + " |")
print("| median | " + " | ".join(f"{statistics.median(se3[n]):.4f} / {statistics.median(sim3[n]):.4f}"
                                  for n in names) + " |")
moving = [0, 0]
static = [0, 0]
for seed in range(1, 6):
    t = variants(f"{work}/street_ablate_s{seed}/ablation.json")["full"]["truth"]
    moving[0] += t["moving_removed"]
    moving[1] += t["moving_keypoints"]
    static[0] += t["static_in_box_removed"]
    static[1] += t["static_in_box_keypoints"]
print()
print(f"street full, all seeds: moving-object keypoints removed {moving[0]}/{moving[1]} = "
      f"{moving[0] / moving[1]:.3f}; static keypoints in dynamic-class boxes removed "
      f"{static[0]}/{static[1]} = {static[0] / static[1]:.3f}")
for on, off in pairs:
    verdict = "no worse" if statistics.median(se3[on]) <= statistics.median(se3[off]) else "WORSE"
    print(f"street median ATE se3: {on} {statistics.median(se3[on]):.4f} m vs {off} "
          f"{statistics.median(se3[off]):.4f} m: distant filter {verdict}")
print(f"street distant drop rate: {dropped}/{cand} = {dropped / cand:.3f}")
PY
