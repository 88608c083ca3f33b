"""Nordmark's discontinuity map at a grazing periodic orbit, and the maps built from it.

Conventions (derivation in ``docs/normal-form.md``): the guard ``h`` is positive
in the allowed region; at a grazing point ``x*`` (time ``t*``) ``h = 0``,
``v = L_f h = 0`` and ``a = L_f^2 h > 0``.  Near ``x*`` a trajectory follows a
parabola ``h(t) = h + v t + a t^2 / 2`` whose minimum is ``-delta`` with

    delta(x) = v^2 / (2 a) - h.

If ``delta > 0`` the trajectory reaches the stop with normal speed
``S = sqrt(2 a delta)``; to leading order the zero-time discontinuity map
(ZDM) is

    D(x) = x - e S        (delta > 0),        D(x) = x        (delta <= 0),

where ``e = (g_x - I) c / (grad(L_f h) . c)`` is the direction and size of the
reset's jump per unit approach speed (``c`` the contact direction).  For the
pendulum ``e = (0, 1 + r)``: the velocity jumps by ``-(1 + r) S``, away from
the stop.  (The paper's eq. 19 takes the square root of ``L_f^2 h`` with the
opposite sign convention, giving an imaginary root and a kick towards the
stop; see docs/equations.md.)

The Poincare map of the paper's eq. 20 is ``Pi = Phi_2 o D o Phi_1``: the
nonlinear flow ignoring the stop, with ``D`` applied once per period at the
grazing phase.  The *normal form* linearises both flow pieces about the
grazing orbit on the section through the contact point ``t = t*``:

    u_{k+1} = M D_mu(u_k) + b mu,

with ``M`` the monodromy matrix at the contact, ``b = dP/dp`` the unfolding
vector of the parameter ``p = p* + mu``, and ``D_mu`` using the linearised
``h``, ``L_f h`` (including their explicit dependence on ``p``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from grazing.core.model import HybridModel
from grazing.engine.runner import DiscontinuityMap, check_map_stop
from grazing.errors import InvalidParameterError
from grazing.maps import flow_map
from grazing.orbits.contact import GrazingPoint


def no_contact_direction(model: HybridModel, stop: int = 0) -> str:
    """The message for a stop without a contact direction, which the discontinuity map needs."""
    return (
        f"model {model.name!r} defines no contact direction for stop {model.stop_names[stop]!r}; the "
        "grazing normal form needs one (HybridModel(..., contact_direction=[...]))"
    )


def zdm_direction(model: HybridModel, x: np.ndarray, t: float, stop: int = 0) -> np.ndarray:
    """``stop``'s reset jump per unit approach speed at ``x``: ``e = (g_x - I) c / (grad(L_f h) @ c)``.

    Parameters
    ----------
    model
        The model (its stop needs a contact direction).
    x
        The state (a grazing contact).
    t
        The time.
    stop
        Index of the stop.

    Returns
    -------
    numpy.ndarray
        ``e``, one entry per state component.

    Examples
    --------
    For the pendulum, whose reset is ``theta' <- -r theta'``, ``e = (0, 1 + r)``:

    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> zdm_direction(m, [math.radians(40), 0.0], 0.0).tolist() == [0.0, 1 + m.params["r"]]
    True
    """
    _, _, gx = model.jacobians(x, t, stop)
    c = np.zeros(model.n_states)
    model.kernels().contact_dir(np.asarray(x, dtype=float), float(t), model.param_vector, c, stop)
    if not np.any(c):
        raise InvalidParameterError(no_contact_direction(model, stop))
    grad_rate = model.contact_derivatives(x, t, stop)["rate_x"]
    return (gx - np.eye(model.n_states)) @ c / float(grad_rate @ c)


@dataclass(frozen=True)
class GrazingNormalForm:
    """Everything the discontinuity map and the normal form need at one grazing point.

    Attributes
    ----------
    point
        The grazing orbit (contact state ``x*``, time ``t*``, monodromy at the
        contact section, multipliers).
    accel
        ``a = L_f^2 h`` at the contact (positive).
    direction
        ``e``, the reset's jump per unit approach speed.
    grad_h, grad_rate
        Gradients of ``h`` and ``L_f h`` at the contact.
    kappa
        ``-grad(h) . M . e / |e|``: how a kick along ``e`` on the contact section
        returns in the impacting coordinate after one period (the paper's
        ``M12`` for the pendulum, whose sign decides between the scenarios).
    unfolding
        For each parameter name: ``(b, h_p, rate_p)``: the unfolding vector
        ``dP/dp`` at the contact and the explicit parameter derivatives of ``h``
        and ``L_f h``.

    Examples
    --------
    At the paper's first grazing at θ̂ = 40° (:func:`normal_form_at` builds it):

    >>> import math, numpy as np, grazing
    >>> from grazing.normalform import find_grazing_point, normal_form_at
    >>> g = find_grazing_point(grazing.models.pendulum("B", theta_hat=math.radians(40)), "eta", 0.40, 0.47)
    >>> nf = normal_form_at(g, ("eta",))
    >>> round(nf.accel, 4), round(nf.kappa, 3), bool(nf.kappa > 0)
    (0.6892, 0.28, True)

    On the stop, the zero-time discontinuity map is the restitution law (a
    state reaching the stop at speed 0.01 leaves at ``-r`` times it):

    >>> x = nf.contact + np.array([0.0, 0.01])
    >>> bool(np.allclose(nf.zdm(x), [nf.contact[0], -nf.model.params["r"] * 0.01]))
    True
    """

    point: GrazingPoint
    accel: float
    direction: np.ndarray
    grad_h: np.ndarray
    grad_rate: np.ndarray
    kappa: float
    unfolding: dict[str, tuple[np.ndarray, float, float]] = field(default_factory=dict)

    @property
    def model(self) -> HybridModel:
        return self.point.model

    @property
    def monodromy(self) -> np.ndarray:
        return self.point.monodromy

    @property
    def multipliers(self) -> np.ndarray:
        return self.point.multipliers

    @property
    def contact(self) -> np.ndarray:
        return self.point.contact

    def discontinuity_map(self, window: float | None = None) -> DiscontinuityMap:
        """The engine's per-period discontinuity map at this grazing point.

        ``window`` bounds ``|L_f h| / a`` (default: a quarter period), so that
        the correction is only applied where the local parabola is meaningful.
        On a model with modes the stop is a mode's own (a reset back into it):
        the engine applies the map only while the run is in that mode.
        """
        check_map_stop(self.model, self.point.stop)
        T = self.model.period
        return DiscontinuityMap(
            phase=self.point.phase,
            accel=self.accel,
            direction=tuple(float(v) for v in self.direction),
            window=T / 4 if window is None else window,
            stop=self.point.stop,
        )

    def zdm(self, x: np.ndarray, t: float | None = None) -> np.ndarray:
        """Apply the leading-order ZDM to a state ``x`` (at time ``t``, default ``t*``)."""
        t = self.point.t_graze if t is None else t
        cd = self.model.contact_derivatives(x, t, self.point.stop)
        delta = cd["rate"] ** 2 / (2 * self.accel) - cd["h"]
        if delta <= 0:
            return np.array(x, dtype=float)
        return np.asarray(x, dtype=float) - self.direction * math.sqrt(2 * self.accel * delta)

    def normal_form(self, param: str):
        """The linear normal form ``u -> M D_mu(u) + b mu`` for unfolding parameter ``param``.

        Returns a function ``step(u, mu) -> (u_next, S)`` on deviations ``u`` from
        the contact state on the section ``t = t*``; ``S`` is the impact speed
        (0 when the map's square-root branch is not active).
        """
        b, h_p, rate_p = self.unfolding[param]
        M, e, a = self.monodromy, self.direction, self.accel
        gh, gv = self.grad_h, self.grad_rate

        def step(u: np.ndarray, mu: float) -> tuple[np.ndarray, float]:
            h = gh @ u + h_p * mu
            v = gv @ u + rate_p * mu
            delta = v * v / (2 * a) - h
            s = math.sqrt(2 * a * delta) if delta > 0 else 0.0
            return M @ (u - e * s) + b * mu, s

        return step


def normal_form_at(point: GrazingPoint, params: tuple[str, ...]) -> GrazingNormalForm:
    """Build the normal form of a grazing point, with unfolding vectors for the parameters ``params``.

    Parameters
    ----------
    point
        The grazing orbit (:func:`find_grazing_point`, :func:`~grazing.orbits.find_grazings`).
    params
        The unfolding parameters (the derivatives of the map with respect to them are computed).

    Returns
    -------
    GrazingNormalForm
        The map's ingredients at the point.

    Examples
    --------
    >>> import math, grazing
    >>> from grazing.orbits import find_grazings
    >>> g, _ = find_grazings(grazing.models.pendulum("B", theta_hat=math.radians(40)), "eta", 0.4, 0.47)
    >>> nf = normal_form_at(g[0], ("eta", "theta_hat"))
    >>> [float(round(v, 4)) + 0.0 for v in nf.direction], round(nf.kappa, 3)
    ([0.0, 1.7675], 0.28)
    """
    m, x, t = point.model, point.contact, point.t_graze
    cd = m.contact_derivatives(x, t, point.stop)
    e = zdm_direction(m, x, t, point.stop)
    M = point.monodromy
    kappa = float(-(cd["h_x"] @ M @ e) / np.linalg.norm(e))
    names = [p.name for p in m.parameters]
    fm = flow_map(m, x, t0=t, periods=point.period, sensitivities=list(params), virtual=True, mode=point.mode)
    unfolding = {}
    for j, p in enumerate(params):
        i = names.index(p)
        unfolding[p] = (fm.sensitivity[:, j].copy(), float(cd["h_p"][i]), float(cd["rate_p"][i]))
    return GrazingNormalForm(
        point=point,
        accel=cd["accel"],
        direction=e,
        grad_h=cd["h_x"],
        grad_rate=cd["rate_x"],
        kappa=kappa,
        unfolding=unfolding,
    )


def find_grazing_point(
    model: HybridModel,
    param: str,
    lo: float,
    hi: float,
    which: str = "first",
    stop_name: int | str | None = None,
    *,
    x0: Sequence[float] | np.ndarray | None = None,
) -> GrazingPoint:
    """The first or second grazing of the period-1 nonimpacting orbit for ``param`` in ``[lo, hi]``.

    ``stop_name``: the stop grazed (name or index; the first by default).
    ``x0``: a guess of the nonimpacting orbit at time 0 with ``param = lo``,
    needed where that orbit is unstable (see
    :func:`~grazing.orbits.grazing.find_grazings`).

    Raises :class:`~grazing.errors.ConvergenceError` (one clear line) if there is none.

    Parameters
    ----------
    model
        The model, with the values of the other parameters.
    param
        The parameter searched.
    lo, hi
        Its interval.
    which
        ``"first"`` or ``"second"`` grazing in increasing ``param``.
    stop_name
        The stop grazed (name or index; the first by default).
    x0
        A guess of the nonimpacting orbit (see above).

    Returns
    -------
    GrazingPoint
        The grazing orbit.

    Examples
    --------
    The paper's two grazings at θ̂ = 40° (case B):

    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> [round(find_grazing_point(m, "eta", 0.40, 0.60, which).model.params["eta"], 4)
    ...  for which in ("first", "second")]
    [0.4451, 0.5473]
    """
    from grazing.errors import ConvergenceError, InvalidParameterError
    from grazing.orbits.grazing import find_grazings

    if which not in ("first", "second"):
        raise InvalidParameterError(f"which must be 'first' or 'second', got {which!r}")
    points, _ = find_grazings(model, param, lo, hi, x0=x0, stop_name=stop_name)
    points.sort(key=lambda g: g.model.params[param])
    k = 0 if which == "first" else 1
    if len(points) <= k:
        raise ConvergenceError(
            f"no {which} grazing of the period-1 orbit for {model.parameter(param).show_range(lo, hi)} "
            f"(found {len(points)}); the discontinuity map needs a grazing orbit"
        )
    return points[k]
