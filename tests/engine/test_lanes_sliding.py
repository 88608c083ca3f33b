"""Sweeps on SIMD lanes through Filippov sliding: the lanes give the scalar Runner's numbers, bit for bit.

The friction oscillator (:func:`grazing.models.friction_oscillator`: stick-slip, the stick phase as the
sliding pseudo-mode on ``h = x' - v_belt``) and a variant on a belt whose speed depends on the position
(``h = x' - v_belt (1 + sin(x) / 4)``: Filippov's field leaves the surface by its rounding, so the per-lane
projection onto ``h = 0`` at step ends and samples changes the bits).  Each sweep is checked against the
independent Runner oracle of ``tests/engine/test_lanes.py`` (samples, impacts by transition, Lyapunov
exponent, transient used, final state and final mode of every point), on vectors of lanes and lane by
lane, chunk by chunk and shared by three threads; and a fresh sweep against :func:`grazing.simulate`.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import sympy as sp

import grazing
from grazing import HybridModel, Mode, Parameter, Surface
from grazing.core.options import SweepSettings
from grazing.engine.codegen import taylor_order
from grazing.models import BUILT_IN, friction_oscillator
from grazing.sweeps.run import run_chunks
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_lanes import assert_chunks_equal, assert_lanes_equal_the_oracle

STICK = 2  # the sliding pseudo-mode's index ("sliding on 'belt'")


def wavy_belt() -> HybridModel:
    """The friction oscillator on a belt whose speed depends on the position: ``x' = v_b (1 + sin(x)/4)``
    while sticking (a curved sliding surface: its Filippov field does not simplify)."""
    x, v, t = sp.symbols("x v t")
    a, omega, mu, vb = sp.symbols("a omega mu v_belt")
    force = -x + a * sp.cos(omega * t)
    params = [
        Parameter("a", 1.0),
        Parameter("omega", 0.5, lower=0.0, lower_open=True),
        Parameter("mu", 0.5, lower=0.0, lower_open=True),
        Parameter("v_belt", 0.2),
    ]
    return HybridModel(
        "wavy-belt", [x, v], t, params, period=2 * sp.pi / omega,
        modes=[Mode("slip_behind", [v, force + mu]), Mode("slip_ahead", [v, force - mu])],
        surfaces=[Surface("belt", v - vb * (1 + sp.sin(x) / 4), "slip_ahead", "slip_behind")],
    )  # fmt: skip


def diagonal() -> HybridModel:
    """``x' = -1 - x^2`` above the diagonal ``h = x - y``, ``2 + c sin(x) / 2`` below, ``y' = 1``: from
    ``(1, 0)`` the motion reaches the diagonal and slides on it for good (``x = y``), where Filippov's
    field leaves the surface by its rounding unless each step's end and sample is put back
    (tests/engine/test_sliding.py)."""
    xs, ys, ts, c = sp.symbols("x y t c")
    return HybridModel(
        "diagonal", [xs, ys], ts, [Parameter("c", 1.0)], period=1,
        modes=[Mode("above", [-1 - xs**2, 1]), Mode("below", [2 + c * sp.sin(xs) / 2, 1])],
        surfaces=[Surface("diag", xs - ys, "above", "below")],
    )  # fmt: skip


SWEEPS = {
    "friction, continuation, Lyapunov": (
        friction_oscillator,
        "mu",
        np.linspace(0.3, 0.9, 16),
        SweepSettings(transient=30, periods=10, chunk_size=2),
    ),
    "friction, fresh, no Lyapunov": (
        friction_oscillator,
        "a",
        np.linspace(0.6, 1.6, 16),
        SweepSettings(transient=30, periods=10, chunk_size=4, fresh=True, lyapunov=False, adaptive=False),
    ),
    "wavy belt, continuation, Lyapunov": (
        wavy_belt,
        "mu",
        np.linspace(0.3, 0.9, 16),
        SweepSettings(transient=30, periods=10, chunk_size=2),
    ),
    "diagonal, continuation, Lyapunov": (
        diagonal,
        "c",
        np.linspace(0.8, 1.2, 8),
        SweepSettings(transient=30, periods=10, chunk_size=4, adaptive=False),
        (1.0, 0.0),
    ),
}


@pytest.mark.parametrize("name", list(SWEEPS))
def test_sweep_through_sliding_on_lanes_equals_the_runner_oracle(name: str) -> None:
    make, param, values, settings_, *x0 = SWEEPS[name]
    model = make()
    spec = sweep_spec(model, param, values, x0=x0[0] if x0 else None, settings=settings_)
    spec = dataclasses.replace(spec, polish=False)
    kern = spec.model.kernels(0, taylor_order(spec.tol))
    assert kern.NMODES == 3 and kern.LANES > 1
    res = assert_lanes_equal_the_oracle(spec)
    modes = np.concatenate([r.mode_final for r in res])
    print(name, modes)
    assert STICK in modes.tolist()  # (points end sliding)
    if name.startswith("diagonal"):  # (on the diagonal, to the last bit: put back on it)
        assert all(np.array_equal(r.samples[..., 0], r.samples[..., 1]) for r in res)
    else:  # (and slipping)
        assert set(modes.tolist()) - {STICK}


def test_sweep_through_sliding_equals_simulate_point_by_point() -> None:
    """A fresh sweep over the friction oscillator's belt speed: each point as grazing.simulate runs it (the
    samples to rounding: a sweep runs in blocks of periods, simulate in chunks), in the same final mode."""
    m = friction_oscillator()
    values = np.linspace(0.05, 0.4, 8)
    settings_ = SweepSettings(
        transient=30, periods=8, chunk_size=4, fresh=True, adaptive=False, lyapunov=False
    )
    spec = dataclasses.replace(sweep_spec(m, "v_belt", values, settings=settings_), polish=False)
    res = run_chunks(spec, list(range(spec.n_chunks)))
    samples = np.concatenate([r.samples for r in res])
    modes = np.concatenate([r.mode_final for r in res])
    for i, vb in enumerate(values):
        point = m.with_params(v_belt=float(vb))
        sol = grazing.simulate(point, spec.x0, transient=30, periods=8)
        np.testing.assert_allclose(samples[i], sol.samples, rtol=0, atol=1e-8)
        assert point.mode_names[modes[i]] == sol.mode_final, i
    print(modes)
    assert STICK in modes.tolist()


X0 = {"rocking-block": (0.05, 0.0)}  # (tilted: it rocks from the start)
WITH_MODES = [name for name, make in BUILT_IN.items() if make().has_modes]


@pytest.mark.parametrize("name", WITH_MODES)
def test_every_built_in_model_with_modes_on_lanes_equals_the_runner_oracle(name: str) -> None:
    """A continuation sweep over the forcing frequency with Lyapunov exponents, on lanes, of each built-in
    model with modes (the soft-impact oscillator, the rocking block, the friction oscillator)."""
    model = BUILT_IN[name]()
    w = model.params["omega"]
    settings_ = SweepSettings(transient=20, periods=8, chunk_size=2)
    spec = sweep_spec(model, "omega", w * np.linspace(0.9, 1.1, 8), x0=X0.get(name), settings=settings_)
    spec = dataclasses.replace(spec, polish=False)
    res = run_chunks(spec, list(range(spec.n_chunks)))
    assert_chunks_equal(spec, res, name)
    assert all((r.status == 0).all() for r in res)
