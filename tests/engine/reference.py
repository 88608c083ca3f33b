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
    scipy fails or the impacts accumulate.
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
                break
            count += 1
            if count > MAX_IMPACTS_PER_PERIOD:
                raise RuntimeError(f"impacts accumulate near t = {t}: the reference does not follow sticking")
            j = next(j for j in stops if sol.t_events[j].size)  # the stop whose event ended the run
            imp_t.append(t)
            imp_x.append(x.copy())
            imp_v.append(abs(float(rate[j](list(x), t, p))))
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

    The impact count must be equal; times, states before impact and samples
    must agree to ``atol`` times the state's scale.  Returns the reference.
    """
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
