"""The report's figures are laid out so that a reader can read them (issue 30).

Rendered with Agg, every text's and window bar's extent is measured in
pixels: window labels touch neither each other nor another window's bar; fig
6's letters sit on no other curve and its colour bar's label clears the
multiplier insets; fig 9's texts stay inside the figure, no axes over another.
"""

from __future__ import annotations

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text
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


def _captured(module, monkeypatch) -> list[Figure]:
    """Keep the figures the module saves (they are drawn as the report draws them)."""
    figures: list[Figure] = []

    def keep(fig: Figure, path) -> None:
        FigureCanvasAgg(fig)
        fig.canvas.draw()
        figures.append(fig)

    monkeypatch.setattr(module, "save_png", keep)
    return figures


@pytest.mark.slow
def test_fig06_letters_sit_on_no_other_curve_and_the_colour_bar_label_clears_the_insets(
    monkeypatch, tmp_path
) -> None:
    from grazing.report import fig06

    figures = _captured(fig06, monkeypatch)
    fig06.draw(fig06.compute(), tmp_path / "fig06.png")
    (fig,) = figures
    renderer = fig.canvas.get_renderer()
    left = fig.axes[0]
    letters = [t for t in left.texts if t.get_text() in fig06.LETTERS]
    assert sorted(t.get_text() for t in letters) == ["A", "B", "C", "D"]
    colours = {t.get_text(): t.get_color() for t in letters}
    for t in letters:
        box = Text.get_window_extent(t, renderer)  # the letter alone, not its leader line
        for line in left.lines:
            if line.get_color() == colours[t.get_text()] or len(line.get_xdata()) == 0:
                continue  # its own curve, the legend's empty lines
            if line.get_marker() not in (None, "", "None"):  # a mark (a fold): its disc clear of the letter
                r = 0.5 * line.get_markersize() * fig.dpi / 72.0 + CLEARANCE_PX
                for x, y in line.get_transform().transform(line.get_xydata()):
                    assert not _grown(box, r).contains(x, y), (t.get_text(), "a mark of", line.get_mec())
                continue
            path = line.get_transform().transform_path(line.get_path())
            assert not path.intersects_bbox(box, filled=False), (t.get_text(), line.get_color())
    colour_bar = next(ax for ax in fig.axes if ax.get_label() == "<colorbar>")
    label = colour_bar.yaxis.label.get_window_extent(renderer)
    for ax in fig.axes[2:]:
        if ax is colour_bar:
            continue
        for part in (ax.title, ax.xaxis.label):
            assert not label.overlaps(part.get_window_extent(renderer)), part.get_text()
        assert not label.overlaps(ax.get_window_extent(renderer))


@pytest.mark.slow
def test_fig09_every_text_inside_the_figure_and_no_axes_over_another(monkeypatch, tmp_path) -> None:
    from grazing.report import fig09

    figures = _captured(fig09, monkeypatch)
    fig09.build(tmp_path)
    fig = figures[0]  # the time series
    renderer = fig.canvas.get_renderer()
    page = fig.bbox
    every = [*fig.axes, *(child for ax in fig.axes for child in ax.child_axes)]  # insets too
    for ax in every:
        for text in (ax.title, ax._left_title, ax.xaxis.label, ax.yaxis.label, *ax.texts):
            if text.get_text():
                box = text.get_window_extent(renderer)
                assert page.x0 - 1 <= box.x0 and box.x1 <= page.x1 + 1, text.get_text()
    boxes = [ax.get_window_extent(renderer) for ax in every]
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            assert not a.overlaps(b), "an axes drawn over another (an inset over the main curve)"
