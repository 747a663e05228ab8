#!/usr/bin/env bash
# Acceptance of dynamic removal on synthetic office and street sequences with photo-textured
# actors (issue 17; docs/synth.md "Actor photos"): three seeds each, simulated network depth,
# YOLOX-nano as the detector, compared with ground-truth boxes and with no dynamic removal.
# Usage: tools/synthetic_dynamic_acceptance.sh [ADEMONO_BINARY] [WORK_DIR] [-- extra ablate args]
#   OFFICE_SEEDS (7 5 11; empty: none), STREET_SEEDS (1 2 3), OFFICE_FRAMES (300), STREET_FRAMES (150),
#   PHOTOS (../shared/images), MODEL (../shared/models/yolox_nano.onnx); SKIP_RUNS=1 only
#   prints the table from earlier results in WORK_DIR.
# Per sequence: `ademono synth --actor-photos`, `ademono recall` (YOLOX-nano's recall against the
# ground-truth boxes), then `ademono ablate` three times: YOLOX-nano (full, no_dynamic) and the
# ground-truth boxes (full). Prints one markdown table with the four criteria:
#   ATE(yolox) <= 1.5 ATE(gt boxes); ATE(yolox) <= 0.3 ATE(no removal);
#   >= 90 % of moving keypoints kept out of tracking and the map (not a pose inlier, and not the
#   source of a new map point that another view admitted; the share labelled by the filter or
#   excluded by the geometric test when matched, the earlier definition, beside it);
#   <= 10 % of static keypoints removed (labelled, excluded when matched, or their new point
#   judged moving before it was admitted).
# The ATE ratios are shown with se3 and sim3 alignment (with the sim3 scales). The simulated
# network's constant 5 % scale error reaches se3 only where nothing observes scale: on the
# street, configs/street.yaml anchors the scale to the camera's height above the road
# (depth.camera_height); sim3 shows what the movers did in any case. A second table gives YOLOX-nano's
# recall of the street's bus and lead car and the share of pose inliers on movers.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="${1:-$here/build/release/bin/ademono}"
work="${2:-/tmp/ademono_synthetic_dynamic}"
shift $(( $# < 2 ? $# : 2 ))
[ "${1:-}" = "--" ] && shift
extra=("$@")
photos="${PHOTOS:-$here/../shared/images}"
model="${MODEL:-$here/../shared/models/yolox_nano.onnx}"
office_seeds="${OFFICE_SEEDS-7 5 11}"
street_seeds="${STREET_SEEDS-1 2 3}"
mkdir -p "$work"

run_one() {  # scene seed
  local scene=$1 seed=$2 seq="$work/$1_s$2" frames config depth
  if [ "$scene" = office ]; then
    frames=${OFFICE_FRAMES:-300}
    config=()
    depth=simulated
    [ -d "$seq/rgb" ] || "$bin" synth --scene office --motion xyz --persons 3 --frames "$frames" \
      --seed "$seed" --actor-photos "$photos" --out "$seq" >/dev/null
  else
    frames=${STREET_FRAMES:-150}
    config=(--config "$here/configs/street.yaml")
    depth="simulated:gt=$seq/depth_full"
    [ -d "$seq/rgb" ] || "$bin" synth --scene street --frames "$frames" --seed "$seed" \
      --actor-photos "$photos" --out "$seq" >/dev/null
  fi
  "$bin" recall --sequence "$seq" --detector "model:$model" --json "$work/$scene"_s"$seed"_recall.json \
    > "$work/$scene"_s"$seed"_recall.md
  rm -rf "$work/$scene"_s"$seed"_yolox "$work/$scene"_s"$seed"_gt
  "$bin" ablate --dataset "tum:$seq" "${config[@]}" --depth "$depth" --detector "model:$model" \
    --variants full,no_dynamic --out "$work/$scene"_s"$seed"_yolox "${extra[@]}" >/dev/null
  "$bin" ablate --dataset "tum:$seq" "${config[@]}" --depth "$depth" \
    --detector "cache:$seq/detections.jsonl" --variants full --out "$work/$scene"_s"$seed"_gt \
    "${extra[@]}" >/dev/null
}

if [ "${SKIP_RUNS:-0}" != 1 ]; then
  for seed in $office_seeds; do run_one office "$seed"; done
  for seed in $street_seeds; do run_one street "$seed"; done
fi

/usr/bin/python3 - "$work" "$office_seeds" "$street_seeds" <<'PY'
import json, os, sys
work, office, street = sys.argv[1], sys.argv[2].split(), sys.argv[3].split()
def variants(path):
    try:
        return {v["variant"]: v for v in json.load(open(path))["variants"]}
    except OSError:
        return None
def pct(a, b):
    return (100.0 * a / b, "%.1f%% (%d/%d)" % (100.0 * a / b, a, b)) if b else (None, "-")
print("| scene | seed | YOLOX recall: persons / cars (photo movers) | ATE se3 yolox | ATE se3 gt boxes | ATE se3 no removal | yolox/gt <= 1.5 | yolox/none <= 0.3 | moving kept out of tracking and map >= 90% | moving labelled or excluded at match | of them unboxed | static removed <= 10% | tracked yolox / gt / none | ATE sim3 yolox / gt / none | sim3 yolox/gt, yolox/none | scale yolox / gt / none |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
ok_all = True
ok_sim3 = True
sim3_rows = []
for scene, seeds in (("office", office), ("street", street)):
    for seed in seeds:
        base = os.path.join(work, "%s_s%s" % (scene, seed))
        y, g = variants(base + "_yolox/ablation.json"), variants(base + "_gt/ablation.json")
        if not y or not g:
            print("| %s | %s | missing results | | | | | | | | | | | | | |" % (scene, seed)); ok_all = False; ok_sim3 = False; continue
        rec = json.load(open(base + "_recall.json"))
        def group_recall(cls):
            t = sum(x["truth_boxes"] for x in rec.get("groups", []) if x["class"] == cls and "photo" in x["label"])
            f = sum(x["found"] for x in rec.get("groups", []) if x["class"] == cls and "photo" in x["label"])
            return "%.2f" % (f / t) if t else "-"
        full, nodyn, gt = y["full"], y["no_dynamic"], g["full"]
        a, an, ag = full["ate_se3_rmse_m"], nodyn["ate_se3_rmse_m"], gt["ate_se3_rmse_m"]
        t = full["truth"] or {}
        r1 = a / ag if a is not None and ag else None
        r2 = a / an if a is not None and an else None
        # Moving: kept out of the pose and the map (a pose inlier, or a new keyframe point that
        # another view admitted, entered); the old figure (labelled by the filter or excluded by
        # the geometric test when matched) beside it. Static: removed by either, plus new points
        # the geometric test judged moving before they were ever admitted.
        mv, mvs = pct(t.get("moving_kept_out", 0), t.get("moving_keypoints", 0))
        _, mls = pct(t.get("moving_removed", 0), t.get("moving_keypoints", 0))
        _, ubs = pct(t.get("moving_unboxed_removed", 0), t.get("moving_unboxed_keypoints", 0))
        st, sts = pct(t.get("static_kept_out", 0), t.get("static_keypoints", 0))
        c1 = r1 is not None and r1 <= 1.5
        c2 = r2 is not None and r2 <= 0.3
        c3 = mv is not None and mv >= 90.0
        c4 = st is not None and st <= 10.0
        ok_all = ok_all and c1 and c2 and c3 and c4
        f = lambda v: "%.4f" % v if v is not None else "-"
        yes = lambda c, v: ("%.2f " % v if v is not None else "") + ("yes" if c else "**no**")
        s3, s3g, s3n = full["ate_sim3_rmse_m"], gt["ate_sim3_rmse_m"], nodyn["ate_sim3_rmse_m"]
        q1 = s3 / s3g if s3 is not None and s3g else None
        q2 = s3 / s3n if s3 is not None and s3n else None
        ok_sim3 = ok_sim3 and q1 is not None and q1 <= 1.5 and q2 is not None and q2 <= 0.3
        sc = lambda v: "%.3f" % v["sim3_scale"] if v.get("sim3_scale") is not None else "-"
        print("| %s | %s | %s / %s | %s | %s | %s | %s | %s | %s %s | %s | %s | %s %s | %d / %d / %d of %d | %s / %s / %s | %s, %s | %s / %s / %s |" % (
            scene, seed, group_recall("person"), group_recall("car"), f(a), f(ag), f(an),
            yes(c1, r1), yes(c2, r2), mvs, "yes" if c3 else "**no**", mls, ubs, sts,
            "yes" if c4 else "**no**", full["tracked"], gt["tracked"], nodyn["tracked"],
            full["frames"], f(full["ate_sim3_rmse_m"]), f(gt["ate_sim3_rmse_m"]),
            f(nodyn["ate_sim3_rmse_m"]), yes(q1 is not None and q1 <= 1.5, q1),
            yes(q2 is not None and q2 <= 0.3, q2), sc(full), sc(gt), sc(nodyn)))
        # The movers that matter (street): YOLOX's recall per object, and how much of the pose
        # the movers are without removal (share of pose inliers on moving keypoints).
        groups = {x["label"].split(" ")[0]: x for x in rec.get("groups", [])}
        def inlier_share(truth, counts):  # pose inliers on moving keypoints, of all pose inliers
            mi = (truth or {}).get("moving_kept_by_state", {}).get("pose_inlier", 0)
            si = (truth or {}).get("static_kept_by_state", {}).get("pose_inlier", 0)
            if not mi + si:
                return "-"
            return "%.1f%%" % (100.0 * mi / (mi + si)) + (" (%d/%d)" % (mi, mi + si) if counts else "")
        obj = lambda n: "%d/%d" % (groups[n]["found"], groups[n]["truth_boxes"]) if n in groups else "-"
        sim3_rows.append("| %s | %s | %s | %s | %s | %s |" % (
            scene, seed, obj("bus-crossing"), obj("car-lead"), inlier_share(nodyn["truth"], True),
            inlier_share(t, False)))
print()
print("all criteria met" if ok_all else "NOT all criteria met")
print("sim3 ratios met (yolox/gt <= 1.5, yolox/none <= 0.3)" if ok_sim3 else "sim3 ratios NOT all met")
# The simulated network's depth has a constant scale error (configs: ~5 %), the same in every
# variant: on the street's 100+ m it dominates the se3 ATE, which then compares three copies of
# the same bias; sim3 takes the scale out and shows what the movers did to the trajectory.
print()
print("| scene | seed | YOLOX recall: bus crossing | lead car | pose inliers on movers, no removal | ... with YOLOX |")
print("|---|---|---|---|---|---|")
for row in sim3_rows:
    print(row)
# Why: what removed the static keypoints, what the moving keypoints that were not removed are,
# and how many moving keypoints the pose used (with YOLOX-nano, and with no dynamic removal).
print()
print("| scene | seed | static removed by: small box / stage 1 / stage 2 / box vote / geometry judged moving / geometry unconfirmed / new point judged moving | static new points never confirmed (not removed) | static removed within 2 px of a mover | moving entered: pose inliers + new points admitted (of new points) | moving not labelled: never matched / pose inlier / pose outlier | ... of them outside every YOLOX box / at the mover's outline | moving keypoints in the pose: yolox / no removal | pose inliers on static keypoints: yolox / no removal |")
print("|---|---|---|---|---|---|---|---|---|---|")
for scene, seeds in (("office", office), ("street", street)):
    for seed in seeds:
        base = os.path.join(work, "%s_s%s" % (scene, seed))
        y = variants(base + "_yolox/ablation.json")
        if not y or "static_removed_by" not in (y["full"]["truth"] or {}):
            continue
        t, tn = y["full"]["truth"], y["no_dynamic"]["truth"]
        by, ms, ns = t["static_removed_by"], t["moving_kept_by_state"], tn["moving_kept_by_state"]
        print("| %s | %s | %d / %d / %d / %d / %d / %d / %d | %d of %d | %d | %d + %d (of %d) | %d / %d / %d | %d / %d | %d / %d | %d / %d |" % (
            scene, seed, by["small_box"], by["stage1"], by["stage2"], by["box_vote"],
            by["geometric_judged_moving"], by["geometric_unconfirmed"],
            t.get("static_new_points_judged_out", 0), t.get("static_new_points_unconfirmed", 0),
            t.get("static_new_points", 0), t["static_at_mover_edge_removed"],
            t.get("moving_pose_inliers", 0), t.get("moving_new_points_admitted", 0),
            t.get("moving_new_points", 0), ms["unmatched"], ms["pose_inlier"],
            ms["pose_outlier"], t["moving_not_removed_unboxed"], t["moving_not_removed_at_edge"],
            ms["pose_inlier"], ns["pose_inlier"], t["static_kept_by_state"]["pose_inlier"],
            tn["static_kept_by_state"]["pose_inlier"]))
PY
