"""Grazing periodic orbits: the contact equations and their solution.

A periodic orbit grazes when it touches the stop with zero normal velocity:
``h = 0`` and ``L_f h = 0`` (with ``L_f^2 h > 0``) at some time ``t_g``.  The
unknowns are the state ``y`` at the contact, the contact time ``t_g`` and the
free parameters; the equations are periodicity from the contact,
``Phi(y, t_g -> t_g + nT) = y``, and the two contact conditions.  Taking the
Poincare section through the contact point itself keeps the problem smooth
and gives the monodromy matrix at the grazing point, which the normal form
needs.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.solution import Impacts
from grazing.errors import ConvergenceError
from grazing.maps import flow_map
from grazing.orbits.palc import PalcSettings, newton
from grazing.orbits.shooting import CROSSING_TOL, sorted_multipliers

CONTACT_TOL = 1e-12
"""Newton's method on the contact (grazing) equations stops when their largest residual is below this:
a grazing orbit is an end result (its parameter is reported, a normal form is built on it), and its
equations, as many as unknowns, are solved to near rounding."""

CONTACT_MAX_NEWTON = 12
"""Newton's iterations on the contact equations: from a closest approach or a weak impact they converge
quadratically in a few; no convergence in this many is no grazing there."""


@dataclass(frozen=True)
class GrazingPoint:
    """A grazing periodic orbit.

    Attributes
    ----------
    model
        Model with the parameter values at grazing.
    contact
        State at the grazing contact (on the stop, zero normal velocity).
    t_graze
        Time of the contact (any representative; see :attr:`phase`).
    monodromy
        Jacobian of the period-n map on the section through the contact
        (``t = t_graze``), with the grazing contact itself not an impact (the
        orbit's other impacts, if any, are).
    multipliers
        Its eigenvalues (the nontrivial Floquet multipliers), largest first.
    accel
        ``L_f^2 h`` at the contact (positive: the orbit turns back from the stop).
    period
        Period of the orbit in forcing periods.
    impacts
        The orbit's other impacts per period (0 for a nonimpacting orbit that grazes).
    stop
        Index of the stop it grazes (:attr:`stop_name` its name).
    crossed
        Names of the other stops that the orbit passes through, computed with
        the stops ignored (a nonimpacting orbit).  Where there are any, the
        grazing is not a motion of the system: it hits those stops first.
    guard_mins
        The smallest value of every stop's guard along the orbit (zero, to
        rounding, for the stop grazed; negative for a stop it passes through).
    other_impacts
        The orbit's other impacts over one period from the contact (with their
        speeds and states; empty for a flow with the stops ignored).
    approach_by_stop
        ``(h, t, x)`` of every stop's closest approach in free flight (None
        where there is none), as :attr:`PeriodicOrbit.approach_by_stop`.
    precision
        For a grazing solved with a free parameter (:func:`refine_grazing`): how far that
        parameter may be from the grazing's, to first order (the parameter component of the Newton
        step that would follow the last); for a codimension-two meeting point
        (:func:`~grazing.orbits.crossings.meeting_point`), the larger parameter component of its last
        Newton step; nan otherwise.
    mode
        A model with modes: the mode the orbit is in at the contact, the source of the transition
        whose guard it touches (:attr:`stop_name`); None without modes.
    switches
        A model with modes: its switches of mode over one period from the contact (the contact itself
        is none); 0 without modes.

    Examples
    --------
    The paper's first grazing at θ̂ = 40° (case B): the nonimpacting period-1
    orbit touches the stop at η = 0.4451 with multipliers of modulus 0.508
    (its §6.1; the paper prints 0.5114, an erratum):

    >>> import math, numpy as np, grazing
    >>> from grazing.orbits import find_grazings
    >>> (g,), _ = find_grazings(grazing.models.pendulum("B", theta_hat=math.radians(40)), "eta", 0.40, 0.50)
    >>> round(g.model.params["eta"], 4), g.period, g.impacts, bool(g.accel > 0)
    (0.4451, 1, 0, True)
    >>> np.abs(g.multipliers).round(4).tolist(), g.contact.round(6).tolist()
    ([0.5079, 0.5079], [0.698132, 0.0])
    """

    model: HybridModel
    contact: np.ndarray
    t_graze: float
    monodromy: np.ndarray
    multipliers: np.ndarray
    accel: float
    period: int = 1
    impacts: int = 0
    stop: int = 0
    crossed: tuple[str, ...] = ()
    guard_mins: tuple[float, ...] = ()
    other_impacts: Impacts | None = None
    approach_by_stop: tuple[tuple[float, float, np.ndarray] | None, ...] = ()
    precision: float = math.nan
    mode: str | None = None
    switches: int = 0

    @property
    def stop_name(self) -> str:
        """The name of the stop it grazes."""
        return self.model.stop_names[self.stop]

    @property
    def abs_lambda(self) -> float:
        """Largest multiplier modulus."""
        return float(np.max(np.abs(self.multipliers)))

    @property
    def phase(self) -> float:
        """Forcing phase of the contact, ``t_graze mod T`` in ``[0, T)``."""
        return float(np.mod(self.t_graze, self.model.period))

    def params(self) -> dict[str, float]:
        return dict(self.model.params)


def contact_system(
    model: HybridModel, names: tuple[str, ...], period: int, *, events: bool = False, stop: int = 0
):
    """``u = (y, t_g, *params) -> (F, DF, GrazingPoint)`` for the grazing equations.

    ``F = (Phi(y, t_g -> t_g + n T) - y, h(y, t_g), L_f h(y, t_g))``: the orbit
    through the contact state ``y`` is periodic and touches the stop there.
    With ``events`` the flow applies the orbit's other impacts (a grazing of an
    orbit that already impacts); the contact itself is never an impact.
    ``stop`` is the index of the stop touched.

    On a model with modes ``stop`` is a transition and the orbit is in its
    source mode at the contact: it touches the guard there without switching
    (for a switch without a reset, an orbit of the source mode tangent to the
    switching surface); its other switches of mode (and impacts) are applied,
    whatever ``events``, and the orbit must be back in the source mode one
    period later.
    """
    n = model.n_states
    eye = np.eye(n)
    pidx = [[p.name for p in model.parameters].index(name) for name in names]
    modes = model.has_modes
    source = model.transition_source[stop] if modes else None

    def evaluate(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, GrazingPoint]:
        y, tg = u[:n], float(u[n])
        m = model.with_params(**{name: float(v) for name, v in zip(names, u[n + 1 :])})
        fm = flow_map(
            m,
            y,
            t0=tg,
            periods=period,
            sensitivities=names,
            virtual=not (events or modes),
            touching=events or modes,
            stop_name=stop,
            mode=source,
        )
        if modes and fm.mode_final != source:
            raise ConvergenceError(
                f"the orbit touching transition {model.stop_names[stop]!r} in mode {source!r} returns in "
                f"mode {fm.mode_final!r} {period} forcing period(s) later: no grazing orbit there"
            )
        J, S = fm.jacobian, fm.sensitivity
        fy = m.vector_field(y, tg, source)
        fend = m.vector_field(fm.image, fm.solution.t_final, source)
        cd = m.contact_derivatives(y, tg, stop)
        F = np.concatenate([fm.image - y, [cd["h"], cd["rate"]]])
        DF = np.zeros((n + 2, n + 1 + len(names)))
        DF[:n, :n] = J - eye
        DF[:n, n] = fend - J @ fy  # moving the start time along the periodic forcing
        DF[:n, n + 1 :] = S
        DF[n, :n], DF[n, n], DF[n, n + 1 :] = cd["h_x"], cd["h_t"], cd["h_p"][pidx]
        DF[n + 1, :n], DF[n + 1, n], DF[n + 1, n + 1 :] = cd["rate_x"], cd["rate_t"], cd["rate_p"][pidx]
        point = GrazingPoint(
            model=m,
            contact=y.copy(),
            t_graze=tg,
            monodromy=J,
            multipliers=sorted_multipliers(J),
            accel=cd["accel"],
            period=period,
            impacts=fm.impacts,
            stop=stop,
            crossed=() if events or modes else _crossed(m, fm.solution.guard_min_by_stop, stop),
            guard_mins=tuple(g[0] for g in fm.solution.guard_min_by_stop or ()),
            other_impacts=fm.solution.impacts,
            approach_by_stop=fm.solution.approach_by_stop or (),
            mode=source,
            switches=len(fm.solution.switches) if modes else 0,
        )
        return F, DF, point

    return evaluate


def _crossed(model: HybridModel, guard_mins, stop: int) -> tuple[str, ...]:
    """The stops other than ``stop`` whose guard goes negative along a flow that ignores the stops."""
    return tuple(
        name
        for j, (name, g) in enumerate(zip(model.stop_names, guard_mins or ()))
        if j != stop and g[0] < -CROSSING_TOL
    )


def refine_grazing(
    model: HybridModel,
    contact: np.ndarray,
    t_graze: float,
    free: str,
    *,
    period: int = 1,
    tol: float = CONTACT_TOL,
    events: bool = False,
    stop_name: int | str | None = None,
) -> GrazingPoint:
    """Solve the grazing equations for the contact state, time and parameter ``free``.

    ``contact``, ``t_graze`` and the model's value of ``free`` are the initial
    guess (for example the closest approach of a nonimpacting orbit, or the
    weakest impact of an impacting one).  With ``events`` the orbit's other
    impacts are applied (see :func:`contact_system`).  ``stop_name``: the stop
    touched (name or index; the first by default).

    Parameters
    ----------
    model
        The model, with the initial guess of ``free``'s value.
    contact
        A guess of the state at the contact.
    t_graze
        A guess of the time of the contact.
    free
        The parameter solved for.
    period
        Period of the orbit in forcing periods.
    tol
        Newton's tolerance on the equations' residual.
    events
        Apply the orbit's other impacts (an impacting orbit that grazes).
    stop_name
        The stop touched (name or index; the first by default).

    Returns
    -------
    GrazingPoint
        The grazing orbit, with the model at ``free``'s grazing value and the
        ``precision`` of that value.

    Raises
    ------
    ConvergenceError
        Newton's method did not converge from the guess.

    Examples
    --------
    From the closest approach of the nonimpacting orbit at η = 0.445, just
    before the paper's first grazing at θ̂ = 40°:

    >>> import math, grazing
    >>> from grazing.orbits import find_orbit
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40), eta=0.445)
    >>> h, t, x = find_orbit(m, virtual=True).approach
    >>> round(h, 4)  # the orbit misses the stop by 0.0015 rad
    0.0015
    >>> g = refine_grazing(m, x, t, "eta")
    >>> round(g.model.params["eta"], 6), bool(g.precision < 1e-10)
    (0.445121, True)
    """
    evaluate = contact_system(model, (free,), period, events=events, stop=model.stop_index(stop_name))
    u0 = np.concatenate([contact, [t_graze, model.params[free]]])
    pt = newton(evaluate, u0, PalcSettings(tol=tol, max_newton=CONTACT_MAX_NEWTON))  # (n + 2 by n + 2)
    if pt is None:
        raise ConvergenceError(
            "Newton's method for the grazing orbit did not converge near "
            f"{model.parameter(free).show(model.params[free], '.8g')}"
        )
    try:
        step = np.linalg.solve(pt.DF, pt.F)  # (the next Newton step: the parameter's remaining error)
        precision = abs(float(step[-1]))
    except np.linalg.LinAlgError:
        precision = math.nan
    return dataclasses.replace(pt.payload, precision=precision)
