#!/usr/bin/env bash
# Map reuse acceptance on 7-Scenes seq-a (docs/maps.md): session 1 builds a map from frames
# 0-299 and saves it; session 2, a second process, loads it and runs frames 300-599 with
# --localize-only. Both with sensor depth and with FastDepth. Prints one table row per depth:
# frames localised, ATE se3 of session 2 alone, ATE se3 of sessions 1+2 under ONE alignment
# (session 2 is in session 1's frame), whether the map file is unchanged, whether a repeat of
# session 2 gives a byte-identical trajectory, map size and save/load times.
# Usage: tools/map_reuse.sh [ADEMONO_BINARY] [WORK_DIR]   (FIRST=0:300 SECOND=300:600 to change)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="${1:-$here/build/release/bin/ademono}"
work="${2:-/tmp/ademono_map_reuse}"
first="${FIRST:-0:300}"
second="${SECOND:-300:600}"
data="7scenes:$here/../shared/data/7scenes-seq-a"
fastdepth="model:$here/../shared/models/fastdepth_nyu_320.onnx,spec=$here/configs/models/fastdepth_nyu.yaml"
mkdir -p "$work"

printf "%-9s %-10s %-12s %-14s %-10s %-10s %-10s %-12s\n" depth localised "ATE se3 s2" "ATE se3 s1+s2" \
  unchanged repeatable "map MB" keyframes
for kind in sensor fastdepth; do
  depth=sensor
  [ "$kind" = fastdepth ] && depth="$fastdepth"
  d="$work/$kind"
  rm -rf "$d" && mkdir -p "$d"
  "$bin" run --overwrite --dataset "$data" --depth "$depth" --frames "$first" --save-map "$d/map.bin" \
    --out "$d/s1" >"$d/s1.log" 2>&1
  before="$(sha256sum <"$d/map.bin")"
  for rep in a b; do
    "$bin" run --overwrite --dataset "$data" --depth "$depth" --frames "$second" --load-map "$d/map.bin" \
      --localize-only --out "$d/s2$rep" >"$d/s2$rep.log" 2>&1
  done
  after="$(sha256sum <"$d/map.bin")"
  unchanged=no; [ "$before" = "$after" ] && unchanged=yes
  repeatable=no; cmp -s "$d/s2a/trajectory.tum" "$d/s2b/trajectory.tum" && repeatable=yes
  cat "$d/s1/trajectory.tum" "$d/s2a/trajectory.tum" | grep -v '^#' >"$d/both.tum"
  cat "$d/s1/groundtruth.tum" "$d/s2a/groundtruth.tum" | grep -v '^#' >"$d/both_gt.tum"
  "$bin" eval --gt "$d/both_gt.tum" --est "$d/both.tum" --align se3 --json "$d/both.json" >/dev/null
  python3 - "$d" "$kind" "$unchanged" "$repeatable" <<'PY'
import json, os, sys
d, kind, unchanged, repeatable = sys.argv[1:]
s2 = json.load(open(f"{d}/s2a/summary.json"))
s1 = json.load(open(f"{d}/s1/summary.json"))
both = json.load(open(f"{d}/both.json"))
def find(j, key):
    if isinstance(j, dict):
        for k, v in j.items():
            if k == key: return v
            r = find(v, key)
            if r is not None: return r
    if isinstance(j, list):
        for v in j:
            r = find(v, key)
            if r is not None: return r
    return None
ate_both = find(both, "rmse")
print(f"{kind:<9} {s2['tracked']}/{s2['frames']:<6} {s2['accuracy']['ate_se3_rmse_m']:<12.4f} "
      f"{ate_both:<14.4f} {unchanged:<10} {repeatable:<10} "
      f"{os.path.getsize(d + '/map.bin') / 1e6:<10.2f} {s1['keyframes']:<12}")
PY
done
