"""A sliding bifurcation followed in two parameters, from the special point where a branch ends.

At each value of the second parameter the bifurcation is bracketed again in the branch's parameter: the
orbits are found at values widening out on both sides of the predicted one (the last point, or the line
through the last two) until two neighbouring values hold the two sides' switches
(:attr:`~grazing.orbits.periodic.PeriodicOrbit.switch_signature`), a guess past the change or short of it
alike; that bracket is then narrowed by bisection
(:func:`~grazing.orbits.sliding_bifurcations.bisect_switches`).  The curve ends, with its reason in
:attr:`SlidingCurve.status`, where the change is no longer bracketed or is of another kind.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from grazing.errors import GrazingError, InvalidParameterError
from grazing.orbits.continuation import Branch, SpecialPoint
from grazing.orbits.kinds import SpecialKind
from grazing.orbits.periodic import PeriodicOrbit
from grazing.orbits.shooting import find_orbit, move_section, quiet_section
from grazing.orbits.sliding_bifurcations import bisect_switches, sliding_kind

SLIDING_KINDS = (
    SpecialKind.GRAZING_SLIDING,
    SpecialKind.CROSSING_SLIDING,
    SpecialKind.SWITCHING_SLIDING,
    SpecialKind.ADDING_SLIDING,
)
"""The special points a sliding curve starts from."""

BRACKET_STEPS = (1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 3e-2)
"""Half-widths (relative to ``max(1, |value|)``) of the brackets tried around the predicted value, in
this order."""

PAST = 1e-9
"""The orbit beyond the branch's sliding bifurcation is sought this far (relative to ``max(1, |value|)``)
past its bracket."""

MAX_HALVINGS = 4
"""A step in the second parameter that does not bracket the change again is halved, at most this many
times in all, before the curve ends."""


@dataclass
class SlidingCurve:
    """A sliding bifurcation in two parameters (:func:`sliding_curve`).

    Attributes
    ----------
    kind
        The bifurcation followed.
    params
        The branch's parameter, then the second one.
    values
        ``(value, value2)`` of each point: the bifurcation's value of the first parameter (the middle of
        its bracket) at each value of the second.
    intervals
        The bracket of the first parameter at each point.
    orbits
        The orbit on the branch's side of each bracket.
    status
        Why the curve ended, in one line.

    Examples
    --------
    >>> from grazing.models import friction_oscillator
    >>> from grazing.orbits import continue_orbit
    >>> branch = continue_orbit(friction_oscillator(omega=2.0, mu=0.1, v_belt=0.0), "mu", 0.1, 0.9)
    >>> curve = sliding_curve(branch, "omega", 2.1, steps=2)
    >>> curve.kind, curve.params, len(curve)
    ('crossing-sliding', ('mu', 'omega'), 3)
    """

    kind: SpecialKind
    params: tuple[str, str]
    values: list[tuple[float, float]] = field(default_factory=list)
    intervals: list[tuple[float, float]] = field(default_factory=list)
    orbits: list[PeriodicOrbit] = field(default_factory=list)
    status: str = ""

    def __len__(self) -> int:
        return len(self.values)


def _orbit_at(like: PeriodicOrbit, **values: float) -> PeriodicOrbit | None:
    """The orbit near ``like`` at ``values``; where a switch has come to its section (the map returns in
    another mode, or Newton's method fails), tried again from ``like`` on its quietest section."""
    for guess in (like, None):
        try:
            if guess is None:
                guess = move_section(like, quiet_section(like))
            model = like.model.with_params(**values)
            return find_orbit(model, guess.state, period=like.period, t0=guess.t0, mode=guess.mode)
        except GrazingError:
            continue
    return None


def _bracket(
    before: PeriodicOrbit, after: PeriodicOrbit, param: str, guess: float, changes: dict[str, float]
) -> tuple[PeriodicOrbit, PeriodicOrbit] | None:
    """Orbits with ``before``'s and ``after``'s switches at two neighbouring values of ``param`` (with
    ``changes`` to the other parameters), ``before``'s on its side: the values tried are ``guess`` plus and
    minus each of :data:`BRACKET_STEPS` in turn, and the first pair of neighbours among those tried so far
    that holds the change is returned (so a guess already past the change, or short of it, is bracketed
    on one side); None if none does."""
    side = float(np.sign(after.model.params[param] - before.model.params[param]))
    # (each value tried: its position from the guess towards ``after``'s side, the orbits found with
    # ``before``'s and with ``after``'s switches there)
    tried: list[tuple[float, PeriodicOrbit | None, PeriodicOrbit | None]] = []
    for step in BRACKET_STEPS:
        eps = step * max(1.0, abs(guess))
        for sign in (-1.0, 1.0):
            value = guess + sign * side * eps
            found = [o for like in (before, after) if (o := _orbit_at(like, **changes, **{param: value}))]
            ours = [o for o in found if o.switch_signature == before.switch_signature]
            theirs = [o for o in found if o.switch_signature == after.switch_signature]
            tried.append((sign * eps, ours[0] if ours else None, theirs[0] if theirs else None))
        tried.sort(key=lambda t: t[0])
        for (_, a, _), (_, _, b) in itertools.pairwise(tried):
            if a is not None and b is not None:
                return a, b
    return None


def sliding_curve(branch: Branch, param2: str, stop: float, *, steps: int = 10) -> SlidingCurve:
    """Follow the sliding bifurcation at the end of ``branch`` as ``param2`` goes to ``stop`` in ``steps``
    equal steps (a step halved where the change is not bracketed again, :data:`MAX_HALVINGS` in all;
    doubled back after each point).

    Parameters
    ----------
    branch
        A branch with a sliding bifurcation among its special points (the first is followed).
    param2
        The second parameter.
    stop
        Its last value.
    steps
        The number of steps from its value on the branch to ``stop``.

    Returns
    -------
    SlidingCurve
        Its points, the first the branch's special point; :attr:`SlidingCurve.status` says why it ended.

    Raises
    ------
    InvalidParameterError
        Without a sliding bifurcation on the branch, or with ``param2`` the branch's parameter.

    Examples
    --------
    Where the friction oscillator with the belt at rest first sticks (a crossing-sliding), in ``mu``
    and then in ``omega``; Den Hartog's closed form of that boundary (``a = 1``) is
    :func:`grazing.report.den_hartog.boundary`:

    >>> from grazing.models import friction_oscillator
    >>> from grazing.orbits import continue_orbit
    >>> from grazing.report.den_hartog import boundary
    >>> branch = continue_orbit(friction_oscillator(omega=2.0, mu=0.1, v_belt=0.0), "mu", 0.1, 0.9)
    >>> branch.special[0].kind
    'crossing-sliding'
    >>> curve = sliding_curve(branch, "omega", 1.8, steps=2)
    >>> curve.status
    'reached omega = 1.8'
    >>> [round(w, 3) for _, w in curve.values]
    [2.0, 1.9, 1.8]
    >>> max(abs(mu - boundary(w)) for mu, w in curve.values) < 1e-9
    True
    """
    found: list[SpecialPoint] = [sp for sp in branch.special if sp.kind in SLIDING_KINDS]
    if not found:
        raise InvalidParameterError("the branch ends at no sliding bifurcation to follow")
    param = branch.param
    if param2 == param:
        raise InvalidParameterError(f"the second parameter must differ from the branch's ({param!r})")
    par2 = branch.model.parameter(param2)
    par2.check(stop)
    sp = found[0]
    assert sp.interval is not None
    before = sp.orbit
    p_before = before.model.params[param]
    past = 2.0 * abs(sp.param - p_before) + PAST * max(1.0, abs(sp.param))  # (beyond the bracket)
    after = _orbit_at(before, **{param: sp.param + np.sign(sp.param - p_before) * past})
    curve = SlidingCurve(kind=sp.kind, params=(param, param2))
    if after is None or after.switch_signature == before.switch_signature:
        curve.status = "the orbit beyond the bifurcation was not found again"
        return curve
    start2 = before.model.params[param2]
    curve.values.append((sp.param, start2))
    curve.intervals.append(sp.interval)
    curve.orbits.append(before)
    h = h0 = (stop - start2) / steps
    value2, halvings = start2, 0
    while (stop - value2) * h > 0:
        trial = value2 + h if abs(stop - value2) > abs(h) * (1 + 1e-9) else float(stop)
        (q1, r1) = curve.values[-1]
        guess = q1
        if len(curve) >= 2:
            q0, r0 = curve.values[-2]
            guess = q1 + (q1 - q0) * (trial - r1) / (r1 - r0)
        pair = _bracket(before, after, param, guess, {param2: trial})
        bracket = bisect_switches(*pair, param) if pair is not None else None
        kind = sliding_kind(bracket.before, bracket.after) if bracket is not None else None
        if bracket is None or kind is not curve.kind:
            if halvings < MAX_HALVINGS:
                h, halvings = 0.5 * h, halvings + 1
                continue
            what = (
                f"the change of switches was not bracketed near {param} = {guess:.10g}"
                if bracket is None
                else f"the bifurcation turns into a {kind or 'change of switches'}"
            )
            curve.status = f"{what} at {param2} = {trial:.10g}"
            return curve
        lo, hi = bracket.interval(param)
        curve.values.append((0.5 * (lo + hi), trial))
        curve.intervals.append((lo, hi))
        curve.orbits.append(bracket.before)
        before, after, value2 = bracket.before, bracket.after, trial
        h = h0 if abs(2.0 * h) > abs(h0) else 2.0 * h  # (back to the steps asked for)
    curve.status = f"reached {param2} = {stop:.10g}"
    return curve
