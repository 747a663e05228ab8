"""The run report in a real browser: a short real run (60-frame synthetic office, simulated depth,
ground-truth boxes, --viz), `ademono report`, headless Chromium. Checks that the page logs nothing
to the console, finishes drawing, and that each plot and the WebGL map view put their colours
where the page says it drew them.

Needs ADEMONO_CLI (CTest sets it) and Debian's chromium and python3-opencv.
"""
import json
import os
import shutil
import subprocess
import sys

import cv2
import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import report_browser  # noqa: E402

CLI = os.environ.get("ADEMONO_CLI", os.path.join(ROOT, "build", "release", "bin", "ademono"))


def run(*args):
    proc = subprocess.run([CLI] + list(args), capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    seq, out = str(tmp / "seq"), str(tmp / "run")
    run("synth", "--scene", "office", "--motion", "xyz", "--persons", "2", "--frames", "60",
        "--seed", "7", "--out", seq)
    run("run", "--dataset", "tum:" + seq, "--depth", "simulated", "--detector",
        "cache:" + seq + "/detections.jsonl", "--viz", out + "/viz", "--out", out)
    # Until `run` writes the unified schema itself: derive it from the files (no-op after).
    subprocess.run([sys.executable, os.path.join(HERE, "legacy_run_to_schema.py"), out, seq],
                   check=True)
    return out


def color_pixels(image, rect, hex_color, tol=40):
    x, y, w, h = rect
    region = image[y:y + h, x:x + w].astype(int)
    rgb = [int(hex_color[i:i + 2], 16) for i in (1, 3, 5)]
    bgr = np.array(rgb[::-1])
    return int((np.abs(region - bgr).max(axis=2) <= tol).sum())


def open_in_browser(html, png):
    result = report_browser.open_report(html, png)
    assert result["console"] == [], "console output: %s" % result["console"]
    assert result["errors"] is None
    assert result["ready"] == "1"
    image = cv2.imread(png)
    assert image is not None
    return result["layout"], image


def test_run_report_draws_every_panel(run_dir):
    out = run("report", run_dir)
    html = os.path.join(run_dir, "report.html")
    assert "report.html" in out and os.path.getsize(html) > 100_000
    layout, image = open_in_browser(html, os.path.join(run_dir, "shot.png"))
    for key in ("plot-top", "plot-axes", "plot-error", "plot-timeline", "plot-filter", "map3d"):
        assert key in layout, key
        _, y, w, h = layout[key]
        assert w > 200 and h > 100 and y + h <= image.shape[0], (key, layout[key])
    # Estimate (orange) and ground truth (dark grey) in the top view and the per-axis plots.
    assert color_pixels(image, layout["plot-top"], "#e8590c") > 300
    assert color_pixels(image, layout["plot-top"], "#343a40", tol=25) > 300
    assert color_pixels(image, layout["plot-axes"], "#e8590c") > 600
    # Error line, inliers/kept lines, stacked filter areas (kept green, enhancement yellow).
    assert color_pixels(image, layout["plot-error"], "#c92a2a") > 200
    assert color_pixels(image, layout["plot-timeline"], "#37b24d") > 200
    assert color_pixels(image, layout["plot-filter"], "#37b24d", tol=20) > 20_000
    assert color_pixels(image, layout["plot-filter"], "#fab005", tol=20) > 2_000
    with open(os.path.join(run_dir, "summary.json")) as f:
        summary = json.load(f)
    # The dataset has depth images: the map's scale against them, one point per keyframe.
    assert "map_scale" in summary
    assert "plot-map-scale" in layout
    assert color_pixels(image, layout["plot-map-scale"], "#0b7285") > 100
    if "ms" in summary["per_frame"][0]:
        assert "plot-timing" in layout
        assert color_pixels(image, layout["plot-timing"], "#ff922b", tol=20) > 2_000
    # The WebGL view: dark background, and map points / path drawn on it.
    x, y, w, h = layout["map3d"]
    canvas = image[y + 2:y + h - 2, x + 2:x + w - 2].astype(int)
    background = np.abs(canvas - np.array([0x22, 0x1a, 0x16])).max(axis=2) <= 6
    assert background.mean() > 0.8
    assert (~background).sum() > 300
    assert color_pixels(image, layout["map3d"], "#4dabf7", tol=30) > 20  # keyframes


def test_timing_and_depth_scale_panels_draw(run_dir, tmp_path):
    # The panels for per-frame stage times and the depth scale factor, on a copy of the real run
    # with those fields filled in (test values: tracking dominates, scale drifts 1.00 -> 1.06).
    copy = str(tmp_path / "run")
    shutil.copytree(run_dir, copy)
    with open(os.path.join(copy, "summary.json")) as f:
        summary = json.load(f)
    for i, frame in enumerate(summary["per_frame"]):
        frame["ms"] = {"extraction": 8.0, "depth": 5.0, "detection": 3.0, "filter": 1.0,
                       "tracking": 12.0 + i % 4, "mapping": 30.0 if frame["keyframe"] else 0.5}
        frame["depth_scale"] = 1.0 + 0.001 * i
    with open(os.path.join(copy, "summary.json"), "w") as f:
        json.dump(summary, f)
    run("report", copy)
    layout, image = open_in_browser(os.path.join(copy, "report.html"), str(tmp_path / "shot.png"))
    assert color_pixels(image, layout["plot-timing"], "#ff922b", tol=20) > 2_000  # tracking band
    assert color_pixels(image, layout["plot-timing"], "#69db7c", tol=20) > 500    # mapping band
    assert color_pixels(image, layout["plot-scale"], "#5f3dc4") > 200


def test_comparison_report(run_dir, tmp_path):
    a, b = str(tmp_path / "full"), str(tmp_path / "again")
    shutil.copytree(run_dir, a)
    shutil.copytree(run_dir, b)
    html = str(tmp_path / "compare.html")
    run("report", a, b, "--name", "full", "--name", "again", "--out", html)
    layout, image = open_in_browser(html, str(tmp_path / "compare.png"))
    # Both variants overlaid in the top view (the second, blue, over the first).
    assert color_pixels(image, layout["plot-top"], "#1971c2") > 300
    assert color_pixels(image, layout["plot-error"], "#1971c2") > 200
    assert color_pixels(image, layout["plot-filter"], "#1971c2") > 200


def test_the_browser_check_sees_script_errors(run_dir, tmp_path):
    # The same report with its data cut short: the page must not pass as drawn.
    run("report", run_dir)
    with open(os.path.join(run_dir, "report.html")) as f:
        html = f.read()
    start = html.index('<script id="report-data"')
    broken = html[:start + 200] + html[html.index("</script>", start):]
    path = str(tmp_path / "broken.html")
    with open(path, "w") as f:
        f.write(broken)
    result = report_browser.open_report(path, str(tmp_path / "broken.png"), timeout=20)
    assert result["ready"] != "1"
    assert result["errors"] == "1"
    assert any(line.startswith("console.error") for line in result["console"]), result["console"]


def test_bad_run_folder_is_one_line_exit_2(tmp_path):
    os.makedirs(tmp_path / "empty")
    proc = subprocess.run([CLI, "report", str(tmp_path / "empty")], capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "summary.json" in proc.stderr
    assert not os.path.exists(tmp_path / "empty" / "report.html")
