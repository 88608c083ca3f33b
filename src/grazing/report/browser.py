"""Open the report in headless Chromium and check it as a reader would: every image shown, every link live.

Chromium is driven over the DevTools protocol on a pipe (``--remote-debugging-pipe``:
commands on file descriptor 3, replies on 4, each message JSON ended by a NUL
byte), so nothing but Chromium itself is needed.  The page is loaded; the
browser reports every ``<img>`` that did not load (``naturalWidth == 0``),
every link, and every in-page anchor without its target; links to local files
are then checked on disk.  Links to other sites are listed, not fetched.

Command line (``make check-report``)::

    python -m grazing.report.browser report/index.html [--screenshot page.png]

exits with status 1 and one line per problem when something is missing.
"""

from __future__ import annotations

import argparse
import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlparse

from grazing.errors import GrazingError
from grazing.outputs import check_replaceable, write_png_bytes

CANDIDATES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome")
"""Executable names tried by :func:`find_chromium`."""

FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
    "--disable-extensions",
    "--disable-dev-shm-usage",
    "--allow-file-access-from-files",
    "--hide-scrollbars",
    "--mute-audio",
)

_PROBE = """(() => {
  const imgs = Array.from(document.images);
  const broken = imgs.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.getAttribute('src'));
  const links = Array.from(document.querySelectorAll('a[href]')).map(a => [a.getAttribute('href'), a.href]);
  const anchors = links.filter(([raw]) => raw.startsWith('#'))
                       .filter(([raw]) => raw.length > 1
                               && !document.getElementById(decodeURIComponent(raw.slice(1))))
                       .map(([raw]) => raw);
  return JSON.stringify({title: document.title, images: imgs.length, broken: broken, links: links,
                         anchors: anchors, height: document.documentElement.scrollHeight});
})()"""


@dataclass
class PageCheck:
    """What the browser found on the page.

    Attributes
    ----------
    title
        The page's title.
    images
        Number of ``<img>`` elements.
    broken_images
        ``src`` of every image that did not load.
    links
        Number of links.
    broken_links
        Local links whose target file does not exist, and in-page anchors without a target.
    external
        Links to other sites (not checked).
    errors
        JavaScript exceptions thrown while loading.
    """

    title: str = ""
    images: int = 0
    broken_images: list[str] = field(default_factory=list)
    links: int = 0
    broken_links: list[str] = field(default_factory=list)
    external: list[str] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not (self.broken_images or self.broken_links or self.errors)

    def problems(self) -> list[str]:
        """One line per problem."""
        return (
            [f"image not shown: {s}" for s in self.broken_images]
            + [f"broken link: {s}" for s in self.broken_links]
            + [f"script error: {s}" for s in self.errors]
        )


def find_chromium() -> str | None:
    """The Chromium executable: ``$CHROMIUM`` if set, else the first of :data:`CANDIDATES` on PATH."""
    env = os.environ.get("CHROMIUM")
    if env:
        return env if shutil.which(env) or Path(env).is_file() else None
    for name in CANDIDATES:
        path = shutil.which(name)
        if path:
            return path
    return None


class _DevTools:
    """A minimal DevTools-protocol client over Chromium's debugging pipe."""

    def __init__(self, executable: str, profile: str, timeout: float) -> None:
        to_chrome_r, self._to_chrome = os.pipe()
        self._from_chrome, from_chrome_w = os.pipe()
        self.timeout = timeout

        def child_fds() -> None:  # runs in the child before exec: the pipe ends on fds 3 and 4
            a, b = os.dup(to_chrome_r), os.dup(from_chrome_w)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.proc = subprocess.Popen(
            [executable, *FLAGS, "--remote-debugging-pipe", f"--user-data-dir={profile}", "about:blank"],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            pass_fds=(3, 4, to_chrome_r, from_chrome_w),
            preexec_fn=child_fds,
        )
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self._buf = b""
        self._id = 0
        self.events: list[dict[str, Any]] = []

    def send(self, method: str, params: dict[str, Any] | None = None, session: str | None = None) -> Any:
        """Send a command and wait for its reply; events that arrive meanwhile are kept in :attr:`events`."""
        self._id += 1
        msg: dict[str, Any] = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._to_chrome, json.dumps(msg).encode() + b"\0")
        while True:
            reply = self._read()
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_event(self, method: str) -> dict[str, Any]:
        """Wait for an event (or take it from those already received)."""
        for i, ev in enumerate(self.events):
            if ev.get("method") == method:
                return self.events.pop(i)
        while True:
            ev = self._read()
            if ev.get("method") == method:
                return ev
            self.events.append(ev)

    def _read(self) -> dict[str, Any]:
        import select

        deadline = time.monotonic() + self.timeout
        while b"\0" not in self._buf:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._from_chrome], [], [], left)[0]:
                raise TimeoutError("Chromium did not answer in time")
            chunk = os.read(self._from_chrome, 1 << 16)
            if not chunk:
                raise RuntimeError("Chromium closed the debugging pipe")
            self._buf += chunk
        raw, self._buf = self._buf.split(b"\0", 1)
        return json.loads(raw)

    def close(self) -> None:
        try:
            self.send("Browser.close")
        except Exception:
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        for fd in (self._to_chrome, self._from_chrome):
            try:
                os.close(fd)
            except OSError:
                pass


def check_page(
    index: Path | str,
    *,
    chromium: str | None = None,
    screenshot: Path | str | None = None,
    width: int = 1400,
    timeout: float = 60.0,
    overwrite: bool = False,
) -> PageCheck:
    """Load ``index`` in headless Chromium and check its images and links.

    Parameters
    ----------
    index
        The HTML file.
    chromium
        The browser executable (default: :func:`find_chromium`).
    screenshot
        If given, a PNG of the whole page is written there (with grazing's
        mark; a file there that grazing did not write is refused, before the
        browser starts, unless ``overwrite``).
    width
        Width of the browser window in CSS pixels.
    timeout
        Seconds to wait for any answer of the browser.

    Raises
    ------
    FileNotFoundError
        When no Chromium is found or ``index`` does not exist.
    ForeignFileError
        When ``screenshot`` names a file grazing did not write (without ``overwrite``).
    """
    if screenshot is not None:
        check_replaceable(screenshot, overwrite=overwrite, hint="use another name, or --overwrite")
    page = Path(index).resolve()
    if not page.is_file():
        raise FileNotFoundError(page)
    exe = chromium or find_chromium()
    if exe is None:
        raise FileNotFoundError("no Chromium found (install chromium or set $CHROMIUM)")
    with tempfile.TemporaryDirectory(prefix="grazing-chromium-") as profile:
        dt = _DevTools(exe, profile, timeout)
        try:
            target = dt.send("Target.createTarget", {"url": "about:blank"})["targetId"]
            session = dt.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
            dt.send("Page.enable", session=session)
            dt.send("Runtime.enable", session=session)
            dt.send(
                "Emulation.setDeviceMetricsOverride",
                {"width": width, "height": 900, "deviceScaleFactor": 1, "mobile": False},
                session=session,
            )
            dt.send("Page.navigate", {"url": page.as_uri()}, session=session)
            dt.wait_event("Page.loadEventFired")
            res = dt.send("Runtime.evaluate", {"expression": _PROBE, "returnByValue": True}, session=session)
            found = json.loads(res["result"]["value"])
            errors = [
                ev["params"]["exceptionDetails"].get("text", "exception")
                for ev in dt.events
                if ev.get("method") == "Runtime.exceptionThrown"
            ]
            if screenshot is not None:
                height = int(found.get("height", 900))
                shot = dt.send(
                    "Page.captureScreenshot",
                    {
                        "format": "png",
                        "captureBeyondViewport": True,
                        "clip": {"x": 0, "y": 0, "width": width, "height": height, "scale": 1},
                    },
                    session=session,
                )
                write_png_bytes(screenshot, base64.b64decode(shot["data"]), overwrite=True)  # (checked)
        finally:
            dt.close()
    out = PageCheck(
        title=found["title"],
        images=found["images"],
        broken_images=found["broken"],
        links=len(found["links"]),
        errors=errors,
    )
    out.broken_links += found["anchors"]
    for raw, resolved in found["links"]:
        url = urlparse(resolved)
        if url.scheme == "file":
            if not Path(unquote(url.path)).exists():
                out.broken_links.append(raw)
        elif url.scheme in ("http", "https"):
            out.external.append(resolved)
    return out


def main(argv: list[str] | None = None) -> int:
    """Command line: check a report page; exit status 1 on any problem, 2 when Chromium is missing."""
    ap = argparse.ArgumentParser(prog="python -m grazing.report.browser", description=__doc__.split("\n")[0])
    ap.add_argument("index", type=Path, help="the report's index.html")
    ap.add_argument("--screenshot", type=Path, help="write a PNG of the whole page here")
    ap.add_argument("--chromium", help="the browser executable (default: chromium on PATH, or $CHROMIUM)")
    ap.add_argument("--overwrite", action="store_true", help="replace a --screenshot grazing did not write")
    args = ap.parse_args(argv)
    try:
        res = check_page(
            args.index, chromium=args.chromium, screenshot=args.screenshot, overwrite=args.overwrite
        )
    except (FileNotFoundError, GrazingError) as exc:
        print(f"check-report: {exc}", file=sys.stderr)
        return 2
    for line in res.problems():
        print(f"check-report: {line}", file=sys.stderr)
    print(
        f"{args.index}: “{res.title}”: {res.images} images, {res.links} links "
        f"({len(res.external)} external, not fetched): " + ("all fine" if res.ok else "PROBLEMS")
    )
    return 0 if res.ok else 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
