"""The report's figures are laid out so that a reader can read them (issue 30).

Rendered with Agg, every text's and window bar's extent is measured in
pixels: window labels touch neither each other nor another window's bar, and
the texts of a figure stay inside it.
"""

from __future__ import annotations

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.transforms import Bbox

from grazing.plotting.diagrams import label_windows
from grazing.sweeps.windows import Window

CLEARANCE_PX = 1.0
"""Least gap between two label parts, in pixels (at the report's 150 dpi)."""


def _window(period: int, lo: float, hi: float) -> Window:
    return Window(period, True, 0, 10, lo, hi, lo, hi)


def _crowded_axes(height: float) -> tuple[Figure, object]:
    """A panel like fig 7(d): a narrow period-5 window at grazing, then 4, 3, 2, 1."""
    fig = Figure(figsize=(6.0, height), dpi=150, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    ax.set_xlim(0.43, 0.50)
    ax.set_ylim(-40.0, -12.0)
    windows = [
        _window(5, 0.4453, 0.4462),
        _window(4, 0.4466, 0.4497),
        _window(3, 0.4520, 0.4590),
        _window(2, 0.4640, 0.4780),
        _window(1, 0.4785, 0.5000),
        _window(8, 0.4470, 0.4474),
        _window(6, 0.4500, 0.4504),
    ]
    fig.canvas.draw()  # the constrained layout first, as the report's figures are saved
    label_windows(ax, windows)
    fig.canvas.draw()
    return fig, ax


def _grown(box: Bbox, px: float) -> Bbox:
    return Bbox.from_extents(box.x0 - px, box.y0 - px, box.x1 + px, box.y1 + px)


def test_window_labels_touch_no_other_label_or_bar() -> None:
    for height in (3.8, 3.0):
        fig, ax = _crowded_axes(height)
        renderer = fig.canvas.get_renderer()
        texts = [t.get_window_extent(renderer) for t in ax.texts]
        bars = [ln.get_window_extent(renderer) for ln in ax.lines]
        assert len(texts) == len(bars) >= 5, "fewer windows labelled than fit"
        for i, t in enumerate(texts):
            for j, other in enumerate(texts):
                if i != j:
                    assert not _grown(t, CLEARANCE_PX).overlaps(other), (height, ax.texts[i].get_text())
            for j, bar in enumerate(bars):
                if i != j:  # a text sits above its own bar, touching no other one
                    assert not _grown(t, CLEARANCE_PX).overlaps(bar), (
                        height,
                        ax.texts[i].get_text(),
                        ax.texts[j].get_text(),
                    )
        axes_box = ax.get_window_extent(renderer)
        for t in texts:
            assert axes_box.y0 <= t.y0 and t.y1 <= axes_box.y1 + 0.5, "a label outside its axes"
