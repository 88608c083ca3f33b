"""Model-independent pieces of the integration driver, compiled once per machine.

The driver (``_driver_template.py``) is compiled into every generated model
module because it calls the model's own kernels; the helpers here do not, so
they live in one module that numba compiles and caches once, instead of once
per model, sensitivity set and Taylor order.  All functions see only arrays and
scalars, and avoid slice assignments (whose error paths make numba compile
string formatting code).

Examples
--------
>>> import numpy as np
>>> X = np.array([[1.0, 2.0, 3.0]])          # 1 + 2 t + 3 t^2
>>> out = np.empty(1)
>>> eval_rows(X, 1, 2, 0.5, out)
>>> float(out[0])
2.75
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def step_size(X, n, O, order, max_step, safety):
    """Jorba-Zou step size from the last two Taylor coefficients.

    ``h = rho * exp(-safety - 0.7 / (order - 1))`` where ``rho`` estimates the
    radius of convergence; Jorba & Zou (and heyoka) use ``safety = 2``.  The
    norms run over the first ``n`` rows of ``X`` (the state, and the
    variational equations when they are integrated) and the event function
    (``O[0]``), so that the event polynomial and the Jacobian are as accurate
    as the state even where the state itself is constant (sticking, an
    equilibrium).
    """
    nx = abs(O[0, 0])
    n1 = abs(O[0, order - 1])
    n2 = abs(O[0, order])
    for i in range(n):
        nx = max(nx, abs(X[i, 0]))
        n1 = max(n1, abs(X[i, order - 1]))
        n2 = max(n2, abs(X[i, order]))
    sc = max(1.0, nx)
    rho = math.inf
    if n1 > 0.0:
        rho = min(rho, (sc / n1) ** (1.0 / (order - 1)))
    if n2 > 0.0:
        rho = min(rho, (sc / n2) ** (1.0 / order))
    h = rho * math.exp(-safety - 0.7 / (order - 1))
    return min(h, max_step)


@njit(cache=True)
def eval_rows(X, nrows, order, dt, out):
    """``out[i]`` = value at ``dt`` of the polynomial ``X[i, :order + 1]``, for ``i < nrows``."""
    for i in range(nrows):
        acc = X[i, order]
        for j in range(order - 1, -1, -1):
            acc = acc * dt + X[i, j]
        out[i] = acc


@njit(cache=True)
def poly_derivative(c, order, u):
    """Derivative at ``u`` of the polynomial ``c[:order + 1]``."""
    acc = 0.0
    for j in range(order, 0, -1):
        acc = acc * u + j * c[j]
    return acc


@njit(cache=True)
def unpack_var(x, n, ncol, V):
    """The variational matrix stored row by row after the state in ``x``, into ``V``."""
    for i in range(n):
        for c in range(ncol):
            V[i, c] = x[n + i * ncol + c]


@njit(cache=True)
def pack_var(V, n, ncol, x):
    """Inverse of :func:`unpack_var`."""
    for i in range(n):
        for c in range(ncol):
            x[n + i * ncol + c] = V[i, c]


@njit(cache=True)
def grow(buf, count):
    """``buf``, or a copy with about twice the rows if row ``count`` does not exist."""
    if count < buf.shape[0]:
        return buf
    new = np.empty((2 * buf.shape[0] + 8, buf.shape[1]))
    for i in range(buf.shape[0]):
        for j in range(buf.shape[1]):
            new[i, j] = buf[i, j]
    return new


@njit(cache=True)
def set_row(buf, row, first, x, n):
    """``buf[row, first:first + n] = x[:n]``."""
    for i in range(n):
        buf[row, first + i] = x[i]


@njit(cache=True)
def set_slice(out, first, x, n):
    """``out[first:first + n] = x[:n]`` for a 1-D ``out``."""
    for i in range(n):
        out[first + i] = x[i]


@njit(cache=True)
def record(buf, count, t, value, x, n):
    """Append the row ``[t, value, x[:n]]`` to ``buf`` (grown as needed); return the buffer."""
    buf = grow(buf, count)
    buf[count, 0] = t
    buf[count, 1] = value
    set_row(buf, count, 2, x, n)
    return buf


@njit(cache=True)
def orthonormalize(V, n, logs):
    """Modified Gram-Schmidt on the first n columns of V; adds log norms to logs."""
    for c in range(n):
        for q in range(c):
            d = 0.0
            for i in range(n):
                d += V[i, c] * V[i, q]
            for i in range(n):
                V[i, c] -= d * V[i, q]
        nrm = 0.0
        for i in range(n):
            nrm += V[i, c] * V[i, c]
        nrm = math.sqrt(nrm)
        logs[c] += math.log(nrm) if nrm > 0.0 else -math.inf
        if nrm > 0.0:
            for i in range(n):
                V[i, c] /= nrm
