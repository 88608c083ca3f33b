"""Filippov sliding in the scalar engine: the friction oscillator's stick-slip against its exact solution.

x'' + x = a cos(w t) - mu sgn(x' - v_b) (grazing.models.friction_oscillator).  Slipping, the motion is
linear (in closed form, a rotation about the forced solution); the stick phase is sliding on h = x' - v_b = 0,
where x = x0 + v_b (t - t0) exactly until |a cos(w t) - x| reaches mu (Brent's method).  The Jacobian
is the product of the slips' rotations, the entry saltation I + (f_s - f-) h_x / (h_x f-) and the stick's
exact variational flow [[1, dt], [0, 1]] (the exit, at a tangency, has S = I), and is checked against
central differences of the exact flow too.  Nothing in the reference uses grazing's engine.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from scipy.optimize import brentq

import grazing
from grazing import HybridModel, Mode, Parameter, Surface, Tangent, Transition
from grazing.models import friction_oscillator

BEHIND, AHEAD, STICK = 0, 1, 2  # the engine's mode indices (slip_behind, slip_ahead, sliding on 'belt')
VALUES = {"a": 1.0, "omega": 0.5, "mu": 0.5, "v_belt": 0.2}  # stick, slip both ways, crossings
SAMPLES_PER_PERIOD = 800


class FrictionReference:
    """The exact stick-slip flow of the friction oscillator with parameters ``p``.

    Slipping with friction ``d = +mu`` (behind the belt) or ``-mu`` (ahead of it), ``x'' + x = a cos(w t)
    + d`` has the solution ``x = d + K cos(w t) + C cos(t - t0) + D sin(t - t0)``, ``K = a / (1 - w^2)``.
    """

    def __init__(self, p: dict[str, float]):
        self.p = p
        self.K = p["a"] / (1.0 - p["omega"] ** 2)

    def f(self, mode: int, x: np.ndarray, t: float) -> np.ndarray:
        d = self.p["mu"] if mode == BEHIND else -self.p["mu"]
        return np.array([x[1], -x[0] + self.p["a"] * math.cos(self.p["omega"] * t) + d])

    def flow(self, mode: int, x0: np.ndarray, t0: float, t):
        """The slip from ``(x0, t0)`` at the time(s) ``t``: ``(x, v)``."""
        w, K = self.p["omega"], self.K
        d = self.p["mu"] if mode == BEHIND else -self.p["mu"]
        C = x0[0] - d - K * math.cos(w * t0)
        D = x0[1] + K * w * math.sin(w * t0)
        tau = np.asarray(t) - t0
        x = d + K * np.cos(w * np.asarray(t)) + C * np.cos(tau) + D * np.sin(tau)
        v = -K * w * np.sin(w * np.asarray(t)) - C * np.sin(tau) + D * np.cos(tau)
        return np.array([x, v])

    def force(self, x: float, t: float) -> float:
        """``a cos(w t) - x``: the force the friction balances while sticking."""
        return self.p["a"] * math.cos(self.p["omega"] * t) - x

    def _first_root(self, g, t0: float, t1: float) -> float | None:
        """The first time in ``(t0, t1]`` where ``g`` (vectorised) goes from >= 0 to < 0, to 1e-15."""
        n = max(8, math.ceil((t1 - t0) * self.p["omega"] / (2 * math.pi) * SAMPLES_PER_PERIOD))
        ts = np.linspace(t0, t1, n + 1)
        vals = g(ts)
        for i in range(1, n + 1):
            if vals[i] < 0.0 <= vals[i - 1] and not (i == 1 and vals[0] == 0.0):
                return brentq(
                    lambda tt: float(g(tt)), ts[i - 1], ts[i], xtol=1e-15, rtol=4 * np.finfo(float).eps
                )
        return None

    def stick_end(self, x0: float, t0: float, t1: float) -> tuple[float, int] | None:
        """The end of a stick from ``(x0, t0)`` before ``t1``: (time, the mode it slips into)."""
        p = self.p
        ends = []
        for sign, mode in ((1.0, AHEAD), (-1.0, BEHIND)):
            tz = self._first_root(
                lambda t, sign=sign: (
                    p["mu"] - sign * (p["a"] * np.cos(p["omega"] * t) - x0 - p["v_belt"] * (t - t0))
                ),
                t0,
                t1,
            )
            if tz is not None:
                ends.append((tz, mode))
        return min(ends) if ends else None

    def run(self, x0, mode: int, t0: float, t1: float, entry_saltation: bool = True):
        """From ``x0`` in ``mode`` at ``t0`` to ``t1``: ``(x, mode, J, events)``, events ``(t, kind)`` with
        kind ``"stick"``, ``"cross"`` or ``"slip"`` (a stick's end).  Without ``entry_saltation`` the
        Jacobian skips the saltation matrix at a stick's start (a wrong one, for the test that it matters)."""
        x, t, J = np.asarray(x0, dtype=float), t0, np.eye(2)
        vb = self.p["v_belt"]
        hx = np.array([0.0, 1.0])
        events = []
        while True:
            if mode == STICK:
                end = self.stick_end(x[0], t, t1)
                stop = t1 if end is None else end[0]
                J = np.array([[1.0, stop - t], [0.0, 1.0]]) @ J
                x = np.array([x[0] + vb * (stop - t), vb])
                if end is None:
                    return x, mode, J, events
                events.append((stop, "slip"))
                t, mode = stop, end[1]
                continue
            sign = -1.0 if mode == BEHIND else 1.0  # the guard sign (v - v_b) reaching 0 from above
            tz = self._first_root(
                lambda tt, x=x, t=t, k=mode, sg=sign: sg * (self.flow(k, x, t, tt)[1] - vb), t, t1
            )
            tau = (t1 if tz is None else tz) - t
            J = np.array([[math.cos(tau), math.sin(tau)], [-math.sin(tau), math.cos(tau)]]) @ J
            if tz is None:
                return self.flow(mode, x, t, t1), mode, J, events
            xz = self.flow(mode, x, t, tz)
            xz[1] = vb  # (on the surface, to rounding)
            far = 1 - mode
            pushes_back = self.f(far, xz, tz)[1] * sign > 0.0  # the far side's field points back
            fm = self.f(mode, xz, tz)
            fp = np.array([vb, 0.0]) if pushes_back else self.f(far, xz, tz)
            if entry_saltation or not pushes_back:
                J = (np.eye(2) + np.outer(fp - fm, hx) / (hx @ fm)) @ J
            events.append((tz, "stick" if pushes_back else "cross"))
            x, t, mode = xz, tz, STICK if pushes_back else far

    def run_long(self, x0, mode: int, t0: float, t1: float, **kw):
        """:meth:`run` a period at a time (the roots are searched on shorter spans)."""
        T = 2 * math.pi / self.p["omega"]
        x, J, events, t = np.asarray(x0, dtype=float), np.eye(2), [], t0
        while t < t1:
            stop = min(t + T, t1)
            x, mode, Jstep, ev = self.run(x, mode, t, stop, **kw)
            J, events, t = Jstep @ J, events + ev, stop
        return x, mode, J, events


def _simulate(m, x0, periods, **kw):
    return grazing.simulate(m, x0, periods=periods, impacts="all", **kw)


def test_stick_slip_against_the_exact_solution():
    m = friction_oscillator(**VALUES)
    ref = FrictionReference(dict(m.params))
    periods = 6
    sol = _simulate(m, [0.0, 0.0], periods, tangent=Tangent(jacobian=True))
    x_ref, mode, t_prev, J, events = np.zeros(2), BEHIND, 0.0, np.eye(2), []
    for i, ts in enumerate(sol.t):
        x_ref, mode, Jstep, ev = ref.run(x_ref, mode, t_prev, ts)
        J, t_prev = Jstep @ J, ts
        events += ev
        assert np.allclose(sol.samples[i], x_ref, rtol=0, atol=1e-10), (i, sol.samples[i] - x_ref)
    kinds = [kind for _, kind in events]
    assert kinds.count("stick") >= 3 and kinds.count("slip") >= 3 and kinds.count("cross") >= 1
    sw = sol.switches
    assert len(sw) == len(events)
    assert np.abs(sw.t - [tz for tz, _ in events]).max() < 1e-12
    names = [sw.target(i) if sw.target(i).startswith("sliding") else "cross/slip" for i in range(len(sw))]
    assert names == ["sliding on 'belt'" if k == "stick" else "cross/slip" for k in kinds]
    slips = [i for i, k in enumerate(kinds) if k == "slip"]
    assert {sw.target(i) for i in slips} == {"slip_ahead", "slip_behind"}  # both exits
    # The stick intervals: from each entry to the following exit (or the end), on surface 0.
    starts = [tz for tz, k in events if k == "stick"]
    ends = [tz for tz, k in events if k == "slip"] + ([sol.t_final] if mode == STICK else [])
    assert sol.sliding.shape == (len(starts), 3) and np.all(sol.sliding[:, 2] == 0)
    assert np.abs(sol.sliding[:, 0] - starts).max() < 1e-12 and np.abs(sol.sliding[:, 1] - ends).max() < 1e-12
    assert sol.mode_final == m.mode_names[mode]
    # Samples while sticking are put on the surface (the step's polynomial leaves it by rounding).
    stuck = [i for i, ts in enumerate(sol.t) if any(a < ts < b for a, b, _ in sol.sliding)]
    assert len(stuck) >= 1 and np.all(sol.samples[stuck, 1] == VALUES["v_belt"])
    assert sol.jacobian_valid
    assert np.allclose(sol.jacobian, J, rtol=0, atol=1e-9 * max(1.0, np.abs(J).max())), sol.jacobian - J


def test_the_stick_phase_is_exact_and_on_the_belt():
    """Dense samples in a stick: x = x0 + v_b (t - t0) and x' = v_b (the projection onto h = 0)."""
    m = friction_oscillator(**VALUES)
    sol = _simulate(m, [0.0, 0.0], 3, save=grazing.SaveAt(periods=3, trajectory=400))
    (t0, t1, _), *_ = sol.sliding
    x0 = sol.switches.state[np.argmin(np.abs(sol.switches.t - t0)), 0]  # (where the stick starts)
    inside = (sol.trajectory_t > t0) & (sol.trajectory_t < t1)
    assert inside.sum() > 10
    x_exact = x0 + VALUES["v_belt"] * (sol.trajectory_t[inside] - t0)
    assert np.abs(sol.trajectory[inside, 0] - x_exact).max() < 1e-12
    assert np.abs(sol.trajectory[inside, 1] - VALUES["v_belt"]).max() < 1e-12


def test_jacobian_and_sensitivities_against_differences_of_the_exact_flow():
    m = friction_oscillator(**VALUES)
    periods = 4
    names = ("mu", "v_belt")
    sol = _simulate(m, [0.3, -0.2], periods, tangent=Tangent(sensitivities=names))
    assert sol.sliding.shape[0] >= 2 and sol.jacobian_valid

    def final(x0, **changes):
        p = {**dict(m.params), **changes}
        return FrictionReference(p).run_long(np.asarray(x0, dtype=float), BEHIND, 0.0, sol.t_final)[0]

    eps = 1e-6
    fd = np.empty((2, 4))
    for c in range(2):
        dx = np.zeros(2)
        dx[c] = eps
        fd[:, c] = (final(np.array([0.3, -0.2]) + dx) - final(np.array([0.3, -0.2]) - dx)) / (2 * eps)
    for c, name in enumerate(names, start=2):
        value = m.params[name]
        fd[:, c] = (final([0.3, -0.2], **{name: value + eps}) - final([0.3, -0.2], **{name: value - eps})) / (
            2 * eps
        )
    assert np.allclose(sol.jacobian, fd, rtol=0, atol=1e-7 * max(1.0, np.abs(fd).max())), sol.jacobian - fd


def test_the_entry_saltation_matters_here():
    """A Jacobian without the entry saltation (S = I) differs by far more than the tolerance above."""
    ref = FrictionReference(dict(VALUES))
    t1 = 6 * 2 * math.pi / VALUES["omega"]
    _, _, J, events = ref.run_long(np.zeros(2), BEHIND, 0.0, t1)
    _, _, J0, _ = ref.run_long(np.zeros(2), BEHIND, 0.0, t1, entry_saltation=False)
    assert any(k == "stick" for _, k in events)
    assert np.abs(J - J0).max() > 1e-3


def test_lyapunov_exponents_through_sliding():
    """On the periodic stick-slip orbit: the largest exponent is the exact monodromy matrix's, per unit
    time; sticking collapses the other direction (rank one: -inf)."""
    m = friction_oscillator(**VALUES)
    sol = grazing.simulate(m, [0.0, 0.0], transient=60, periods=40, lyapunov=True)
    p = sol.period()
    assert p >= 1 and sol.sliding.shape[0] >= 10
    ref = FrictionReference(dict(VALUES))
    mode = m.mode_names.index(sol.mode_final)
    _, _, J, _ = ref.run_long(sol.x_final, mode, sol.t_final, sol.t_final + p * m.period)
    exact = math.log(np.abs(np.linalg.eigvals(J)).max()) / (p * m.period)
    assert abs(sol.lyapunov[0] - exact) < 1e-3 * max(1.0, abs(exact)), (sol.lyapunov, exact)
    assert sol.lyapunov[1] == -math.inf


def test_filippov_field_keeps_the_surface():
    """h_x f_s + h_t == 0 identically (symbolically), and the compiled pseudo-mode's field is f_s."""
    m = friction_oscillator(**VALUES)
    system = m.symbolic
    (sl,) = system.sliding_modes()
    sf = system.surfaces[sl.surface]
    fs = system.filippov_field(sl.surface)
    assert (
        sp.simplify(sum(sp.diff(sf.h, s) * f for s, f in zip(system.states, fs)) + sp.diff(sf.h, system.time))
        == 0
    )
    x = np.array([0.3, VALUES["v_belt"]])
    assert np.allclose(
        m.vector_field(x, 1.0, "sliding on 'belt'"), [VALUES["v_belt"], 0.0], rtol=0, atol=1e-15
    )


x_, v_, t_ = sp.symbols("x v t")
w_ = sp.Symbol("omega")


def opposing(surface: bool) -> HybridModel:
    """Two fields pushing into x = 0 from both sides, as transitions or as a surface with sliding."""
    modes = [Mode("up", [-1 + 0 * v_, sp.cos(w_ * t_)]), Mode("down", [1 + 0 * v_, sp.cos(w_ * t_)])]
    if surface:
        kw = {"surfaces": [Surface("wall", x_, "up", "down")]}
    else:
        kw = {"transitions": [Transition("touch", "up", "down", x_), Transition("leave", "down", "up", -x_)]}
    params = [Parameter("omega", 1.0, lower=0, lower_open=True)]
    return HybridModel("opposing", [x_, v_], t_, params, period=2 * sp.pi / w_, modes=modes, **kw)


def test_opposing_fields_slide_once_the_surface_is_declared():
    """Without a surface they end in one line (test_mode_switches); with it they slide, x = 0, v' = cos t."""
    sol = grazing.simulate(opposing(True), [1.0, 0.0], periods=3, jacobian=True)
    assert sol.mode_final == "sliding on 'wall'"
    assert sol.sliding.shape == (1, 3) and abs(sol.sliding[0, 0] - 1.0) < 1e-12
    assert abs(sol.sliding[0, 1] - sol.t_final) < 1e-12
    assert np.abs(sol.samples[:, 0]).max() < 1e-15
    assert np.allclose(sol.samples[:, 1], np.sin(sol.t), rtol=0, atol=1e-12)
    # d x_final / d x0: x0 moves the arrival time (x = 0 at t = x0), not the sliding state x = 0, v = sin t.
    assert np.allclose(sol.jacobian, [[0.0, 0.0], [0.0, 1.0]], rtol=0, atol=1e-12)


def test_sliding_stays_on_a_surface_that_its_rounded_field_leaves():
    """x' = -1 - x^2 above the diagonal h = x - y, 2 + sin(x)/2 below, y' = 1: from (1, 0) the motion reaches
    the diagonal where tan(pi/4 - t) = t and slides on it for good, x = y = t.  Filippov's field does not
    simplify here: its rounding drifts off the surface (3e-11 in 300 steps) unless the samples (and each
    step's end) are put back on it."""
    xs, ys, ts = sp.symbols("x y t")
    model = HybridModel(
        "diagonal", [xs, ys], ts, [Parameter("c", 1.0)], period=1, periodic=False,
        modes=[Mode("above", [-1 - xs**2 + 0 * sp.Symbol("c"), 1]), Mode("below", [2 + sp.sin(xs) / 2, 1])],
        surfaces=[Surface("diag", xs - ys, "above", "below")],
    )  # fmt: skip
    sol = grazing.simulate(model, [1.0, 0.0], periods=300)
    entry = brentq(lambda tt: math.tan(math.pi / 4 - tt) - tt, 0.1, 0.7, xtol=1e-15)
    assert sol.sliding.shape == (1, 3) and abs(sol.sliding[0, 0] - entry) < 1e-12
    assert sol.sliding[0, 1] == sol.t_final and sol.mode_final == "sliding on 'diag'"
    assert np.all(sol.samples[:, 0] == sol.samples[:, 1])  # on the surface, to the last bit
    assert np.abs(sol.samples[:, 0] - sol.t).max() < 1e-12 * sol.t[-1]  # (the time steps' rounding)


def test_sliding_intervals_of_the_sampled_span_across_chunks(monkeypatch):
    """After a transient and in chunks of two periods, the intervals are those of one whole run within
    the recorded span (it starts a period before the first sample), a stick split by a chunk joined."""
    from grazing.engine import simulate as simulate_module

    m = friction_oscillator(**VALUES)
    whole = _simulate(m, [0.0, 0.0], 13, phase=0.25)  # (samples, and chunks' ends, inside sticks)
    monkeypatch.setattr(simulate_module, "CHUNK_PERIODS", 2)
    part = grazing.simulate(m, [0.0, 0.0], transient=3, periods=10, phase=0.25)
    span = part.t[0] - m.period
    expected = whole.sliding[whole.sliding[:, 1] > span].copy()
    expected[0, 0] = max(expected[0, 0], span)
    assert part.sliding.shape == expected.shape and np.abs(part.sliding - expected).max() < 1e-9
    chunk_ends = part.t[0] + (np.arange(2, 13, 2) - 4) * m.period  # (at every second sample)
    assert any(a < tc < b for a, b, _ in part.sliding for tc in chunk_ends)  # a stick across a chunk's end
    assert np.array_equal(part.sliding, part.sliding[np.argsort(part.sliding[:, 0])])


def test_no_sliding_pseudo_mode_to_start_in():
    m = friction_oscillator()
    with pytest.raises(grazing.InvalidParameterError, match="cannot start in mode \"sliding on 'belt'\""):
        grazing.simulate(m, [0.0, 0.5], periods=1, mode="sliding on 'belt'")


@pytest.mark.parametrize("impacts", ["all", "sampled"])
@pytest.mark.parametrize("mode", ["slip_behind", "slip_ahead"])
def test_a_run_starting_on_the_belt_slides_from_its_start(impacts, mode):
    """Started on the belt (x' = v_b) where the friction holds the mass (|a cos(0) - x| < mu), the run
    sticks at t = 0 from either side: its first sliding interval starts there and ends at the exact
    stick's end, as its first stay in mode_spans() does (it was left out of Solution.sliding)."""
    m = friction_oscillator(**VALUES)
    ref = FrictionReference(dict(m.params))
    x0 = [0.8, VALUES["v_belt"]]
    assert abs(ref.force(x0[0], 0.0)) < VALUES["mu"]  # (stuck at once)
    sol = grazing.simulate(m, x0, periods=2, impacts=impacts, mode=mode)
    _, last, _, events = ref.run(np.array(x0), STICK, 0.0, sol.t_final)
    starts = [0.0] + [tz for tz, k in events if k == "stick"]
    ends = [tz for tz, k in events if k == "slip"] + ([sol.t_final] if last == STICK else [])
    assert len(starts) >= 2 and len(ends) == len(starts)
    assert sol.sliding.shape == (len(starts), 3) and np.all(sol.sliding[:, 2] == 0)
    assert np.abs(sol.sliding[:, 0] - starts).max() < 1e-12 and np.abs(sol.sliding[:, 1] - ends).max() < 1e-12
    stays = [(a, b) for a, b, k in sol.mode_spans() if k == STICK]
    assert np.abs(np.array(stays) - sol.sliding[:, :2]).max() < 1e-12
