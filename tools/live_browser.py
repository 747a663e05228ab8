#!/usr/bin/env python3
"""Runs `ademono run --live` and opens its live page in headless Chromium during the run; waits
until the run has finished and the page has drawn its final state, takes a screenshot.

    tools/live_browser.py SHOT.png [--dataset KIND:PATH] [--frames A:B] [--depth sensor]
                          [--port N] [--width 1280] [--height 1300] [--crop HEIGHT]

Prints the page's console lines, its states seen while polling and the run's summary.json "live"
block as JSON. Used by tests/live/live_browser_test.py and for the README's picture (with the
whole of seq-a). Chromium through tools/report_browser.py (DevTools over a pipe, SwiftShader
WebGL).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import report_browser  # noqa: E402

CLI = os.environ.get("ADEMONO_CLI", os.path.join(ROOT, "build", "release", "bin", "ademono"))
SHARED = os.environ.get("ADEMONO_SHARED_DIR", os.path.join(os.path.dirname(ROOT), "shared"))
# No GPU process, on top of report_browser's flags (which have the fresh profile). WebGL then
# composites in software: Chromium warns once per page that reading the canvas back stalls,
# a performance note of its GL driver and nothing the page did (see significant()).
EXTRA_FLAGS = ["--disable-gpu"]
GL_PERFORMANCE_NOTE = "GL Driver Message (OpenGL, Performance"


def significant(console):
    """The console lines that matter: everything but the software-compositing performance note."""
    return [line for line in console
            if not (line.startswith("log.warning: ") and GL_PERFORMANCE_NOTE in line)]


def run_and_capture(png, dataset=None, frames="0:200", depth="sensor", port=0, width=1280,
                    height=1300, out=None, timeout=240):
    dataset = dataset or "7scenes:" + os.path.join(SHARED, "data", "7scenes-seq-a")
    tmp = None
    if out is None:
        tmp = tempfile.mkdtemp(prefix="ademono-live-page-")
        out = os.path.join(tmp, "run")
    cmd = [CLI, "run", "--dataset", dataset, "--depth", depth, "--frames", frames, "--out", out,
           "--live", "127.0.0.1:%d" % port, "--live-wait-clients", "1", "--live-linger", "60"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    stderr_lines = []
    url_found = threading.Event()
    url = {}

    def read_stderr():
        for line in proc.stderr:
            stderr_lines.append(line)
            m = re.search(r"live view at (http://\S+/)", line)
            if m and not url_found.is_set():
                url["value"] = m.group(1)
                url_found.set()

    reader = threading.Thread(target=read_stderr, daemon=True)
    reader.start()
    try:
        if not url_found.wait(60):
            raise RuntimeError("the run did not start serving: " + "".join(stderr_lines))
        states = []

        def on_poll(state):
            summary = (state.get("state"), state.get("frames"))
            if not states or states[-1] != summary:
                states.append(summary)

        result = report_browser.open_url(url["value"], png, width, height, timeout,
                                         extra_flags=EXTRA_FLAGS, on_poll=on_poll)
        # Closing the browser closed the page's connection: the run's linger ends.
        code = proc.wait(timeout=60)
        stdout = proc.stdout.read()
        reader.join(5)
        summary = {}
        if os.path.exists(os.path.join(out, "summary.json")):
            with open(os.path.join(out, "summary.json")) as f:
                summary = json.load(f)
        result.update({"states": states, "exit_code": code, "stdout": stdout,
                       "stderr": "".join(stderr_lines), "summary": summary, "url": url["value"]})
        return result
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        if tmp:
            shutil.rmtree(tmp, ignore_errors=True)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("png")
    p.add_argument("--dataset")
    p.add_argument("--frames", default="0:200")
    p.add_argument("--depth", default="sensor")
    p.add_argument("--port", type=int, default=0)
    p.add_argument("--width", type=int, default=1280)
    p.add_argument("--height", type=int, default=1300)
    p.add_argument("--crop", type=int, help="keep only the top HEIGHT pixels of the screenshot")
    a = p.parse_args()
    r = run_and_capture(a.png, a.dataset, a.frames, a.depth, a.port, a.width, a.height)
    if a.crop:
        import cv2  # python3-opencv
        image = cv2.imread(a.png)
        cv2.imwrite(a.png, image[:a.crop], [cv2.IMWRITE_PNG_COMPRESSION, 9])
    print(json.dumps({"console": r["console"], "ready": r["ready"], "errors": r["errors"],
                      "states": r["states"], "exit_code": r["exit_code"],
                      "live": r["summary"].get("live")}, indent=1))
    return 0 if r["ready"] == "1" and not significant(r["console"]) and r["exit_code"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
