"""The discontinuity map of a trajectory grazing a switching surface that has no reset.

A model with modes switches from a *source* mode (field ``f-``, guard ``h > 0``)
to a *target* mode (field ``f+``) where ``h`` reaches 0, without a reset, and
back across the same surface.  Where the field is continuous across the surface
(``f+ = f-`` on ``h = 0``) and only its derivative jumps -- a compliant contact,
a spring that engages -- the jump is ``f+ - f- = h w + O(h^2)``, and a
trajectory grazing the surface is changed by a zero-time discontinuity map
(ZDM) of order 3/2 in its penetration, not 1/2 as an impact's (derivation in
``docs/normal-form.md``, section 5; di Bernardo, Budd & Champneys, Physica D
160, 2001):

    D(x) = x - (4/3) sqrt(2 / a) delta^(3/2) w + O(delta^2)   (delta > 0),   D(x) = x   (delta <= 0),

with ``delta = (L_f h)^2 / (2 a) - h`` the depth the local parabola of ``h``
reaches past the surface, ``a = L_f^2 h`` at the grazing contact (Lie
derivatives along the source field, with ``dh/dt``).  The correction is the
jump integrated over the time spent in the target mode:
``w * integral of h = -(4/3) sqrt(2 / a) delta^(3/2) w``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from grazing.core.model import HybridModel
from grazing.errors import InvalidParameterError, InvalidStateError

SWITCH_CHECK_TOL = 1e-8
"""Relative tolerance of the checks at the contact: ``h``, ``L_f h``, the jump ``f+ - f-`` and the part
of its derivative that is not normal to the surface must vanish to this (relative to the state's, the
field's and the derivative's sizes).  A grazing contact is solved to ~1e-12 (``CONTACT_TOL``), a field
continuous across the surface gives a jump of that order there, and a real jump or a tangential
derivative is of the order of the model's coefficients: 1e-8 separates them with room on both sides."""

ZDM_COEFFICIENT = 4.0 / 3.0 * math.sqrt(2.0)
"""``(4/3) sqrt(2)``: the correction is ``-ZDM_COEFFICIENT delta^(3/2) w / sqrt(a)``
(``integral of (-delta + a s^2 / 2) ds`` over the contact, ``|s| <= sqrt(2 delta / a)``)."""


@dataclass(frozen=True)
class SwitchingMap:
    """The zero-time discontinuity map at a grazing contact with a switching surface without a reset.

    Attributes
    ----------
    model
        The model with modes, with the parameter values at grazing.
    transition
        Index of the transition grazed (one of :attr:`HybridModel.stop_names`).
    contact
        The grazing contact ``x*`` (``h = 0``, ``L_f h = 0``).
    t_graze
        Its time ``t*``: the map acts on the section ``t = t*``.
    accel
        ``a = L_f^2 h`` at the contact (positive: the source mode's flow turns back).
    jump
        ``w``: the jump of the field per unit guard, ``f+ - f- = h w + O(h^2)`` (from the
        derivative of ``f+ - f-`` at the contact, which is ``w`` times the guard's gradient).

    Examples
    --------
    A soft stop: ``x'' = -x + cos(t) / 2`` while ``x < 1``; beyond, a spring ``k (x - 1)`` pushes back
    (``w = (0, k)``).  The motion through ``(1, 0)`` at ``t = 0`` touches ``x = 1`` and turns back with
    ``a = -x'' = 1/2``:

    >>> import sympy as sp, numpy as np, grazing
    >>> x, v, t, k = sp.symbols("x v t k")
    >>> free, contact = [v, -x + sp.cos(t) / 2], [v, -x + sp.cos(t) / 2 - k * (x - 1)]
    >>> m = grazing.HybridModel("soft", [x, v], t, [grazing.Parameter("k", 4.0)], period=2 * sp.pi,
    ...     modes=[grazing.Mode("free", free), grazing.Mode("contact", contact)],
    ...     transitions=[grazing.Transition("touch", "free", "contact", 1 - x),
    ...                  grazing.Transition("leave", "contact", "free", x - 1)])
    >>> zdm = switching_map_at(m, "touch", [1.0, 0.0], 0.0)
    >>> zdm.accel, zdm.jump.tolist()
    (0.5, [0.0, 4.0])

    A state ``1e-4`` beyond the surface at rest loses ``(4/3) sqrt(2 / a) k 1e-6`` of velocity:

    >>> bool(np.isclose(zdm.zdm([1.0001, 0.0])[1], -4 / 3 * np.sqrt(2 / 0.5) * 4.0 * 1e-6))
    True
    """

    model: HybridModel
    transition: int
    contact: np.ndarray
    t_graze: float
    accel: float
    jump: np.ndarray

    @property
    def transition_name(self) -> str:
        return self.model.stop_names[self.transition]

    @property
    def coefficient(self) -> float:
        """``(4/3) sqrt(2 / a)``: the correction is ``-coefficient * delta^(3/2) * jump``."""
        return ZDM_COEFFICIENT / math.sqrt(self.accel)

    def penetration(self, x: Sequence[float] | np.ndarray, t: float | None = None,
                    model: HybridModel | None = None) -> float:  # fmt: skip
        """``delta = (L_f h)^2 / (2 a) - h`` at ``x`` (time ``t``, default ``t*``): how far past the
        surface the local parabola of the guard reaches (negative: it turns back before).

        ``model``: the same model at other parameter values (an unfolding: the guard and its rate are
        taken there; ``a`` stays the contact's), by default :attr:`model`.
        """
        m = self.model if model is None else model
        cd = m.contact_derivatives(x, self.t_graze if t is None else t, self.transition)
        return cd["rate"] ** 2 / (2 * self.accel) - cd["h"]

    def correction(self, x: Sequence[float] | np.ndarray, t: float | None = None,
                   model: HybridModel | None = None) -> np.ndarray:  # fmt: skip
        """``D(x) - x``: ``-(4/3) sqrt(2 / a) delta^(3/2) w`` where ``delta > 0``, else zeros."""
        delta = self.penetration(x, t, model)
        if delta <= 0:
            return np.zeros(self.model.n_states)
        return -self.coefficient * delta**1.5 * self.jump

    def zdm(self, x: Sequence[float] | np.ndarray, t: float | None = None,
            model: HybridModel | None = None) -> np.ndarray:  # fmt: skip
        """Apply the map to a state ``x`` on the section ``t`` (default ``t*``): ``x + correction(x)``."""
        return np.asarray(x, dtype=float) + self.correction(x, t, model)


def _way_back(model: HybridModel, j: int) -> int | None:
    """The transition without a reset from ``j``'s target back to its source across ``j``'s surface
    (guard ``-h``), or None."""
    import sympy as sp

    sym = model.symbolic
    guard = sym.stops[j].guard
    for i, stop in enumerate(sym.stops):
        if (sym.sources[i], sym.targets[i]) == (sym.targets[j], sym.sources[j]) and not sym.resets[i]:
            if sp.simplify(stop.guard + guard) == 0:
                return i
    return None


def _jump_and_derivative(
    model: HybridModel, j: int, x: np.ndarray, t: float
) -> tuple[np.ndarray, np.ndarray]:
    """``f+ - f-`` of transition ``j`` at ``(x, t)`` and its derivative ``[d/dx | d/dt]`` (n by n + 1)."""
    import sympy as sp

    sym = model.symbolic.canonical()
    source, target = sym.modes[sym.sources[j]], sym.modes[sym.targets[j]]
    jump = sp.Matrix(target.vector_field) - sp.Matrix(source.vector_field)
    wrt = sp.Matrix([*sym.states, sym.time])
    fn = sp.lambdify((list(sym.states), sym.time, list(sym.params)), [jump, jump.jacobian(wrt)],
                     modules="numpy", dummify=True)  # fmt: skip
    value, deriv = fn(list(x), float(t), list(model.param_vector))
    n = model.n_states
    return np.asarray(value, dtype=float).reshape(n), np.asarray(deriv, dtype=float).reshape(n, n + 1)


def switching_map_at(model: HybridModel, transition: int | str, contact: Sequence[float] | np.ndarray,
                     t_graze: float) -> SwitchingMap:  # fmt: skip
    """The discontinuity map of grazing ``transition``, a switch without a reset, at a grazing contact.

    The field must be continuous across the surface and its derivative may jump (a degree-two
    discontinuity: ``f+ - f- = h w + O(h^2)``); the map is then ``D(x) = x - (4/3) sqrt(2 / a)
    delta^(3/2) w`` (module docstring; ``docs/normal-form.md``, section 5), and the motion must come back
    across the same surface (a transition from the target mode to the source without a reset, with the
    guard ``-h``: a :class:`~grazing.Surface`, or two :class:`~grazing.Transition` s).

    Parameters
    ----------
    model
        A model with modes, with the parameter values at grazing.
    transition
        The transition grazed (name or index), leaving the mode the grazing trajectory is in.
    contact
        A state where the source mode's flow touches the surface: ``h = 0`` and ``L_f h = 0`` (to
        :data:`SWITCH_CHECK_TOL`), ``L_f^2 h > 0`` -- the contact of a grazing periodic orbit, say.
    t_graze
        The time of the contact: the map acts on the section ``t = t_graze``.

    Returns
    -------
    SwitchingMap
        The map's ingredients, and the map.

    Raises
    ------
    InvalidParameterError
        One line: the transition has a reset (grazing it is an impact: :func:`normal_form_at`), the field
        jumps across the surface (degree one) or its jump does not vanish along the surface, or there
        is no way back across the same surface.
    InvalidStateError
        One line: ``contact`` is not a grazing contact.

    Examples
    --------
    The soft stop of :class:`SwitchingMap`'s example, a surface this time: the correction grows as the
    penetration to the power 3/2 (a thousand times for a hundred times deeper), and the same model with a
    constant contact force, a field that jumps, is refused:

    >>> import sympy as sp, grazing
    >>> x, v, t, k, f0 = sp.symbols("x v t k f0")
    >>> def soft(force):
    ...     free, contact = [v, -x + sp.cos(t) / 2], [v, -x + sp.cos(t) / 2 - k * (x - 1) - force]
    ...     return grazing.HybridModel("soft-" + str(force), [x, v], t,
    ...         [grazing.Parameter("k", 4.0), grazing.Parameter("f0", 0.1)], period=2 * sp.pi,
    ...         modes=[grazing.Mode("free", free), grazing.Mode("contact", contact)],
    ...         surfaces=[grazing.Surface("wall", 1 - x, "free", "contact", sliding=False)])
    >>> zdm = switching_map_at(soft(0), "wall_to_contact", [1.0, 0.0], 0.0)
    >>> round(float(zdm.correction([1 + 1e-4, 0.0])[1] / zdm.correction([1 + 1e-6, 0.0])[1]), 6)
    1000.0
    >>> switching_map_at(soft(f0), "wall_to_contact", [1.0, 0.0], 0.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: the field jumps ... = [0.0, -0.1]): ... of degree one ...
    """
    j = model.stop_index(transition)
    name = model.stop_names[j]
    if not model.has_modes or model.symbolic.resets[j]:
        what = "transition" if model.has_modes else "stop"
        raise InvalidParameterError(
            f"{what} {name!r} has a reset: grazing it is an impact, whose discontinuity map is "
            "normal_form_at's (a square-root map), not a switch's"
        )
    source, target = model.transition_source[j], model.transition_target[j]
    if _way_back(model, j) is None:
        raise InvalidParameterError(
            f"transition {name!r} has no way back across its surface: the map needs a transition from "
            f"{target!r} to {source!r} without a reset whose guard is minus {name!r}'s (or a Surface)"
        )
    x = model.check_state(contact, t_graze, allowed=False)
    t = float(t_graze)
    cd = model.contact_derivatives(x, t, j)
    f = model.vector_field(x, t, source)
    size = max(1.0, float(np.max(np.abs(x))))
    rate_size = max(1.0, float(np.abs(cd["h_x"]) @ np.abs(f)) + abs(cd["h_t"]))
    if abs(cd["h"]) > SWITCH_CHECK_TOL * size or abs(cd["rate"]) > SWITCH_CHECK_TOL * rate_size:
        raise InvalidStateError(
            f"{x.tolist()} at t = {t:.10g} is not a grazing contact of transition {name!r} "
            f"(h = {cd['h']:.3g}, L_f h = {cd['rate']:.3g}; both must be 0)"
        )
    if not cd["accel"] > 0:
        raise InvalidStateError(
            f"the flow of mode {source!r} does not turn back from the surface of transition {name!r} at "
            f"{x.tolist()}, t = {t:.10g} (L_f^2 h = {cd['accel']:.3g}, must be > 0): not a grazing contact"
        )
    jump, deriv = _jump_and_derivative(model, j, x, t)
    if float(np.max(np.abs(jump))) > SWITCH_CHECK_TOL * max(1.0, float(np.max(np.abs(f)))):
        raise InvalidParameterError(
            f"the field jumps across transition {name!r} at the contact (f+ - f- = "
            f"{np.round(jump, 6).tolist()}): a discontinuity of degree one (its map goes as the square "
            "root of the penetration), which switching_map_at does not cover"
        )
    normal = np.append(cd["h_x"], cd["h_t"])
    w = deriv @ normal / float(normal @ normal)
    tangential = float(np.max(np.abs(deriv - np.outer(w, normal))))
    if tangential > SWITCH_CHECK_TOL * max(1.0, float(np.max(np.abs(deriv)))):
        raise InvalidParameterError(
            f"the jump f+ - f- across transition {name!r} does not vanish along the surface near the "
            f"contact (its derivative is not normal to the surface, by {tangential:.3g}): "
            "switching_map_at needs a field continuous across the surface"
        )
    return SwitchingMap(model=model, transition=j, contact=x, t_graze=t, accel=float(cd["accel"]), jump=w)
