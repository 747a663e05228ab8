#!/usr/bin/env bash
# Makes the README's screenshot of a real run report (docs/images/report.png): renders a 60-frame
# synthetic office sequence, runs ademono on it (simulated depth, ground-truth boxes, --viz), writes
# report.html and photographs it in headless Chromium (tools/report_browser.py).
#   tools/report_screenshot.sh [--out docs/images/report.png] [--work out/report-screenshot]
#                              [--run RUN_DIR]   # photograph an existing run folder instead
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"  # relative paths, so the page shows no machine-specific folders
out="docs/images/report.png" work="out/report-screenshot" run=""
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --run) run="$2"; shift 2 ;;
    *) echo "report_screenshot.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
bin="$here/build/release/bin/ademono"
[ -x "$bin" ] || { echo "report_screenshot.sh: build first (scripts/setup.sh)" >&2; exit 2; }
py=/usr/bin/python3  # Debian's, with python3-opencv
if [ -z "$run" ]; then
  rm -rf "$work" && mkdir -p "$work"
  "$bin" synth --scene office --motion xyz --persons 2 --frames 60 --seed 7 --out "$work/seq"
  "$bin" run --overwrite --dataset "tum:$work/seq" --depth simulated --detector "cache:$work/seq/detections.jsonl" \
    --viz "$work/run/viz" --out "$work/run"
  # Until `run` writes the unified run schema itself (no-op once it does).
  "$py" "$here/tests/report/legacy_run_to_schema.py" "$work/run" "$work/seq"
  run="$work/run"
fi
"$bin" report "$run"
full="$work/report-full.png"
mkdir -p "$work"
"$py" "$here/tools/report_browser.py" "$run/report.html" "$full" --crop-to-page
# The README shows the top of the page (summary, trajectory, error), scaled to stay small.
"$py" - "$full" "$out" <<'PY'
import sys, cv2
image = cv2.imread(sys.argv[1])
top = image[:min(1560, image.shape[0])]
scale = 900 / top.shape[1]
small = cv2.resize(top, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
cv2.imwrite(sys.argv[2], small, [cv2.IMWRITE_PNG_COMPRESSION, 9])
PY
echo "wrote $out ($(du -k "$out" | cut -f1) KB) and the full page $full"
