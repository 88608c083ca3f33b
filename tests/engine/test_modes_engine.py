"""The engine on models with modes: kernels per mode behind the dispatch, the active field ``vf``."""

from __future__ import annotations

import numpy as np
import sympy as sp

from grazing import HybridModel, Mode, Parameter, Stop, Transition
from grazing.engine.codegen import generate_source
from grazing.engine.runner import Runner
from grazing.models import impact_oscillator

x, v, t = sp.symbols("x v t")
zeta, w, sigma, r = sp.symbols("zeta omega sigma r")
PARAMS = [
    Parameter("zeta", 0.05), Parameter("omega", 2.8, lower=0, lower_open=True), Parameter("sigma", 0.1),
    Parameter("r", 0.8),
]  # fmt: skip
FIELD = [v, -2 * zeta * v - x + sp.cos(w * t)]
STOP = Stop("stop", sigma - x, [x, -r * v])


def one_mode():
    return HybridModel("io", [x, v], t, PARAMS, FIELD, period=2 * sp.pi / w, stops=[STOP])


def with_unused_mode(far=100):
    """The same impact oscillator, with a second mode behind a transition whose guard is never reached."""
    return HybridModel(
        "io-modes", [x, v], t, PARAMS, period=2 * sp.pi / w,
        modes=[Mode("free", FIELD, stops=[STOP]), Mode("away", [v, -x])],
        transitions=[Transition("go", "free", "away", x + far), Transition("back", "away", "free", -x - far)],
    )  # fmt: skip


def test_one_mode_text_has_no_dispatch_by_mode():
    src = generate_source(one_mode().symbolic)
    assert "def tc_free(" in src.text and "def rhs(" in src.text and "_m0" not in src.text
    assert "tc_free" not in src.dispatch and "nmodes" not in src.sizes


def test_kernels_per_mode_behind_the_dispatch():
    src = generate_source(with_unused_mode().symbolic)
    assert src.dispatch["tc_free"] == ["tc_free_m0", "tc_free_m1"]
    assert src.dispatch["rhs"] == ["rhs_m0", "rhs_m1"]
    assert src.sizes["rows"] == [[0, 1], [2, -1]] and src.sizes["targets"] == [0, 1, 0]
    assert src.sizes["resets"] == [True, False, False]
    m = with_unused_mode()
    kern = m.kernels()
    out = np.empty(2)
    for vf, expected in ((0, [0.5, -0.3 - 2 * 0.05 * 0.5 + np.cos(2.8 * 0.2)]), (1, [0.5, -0.3])):
        kern.rhs(np.array([0.3, 0.5]), 0.2, m.param_vector, out, vf)
        assert out.tolist() == expected


def test_an_unentered_mode_changes_no_bit():
    """A second mode never entered: the same samples, impacts and Jacobian, bit for bit."""
    runs = []
    for m in (one_mode(), with_unused_mode()):
        run = Runner(m, [0.0, 0.0], variational=True)
        seg = run.advance(40, 40, impacts="all")
        runs.append((seg.samples, seg.impacts, run.V, run.vf))
    (s1, i1, v1, vf1), (s2, i2, v2, vf2) = runs
    assert len(i1) > 20  # (it impacts)
    assert np.array_equal(s1, s2) and np.array_equal(i1, i2) and np.array_equal(v1, v2)
    assert vf1 == vf2 == 0
    # and the built-in impact oscillator is this model
    ref = Runner(impact_oscillator(zeta=0.05, omega=2.8, sigma=0.1, r=0.8), [0.0, 0.0], variational=True)
    assert np.array_equal(ref.advance(40, 40).samples, s1)
