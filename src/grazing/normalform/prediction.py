"""What happens past a grazing bifurcation, predicted from the grazing orbit alone.

Rules (sources in ``docs/normal-form.md``):

* ``kappa < 0`` (the paper's ``M12 < 0``): impacting period-one orbits exist
  before grazing (a saddle-node at ``mu < 0``); at grazing the response jumps to
  a stable period-one impacting orbit, with hysteresis (Nordmark 1991; the
  working notes' case C).
* ``kappa ~ 0``: resonant grazing, a codimension-two point (saddle-node and
  period-doubling curves emanate from it; Simpson & Ghosh 2026).  Near it the
  square-root coefficient is small and higher-order terms of the map matter,
  so the leading-order prediction is flagged as unreliable.
* Real multipliers ``0 < lambda_2 << lambda_1 = lambda < 1`` and
  ``kappa > 0``: the one-dimensional square-root map
  ``x -> lambda x + mu`` / ``mu - sqrt(x)`` (Nordmark 1991; Chin, Ott, Nusse &
  Grebogi 1994; the paper's eq. 21):

  - ``lambda < 1/4``: period adding with overlapping windows (hysteresis), no chaos;
  - ``1/4 < lambda < 2/3``: period adding with chaotic bands between the windows;
  - ``lambda > 2/3``: robust chaos.

* Otherwise (complex or negative multipliers): no one-line rule decides; the
  two-dimensional normal form ``u -> M D_mu(u) + b mu`` is iterated over a
  logarithmic range of ``mu`` past grazing and its attractors classified:
  windows whose period grows as ``mu -> 0`` separated by aperiodic bands is
  period adding with chaotic bands; windows without chaos is period adding;
  mostly aperiodic is robust chaos; a period-one impacting orbit for every
  ``mu`` is an immediate period-one impacting orbit; an attractor that does not
  shrink with ``mu`` (of the size of the kick even as ``mu -> 0``) or escapes
  leaves the neighbourhood: a jump to a distant attractor, about which the
  local theory says little.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from grazing.core.period import detect_period
from grazing.normalform.discontinuity import GrazingNormalForm

PERIOD_ADDING_CHAOS = "period-adding cascade with chaotic bands"
PERIOD_ADDING_OVERLAP = "period adding with overlapping windows (no chaos)"
ROBUST_CHAOS = "robust chaos"
PERIOD_ONE = "immediate stable period-one impacting orbit"
JUMP = "jump to a distant attractor"
RESONANT = "near-resonant grazing (kappa ~ 0): the leading-order map is unreliable"

RESONANCE_TOL = 0.05
"""|kappa| below this fraction of the largest monodromy entry counts as near-resonant."""

MU_RANGE = (1e-6, 3e-3)
"""Distances past grazing (in the unfolding parameter) over which scenarios are classified."""


@dataclass(frozen=True)
class Prediction:
    """The predicted scenario at one grazing point, and why.

    Attributes
    ----------
    scenario
        One of the module's scenario strings.
    rule
        Which rule decided: ``"kappa < 0"``, ``"resonance"``,
        ``"1-D map (eq. 21)"`` or ``"2-D normal form iteration"``.
    abs_lambda
        Largest nontrivial multiplier modulus.
    kappa
        The sign-deciding entry ``-grad(h) . M . e / |e|``.
    side
        Sign of the parameter change (of the unfolding parameter) that makes
        the orbit impact.
    windows
        From the 2-D iteration: ``(mu, period)`` pairs (period 0: aperiodic).

    Examples
    --------
    At the paper's first grazing at θ̂ = 40°: complex multipliers of modulus
    0.508, so no one-line rule; the 2-D normal form iterated past the grazing
    shows windows of period 7, 6, 5 ... separated by chaos (the paper's fig. 10):

    >>> import math, numpy as np, grazing
    >>> from grazing.normalform import find_grazing_point, normal_form_at
    >>> g = find_grazing_point(grazing.models.pendulum("B", theta_hat=math.radians(40)), "eta", 0.40, 0.47)
    >>> nf = normal_form_at(g, ("eta",))
    >>> p = predict(nf)
    >>> p.scenario, p.rule, round(p.abs_lambda, 4), p.side
    ('period-adding cascade with chaotic bands', '2-D normal form iteration', 0.5079, 1.0)
    >>> p.windows[0]  # (distance past the grazing, period)
    (1e-06, 7)
    """

    scenario: str
    rule: str
    abs_lambda: float
    kappa: float
    side: float
    windows: list[tuple[float, int]] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        return {
            "scenario": self.scenario,
            "rule": self.rule,
            "abs_lambda": self.abs_lambda,
            "kappa": self.kappa,
            "impacting_side": self.side,
            "windows": [[mu, p] for mu, p in self.windows],
        }


def impacting_side(nf: GrazingNormalForm, param: str) -> float:
    """+1 or -1: the direction of ``param`` in which the grazing orbit starts to impact."""
    b, h_p, rate_p = nf.unfolding[param]
    n = nf.monodromy.shape[0]
    # fixed point of the smooth map per unit mu, and the guard there
    u = np.linalg.solve(np.eye(n) - nf.monodromy, b)
    h = nf.grad_h @ u + h_p
    v = nf.grad_rate @ u + rate_p
    delta = v * v / (2 * nf.accel) - h  # per unit mu, to first order: -h
    return 1.0 if -h > 0 or (h == 0 and delta > 0) else -1.0


def iterate_normal_form(
    nf: GrazingNormalForm, param: str, mu: float | np.ndarray, n: int = 3000, keep: int = 400
) -> tuple[np.ndarray, np.ndarray]:
    """Iterate the 2-D normal form at ``mu``; return the last ``keep`` states and impact speeds.

    ``mu`` may be an array: the iterations for all its values run together
    (states ``(keep, len(mu), dim)``, speeds ``(keep, len(mu))``).  An
    iteration that escapes (beyond ``1e6 |mu|``) or stops being finite is NaN
    throughout.  The map is :meth:`GrazingNormalForm.normal_form`'s.
    """
    b, h_p, rate_p = nf.unfolding[param]
    M, e, a = nf.monodromy, nf.direction, nf.accel
    gh, gv = nf.grad_h, nf.grad_rate
    mus = np.atleast_1d(np.asarray(mu, dtype=float))
    dim = M.shape[0]
    u = np.zeros((mus.size, dim))
    states = np.empty((keep, mus.size, dim))
    speeds = np.empty((keep, mus.size))
    alive = np.ones(mus.size, dtype=bool)
    limit = 1e6 * (np.abs(mus) + 1e-12)
    b_mu, h_mu, rate_mu = np.outer(mus, b), h_p * mus, rate_p * mus

    def dot(w: np.ndarray, c: np.ndarray) -> np.ndarray:  # row by row, the same sums whatever the batch
        out = w[:, 0] * c[0]
        for i in range(1, dim):
            out = out + w[:, i] * c[i]
        return out

    for k in range(n):
        h = dot(u, gh) + h_mu
        v = dot(u, gv) + rate_mu
        delta = v * v / (2 * a) - h
        s = np.sqrt(np.where(delta > 0, 2 * a * delta, 0.0))
        kicked = u - s[:, None] * e
        u = np.stack([dot(kicked, M[r]) for r in range(dim)], axis=1) + b_mu
        bad = ~np.isfinite(u).all(axis=1) | (np.abs(u).max(axis=1) > limit)
        if bad.any():
            alive &= ~bad
            u[bad] = 0.0
        if k >= n - keep:
            states[k - (n - keep)] = u
            speeds[k - (n - keep)] = s
    states[:, ~alive] = np.nan
    speeds[:, ~alive] = np.nan
    if np.ndim(mu) == 0:
        return states[:, 0], speeds[:, 0]
    return states, speeds


def immediate_periodic(p: int) -> str:
    return PERIOD_ONE if p == 1 else f"immediate stable period-{p} impacting orbit"


def classify_iterates(mus: np.ndarray, periods: np.ndarray, sizes: np.ndarray, impacting: np.ndarray) -> str:
    """Name the scenario from attractors at increasing distance ``mus`` past grazing.

    ``periods`` (0 aperiodic), ``sizes`` (attractor extent about the grazing
    orbit; nan if it escaped) and ``impacting`` per ``mu``.  A local attractor
    shrinks as ``mu -> 0`` (like ``sqrt(mu)``: the square-root kick); one that
    keeps its size over the smallest decade of ``mu`` has left the
    neighbourhood.
    """
    if np.any(np.isnan(sizes)):
        return JUMP
    periodic = periods > 0
    single = sorted(set(periods.tolist()))
    if len(single) == 1 and single[0] > 0 and np.all(impacting):
        return immediate_periodic(single[0])
    decade = mus <= mus[0] * 10
    if decade.sum() >= 2 and np.median(sizes[decade]) > 0.5 * np.median(sizes[-max(2, decade.sum()) :]):
        return JUMP
    window_periods = sorted(set(periods[periodic & impacting].tolist()))
    chaotic = int((~periodic).sum())
    if chaotic > 0.8 * periods.size:
        return ROBUST_CHAOS
    if len(window_periods) >= 2:
        return PERIOD_ADDING_CHAOS if chaotic else PERIOD_ADDING_OVERLAP
    if len(window_periods) == 1:
        p = window_periods[0]
        return immediate_periodic(p) if not chaotic else f"chaos with a period-{p} window"
    return ROBUST_CHAOS if chaotic else RESONANT


def predict(nf: GrazingNormalForm, param: str | None = None, mu_range: tuple[float, float] = MU_RANGE,
            points: int = 60) -> Prediction:  # fmt: skip
    """Predict the scenario past this grazing point when ``param`` is varied.

    ``param`` is one of the normal form's unfolding parameters (default: the first).

    Parameters
    ----------
    nf
        The normal form at the grazing point (:func:`~grazing.normalform.normal_form_at`).
    param
        The unfolding parameter varied.
    mu_range
        Distances past the grazing (in ``param``) at which the 2-D normal form
        is iterated, where no one-line rule decides.
    points
        Number of distances, spaced logarithmically.

    Returns
    -------
    Prediction
        The scenario, the rule that decided it and the numbers it used.

    Examples
    --------
    >>> import math, grazing
    >>> from grazing.orbits import find_grazings
    >>> from grazing.normalform import normal_form_at
    >>> g, _ = find_grazings(grazing.models.pendulum("B", theta_hat=math.radians(40)), "eta", 0.4, 0.47)
    >>> predict(normal_form_at(g[0], ("eta",))).scenario
    'period-adding cascade with chaotic bands'
    """
    mu_mult = nf.multipliers
    lam = float(np.max(np.abs(mu_mult)))
    kappa = nf.kappa
    param = param if param is not None else next(iter(nf.unfolding))
    side = impacting_side(nf, param)
    if abs(kappa) < RESONANCE_TOL * float(np.max(np.abs(nf.monodromy))):
        return Prediction(RESONANT, "resonance", lam, kappa, side)
    if kappa < 0:
        return Prediction(PERIOD_ONE, "kappa < 0", lam, kappa, side)
    if np.all(np.abs(mu_mult.imag) < 1e-12):
        l1, l2 = sorted(mu_mult.real, key=abs, reverse=True)
        if 0 < l1 < 1 and abs(l2) < 0.1 * l1:
            if l1 < 0.25:
                scen = PERIOD_ADDING_OVERLAP
            elif l1 < 2 / 3:
                scen = PERIOD_ADDING_CHAOS
            else:
                scen = ROBUST_CHAOS
            return Prediction(scen, "1-D map (eq. 21)", lam, kappa, side)
    mus = np.geomspace(*mu_range, points)
    periods = np.zeros(points, dtype=int)
    sizes = np.zeros(points)
    impacting = np.zeros(points, dtype=bool)
    all_states, all_speeds = iterate_normal_form(nf, param, side * mus)
    for i in range(points):
        states, speeds = all_states[:, i], all_speeds[:, i]
        if np.any(np.isnan(states)):
            sizes[i] = np.nan
            continue
        sizes[i] = float(np.max(np.abs(states)))
        tol = 1e-9 * max(1.0, sizes[i])
        periods[i] = detect_period(states, tol=tol, max_period=64)
        impacting[i] = bool(np.any(speeds > 0))
    scen = classify_iterates(mus, periods, sizes, impacting)
    windows = list(zip(mus.tolist(), periods.tolist()))
    return Prediction(scen, "2-D normal form iteration", lam, kappa, side, windows)


def predicted_windows(lam: float, n_max: int = 12) -> list[tuple[int, float, float]]:
    """Stability intervals of the period-n orbits of the 1-D map in the scaled parameter.

    For ``x -> lambda x + mu_hat`` (x <= 0), ``mu_hat - sqrt(x)`` (x > 0), the
    orbit with one impact and ``n - 1`` free periods is stable for ``mu_hat`` in
    ``(3 (1-l) l^(2n-2) / (4 (1-l^n)), (1-l)^2 l^(2n-4) / (1-l^(n-1))^2)``
    (flip at the lower end, border collision at the upper); empty intervals
    are omitted.  Windows accumulate at 0 with ratio ``lambda^2``; for large
    ``n`` they are non-empty iff ``lambda < 2/3`` (``3 lambda^2 / 4 < 1 - lambda``)
    and neighbours overlap iff ``lambda < 1/4``; a few low-period windows
    survive above 2/3.

    Parameters
    ----------
    lam
        The multiplier ``lambda`` of the 1-D map, in (0, 1).
    n_max
        The longest period considered.

    Returns
    -------
    list of (int, float, float)
        ``(n, lower, upper)``: each period-n window's interval of ``mu_hat``.

    Examples
    --------
    >>> [n for n, lo, hi in predicted_windows(0.5, 6)]
    [2, 3, 4, 5, 6]

    Above 2/3 only a few low-period windows are left (robust chaos between them):

    >>> [n for n, lo, hi in predicted_windows(0.8, 12)]
    [2, 3, 4]
    """
    out = []
    for n in range(2, n_max + 1):
        lo = 3 * (1 - lam) * lam ** (2 * n - 2) / (4 * (1 - lam**n))
        hi = (1 - lam) ** 2 * lam ** (2 * n - 4) / (1 - lam ** (n - 1)) ** 2
        if lo < hi:
            out.append((n, lo, hi))
    return out


@dataclass(frozen=True)
class Observation:
    """What direct simulation of the impacting system shows just past a grazing point (:func:`observe`).

    Parameters
    ----------
    scenario
        The scenario named from the runs (as :class:`Prediction`'s).
    offsets
        The distances ``mu`` past the grazing that were simulated.
    periods
        The period of each run's attractor (0: aperiodic).
    sizes
        Each attractor's largest distance from the grazing orbit.
    impacting
        Whether each attractor impacts.

    Examples
    --------
    Simulated past the paper's first grazing at θ̂ = 40°: the period-adding
    cascade of fig. 10, periods 7, 6, 5, 4 with chaos between:

    >>> import math, numpy as np, grazing
    >>> from grazing.normalform import find_grazing_point, normal_form_at
    >>> g = find_grazing_point(grazing.models.pendulum("B", theta_hat=math.radians(40)), "eta", 0.40, 0.47)
    >>> nf = normal_form_at(g, ("eta",))
    >>> obs = observe(nf)
    >>> obs.scenario, obs.periods[::3]
    ('period-adding cascade with chaotic bands', [7, 7, 7, 7, 6, 6, 5, 0])
    >>> all(obs.impacting), len(obs.offsets)
    (True, 24)
    """

    scenario: str
    offsets: list[float]
    periods: list[int]
    sizes: list[float]
    impacting: list[bool]


def observe(nf: GrazingNormalForm, param: str | None = None, mu_range: tuple[float, float] = MU_RANGE,
            points: int = 24, transient: int = 1500, periods: int = 200) -> Observation:  # fmt: skip
    """Simulate the real system at ``param* + side * mu`` and classify like :func:`predict`.

    ``param`` is one of the normal form's unfolding parameters (default: the first).

    Every run starts from the grazing orbit (on the section through the
    contact), so that the attractor reached is the one born at grazing; the
    attractor's size is its largest distance from the grazing orbit.

    Parameters
    ----------
    nf
        The normal form at the grazing point.
    param
        The unfolding parameter varied.
    mu_range
        Distances past the grazing (in ``param``) simulated.
    points
        Number of distances, spaced logarithmically.
    transient, periods
        Forcing periods run before sampling, and sampled, at each distance.

    Returns
    -------
    Observation
        The scenario and each run's period, size and impacts.

    Examples
    --------
    Fewer, shorter runs than the default, past the paper's first grazing at
    θ̂ = 40°: the windows' periods fall as the distance grows:

    >>> import math, grazing
    >>> from grazing.normalform import find_grazing_point, normal_form_at
    >>> g = find_grazing_point(grazing.models.pendulum("B", theta_hat=math.radians(40)), "eta", 0.40, 0.47)
    >>> observe(normal_form_at(g, ("eta",)), points=6, transient=500, periods=100).periods
    [7, 7, 7, 6, 5, 4]
    """
    from grazing.engine.simulate import simulate

    param = param if param is not None else next(iter(nf.unfolding))
    side = impacting_side(nf, param)
    mus = np.geomspace(*mu_range, points)
    p0 = nf.model.params[param]
    t0 = nf.point.t_graze
    per = np.zeros(points, dtype=int)
    sizes = np.zeros(points)
    imp = np.zeros(points, dtype=bool)
    for i, mu in enumerate(mus):
        m = nf.model.with_params(**{param: p0 + side * mu})
        x0 = nf.contact.copy()
        if m.guard(x0, t0, nf.point.stop) < 0:
            x0 = x0 + 1e-12 * nf.grad_h / float(nf.grad_h @ nf.grad_h)  # start on the allowed side
        sol = simulate(m, x0, t0=t0, transient=transient, periods=periods,
                       phase=2 * np.pi * (t0 / m.period % 1.0))  # fmt: skip
        sizes[i] = float(np.max(np.abs(sol.samples - nf.contact)))
        per[i] = sol.period()
        imp[i] = len(sol.impacts) > 0
    scen = classify_iterates(mus, per, sizes, imp)
    return Observation(scen, mus.tolist(), per.tolist(), sizes.tolist(), imp.tolist())
