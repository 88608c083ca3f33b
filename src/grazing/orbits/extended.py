"""Extended systems of bifurcation curves of periodic orbits in two parameters, and their test functions.

A bifurcation of a period-``n`` orbit is followed in two parameters ``p = (p1, p2)``
on the shooting formulation: the unknowns are a point ``x`` of the orbit on the
stroboscopic section ``t0`` and ``p``; the equations are the periodicity
``P^n(x; p) - x = 0`` (the Jacobian ``[M - I, P_p]`` from the variational
equations with saltation matrices at the impacts, ``M`` the monodromy, the
parameter columns including the moving return time of a parameter that sets the
forcing period: :func:`~grazing.maps.flow_map`) and one scalar defining
condition ``g = 0``, a minimally augmented test function
(:mod:`grazing.orbits.bordered`):

* fold and branch point: ``A = M - I`` singular;
* period-doubling: ``A = M + I`` singular;
* Neimark-Sacker: ``A = M (.) M - I`` singular (bialternate product; for two
  states ``det M - 1``).

Its gradient is ``dg = -w^T dA v`` with the derivatives of the monodromy from
central differences of the map's Jacobian, using the symmetry of second
derivatives: ``d/dz (M v) = d/ds P_z(x + s v)`` for every unknown ``z`` (states
and parameters), so one direction (``v``) gives the whole gradient for folds and
period-doublings, and the ``n`` state directions give every derivative of ``M``
(Neimark-Sacker, branch points).

A branch point of a one-parameter family (``p1``) is where ``[M - I, P_p1]``
loses rank: ``M - I`` is singular and ``P_p1`` lies in its range
(``w^T P_p1 = 0``, ``w`` the left null vector).  Where a branch point persists
along a curve (a symmetric system: a symmetric orbit losing its symmetry), the
equations ``P^n - x = 0`` are singular on the curve (two branches cross); they
are regularised with an unknown ``shift`` as ``P^n(x; p) - x + shift psi = 0``
(``psi`` the left null vector of the last point), with ``g = 0`` and
``w^T P_p1 = 0``: ``shift`` is zero on the curve (Govaerts 2000, sec. 4.2;
MatCont's branch point continuation).

The grazing of an orbit (a contact with a stop at zero normal speed) is
followed on the contact equations of :mod:`grazing.orbits.contact`, with the
orbit's other impacts applied.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from grazing.core.model import HybridModel
from grazing.errors import ConvergenceError, GrazingError
from grazing.maps import FlowMap, flow_map
from grazing.orbits.bifurcations import critical_pair, resolved_multipliers
from grazing.orbits.bordered import Bordered, Borders, bialternate, bordered
from grazing.orbits.contact import GrazingPoint, contact_system
from grazing.orbits.shooting import PeriodicOrbit, _orbit_from

DIFFERENCE_STEP = 1e-6
"""Step of the central differences of the map's Jacobian, relative to ``max(1, |x|, |p|)``."""


MONODROMY_ROUNDING = 64.0
"""The computed monodromy ``M`` is taken to be accurate to this many ``eps |M|`` (``eps`` the
machine epsilon, ``|M|`` the 2-norm): a bound, not an estimate (what is left of the scatter of the
critical multipliers under rounding-level changes of a curve point, once the first-order effect of
the changes is taken out, is 0.2 to 70 ``eps |M|`` times the eigenvalue condition number on the
curves of the tests).  What a monodromy of a given norm can resolve is judged by it
(``core.options.UNRESOLVED_NORM``, ``core.options.NON_ISOLATED_TOL``); a curve point's
:func:`multiplier_accuracy` is an estimate instead."""

UNKNOWN_ROUNDING = 2.0
"""A curve point's unknowns ``u = (x, p1, p2)`` are known to this many ``eps |u_i|`` each (their
rounding in double precision, and that of the arithmetic that produced them)."""

INTEGRATION_ROUNDING = 1.0
"""The rounding of the orbit by the integration, in units of the unknowns' (``UNKNOWN_ROUNDING eps
sum_i |dg/du_i| |u_i|``): the state, the time and the forcing phase are rounded at each step and
each impact, which changes the orbit as rounding-level changes of its unknowns do."""

ENTRY_ROUNDING = 1.0
"""The rounding of the computed monodromy's own entries, in ``eps |M|``: it moves the defining
condition by up to this times ``eps |M| |w| |v|`` (``2 |M|`` times that for ``M (.) M``), the least
that any computed ``M`` carries (where :data:`MONODROMY_ROUNDING` is the most)."""


def defining_matrix(kind: str, M: np.ndarray) -> np.ndarray:
    """The matrix ``A`` that is singular on a curve of ``kind`` (see the module docstring)."""
    eye = np.eye(M.shape[0])
    if kind in ("fold", "branch-point"):
        return M - eye
    if kind == "period-doubling":
        return M + eye
    if kind == "neimark-sacker":
        return bialternate(M, M) - np.eye(M.shape[0] * (M.shape[0] - 1) // 2)
    raise ValueError(f"no defining matrix for {kind!r}")


def multiplier_accuracy(kind: str, M: np.ndarray, sol: Bordered, grad: np.ndarray, u: np.ndarray) -> float:
    """How far the critical multipliers of a curve point may be from the curve's condition: an estimate.

    The distance of ``mu`` from 1 (fold, branch point), of ``mu`` from -1
    (period-doubling), of ``mu_i mu_j`` from 1 (Neimark-Sacker).  ``A``'s eigenvalue
    nearest zero is ``lambda = -g / (w^T v)`` to first order in the defining
    condition ``g`` (``sol``: :class:`~grazing.orbits.bordered.Bordered` of ``A``), so
    the point is

    .. math::

        \\frac{|g| + (1 + c_I)\\, c_u \\varepsilon \\sum_i |\\partial g / \\partial u_i|\\, |u_i|
        + c_M \\varepsilon |M|\\, |w|\\, |v|}{|w^T v|}

    from it: Newton's residual ``|g|``; the rounding of the unknowns
    ``u = (x, p1, p2)`` (:data:`UNKNOWN_ROUNDING` ``c_u eps |u_i|`` each) through the
    gradient ``grad`` of ``g`` (the row of the extended system's Jacobian); the
    integration's rounding of the orbit, :data:`INTEGRATION_ROUNDING` ``c_I`` times
    that; and the rounding of the monodromy's entries (:data:`ENTRY_ROUNDING` ``c_M``;
    ``2 |M|`` times it for ``M (.) M``).  Near a grazing, where a saltation matrix
    holds ``1 / v`` (``v`` the impact speed), this grows like ``1 / v^2``: no point
    represented in double precision does better.  Against the larger of the
    scatter of the critical multipliers under random rounding-level changes
    (``2 eps`` relative, 32 draws) of the point's unknowns and their own distance from
    the condition, it is 0.6 to 4.7 times it on the fold, period-doubling and
    Neimark-Sacker curves of the tests (docs/bifurcation-curves.md).

    Examples
    --------
    >>> M = np.array([[1.0 + 1e-12, 1e4], [0.0, 0.5]])  # a multiplier 1 + 1e-12, far from normal
    >>> sol = bordered(defining_matrix("fold", M), Borders.of(defining_matrix("fold", M)))
    >>> u = np.array([0.5, -1.0, 2.0, 3.0])
    >>> eps, kappa = np.finfo(float).eps, sol.eigenvalue_condition
    >>> residual = 1e-12 + ENTRY_ROUNDING * eps * np.linalg.norm(M, 2) * kappa  # g moves with nothing
    >>> bool(np.isclose(multiplier_accuracy("fold", M, sol, np.zeros(4), u), residual))
    True
    >>> grad = np.array([0.0, 0.0, 1e3, 0.0])  # g moves with p1 alone
    >>> rounding = (1 + INTEGRATION_ROUNDING) * UNKNOWN_ROUNDING * eps * 1e3 * 2.0 / abs(sol.w @ sol.v)
    >>> bool(np.isclose(multiplier_accuracy("fold", M, sol, grad, u), residual + rounding))
    True
    """
    wv = abs(float(sol.w @ sol.v))
    if wv == 0:
        return math.inf
    eps = float(np.finfo(float).eps)
    unknowns = UNKNOWN_ROUNDING * eps * float(np.abs(grad) @ np.abs(u[: grad.size]))
    norm = float(np.linalg.norm(M, 2))
    entries = ENTRY_ROUNDING * eps * norm * (2.0 * norm if kind == "neimark-sacker" else 1.0)
    action = entries * float(np.linalg.norm(sol.w) * np.linalg.norm(sol.v))
    return (abs(sol.g) + (1.0 + INTEGRATION_ROUNDING) * unknowns + action) / wv


# ----------------------------------------------------------------------------
# Test functions of codimension-two points


def _critical(kind: str, mu: np.ndarray) -> list[int]:
    """The multipliers that the defining condition of ``kind`` puts on the unit circle."""
    if kind in ("fold", "branch-point"):
        return [int(np.argmin(np.abs(mu - 1.0)))]
    if kind == "period-doubling":
        return [int(np.argmin(np.abs(mu + 1.0)))]
    if kind == "neimark-sacker":
        return list(critical_pair(mu))
    return []


def _through(mu: np.ndarray, z: float) -> float:
    """``prod (mu_k - z)`` (real: complex multipliers come in conjugate pairs); 1 for none."""
    return float(np.prod(mu - z).real) if mu.size else 1.0


def _pair_on_circle(mu: np.ndarray) -> float:
    """``prod (|mu|^2 - 1) / (1 + |mu|^2)`` over the complex pairs among ``mu`` (nan where there is none).

    Zero where one pair is on the unit circle, whatever the number of pairs (a model of three or more
    degrees of freedom has several); each factor scaled into ``(-1, 1)``.

    Examples
    --------
    >>> two = np.array([1.1 * np.exp(0.4j), 1.1 * np.exp(-0.4j), 0.5 * np.exp(2j), 0.5 * np.exp(-2j)])
    >>> _pair_on_circle(two) < 0, _pair_on_circle(np.array([0.5, 0.2]))
    (True, nan)
    """
    upper = mu[mu.imag > 1e-12]
    if not upper.size:
        return math.nan
    m2 = np.abs(upper) ** 2
    return float(np.prod((m2 - 1.0) / (1.0 + m2)))


CODIM2_TESTS: dict[str, tuple[str, ...]] = {
    "fold": ("cusp", "1:1 resonance", "fold-flip", "fold-neimark-sacker"),
    "period-doubling": ("fold-flip", "1:2 resonance", "flip-neimark-sacker"),
    "neimark-sacker": (
        "1:1 resonance", "1:2 resonance", "1:3 resonance", "1:4 resonance", "fold-neimark-sacker",
        "flip-neimark-sacker", "double neimark-sacker",
    ),
    "branch-point": ("fold", "period-doubling", "neimark-sacker"),
    "grazing": ("fold", "period-doubling", "neimark-sacker"),
}  # fmt: skip
"""The codimension-two points detected along each kind of curve (by sign changes of test functions).

On a fold curve: a cusp (the fold's quadratic coefficient vanishes), a second
multiplier +1 (1:1 resonance), a multiplier -1 (fold-flip) or a pair on the
unit circle (fold-Neimark-Sacker); on a period-doubling curve: a multiplier +1
(fold-flip), a second -1 (1:2 resonance), a pair on the circle; on a
Neimark-Sacker curve, with ``mu = exp(+-i theta)`` the critical pair: the
strong resonances ``theta = 0, pi, 2 pi / 3, pi / 2`` and another multiplier
+1, -1 or pair on the circle.  A branch-point curve and a grazing curve meet
the fold, period-doubling and Neimark-Sacker curves of their orbits."""

ENDING = {"neimark-sacker": ("1:1 resonance", "1:2 resonance")}
"""Codimension-two points that end a curve: beyond a 1:1 or 1:2 resonance the Neimark-Sacker
pair is real (``mu`` and ``1/mu``: a neutral saddle, not a bifurcation)."""


def codim2_tests(kind: str, mu: np.ndarray, cusp: float = math.nan) -> dict[str, float]:
    """The test functions of the codimension-two points on a curve of ``kind`` at multipliers ``mu``."""
    crit = _critical(kind, mu)
    others = np.delete(mu, crit)
    if kind == "fold":
        return {
            "cusp": cusp,
            "1:1 resonance": _through(others, 1.0),
            "fold-flip": _through(others, -1.0),
            "fold-neimark-sacker": _pair_on_circle(others),
        }
    if kind == "period-doubling":
        return {
            "fold-flip": _through(others, 1.0),
            "1:2 resonance": _through(others, -1.0),
            "flip-neimark-sacker": _pair_on_circle(others),
        }
    if kind == "neimark-sacker":
        sigma = float((mu[crit[0]] + mu[crit[1]]).real)  # 2 cos(theta) on the circle
        return {
            "1:1 resonance": sigma - 2.0,
            "1:2 resonance": sigma + 2.0,
            "1:3 resonance": sigma + 1.0 if abs(sigma) < 2 else math.nan,
            "1:4 resonance": sigma if abs(sigma) < 2 else math.nan,
            "fold-neimark-sacker": _through(others, 1.0),
            "flip-neimark-sacker": _through(others, -1.0),
            "double neimark-sacker": _pair_on_circle(others),
        }
    others = others if kind == "branch-point" else mu
    return {
        "fold": _through(others, 1.0),
        "period-doubling": _through(others, -1.0),
        "neimark-sacker": _pair_on_circle(others),
    }


# ----------------------------------------------------------------------------
# The extended systems


@dataclass(frozen=True)
class Evaluation:
    """What an extended system knows at a point (the payload of its PALC points).

    Attributes
    ----------
    orbit
        The periodic orbit (curves of orbit bifurcations; None on a grazing curve).
    grazing
        The grazing orbit (grazing curves).
    condition
        The defining condition's value (zero on the curve): the test function
        ``g``, or the guard at the contact for a grazing.
    tests
        The codimension-two test functions (:func:`codim2_tests`).
    shift
        The regularising unknown of a branch-point curve (zero on the curve).
    solution
        The bordered system's solution (null vectors), if any.
    accuracy
        How far the critical multipliers may be from the condition (:func:`multiplier_accuracy`;
        nan on a grazing curve).
    """

    orbit: PeriodicOrbit | None
    grazing: GrazingPoint | None
    condition: float
    tests: dict[str, float] = field(default_factory=dict)
    shift: float = 0.0
    solution: Bordered | None = None
    accuracy: float = math.nan

    @property
    def monodromy(self) -> np.ndarray:
        return self.orbit.monodromy if self.orbit is not None else self.grazing.monodromy  # type: ignore[union-attr]

    @property
    def multipliers(self) -> np.ndarray:
        return self.orbit.multipliers if self.orbit is not None else self.grazing.multipliers  # type: ignore[union-attr]


def directional_difference(f, z: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """``d/ds f(z + s direction)`` at ``s = 0`` by central differences, the step :data:`DIFFERENCE_STEP`
    relative to ``max(1, |z|)``; one-sided where a step raises a :class:`~grazing.errors.GrazingError`
    (a bound or a grazing within the step).

    Examples
    --------
    >>> d = directional_difference(lambda z: np.outer(z, z), np.array([1.0, 2.0]), np.array([0.0, 1.0]))
    >>> bool(np.allclose(d, [[0.0, 1.0], [1.0, 4.0]]))
    True
    """
    h = DIFFERENCE_STEP * max(1.0, float(np.max(np.abs(z)))) / float(np.max(np.abs(direction)))
    try:
        plus = f(z + h * direction)
    except GrazingError:
        return (f(z) - f(z - h * direction)) / h
    try:
        minus = f(z - h * direction)
    except GrazingError:
        return (plus - f(z)) / h
    return (plus - minus) / (2 * h)


class OrbitSystem:
    """The extended system of a fold, period-doubling, Neimark-Sacker or branch-point curve.

    Unknowns ``u = (x, p1, p2)`` (and ``shift`` for a branch point, last);
    ``evaluate(u) -> (F, DF, Evaluation)``.  The bordering vectors are those of
    the last accepted point: :meth:`accept` updates them.
    """

    def __init__(
        self, model: HybridModel, kind: str, params: tuple[str, str], period: int, t0: float,
        virtual: bool, stop: int, monodromy: np.ndarray, mode: str | None = None,
    ):  # fmt: skip
        self.model, self.kind, self.params = model, kind, params
        self.period, self.t0, self.virtual, self.stop = period, t0, virtual, stop
        self.mode = mode  # (a model with modes: the mode on the section)
        self.n = model.n_states
        self.borders = Borders.of(defining_matrix(kind, monodromy))

    def start(self, orbit: PeriodicOrbit) -> np.ndarray:
        """The unknowns at an orbit (``shift = 0``)."""
        u = np.concatenate([orbit.state, [orbit.model.params[q] for q in self.params]])
        return np.append(u, 0.0) if self.kind == "branch-point" else u

    def accept(self, payload: Evaluation) -> None:
        """Border the next points with the null vectors of this one."""
        if payload.solution is not None:
            self.borders = self.borders.updated(payload.solution)

    def _map(self, x: np.ndarray, p: np.ndarray) -> tuple[HybridModel, FlowMap]:
        m = self.model.with_params(**{q: float(v) for q, v in zip(self.params, p)})
        fm = flow_map(
            m, x, t0=self.t0, periods=self.period, sensitivities=self.params, virtual=self.virtual,
            stop_name=self.stop, mode=self.mode,
        )  # fmt: skip
        if not fm.solution.jacobian_valid:
            raise ConvergenceError("the orbit sticks to the stop: no Jacobian across sticking")
        return m, fm

    def jacobian(self, x: np.ndarray, p: np.ndarray, impacts: int | None = None) -> np.ndarray:
        """``[P_x, P_p1, P_p2]`` at ``(x, p)`` (on the same impact count, if given)."""
        _, fm = self._map(x, p)
        if impacts is not None and fm.impacts != impacts:
            raise ConvergenceError("a difference step crosses a grazing")
        return np.hstack([fm.jacobian, fm.sensitivity])

    def along(self, x: np.ndarray, p: np.ndarray, dx: np.ndarray, dp: np.ndarray, impacts: int) -> np.ndarray:
        """``d/ds [P_x, P_p](x + s dx, p + s dp)`` at ``s = 0``, by central differences
        (:func:`directional_difference`)."""
        n = x.size
        return directional_difference(
            lambda z: self.jacobian(z[:n], z[n:], impacts), np.concatenate([x, p]), np.concatenate([dx, dp])
        )

    def __call__(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, Evaluation]:
        n, kind = self.n, self.kind
        x, p = u[:n], u[n : n + 2]
        m, fm = self._map(x, p)
        M, S = fm.jacobian, fm.sensitivity
        F0 = fm.image - x
        orbit = _orbit_from(
            m, x, self.t0, self.period, fm, self.virtual, [float(np.max(np.abs(F0)))], self.stop
        )
        sol = bordered(defining_matrix(kind, M), self.borders)
        zeros = np.zeros(2)
        cusp = math.nan
        if kind in ("fold", "period-doubling"):
            D = self.along(x, p, sol.v, zeros, fm.impacts)  # d/ds [P_x, P_p](x + s v)
            grad = -sol.w @ D
            if kind == "fold":
                cusp = 0.5 * float(sol.w @ D[:, :n] @ sol.v) / float(sol.w @ sol.v)
        else:
            T = [self.along(x, p, e, zeros, fm.impacts) for e in np.eye(n)]  # d/dx_j [P_x, P_p]
            if kind == "neimark-sacker":
                # dM/dz_k has column j = d/dx_j P_z_k = T[j][:, k]; d(M (.) M) = 2 dM (.) M.
                grad = np.array(
                    [sol.derivative(2 * bialternate(np.stack([t[:, k] for t in T], axis=1), M))
                     for k in range(n + 2)]
                )  # fmt: skip
            else:
                return self._branch_point(u, orbit, fm, sol, T)
        F = np.append(F0, sol.g)
        DF = np.vstack([np.hstack([M - np.eye(n), S]), grad])
        tests = codim2_tests(kind, resolved_multipliers(orbit), cusp)
        accuracy = multiplier_accuracy(kind, M, sol, grad, u)
        return F, DF, Evaluation(orbit, None, sol.g, tests, 0.0, sol, accuracy)

    def _branch_point(
        self, u: np.ndarray, orbit: PeriodicOrbit, fm: FlowMap, sol: Bordered, T: list[np.ndarray]
    ) -> tuple[np.ndarray, np.ndarray, Evaluation]:
        """``(P^n - x + shift psi, g, w^T P_p1)`` and its Jacobian in ``(x, p1, p2, shift)``."""
        n = self.n
        x, p, shift = u[:n], u[n : n + 2], float(u[n + 2])
        M, S = fm.jacobian, fm.sensitivity
        psi = self.borders.b
        Tp = self.along(x, p, np.zeros(n), np.array([1.0, 0.0]), fm.impacts)  # d/dp1 [P_x, P_p]
        Q = np.array([sol.w @ t for t in T])  # Q[j, k] = w^T d/dz_k P_x_j: (w^T dA/dz_k)_j
        grad_g = -sol.v @ Q
        # The bordered transposed system, differentiated: K^T [w_z; g_z] = -[dA^T w; 0].
        dw = (sol.inverse_transposed @ -np.vstack([Q, np.zeros((1, n + 2))]))[:n]
        g2 = float(sol.w @ S[:, 0])
        grad_g2 = S[:, 0] @ dw + sol.w @ Tp
        F = np.concatenate([fm.image - x + shift * psi, [sol.g, g2]])
        DF = np.zeros((n + 2, n + 3))
        DF[:n, :n] = M - np.eye(n)
        DF[:n, n : n + 2] = S
        DF[:n, n + 2] = psi
        DF[n, : n + 2] = grad_g
        DF[n + 1, : n + 2] = grad_g2
        tests = codim2_tests("branch-point", resolved_multipliers(orbit))
        accuracy = multiplier_accuracy("branch-point", M, sol, grad_g, u)
        return F, DF, Evaluation(orbit, None, sol.g, tests, shift, sol, accuracy)


class GrazingSystem:
    """The contact equations of a grazing orbit in two parameters
    (:func:`~grazing.orbits.contact.contact_system`).

    Unknowns ``u = (y, t_g, p1, p2)``: the contact state and time and the parameters.
    """

    def __init__(self, model: HybridModel, params: tuple[str, str], period: int, events: bool, stop: int):
        self.params, self.n = params, model.n_states
        self._evaluate = contact_system(model, params, period, events=events, stop=stop)

    def start(self, point: GrazingPoint) -> np.ndarray:
        return np.concatenate([point.contact, [point.t_graze], [point.model.params[q] for q in self.params]])

    def accept(self, payload: Evaluation) -> None:
        """(Nothing to update.)"""

    def __call__(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, Evaluation]:
        F, DF, point = self._evaluate(u)
        tests = codim2_tests("grazing", point.multipliers)
        return F, DF, Evaluation(None, point, float(F[self.n]), tests)
