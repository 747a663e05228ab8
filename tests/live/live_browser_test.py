"""The live page in headless Chromium during a real run: `ademono run --live` on 200 frames of
seq-a (sensor depth) waits for the page, which connects over the Foxglove WebSocket protocol and
draws while the run goes on. Checks that the page saw the run running, then finished, logged
nothing to the console, and that the 3D view (map points, path) and the plots are drawn where
the page says they are.

Needs ADEMONO_CLI (CTest sets it), ../shared, Debian's chromium and python3-opencv.
"""
import os
import sys

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import live_browser  # noqa: E402


def color_pixels(image, rect, hex_color, tol=40):
    x, y, w, h = rect
    region = image[y:y + h, x:x + w].astype(int)
    rgb = [int(hex_color[i:i + 2], 16) for i in (1, 3, 5)]
    return int((np.abs(region - np.array(rgb[::-1])).max(axis=2) <= tol).sum())


def test_live_page_draws_the_run(tmp_path):
    png = str(tmp_path / "live.png")
    port = int(os.environ.get("ADEMONO_LIVE_PORT", "0"))
    r = live_browser.run_and_capture(png, port=port, out=str(tmp_path / "run"))
    assert r["exit_code"] == 0, r["stderr"]
    assert live_browser.significant(r["console"]) == [], "console output: %s" % r["console"]
    assert not any("error" in line.split(":")[0] for line in r["console"]), r["console"]
    assert r["errors"] is None
    assert r["ready"] == "1", r["states"]
    # Open during the run: it saw frames arrive before the run finished.
    assert any(s == "running" and int(n or 0) > 0 for s, n in r["states"]), r["states"]
    assert r["states"][-1][0] == "finished"
    assert r["summary"]["live"]["clients"] == 1
    layout = r["layout"]
    image = cv2.imread(png)
    assert image is not None
    for key in ("view3d", "camera", "plot-points", "plot-ms"):
        _, y, w, h = layout[key]
        assert w > 200 and h > 100 and y + h <= image.shape[0], (key, layout[key])
    # The WebGL view: dark background with map points (green: static) and the orange path.
    x, y, w, h = layout["view3d"]
    canvas = image[y + 2:y + h - 2, x + 2:x + w - 2].astype(int)
    background = np.abs(canvas - np.array([0x22, 0x1a, 0x16])).max(axis=2) <= 6
    assert 0.3 < background.mean() < 0.995, background.mean()
    assert color_pixels(image, layout["view3d"], "#00dc28", tol=60) > 300  # static map points
    assert color_pixels(image, layout["view3d"], "#e8590d", tol=40) > 50    # the camera path
    # Plots: kept and inliers lines, tracking time.
    assert color_pixels(image, layout["plot-points"], "#37b24d") > 200
    assert color_pixels(image, layout["plot-points"], "#1971c2") > 200
    assert color_pixels(image, layout["plot-ms"], "#ff922b") > 100
