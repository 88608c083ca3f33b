"""Driver piece: the tangent dynamics and the discontinuity map.

The variational matrix ``V`` is integrated with the state (its rows follow
the state in ``x``): columns ``0 .. n-1`` are ``d x / d x0``, the next
``m.nsens`` the derivatives along the sensitivity directions in parameter space.
"""

import math

import numpy as np
from numba import njit

from grazing.engine.driver.calls import guard, guard_grad, normal_rate, normal_rate_grad, rhs
from grazing.engine.driver.events import tracked_in
from grazing.engine.stepping import append_record, eval_rows, orthonormalize, pack_var, unpack_var


@njit(cache=True)
def shift_period(m, x, s, pv, Tp, ncol, f, vf):
    """Parameter columns of V at a period boundary: ``V_p += f(x, s) dT/dp``.

    Time is kept as ``k T + s``; the variational equations give derivatives at
    fixed ``(k, s)``.  Relabelling ``(k, s)`` as ``(k + 1, s - T)`` keeps the
    time only at the current parameter values: where ``T`` depends on a
    parameter the two labels are different instants, ``dT/dp`` apart per
    period, and the state moves by ``f dT/dp`` between them.
    """
    rhs(m, x, s, pv, f, vf)
    n = m.nx
    for i in range(n):
        for c in range(m.nsens):
            x[n + i * ncol + n + c] += f[i] * Tp[c]


@njit(cache=True, inline="always")
def lyapunov_step(m, r, x, X, V, ncol, t, scratch, logs, xe):
    """Gram-Schmidt on the tangent vectors of run ``r`` after a step that ends at time ``t``.

    Before the recorded span the vectors are only aligned (their growth is
    discarded); from its start, ``r.lyap_t0``, the log norms are summed into
    ``logs``.  A span that starts inside the step, ``r.span_dt`` after its
    start (at a sample, :func:`.recording.take_samples`), counts the growth
    from there: the log norms of the aligned vectors at the end of the step
    less those of the vectors at the span's start, evaluated there from the
    step's polynomials ``X`` (into ``xe``).  The sums are then the same
    (to rounding) whether or not a step, or a call of the driver, ends at
    that sample.
    """
    n = m.nx
    if r.recording and not r.lyap_started:
        r.lyap_started = True
        if math.isnan(r.span_dt):  # (the span started in an earlier step, while sticking)
            r.lyap_t0 = t
            unpack_var(x, n, ncol, V)
            orthonormalize(V, n, scratch)
        else:
            eval_rows(X, n + n * ncol, m.order, r.span_dt, xe)
            unpack_var(xe, n, ncol, V)
            before = np.zeros(n)
            orthonormalize(V, n, before)  # the vectors' growth before the span ...
            unpack_var(x, n, ncol, V)
            orthonormalize(V, n, logs)
            for c in range(n):
                logs[c] -= before[c]  # ... is not the span's (the diagonal of R1^-1 R: log R - log R1)
                if before[c] == -math.inf:  # a direction already collapsed (sliding): it stays collapsed
                    logs[c] = -math.inf
    elif r.lyap_started:
        unpack_var(x, n, ncol, V)
        orthonormalize(V, n, logs)
    else:
        unpack_var(x, n, ncol, V)
        orthonormalize(V, n, scratch)  # before the span: align V, discard growth
    pack_var(V, n, ncol, x)


@njit(cache=True)
def discontinuity_map(m, r, x, pv, cfg, V, gh, gv, record, imp):
    """Nordmark's discontinuity map at leading order, at the grazing phase; returns whether it applied.

    ``cfg`` holds the map's settings (``stop`` the stop it stands for,
    ``zdm_a``, ``zdm_e``, ``zdm_window``: the fields of
    :class:`~grazing.engine.records.Config` and
    :class:`~grazing.engine.records.LaneSettings`).  On a model with modes it
    applies only while the run is in the stop's source mode (its guard an
    event row of mode ``r.vf``: :func:`.events.tracked_in`).  With ``v = L_f h`` and
    ``delta = v^2 / (2 a) - h`` (how far the local parabola would reach past
    the stop, ``a = L_f^2 h`` at the grazing point): if ``delta > 0`` and
    ``|v| / a < window``, ``x <- x - e sqrt(2 a delta)``, and the variational
    matrix by ``dD/dx = I - e (grad S)^T``.  The kick is recorded as an impact
    (time, speed ``S``, state) in ``imp`` when ``record`` (``r.n_imp_rec``).
    """
    n = m.nx
    ncol = n + m.nsens
    j = cfg.stop
    if not tracked_in(m, r.vf, j):  # (another mode: the stop is not there, nothing happens)
        return False
    a = cfg.zdm_a
    e = cfg.zdm_e
    s = r.s
    hval = guard(m, x, s, pv, j)
    vn = normal_rate(m, x, s, pv, j)
    sp_ = map_kick(hval, vn, a, cfg.zdm_window)
    if sp_ < 0.0:
        return False
    if r.use_var:
        guard_grad(m, x, s, pv, gh, j)
        normal_rate_grad(m, x, s, pv, gv, j)
        unpack_var(x, n, ncol, V)
        kick_tangent(V, n, ncol, vn, a, sp_, e, gh, gv)
        pack_var(V, n, ncol, x)
    if record:
        append_record(imp, r.n_imp_rec, r.k * r.T + s, sp_, x, n)
        imp[0][r.n_imp_rec, 2 + n] = j
        r.n_imp_rec += 1
    for i in range(n):
        x[i] -= e[i] * sp_
    return True


@njit(cache=True, inline="always")
def map_kick(hval, vn, a, window):
    """The kick ``S = sqrt(2 a delta)`` of the discontinuity map at a state where the guard is ``hval`` and
    its rate ``vn`` (:func:`discontinuity_map`), or -1 where the map does not apply (``delta <= 0``, or
    ``|vn| / a >= window``)."""
    dz = vn * vn / (2.0 * a) - hval
    if not (dz > 0.0 and abs(vn) < window * a):
        return -1.0
    return math.sqrt(2.0 * a * dz)


@njit(cache=True, inline="always")
def kick_tangent(V, n, ncol, vn, a, sp_, e, gh, gv):
    """The tangent vectors ``V`` (``n x ncol``) through the map's kick ``sp_`` (:func:`map_kick`):
    ``V <- (I - e (grad S)^T) V``, ``grad S = a grad(delta) / S = (vn grad(vn) - a grad(h)) / S`` from the
    guard's gradient ``gh`` and its rate's ``gv``."""
    for c in range(ncol):
        gs = 0.0
        for q in range(n):
            gs += (vn * gv[q] - a * gh[q]) * V[q, c]
        gs /= sp_
        for i in range(n):
            V[i, c] -= e[i] * gs
