"""The explorer in a real browser: ``grazing explore`` in a process of its own, its page in headless Chromium.

Chromium is driven over the DevTools protocol on a pipe, by the client of
:mod:`grazing.report.browser` (no Playwright, no browser download).  A click is a
real mouse click (``Input.dispatchMouseEvent``) at the pixel where the diagram's
own scales put a parameter value; what the page says is read as a person reads
it: the text of every element, through Panel's shadow roots.
"""

from __future__ import annotations

import base64
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from grazing.report.browser import _DevTools, find_chromium
from tests.processes import all_gone, descendants

SERVER_START = 120.0
"""Seconds the server may take to listen (a cold machine compiles the kernels first)."""

_TEXT = """(() => {
  const parts = [];
  const walk = (node) => {
    if (node.shadowRoot) walk(node.shadowRoot);
    for (const c of node.childNodes) {
      if (c.nodeType === 3) parts.push(c.textContent);
      else if (c.nodeType === 1 && !['STYLE', 'SCRIPT', 'TEMPLATE'].includes(c.tagName)) walk(c);
      else if (c.nodeType === 11) walk(c);
    }
  };
  walk(document.body);
  return parts.join(' ').replace(/\\s+/g, ' ');
})()"""

_POINT = """(() => {
  const found = [];
  const walk = (v) => {
    if (v.model.name === 'diagram') found.push(v);
    for (const c of (v.child_views ?? [])) walk(c);
  };
  for (const r of Bokeh.index.roots) walk(r);
  if (!found.length) return null;
  const pv = found[0], fr = pv.frame.bbox, rect = pv.canvas_view.el.getBoundingClientRect();
  const sx = pv.frame.x_scale.compute(%r);
  return JSON.stringify({x: rect.left + sx, y: rect.top + fr.top + fr.height / 2,
                         left: rect.left + fr.left, right: rect.left + fr.right});
})()"""


class ExplorerPage:
    """``grazing explore ARGS --no-browser --port 0`` and its page in headless Chromium (context manager)."""

    def __init__(
        self, args: list[str], cwd: Path, width: int = 1400, height: int = 1000, *, mobile: bool = False
    ) -> None:
        self.args = args
        self.cwd = cwd
        self.width, self.height = width, height
        self.mobile = mobile  # (a phone: the page is laid out as its viewport tag says, 980 px without one)
        self.server: subprocess.Popen[str] | None = None
        self.url = ""
        self.exit_code: int | None = None
        self.stderr = ""

    def __enter__(self) -> ExplorerPage:
        exe = find_chromium()
        assert exe is not None
        cmd = [sys.executable, "-m", "grazing", "explore", *self.args, "--no-browser", "--port", "0"]
        self.server = subprocess.Popen(
            cmd,
            cwd=self.cwd,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        line = _read_line(self.server, SERVER_START)
        match = re.search(r"http://127\.0\.0\.1:\d+/", line)
        assert match, f"no address in {line!r}"
        self.url = match.group(0)
        self._profile = tempfile.TemporaryDirectory(prefix="grazing-explore-chromium-")
        self.dt = _DevTools(exe, self._profile.name, 60.0)
        target = self.dt.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.dt.send("Target.attachToTarget", {"targetId": target, "flatten": True})[
            "sessionId"
        ]
        self.dt.send("Page.enable", session=self.session)
        self.dt.send("Runtime.enable", session=self.session)
        self.dt.send(
            "Emulation.setDeviceMetricsOverride",
            {"width": self.width, "height": self.height, "deviceScaleFactor": 1, "mobile": self.mobile},
            session=self.session,
        )
        self.dt.send("Page.navigate", {"url": self.url}, session=self.session)
        self.dt.wait_event("Page.loadEventFired")
        return self

    def evaluate(self, expression: str) -> Any:
        res = self.dt.send(
            "Runtime.evaluate", {"expression": expression, "returnByValue": True}, session=self.session
        )
        return res.get("result", {}).get("value")

    def text(self) -> str:
        """The page's text, as shown."""
        return self.evaluate(_TEXT) or ""

    def wait_for(self, pattern: str, limit: float = 60.0) -> str:
        """Wait until the page's text matches ``pattern``; the text."""
        end = time.monotonic() + limit
        while True:
            text = self.text()
            if re.search(pattern, text):
                return text
            if time.monotonic() > end:
                raise AssertionError(f"the page never showed {pattern!r}; it shows: {text[-1500:]}")
            time.sleep(0.2)

    def diagram_pixel(self, value: float) -> dict[str, float]:
        """Where the diagram's scales put ``value`` (display units): page pixels, and the frame's edges.

        Read until three readings 0.2 s apart agree: the frame moves while the page lays itself out
        (the width of the axis's tick labels changes when the data arrives), and on a loaded
        machine two readings may agree before it has.
        """
        readings: list[str] = []
        for _ in range(150):
            found = self.evaluate(_POINT % value)
            assert found, "no diagram on the page"
            readings = [*readings[-2:], found]
            if len(readings) == 3 and len(set(readings)) == 1:
                return json.loads(found)
            time.sleep(0.2)
        raise AssertionError("the diagram never stopped moving")

    def click(self, x: float, y: float) -> None:
        """A left click at page pixel ``(x, y)``."""
        for kind in ("mouseMoved", "mousePressed", "mouseReleased"):
            self.dt.send(
                "Input.dispatchMouseEvent",
                {"type": kind, "x": x, "y": y, "button": "left", "clickCount": 1},
                session=self.session,
            )

    def screenshot(self, path: Path) -> None:
        shot = self.dt.send("Page.captureScreenshot", {"format": "png"}, session=self.session)
        path.write_bytes(base64.b64decode(shot["data"]))

    def stop(self) -> None:
        """Ctrl-C to the server (its process group, as a terminal sends it); wait for it and its children."""
        assert self.server is not None
        if self.server.poll() is None:
            children = descendants(self.server.pid)
            os.killpg(self.server.pid, signal.SIGINT)
            try:
                _, self.stderr = self.server.communicate(timeout=60)
            except subprocess.TimeoutExpired:
                os.killpg(self.server.pid, signal.SIGKILL)
                self.server.communicate()
                raise AssertionError("the server did not stop within 60 s of Ctrl-C") from None
            assert all_gone(children | {self.server.pid})
        self.exit_code = self.server.returncode

    def __exit__(self, *exc: object) -> None:
        try:
            self.dt.close()
            self._profile.cleanup()
        finally:
            self.stop()


def _read_line(proc: subprocess.Popen[str], limit: float) -> str:
    """The first line the server prints (its address), within ``limit`` seconds."""
    import selectors

    assert proc.stdout is not None
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    if not sel.select(limit):
        proc.kill()
        raise AssertionError(f"grazing explore printed nothing in {limit:.0f} s")
    line = proc.stdout.readline()
    if not line:
        _, err = proc.communicate()
        raise AssertionError(f"grazing explore ended (status {proc.returncode}): {err.strip()}")
    return line


def docs_screenshot(path: Path) -> None:
    """The screenshot of docs/explore.md: the default view, η = 0.446 clicked, its orbit continued (the
    diagram framed to its narrow branch and computed again there), the grazings found
    (``python -m tests.explore.page docs/img/explore.png``)."""
    from grazing.outputs import write_png_bytes

    with ExplorerPage([], Path(tempfile.gettempdir()), width=1400, height=1000) as page:
        page.wait_for(r"diagram: 200 points")
        where = page.diagram_pixel(0.446)
        page.click(where["x"], where["y"])
        page.wait_for(r"Floquet multipliers")
        for label, done in (
            ("Continue this orbit", r"towards eta = 0\.49"),
            ("Find the grazings", r"stop stop"),
        ):
            page.evaluate(_CLICK_BUTTON % label)
            page.wait_for(done, 120)
        page.wait_for(r"refined: 200 points", 120)
        page.dt.send("Input.dispatchMouseEvent", {"type": "mouseMoved", "x": 5, "y": 5}, session=page.session)
        time.sleep(1.0)  # (the plots redraw)
        shot = page.dt.send("Page.captureScreenshot", {"format": "png"}, session=page.session)
        write_png_bytes(path, base64.b64decode(shot["data"]), overwrite=True)


_CLICK_BUTTON = """(() => {
  const walk = (node) => {
    if (node.shadowRoot) { const b = walk(node.shadowRoot); if (b) return b; }
    for (const c of node.children ?? []) {
      if (c.tagName === 'BUTTON' && c.textContent.trim() === %r) return c;
      const b = walk(c); if (b) return b;
    }
    return null;
  };
  const button = walk(document.body);
  button.click();
  return true;
})()"""


def docs_map_screenshot(path: Path) -> None:
    """The period map of docs/explore.md: (η, θ̂) over [0.42, 0.48] x [30, 50] deg, η = 0.446 and
    θ̂ = 40° clicked, its orbit continued, its bifurcation curves followed, the grazings found."""
    from grazing.outputs import write_png_bytes

    args = ["--params", "eta,theta-hat", "--range", "0.42,0.48", "--range", "30,50", "--num", "40"]
    with ExplorerPage(args, Path(tempfile.gettempdir()), width=1400, height=1000) as page:
        page.wait_for(r"diagram: 1600 points")
        where = page.diagram_pixel(0.446)  # (at the frame's middle height: 40 deg)
        page.click(where["x"], where["y"])
        page.wait_for(r"Floquet multipliers")
        steps = (
            ("Continue this orbit", r"towards eta = 0\.48"),
            ("Follow the bifurcation curves", r"curve from"),
            ("Find the grazings", r"stop stop"),
        )
        for label, done in steps:
            page.evaluate(_CLICK_BUTTON % label)
            page.wait_for(done, 120)
        page.dt.send("Input.dispatchMouseEvent", {"type": "mouseMoved", "x": 5, "y": 5}, session=page.session)
        time.sleep(1.0)  # (the plots redraw)
        shot = page.dt.send("Page.captureScreenshot", {"format": "png"}, session=page.session)
        write_png_bytes(path, base64.b64decode(shot["data"]), overwrite=True)


if __name__ == "__main__":
    (docs_map_screenshot if "map" in Path(sys.argv[1]).name else docs_screenshot)(Path(sys.argv[1]))
