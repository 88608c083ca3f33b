"""``make check-report`` judges what each saved figure shows, plot area by plot area.

Every PNG grazing saves carries the layout of its plot areas
(:func:`grazing.plotting.checks.axes_layout`); :func:`grazing.report.browser.image_problems`
reads it back and looks at the pixels: a plot area nearly blank, data only outside the axis
limits (the two-parameter map drawn in radians on a degree axis, issue 30), labels running
off the image (fig 10's titles did, by a few pixels).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from matplotlib.figure import Figure

from grazing.outputs import png_text, save_png
from grazing.plotting.checks import LAYOUT_KEY, axes_layout, read_layout
from grazing.report.browser import check_page, find_chromium, image_problems, main


def _save(fig: Figure, path: Path) -> Path:
    return save_png(fig, path, dpi=100)


def _good(fig: Figure) -> None:
    ax = fig.subplots()
    t = np.linspace(0, 10, 400)
    ax.plot(t, np.sin(t))
    ax.set_title("a sine")


def test_a_sound_figure_has_no_problem_and_records_where_its_plot_area_is(tmp_path: Path) -> None:
    fig = Figure(figsize=(5, 3))
    _good(fig)
    path = _save(fig, tmp_path / "good.png")
    assert image_problems(path) == []
    (layout,) = read_layout(png_text(path.read_bytes(), LAYOUT_KEY) or "")
    assert layout.name == "axes 1 of 1 ('a sine')" and layout.data_in_view
    # the recorded box is the frame of the plot area: the frame's pixels are dark, just outside it white
    from PIL import Image

    img = np.asarray(Image.open(path).convert("L"), dtype=int)
    h, w = img.shape
    _, top, right, bottom = layout.box
    row = int((top + bottom) / 2 * h)
    frame_x = round(right * w)  # (the right-hand frame: no ticks beside it)
    assert img[row, frame_x - 1 : frame_x + 1].min() < 100
    assert img[row, frame_x + 3] > 200 and img[row, frame_x - 4] > 200


def test_a_blank_plot_area_beside_a_drawn_one_is_found(tmp_path: Path) -> None:
    fig = Figure(figsize=(8, 3))
    a, b = fig.subplots(1, 2)
    a.plot([0, 1], [0, 1])
    b.set_title("nothing here")
    b.grid(alpha=0.3)  # light grid lines are not data
    problems = image_problems(_save(fig, tmp_path / "blank.png"))
    assert problems == [
        "axes 2 of 2 ('nothing here'): no data inside its limits (x in [0, 1], y in [0, 1])",
        "axes 2 of 2 ('nothing here'): plot area nearly blank (0.0% drawn on)",
    ]


def test_a_map_drawn_in_radians_on_a_degree_axis_is_found(tmp_path: Path) -> None:
    """Issue 30's blank two-parameter map: the mesh in radians, the axis in degrees."""
    fig = Figure(figsize=(5, 4))
    ax = fig.subplots()
    eta = np.linspace(0.41, 0.485, 30)
    theta = np.radians(np.linspace(24, 54, 20))
    ax.pcolormesh(eta, theta, np.random.default_rng(0).integers(1, 6, (20, 30)), shading="nearest")
    ax.set_ylim(24, 54)
    ax.set_title("period map")
    problems = image_problems(_save(fig, tmp_path / "map.png"))
    assert problems[0].startswith("axes 1 of 1 ('period map'): no data inside its limits (x in [")
    assert any("nearly blank" in p for p in problems)
    ax.set_ylim(theta[0], theta[-1])  # the mesh where the axis is: fine
    assert image_problems(_save(fig, tmp_path / "map.png")) == []


def test_a_title_running_off_the_image_is_found(tmp_path: Path) -> None:
    fig = Figure(figsize=(4, 3), layout="constrained")
    a, b = fig.subplots(1, 2)
    a.plot([0, 1], [0, 1])
    b.plot([0, 1], [1, 0])
    b.set_title("a title far too long for the right-hand panel of this figure", loc="left")
    problems = image_problems(_save(fig, tmp_path / "long.png"))
    assert problems == [
        "axes 2 of 2 ('a title far too long for the right-hand panel of this figure'): "
        "its labels or title run off the image"
    ]


def test_an_image_without_a_layout_is_not_judged_here(tmp_path: Path) -> None:
    from PIL import Image

    Image.new("RGB", (50, 50), "white").save(tmp_path / "plain.png")
    assert image_problems(tmp_path / "plain.png") == []
    (tmp_path / "x.svg").write_text("<svg/>")
    assert image_problems(tmp_path / "x.svg") == []


def test_colour_bars_and_hidden_axes_are_not_plot_areas() -> None:
    fig = Figure(figsize=(5, 3))
    a, b = fig.subplots(1, 2)
    mesh = a.pcolormesh(np.arange(9.0).reshape(3, 3))
    fig.colorbar(mesh, ax=a)
    b.set_axis_off()
    fig.canvas.draw()  # (Figure.savefig draws too)
    assert [lay.name for lay in axes_layout(fig)] == ["axes 1 of 3"]


@pytest.mark.skipif(find_chromium() is None, reason="no Chromium installed")
def test_check_report_fails_on_a_page_showing_a_blank_plot_area(tmp_path: Path) -> None:
    fig = Figure(figsize=(8, 3))
    a, b = fig.subplots(1, 2)
    a.plot([0, 1], [0, 1])
    b.plot([5, 6], [5, 6])
    b.set(xlim=(0, 1), ylim=(0, 1))
    _save(fig, tmp_path / "fig.png")
    page = tmp_path / "index.html"
    page.write_text('<html><head><title>t</title></head><body><img src="fig.png"></body></html>')
    res = check_page(page)
    assert res.blank_images == [] and not res.ok
    assert res.figure_problems[0].startswith("fig.png: axes 2 of 2: no data inside its limits")
    assert "figure: fig.png: axes 2 of 2" in res.problems()[0]
    assert main([str(page)]) == 1
