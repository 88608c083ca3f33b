"""compare_with_flow: the switching map against the flow through the contact, and its one-line refusals.

Its numbers against theory are checked in test_switching_zdm.py (which uses it) and in the report's
section (tests/report/test_switch_section.py); here, what it refuses.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

import grazing
from grazing import InvalidParameterError, InvalidStateError
from grazing.normalform import switching_map_at
from grazing.normalform.switching_check import compare_with_flow, loglog_slope, state_at

x, v, t, k, s = sp.symbols("x v t k s")


@pytest.fixture(scope="module")
def soft_stop():
    """``x'' = -x + cos(t) / 2``; beyond ``x = s`` a spring ``k (x - s)``: at ``s = 1`` the motion through
    ``(1, 0)`` at ``t = 0`` grazes with ``a = 1/2``, ``w = (0, k)``."""
    free = [v, -x + sp.cos(t) / 2]
    modes = [grazing.Mode("free", free), grazing.Mode("contact", [v, free[1] - k * (x - s)])]
    model = grazing.HybridModel(
        "soft-stop-check", [x, v], t, [grazing.Parameter("k", 4.0), grazing.Parameter("s", 1.0)],
        period=2 * sp.pi, modes=modes,
        surfaces=[grazing.Surface("wall", s - x, "free", "contact", sliding=False)],
    )  # fmt: skip
    return model, switching_map_at(model, "wall_to_contact", [1.0, 0.0], 0.0)


def _one_line(error, match, *args, **kw):
    with pytest.raises(error, match=match) as info:
        compare_with_flow(*args, **kw)
    assert "\n" not in str(info.value)


def test_the_check_of_the_soft_stop(soft_stop) -> None:
    model, zdm = soft_stop
    ys = np.geomspace(1e-6, 1e-4, 5)
    starts = [(model, [1 - y, math.sqrt(4 * zdm.accel * y)], 0.0) for y in ys]
    check = compare_with_flow(zdm, starts, model.with_params(s=100.0))
    np.testing.assert_allclose(check.depth, ys, rtol=1e-9)  # (1 - y rounds: ~1e-16 / y)
    np.testing.assert_array_equal(check.on_section, [st[1] for st in starts])
    assert check.t_end == math.pi / 2
    assert loglog_slope(ys, check.size) == pytest.approx(1.5, abs=0.01)
    assert loglog_slope(ys, check.error) == pytest.approx(2.0, abs=0.05)
    assert np.all(check.error < 0.05 * check.size)


def test_one_line_refusals(soft_stop) -> None:
    model, zdm = soft_stop
    far = model.with_params(s=100.0)
    # a start that never reaches the surface: no switch to compare
    _one_line(InvalidStateError, r"must switch across 'wall_to_contact' and back once before .*: \[\]", zdm,
              [(model, [0.9, 0.0], 0.0)], far)  # fmt: skip
    # a "free" model that switches: its runs are not the free flow
    _one_line(InvalidStateError, r"^the free model switched \(at t = ", zdm,
              [(model, [1 - 1e-4, math.sqrt(2e-4)], 0.0)], model)  # fmt: skip
    # a comparison time past a period
    _one_line(InvalidParameterError, r"^t1 = .* must be within a period", zdm,
              [(model, [1 - 1e-4, math.sqrt(2e-4)], 0.0)], far, t_end=7.0)  # fmt: skip


def test_state_at_ends_at_the_time_asked(soft_stop) -> None:
    model, _ = soft_stop
    far = model.with_params(s=100.0)
    sol = state_at(far, [0.0, 0.0], 0.3, 2.0)
    assert sol.t_final == pytest.approx(2.0, abs=1e-12)
    # x'' = -x + cos(t)/2 from rest at t0: x(t) = (t - t0) sin(t) / 4 + ... ; compare with the closed form
    t0, t1 = 0.3, 2.0
    A = np.array([[np.cos(t1 - t0), np.sin(t1 - t0)], [-np.sin(t1 - t0), np.cos(t1 - t0)]])
    # particular solution xp = t sin(t) / 4, xp' = (sin t + t cos t) / 4
    xp = lambda tt: np.array([tt * np.sin(tt) / 4, (np.sin(tt) + tt * np.cos(tt)) / 4])  # noqa: E731
    exact = A @ (np.zeros(2) - xp(t0)) + xp(t1)
    np.testing.assert_allclose(sol.x_final, exact, rtol=0, atol=1e-12)
