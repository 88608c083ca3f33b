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
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

_LN2_HI = 6.93147180369123816490e-01
"""ln 2's leading bits (fdlibm's split: ``k * _LN2_HI`` is exact for ``|k| < 2**11``)..."""
_LN2_LO = 1.90821492927058770002e-10
"""... and the rest."""
_LOG2E = 1.4426950408889634
_SQRT2 = 1.4142135623730951
_RATIO_MIN, _RATIO_MAX = 1e-300, 1e300

GUARD_SCALE = 16.0
"""In free flight a guard's value counts in the step's scale (:func:`step_size`) up to this many times
the state's, ``max(1, |x|)``: it is offset by its stop's distance, which says nothing about the scale
of the solution (a stop at 1e12, counted in full, made the steps of an orbit of size 1 a thousand
times too long).  Every guard of the built-in models stays within it: their results are unchanged."""
"""The ratios whose logarithms :func:`step_from_norms` takes are clamped to this range (``fast_log``'s)."""


@intrinsic
def _bits_of(typingctx, x):
    """The bits of the double ``x``, as an int64."""
    sig = types.int64(types.float64)
    return sig, lambda context, builder, signature, args: builder.bitcast(args[0], ir.IntType(64))


@intrinsic
def _double_of(typingctx, bits):
    """The double whose bits are the int64 ``bits``."""
    sig = types.float64(types.int64)
    return sig, lambda context, builder, signature, args: builder.bitcast(args[0], ir.DoubleType())


@njit(cache=True, inline="always")
def fast_log(x):
    """``log(x)`` for ``1e-300 <= x <= 1e300`` to a relative 1e-10, in a few multiplications.

    No call into the C library, and no branch: a loop over lanes vectorises
    (the C library's ``log`` and ``exp`` cost the sweep a tenth of its time,
    three calls per lane and step in :func:`step_from_norms`), and the same
    doubles on every processor.  The exponent from the bits; ``log m`` of the
    mantissa ``m`` in ``[1/sqrt 2, sqrt 2]`` as ``2 atanh((m - 1)/(m + 1))``,
    its series to the 11th power.
    """
    b = _bits_of(x)
    m = _double_of((b & 0xFFFFFFFFFFFFF) | 0x3FF0000000000000)
    up = m > _SQRT2
    e = float(((b >> 52) & 0x7FF) - 1023) + (1.0 if up else 0.0)
    m = m * 0.5 if up else m
    t = (m - 1.0) / (m + 1.0)
    t2 = t * t
    t4 = t2 * t2
    s = t2 * ((1.0 / 3.0 + t2 * (1.0 / 5.0)) + t4 * ((1.0 / 7.0 + t2 * (1.0 / 9.0)) + t4 * (1.0 / 11.0)))
    return e * _LN2_HI + (2.0 * t + (2.0 * t * s + e * _LN2_LO))


@njit(cache=True, inline="always")
def fast_exp(y):
    """``exp(y)`` for ``|y| <= 700`` to a relative 1e-14 (see :func:`fast_log`: no call, no branch).

    ``y = k ln 2 + r`` with ``|r| <= ln(2)/2``; ``e^r`` by its series to the 11th power (Estrin's
    scheme), times ``2^k`` made from its bits.
    """
    k = math.floor(y * _LOG2E + 0.5)
    r = (y - k * _LN2_HI) - k * _LN2_LO
    # the series to r^11 in Estrin's scheme (pairs, then powers of r^2: a short chain of dependent operations)
    r2 = r * r
    r4 = r2 * r2
    p01 = 1.0 + r
    p23 = 1.0 / 2.0 + r * (1.0 / 6.0)
    p45 = 1.0 / 24.0 + r * (1.0 / 120.0)
    p67 = 1.0 / 720.0 + r * (1.0 / 5040.0)
    p89 = 1.0 / 40320.0 + r * (1.0 / 362880.0)
    pab = 1.0 / 3628800.0 + r * (1.0 / 39916800.0)
    p = (p01 + r2 * p23) + r4 * ((p45 + r2 * p67) + r4 * (p89 + r2 * pab))
    return p * _double_of((int(k) + 1023) << 52)


@njit(cache=True)
def step_factor(safety, order):
    """The factor ``exp(-safety - 0.7 / (order - 1))`` of :func:`step_size`."""
    return math.exp(-safety - 0.7 / (order - 1))


@njit(cache=True, inline="always")
def step_size(X, n, O, nout, orow, cap, order, max_step, factor):
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
    the contact force while sticking), that row up to ``cap`` times the
    state's scale ``max(1, |x|)`` (:data:`GUARD_SCALE` for a guard, ``inf``
    for the contact force): a guard is offset by its stop's distance, which
    says nothing about the scale of the solution.  Inlined into the driver
    (no reference counting of its arrays on the hot path).
    """
    nx = 0.0
    n1 = 0.0
    n2 = 0.0
    for r in range(nout):
        n1 = max(n1, abs(O[r, order - 1]))
        n2 = max(n2, abs(O[r, order]))
    for i in range(n):
        nx = max(nx, abs(X[i, 0]))
        n1 = max(n1, abs(X[i, order - 1]))
        n2 = max(n2, abs(X[i, order]))
    nx = max(nx, min(abs(O[orow, 0]), cap * max(1.0, nx)))
    return step_from_norms(nx, n1, n2, order, max_step, factor)


@njit(cache=True, inline="always")
def step_from_norms(nx, n1, n2, order, max_step, factor):
    """The step of :func:`step_size` from its norms: the values' ``nx`` and the last two coefficients'."""
    sc = max(1.0, nx)
    # log rho = min(log(sc/n1)/(order-1), log(sc/n2)/order), without a branch or a C function: a zero or NaN
    # norm says nothing (its ratio is the largest, 1e300, whose step is beyond max_step anyway)
    low = sc * _RATIO_MIN
    r1 = sc / (n1 if n1 > low else low)
    r1 = r1 if r1 > _RATIO_MIN else _RATIO_MIN
    r2 = sc / (n2 if n2 > low else low)
    r2 = r2 if r2 > _RATIO_MIN else _RATIO_MIN
    log_rho = min(fast_log(r1) * (1.0 / (order - 1)), fast_log(r2) * (1.0 / order))  # (no division per lane)
    h = fast_exp(log_rho) * factor
    return h if h < max_step else max_step


@njit(cache=True, error_model="numpy")
def steps_from_norms(nx, n1, n2, order, max_steps, factor, out):
    """:func:`step_from_norms` of every lane, ``out[lane]`` from ``nx[lane]``, ...: on vectors.

    (The "numpy" error model: no test for a zero divisor, which numba would
    otherwise make at every division, so the loop vectorises; none is zero.)
    """
    for lane in range(out.shape[0]):
        out[lane] = step_from_norms(nx[lane], n1[lane], n2[lane], order, max_steps[lane], factor)


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
def copy_rows(table, count, into):
    """The first ``count`` rows of ``table`` into ``into``, as many as it has room for."""
    buf = table[0]
    for i in range(min(count, into.shape[0])):
        for j in range(into.shape[1]):
            into[i, j] = buf[i, j]


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
