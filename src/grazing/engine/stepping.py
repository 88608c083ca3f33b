"""Model-independent pieces of the integration driver, compiled once per machine.

The driver (:mod:`grazing.engine.driver`) is compiled into every generated model
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
def step_factor(safety, order):
    """The factor ``exp(-safety - 0.7 / (order - 1))`` of :func:`step_size`."""
    return math.exp(-safety - 0.7 / (order - 1))


@njit(cache=True, inline="always")
def step_size(X, n, O, nout, orow, order, max_step, factor):
    """Jorba-Zou step size from the last two Taylor coefficients.

    ``h = rho * factor`` where ``rho`` estimates the radius of convergence and
    ``factor = exp(-safety - 0.7 / (order - 1))`` (:func:`step_factor`);
    Jorba & Zou (and heyoka) use ``safety = 2``.  The norms run over the first
    ``n`` rows of ``X`` (the state, and the variational equations when they are
    integrated) and the ``nout`` event rows of ``O`` (every stop's guard, or
    while sticking the contact force), so that the event polynomials and the
    Jacobian are as accurate as the state even where the state itself is
    constant (sticking, an equilibrium).  The scale of the values counts the
    state and one event row, ``orow`` (the first stop's guard in free flight,
    the contact force while sticking): another stop's guard is offset by its
    distance, which says nothing about the scale of the solution.  Inlined
    into the driver (no reference counting of its arrays on the hot path).
    """
    nx = abs(O[orow, 0])
    n1 = 0.0
    n2 = 0.0
    for r in range(nout):
        n1 = max(n1, abs(O[r, order - 1]))
        n2 = max(n2, abs(O[r, order]))
    for i in range(n):
        nx = max(nx, abs(X[i, 0]))
        n1 = max(n1, abs(X[i, order - 1]))
        n2 = max(n2, abs(X[i, order]))
    return step_from_norms(nx, n1, n2, order, max_step, factor)


@njit(cache=True, inline="always")
def step_from_norms(nx, n1, n2, order, max_step, factor):
    """The step of :func:`step_size` from its norms: the values' ``nx`` and the last two coefficients'."""
    sc = max(1.0, nx)
    # log rho = min(log(sc/n1)/(order-1), log(sc/n2)/order): two logs and one exp
    log_rho = math.inf
    if n1 > 0.0:
        log_rho = min(log_rho, math.log(sc / n1) / (order - 1))
    if n2 > 0.0:
        log_rho = min(log_rho, math.log(sc / n2) / order)
    if log_rho == math.inf:
        return max_step
    return min(math.exp(log_rho) * factor, max_step)


@njit(cache=True, inline="always")
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


# Growable tables of rows.  The table is held in a one-element list so that
# growing it does not rebind a variable of the driver's loop: numba would turn
# such a variable into a loop phi and reference-count it on every step.


@njit(cache=True)
def new_table(rows, width):
    """An empty growable table: ``[array of shape (rows, width)]``."""
    return [np.empty((rows, width))]


@njit(cache=True)
def append_row(table, count, t, x, n):
    """Row ``count`` of ``table`` = ``[t, x[:n]]`` (the table grows as needed)."""
    buf = grow(table[0], count)
    table[0] = buf
    buf[count, 0] = t
    set_row(buf, count, 1, x, n)


@njit(cache=True)
def append_record(table, count, t, value, x, n):
    """Row ``count`` of ``table`` = ``[t, value, x[:n]]`` (the table grows as needed)."""
    buf = grow(table[0], count)
    table[0] = buf
    buf[count, 0] = t
    buf[count, 1] = value
    set_row(buf, count, 2, x, n)


@njit(cache=True)
def append_pair(table, count, a, b):
    """Row ``count`` of ``table`` = ``[a, b]`` (the table grows as needed)."""
    buf = grow(table[0], count)
    table[0] = buf
    buf[count, 0] = a
    buf[count, 1] = b


@njit(cache=True)
def table_rows(table, count):
    """A copy of the first ``count`` rows."""
    return table[0][:count].copy()


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


@njit(cache=True)
def divide_double_root_at_one(a, deg):
    """Divide the polynomial ``a[:deg + 1]`` by ``(u - 1)^2`` in place; return the new degree.

    Used where a run ends in tangential contact with the stop: the guard has a
    double root at the end of the last step, which is known and not an impact.
    The remainder (rounding, or how far a Newton iterate is from the contact)
    is dropped.
    """
    for _ in range(2):
        if deg < 1:
            return deg
        acc = 0.0
        for j in range(deg, 0, -1):
            acc += a[j]
            a[j] = acc  # the coefficient of u^(j-1) of the quotient
        for j in range(deg):
            a[j] = a[j + 1]
        deg -= 1
    return deg
