"""Minimally augmented test functions: bordered systems and the bialternate product.

A square matrix ``A`` (``m x m``) is singular exactly where the scalar ``g``
of the bordered system

.. math::

    \\begin{pmatrix} A & b \\\\ c^T & 0 \\end{pmatrix}
    \\begin{pmatrix} v \\\\ g \\end{pmatrix} =
    \\begin{pmatrix} 0 \\\\ 1 \\end{pmatrix}

vanishes, for any bordering vectors ``b``, ``c`` that keep the bordered matrix
nonsingular (close to the left and right null vectors of ``A``); the transposed
system gives ``w`` with ``w^T A = -g c^T``, and the derivative of ``g`` along any
change of ``A`` is ``dg = -w^T dA v`` (Govaerts, *Numerical Methods for
Bifurcations of Dynamical Equilibria*, SIAM 2000, ch. 3 and 4; Kuznetsov,
*Elements of Applied Bifurcation Theory*, 3rd ed., ch. 10).  At ``g = 0``,
``v`` and ``w`` are the right and left null vectors of ``A``.

For the monodromy ``M`` of a periodic orbit (the Jacobian of its period map):

* ``A = M - I``: a multiplier +1 (fold, branch point);
* ``A = M + I``: a multiplier -1 (period-doubling);
* ``A = M (.) M - I``, with the bialternate product ``M (.) M`` (the second
  compound matrix: its eigenvalues are the products ``mu_i mu_j``, ``i < j``):
  two multipliers whose product is 1, a pair on the unit circle
  (Neimark-Sacker) or a real pair ``mu, 1/mu`` (a neutral saddle).  For two
  states ``M (.) M = det M``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def _pairs(n: int) -> list[tuple[int, int]]:
    """The index pairs ``(p, q)``, ``p > q``, that number the rows of a bialternate product."""
    return [(p, q) for p in range(1, n) for q in range(p)]


def bialternate(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """The bialternate product ``A (.) B`` of two ``n x n`` matrices (``m x m``, ``m = n(n-1)/2``).

    .. math::

        (A \\odot B)_{(p,q),(r,s)} = \\tfrac12 \\left(
        \\begin{vmatrix} a_{pr} & a_{ps} \\\\ b_{qr} & b_{qs} \\end{vmatrix} +
        \\begin{vmatrix} b_{pr} & b_{ps} \\\\ a_{qr} & a_{qs} \\end{vmatrix} \\right)

    with ``p > q``, ``r > s`` (Govaerts 2000, sec. 4.4.4).  It is bilinear and
    symmetric, so ``d(M (.) M) = 2 dM (.) M``; the eigenvalues of ``M (.) M``
    are the products ``mu_i mu_j`` (``i < j``) of the eigenvalues of ``M``.

    Examples
    --------
    >>> M = np.array([[2.0, 1.0], [0.5, 3.0]])
    >>> float(bialternate(M, M)[0, 0]) == float(np.linalg.det(M))
    True
    >>> M = np.diag([2.0, 3.0, 5.0])
    >>> sorted(np.linalg.eigvals(bialternate(M, M)).real.round(12).tolist())
    [6.0, 10.0, 15.0]
    """
    n = A.shape[0]
    idx = _pairs(n)
    p, q = np.array([i for i, _ in idx]), np.array([j for _, j in idx])
    r, s = p, q
    a_pr, a_ps, a_qr, a_qs = A[np.ix_(p, r)], A[np.ix_(p, s)], A[np.ix_(q, r)], A[np.ix_(q, s)]
    b_pr, b_ps, b_qr, b_qs = B[np.ix_(p, r)], B[np.ix_(p, s)], B[np.ix_(q, r)], B[np.ix_(q, s)]
    return 0.5 * ((a_pr * b_qs - a_ps * b_qr) + (b_pr * a_qs - b_ps * a_qr))


@dataclass(frozen=True)
class Borders:
    """The bordering vectors: ``b`` (close to the left null vector), ``c`` (close to the right one)."""

    b: np.ndarray
    c: np.ndarray

    @classmethod
    def of(cls, A: np.ndarray) -> Borders:
        """Borders from the singular vectors of ``A``'s smallest singular value."""
        u, _, vt = np.linalg.svd(A)
        return cls(u[:, -1].copy(), vt[-1].copy())

    def updated(self, solution: Bordered) -> Borders:
        """The borders for the next point: the null vectors found at this one (unit length, same
        orientation as before, so that the test function keeps its sign convention)."""
        b = solution.w / np.linalg.norm(solution.w)
        c = solution.v / np.linalg.norm(solution.v)
        return Borders(b if b @ self.b >= 0 else -b, c if c @ self.c >= 0 else -c)


@dataclass(frozen=True)
class Bordered:
    """The solution of the bordered system of ``A`` (see the module docstring).

    Attributes
    ----------
    g
        The test function: zero where ``A`` is singular (complex for a complex ``A``).
    v, w
        ``A v = -g b`` with ``c^T v = 1``, and ``A^T w = -g c`` with ``b^T w = 1``: at
        ``g = 0`` the right and left null vectors of ``A``.
    inverse_transposed
        The inverse of the transposed bordered matrix (for derivatives of ``w``).
    """

    g: float
    v: np.ndarray
    w: np.ndarray
    inverse_transposed: np.ndarray

    def derivative(self, dA: np.ndarray) -> float:
        """``dg = -w^T dA v``: the change of ``g`` for a change ``dA`` of ``A``."""
        return float(-self.w @ dA @ self.v)

    @property
    def eigenvalue_condition(self) -> float:
        """``|v| |w| / |w^T v|``: the condition number of ``A``'s eigenvalue nearest zero.

        ``A + g b c^T`` is singular, with null vectors ``v`` and ``w``, so ``A``'s
        eigenvalue nearest zero is ``-g / (w^T v)`` to first order in ``g``, and a
        change ``dA`` moves it by at most this number times ``|dA|`` (Wilkinson's
        ``1 / |cos|`` of the angle between the null vectors; 1 for a normal
        matrix, large for a strongly non-normal one such as a monodromy near a
        grazing, where a saltation matrix holds ``1 / v``, ``v`` the impact speed).
        Infinite where the null vectors are orthogonal (a defective eigenvalue).

        Examples
        --------
        >>> A = np.array([[1e-12, 1e4], [0.0, 0.5]])  # eigenvalue 1e-12, far from normal
        >>> sol = bordered(A, Borders.of(A))
        >>> bool(abs(-sol.g / (sol.w @ sol.v) - 1e-12) < 1e-20), round(sol.eigenvalue_condition / 2e4, 3)
        (True, 1.0)
        """
        wv = abs(float(self.w @ self.v))
        norms = float(np.linalg.norm(self.v) * np.linalg.norm(self.w))
        return norms / wv if wv > 0 else math.inf


def bordered(A: np.ndarray, borders: Borders) -> Bordered:
    """Solve the bordered system of ``A`` and its transpose (see the module docstring).

    A complex ``A`` (with complex borders) gives a complex ``g``, with plain transposes throughout.

    Examples
    --------
    >>> A = np.array([[1.0, 2.0], [2.0, 4.0]])  # singular
    >>> sol = bordered(A, Borders.of(A))
    >>> abs(sol.g) < 1e-14, bool(np.allclose(A @ sol.v, 0)), bool(np.allclose(sol.w @ A, 0))
    (True, True, True)
    >>> z = bordered(A * 1j, Borders(np.array([2.0, -1.0]) + 0j, np.array([2.0, -1.0]) + 0j))
    >>> bool(abs(z.g) < 1e-14), bool(np.allclose(A @ z.v, 0)), bool(np.allclose(z.w @ A, 0))
    (True, True, True)
    """
    m = A.shape[0]
    K = np.zeros((m + 1, m + 1), dtype=np.result_type(A, borders.b, borders.c))
    K[:m, :m] = A
    K[:m, m] = borders.b
    K[m, :m] = borders.c
    rhs = np.zeros(m + 1)
    rhs[m] = 1.0
    inv_t = np.linalg.inv(K.T)
    right = np.linalg.solve(K, rhs)
    left = inv_t @ rhs
    g = complex(right[m]) if np.iscomplexobj(right) else float(right[m])
    return Bordered(g, right[:m], left[:m], inv_t)  # type: ignore[arg-type]
