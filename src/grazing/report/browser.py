"""Open the report in headless Chromium and check it as a reader would: every image shown, every link live.

Chromium is driven over the DevTools protocol on a pipe (``--remote-debugging-pipe``:
commands on file descriptor 3, replies on 4, each message JSON ended by a NUL
byte), so nothing but Chromium itself is needed.  The page is loaded; the
browser reports every ``<img>`` that did not load (``naturalWidth == 0``),
every link, and every in-page anchor without its target; links to local files
are then checked on disk, and every local image that loaded is checked for
paint (:func:`painted_fraction`: a blank image is a problem).  Links to other
sites are listed, not fetched.  :func:`check_site` checks every page of a folder
(the documentation site) in one browser, and also the anchors that links from
one page name in another.

Command line (``make check-report``, ``make docs-check``)::

    python -m grazing.report.browser report/index.html [--screenshot page.png]
    python -m grazing.report.browser docs/_build/html

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
  const shown = imgs.filter(i => i.complete && i.naturalWidth > 0).map(i => [i.getAttribute('src'), i.src]);
  const ids = Array.from(document.querySelectorAll('[id]')).map(e => e.id)
                   .concat(Array.from(document.querySelectorAll('a[name]')).map(e => e.name));
  return JSON.stringify({title: document.title, images: imgs.length, broken: broken, links: links,
                         anchors: anchors, shown: shown, ids: ids,
                         height: document.documentElement.scrollHeight});
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
    blank_images
        ``src`` of every local image that loaded but is blank (:func:`is_blank`).
    figure_problems
        ``src: problem`` for every plot area of a local figure that is wrong (:func:`image_problems`).
    ids
        Every element id of the page (the targets of anchors).
    local_links
        Links to local files, as ``(href, absolute path, fragment)``.
    """

    title: str = ""
    images: int = 0
    broken_images: list[str] = field(default_factory=list)
    links: int = 0
    broken_links: list[str] = field(default_factory=list)
    external: list[str] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    blank_images: list[str] = field(default_factory=list)
    figure_problems: list[str] = field(default_factory=list)
    ids: set[str] = field(default_factory=set, repr=False)
    local_links: list[tuple[str, Path, str]] = field(default_factory=list, repr=False)

    @property
    def ok(self) -> bool:
        return not self.problems()

    def problems(self) -> list[str]:
        """One line per problem."""
        return (
            [f"image not shown: {s}" for s in self.broken_images]
            + [f"blank image: {s}" for s in self.blank_images]
            + [f"figure: {s}" for s in self.figure_problems]
            + [f"broken link: {s}" for s in self.broken_links]
            + [f"script error: {s}" for s in self.errors]
        )


BLANK_FRACTION = 0.005
"""An image is blank when fewer than this fraction of its pixels differ from its background."""


def _image_rgb(path: Path | str | Any) -> Any:
    """The image as an ``(h, w, 3)`` int16 array, transparent pixels over white."""
    import numpy as np
    from PIL import Image

    with Image.open(path) as im:
        rgba = np.asarray(im.convert("RGBA"), dtype=np.int16)
    alpha = rgba[..., 3:4] / 255.0
    return (rgba[..., :3] * alpha + 255 * (1 - alpha)).round().astype(np.int16)


def _painted(rgb: Any) -> float:
    """The fraction of pixels of ``rgb`` (``(..., 3)``) that differ from its most frequent colour."""
    import numpy as np

    flat = rgb.reshape(-1, 3)
    if flat.size == 0:
        return 0.0
    packed = (flat[:, 0].astype(np.int32) << 16) | (flat[:, 1].astype(np.int32) << 8) | flat[:, 2]
    commonest = int(np.argmax(np.bincount(packed, minlength=1)))  # (one pass; np.unique on rows sorts)
    background = np.array([commonest >> 16, (commonest >> 8) & 255, commonest & 255])
    return float(np.mean(np.any(np.abs(flat - background) > 8, axis=1)))


def painted_fraction(path: Path | str | Any) -> float:
    """The fraction of an image's pixels that differ from its background (its most frequent colour).

    Transparent pixels count as white; a pixel differs when one of its channels
    differs by more than 8 of 255 (anti-aliasing and compression noise aside).

    Examples
    --------
    >>> import io, numpy as np
    >>> from PIL import Image
    >>> img = np.full((100, 100, 3), 255, np.uint8)
    >>> img[10:20, 10:30] = (0, 0, 200)
    >>> buf = io.BytesIO(); Image.fromarray(img).save(buf, format="png")
    >>> painted_fraction(buf)
    0.02
    """
    return _painted(_image_rgb(path))


def is_blank(path: Path | str) -> bool:
    """True when the image at ``path`` is (nearly) one colour: :func:`painted_fraction` below
    :data:`BLANK_FRACTION`.  Only raster images (PNG, JPEG, GIF, WebP) are judged; others are not blank.
    """
    if Path(path).suffix.lower() not in (".png", ".jpg", ".jpeg", ".gif", ".webp"):
        return False
    return painted_fraction(path) < BLANK_FRACTION


AXES_INK = 40
"""A pixel of a plot area is drawn on when a channel differs from the area's background by more
than this (of 255): light grid lines and faint shading (alpha ≤ 0.3 over white) do not count."""

AXES_BLANK_FRACTION = 0.002
"""A plot area is nearly blank when fewer than this fraction of its pixels are drawn on (:data:`AXES_INK`)."""

RUN_OFF = 0.002
"""An axes runs off its image when its labels or title reach beyond the image by more than this fraction."""


def image_problems(path: Path | str) -> list[str]:
    """What is wrong with the content of a figure grazing saved, one line each.

    A PNG written by :func:`grazing.outputs.save_png` carries the layout of its
    plot areas (:func:`grazing.plotting.checks.axes_layout`); each plot area is
    judged on the pixels of the image: nearly blank (fewer than
    :data:`AXES_BLANK_FRACTION` of its pixels drawn on, frame aside), data
    drawn only outside its axis limits, or labels and title running off the
    image.  An image without a layout (a screenshot, an image grazing did not
    draw) gets no line here (:func:`is_blank` judges it as a whole).

    Examples
    --------
    >>> import matplotlib, tempfile, os
    >>> matplotlib.use("Agg")
    >>> from matplotlib.figure import Figure
    >>> from grazing.outputs import save_png
    >>> fig = Figure(figsize=(6, 3)); a, b = fig.subplots(1, 2)
    >>> _ = a.plot([0, 1], [0, 1]); _ = b.plot([0.4, 0.9], [0.4, 0.9]); _ = b.set_xlim(24, 54)
    >>> path = os.path.join(tempfile.mkdtemp(), "f.png")
    >>> _ = save_png(fig, path, dpi=100)
    >>> for line in image_problems(path): print(line)
    axes 2 of 2: no data inside its limits (x in [24, 54], y in [0.375, 0.925])
    axes 2 of 2: plot area nearly blank (0.0% drawn on)
    """
    import numpy as np

    from grazing.outputs import png_text
    from grazing.plotting.checks import LAYOUT_KEY, read_layout

    if Path(path).suffix.lower() != ".png":
        return []
    try:
        text = png_text(Path(path).read_bytes(), LAYOUT_KEY)
        layouts = read_layout(text) if text is not None else []
    except (OSError, ValueError) as exc:
        return [f"unreadable figure ({exc})"]
    if not layouts:
        return []
    rgb = _image_rgb(path)
    h, w = rgb.shape[:2]
    out = []
    for lay in layouts:
        if not lay.data_in_view:
            out.append(f"{lay.name}: no data inside its limits ({lay.limits})")
        left, top, right, bottom = lay.box
        # the inside of the frame: 2 pixels in from each edge (the frame and inward ticks aside)
        x0, x1 = int(np.ceil(left * w)) + 2, int(np.floor(right * w)) - 2
        y0, y1 = int(np.ceil(top * h)) + 2, int(np.floor(bottom * h)) - 2
        if x1 > x0 and y1 > y0:
            area = rgb[y0:y1, x0:x1].reshape(-1, 3)
            drawn = float(np.mean(np.any(np.abs(area - np.array(lay.facecolor)) > AXES_INK, axis=1)))
            if drawn < AXES_BLANK_FRACTION:
                out.append(f"{lay.name}: plot area nearly blank ({100 * drawn:.1f}% drawn on)")
        ol, ot, orr, ob = lay.outer
        if min(ol, ot) < -RUN_OFF or max(orr, ob) > 1 + RUN_OFF:
            out.append(f"{lay.name}: its labels or title run off the image")
    return out


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
    shots = {page: Path(screenshot)} if screenshot is not None else {}
    return check_pages([page], chromium=chromium, screenshots=shots, width=width, timeout=timeout)[page]


def check_pages(
    pages: list[Path],
    *,
    chromium: str | None = None,
    screenshots: dict[Path, Path] | None = None,
    width: int = 1400,
    timeout: float = 60.0,
) -> dict[Path, PageCheck]:
    """Load each of ``pages`` in turn in one headless Chromium and check it as :func:`check_page` does.

    ``screenshots`` maps a page (resolved path) to the PNG to write of it (replaced
    without a check: :func:`check_page` checks first).  Returns the check of
    each page, by its resolved path.

    Raises
    ------
    FileNotFoundError
        When no Chromium is found or a page does not exist.
    """
    pages = [Path(p).resolve() for p in pages]
    for page in pages:
        if not page.is_file():
            raise FileNotFoundError(page)
    exe = chromium or find_chromium()
    if exe is None:
        raise FileNotFoundError("no Chromium found (install chromium or set $CHROMIUM)")
    shots = {Path(k).resolve(): v for k, v in (screenshots or {}).items()}
    found: dict[Path, tuple[dict[str, Any], list[str]]] = {}
    with tempfile.TemporaryDirectory(prefix="grazing-chromium-") as profile:
        dt = _DevTools(exe, profile, timeout)
        try:
            for page in pages:
                found[page] = _load(dt, page, width, shots.get(page))
        finally:
            dt.close()
    return {page: _judge(*found[page]) for page in pages}


def _load(dt: _DevTools, page: Path, width: int, screenshot: Path | None) -> tuple[dict[str, Any], list[str]]:
    """Open ``page`` in a new tab, probe it (and take its screenshot), close the tab."""
    dt.events.clear()
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
    dt.send("Target.closeTarget", {"targetId": target})
    return found, errors


def _judge(found: dict[str, Any], errors: list[str]) -> PageCheck:
    """The :class:`PageCheck` of what the probe found: local links and images checked on disk."""
    out = PageCheck(
        title=found["title"],
        images=found["images"],
        broken_images=found["broken"],
        links=len(found["links"]),
        errors=errors,
        ids=set(found.get("ids", ())),
    )
    out.broken_links += found["anchors"]
    for raw, resolved in found["links"]:
        url = urlparse(resolved)
        if url.scheme == "file":
            target = Path(unquote(url.path))
            if not target.exists():
                out.broken_links.append(raw)
            else:
                out.local_links.append((raw, target.resolve(), unquote(url.fragment)))
        elif url.scheme in ("http", "https"):
            out.external.append(resolved)
    for raw, resolved in found.get("shown", ()):
        url = urlparse(resolved)
        if url.scheme == "file" and is_blank(unquote(url.path)):
            out.blank_images.append(raw)
        elif url.scheme == "file":
            out.figure_problems += [f"{raw}: {line}" for line in image_problems(unquote(url.path))]
    return out


def site_pages(folder: Path | str) -> list[Path]:
    """The HTML pages of a built site, sorted (Sphinx's copies of the sources and static files left out)."""
    root = Path(folder).resolve()
    skip = {"_sources", "_static", "_images", "_modules"}
    return sorted(p for p in root.rglob("*.html") if not skip & set(p.relative_to(root).parts[:-1]))


def check_site(
    folder: Path | str, *, chromium: str | None = None, timeout: float = 60.0
) -> dict[Path, PageCheck]:
    """Check every page of a built site (:func:`site_pages`) in one browser.

    Beyond :func:`check_pages`: a link from one page to an anchor of another
    page of the site (``api/x.html#name``) must find that anchor there.

    Raises
    ------
    FileNotFoundError
        When no Chromium is found, ``folder`` has no ``index.html``, or a page does not exist.
    """
    root = Path(folder).resolve()
    if not (root / "index.html").is_file():
        raise FileNotFoundError(root / "index.html")
    results = check_pages(site_pages(root), chromium=chromium, timeout=timeout)
    for res in results.values():
        for raw, target, fragment in res.local_links:
            other = results.get(target)
            if fragment and other is not None and fragment not in other.ids:
                res.broken_links.append(raw)
    return results


def main(argv: list[str] | None = None) -> int:
    """Command line: check a report page; exit status 1 on any problem, 2 when Chromium is missing."""
    ap = argparse.ArgumentParser(prog="python -m grazing.report.browser", description=__doc__.split("\n")[0])
    ap.add_argument("index", type=Path, help="the report's index.html, or a built site's folder (every page)")
    ap.add_argument("--screenshot", type=Path, help="write a PNG of the whole page here")
    ap.add_argument("--chromium", help="the browser executable (default: chromium on PATH, or $CHROMIUM)")
    ap.add_argument("--overwrite", action="store_true", help="replace a --screenshot grazing did not write")
    args = ap.parse_args(argv)
    if args.index.is_dir():
        return _main_site(args.index, args.chromium)
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


def _main_site(folder: Path, chromium: str | None) -> int:
    """Check every page of a site; one line per problem (with its page), a summary line."""
    try:
        results = check_site(folder, chromium=chromium)
    except (FileNotFoundError, GrazingError) as exc:
        print(f"check-site: {exc}", file=sys.stderr)
        return 2
    root = Path(folder).resolve()
    bad = 0
    for page, res in results.items():
        for line in res.problems():
            print(f"check-site: {page.relative_to(root)}: {line}", file=sys.stderr)
        bad += not res.ok
    images = sum(r.images for r in results.values())
    links = sum(r.links for r in results.values())
    external = len({u for r in results.values() for u in r.external})
    print(
        f"{folder}: {len(results)} pages, {images} images, {links} links ({external} external, not fetched): "
        + ("all fine" if not bad else f"PROBLEMS on {bad} pages")
    )
    return 0 if not bad else 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
