"""What the explorer's figures draw, without a browser (issue 44): the report's period palette, period 1
with and without impacts apart, the legend, states in degrees, the framing of a narrow branch."""

from __future__ import annotations

import html
import math

import numpy as np
import pytest

import grazing
from grazing.core.solution import Status
from grazing.explore.branch import BranchPiece, Continued
from grazing.explore.diagram import Axis, Diagram, View
from grazing.explore.figures import (
    Figures,
    branch_frame,
    diagram_columns,
    legend_html,
    map_image,
)
from grazing.plotting import period_classes


def _map(period, impacts) -> Diagram:
    """A 2 x 3 period map of the pendulum in (eta, theta_hat), as computed, without computing it."""
    view = View.of(grazing.models.pendulum("B"), {"eta": (0.44, 0.46), "theta_hat": (30, 40)}, num=3)
    b = view.axes[1]
    view = View(view.model, (view.axes[0], Axis(b.name, b.lo, b.hi, 2)))
    ok = np.full((2, 3), int(Status.OK))
    return Diagram(view, tuple(a.values() for a in view.axes), np.array(period), np.array(impacts), ok,
                   np.zeros((2, 3, 3)), None, 0.0)  # fmt: skip


def test_the_map_tells_impacting_from_nonimpacting_period_1_in_the_report_s_colours():
    d = _map([[1, 1, 2], [0, -1, 12]], [[0, 1, 1], [3, 0, 1.0]])
    image = map_image(d)["image"][0]
    codes, labels, colours = period_classes(d.period, d.impacts_per_period, 8)  # (the report's)
    assert image.tolist() == codes.tolist()
    assert image[0, 0] != image[0, 1]  # period 1 without impacts, with impacts
    assert [labels[int(c)] for c in image.ravel()] == [
        "1, no impacts", "1, impacting", "2", "aperiodic", "failed", "> 8",
    ]  # fmt: skip
    mapper = next(
        r.glyph.color_mapper for r in Figures(d.view).diagram.renderers if hasattr(r.glyph, "image")
    )
    # one colour per class, in the report's order: class k is drawn in the report's colour k
    assert list(mapper.palette) == colours
    assert (mapper.low, mapper.high) == (-0.5, len(colours) - 0.5)
    legend = legend_html(np.unique(image), map_view=True)
    for k in np.unique(image).astype(int):
        assert html.escape(labels[k]) in legend and colours[k] in legend
    assert "period-doubling curve" in legend


def test_the_diagram_is_coloured_by_the_report_s_palette_in_degrees():
    model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    view = View.of(model, {"eta": (0.44, 0.45)}, num=3)
    samples = np.full((3, 4, 3), np.nan)
    samples[0, :, 0] = 0.1  # period 1, no impacts
    samples[1, :, 0] = 0.2  # period 1, impacting
    samples[2, :, 0] = [0.3, 0.4, 0.3, 0.4]  # period 2
    ok = np.full(3, int(Status.OK))
    d = Diagram(view, (view.axes[0].values(),), np.array([1, 1, 2]), np.array([0, 1, 1.0]), ok,
                np.zeros((3, 3)), samples, 0.0)  # fmt: skip
    cols = diagram_columns(d, 0)
    _, _, colours = period_classes(np.array([1]), np.array([0]), 8)
    assert cols["colour"] == [colours[2], colours[3], colours[4], colours[4]]
    assert cols["y"] == pytest.approx(np.degrees([0.1, 0.2, 0.3, 0.4]).tolist())  # (theta in degrees)
    assert cols["text"][0] == "η = 0.440000: period 1, 0 impacts per period"
    figures = Figures(view)
    assert figures.diagram.yaxis[0].axis_label == "θ (deg)"
    assert figures.phase.yaxis[0].axis_label == "θ′ (deg per unit time)"
    assert figures.stop_spans[0][1].location == pytest.approx(40.0)  # the stop at theta_hat = 40 deg


def _continued(values) -> Continued:
    v = np.asarray(values, dtype=float)
    piece = BranchPiece(
        None, v, [np.zeros((1, 3))] * len(v), np.ones(len(v), bool), np.zeros(len(v), bool), 0.0
    )  # type: ignore[arg-type]
    return Continued("eta", (piece,), ())


def test_a_narrow_branch_frames_the_diagram_a_wide_one_does_not():
    view = View.of(grazing.models.pendulum("B"), {"eta": (0.44, 0.49)})
    assert branch_frame(view, _continued([0.446, 0.4451, 0.4463])) == pytest.approx((0.4439, 0.4475))
    assert branch_frame(view, _continued([0.446, 0.44, 0.46])) is None  # (0.02 of 0.05: shown as is)
    assert branch_frame(view, _continued([0.4899, 0.49])) == pytest.approx((0.4894, 0.49))  # (clipped)
    figures = Figures(view)
    assert figures.show_branch(_continued([0.446, 0.4451, 0.4463])) == pytest.approx((0.4439, 0.4475))
    assert (figures.diagram.x_range.start, figures.diagram.x_range.end) == pytest.approx((0.4439, 0.4475))
