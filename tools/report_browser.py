#!/usr/bin/env python3
"""Opens an ademono report.html in headless Chromium (Debian's `chromium`), takes a screenshot and
returns every console message, uncaught exception and browser log entry, plus the page's own
record of where it drew each plot.

    tools/report_browser.py REPORT.html SHOT.png [--width 1280] [--height 4400] [--crop-to-page]

One browser launch per page, driven over the DevTools protocol on a pipe
(--remote-debugging-pipe: JSON messages ending in a NUL byte, Chromium reads fd 3 and writes
fd 4), so no port and no extra package. WebGL runs on SwiftShader (software), no GPU needed.
Used by the report's browser test (tests/report/browser_test.py) and tools/report_screenshot.sh.
"""
import argparse
import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

FLAGS = [
    "--headless", "--no-sandbox", "--hide-scrollbars", "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader", "--no-first-run", "--disable-extensions",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-quic", "--remote-debugging-pipe",
]


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    raise FileNotFoundError("no chromium on PATH (apt-get install chromium)")


class Browser:
    def __init__(self, extra_flags=()):
        self.profile = tempfile.TemporaryDirectory()
        to_chrome_r, self.to_chrome = os.pipe()
        self.from_chrome, from_chrome_w = os.pipe()

        def wire():  # in the child: its fd 3 reads our commands, fd 4 writes its answers
            os.dup2(to_chrome_r, 3)
            os.dup2(from_chrome_w, 4)

        self.proc = subprocess.Popen(
            [chromium()] + FLAGS + list(extra_flags) +
            ["--user-data-dir=" + self.profile.name, "about:blank"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            preexec_fn=wire, pass_fds=(3, 4))  # the numbers after wire()
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self.buffer = b""
        self.next_id = 0
        self.events = []

    def _read_message(self, deadline):
        while b"\0" not in self.buffer:
            if time.monotonic() > deadline:
                raise TimeoutError("chromium did not answer in time")
            chunk = os.read(self.from_chrome, 1 << 20)
            if not chunk:
                raise RuntimeError("chromium closed the DevTools pipe (exit %s)" % self.proc.poll())
            self.buffer += chunk
        message, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method, params=None, session=None, timeout=60):
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self.to_chrome, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            answer = self._read_message(deadline)
            if answer.get("id") == self.next_id:
                if "error" in answer:
                    raise RuntimeError("%s: %s" % (method, answer["error"]))
                return answer.get("result", {})
            self.events.append(answer)

    def close(self):
        try:
            self.call("Browser.close", timeout=10)
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self.to_chrome)
        os.close(self.from_chrome)
        self.profile.cleanup()


def _messages(events):
    """Console calls, uncaught exceptions and browser log entries, as one line each."""
    out = []
    for e in events:
        method, p = e.get("method"), e.get("params", {})
        if method == "Runtime.consoleAPICalled":
            text = " ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", []))
            out.append("console.%s: %s" % (p.get("type"), text))
        elif method == "Runtime.exceptionThrown":
            d = p.get("exceptionDetails", {})
            out.append("exception: %s" % d.get("exception", {}).get("description", d.get("text")))
        elif method == "Log.entryAdded":
            entry = p.get("entry", {})
            out.append("log.%s: %s" % (entry.get("level"), entry.get("text")))
    return out


def open_report(html, png, width=1280, height=4400, timeout=60):
    """Returns {"console": [lines], "ready": str, "errors": str|None, "layout": {id: [x, y, w, h]}}."""
    return open_url("file://" + os.path.abspath(html), png, width, height, timeout)


def open_url(url, png, width=1280, height=4400, timeout=60, extra_flags=(), on_poll=None):
    """open_report for any URL (the live page: http://HOST:PORT/). on_poll(state), if given, sees
    the page's body.dataset at every poll."""
    browser = Browser(extra_flags)
    try:
        target = browser.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = browser.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for method in ("Runtime.enable", "Page.enable", "Log.enable"):
            browser.call(method, session=session)
        browser.call("Emulation.setDeviceMetricsOverride",
                     {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
                     session=session)
        browser.call("Page.navigate", {"url": url}, session=session)
        state = {}
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            state = browser.call("Runtime.evaluate", {
                "expression": "JSON.stringify(document.body ? Object.assign({}, document.body.dataset) : {})",
                "returnByValue": True}, session=session)["result"].get("value", "{}")
            state = json.loads(state)
            if on_poll:
                on_poll(state)
            if state.get("ready") or state.get("errors"):
                break
            time.sleep(0.2)
        shot = browser.call("Page.captureScreenshot", {"format": "png"}, session=session)
        with open(png, "wb") as f:
            f.write(base64.b64decode(shot["data"]))
        return {"console": _messages(browser.events), "ready": state.get("ready"),
                "errors": state.get("errors"), "layout": json.loads(state.get("layout", "{}"))}
    finally:
        browser.close()


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
    if a.crop_to_page and "page" in result["layout"]:
        import cv2  # python3-opencv
        image = cv2.imread(a.png)
        cv2.imwrite(a.png, image[:min(result["layout"]["page"][3], image.shape[0])])
    print(json.dumps({k: v for k, v in result.items() if k != "layout"}, indent=1))
    return 0 if result["ready"] == "1" and not result["console"] else 1


if __name__ == "__main__":
    sys.exit(main())
