"""The bifurcation-diagram helpers of grazing.plotting, on synthetic sweep datasets (no simulation)."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

from grazing.models import pendulum
from grazing.plotting import (
    Window,
    find_windows,
    label_windows,
    mark_grazings,
    period_classes,
    plot_bifurcation,
    plot_period_map,
    visible_windows,
)
from grazing.report.diagrams import describe_windows, drop_doublings


def synthetic_sweep(param: str = "eta", values: np.ndarray | None = None) -> xr.Dataset:
    """A 40-point sweep: 10 nonimpacting period 1, 5 aperiodic, 10 period 4, 5 aperiodic, 10 period 2."""
    value = np.linspace(0.40, 0.50, 40) if values is None else values
    period = np.array([1] * 10 + [0] * 5 + [4] * 10 + [0] * 5 + [2] * 10)
    impacts = np.where(np.arange(40) < 10, 0.0, 1.0)
    rng = np.random.default_rng(1)
    samples = np.zeros((40, 12, 2))
    for i, p in enumerate(period):
        base = rng.uniform(-0.5, 0.0, size=max(p, 1))
        samples[i, :, 0] = rng.uniform(-0.5, 0.0, 12) if p == 0 else np.resize(base, 12)
    # The metadata a real sweep of the pendulum carries (grazing.sweeps.store.build_dataset).
    model = pendulum("B")
    par = model.parameter(param)
    stop = value if param == "theta_hat" else np.full(40, model.params["theta_hat"])
    ds = xr.Dataset(
        {
            "samples": (("point", "sample", "component"), samples),
            "period": ("point", period),
            "impacts_per_period": ("point", impacts),
            "stop_level": (("point", "component"), np.column_stack([stop, np.full(40, np.nan)])),
        },
        coords={"value": ("point", value), param: ("point", value), "component": ["theta", "dtheta"]},
        attrs={
            "params": param, "state_labels": json.dumps(list(model.state_labels)),
            "state_units": json.dumps(list(model.state_units)), "time_label": model.time_label,
            "forcing_period": model.period,
        },
    )  # fmt: skip
    ds[param].attrs.update({"symbol": par.label, "units": par.unit, "angle": int(par.angle)})
    return ds


def test_find_windows_covers_every_point_in_order() -> None:
    ds = synthetic_sweep()
    runs = find_windows(ds)
    assert [(w.period, w.impacting, w.points) for w in runs] == [
        (1, False, 10), (0, True, 5), (4, True, 10), (0, True, 5), (2, True, 10)
    ]  # fmt: skip
    assert runs[0].lo == 0.40 and runs[-1].hi == 0.50
    for a, b in itertools.pairwise(runs):
        assert a.last + 1 == b.first and math.isclose(a.hi, b.lo)
    assert runs[0].label == "1 (no impacts)" and runs[1].label == "aperiodic" and runs[2].label == "4"
    # unsorted input: the same runs
    rev = ds.isel(point=slice(None, None, -1))
    assert [(w.period, w.points) for w in find_windows(rev)] == [(w.period, w.points) for w in runs]


def test_find_windows_splits_impacting_from_nonimpacting_period_one() -> None:
    ds = xr.Dataset(
        {"period": ("point", [1, 1, 1, 1]), "impacts_per_period": ("point", [0.0, 0.0, 1.0, 1.0])},
        coords={"value": ("point", [0.1, 0.2, 0.3, 0.4])},
    )
    assert [w.label for w in find_windows(ds)] == ["1 (no impacts)", "1"]
    assert find_windows(ds.isel(point=slice(0, 0))) == []


def test_visible_windows_thresholds() -> None:
    runs = find_windows(synthetic_sweep())
    span = 0.1
    assert [w.period for w in visible_windows(runs, span)] == [4, 2]
    assert visible_windows(runs, span, min_points=11) == []
    assert [w.period for w in visible_windows(runs, span, min_period=3)] == [4]
    assert visible_windows(runs, span, min_fraction=0.5) == []


def test_label_windows_writes_each_period_and_staggers_neighbours() -> None:
    ax = Figure().add_subplot()
    ax.set_xlim(0.0, 1.0)
    ws = [
        Window(3, True, 0, 5, 0.10, 0.15, 0.10, 0.15),
        Window(5, True, 6, 7, 0.135, 0.145, 0.135, 0.145),  # centre 0.015 from the previous one: too close
        Window(2, True, 8, 20, 0.5, 0.8, 0.5, 0.8),
    ]
    label_windows(ax, ws)
    texts = [t.get_text() for t in ax.texts]
    assert texts == ["3", "5", "2"]
    heights = [t.get_position()[1] for t in ax.texts]
    assert heights[0] != heights[1]  # too close: the second label goes to the next row
    assert heights[2] == heights[0]
    assert len(ax.lines) == 3  # one extent bar per window


def test_plot_bifurcation_draws_all_samples_and_labels() -> None:
    ds = synthetic_sweep()
    ax = Figure().add_subplot()
    runs = plot_bifurcation(ax, ds)
    dots = ax.lines[0]
    assert len(dots.get_xdata()) == 40 * 12
    assert np.allclose(np.max(dots.get_ydata()), np.degrees(ds.samples.values[:, :, 0].max()))
    assert [t.get_text() for t in ax.texts if t.get_text().isdigit()] == ["4", "2"]
    assert len(ax.patches) == 1  # the shaded nonimpacting range
    assert len(runs) == 5 and ax.get_xlabel() == "η" and ax.get_ylabel().startswith("θ (degrees)")


def test_plot_bifurcation_in_the_stop_angle_uses_degrees() -> None:
    values = np.radians(np.linspace(30.0, 40.0, 40))
    ds = synthetic_sweep("theta_hat", values)
    ax = Figure().add_subplot()
    plot_bifurcation(ax, ds, windows=False, nonimpacting=False, stop=True)
    assert ax.get_xlabel() == "θ̂ (degrees)"
    lo, hi = ax.get_xlim()
    assert lo < 30.0 < 40.0 < hi < 41.0
    assert not ax.texts and len(ax.lines) == 2  # dots and the line theta = theta_hat
    mark_grazings(ax, [math.radians(39.0)], scale=180 / math.pi, labels=["g"])
    assert ax.lines[-1].get_xdata()[0] == pytest.approx(39.0)
    assert ax.texts[-1].get_text().strip() == "g"


def test_period_classes_and_map() -> None:
    codes, labels, colors = period_classes(np.array([-1, 0, 1, 1, 2, 9]), np.array([0, 1, 0, 1, 1, 1]), 8)
    assert [labels[c] for c in codes] == ["failed", "aperiodic", "1, no impacts", "1, impacting", "2", "> 8"]
    assert len(labels) == len(colors) == 12
    ds = xr.Dataset(
        {"period": (("theta_hat", "eta"), [[1, 1, 2], [0, 3, 1]]),
         "impacts_per_period": (("theta_hat", "eta"), [[0, 1, 1], [1, 1, 1.0]])},
        coords={"theta_hat": np.radians([10.0, 20.0]), "eta": [0.3, 0.4, 0.5]},
        attrs={"params": "eta,theta_hat"},
    )  # fmt: skip
    for name in ("eta", "theta_hat"):
        par = pendulum("B").parameter(name)
        ds[name].attrs.update({"symbol": par.label, "units": par.unit, "angle": int(par.angle)})
    fig = Figure()
    ax = fig.add_subplot()
    plot_period_map(ax, ds)
    cbar_ax = fig.axes[-1]
    shown = [t.get_text() for t in cbar_ax.get_yticklabels()]
    assert shown == ["aperiodic", "1, no impacts", "1, impacting", "2", "3"]
    assert ax.get_ylabel() == "θ̂ (degrees)" and ax.get_ylim()[1] > 20.0


def test_drop_doublings_and_describe() -> None:
    ws = [
        Window(2, True, 0, 9, 0.0, 0.9, 0.0, 0.95),
        Window(4, True, 12, 13, 1.2, 1.3, 1.15, 1.35),
        Window(3, True, 20, 29, 2.0, 2.9, 1.95, 2.95),
        Window(6, True, 40, 41, 4.0, 4.1, 3.95, 4.15),
    ]
    assert [w.period for w in drop_doublings(ws)] == [2, 3, 6]  # the 6 is far from the 3
    assert [w.period for w in drop_doublings(ws, gap=20)] == [2, 3]
    assert describe_windows([]) == "none"
    assert describe_windows(ws[:1], digits=2) == "2 (η 0–0.9)"


def test_a_sweep_up_and_down_is_drawn_in_markers_of_real_size_and_shaded_as_each_sweep_says() -> None:
    """The hysteresis diagram: both sweeps seen (rings and dots, not 1-px points); the nonimpacting
    shade where both sweeps are free of the stop, and a hatch in the down sweep's colour where only it is."""
    up = synthetic_sweep()
    down = up.copy(deep=True)
    down["impacts_per_period"].values[10:15] = 0.0  # swept down, free of the stop 5 points further
    down["period"].values[10:15] = 1
    ds = xr.concat([up, down], dim="direction").assign_coords(direction=["up", "down"])
    ax = Figure().add_subplot()
    plot_bifurcation(ax, ds, windows=False)
    lines = {line.get_label(): line for line in ax.lines}
    assert set(lines) == {"swept up", "swept down"}
    assert lines["swept up"].get_markersize() >= 3 and lines["swept up"].get_markerfacecolor() == "none"
    assert lines["swept down"].get_markersize() >= 1.5
    assert lines["swept down"].get_markersize() < lines["swept up"].get_markersize()  # a dot inside a ring
    value = up["value"].values
    spans = [(p.get_x(), p.get_x() + p.get_width(), p.get_hatch()) for p in ax.patches]
    shaded = [(a, b) for a, b, h in spans if not h]
    hatched = [(a, b) for a, b, h in spans if h]
    assert len(shaded) == 1 and np.isclose(shaded[0][1], (value[9] + value[10]) / 2)  # both free
    assert len(hatched) == 1 and np.isclose(hatched[0][0], shaded[0][1])  # the down sweep alone
    assert np.isclose(hatched[0][1], (value[14] + value[15]) / 2)
