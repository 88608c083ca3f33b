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
from grazing.engine.driver.state import STATUS_OK, STATUS_OUTSIDE_MODE
from grazing.engine.driver.transitions import (
    ENTER_SLIDING,
    LEAVE_SLIDING,
    SWITCH,
    apply_saltation,
    mode_after,
    onto_zero_step,
    outside_region,
    roots_after_reset,
    saltation_vector,
)
from grazing.engine.stepping import append_pair, append_record, append_row, pack_var, unpack_var


@njit(cache=True)
def saltation(m, xm, xp, s, pv, j, V, ncol, vf_from, vf_to):
    """Apply the saltation matrix of stop ``j`` (paper eq. 14, with time and parameter terms) to V.

    ``f-`` is mode ``vf_from``'s field at ``xm``, ``f+`` mode ``vf_to``'s at ``xp``.

    Returns False, leaving V alone, for an impact at zero normal speed (``L_f h = 0``): there the
    saltation matrix is unbounded and the flow's Jacobian does not exist.
    """
    n = m.nx
    nsens = m.nsens
    fm = np.empty(n)
    fp = np.empty(n)
    rhs(m, xm, s, pv, fm, vf_from)
    rhs(m, xp, s, pv, fp, vf_to)
    Gx = np.zeros((n, n))
    Gt = np.zeros(n)
    Gp = np.zeros((n, max(nsens, 1)))
    reset_jac(m, xm, s, pv, Gx, Gt, Gp, j)
    hx = np.zeros(n)
    hp = np.zeros(max(nsens, 1))
    ht = guard_grad(m, xm, s, pv, hx, j)
    guard_pgrad(m, xm, s, pv, hp, j)
    w = np.empty(n)
    if not saltation_vector(fm, fp, Gx, Gt, hx, ht, n, w):
        return False
    apply_saltation(V, Gx, Gp, hx, hp, w, n, ncol, np.zeros(ncol), np.empty((n, ncol)))
    return True


@njit(cache=True)
def onto_guard(m, x, s, pv, j):
    """Project x onto the zero set of stop ``j``'s guard (Newton along its gradient, three steps at most)."""
    gx = np.zeros(m.nx)
    for _ in range(3):
        hval = guard(m, x, s, pv, j)
        guard_grad(m, x, s, pv, gx, j)
        if not onto_zero_step(x, m.nx, hval, gx):
            break


@njit(cache=True)
def enter_contact(m, x, s, pv, j):
    """Project x onto the contact manifold {h = 0, L_f h = 0} of stop ``j``."""
    n = m.nx
    onto_guard(m, x, s, pv, j)
    e = np.zeros(n)
    contact_dir(m, x, s, pv, e, j)
    gr = np.zeros(n)
    for _ in range(3):
        vn = normal_rate(m, x, s, pv, j)
        normal_rate_grad(m, x, s, pv, gr, j)
        if not along_contact_dir(x, e, gr, vn, n):
            break


@njit(cache=True, inline="always")
def along_contact_dir(x, e, gr, vn, n):
    """One Newton step of :func:`enter_contact` (record-free: the GPU's too): ``x`` moved along the contact
    direction ``e`` to cancel the normal rate ``vn`` whose gradient is ``gr``; False, ``x`` unchanged, where
    ``vn`` is 0 or ``e`` does not change it."""
    d = 0.0
    for i in range(n):
        d += gr[i] * e[i]
    if d == 0.0 or vn == 0.0:
        return False
    for i in range(n):
        x[i] -= vn / d * e[i]
    return True


@njit(cache=True)
def apply_impact(m, r, x, xp, pv, j, nrows, V, record, tables):
    """Reset the state of run ``r`` on stop ``j`` (``x`` holds it) and its variational matrix.

    Returns ``(speed, jac_ok)``: the approach speed ``-L_f h``, and False when
    the variational matrix could not be carried across (an impact at zero
    normal speed).  The impact is recorded as ``[t, speed, state before, j]``
    in ``tables[0]`` when ``record``; both states go into the trajectory
    ``tables[2]`` when it is recorded (``r.recording``, ``r.traj_dt > 0``).
    Afterwards the first ``nrows`` of ``x`` hold the state after the reset.
    """
    n = m.nx
    ncol = n + m.nsens
    s = r.s
    t = r.k * r.T + s
    vn = normal_rate(m, x, s, pv, j)
    reset(m, x, s, pv, xp, j)
    if r.use_var:
        unpack_var(x, n, ncol, V)
        jac_ok = saltation(m, x, xp, s, pv, j, V, ncol, r.vf, m.targets[j])
        pack_var(V, n, ncol, xp)
    else:
        jac_ok = True
    if record:
        imp = tables[0]
        append_record(imp, r.n_imp_rec, t, -vn, x, n)
        imp[0][r.n_imp_rec, 2 + n] = j
        r.n_imp_rec += 1
    if r.recording and r.traj_dt > 0.0:
        traj = tables[2]
        append_row(traj, r.n_traj, t, x, n)
        append_row(traj, r.n_traj + 1, t, xp, n)
        r.n_traj += 2
    for i in range(nrows):
        x[i] = xp[i]
    return -vn, jac_ok


@njit(cache=True, inline="always")
def at_event(m, r, x, xp, pv, j, nrows, V, chatter_time, record, tables, virtual):
    """The event that ends the step of run ``r``, on stop ``j``; returns True for an impact.

    Sticking to stop ``j``, its contact force changes sign: the release;
    sticking to another, the contact ends first.  Then a switch of mode
    (sliding's entry and exit among them), or an impact (:func:`apply_impact`),
    and on a stop with a sticking mode a chattering sequence shorter than
    ``chatter_time`` is summed to its accumulation point and continued as
    sticking.  After a reset within a mode the root of the stop's guard at
    the next step's start (``r.defl``) is known only where the reset leaves
    the state on the guard (:func:`.transitions.roots_after_reset`), and a
    state after it outside the mode's region (beyond a stop) ends the run
    (:func:`check_region`, status ``OUTSIDE_MODE``), the guard of stop
    ``virtual`` aside (the discontinuity map's, which the flow crosses; -1: none).  The sticking
    intervals of the recorded span go into
    ``tables[1]`` (``r.n_stick``).
    """
    t = r.k * r.T + r.s
    if j >= m.nstops:  # sliding ends at a tangency: to that side (f_s = f there, S = I)
        leave_sliding(m, r, x, pv, j, record, tables)
        return False
    if r.mode == 1 and j == r.stuck:  # release from sticking: the contact force changes sign
        r.mode = 0
        r.defl = 3
        r.defl_stop = r.stuck
        if r.recording:
            close_sticking(tables[1], r.n_stick, t)
        return False
    if r.mode == 1:  # sticking to one stop, another transition fires (an impact, a switch): the contact ends
        r.mode = 0
        if r.recording:
            close_sticking(tables[1], r.n_stick, t)
        if not m.resets[j]:  # (a switch: from the contact, off which the step drifted by rounding)
            enter_contact(m, x, r.s, pv, r.stuck)
    entry = m.slide_entry[j]
    if entry >= 0 and r.surface == 0 and normal_rate(m, x, r.s, pv, m.back[j]) < 0.0:
        enter_sliding(m, r, x, pv, j, V, record, tables)  # (the far side's field pushes back)
        return False
    if not m.resets[j]:  # a switch of vector field: the state goes on, the field changes
        switch_mode(m, r, x, pv, j, V, record, tables)
        return False
    # Impact: x holds the state on stop j, just before its reset.
    speed, jac_ok = apply_impact(m, r, x, xp, pv, j, nrows, V, record, tables)
    r.jac_valid = r.jac_valid and jac_ok  # (an impact at zero normal speed has no Jacobian)
    if m.targets[j] != r.vf:  # a reset that also changes the mode (the rocking block's corners)
        change_mode(m, r, x, pv, j, record, tables)  # (its way back's guard is 0 after it: codegen checks)
    else:  # a reset within a mode: it too lands inside the mode's region, or the run ends ...
        check_region(m, r, x, pv, virtual)  # (... the discontinuity map's stop aside: the flow crosses it)
        r.defl = roots_after_reset(guard(m, x, r.s, pv, j), x, m.nx)  # (... and on its guard, or off it)
        r.defl_stop = j
    if r.status != STATUS_OK:
        return True
    if m.sticks[j]:
        dt_acc = chatter_remaining(m, x, r.s, pv, j, speed, chatter_time)
        if dt_acc >= 0.0:  # complete chattering: on to the accumulation point, then sticking
            r.s += dt_acc
            if r.wrap and r.s >= r.T:  # (the Jacobian is not valid after sticking)
                r.s -= r.T
                r.k += 1
            enter_contact(m, x, r.s, pv, j)
            r.mode = 1
            r.stuck = j
            r.defl = 0
            r.jac_valid = False
            if r.recording:
                append_pair(tables[1], r.n_stick, r.k * r.T + r.s, math.nan)
                r.n_stick += 1
    return True


@njit(cache=True)
def switch_mode(m, r, x, pv, j, V, record, tables):
    """Run ``r`` (its state ``x``, on transition ``j``'s guard) switches to ``j``'s target mode, no reset.

    The variational matrix is multiplied by the saltation matrix of a switch
    (:func:`switch_saltation`); the switch is recorded as ``[t, j, state]`` in
    ``tables[3]`` when ``record``, and in the trajectory.  The root at ``u = 0``
    of the transition back (``m.back[j]``, whose guard is 0 here) is known.  A
    state outside the target mode's region ends the run (:func:`check_region`).
    """
    switch_saltation(m, r, x, pv, j, m.targets[j], V)
    record_switch(m, r, x, j, record, tables)
    set_mode(m, r, j, SWITCH)
    check_region(m, r, x, pv, m.back[j])


@njit(cache=True)
def switch_saltation(m, r, x, pv, j, target, V):
    """The variational matrix of run ``r`` (in ``x``, on transition ``j``'s guard) times the saltation
    matrix of a switch from mode ``r.vf`` to mode ``target``.

    ``S = I + (f+ - f-) (h_x V + h_p) / (h_x f- + h_t)``: :func:`saltation`
    with the identity reset.  A switch at zero normal speed leaves the
    Jacobian invalid (``r.jac_valid``).
    """
    if r.use_var:
        n = m.nx
        ncol = n + m.nsens
        unpack_var(x, n, ncol, V)
        ok = saltation(m, x, x, r.s, pv, j, V, ncol, r.vf, target)
        pack_var(V, n, ncol, x)
        r.jac_valid = r.jac_valid and ok


@njit(cache=True)
def record_switch(m, r, x, code, record, tables):
    """A change of mode of run ``r`` at state ``x``: ``[t, code, state]`` in ``tables[3]`` when
    ``record``, and the state in the trajectory when it is recorded."""
    t = r.k * r.T + r.s
    if record:
        append_record(tables[3], r.n_switch, t, code, x, m.nx)
        r.n_switch += 1
    if r.recording and r.traj_dt > 0.0:
        append_row(tables[2], r.n_traj, t, x, m.nx)
        r.n_traj += 1


@njit(cache=True)
def set_mode(m, r, j, how):
    """Run ``r``'s mode, surface and known roots after transition ``j`` (:func:`.transitions.mode_after`)."""
    r.vf, r.surface, r.defl, r.defl_stop = mode_after(j, how, m.targets, m.back, m.slide_entry)


@njit(cache=True)
def check_region(m, r, x, pv, known):
    """Run ``r``, which has just entered mode ``r.vf`` at state ``x``, ends (status ``OUTSIDE_MODE``) if
    ``x`` is outside that mode's region.

    Outside: a guard of the mode's own transitions, other than ``known`` (the way back after a switch,
    whose guard is 0 there; -1: none), below ``-ON_STOP_TOL * max(1, |x|)``
    (:func:`.transitions.outside_region`).  The run would take an event at once on that guard, off its
    surface: the modes' regions do not fit together there.  The run keeps its state and mode, and its
    status says why it ended.
    """
    rows = m.rows[r.vf]
    row_guards = np.zeros(rows.shape[0])
    for row in range(rows.shape[0]):
        if 0 <= rows[row] < m.nstops:  # (-1: padding; from m.nstops on: a sliding pseudo-mode's exits)
            row_guards[row] = guard(m, x, r.s, pv, rows[row])
    if outside_region(x, m.nx, row_guards, rows, m.nstops, known):
        r.status = STATUS_OUTSIDE_MODE


@njit(cache=True)
def sliding_guard(m, vf):
    """The transition whose guard is 0 on the surface of sliding pseudo-mode ``vf``, or -1 (a real mode).

    A pseudo-mode's first event row is its exit to the positive side, a virtual
    transition (``>= m.nstops``) whose way back is the surface's transition
    from that side.
    """
    first = m.rows[vf, 0]
    return m.back[first] if first >= m.nstops else -1


@njit(cache=True)
def enter_sliding(m, r, x, pv, j, V, record, tables):
    """Run ``r``, crossing the surface of transition ``j`` where the far side's field pushes back, slides.

    The crossing is replaced by the virtual transition ``m.slide_entry[j]``
    into the sliding pseudo-mode (Filippov's field ``f_s``): the variational
    matrix is multiplied by the saltation matrix of a switch with ``f+ = f_s``
    (after which ``h_x V + h_p = 0``: the variations stay on the surface), the
    state put onto the surface, and the entry recorded as ``[t, entry, state]``
    in ``tables[3]`` when ``record``.  No root at ``u = 0`` is known: the exit
    rows are nonzero in strict sliding.
    """
    entry = m.slide_entry[j]
    switch_saltation(m, r, x, pv, j, m.targets[entry], V)
    onto_guard(m, x, r.s, pv, j)
    record_switch(m, r, x, entry, record, tables)
    set_mode(m, r, j, ENTER_SLIDING)


@njit(cache=True)
def leave_sliding(m, r, x, pv, j, record, tables):
    """Run ``r`` leaves its sliding pseudo-mode by the virtual exit ``j`` (an exit row reached 0).

    There ``f_s`` equals the field of the side it leaves to, so the saltation
    matrix is the identity.  The guard of the surface's transition from that
    side (``m.back[j]``) starts with a double root at ``u = 0`` (``h = 0`` and
    ``L_f h = 0``).  Recorded as ``[t, j, state]`` in ``tables[3]`` when ``record``.  A state outside
    the region of the mode it leaves to ends the run (:func:`check_region`).
    """
    record_switch(m, r, x, j, record, tables)
    set_mode(m, r, j, LEAVE_SLIDING)
    check_region(m, r, x, pv, m.back[j])


@njit(cache=True)
def change_mode(m, r, x, pv, j, record, tables):
    """Run ``r``, just reset by transition ``j`` (``x`` holds the state after it), enters ``j``'s target mode.

    The impact is recorded by :func:`apply_impact` (with the saltation matrix
    between the two modes' fields); here the switch is recorded as well, as
    ``[t, j, state after the reset]`` in ``tables[3]`` when ``record``.  The
    root at ``u = 0`` is that of the transition back (``m.back[j]``, whose
    guard is 0 right after the reset; -1: none known).  A state after the reset outside the target
    mode's region ends the run (:func:`check_region`).
    """
    if record:
        append_record(tables[3], r.n_switch, r.k * r.T + r.s, j, x, m.nx)
        r.n_switch += 1
    set_mode(m, r, j, SWITCH)
    check_region(m, r, x, pv, -1)


@njit(cache=True)
def chatter_remaining(m, x, s, pv, j, speed, chatter_time):
    """The time to the accumulation point of a chattering sequence on stop ``j`` starting now, or -1
    (:func:`chatter_time_left` of the state ``x`` just after the reset)."""
    w = normal_rate(m, x, s, pv, j)
    acc = normal_accel(m, x, s, pv, j)
    return chatter_time_left(w, acc, speed, chatter_time)


@njit(cache=True, inline="always")
def chatter_time_left(w, acc, speed, chatter_time):
    """The time to the accumulation point of a chattering sequence, or -1 (record-free: the GPU's too).

    After the reset the body leaves the stop with speed ``w`` (``L_f h``)
    while the stop pushes it back (``acc = L_f^2 h < 0``): the next bounces
    form a geometric sequence of ratio ``w / speed`` (``speed``: the approach
    speed of the impact), over in ``2 w / (|acc| (1 - w / speed))``.  Returns
    that time when it is below ``chatter_time`` (or 0 when the body does not
    leave the stop at all), else -1: no sticking.

    Examples
    --------
    >>> chatter_time_left(0.5, -1.0, 1.0, 10.0)  # (2 * 0.5 / (1 * (1 - 0.5)))
    2.0
    >>> chatter_time_left(0.5, -1.0, 1.0, 1.0), chatter_time_left(0.5, 1.0, 1.0, 10.0)
    (-1.0, -1.0)
    """
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
