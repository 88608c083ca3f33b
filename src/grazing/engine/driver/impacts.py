"""Driver piece: impacts, chattering and sticking.

At an impact the state on the stop is reset, ``x <- g(x)``, and the
variational matrix multiplied by the saltation matrix (paper eq. 14).  If the
impacts that follow would accumulate within ``chatter_time`` (complete
chattering: each bounce a factor ``w / speed`` of the one before), the rest of
the sequence is summed in closed form and the motion continues on the stop
(sticking) until the contact force changes sign (release).
"""

import math

import numpy as np
from numba import njit

from grazing.engine.driver.calls import (
    contact_dir,
    guard,
    guard_grad,
    guard_pgrad,
    normal_accel,
    normal_rate,
    normal_rate_grad,
    reset,
    reset_jac,
    rhs,
)
from grazing.engine.stepping import append_record, append_row, pack_var, unpack_var


@njit(cache=True)
def saltation(m, xm, xp, s, pv, j, V, ncol):
    """Apply the saltation matrix of stop ``j`` (paper eq. 14, with time and parameter terms) to V.

    Returns False, leaving V alone, for an impact at zero normal speed (``L_f h = 0``): there the
    saltation matrix is unbounded and the flow's Jacobian does not exist.
    """
    n = m.nx
    nsens = m.nsens
    fm = np.empty(n)
    fp = np.empty(n)
    rhs(m, xm, s, pv, fm)
    rhs(m, xp, s, pv, fp)
    Gx = np.zeros((n, n))
    Gt = np.zeros(n)
    Gp = np.zeros((n, max(nsens, 1)))
    reset_jac(m, xm, s, pv, Gx, Gt, Gp, j)
    hx = np.zeros(n)
    hp = np.zeros(max(nsens, 1))
    ht = guard_grad(m, xm, s, pv, hx, j)
    guard_pgrad(m, xm, s, pv, hp, j)
    den = ht
    for i in range(n):
        den += hx[i] * fm[i]
    if den == 0.0:
        return False
    w = np.empty(n)
    for i in range(n):
        acc = fp[i] - Gt[i]
        for j in range(n):
            acc -= Gx[i, j] * fm[j]
        w[i] = acc / den
    # row vector hx V (+ hp on the parameter columns)
    hv = np.zeros(ncol)
    for c in range(ncol):
        acc = 0.0
        for j in range(n):
            acc += hx[j] * V[j, c]
        if c >= n:
            acc += hp[c - n]
        hv[c] = acc
    Vn = np.empty((n, ncol))
    for i in range(n):
        for c in range(ncol):
            acc = 0.0
            for j in range(n):
                acc += Gx[i, j] * V[j, c]
            if c >= n:
                acc += Gp[i, c - n]
            Vn[i, c] = acc + w[i] * hv[c]
    for i in range(n):
        for c in range(ncol):
            V[i, c] = Vn[i, c]
    return True


@njit(cache=True)
def enter_contact(m, x, s, pv, j):
    """Project x onto the contact manifold {h = 0, L_f h = 0} of stop ``j``."""
    n = m.nx
    gx = np.zeros(n)
    for _ in range(3):
        hval = guard(m, x, s, pv, j)
        guard_grad(m, x, s, pv, gx, j)
        nn = 0.0
        for i in range(n):
            nn += gx[i] * gx[i]
        if nn == 0.0 or hval == 0.0:
            break
        for i in range(n):
            x[i] -= hval * gx[i] / nn
    e = np.zeros(n)
    contact_dir(m, x, s, pv, e, j)
    gr = np.zeros(n)
    for _ in range(3):
        vn = normal_rate(m, x, s, pv, j)
        normal_rate_grad(m, x, s, pv, gr, j)
        d = 0.0
        for i in range(n):
            d += gr[i] * e[i]
        if d == 0.0 or vn == 0.0:
            break
        for i in range(n):
            x[i] -= vn / d * e[i]


@njit(cache=True)
def apply_impact(m, x, xp, s, t, pv, j, use_var, ncol, nrows, V, record, imp, n_rec, traj_on, traj, n_traj):
    """Reset the state on stop ``j`` (``x`` holds it) and its variational matrix; returns the speed.

    Returns ``(speed, n_rec, n_traj, jac_ok)``: the approach speed ``-L_f h``,
    the impact and trajectory counters, and False when the variational matrix
    could not be carried across (an impact at zero normal speed; the impact is recorded as
    ``[t, speed, state before, j]`` when ``record``; both states go into the
    trajectory when ``traj_on``).  Afterwards ``x`` holds the state after the
    reset.
    """
    n = m.nx
    vn = normal_rate(m, x, s, pv, j)
    reset(m, x, s, pv, xp, j)
    if use_var:
        unpack_var(x, n, ncol, V)
        jac_ok = saltation(m, x, xp, s, pv, j, V, ncol)
        pack_var(V, n, ncol, xp)
    else:
        jac_ok = True
    if record:
        append_record(imp, n_rec, t, -vn, x, n)
        imp[0][n_rec, 2 + n] = j
        n_rec += 1
    if traj_on:
        append_row(traj, n_traj, t, x, n)
        append_row(traj, n_traj + 1, t, xp, n)
        n_traj += 2
    for i in range(nrows):
        x[i] = xp[i]
    return -vn, n_rec, n_traj, jac_ok


@njit(cache=True)
def chatter_remaining(m, x, s, pv, j, speed, chatter_time):
    """The time to the accumulation point of a chattering sequence on stop ``j`` starting now, or -1.

    After the reset the body leaves the stop with speed ``w`` while the stop
    pushes it back (``L_f^2 h < 0``): the next bounces form a geometric
    sequence of ratio ``w / speed``, over in ``2 w / (|a| (1 - w / speed))``.
    Returns that time when it is below ``chatter_time`` (or 0 when the body
    does not leave the stop at all), else -1: no sticking.
    """
    w = normal_rate(m, x, s, pv, j)
    acc = normal_accel(m, x, s, pv, j)
    if not acc < 0.0:
        return -1.0
    if speed <= 0.0 or w <= 0.0:
        return 0.0
    ratio = w / speed
    if ratio < 1.0:
        dt_acc = 2.0 * w / (-acc * (1.0 - ratio))
        if dt_acc < chatter_time:
            return dt_acc
    return -1.0


@njit(cache=True)
def close_sticking(sticks, n_stick, t):
    """End the open sticking interval (if any) at ``t``."""
    if n_stick > 0 and math.isnan(sticks[0][n_stick - 1, 1]):
        sticks[0][n_stick - 1, 1] = t
