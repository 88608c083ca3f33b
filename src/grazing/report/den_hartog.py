"""Den Hartog's exact non-stop motion of the forced Coulomb oscillator, against grazing's orbits.

With the belt at rest (``v_belt = 0``) the built-in ``friction-oscillator`` is ::

    x'' + x = a cos(omega t) - mu sgn(x')

J. P. Den Hartog, "Forced vibrations with combined Coulomb and viscous friction",
Trans. ASME APM-53-9 (1931) 107-115, solved its symmetric steady motion without
stops exactly (see also S. W. Shaw, "On the dynamic response of a system with dry
friction", J. Sound Vib. 108 (1986) 305-325).  Re-derived here (docs/den-hartog.md):
over the half-period ``0 < s < pi/omega`` after the velocity reversal at
``x = -X``, ``x = -mu + K cos(omega s + psi) + mu cos s + mu U sin s`` with
``K = a / (1 - omega^2)`` and ``U = tan(pi / (2 omega))``; so

    X = sqrt(K^2 - (mu U / omega)^2)                       (the amplitude)

and the mass leaves the reversal (does not stick, static = kinetic friction) while
the force there, ``a cos(psi) + X = omega^2 X``, is at least ``mu``:

    mu / a <= omega^2 / (|1 - omega^2| sqrt(1 + omega^2 U^2))   (the boundary)

This module computes both, grazing's periodic orbits and their amplitudes, and the
boundary of non-stop motion located on grazing's orbits (the friction at which the
orbit first sticks), for the page ``docs/den-hartog.md`` and ``tests/report/test_den_hartog.py``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import brentq

from grazing.engine.simulate import simulate
from grazing.errors import ConvergenceError, InvalidParameterError
from grazing.models.friction_oscillator import friction_oscillator
from grazing.orbits.periodic import PeriodicOrbit
from grazing.orbits.shooting import find_orbit

if TYPE_CHECKING:
    from matplotlib.figure import Figure

AMPLITUDE_RULE = 1e-9
"""The rule of the comparison: ``|X_grazing - X_closed| <= 1e-9 a`` where the motion has no stops."""

SECTION_TRIES = 8
"""Sections ``t0 = k T / 8`` tried in turn by :func:`orbit_at` (find_orbit cannot start sticking)."""

MARGIN_TOL = 1e-9
"""At a crossing-sliding the stick margin passes through zero: within this of it at the located boundary."""

BOUNDARY_RULE = 1e-9
"""The rule for the boundary of non-stop motion: ``|mu/a (grazing) - mu/a (Den Hartog)| <= 1e-9``."""


def amplitude(omega: float, mu_ratio: float) -> float:
    """Den Hartog's amplitude ``X / a`` of the non-stop motion (nan where it has none).

    Parameters
    ----------
    omega
        Forcing frequency (the natural frequency is 1); not 1 nor ``1 / (2k + 1)``.
    mu_ratio
        ``mu / a``, the friction force over the forcing amplitude.

    Returns
    -------
    float
        ``sqrt(K^2 - (mu_ratio U / omega)^2)``, ``K = 1 / (1 - omega^2)``, ``U = tan(pi / (2 omega))``;
        nan where the square is negative.

    Examples
    --------
    >>> round(amplitude(2.0, 0.0), 12)   # no friction: |1 / (1 - omega^2)|
    0.333333333333
    """
    k = 1.0 / (1.0 - omega * omega)
    u = math.tan(math.pi / (2.0 * omega))
    square = k * k - (mu_ratio * u / omega) ** 2
    return math.sqrt(square) if square >= 0.0 else math.nan


def boundary(omega: float) -> float:
    """Den Hartog's boundary of non-stop motion: the largest ``mu / a`` without stops.

    Parameters
    ----------
    omega
        Forcing frequency (at 1 exactly: the limit ``pi / 4``).

    Returns
    -------
    float
        ``omega^2 / (|1 - omega^2| sqrt(1 + omega^2 U^2))``, ``U = tan(pi / (2 omega))``.

    Examples
    --------
    >>> round(boundary(1.0 + 1e-7), 5), round(math.pi / 4, 5), boundary(1.0) == math.pi / 4  # at resonance
    (0.7854, 0.7854, True)
    """
    if omega == 1.0:  # (0 / 0: the limit, where the work of the friction, 4 mu X a period, is the forcing's)
        return math.pi / 4.0
    u = math.tan(math.pi / (2.0 * omega))
    return omega * omega / (abs(1.0 - omega * omega) * math.sqrt(1.0 + (omega * u) ** 2))


def _half_period_constants(omega: float, mu_ratio: float) -> tuple[float, float, float]:
    """``K = 1 / (1 - omega^2)``, ``U = tan(pi / 2 omega)`` and the phase ``psi`` (``K cos psi = -X``) of
    Den Hartog's motion after a reversal (:func:`closed_form_velocity`)."""
    k = 1.0 / (1.0 - omega * omega)
    u = math.tan(math.pi / (2.0 * omega))
    x = amplitude(omega, mu_ratio)
    return k, u, math.atan2(mu_ratio * u / (k * omega), -x / k)


def closed_form_velocity(omega: float, mu_ratio: float, s: np.ndarray) -> np.ndarray:
    """The velocity ``x'(s) / a`` of Den Hartog's motion, ``s`` after a reversal at ``x = -X``.

    It must stay positive on ``0 < s < pi / omega`` for the motion to be the non-stop one: at low
    frequencies it does not (the closed form then describes no motion of the oscillator).

    Parameters
    ----------
    omega, mu_ratio
        As :func:`amplitude`.
    s
        Times after the reversal.

    Returns
    -------
    numpy.ndarray
        ``-K omega sin(omega s + psi) - mu sin s + mu U cos s`` (``a = 1``), ``K cos psi = -X``.

    Examples
    --------
    >>> float(closed_form_velocity(2.0, 0.1, np.array([0.0]))[0]) == 0.0
    True
    """
    k, u, psi = _half_period_constants(omega, mu_ratio)
    s = np.asarray(s, dtype=float)
    return -k * omega * np.sin(omega * s + psi) - mu_ratio * np.sin(s) + mu_ratio * u * np.cos(s)


def closed_form_acceleration(omega: float, mu_ratio: float, s: np.ndarray) -> np.ndarray:
    """The acceleration ``x''(s) / a`` of Den Hartog's motion (:func:`closed_form_velocity`'s derivative).

    Parameters
    ----------
    omega, mu_ratio
        As :func:`amplitude`.
    s
        Times after the reversal.

    Returns
    -------
    numpy.ndarray
        ``-K omega^2 cos(omega s + psi) - mu cos s - mu U sin s`` (``a = 1``).

    Examples
    --------
    >>> w, r = 2.0, 0.1   # at the reversal: omega^2 X - mu
    >>> bool(abs(closed_form_acceleration(w, r, np.array([0.0]))[0] - (w * w * amplitude(w, r) - r)) < 1e-12)
    True
    """
    k, u, psi = _half_period_constants(omega, mu_ratio)
    s = np.asarray(s, dtype=float)
    return -k * omega * omega * np.cos(omega * s + psi) - mu_ratio * np.cos(s) - mu_ratio * u * np.sin(s)


def min_velocity(omega: float, mu_ratio: float, n_grid: int = 4000) -> float:
    """The smallest velocity of Den Hartog's motion inside its half-period ``0 < s < pi / omega``.

    The interior minimum on a grid of ``n_grid`` intervals, refined where the acceleration vanishes
    (Brent's method); ``+inf`` without an interior minimum (the velocity rises, then falls).

    Parameters
    ----------
    omega, mu_ratio
        As :func:`amplitude`.
    n_grid
        Grid intervals on the half-period.

    Returns
    -------
    float
        ``min x'(s) / a``: negative where the closed form's velocity changes sign inside the half-period
        (it then is no motion of the oscillator).

    Examples
    --------
    >>> bool(min_velocity(2.0, 0.1) > 0), bool(min_velocity(0.45, 0.3) < 0)
    (True, True)
    """
    s = np.linspace(0.0, math.pi / omega, n_grid + 1)
    acc = closed_form_acceleration(omega, mu_ratio, s)
    best = math.inf
    for i in range(1, n_grid - 1):
        if acc[i] < 0.0 <= acc[i + 1]:  # a local minimum of the velocity in (s_i, s_i+1]
            root = brentq(
                lambda t: float(closed_form_acceleration(omega, mu_ratio, np.array([t]))[0]),
                float(s[i]),
                float(s[i + 1]),
                xtol=1e-15,
            )
            best = min(best, float(closed_form_velocity(omega, mu_ratio, np.array([root]))[0]))
    return best


def nonstop_boundary(omega: float) -> float:
    """The boundary of non-stop motion from the closed form with the velocity's sign checked as well.

    Den Hartog's :func:`boundary` asks only that the mass leave each reversal; the motion also needs
    its velocity of one sign between reversals.  Where :func:`min_velocity` at the boundary is
    negative, the largest ``mu / a`` where it is zero (Brent's method) is the boundary instead.

    Parameters
    ----------
    omega
        Forcing frequency.

    Returns
    -------
    float
        ``min(boundary(omega), the velocity's limit)``.

    Examples
    --------
    >>> nonstop_boundary(2.0) == boundary(2.0), bool(nonstop_boundary(0.45) < boundary(0.45))
    (True, True)
    """
    top = boundary(omega)
    if omega == 1.0 or min_velocity(omega, top) >= 0.0:  # (at resonance the motion grows: no velocity limit)
        return top
    grid = np.linspace(0.0, top, 41)[1:]
    prev = grid[0]
    for r in grid:
        if min_velocity(omega, float(r)) < 0.0:
            lowest = lambda q: min(min_velocity(omega, q), 1.0)  # noqa: E731
            return float(brentq(lowest, float(prev), float(r), xtol=1e-14))
        prev = r
    return top


@dataclass(frozen=True)
class Reversals:
    """The velocity reversals of a periodic orbit over one period (its arrivals at ``x' = 0``).

    Attributes
    ----------
    t, x
        Times and positions of the arrivals (slips onto the belt surface, crossing or sticking).
    sticks
        Whether each arrival sticks (enters sliding on the surface).
    margin
        ``min |a cos(omega t) - x| - mu`` over the arrivals: positive while the orbit never stops,
        negative once it sticks; zero at the boundary.
    """

    t: np.ndarray
    x: np.ndarray
    sticks: np.ndarray
    margin: float

    @property
    def amplitude(self) -> float:
        """``max |x|`` at the reversals (the motion's amplitude)."""
        return float(np.max(np.abs(self.x)))


def reversals(orbit: PeriodicOrbit) -> Reversals:
    """The velocity reversals of a friction oscillator's periodic orbit, simulated over one period.

    Parameters
    ----------
    orbit
        A periodic orbit of ``friction-oscillator`` (any belt speed).

    Returns
    -------
    Reversals
        Every switch that leaves a slip mode, in time order.

    Examples
    --------
    >>> from grazing.orbits import find_orbit
    >>> r = reversals(find_orbit(friction_oscillator(omega=2.0, mu=0.1, v_belt=0.0)))
    >>> len(r.t), bool(r.margin > 0)
    (2, True)
    """
    model = orbit.model
    sol = simulate(model, orbit.state, t0=orbit.t0, periods=orbit.period, impacts="all", mode=orbit.mode)
    sw = sol.switches
    slips = {"slip_ahead", "slip_behind"}
    keep = np.array([sw.source(i) in slips for i in range(len(sw))], dtype=bool)
    t, x = sw.t[keep], sw.state[keep, 0]
    sticks = np.array([sw.target(i) not in slips for i in range(len(sw)) if keep[i]], dtype=bool)
    p = model.params
    force = np.abs(p["a"] * np.cos(p["omega"] * t) - x)
    margin = float(np.min(force) - p["mu"]) if len(t) else math.nan
    return Reversals(t, x, sticks, margin)


@dataclass(frozen=True)
class AmplitudePoint:
    """One computed orbit against Den Hartog's amplitude.

    Attributes
    ----------
    omega, mu_ratio
        The parameters (``a = 1``).
    computed
        ``max |x|`` at the orbit's reversals.
    closed
        :func:`amplitude`.
    sticks
        Whether the computed orbit sticks anywhere (then the closed form does not apply).
    """

    omega: float
    mu_ratio: float
    computed: float
    closed: float
    sticks: bool

    @property
    def difference(self) -> float:
        """``computed - closed``."""
        return self.computed - self.closed


def orbit_at(omega: float, mu_ratio: float, v_belt: float = 0.0) -> PeriodicOrbit:
    """grazing's periodic orbit at ``(omega, mu / a)``, ``a = 1``, found from rest.

    Parameters
    ----------
    omega, mu_ratio
        As :func:`amplitude`.
    v_belt
        The belt's speed (Den Hartog's oscillator: 0).

    Returns
    -------
    PeriodicOrbit
        From :func:`~grazing.orbits.find_orbit` (a transient from rest, then Newton).

    Examples
    --------
    >>> orbit_at(2.0, 0.1).period
    1
    """
    model = friction_oscillator(a=1.0, omega=omega, mu=mu_ratio, v_belt=v_belt)
    period = 2.0 * math.pi / omega
    for k in range(SECTION_TRIES):
        try:
            return find_orbit(model, t0=k * period / SECTION_TRIES)
        except (InvalidParameterError, ConvergenceError):  # sticking or a switch on this section: next
            if k == SECTION_TRIES - 1:
                raise
    raise AssertionError("unreachable")


def compare_amplitudes(omegas: Sequence[float], mu_ratio: float) -> list[AmplitudePoint]:
    """grazing's orbits over ``omegas`` at one ``mu / a``, each beside Den Hartog's amplitude.

    Parameters
    ----------
    omegas
        Forcing frequencies.
    mu_ratio
        ``mu / a``.

    Returns
    -------
    list of AmplitudePoint
        One per frequency.

    Examples
    --------
    >>> [p.sticks for p in compare_amplitudes([2.0, 0.3], 0.1)]
    [False, True]
    """
    out = []
    for w in omegas:
        r = reversals(orbit_at(w, mu_ratio))
        out.append(AmplitudePoint(w, mu_ratio, r.amplitude, amplitude(w, mu_ratio), bool(r.sticks.any())))
    return out


def computed_boundary(
    omega: float, bracket: tuple[float, float] = (0.02, 2.0), n_scan: int = 25, v_belt: float = 0.0
) -> float:
    """The boundary of non-stop motion on grazing's orbits: the ``mu / a`` where the orbit first sticks.

    The stick margin of :func:`reversals` (positive without stops, negative with) is scanned on
    ``n_scan`` values of ``mu / a`` in ``bracket`` from below and its first change of sign refined by
    Brent's method to 1e-13.  Nothing of Den Hartog's closed form is used.  At resonance
    (``omega = 1`` exactly, ``v_belt = 0``) the motion below the boundary never stops and grows without
    bound: there is no periodic orbit there, and a value of ``mu / a`` where Newton's method finds none
    counts as non-stop (its margin positive); the boundary is where the sticking orbits begin (Den
    Hartog's limit ``pi / 4``).

    Parameters
    ----------
    omega
        Forcing frequency.
    bracket
        The range of ``mu / a`` searched.
    n_scan
        Values of the scan.
    v_belt
        The belt's speed (Den Hartog's oscillator: 0).

    Returns
    -------
    float
        The boundary; nan where the margin does not change sign in ``bracket``.

    Examples
    --------
    >>> abs(computed_boundary(2.0) - boundary(2.0)) < 1e-9
    True
    """
    resonant = omega == 1.0 and v_belt == 0.0

    def margin(mu: float) -> float:
        try:
            orbit = orbit_at(omega, mu, v_belt)
        except ConvergenceError:
            if not resonant:
                raise
            return math.inf  # (no periodic orbit: the resonant motion grows without bound, never stopping)
        if resonant and not orbit.isolated:  # (Newton's "orbit" at a huge amplitude, multipliers 1, 1: none)
            return math.inf
        return reversals(orbit).margin

    grid = np.linspace(bracket[0], bracket[1], n_scan)
    prev = margin(float(grid[0]))
    for lo, hi in itertools.pairwise(grid):
        cur = margin(float(hi))
        if prev > 0.0 >= cur:
            # (a positive margin capped: Brent's method needs finite values, and only their sign matters)
            capped = lambda mu: min(margin(mu), 1.0)  # noqa: E731
            return float(brentq(capped, float(lo), float(hi), xtol=1e-13, rtol=1e-13))
        prev = cur
    return math.nan


def transition_kind(omega: float, mu_ratio: float, v_belt: float = 0.0) -> str:
    """Which sliding bifurcation starts the sticking at a located boundary ``mu_ratio``.

    At a crossing-sliding the orbit crosses the surface where the sliding region begins: the stick
    margin of :func:`reversals` passes through zero there.  At a grazing-sliding the orbit touches
    the surface tangentially inside a slip, at the sliding region's edge: no reversal is there
    below the boundary, and the margin jumps from a positive value to about zero.

    Parameters
    ----------
    omega, mu_ratio
        The frequency and the boundary there (:func:`computed_boundary`).
    v_belt
        The belt's speed.

    Returns
    -------
    str
        ``"crossing-sliding"`` where the margin just below ``mu_ratio`` is within :data:`MARGIN_TOL`
        of zero, else ``"grazing-sliding"``.

    Examples
    --------
    >>> transition_kind(2.0, computed_boundary(2.0))
    'crossing-sliding'
    """
    below = reversals(orbit_at(omega, mu_ratio * (1.0 - 1e-12), v_belt)).margin
    return "crossing-sliding" if abs(below) <= MARGIN_TOL else "grazing-sliding"


def plot_amplitudes(points: Sequence[AmplitudePoint], ax=None) -> Figure:
    """Amplitude against frequency: grazing's orbits as points, Den Hartog's closed form as lines.

    Parameters
    ----------
    points
        From :func:`compare_amplitudes` (any ``mu / a`` values; one line each).
    ax
        Axes to draw on (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.

    Examples
    --------
    >>> fig = plot_amplitudes(compare_amplitudes([1.5, 2.0], 0.1))
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(7, 4), layout="constrained")
    for i, r in enumerate(sorted({p.mu_ratio for p in points})):
        colour = f"C{i}"
        pts = [p for p in points if p.mu_ratio == r]
        w_min, w_max = min(p.omega for p in pts), max(p.omega for p in pts)
        ws = np.linspace(w_min, w_max, 2000)
        xs = np.array([amplitude(w, r) if nonstop_boundary(w) >= r else math.nan for w in ws])
        xs[np.abs(ws - 1.0) < 0.02] = math.nan  # resonance: no line across it
        ax.plot(ws, xs, color=colour, lw=1, label=f"Den Hartog, μ/a = {r:g}")
        free = [p for p in pts if not p.sticks]
        stuck = [p for p in pts if p.sticks]
        ax.plot([p.omega for p in free], [p.computed for p in free], "o", color=colour, ms=4)
        ax.plot([p.omega for p in stuck], [p.computed for p in stuck], "x", color=colour, ms=5)
    ax.plot([], [], "ko", ms=4, label="grazing, no stops")
    ax.plot([], [], "kx", ms=5, label="grazing, sticks")
    ax.set_xlabel("forcing frequency ω")
    ax.set_ylabel("amplitude X / a")
    ax.set_yscale("log")
    ax.set_ylim(0.05, 30.0)
    ax.legend(fontsize=8)
    return ax.figure


def plot_boundary(omegas: Sequence[float], computed: Sequence[float], ax=None) -> Figure:
    """The boundary of non-stop motion in ``(omega, mu / a)``: Den Hartog's line, grazing's points.

    Parameters
    ----------
    omegas, computed
        Frequencies and :func:`computed_boundary` at each.
    ax
        Axes to draw on (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.

    Examples
    --------
    >>> fig = plot_boundary([2.0], [computed_boundary(2.0)])
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(7, 4), layout="constrained")
    ws = np.linspace(min(omegas), max(omegas), 3000)
    ws = ws[np.abs(ws - 1.0) > 1e-4]
    ax.plot(ws, [boundary(w) for w in ws], "k-", lw=1, label="Den Hartog (1931), re-derived")
    low = ws[ws < 0.7]
    ax.plot(low, [nonstop_boundary(w) for w in low], "k--", lw=1, label="with x′ > 0 between reversals")
    ax.plot(omegas, computed, "o", color="C3", ms=4, label="grazing: the orbit first sticks")
    ax.axhline(math.pi / 4, color="0.6", lw=0.8, ls=":")
    ax.text(max(omegas), math.pi / 4 + 0.01, "π/4", ha="right", va="bottom", fontsize=8, color="0.4")
    ax.set_xlabel("forcing frequency ω")
    ax.set_ylabel("friction μ / a")
    ax.set_ylim(0.0, 0.95)
    ax.text(
        0.98,
        0.3,
        "stick-slip above the line\nno stops below it",
        ha="right",
        fontsize=8,
        transform=ax.transAxes,
    )
    ax.legend(fontsize=8, loc="lower right")
    return ax.figure
