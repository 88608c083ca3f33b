"""Extended systems of bifurcation curves on the multiple-shooting equations.

Where an orbit's monodromy ``M`` is large (a saddle flow between impacts, a
saltation matrix's ``1 / v`` as an impact speed ``v`` falls: ``|M|`` of
``1e7`` and more), single shooting's residual cannot fall below
``|M| eps |x|`` and the extended systems of :mod:`grazing.orbits.extended`
(built on ``P^n(x) - x = 0``) cannot be solved.  Here a fold, period-doubling,
Neimark-Sacker or branch-point curve is followed on the segmented equations
of :mod:`grazing.orbits.segments` (one segment of free flight per impact, the
impact times and the states after the impacts as unknowns), with the defining
condition taken from the *segmented* Jacobian, as COCO's ``hspo`` toolbox takes
it from its collocation Jacobian (Dankowicz & Schilder, *Recipes for
Continuation*, SIAM 2013):

* unknowns ``u = (z, p1, p2)`` (``z`` the segment unknowns
  ``(s_0, t_1, s_1, ..., t_k, s_k)``), and for a Neimark-Sacker curve the
  angle of the critical pair (``angle``), for a branch-point curve the
  regularising ``shift`` (as in :mod:`grazing.orbits.extended`), last;
* equations: the segmented equations ``F(z; p) = 0`` and the defining
  condition.

The segmented Jacobian ``J = dF/dz`` is square; eliminating the impact times
and the states after the impacts segment by segment leaves ``M - I`` on the
section state ``s_0`` (the return equation ``phi(s_k) - s_0`` has ``-I`` in
the columns of ``s_0``), so ``det J = det(M - I)`` times the guards' rates
``h_x f`` at the impacts (nonzero: an impact has a speed).  Replacing that
``-I`` by ``-mu I`` gives ``A(mu)``, singular exactly where ``mu`` is a
multiplier:

* fold and branch point: ``A(1) = J`` singular;
* period-doubling: ``A(-1)`` singular;
* Neimark-Sacker: ``A(exp(i angle))`` singular, a complex condition (two real
  equations) with ``angle`` an unknown: the critical pair ``exp(+-i angle)``.

The defining condition is the ``g`` of the bordered system of ``A``
(:mod:`grazing.orbits.bordered`), its gradient ``-w^T dA v`` with the
derivatives of ``J`` from central differences of the segmented Jacobian along
``v`` (the symmetry of second derivatives: ``d/dz_j (J v) = d/ds F_{z_j}(z + s v)``
for every unknown ``z_j``, the parameters included).  Every entry of ``J`` is
one segment's, rounded as a segment is: the condition holds to a segment's
accuracy however large the product of the segments is.  The multipliers and
the codimension-two tests are those of the monodromy, the product of the
segments' ``Phi`` and the saltation matrices.
"""

from __future__ import annotations

import math

import numpy as np

from grazing.core.model import HybridModel
from grazing.orbits.bifurcations import critical_pair, resolved_multipliers
from grazing.orbits.bordered import Bordered, Borders, bordered
from grazing.orbits.extended import (
    ENTRY_ROUNDING,
    INTEGRATION_ROUNDING,
    UNKNOWN_ROUNDING,
    Evaluation,
    codim2_tests,
    directional_difference,
)
from grazing.orbits.periodic import PeriodicOrbit
from grazing.orbits.segments import SegmentLayout, layout_of, segmented_equations

CRITICAL_MULTIPLIER = {"fold": 1.0, "branch-point": 1.0, "period-doubling": -1.0}
"""The multiplier ``mu`` at which ``A(mu)`` is singular on a curve of each real kind (the
Neimark-Sacker curve's is ``exp(i angle)``, ``angle`` an unknown)."""


def multiplier_slope(null: Bordered, n: int) -> complex:
    """``dg/dmu = w_r^T v_0``: how the defining condition moves with the multiplier ``mu`` of ``A(mu)``.

    ``A(mu)`` is ``-mu`` times the identity in the return equations' (the last ``n`` rows) columns of
    ``s_0`` (the first ``n`` unknowns), so ``dg/dmu = -w^T (dA/dmu) v`` is ``w``'s return rows times
    ``v``'s entries of ``s_0``; the critical multiplier is ``mu - g / (w_r^T v_0)`` to first order.
    """
    return complex(null.w[-n:] @ null.v[:n])


def multiplier_accuracy(
    kind: str, J: np.ndarray, null: Bordered, grad: np.ndarray, u: np.ndarray, n: int
) -> float:
    """How far the critical multiplier(s) of a segmented curve point may be from the curve's condition.

    ``A(mu)``'s dependence on ``mu`` is ``-mu`` times the identity in the
    return equations' columns of ``s_0``, so ``dg/dmu = w_r^T v_0`` (``w_r``:
    ``w``'s return rows, ``v_0``: ``v``'s entries of ``s_0``) and the critical
    multiplier is ``-g / (w_r^T v_0)`` from the condition's to first order.  As
    :func:`grazing.orbits.extended.multiplier_accuracy`: Newton's residual
    ``|g|``, the unknowns' rounding through the gradient ``grad`` (and the
    integration's, :data:`~grazing.orbits.extended.INTEGRATION_ROUNDING` times
    it) and the rounding of ``J``'s own entries, each to ``eps`` of itself
    (``eps |w|^T |J| |v|``, componentwise: an entry that the null vectors do not
    meet moves nothing), over ``|w_r^T v_0|``; twice that on a Neimark-Sacker
    curve, where it is the distance of ``mu_i mu_j`` from 1.  ``J``'s entries
    are each one segment's (no product of segments): this stays of the order of
    a segment's rounding however large the monodromy is.
    """
    wv = abs(multiplier_slope(null, n))
    if wv == 0:
        return math.inf
    eps = float(np.finfo(float).eps)
    unknowns = UNKNOWN_ROUNDING * eps * float(np.abs(grad) @ np.abs(u[: grad.size]))
    action = ENTRY_ROUNDING * eps * float(np.abs(null.w) @ np.abs(J) @ np.abs(null.v))
    scale = 2.0 if kind == "neimark-sacker" else 1.0
    return scale * (abs(null.g) + (1.0 + INTEGRATION_ROUNDING) * unknowns + action) / wv


class SegmentedOrbitSystem:
    """The extended system of a fold, period-doubling, Neimark-Sacker or branch-point curve on the
    segmented equations (see the module docstring).

    Unknowns ``u = (z, p1, p2)``, then ``angle`` (Neimark-Sacker) or ``shift``
    (branch point); ``evaluate(u) -> (F, DF, Evaluation)``.  The bordering vectors
    are those of the last accepted point (:meth:`accept`).  :attr:`offset` is the
    index of ``p1`` in ``u``.  The segments are those of ``orbit``'s impacts, or ``layout``.
    """

    def __init__(
        self, model: HybridModel, kind: str, params: tuple[str, str], period: int, t0: float, stop: int,
        orbit: PeriodicOrbit | None = None, layout: SegmentLayout | None = None,
    ):  # fmt: skip
        self.model, self.kind, self.params, self.period, self.t0 = model, kind, params, period, t0
        self.n = model.n_states
        if layout is None:
            assert orbit is not None, "give the orbit or the layout of its impacts"
            layout = layout_of(orbit)
        self.layout: SegmentLayout = layout
        self.offset = self.layout.size
        self._equations = segmented_equations(model, params, period, t0, self.layout, stop)
        self._borders: tuple[np.ndarray, np.ndarray] | None = None

    # -- the unknowns ---------------------------------------------------------------------
    def start(self, orbit: PeriodicOrbit) -> np.ndarray:
        """The unknowns at an orbit of this impact sequence (``angle``: its critical pair's angle)."""
        values = [orbit.model.params[q] for q in self.params]
        u = self.layout.pack(orbit, values[0])
        u = np.append(u, values[1])
        if self.kind == "neimark-sacker":
            i, _ = critical_pair(orbit.multipliers)
            return np.append(u, abs(float(np.angle(orbit.multipliers[i]))))
        return np.append(u, 0.0) if self.kind == "branch-point" else u

    def accept(self, payload: Evaluation) -> None:
        """Border the next points with the null vectors of this one (same orientation as before)."""
        null = payload.solution
        if not isinstance(null, Bordered):
            return
        b, c = np.conj(null.w), np.conj(null.v)
        b, c = b / np.linalg.norm(b), c / np.linalg.norm(c)
        if self._borders is not None:  # (keep the sign, or the phase, of the condition's convention)
            b = b * _phase(np.vdot(b, self._borders[0]))
            c = c * _phase(np.vdot(c, self._borders[1]))
        if not np.iscomplexobj(null.v):
            b, c = b.real, c.real
        self._borders = (b, c)

    # -- the defining matrix ---------------------------------------------------------------
    def defining(self, J: np.ndarray, mu: complex) -> np.ndarray:
        """``A(mu)``: ``J`` with ``-mu I`` for ``-I`` in the return equations' columns of ``s_0``."""
        n = self.n
        A = J.astype(complex) if isinstance(mu, complex) else J.copy()
        A[-n:, :n] += (1.0 - mu) * np.eye(n)
        return A

    def _null(self, A: np.ndarray) -> Bordered:
        if self._borders is None:
            U, _, Vt = np.linalg.svd(A)
            self._borders = (U[:, -1].copy(), np.conj(Vt[-1]).copy())
        b, c = self._borders
        return bordered(A, Borders(b.astype(A.dtype), c.astype(A.dtype)))

    # -- derivatives ------------------------------------------------------------------------
    def _jacobian(self, u: np.ndarray) -> np.ndarray:
        return self._equations(u)[1]

    def along(self, u: np.ndarray, direction: np.ndarray) -> np.ndarray:
        """``d/ds DF(u + s direction)`` at ``s = 0`` (``u``: the segment unknowns and the parameters), by
        central differences (:func:`~grazing.orbits.extended.directional_difference`)."""
        return directional_difference(self._jacobian, u, direction)

    # -- the system ------------------------------------------------------------------------
    def __call__(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, Evaluation]:
        if self.kind == "neimark-sacker":
            return self._neimark_sacker(u)
        if self.kind == "branch-point":
            return self._branch_point(u)
        m = self.offset + 2
        z = u[:m]
        F0, DF0, orbit = self._equations(z)
        J = DF0[:, : self.offset]
        null = self._null(self.defining(J, CRITICAL_MULTIPLIER[self.kind]))
        v = null.v.real
        D = self.along(z, np.concatenate([v, [0.0, 0.0]]))  # d/ds DF(z + s v)
        grad = -null.w.real @ D
        cusp = math.nan
        if self.kind == "fold":
            cusp = 0.5 * float(null.w.real @ D[:, : self.offset] @ v) / multiplier_slope(null, self.n).real
        g = float(null.g.real)
        F = np.append(F0, g)
        DF = np.vstack([DF0, grad])
        tests = codim2_tests(self.kind, resolved_multipliers(orbit), cusp)
        accuracy = multiplier_accuracy(self.kind, J, null, grad, u, self.n)
        return F, DF, Evaluation(orbit, None, g, tests, 0.0, null, accuracy)  # type: ignore[arg-type]

    def _neimark_sacker(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, Evaluation]:
        """``(F, Re g, Im g)`` in ``(z, p1, p2, angle)``: ``A(exp(i angle))`` singular."""
        m, n = self.offset + 2, self.n
        z, angle = u[:m], float(u[m])
        F0, DF0, orbit = self._equations(z)
        J = DF0[:, : self.offset]
        mu = complex(np.exp(1j * angle))
        null = self._null(self.defining(J, mu))
        pad = np.zeros(2)
        Dr = self.along(z, np.concatenate([null.v.real, pad]))
        Di = self.along(z, np.concatenate([null.v.imag, pad]))
        dg = -(null.w @ Dr + 1j * (null.w @ Di))  # d g / d (z, p1, p2)
        dg_angle = 1j * mu * multiplier_slope(null, n)  # dg/dmu dmu/dangle
        grad = np.append(dg, dg_angle)
        F = np.concatenate([F0, [null.g.real, null.g.imag]])
        DF = np.zeros((F.size, u.size))
        DF[: F0.size, :m] = DF0
        DF[-2] = grad.real
        DF[-1] = grad.imag
        tests = codim2_tests("neimark-sacker", resolved_multipliers(orbit))
        accuracy = multiplier_accuracy("neimark-sacker", J, null, np.abs(grad), u, n)
        return F, DF, Evaluation(orbit, None, abs(null.g), tests, 0.0, null, accuracy)  # type: ignore[arg-type]

    def _branch_point(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, Evaluation]:
        """``(F + shift psi, g, w^T F_p1)`` in ``(z, p1, p2, shift)`` (as
        :meth:`grazing.orbits.extended.OrbitSystem._branch_point`, on the segmented equations)."""
        size, m = self.offset, self.offset + 2
        z, shift = u[:m], float(u[m])
        F0, DF0, orbit = self._equations(z)
        J = DF0[:, :size]
        null = self._null(J)
        v, w = null.v.real, null.w.real
        assert self._borders is not None
        psi = self._borders[0].real
        T = [self.along(z, np.eye(m)[j]) for j in range(size)]  # d/dz_j DF
        Tp = self.along(z, np.eye(m)[size])  # d/dp1 DF
        Q = np.array([w @ t for t in T])  # Q[j, k] = w^T d^2 F / dz_j du_k: (w^T dJ/du_k)_j
        grad_g = -v @ Q
        # The bordered transposed system, differentiated: K^T [w_u; g_u] = -[dJ^T w; 0].
        dw = (null.inverse_transposed @ -np.vstack([Q, np.zeros((1, m))]))[:size]
        Fp1 = DF0[:, size]
        g2 = float(w @ Fp1)
        grad_g2 = Fp1 @ dw + w @ Tp
        F = np.concatenate([F0 + shift * psi, [float(null.g.real), g2]])
        DF = np.zeros((size + 2, m + 1))
        DF[:size, :m] = DF0
        DF[:size, m] = psi
        DF[size, :m] = grad_g
        DF[size + 1, :m] = grad_g2
        tests = codim2_tests("branch-point", resolved_multipliers(orbit))
        accuracy = multiplier_accuracy("branch-point", J, null, grad_g, u, self.n)
        return F, DF, Evaluation(orbit, None, float(null.g.real), tests, shift, null, accuracy)  # type: ignore[arg-type]


def _phase(z: complex) -> complex:
    """The unit factor that turns a vector's overlap ``z`` with the previous one to the positive reals."""
    return complex(z / abs(z)) if abs(z) > 0 else 1.0
