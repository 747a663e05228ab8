#!/usr/bin/env python3
"""Opens an ademono report.html in headless Chromium (Debian's `chromium`), takes a screenshot and
returns what the page logged to the console and the page's own record of where it drew.

    tools/report_browser.py REPORT.html SHOT.png [--width 1280] [--height 4400] [--crop-to-page]

Used by the report's browser test (tests/report/browser_test.py) and by
tools/report_screenshot.sh. WebGL runs on SwiftShader (software), so no GPU is needed.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

FLAGS = [
    "--headless", "--no-sandbox", "--hide-scrollbars", "--force-device-scale-factor=1",
    "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--enable-logging=stderr", "--v=0",
    "--no-first-run", "--disable-extensions", "--disable-background-networking",
    # Lets the page run its scripts to the end before the screenshot / DOM dump.
    "--virtual-time-budget=10000",
]
CONSOLE = re.compile(r":INFO:CONSOLE[^\]]*\] (.*)$")


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    raise FileNotFoundError("no chromium on PATH (apt-get install chromium)")


def _run(args, timeout):
    with tempfile.TemporaryDirectory() as profile:
        proc = subprocess.run([chromium()] + FLAGS + ["--user-data-dir=" + profile] + args,
                              capture_output=True, text=True, timeout=timeout)
    console = [m.group(1) for m in map(CONSOLE.search, proc.stderr.splitlines()) if m]
    return proc, console


def open_report(html, png, width=1280, height=4400, timeout=120):
    """Returns {"console": [...], "ready": str, "errors": str|None, "layout": {id: [x, y, w, h]}}."""
    url = "file://" + os.path.abspath(html)
    size = "--window-size=%d,%d" % (width, height)
    proc, console = _run([size, "--screenshot=" + os.path.abspath(png), url], timeout)
    if proc.returncode != 0 or not os.path.exists(png):
        raise RuntimeError("chromium screenshot failed (%d): %s" % (proc.returncode, proc.stderr[-2000:]))
    proc, console_dom = _run([size, "--dump-dom", url], timeout)
    body = re.search(r"<body([^>]*)>", proc.stdout)
    attrs = dict(re.findall(r'(data-[a-z]+)="([^"]*)"', body.group(1))) if body else {}
    layout = json.loads(attrs.get("data-layout", "{}").replace("&quot;", '"'))
    return {"console": console + console_dom, "ready": attrs.get("data-ready"),
            "errors": attrs.get("data-errors"), "layout": layout}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("html")
    p.add_argument("png")
    p.add_argument("--width", type=int, default=1280)
    p.add_argument("--height", type=int, default=4400)
    p.add_argument("--crop-to-page", action="store_true",
                   help="cut the screenshot at the bottom of the page")
    a = p.parse_args()
    result = open_report(a.html, a.png, a.width, a.height)
    if a.crop_to_page and result["layout"]:
        import cv2  # python3-opencv
        image = cv2.imread(a.png)
        bottom = result["layout"]["page"][3]
        cv2.imwrite(a.png, image[:min(bottom, image.shape[0])])
    print(json.dumps({k: v for k, v in result.items() if k != "layout"}, indent=1))
    return 0 if result["ready"] == "1" and not result["console"] else 1


if __name__ == "__main__":
    sys.exit(main())
