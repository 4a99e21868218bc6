"""The report and the HTML animation in a real browser (headless Chromium, driven through its DevTools protocol
over a pipe: no extra Python package): the report renders with its diagram, the animation plays (its picture
and its frame counter change with time), and neither page sends a request anywhere but its own file.

Skipped only where no Chromium is installed (`.ci/run` installs Debian's `chromium` where apt-get exists);
the skip says why."""

from __future__ import annotations

import base64
import io
import json
import os
import select
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

import mbplanar

ROOT = Path(__file__).resolve().parents[1]
BROWSER = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
WHY = os.environ.get("MBPLANAR_BROWSER_NOTE", "")

pytestmark = pytest.mark.skipif(
    BROWSER is None,
    reason="no Chromium on PATH, so the report and animation were not opened in a browser"
           + (f" ({WHY})" if WHY else "") + ": apt-get install chromium to run these tests")


class DevTools:
    """A headless Chromium and a minimal client of its DevTools protocol (JSON messages ending in NUL on the
    pipe given by --remote-debugging-pipe: the browser reads fd 3 and writes fd 4)."""

    def __init__(self, home: Path, size=(1100, 1400)):
        to_browser, self._out = os.pipe()
        self._in, from_browser = os.pipe()
        high = [os.dup(fd) for fd in (to_browser, from_browser)]   # out of the way of 3 and 4 in the child

        def wire():
            os.dup2(high[0], 3)
            os.dup2(high[1], 4)

        args = [BROWSER, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--mute-audio",
                "--no-first-run", "--no-default-browser-check", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--disable-default-apps",
                "--disable-extensions", f"--user-data-dir={home / 'profile'}", f"--window-size={size[0]},{size[1]}",
                "--remote-debugging-pipe", "about:blank"]
        self.proc = subprocess.Popen(args, pass_fds=(3, 4), preexec_fn=wire, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL, env=dict(os.environ, HOME=str(home)))
        for fd in (to_browser, from_browser, *high):
            os.close(fd)
        self._next, self._buffer, self.events = 0, b"", []
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]

    def _read(self, timeout: float):
        end = time.monotonic() + timeout
        while b"\0" not in self._buffer:
            left = end - time.monotonic()
            if left <= 0 or not select.select([self._in], [], [], left)[0]:
                raise TimeoutError("Chromium did not answer")
            chunk = os.read(self._in, 1 << 20)
            if not chunk:
                raise RuntimeError("Chromium closed its DevTools pipe")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method: str, params=None, session=True, timeout: float = 60.0):
        self._next += 1
        message = {"id": self._next, "method": method, "params": params or {}}
        if session and hasattr(self, "session"):
            message["sessionId"] = self.session
        os.write(self._out, json.dumps(message).encode() + b"\0")
        while True:
            reply = self._read(timeout)
            if reply.get("id") == self._next:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, method: str, timeout: float = 60.0):
        end = time.monotonic() + timeout
        while True:
            for k, event in enumerate(self.events):
                if event.get("method") == method:
                    return self.events.pop(k)
            self.events.append(self._read(max(end - time.monotonic(), 0.01)))

    def open(self, url: str):
        self.call("Network.enable")
        self.call("Page.enable")
        self.call("Page.navigate", {"url": url})
        self.wait_for("Page.loadEventFired")

    def requests(self) -> list[str]:
        """Every URL the page asked for so far (navigation, images, scripts, fetches ...)."""
        while True:                       # drain what has arrived
            if not select.select([self._in], [], [], 0.2)[0] and b"\0" not in self._buffer:
                break
            self.events.append(self._read(5.0))
        return [e["params"]["request"]["url"] for e in self.events if e.get("method") == "Network.requestWillBeSent"]

    def evaluate(self, expression: str):
        result = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True})
        return result["result"].get("value")

    def screenshot(self, clip=None) -> np.ndarray:
        """The page (or the `clip` {x, y, width, height} of it) as a grey image (H, W), 0 … 255."""
        from PIL import Image
        params = {"format": "png"}
        if clip:
            params["clip"] = dict(clip, scale=1)
            params["captureBeyondViewport"] = True
        data = base64.b64decode(self.call("Page.captureScreenshot", params)["data"])
        with Image.open(io.BytesIO(data)) as im:
            return np.asarray(im.convert("L"), float)

    def close(self):
        try:
            self.call("Browser.close", session=False, timeout=10)
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        for fd in (self._in, self._out):
            os.close(fd)


@pytest.fixture
def browser(tmp_path):
    pytest.importorskip("PIL", reason="reading the screenshots needs Pillow (the [plot] extra)")
    tools = DevTools(tmp_path)
    yield tools
    tools.close()


def offline(tools: DevTools, page: Path) -> list[str]:
    """The requests that left the page: every URL asked for other than the page itself and inline data."""
    urls = tools.requests()
    assert page.as_uri() in urls              # the recorder saw the navigation: it sees requests
    return [u for u in urls if u != page.as_uri() and not u.startswith(("data:", "about:"))]


def test_the_report_renders_with_its_diagram_offline(browser, tmp_path):
    pytest.importorskip("matplotlib", reason="the report's figures need matplotlib (the [plot] extra)")
    from mbplanar.viz import report_html
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "fourbar_loaded.toml"))
    page = tmp_path / "report.html"
    page.write_text(report_html(engine, positions=6, frames=8, dpi=50), encoding="utf-8")
    browser.open(page.as_uri())
    whole = browser.screenshot()
    assert whole.std() > 10 and (whole < 100).mean() > 0.002      # text and tables: not a blank page
    images = browser.evaluate("Array.from(document.images).map(i => [i.complete, i.naturalWidth])")
    assert images and all(done and width > 0 for done, width in images)   # every inline figure decoded
    box = browser.evaluate("(() => { const r = document.querySelector('#diagram img').getBoundingClientRect();"
                           " return {x: r.x + scrollX, y: r.y + scrollY, width: r.width, height: r.height}; })()")
    assert box["width"] > 200 and box["height"] > 150
    diagram = browser.screenshot(box)
    assert diagram.shape[0] > 100 and diagram.shape[1] > 150
    ink = diagram < 128
    assert 0.005 < ink.mean() < 0.5                       # the drawn mechanism: lines on white
    rows, cols = np.nonzero(ink)
    assert np.ptp(rows) > 0.4 * diagram.shape[0] and np.ptp(cols) > 0.4 * diagram.shape[1]   # spread out
    assert offline(browser, page) == []


def test_the_animation_plays_offline(browser, tmp_path):
    from mbplanar.viz import html_animation
    engine = mbplanar.Engine(mbplanar.read_model(ROOT / "models" / "six_bar_press.toml"))
    page = tmp_path / "animation.html"
    page.write_text(html_animation(engine, frames=36, fps=12), encoding="utf-8")
    browser.open(page.as_uri())
    state = "[document.querySelector('output').textContent, +document.querySelector('input[type=range]').value]"
    box = browser.evaluate("(() => { const r = document.querySelector('svg').getBoundingClientRect();"
                           " return {x: r.x, y: r.y, width: r.width, height: r.height}; })()")
    first_text, first_frame = browser.evaluate(state)
    first = browser.screenshot(box)
    assert first.std() > 5                                 # the mechanism is drawn
    time.sleep(1.0)
    later_text, later_frame = browser.evaluate(state)
    later = browser.screenshot(box)
    assert later_frame != first_frame and later_text != first_text    # the frame counter advances
    assert first_text.startswith("f = ") and later_text.startswith("f = ")
    assert np.abs(later - first).mean() > 0.2 and (np.abs(later - first) > 64).sum() > 50   # the picture moves
    browser.evaluate("document.querySelector('button').click()")      # pause: the counter stops
    paused = browser.evaluate(state)
    time.sleep(0.5)
    assert browser.evaluate(state) == paused
    assert offline(browser, page) == []
