"""Driver piece: the integration loop.

``integrate(start, pv, cfg, m)`` takes a :class:`~grazing.engine.records.Start`,
the parameter vector (values, then the sensitivity directions), a
:class:`~grazing.engine.records.Config` and the model's compiled functions
(:class:`~grazing.engine.records.Kernels`), and returns the fields of a
:class:`~grazing.engine.records.Result`.  Each step: the Taylor coefficients
and the step size (:mod:`.events`), the step cut at the last sample or at the
discontinuity map's phase, the first event on it, what the step records
(:mod:`.recording`), the advance to the end of its accepted part (with the
period-boundary term of the sensitivities, :mod:`.tangent`), Lyapunov
orthonormalisation, the discontinuity map, and at an event an impact (reset,
saltation, chattering to sticking) or a release (:mod:`.impacts`).

Time is kept as ``k * T + s`` with ``s`` in ``[0, T)`` for models whose
vector field is T-periodic in time (``cfg.wrap``), so that the forcing phase
does not lose precision over long runs.  Samples are taken at local times
``(ks, ss)``, ``(ks + 1, ss)``, ... (or ``ss``, ``ss + T``, ... without
wrapping); the last ``n_keep`` are stored and define the recorded span
(impacts, trajectory, minimum of the guard, Lyapunov sums), which starts at
the sample before the first kept one.  ``start.mode``
is 0 in free flight, ``1 + j`` when sticking to stop ``j``; the final mode is
returned so that a run can be continued.  ``cfg.stop`` is the stop a grazing
analysis looks at: its guard's minimum is tracked, a grazing contact at the
start or end of the run is on it, and the discontinuity map stands for it.
With ``cfg.events`` false the guards of the transitions with a reset are ignored (the "virtual" flow
through the stops; a model with modes still switches its vector field and slides), which is how
nonimpacting orbits are continued past grazing.  The
parameter columns of the variational matrix are derivatives at fixed ``(k, s)``, the instant ``k T(p) + s``.
"""

import math

import numpy as np
from numba import njit

from grazing.engine.driver.atomics import load_acquire
from grazing.engine.driver.calls import tc_free, tc_stick, tc_var
from grazing.engine.driver.events import contact_row, first_event, tracked_in
from grazing.engine.driver.impacts import close_sticking, sliding_guard
from grazing.engine.driver.recording import (
    finish_guard,
    guard_at_end,
    new_guard_info,
    sample_modes,
    take_samples,
    track_guard,
    trajectory_points,
)
from grazing.engine.driver.state import (
    STATUS_INTERRUPTED,
    STATUS_NONFINITE,
    STATUS_OK,
    STATUS_STEP_LIMIT,
    new_state,
)
from grazing.engine.driver.step import STEP_LAST, accept_step, end_plain_step, end_step, map_period, step_end
from grazing.engine.polyroots import work_shape
from grazing.engine.records import Config, Kernels, RunOutput, Start
from grazing.engine.stepping import (
    GUARD_SCALE,
    append_pair,
    append_row,
    copy_rows,
    eval_rows,
    new_table,
    step_factor,
    step_size,
    unpack_var,
)

ROOT_WORK_ROWS, ROOT_WORK_MIN_COLS = work_shape(0)


@njit(cache=False, nogil=True)  # (compiled once per machine into its own object file, grazing.engine.native)
def integrate(start, pv, cfg, m, out):
    """Integrate from ``start`` until the ``cfg.n_samples``-th stroboscopic sample (see the module).

    Writes the run's end, samples and tables into ``out`` (a
    :class:`~grazing.engine.records.RunOutput` whose arrays the caller
    allocated).  The GIL is released while it runs: other Python threads go
    on meanwhile.

    ``start``, ``cfg``, ``m`` and ``out`` arrive as plain tuples in the field
    order of their records (numba types a plain tuple in C, a named tuple
    field by field in Python: 3x faster per call) and are named again here.
    Every setting used in the loop is read from the record once, into a local.
    """
    start = Start(*start)
    cfg = Config(*cfg)
    m = Kernels(*m)
    out = RunOutput(*out)
    n = m.nx
    order = m.order
    nstops = m.nstops
    # The settings read on every step, as locals (no record access in the loop).
    T = cfg.T
    use_var = cfg.use_var
    max_step = cfg.max_step
    max_steps = cfg.max_steps
    n_samples = cfg.n_samples
    events = cfg.events
    touch_end = cfg.touch_end
    zdm_on = cfg.zdm
    traj_dt = cfg.traj_dt
    track_min = cfg.track_min
    lyap = cfg.lyapunov
    record_impacts = cfg.record_impacts
    Tp = cfg.Tp
    chatter_time = cfg.chatter_time
    watch = cfg.stop
    sigints = cfg.sigints
    sigints_seen = cfg.sigints_seen
    factor = step_factor(cfg.safety, order)
    ncol = n + m.nsens
    nv = n * ncol if use_var else 0
    ntot = n + nv
    x = np.empty(ntot)
    for i in range(n):
        x[i] = start.x[i]
    if use_var:
        for i in range(n):
            for c in range(ncol):
                x[n + i * ncol + c] = start.V[i, c]
    X = np.zeros((ntot, order + 1))
    nevents = m.rows.shape[1]  # event rows of a mode's kernels (every stop's guard, for one mode)
    O = np.zeros((nevents, order + 1))
    work = np.zeros((ROOT_WORK_ROWS, max(order + 1, ROOT_WORK_MIN_COLS)))
    a = np.zeros(order + 1)
    gm = np.zeros(order + 1)
    xe = np.empty(ntot)
    xp = np.empty(ntot)
    V = np.empty((n, ncol))

    samples = out.samples  # (n_keep, n)
    imp = new_table(16, 3 + n)
    sticks = new_table(4, 2)
    traj = new_table(64 if traj_dt > 0.0 else 1, 1 + n)
    switches = new_table(16 if m.nmodes > 1 else 1, 2 + n)
    logs = out.log_sums
    logs[:] = 0.0
    scratch = np.zeros(n)
    guard_info = new_guard_info(nstops, n)  # per stop: the guard's minimum, closest approach, slopes
    tables = (imp, sticks, traj, switches)
    fbuf = np.empty(n)
    zdm_gh = np.zeros(n)
    zdm_gv = np.zeros(n)
    buffers = (xp, V, scratch, logs, xe, zdm_gh, zdm_gv, fbuf)  # (step.end_step's)

    runs = new_state(1)  # (read again in the return statement: a record does not keep its array alive)
    r = runs[0]  # the run's state (see .state)
    start_run(m, r, start, cfg, x, tables)
    sz = cfg.zdm_s

    while True:
        if r.steps >= max_steps:
            r.status = STATUS_STEP_LIMIT
            break
        if load_acquire(sigints, 0) != sigints_seen:  # Ctrl-C (grazing.engine.interrupts)
            r.status = STATUS_INTERRUPTED
            break
        for i in range(n):
            if not math.isfinite(x[i]):
                r.status = STATUS_NONFINITE
                break
        if r.status != STATUS_OK:
            break
        # The step: Taylor coefficients of the solution (and of the event function), and the step size.
        if r.mode == 0:
            if use_var:
                tc_var(m, x, r.s, pv, X, O, r.vf)
            else:
                tc_free(m, x, r.s, pv, X, O, r.vf)
            h = step_size(X, ntot, O, nevents, 0, GUARD_SCALE, order, max_step, factor)
        else:
            tc_stick(m, x, r.s, pv, X, O, r.stuck)  # the first n rows only
            h = step_size(X, n, O, nevents, contact_row(m, r.vf, r.stuck), math.inf, order, max_step, factor)
        h, ends = step_end(r, h, zdm_on, sz)  # (at the last sample, at the map's phase)
        is_last = (ends & STEP_LAST) != 0

        # The first event on the step (each guard's polynomial in u in [0, 1]).
        u, ev_stop = first_event(
            m, r, O, h, events, watch if zdm_on else -1, touch_end and is_last and r.mode == 0, watch, a, work
        )
        if not accept_step(r, h, ends, u, ev_stop):  # (events accumulate)
            break
        h_acc = r.h_acc
        event = r.event
        nrows = ntot if r.mode == 0 else n

        # What the step records within (0, h_acc].
        if (r.ks - r.k) * T + (r.ss - r.s) <= h_acc:  # a sample is due on this step (about once a period)
            first = r.isamp
            take_samples(m, r, X, pv, h_acc, event, is_last, samples, sticks, traj, xe)
            sample_modes(r, first, out.sample_modes)
        if r.recording and traj_dt > 0.0:
            trajectory_points(m, r, X, h_acc, traj, xe, is_last and not event)
        if r.recording and track_min and r.mode == 0 and h_acc > 0.0:
            if m.nmodes == 1:
                for j in range(nstops):  # every stop's closest approach
                    track_guard(m, r, O[j], j, X, x, h, h_acc, event, gm, guard_info[j], xe)
            else:  # the impacts' guards that are event rows of the current mode (it is their source)
                for row in range(nevents):
                    j = m.rows[r.vf, row]
                    if 0 <= j < nstops and m.resets[j]:
                        track_guard(m, r, O[row], j, X, x, h, h_acc, event, gm, guard_info[j], xe)
                        if event:  # a switch may leave the mode here: its guard at the step's end
                            guard_at_end(m, r, X, h, h_acc, gm, guard_info[j], xe)

        # Advance to the end of the accepted part of the step.
        eval_rows(X, nrows, order, h_acc, xe)
        for i in range(nrows):
            x[i] = xe[i]
        if not end_plain_step(r, lyap, m.nsens > 0):  # (the step's end has work to do)
            kicked, impact = end_step(
                m, r, x, X, pv, nrows, cfg, chatter_time, record_impacts, Tp, buffers, tables
            )
            r.n_imp += int(kicked) + int(impact)
            if r.status != STATUS_OK:  # (a mode entered outside its region: impacts.check_region)
                break
        if r.isamp >= n_samples:
            break

    finish_run(m, runs, cfg, x, pv, guard_info, tables, out)  # (the last use of runs: see above)


@njit(cache=True)
def finish_run(m, runs, cfg, x, pv, guard_info, tables, out):
    """Write the end of the run ``runs[0]`` (its state ``x``) into ``out``, a :class:`RunOutput`.

    The tables (``(impacts, sticking, trajectory)``) are copied as far as
    ``out``'s have room; ``out.totals`` counts the rows they need.
    """
    r = runs[0]
    n = m.nx
    T = cfg.T
    if cfg.track_min and r.mode == 0 and r.recording:
        for j in range(m.nstops):
            if m.nmodes == 1 or (m.resets[j] and tracked_in(m, r.vf, j)):
                finish_guard(m, r, x, pv, j, guard_info[j])
    close_sticking(tables[1], r.n_stick, r.k * T + r.s)
    tot = out.totals[0]
    tot.status = r.status
    tot.k = r.k
    tot.s = r.s
    tot.mode = 0 if r.mode == 0 else 1 + r.stuck
    tot.vf = r.vf
    tot.steps = r.steps
    tot.n_impacts = r.n_imp
    tot.samples_kept = max(0, min(cfg.n_keep, r.isamp - (cfg.n_samples - cfg.n_keep)))
    tot.impact_rows = r.n_imp_rec
    tot.sticking_rows = r.n_stick
    tot.trajectory_rows = r.n_traj
    tot.lyap_span = r.k * T + r.s - r.lyap_t0 if (cfg.lyapunov and r.lyap_started) else 0.0
    tot.jacobian_valid = r.jac_valid
    tot.switch_rows = r.n_switch
    tot.vf_span = r.vf_span
    for i in range(n):
        out.x[i] = x[i]
    out.V[:, :] = 0.0
    if cfg.use_var:
        unpack_var(x, n, out.V.shape[1], out.V)
    copy_rows(tables[0], r.n_imp_rec, out.impacts)
    copy_rows(tables[1], r.n_stick, out.sticking)
    copy_rows(tables[2], r.n_traj, out.trajectory)
    copy_rows(tables[3], r.n_switch, out.switches)
    out.guard_min[:, :] = guard_info[:, : out.guard_min.shape[1]]


@njit(cache=True)
def start_run(m, r, start, cfg, x, tables):
    """Set the state ``r`` of a run from ``start`` with the settings ``cfg`` (its state ``x``).

    A run whose recorded span starts at once records its first trajectory
    point, and a sticking interval if it starts sticking (``tables`` =
    ``(impacts, sticking, trajectory, switches)``).
    """
    n = m.nx
    T = cfg.T
    r.T = T
    r.wrap = cfg.wrap
    r.traj_dt = cfg.traj_dt
    r.n_samples = cfg.n_samples
    r.n_keep = cfg.n_keep
    r.use_var = cfg.use_var
    r.max_steps = cfg.max_steps
    r.k = start.k
    r.s = start.s
    r.mode = 1 if start.mode > 0 else 0
    r.stuck = max(start.mode - 1, 0)  # the stop it sticks to
    r.vf = start.vf
    r.surface = 1 + sliding_guard(m, r.vf)  # (a run continued while sliding)
    r.defl = 2 if cfg.touch_start else 0
    r.defl_stop = cfg.stop  # the stop the known roots at u = 0 belong to
    r.ks = cfg.ks
    r.ss = cfg.ss
    r.isamp = 0
    r.recording = cfg.n_samples - cfg.n_keep == 0
    r.vf_span = r.vf
    r.lyap_t0 = r.k * T + r.s
    r.lyap_started = r.recording
    r.span_dt = math.nan
    r.n_imp = 0
    r.n_imp_rec = 0
    r.n_stick = 0
    r.n_traj = 0
    r.n_switch = 0
    r.kt = r.k
    r.st = r.s
    r.kz = map_period(r.k, r.s, cfg.zdm_s, T)
    r.status = STATUS_OK
    r.steps = 0
    r.zero_events = 0
    r.jac_valid = True
    if r.recording and r.traj_dt > 0.0:
        append_row(tables[2], 0, r.k * T + r.s, x, n)
        r.n_traj = 1
        r.st += r.traj_dt
        while r.wrap and r.st >= T:
            r.st -= T
            r.kt += 1
    if r.recording and r.mode == 1:  # the recorded span starts while sticking
        append_pair(tables[1], r.n_stick, r.k * T + r.s, math.nan)
        r.n_stick += 1
