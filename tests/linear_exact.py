"""An exact reference for linear forced impact models: matrix exponentials, impacts by bracketing.

Between impacts ``x' = A x + b cos(w t)``; the solution is
``x(t) = exp(A (t - t0)) (x0 - xp(t0)) + xp(t)`` with the periodic particular
solution ``xp(t) = Re(X exp(i w t))``, ``X = (i w I - A)^-1 b``.  A stop is a
linear guard ``h = c . x + d`` (positive where motion is free) with a linear
reset ``x <- R x``.  Impacts are found on the exact solution (the guard sampled
densely, each sign change refined by Brent's method to 1e-15), and the map's
Jacobian is the product of the flows' exponentials and the saltation matrices
``S = R + (f+ - R f-) c^T / (c^T f-)``.  Nothing here uses grazing's engine: its
Taylor integration, event location and variational equations are what this
checks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import sympy as sp
from scipy.linalg import expm
from scipy.optimize import brentq

import grazing
from grazing import HybridModel, Parameter
from grazing.core.symbolic import Stop

SAMPLES_PER_PERIOD = 400
"""The guard is sampled this often per forcing period between impacts (the impacts here are
transversal; a sampled sign change is refined by Brent's method)."""


@dataclass(frozen=True)
class LinearStop:
    """A stop of a linear model: guard ``c . x + d``, reset ``x <- R x``."""

    c: np.ndarray
    d: float
    R: np.ndarray


@dataclass
class LinearImpactModel:
    """``x' = A x + b cos(w t)`` with linear stops (the exact reference)."""

    A: np.ndarray
    b: np.ndarray
    w: float
    stops: list[LinearStop]
    X: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        n = self.A.shape[0]
        self.X = np.linalg.solve(1j * self.w * np.eye(n) - self.A, self.b.astype(complex))

    @property
    def period(self) -> float:
        return 2 * math.pi / self.w

    def xp(self, t: float) -> np.ndarray:
        return (self.X * np.exp(1j * self.w * t)).real

    def f(self, x: np.ndarray, t: float) -> np.ndarray:
        return self.A @ x + self.b * math.cos(self.w * t)

    def flow(self, x0: np.ndarray, t0: float, t: float) -> np.ndarray:
        return expm(self.A * (t - t0)) @ (x0 - self.xp(t0)) + self.xp(t)

    def first_impact(self, x0: np.ndarray, t0: float, t1: float, skip: int) -> tuple[float, int] | None:
        """The first impact in ``(t0, t1]`` (time, stop), ``skip`` the stop just left (-1: none)."""
        n = max(4, math.ceil((t1 - t0) / self.period * SAMPLES_PER_PERIOD))
        ts = np.linspace(t0, t1, n + 1)
        # x(t) on the grid: exp(A k dt) by repeated multiplication
        E = expm(self.A * (ts[1] - ts[0]))
        y = x0 - self.xp(t0)
        prev = None
        for k, t in enumerate(ts):
            if k:
                y = E @ y
            x = y + self.xp(t)
            h = np.array([s.c @ x + s.d for s in self.stops])
            if prev is not None:
                for j, s in enumerate(self.stops):
                    if prev[1][j] > 0 >= h[j] and not (k == 1 and j == skip):
                        ta = prev[0]
                        g = lambda tt, s=s: float(s.c @ self.flow(x0, t0, tt) + s.d)  # noqa: E731
                        return brentq(g, ta, t, xtol=1e-15, rtol=1e-15, maxiter=200), j
            prev = (t, h)
        return None

    def flow_map(self, x0: np.ndarray, t0: float, periods: int = 1) -> tuple[np.ndarray, np.ndarray, list]:
        """``(P^n(x0), dP^n/dx0, [(t, stop), ...])`` over ``periods`` forcing periods from ``t0``."""
        t_end = t0 + periods * self.period
        x, t = np.array(x0, dtype=float), t0
        J = np.eye(x.size)
        impacts = []
        skip = -1
        while True:
            hit = self.first_impact(x, t, t_end, skip)
            if hit is None:
                J = expm(self.A * (t_end - t)) @ J
                return self.flow(x, t, t_end), J, impacts
            ti, j = hit
            xm = self.flow(x, t, ti)
            s = self.stops[j]
            xp = s.R @ xm
            fm, fp = self.f(xm, ti), self.f(xp, ti)
            S = s.R + np.outer(fp - s.R @ fm, s.c) / float(s.c @ fm)
            J = S @ expm(self.A * (ti - t)) @ J
            impacts.append((ti, j))
            x, t, skip = xp, ti, j

    def periodic_orbit(
        self, x0: np.ndarray, t0: float = 0.0, periods: int = 1
    ) -> tuple[np.ndarray, np.ndarray]:
        """The fixed point of ``P^n`` near ``x0`` (Newton) and its monodromy."""
        x = np.array(x0, dtype=float)
        for _ in range(30):
            img, J, _ = self.flow_map(x, t0, periods)
            F = img - x
            if np.max(np.abs(F)) < 1e-14 * max(1.0, np.max(np.abs(x))):
                break
            x = x - np.linalg.solve(J - np.eye(x.size), F)
        img, J, _ = self.flow_map(x, t0, periods)
        return x, J


def pair_closest_to_circle(J: np.ndarray) -> complex:
    """The multiplier of positive imaginary part whose complex pair is closest to the unit circle."""
    mu = np.linalg.eigvals(J)
    upper = mu[mu.imag > 1e-9]
    return complex(upper[np.argmin(np.abs(np.abs(upper) - 1.0))])


def neimark_sacker_parameter(
    build, lo: float, hi: float, x0: np.ndarray, t0: float = 0.0
) -> tuple[float, complex]:
    """The parameter in ``[lo, hi]`` where the pair closest to the circle is on it, and that multiplier.

    ``build(p)`` gives the :class:`LinearImpactModel` at ``p``; ``x0`` is near the period-1 orbit
    on the section ``t0``.
    """
    state = {"x": np.array(x0, dtype=float)}

    def modulus_minus_one(p: float) -> float:
        x, J = build(p).periodic_orbit(state["x"], t0)
        state["x"] = x
        return abs(pair_closest_to_circle(J)) - 1.0

    p = brentq(modulus_minus_one, lo, hi, xtol=1e-14, rtol=1e-15)
    _, J = build(p).periodic_orbit(state["x"], t0)
    return p, pair_closest_to_circle(J)


# ----------------------------------------------------------------------------
# The models: the impact damper (4 states) and a 6-state one with an absorber on the primary mass


def damper_matrices(omega: float, *, zeta=0.05, amp=1.0, mu=0.3, gap=2.0, r=0.8, absorber=None):
    """The impact damper (``grazing.models.impact_damper``, ``omega2 = 0``) as a linear reference; with
    ``absorber = (k3, zeta3, coupling)`` two more states: a mass ``x3`` on a spring of stiffness ``k3``
    and damping ``2 zeta3 sqrt(k3)``, tied to the primary by a spring ``coupling``."""
    n = 4 if absorber is None else 6
    A = np.zeros((n, n))
    A[0, 1] = 1.0
    A[1, 0], A[1, 1] = -1.0, -2 * zeta
    A[2, 3] = 1.0
    b = np.zeros(n)
    b[1] = amp
    if absorber is not None:
        k3, zeta3, kc = absorber
        A[1, 0] -= kc
        A[1, 4] = kc
        A[4, 5] = 1.0
        A[5, 4], A[5, 5], A[5, 0] = -k3 - kc, -2 * zeta3 * math.sqrt(k3), kc
    R = np.eye(n)
    # v1 <- v1 + mu (1 + r)/(1 + mu) (v2 - v1); v2 <- v2 - (1 + r)/(1 + mu) (v2 - v1)
    a1, a2 = mu * (1 + r) / (1 + mu), (1 + r) / (1 + mu)
    R[1, 1], R[1, 3] = 1 - a1, a1
    R[3, 1], R[3, 3] = a2, 1 - a2
    c = np.zeros(n)
    c[0], c[2] = 1.0, -1.0  # right: gap - (x2 - x1)
    stops = [LinearStop(c, gap, R), LinearStop(-c, gap, R)]
    return LinearImpactModel(A, b, omega, stops)


def six_state_model(*, k3=2.3, zeta3=0.04, coupling=0.05, **values: float) -> HybridModel:
    """The impact damper with a damped absorber mass on the primary (6 states), with unusual names.

    States ``Xp, Vp`` (primary), ``Xq, Vq`` (rattling mass), ``Xa, Va`` (absorber); parameters
    ``zeta, amp, Om, mu, d, rr, k3, zeta3, kc``; stops ``east`` and ``west``.
    """
    Xp, Vp, Xq, Vq, Xa, Va, s = sp.symbols("Xp Vp Xq Vq Xa Va s")
    zeta, amp, Om, mu, d, rr, K3, Z3, kc = sp.symbols("zeta amp Om mu d rr k3 zeta3 kc")
    dv = Vq - Vp
    reset = [Xp, Vp + mu * (1 + rr) / (1 + mu) * dv, Xq, Vq - (1 + rr) / (1 + mu) * dv, Xa, Va]
    field = [
        Vp, -2 * zeta * Vp - Xp + amp * sp.cos(Om * s) - kc * (Xp - Xa),
        Vq, 0,
        Va, -2 * Z3 * sp.sqrt(K3) * Va - K3 * Xa - kc * (Xa - Xp),
    ]  # fmt: skip
    direction = [0, mu, 0, -1, 0, 0]
    defaults = {"zeta": 0.05, "amp": 1.0, "Om": 1.2, "mu": 0.3, "d": 2.0, "rr": 0.8, "k3": k3, "zeta3": zeta3,
                "kc": coupling}  # fmt: skip
    defaults.update(values)
    params = [Parameter(name, value) for name, value in defaults.items()]
    return HybridModel(
        "six-state-damper", [Xp, Vp, Xq, Vq, Xa, Va], s, params, field, period=2 * sp.pi / Om,
        stops=[Stop("east", d - (Xq - Xp), reset, direction), Stop("west", d + (Xq - Xp), reset, direction)],
    )  # fmt: skip


def six_state_matrices(model: HybridModel) -> LinearImpactModel:
    """:func:`damper_matrices` with the absorber, at ``model``'s parameter values."""
    p = model.params
    return damper_matrices(
        p["Om"], zeta=p["zeta"], amp=p["amp"], mu=p["mu"], gap=p["d"], r=p["rr"],
        absorber=(p["k3"], p["zeta3"], p["kc"]),
    )  # fmt: skip


def damper(**values: float) -> HybridModel:
    """``grazing.models.impact_damper`` at ``values`` (mu = 0.3, r = 0.8 unless given)."""
    return grazing.models.impact_damper(**{"mu": 0.3, "r": 0.8, **values})


# ----------------------------------------------------------------------------
# An inverted pendulum between two walls: a saddle flow between impacts (multipliers ~1e7 near grazing)


def inverted_walls(**values: float) -> HybridModel:
    """``q'' = k q - c q' + a cos(w s)`` between walls at ``q = +-1`` (``q' <- -r q'``), names ``q, v, s``.

    The upright position is a saddle (eigenvalues ``+-sqrt(k)``): over a period the flow between
    impacts stretches by ``exp(sqrt(k) T)``, and a saltation matrix adds ``1 / v`` as an impact speed
    ``v`` falls to zero.
    """
    q, v, s = sp.symbols("q v s")
    k, c, a, w, r = sp.symbols("k c a w r")
    defaults = {"k": 2.0, "c": 0.1, "a": 3.0, "w": 2.0, "r": 0.8}
    defaults.update(values)
    reset = [q, -r * v]
    return HybridModel(
        "inverted-walls", [q, v], s, [Parameter(name, value) for name, value in defaults.items()],
        [v, k * q - c * v + a * sp.cos(w * s)], period=2 * sp.pi / w,
        stops=[Stop("right", 1 - q, reset, [0, 1]), Stop("left", 1 + q, reset, [0, 1])],
    )  # fmt: skip


def inverted_walls_matrices(model: HybridModel) -> LinearImpactModel:
    """:func:`inverted_walls` as a :class:`LinearImpactModel` at ``model``'s parameter values."""
    p = model.params
    A = np.array([[0.0, 1.0], [p["k"], -p["c"]]])
    R = np.diag([1.0, -p["r"]])
    stops = [LinearStop(np.array([-1.0, 0.0]), 1.0, R), LinearStop(np.array([1.0, 0.0]), 1.0, R)]
    return LinearImpactModel(A, np.array([0.0, p["a"]]), p["w"], stops)


def grazing_of_impact(build, stops, t0: float, guess: np.ndarray, grazing: int) -> np.ndarray:
    """The parameter where impact ``grazing`` (an index into ``stops``) of a period-1 orbit has zero speed.

    Unknowns ``z = (s_0, t_1, ..., t_k, p)``; the orbit is flown exactly (matrix exponentials) from
    ``s_0`` at ``t0`` through impacts on ``stops`` at the times ``t_i`` (each guard zero there), and
    returns to ``s_0`` at ``t0 + T``; the speed of impact ``grazing`` is zero.  ``build(p)`` gives the
    :class:`LinearImpactModel`; ``guess`` is a guess of ``z``.  Returns the solved ``z``.
    """
    from scipy.optimize import least_squares

    k = len(stops)

    def residual(z: np.ndarray) -> np.ndarray:
        ref = build(float(z[-1]))
        x, t = z[:2], t0
        out = []
        for i, j in enumerate(stops):
            ti = float(z[2 + i])
            y = ref.flow(x, t, ti)
            st = ref.stops[j]
            out.append(st.c @ y + st.d)
            if i == grazing:
                out.append(st.c @ ref.f(y, ti))  # (the guard's rate: zero speed)
            x, t = st.R @ y, ti
        out.extend(ref.flow(x, t, t0 + ref.period) - z[:2])
        return np.array(out)

    assert len(residual(guess)) == 2 + k + 1
    sol = least_squares(residual, guess, xtol=1e-15, ftol=1e-15, gtol=1e-15, method="lm")
    assert np.max(np.abs(residual(sol.x))) < 1e-12, residual(sol.x)
    return sol.x


# ----------------------------------------------------------------------------
# Random two- and three-body models: a primary mass, a rattling mass between two walls, an absorber


def chain_model(bodies: int) -> HybridModel:
    """A forced primary mass ``P`` (spring ``kP``, damping ``cP``, forcing ``F0 cos(wf s)``), a mass ``Q``
    rattling in a cavity of half-width ``gap`` (tied to ``P`` by a spring ``kQ`` and dashpot ``cQ``;
    stops ``upper`` and ``lower``, momentum-conserving resets with mass ratio ``m`` and restitution
    ``e``), and with ``bodies = 3`` an absorber ``A`` on ``P`` (spring ``kA``, damping ``cA``).

    States ``P, dP, Q, dQ[, A, dA]``; time ``s``; the period ``2 pi / wf`` is set by ``wf``.  Every
    parameter's default is 1 (they are drawn by the tests).
    """
    P, dP, Q, dQ, A, dA, s = sp.symbols("P dP Q dQ A dA s")
    kP, cP, F0, wf, kQ, cQ, gap, m, e, kA, cA = sp.symbols("kP cP F0 wf kQ cQ gap m e kA cA")
    coupling = kQ * (Q - P) + cQ * (dQ - dP)
    field = [dP, -kP * P - cP * dP + F0 * sp.cos(wf * s) + m * coupling, dQ, -coupling]
    states = [P, dP, Q, dQ]
    names = ["kP", "cP", "F0", "wf", "kQ", "cQ", "gap", "m", "e"]
    if bodies == 3:
        field[1] += kA * (A - P) + cA * (dA - dP)
        field += [dA, -kA * (A - P) - cA * (dA - dP)]
        states += [A, dA]
        names += ["kA", "cA"]
    dv = dQ - dP
    reset = [P, dP + m * (1 + e) / (1 + m) * dv, Q, dQ - (1 + e) / (1 + m) * dv, *states[4:]]
    direction = [0, m, 0, -1] + [0] * (len(states) - 4)
    params = [Parameter(name, 1.0) for name in names]
    return HybridModel(
        f"chain-{bodies}", states, s, params, field, period=2 * sp.pi / wf,
        stops=[
            Stop("upper", gap - (Q - P), reset, direction), Stop("lower", gap + (Q - P), reset, direction),
        ],
    )  # fmt: skip


def chain_matrices(model: HybridModel) -> LinearImpactModel:
    """:func:`chain_model` as a :class:`LinearImpactModel` at ``model``'s parameter values."""
    p = model.params
    n = model.n_states
    A = np.zeros((n, n))
    A[0, 1] = A[2, 3] = 1.0
    A[1, 0], A[1, 1] = -p["kP"], -p["cP"]
    # the coupling kQ (Q - P) + cQ (dQ - dP): + m on P's acceleration, - on Q's
    for row, sign in ((1, p["m"]), (3, -1.0)):
        A[row, 2] += sign * p["kQ"]
        A[row, 0] -= sign * p["kQ"]
        A[row, 3] += sign * p["cQ"]
        A[row, 1] -= sign * p["cQ"]
    if n == 6:
        A[4, 5] = 1.0
        for row, sign in ((1, 1.0), (5, -1.0)):
            A[row, 4] += sign * p["kA"]
            A[row, 0] -= sign * p["kA"]
            A[row, 5] += sign * p["cA"]
            A[row, 1] -= sign * p["cA"]
    b = np.zeros(n)
    b[1] = p["F0"]
    R = np.eye(n)
    a1, a2 = p["m"] * (1 + p["e"]) / (1 + p["m"]), (1 + p["e"]) / (1 + p["m"])
    R[1, 1], R[1, 3] = 1 - a1, a1
    R[3, 1], R[3, 3] = a2, 1 - a2
    c = np.zeros(n)
    c[0], c[2] = 1.0, -1.0  # upper: gap - (Q - P)
    return LinearImpactModel(A, b, p["wf"], [LinearStop(c, p["gap"], R), LinearStop(-c, p["gap"], R)])
