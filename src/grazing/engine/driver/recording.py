"""Driver piece: what a step records.

Stroboscopic samples and trajectory points are evaluated from the step's
Taylor polynomials (dense output) at their exact times; the recorded span
starts when the first kept sample's predecessor is taken.  The guard's minimum
over the span, and its closest approach away from contacts (a local minimum
in free flight), are tracked for grazing analysis.
"""

import math

import numpy as np
from numba import njit

from grazing.engine.driver.calls import guard
from grazing.engine.driver.impacts import enter_contact, onto_guard
from grazing.engine.polyroots import horner
from grazing.engine.stepping import append_pair, append_row, eval_rows, poly_derivative, set_row, set_slice

TRAJECTORY_END_TOL = 1e-9
"""A trajectory point at most this many spacings past the run's end is its end (rounding)."""


@njit(cache=True, inline="always")
def take_samples(m, r, X, pv, h_acc, event, is_last, samples, sticks, traj, xe):
    """The samples within ``(0, h_acc]`` of the step of run ``r`` (a :data:`.state.RUN_STATE` record).

    A sample taken while sticking is put on the stop's contact manifold
    (:func:`.impacts.enter_contact`, as the step's end is): the step's
    polynomial leaves it by its local error.

    Updates the sampling state of ``r``: samples taken (into ``samples``, the
    kept ones), the next sample's time, whether the recorded span has started
    (and where: ``r.span_dt`` into the step, at time ``r.lyap_t0``), and the
    sticking-interval and trajectory counters (the span may start while
    sticking, and starts the trajectory).
    """
    n = m.nx
    order = m.order
    T = r.T
    keep_from = r.n_samples - r.n_keep
    while r.isamp < r.n_samples:
        dt = (r.ks - r.k) * T + (r.ss - r.s)
        if dt > h_acc or (event and dt == h_acc and not is_last):
            break
        if is_last and r.isamp == r.n_samples - 1:
            dt = h_acc
        if r.isamp >= keep_from:
            eval_rows(X, n, order, dt, xe)
            if r.mode == 1 or r.surface > 0:
                s = r.s + dt
                if r.wrap and s >= T:
                    s -= T
                if r.mode == 1:
                    enter_contact(m, xe, s, pv, r.stuck)
                else:  # sliding: on the surface, as the step's end is put
                    onto_guard(m, xe, s, pv, r.surface - 1)
            set_row(samples, r.isamp - keep_from, 0, xe, n)
        r.isamp += 1
        if r.wrap:
            r.ks += 1
        else:
            r.ss += T
        if r.isamp == keep_from and not r.recording and r.n_keep > 0:
            r.recording = True
            r.vf_span = r.vf
            r.span_dt = dt  # (where the Lyapunov sums start: tangent.lyapunov_step)
            r.lyap_t0 = r.k * T + r.s + dt
            if r.mode == 1:  # recording starts while sticking: the interval starts here
                append_pair(sticks, r.n_stick, r.k * T + r.s + dt, math.nan)
                r.n_stick += 1
            if r.traj_dt > 0.0:
                eval_rows(X, n, order, dt, xe)
                append_row(traj, r.n_traj, r.k * T + r.s + dt, xe, n)
                r.n_traj += 1
                r.kt = r.k
                r.st = r.s + dt + r.traj_dt
                while r.wrap and r.st >= T:
                    r.st -= T
                    r.kt += 1


@njit(cache=True, inline="always")
def sample_modes(r, first, modes):
    """The mode of run ``r`` for the kept samples its last :func:`take_samples` took: ``modes[i]`` for the
    samples ``first <= i < r.isamp`` (counted from the first kept one).

    A step ends at an event, so the mode is the step's (a sample at the event's time is the next step's).
    """
    keep_from = r.n_samples - r.n_keep
    for i in range(max(first, keep_from), r.isamp):
        modes[i - keep_from] = r.vf


@njit(cache=True, inline="always")
def trajectory_points(m, r, X, h_acc, traj, xe, run_end):
    """Trajectory points of run ``r`` within the step, every ``r.traj_dt``, from ``(r.kt, r.st)`` on.

    At the run's end (``run_end``: the step ends there, not at an event) a
    point that the sums of ``traj_dt`` put past it by rounding is the end's
    (the last row of a trajectory was missing where they came out a hair long).
    """
    n = m.nx
    T = r.T
    while True:
        dt = (r.kt - r.k) * T + (r.st - r.s)
        if dt > h_acc:
            if not (run_end and dt - h_acc <= TRAJECTORY_END_TOL * r.traj_dt):
                break
            dt = h_acc
        eval_rows(X, n, m.order, dt, xe)
        append_row(traj, r.n_traj, r.k * T + r.s + dt, xe, n)
        r.n_traj += 1
        r.st += r.traj_dt
        while r.wrap and r.st >= T:
            r.st -= T
            r.kt += 1


@njit(cache=True, inline="always")
def track_guard(m, r, o_row, stop, X, x, h, h_acc, event, gm, info, xe):
    """Minimum of the event row ``o_row`` (the Taylor coefficients of stop ``stop``'s guard, a row of the
    kernel's ``O``) over the step of run ``r`` up to ``h_acc``, and the closest approach.

    ``info`` is the stop's row of the guard's record (:func:`new_guard_info`):
    ``info[:2 + n]`` holds the smallest value, its time and the state there;
    ``info[2 + n:4 + 2n]`` the same for the smallest local minimum in free
    flight (where ``L_f h`` turns from negative to positive, inside the step
    or at its start); the last two, the guard's slope at the end of the
    previous step (nan when an event followed) and at the start of the
    first recorded one.  ``x`` is the state at the step's start.
    """
    n = m.nx
    order = m.order
    t = r.k * r.T + r.s
    defl = r.defl if r.defl_stop == stop else 0
    slope_end = info[4 + 2 * n]
    slope_first = info[5 + 2 * n]
    hk = 1.0
    for j in range(order + 1):
        gm[j] = o_row[j] * hk
        hk *= h
    if gm[0] < info[0]:
        info[0] = gm[0]
        info[1] = t
        set_slice(info, 2, x, n)
    if defl == 0:  # not leaving a contact
        if math.isnan(slope_first):
            slope_first = gm[1] / h
        elif slope_end < 0.0 <= gm[1] and gm[0] < info[2 + n]:
            info[2 + n] = gm[0]  # a local minimum exactly at the step boundary
            info[3 + n] = t
            set_slice(info, 4 + n, x, n)
    uend = h_acc / h
    slope_end = poly_derivative(gm, order, uend) / h
    if gm[1] < 0.0 and slope_end > 0.0:
        lo = 0.0
        hi = uend
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if poly_derivative(gm, order, mid) < 0.0:
                lo = mid
            else:
                hi = mid
        um = 0.5 * (lo + hi)
        gv = horner(gm, order, um)
        if gv < info[0] or gv < info[2 + n]:
            eval_rows(X, n, order, um * h, xe)
        for base in (0, 2 + n):
            if gv < info[base]:
                info[base] = gv
                info[base + 1] = t + um * h
                set_slice(info, base + 2, xe, n)
    if event:
        slope_end = math.nan  # an impact or a release follows: no free-flight minimum here
    info[4 + 2 * n] = slope_end
    info[5 + 2 * n] = slope_first


@njit(cache=True, inline="always")
def guard_at_end(m, r, X, h, h_acc, gm, info, xe):
    """The guard's value at the end ``h_acc`` of a step that ends at an event (``gm``, its polynomial in the
    step's fraction, from :func:`track_guard`): in a model with modes a switch may leave the guard's mode
    there, and the next step, in another mode, does not see it."""
    uend = h_acc / h
    ge = horner(gm, m.order, uend)
    if ge < info[0]:
        eval_rows(X, m.nx, m.order, h_acc, xe)
        info[0] = ge
        info[1] = r.k * r.T + r.s + h_acc
        set_slice(info, 2, xe, m.nx)


@njit(cache=True)
def new_guard_info(nstops, n):
    """Each stop's guard record (:func:`track_guard`): no minimum yet (inf), no slopes (nan)."""
    info = np.full((nstops, 2 * (2 + n) + 2), math.inf)
    info[:, 2 * (2 + n) :] = math.nan
    return info


@njit(cache=True)
def finish_guard(m, r, x, pv, j, info):
    """At the end of run ``r``: the final state, and a minimum where the orbit closes (``info`` of stop j)."""
    n = m.nx
    t = r.k * r.T + r.s
    g_end = guard(m, x, r.s, pv, j)
    if g_end < info[0]:
        info[0] = g_end
        info[1] = t
        set_slice(info, 2, x, n)
    # A run over whole periods of an orbit ends where it started: a minimum there.
    if info[4 + 2 * n] < 0.0 <= info[5 + 2 * n] and g_end < info[2 + n]:
        info[2 + n] = g_end
        info[3 + n] = t
        set_slice(info, 4 + n, x, n)
