"""Where a bifurcation curve meets a grazing curve: a codimension-two point, from the grazing equations.

A branch of impacting orbits keeps its impact sequence up to a grazing; so
does a curve of its folds, period-doublings or Neimark-Sacker points, which
therefore ends where it meets the grazing curve of its orbit.  The point is
found in two steps, from the last point of the curve before it:

1. :func:`nearest_grazing`: the grazing orbit closest to that point, from the
   contact equations of :mod:`grazing.orbits.contact` in both parameters, with
   the parameters on the normal through the point to the grazing curve.
2. :func:`meeting_point`: the contact equations with the curve's defining
   condition in its limit at the grazing, as one square system.  Where the
   orbit *gains* an impact (it touches the stop between its impacts) its
   monodromy is continuous there: the condition is that of the grazing orbit,
   ``det A(J) = 0`` (``J`` its monodromy through the contact, the contact not
   an impact).  Where an impact's speed falls to zero (the orbit *loses* it),
   the monodromy is ``S J`` with the saltation matrix
   ``S = g_x + N h_x / nu`` of an impact at normal speed ``nu -> 0``
   (``N = f(g(y)) - g_x f(y) - g_t``): it is unbounded, and ``det A(g_x J +
   N h_x J / nu) = d0 + d1 / nu`` (exactly, for a fold, a period-doubling and a
   Neimark-Sacker point of two states: a rank-one change) vanishes near the
   grazing only where ``d1 = 0``.  There the curve meets the grazing curve
   tangentially (the multipliers vary as the square root of the distance to
   it), which is why step 1 alone locates it only to about the square root of
   the last point's distance.  A Neimark-Sacker curve of more than two states
   (its bialternate product is quadratic in ``S J``: not a rank-one change):
   as ``nu -> 0`` one multiplier grows as ``c N / nu`` (``c = h_x J``) and the
   others tend to those of ``P g_x J`` on the hyperplane ``c x = 0``, ``P``
   the projection onto it along ``N``; the condition is that two of those
   have the product 1, ``det A(Q^T P g_x J Q) = 0`` (``Q`` an orthonormal
   basis of the hyperplane; the same whatever the basis).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.options import CORRECTOR_TOL
from grazing.errors import GrazingError
from grazing.orbits.contact import CONTACT_MAX_NEWTON, CONTACT_TOL, GrazingPoint, contact_system
from grazing.orbits.extended import defining_matrix
from grazing.orbits.kinds import CurveKind
from grazing.orbits.palc import PalcSettings, newton

FAILURES = (GrazingError, np.linalg.LinAlgError, FloatingPointError)
"""Errors of an evaluation that mean: no solution here."""

NEWTON = PalcSettings(tol=CONTACT_TOL, max_newton=CONTACT_MAX_NEWTON)
"""Newton's method on the contact equations (as :func:`~grazing.orbits.contact.refine_grazing`)."""

DIFFERENCE_STEP = 1e-7
"""The step of :func:`_gradient`'s central differences (relative to ``max(1, |u|)``): near the square
root of the machine epsilon, the usual step for a function computed to rounding (truncation error about
1e-14, rounding about 1e-9 relative).  The gradient only steers Newton's method, whose end is decided on
its step (:data:`MEETING_STEP`) and on the residual (:data:`MEETING_RESIDUAL`)."""

MEETING_STEP = 1e-12
"""Newton's method for a codimension-two point stops once its step is below this (relative to
``max(1, |u|)``), as the contact equations' own (:data:`~grazing.orbits.contact.CONTACT_TOL`)."""

MEETING_REACH = 1e-3
"""A codimension-two point farther than this (relative) in the parameters from the grazing orbit it was
sought from is another one (Newton wandered), and not taken."""

MEETING_RESIDUAL = CORRECTOR_TOL
"""A codimension-two point is taken when the contact equations hold there to this: the tolerance of the
curves it lies on (:data:`~grazing.core.options.CORRECTOR_TOL`)."""


def project_on_contact(model: HybridModel, y: np.ndarray, t: float, stop: int) -> np.ndarray:
    """``y`` moved (least change) onto the contact conditions ``h = 0``, ``L_f h = 0`` to first order.

    An impact state at a small normal speed is not a contact: the flow from it
    starts with an impact whose saltation matrix is nearly singular.
    """
    cd = model.contact_derivatives(y, t, stop)
    rows = np.vstack([cd["h_x"], cd["rate_x"]])
    return y - np.linalg.lstsq(rows, np.array([cd["h"], cd["rate"]]), rcond=None)[0]


def contact_guess(
    model: HybridModel, params: tuple[str, str], period: int, events: bool, stop: int, y: np.ndarray,
    t: float, p: np.ndarray,
) -> GrazingPoint | None:  # fmt: skip
    """The grazing orbit's guess itself: the contact equations evaluated at ``(y, t)`` moved onto the
    contact (:func:`project_on_contact`) and the parameters ``p``, not solved (None where the evaluation
    fails).

    Where a fold curve meets a grazing curve, the grazing curve turns back in the parameters (the
    orbits' surface folds there): no grazing orbit is "nearest" along a line through ``p``
    (:func:`nearest_grazing`), and :func:`meeting_point` starts from this guess instead.
    """
    m = model.with_params(**{q: float(v) for q, v in zip(params, p)})
    contact = contact_system(model, params, period, events=events, stop=stop)
    try:
        return contact(np.concatenate([project_on_contact(m, y, t, stop), [t], p]))[2]
    except FAILURES:
        return None


def nearest_grazing(
    model: HybridModel, params: tuple[str, str], period: int, events: bool, stop: int, y: np.ndarray,
    t: float, p: np.ndarray,
) -> GrazingPoint | None:  # fmt: skip
    """The grazing orbit of stop ``stop`` nearest the parameters ``p``, from the contact guess ``(y, t)``.

    The contact equations in both parameters, with the parameters on the line
    through ``p`` normal to the grazing curve (its tangent at the guess).
    """
    n = model.n_states
    m = model.with_params(**{q: float(v) for q, v in zip(params, p)})
    contact = contact_system(model, params, period, events=events, stop=stop)
    u0 = np.concatenate([project_on_contact(m, y, t, stop), [t], p])
    try:
        _, DF, _ = contact(u0)
    except FAILURES:
        return None
    along = np.linalg.svd(DF)[2][-1][n + 1 :]  # the grazing curve's direction in the parameters
    if not np.any(along):
        return None
    along = along / np.linalg.norm(along)

    def evaluate(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, GrazingPoint]:
        F, DF, point = contact(u)
        row = np.zeros(n + 3)
        row[n + 1 :] = along
        return np.append(F, along @ (u[n + 1 :] - p)), np.vstack([DF, row]), point

    sol = newton(evaluate, u0, NEWTON)
    return None if sol is None else sol.payload


def limit_condition(kind: str, point: GrazingPoint, loses: bool) -> float:
    """The defining condition of a curve of ``kind`` in its limit at a grazing (see the module docstring).

    ``loses``: the curve's orbit has an impact at the contact (its speed tending to zero);
    else it only touches the stop there.  NaN where the limit has no multiplier growing as
    ``1 / nu`` (``c N = 0``).
    """
    det_kind = CurveKind.FOLD if kind == CurveKind.BRANCH_POINT else kind
    J = point.monodromy
    if not loses:
        return float(np.linalg.det(defining_matrix(det_kind, J)))
    n = J.shape[0]
    m, y, t, j = point.model, point.contact, point.t_graze, point.stop
    _, h_x, g_x = m.jacobians(y, t, j)
    g_t = np.asarray(m._call("g_t", y, t, j), dtype=float).reshape(-1)
    N = m.vector_field(m.reset(y, t, j), t) - g_x @ m.vector_field(y, t) - g_t
    M0 = g_x @ J
    if kind == CurveKind.NEIMARK_SACKER and n > 2:
        return float(np.linalg.det(defining_matrix(det_kind, reduced_limit(M0, N, h_x @ J))))
    R = np.outer(N, h_x @ J)
    size = float(np.linalg.norm(R))
    if size == 0:
        return math.nan
    R = R / size * max(1.0, float(np.linalg.norm(M0)))
    return float(
        np.linalg.det(defining_matrix(det_kind, M0 + R)) - np.linalg.det(defining_matrix(det_kind, M0))
    )


def reduced_limit(M0: np.ndarray, N: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The matrix whose eigenvalues are the limits of the bounded eigenvalues of ``M0 + N c^T / nu`` as
    ``nu -> 0`` (one grows as ``c N / nu``): ``P M0`` on the hyperplane ``c x = 0``, in an orthonormal
    basis ``Q`` of it, ``P = I - N c^T / (c N)`` the projection onto it along ``N``.  NaN where ``c N = 0``.

    Examples
    --------
    >>> M0, N, c = np.diag([0.5, 0.8, 2.0]), np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0])
    >>> np.sort(np.linalg.eigvals(reduced_limit(M0, N, c))).tolist()
    [0.5, 0.8]
    """
    n = M0.shape[0]
    cN = float(c @ N)
    if not (math.isfinite(cN) and abs(cN) > 0.0):
        return np.full((n - 1, n - 1), math.nan)
    P = np.eye(n) - np.outer(N, c) / cN
    Q = np.linalg.svd(c[None, :])[2][1:].T  # (n, n - 1): orthonormal, orthogonal to c
    return Q.T @ P @ M0 @ Q


def _gradient(f, u: np.ndarray, fu: float) -> np.ndarray:
    """The gradient of ``f`` at ``u`` by central differences, one-sided where a step leaves the domain
    (a contact state moved beyond its stop)."""
    grad = np.empty(u.size)
    for k in range(u.size):
        h = DIFFERENCE_STEP * max(1.0, abs(u[k]))
        e = np.zeros(u.size)
        e[k] = h
        values = []
        for step in (e, -e):
            try:
                values.append(f(u + step))
            except FAILURES:
                values.append(None)
        plus, minus = values
        if plus is not None and minus is not None:
            grad[k] = (plus - minus) / (2 * h)
        elif plus is not None or minus is not None:
            grad[k] = (plus - fu) / h if plus is not None else (fu - minus) / h  # type: ignore[operator]
        else:
            raise GrazingError("no difference step stays in the domain")
    return grad


def meeting_point(
    kind: str, params: tuple[str, str], events: bool, near: GrazingPoint, loses: bool
) -> GrazingPoint | None:
    """The codimension-two point where the curve of ``kind`` meets the grazing curve, from a grazing
    orbit ``near`` it: Newton's method on the contact equations and :func:`limit_condition` (its
    gradient by central differences).  None if it does not converge, or converges far from ``near``
    (more than :data:`MEETING_REACH` relative in the parameters).  Its ``precision`` is the larger
    parameter component of the last Newton step (the error before that step: a bound on the error after
    it, once the iteration converges)."""
    model, period, stop = near.model, near.period, near.stop
    n = model.n_states
    contact = contact_system(model, params, period, events=events, stop=stop)

    def system(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, GrazingPoint]:
        F, DF, point = contact(u)
        return F, DF, point

    def condition(u: np.ndarray) -> float:
        return limit_condition(kind, system(u)[2], loses)

    u = np.concatenate([near.contact, [near.t_graze], [near.model.params[q] for q in params]])
    p0 = u[n + 1 :].copy()
    scale = max(1.0, float(np.max(np.abs(u))))
    for _ in range(NEWTON.max_newton):
        try:
            F, DF, point = system(u)
            c = limit_condition(kind, point, loses)
            if not math.isfinite(c):
                return None
            grad = _gradient(condition, u, c)
            du = np.linalg.solve(np.vstack([DF, grad]), -np.append(F, c))
        except FAILURES:  # a failed evaluation or a singular system: not found
            return None
        u = u + du
        if np.max(np.abs(du)) <= MEETING_STEP * scale:
            break
    else:
        return None
    try:
        F, _, point = system(u)
    except FAILURES:
        return None
    far = np.max(np.abs(u[n + 1 :] - p0)) > MEETING_REACH * max(1.0, float(np.max(np.abs(p0))))
    if far or not np.max(np.abs(F)) <= MEETING_RESIDUAL:
        return None
    return dataclasses.replace(point, precision=float(np.max(np.abs(du[n + 1 :]))))
