"""A slow, obviously right reference for the engine: scipy's DOP853 with event location.

Nothing of grazing's engine is used: the vector field, the guard and the reset
are the model's own sympy expressions turned into numpy functions by
``sympy.lambdify`` (:meth:`grazing.HybridModel.numeric`), the integrator is
``scipy.integrate.solve_ivp`` with one terminal event per stop on
``h(x, t) = 0`` crossed downwards, a step at most ``T / STEPS_PER_PERIOD``
(events are only seen between steps), and an impact restarts the integration
from that stop's ``g(x, t)``.
It works for any model without sticking (an impact sequence that accumulates
is refused, not followed) and is a few hundred times slower than the engine,
which is why it checks short spans.

Two integrators agree only as far as the trajectory lets them: along a chaotic
or near-grazing trajectory the last bits of each (the reference's depend on the
BLAS kernel numpy's dot products use) are amplified without bound, and the
comparison's outcome would depend on the machine.  :func:`assert_agrees`
therefore first measures how much the trajectory amplifies a perturbation of its
initial state (:func:`amplification`) and refuses an ill-conditioned
comparison instead of deciding it by rounding.

Example
-------
>>> import math, grazing
>>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
>>> ref = scipy_reference(m, [0.0, 0.0], periods=4)
>>> ref.samples.shape, ref.impacts_t.round(6)
((4, 2), array([21.017321]))
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

import grazing

RTOL, ATOL = 1e-12, 1e-13
"""DOP853 tolerances: tight enough that the reference's own error is far below the comparisons'."""

STEPS_PER_PERIOD = 500
"""At least this many steps per forcing period.  solve_ivp looks for events only
between steps, so an excursion through the stop shorter than one step is missed:
with steps of T/500 the pendulum's slowest impact it sees is ~1e-3 (a grazing
impact is by nature resolved by neither integrator alone)."""

MAX_IMPACTS_PER_PERIOD = 200
"""More impacts than this in one forcing period means an accumulation (chattering): refused."""

SLOWEST_IMPACT = 1e-7
"""An impact slower than this (times the state's scale) is refused as the sign of an accumulation.

A chattering sequence's speeds fall geometrically (by r per impact); followed to the
last bits, the reset state lies on the wrong side of the stop by rounding and the
reference either counts hundreds of impacts or lets the state fall through the stop
unseen, depending on the machine.  Refusing at 1e-7, some 25 impacts before rounding
decides anything, makes the refusal deterministic.  No comparison loses by it: an
impact that slow is resolved by neither integrator to the comparisons' 1e-8 (near
grazing an error e in position moves the impact speed by about e / speed)."""

PROBE = 1e-10
"""Relative size of the perturbation of the initial state by which :func:`amplification`
measures how much a trajectory amplifies errors (far above both integrators' rounding,
far below anything nonlinear on a well-conditioned trajectory)."""

MAX_AMPLIFICATION = 1e3
"""The largest amplification :func:`assert_agrees` accepts.  Both integrators' own errors
are ~1e-13 (the reference's steps are capped at T/500, so its truncation error is below
its rounding); amplified 1e3 times they stay near 1e-10, a hundredth of the comparisons'
1e-8, so the outcome cannot depend on the last bits of either.  Along a chaotic
trajectory the amplification passes 1e3 within a few periods (the impact oscillator's
default parameters: ~7 after 10 periods, ~1e4 after 20, ~1e7 after 30)."""


@dataclass(frozen=True)
class Reference:
    """Samples at ``t0 + k T`` (k = 1..periods) and every impact (time, state before, speed, stop)."""

    t: np.ndarray
    samples: np.ndarray
    impacts_t: np.ndarray
    impacts_x: np.ndarray
    impacts_speed: np.ndarray
    impacts_stop: np.ndarray


def scipy_reference(
    model: grazing.HybridModel, x0, *, t0: float = 0.0, periods: int = 10, phase: float = 0.0
) -> Reference:
    """Integrate ``model`` from ``x0`` at ``t0`` and sample once per forcing period.

    The samples are taken at the ``periods`` times ``t = (phase/2pi + k) T``
    after ``t0`` (the forcing phase is absolute), grazing's convention for
    ``simulate(..., t0=t0, phase=phase)`` without a transient.  Raises ``RuntimeError`` when
    scipy fails, the impacts accumulate (more than ``MAX_IMPACTS_PER_PERIOD`` in a period, or
    one slower than ``SLOWEST_IMPACT``) or the state is found beyond a stop it crossed unseen.
    """
    f = model.numeric("f")
    stops = range(model.n_stops)
    h = [model.numeric("h", j) for j in stops]
    g = [model.numeric("g", j) for j in stops]
    rate = [model.numeric("rate", j) for j in stops]
    p = list(model.param_vector)
    period = model.period
    max_step = period / STEPS_PER_PERIOD

    def rhs(t, x):
        return np.asarray(f(list(x), t, p), dtype=float).ravel()

    def event(j):
        def hit(t, x):
            return float(h[j](list(x), t, p))

        hit.terminal, hit.direction = True, -1  # leaving the allowed region h > 0
        return hit

    events = [event(j) for j in stops]

    # the first sample is the first time after t0 at the forcing phase (grazing's convention)
    first = (math.floor(t0 / period) + (phase % (2 * math.pi)) / (2 * math.pi)) * period
    if first <= t0 + 1e-9 * period:
        first += period
    t, x = float(t0), np.asarray(x0, dtype=float)
    times, samples, imp_t, imp_x, imp_v, imp_s = [], [], [], [], [], []
    for k in range(1, periods + 1):
        t_k = first + (k - 1) * period
        count = 0
        while True:
            sol = solve_ivp(
                rhs, (t, t_k), x, method="DOP853", rtol=RTOL, atol=ATOL, events=events, max_step=max_step
            )
            if sol.status == -1:
                raise RuntimeError(f"solve_ivp failed at t = {t}: {sol.message}")
            t, x = float(sol.t[-1]), sol.y[:, -1].copy()
            if sol.status != 1:
                beyond = [
                    j for j in stops if h[j](list(x), t, p) < -SLOWEST_IMPACT * max(1.0, np.max(np.abs(x)))
                ]
                if beyond:
                    raise RuntimeError(f"at t = {t} the state is beyond stop {beyond[0]}, crossed unseen")
                break
            count += 1
            if count > MAX_IMPACTS_PER_PERIOD:
                raise RuntimeError(f"impacts accumulate near t = {t}: the reference does not follow sticking")
            j = next(j for j in stops if sol.t_events[j].size)  # the stop whose event ended the run
            speed = abs(float(rate[j](list(x), t, p)))
            if speed < SLOWEST_IMPACT * max(1.0, float(np.max(np.abs(x)))):
                raise RuntimeError(
                    f"an impact at speed {speed:.1e} near t = {t}: impacts accumulate (or graze) below what "
                    "the reference resolves; it does not follow sticking"
                )
            imp_t.append(t)
            imp_x.append(x.copy())
            imp_v.append(speed)
            imp_s.append(j)
            x = np.asarray(g[j](list(x), t, p), dtype=float).ravel()
        times.append(t_k)
        samples.append(x.copy())
    n = model.n_states
    return Reference(
        t=np.array(times),
        samples=np.array(samples).reshape(-1, n),
        impacts_t=np.array(imp_t),
        impacts_x=np.array(imp_x).reshape(-1, n),
        impacts_speed=np.array(imp_v),
        impacts_stop=np.array(imp_s, dtype=int),
    )


def amplification(
    model: grazing.HybridModel, x0, *, t0: float = 0.0, periods: int = 10, phase: float = 0.0
) -> float:
    """How much the trajectory from ``x0`` amplifies a perturbation of its initial state.

    The engine is run from ``x0`` and from ``x0`` moved by ``PROBE`` (times the state's
    scale) along two directions (all components up; alternately up and down); the
    result is the largest difference of the impact times, states before impact and
    samples (scaled as :func:`assert_agrees` scales them) divided by ``PROBE``, and
    infinity when the impact sequence changes.  It is a property of the trajectory, not
    of the integrator: ~1 on a stable attractor, growing exponentially along a chaotic
    trajectory.  Cheap (three engine runs), so it is measured before the reference runs.

    Example
    -------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> amplification(m, [0.0, 0.0], periods=20) < 100      # transient to the stable period-5 orbit
    True
    >>> m = grazing.models.impact_oscillator()               # chaotic at its default parameters
    >>> amplification(m, [0.0, 0.8], t0=0.4, periods=30) > 1e6
    True
    """
    x0 = np.asarray(x0, dtype=float)

    def run(x):
        return grazing.simulate(model, x, t0=t0, phase=phase, periods=periods, impacts="all")

    base = run(x0)
    scale = max(1.0, float(np.max(np.abs(x0))), float(np.max(np.abs(base.samples))))
    t_scale = max(1.0, abs(float(base.t[-1])))
    worst = 0.0
    for direction in (np.ones(x0.size), (-1.0) ** np.arange(x0.size)):
        moved = run(x0 + PROBE * scale * direction)
        if len(moved.impacts) != len(base.impacts) or np.any(moved.impacts.stop != base.impacts.stop):
            return math.inf
        differences = [np.abs(moved.samples - base.samples).max() / scale]
        if len(base.impacts):
            differences.append(np.abs(moved.impacts.t - base.impacts.t).max() / t_scale)
            differences.append(np.abs(moved.impacts.state - base.impacts.state).max() / scale)
        worst = max(worst, *differences)
    return float(worst / PROBE)


def well_conditioned_periods(
    model: grazing.HybridModel, x0, *, t0: float = 0.0, periods: int = 10, phase: float = 0.0
) -> int:
    """The longest horizon, at most ``periods``, over which :func:`assert_agrees` may compare (0: none).

    For property tests that draw chaotic cases too: they compare each case while errors
    stay below ``MAX_AMPLIFICATION`` times their size, and discard it if even one period
    amplifies them more.
    """
    for n in range(periods, 0, -1):
        if amplification(model, x0, t0=t0, periods=n, phase=phase) <= MAX_AMPLIFICATION:
            return n
    return 0


def assert_agrees(
    model: grazing.HybridModel,
    x0,
    *,
    t0: float = 0.0,
    periods: int = 10,
    phase: float = 0.0,
    atol: float = 1e-8,
) -> Reference:
    """``simulate`` and :func:`scipy_reference` give the same impacts and samples (to ``atol``, scaled).

    First the comparison must be well-conditioned: the trajectory may amplify a
    perturbation of its initial state at most ``MAX_AMPLIFICATION`` times
    (:func:`amplification`), otherwise the comparison is refused (an ``AssertionError``
    naming it: compare fewer periods, or on a stable attractor).  Then the impact count
    and stops must be equal; times, states before impact and samples must agree to
    ``atol`` times the state's scale.  Returns the reference.
    """
    growth = amplification(model, x0, t0=t0, periods=periods, phase=phase)
    assert growth <= MAX_AMPLIFICATION, (
        f"{model.name}: ill-conditioned comparison: over {periods} periods a perturbation of the initial "
        f"state grows {growth:.1e} times (at most {MAX_AMPLIFICATION:.0e} allowed), so rounding, not the "
        "engine, would decide it; compare fewer periods or on a stable attractor"
    )
    ref = scipy_reference(model, x0, t0=t0, periods=periods, phase=phase)
    sol = grazing.simulate(model, x0, t0=t0, phase=phase, periods=periods, impacts="all")
    scale = max(1.0, float(np.max(np.abs(ref.samples))))
    np.testing.assert_allclose(sol.t, ref.t, rtol=0, atol=1e-12 * max(1.0, abs(ref.t[-1])))
    assert len(sol.impacts) == len(ref.impacts_t), (
        f"{model.name}: {len(sol.impacts)} impacts, scipy finds {len(ref.impacts_t)}"
    )
    np.testing.assert_array_equal(sol.impacts.stop, ref.impacts_stop, err_msg=f"{model.name}: stops hit")
    np.testing.assert_allclose(sol.impacts.t, ref.impacts_t, rtol=0, atol=atol * max(1.0, ref.t[-1]))
    np.testing.assert_allclose(sol.impacts.state, ref.impacts_x, rtol=0, atol=atol * scale)
    np.testing.assert_allclose(sol.samples, ref.samples, rtol=0, atol=atol * scale)
    return ref
