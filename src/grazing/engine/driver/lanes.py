"""Driver piece: a sweep on SIMD lanes, several parameter values integrated in lockstep.

``sweep_lanes`` computes the points of a sweep (:mod:`grazing.sweeps.run`)
``L`` at a time.  Each lane integrates its own point with its own step size,
event search, samples, impacts and sticking -- the step of :mod:`.loop`, for
the settings a sweep uses -- while the Taylor coefficients of all lanes in
free flight come from one call of the model's lane function (``tc_free`` or
``tc_var`` on vectors of ``L`` doubles, :mod:`grazing.engine.llvmgen`): that
is where a step spends most of its time.  A lane that sticks, or the only
lane of its kind (with or without variational equations), calls the scalar
function; a lane whose point is finished takes the next one, so a lane that
impacts or sticks holds up no other.  A lane of a model with modes carries
its active mode (its kernels; switches and sliding through the scalar
driver's functions: a sliding lane is put back on its surface at each step's
end and sample as a scalar run is).  Every lane's arithmetic is the scalar
path's: the results are the same numbers, bit for bit.

A point is run as :mod:`grazing.sweeps.run` describes: the transient in
blocks of :data:`~grazing.core.options.ADAPTIVE_BLOCK` periods (stopped
early, at the point of the cycle where it would have ended, once the samples
repeat to ``adaptive_tol`` with a period of at most
:data:`~grazing.core.options.ADAPTIVE_MAX_PERIOD`, when ``adaptive``), then either
``periods`` sampled periods, or (``lyapunov``) ``align + periods`` with the
variational equations from the identity, the Lyapunov sums taken over the
last ``periods``.  ``jobs`` are runs of consecutive points; within a job each
point starts from the previous one's final state (unless ``fresh``, or the
previous point failed: then from ``x0`` at time 0), every job's first point
from its own start ``firsts`` (a time and a state: ``x0`` at time 0 for a
sweep's chunk, the previous chunk's final state to continue a chain, a grid
point of initial states at its phase).
"""

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from grazing.core import options as core_options
from grazing.core import period as core_period
from grazing.core.options import ADAPTIVE_BLOCK, ADAPTIVE_MAX_PERIOD, LYAPUNOV_ALIGN
from grazing.engine import timebase
from grazing.engine.abi import TC_FREE_LANES, TC_VAR_LANES, call_model
from grazing.engine.driver.atomics import fetch_add, load_acquire, store_release
from grazing.engine.driver.calls import tc_free, tc_stick, tc_var
from grazing.engine.driver.events import contact_row, first_event
from grazing.engine.driver.impacts import sliding_guard
from grazing.engine.driver.recording import take_samples
from grazing.engine.driver.state import STATUS_NONFINITE, STATUS_OK, STATUS_STEP_LIMIT, new_state
from grazing.engine.driver.step import STEP_LAST, accept_step, end_plain_step, end_step, map_period, step_end
from grazing.engine.lanevec import LANE_WIDTH, advance_rows, certify_stop
from grazing.engine.polyroots import quadratic_bound, work_shape
from grazing.engine.records import Kernels, LaneJobs, LanePoints, LaneResults, LaneSettings
from grazing.engine.stepping import GUARD_SCALE, new_table, step_factor, step_size, steps_from_norms

LANE_ROOT_ROWS, LANE_ROOT_MIN_COLS = work_shape(0)
VECTOR_MIN_LANES = 3
"""Fewest lanes of a kind for which the lane function is called (else the scalar one, lane by lane)."""


class LaneArrays(NamedTuple):
    """The lanes' own arrays in :func:`sweep_lanes` (one row or column per lane)."""

    ls: np.ndarray  # the lanes' runs (state.RUN_STATE records)
    XS: np.ndarray  # (rows, lanes): their states (and variational matrices)
    pl: np.ndarray  # (lanes, parameters): their parameter vectors ...
    PT: np.ndarray  # ... and transposed, for the lane functions
    logs: np.ndarray  # (lanes, nx): their Lyapunov sums
    buf: np.ndarray  # (lanes, samples, nx): their kept samples
    counts: np.ndarray  # (lanes, stops): their impacts on each stop


# A lane's stage in its point's protocol.
IDLE, TRANSIENT, EXTRA, FINAL = 0, 1, 2, 3
FAILED = 8
"""A lane's step flag: its point failed."""


repeats_with_period = njit(inline="always")(core_period.repeats_with_period)
"""Smallest ``p <= max_period`` with ``samples[:count]`` p-periodic to ``tol`` (``core.period``'s test)."""

step_limit = njit(inline="always")(core_options.step_limit)
"""The step limit of a run over ``periods`` forcing periods (``core.options``', as the scalar runner's)."""

start_times = njit(inline="always")(timebase.start_times)
"""``(k, s, ks, ss)`` of a run starting at ``t0`` sampled at local time ``s_phase`` (as ``Runner``'s)."""


@njit(cache=True)
def to_lane(X, O, rows, nstops, K, XT, OT, lane):
    """Lane ``lane`` of the lane arrays ``XT``, ``OT`` = the scalar coefficients ``X``, ``O``."""
    for i in range(rows):
        for c in range(K):
            XT[i, c, lane] = X[i, c]
    for r in range(nstops):
        for c in range(K):
            OT[r, c, lane] = O[r, c]


@njit(cache=True)
def begin_request(m, st, periods, keep, use_var, T, zdm_s):
    """Start a lane (state ``st``) on ``periods`` samples keeping the last ``keep`` (``Runner.advance``).

    As :func:`.loop.start_run` does, a lane in a sliding pseudo-mode is kept on its surface's transition
    from the positive side (the one it entered by within the previous request).
    """
    st.n_samples = periods
    st.n_keep = keep
    st.isamp = 0
    st.recording = periods - keep == 0
    st.lyap_started = st.recording
    st.span_dt = math.nan
    st.steps = 0
    st.max_steps = step_limit(periods)
    st.zero_events = 0
    st.jac_valid = True
    st.use_var = use_var
    st.defl = 0
    st.surface = 1 + sliding_guard(m, st.vf)  # (0: not sliding)
    st.ks = st.req_ks
    st.ss = st.req_ss
    k = st.k
    s = st.s
    st.lyap_t0 = k * T + s
    st.kz = map_period(k, s, zdm_s, T)


@njit(cache=False, nogil=True)  # (compiled once per machine into its own object file, grazing.engine.native)
def sweep_lanes(m, cfg, work, points, out):
    """Compute the points of the jobs ``work`` on ``cfg.lanes`` lanes (see the module); results into ``out``.

    The arguments are the records of :data:`grazing.engine.records.SWEEP_RECORDS`
    as plain tuples: the model's :class:`~grazing.engine.records.Kernels`, the
    :class:`~grazing.engine.records.LaneSettings`, the
    :class:`~grazing.engine.records.LaneJobs`, the
    :class:`~grazing.engine.records.LanePoints` and the
    :class:`~grazing.engine.records.LaneResults`.  Job ``j``'s first point
    starts from state ``firsts[j, 1:]`` at time ``firsts[j, 0]``; a point after
    a failed one from ``x0[j]`` at time 0.  ``out.status[p]`` becomes the
    point's :class:`~grazing.core.solution.Status` code once it is finished: 0
    once its results are written, else why it failed (1 step limit, 2
    non-finite state, 3 accumulating impacts); the caller sets it to -1 before.

    Several threads may run the same call (the same arrays): they take the
    jobs in turn from the counter ``control[0]`` (0 at the start), each
    running at most ``control[2]`` jobs at a time (0: one per lane; so that
    a few jobs are shared out evenly), and stop at the next step once the
    caller sets ``control[1]`` to 1, leaving the points they had not
    finished at -1.
    """
    m = Kernels(*m)
    cfg = LaneSettings(*cfg)
    work = LaneJobs(*work)
    points = LanePoints(*points)
    out = LaneResults(*out)
    zdms = points.zdms
    npv = points.pvs.shape[1]
    n = m.nx
    order = m.order
    nstops = m.nstops
    nev = m.rows.shape[1]  # event rows of a mode's kernels (every stop's guard, for one mode)
    K = order + 1
    L = cfg.lanes
    ncol = n
    ntot = n + n * ncol
    factor = step_factor(cfg.safety, order)
    align = min(LYAPUNOV_ALIGN, cfg.transient) if cfg.lyapunov else 0
    budget = cfg.transient - align
    keep_max = max(cfg.periods, ADAPTIVE_BLOCK)
    use_lanes = L > 1 and L == m.lanes and m.fns[TC_FREE_LANES] != 0  # (the lane functions' width)

    ls = new_state(L)  # the lanes' runs and where each is in its point's protocol
    XS = np.zeros((ntot, L))  # the lanes' states (and variational matrices), lane by lane
    Xs = np.zeros((ntot, K))  # one lane's coefficients from a scalar function
    Os = np.zeros((nev, K))
    xl = np.zeros(ntot)  # one lane's state, for the scalar functions
    pl = np.zeros((L, npv))
    logs = np.zeros((L, n))
    buf = np.zeros((L, keep_max, n))
    counts = np.zeros((L, nstops), dtype=np.int64)
    SI = np.zeros(L)
    PT = np.zeros((npv, L))
    XT = np.zeros((ntot, K, L))
    OT = np.zeros((nev, K, L))
    nscratch = L if m.nmodes > 1 and use_lanes else 0  # (a mode's lane function writes every lane)
    XM = np.zeros((ntot, K, nscratch))
    OM = np.zeros((nev, K, nscratch))
    roots = np.zeros((LANE_ROOT_ROWS, max(K, LANE_ROOT_MIN_COLS)))
    a = np.zeros(K)
    xe = np.empty(ntot)
    xp = np.empty(ntot)
    V = np.empty((n, ncol))
    scratch = np.zeros(n)
    gh = np.zeros(n)
    gv = np.zeros(n)
    imp = new_table(1, 3 + n)  # (impacts are counted, not recorded)
    sticks = new_table(1, 2)
    traj = new_table(1, 1 + n)
    switches = new_table(1, 2 + n)
    tables = (imp, sticks, traj, switches)
    fbuf = np.zeros(n)
    Tp = np.zeros(0)  # (no sensitivities on lanes: end_step's period term is never taken)
    kinds = np.zeros(L, dtype=np.int64)  # 0 sticking or idle, 1 free flight, 2 with the variational equations
    # What a step decides for each lane (pass A), for the advance (vectors) and the rest (pass B).
    hs = np.zeros(L)  # step
    dts = np.zeros(L)  # accepted part of it
    flags = np.zeros(L, dtype=np.int64)  # how it ends (step.STEP_LAST, STEP_MAP), or FAILED
    todo = np.zeros(L, dtype=np.int64)  # 1: the lane steps this round
    norms = np.zeros(5 * L)  # the norms of the steps, the steps in free flight, the periods (lane_norms)
    certs = np.zeros(5 * L)  # (no_events_certain)
    plain = np.zeros(L, dtype=np.int64)  # 1: no event on the step is certain so far
    acc = np.zeros(L, dtype=np.int64)  # (advance_lanes: which lanes advance)

    la = LaneArrays(ls, XS, pl, PT, logs, buf, counts)
    coeffs = (XT, OT, SI, Xs, Os, xl, XM, OM)
    active = 0
    for lane in range(L):
        ls[lane].stage = IDLE
    while True:
        if load_acquire(work.control, 1) != 0:  # the caller stops the sweep: unfinished points stay at -1
            return
        # Idle lanes take the next point: their job's next one, else the next job's first.
        for lane in range(L):
            if ls[lane].stage == IDLE and ls[lane].job_end >= 0:  # (a call only where it takes a point)
                active = take_point(m, cfg, work, points, out, la, lane, budget, align, active)
        if active == 0:
            break

        # The Taylor coefficients: lanes in free flight by kind, on vectors where there are enough of them;
        # the norms of their step sizes.
        nvar = lane_coefficients(m, la, kinds, use_lanes, coeffs)
        lane_norms(m, ls, XT, OT, kinds, nvar, factor, norms)

        # Pass A, lane by lane: the step, its events and its samples.
        plan_steps(m, cfg, la, zdms, norms, coeffs, factor, (hs, flags, todo, plain))
        # No event on the step where every guard's polynomial is certainly positive; the other lanes
        # search lane by lane (and a single lane at once).
        no_events_certain(m, cfg, OT, hs, plain, certs)
        for lane in range(L):
            if todo[lane] == 0:
                continue
            h = hs[lane]
            if plain[lane] == 1:
                u = -1.0
                ev_stop = 0
            else:
                skip = cfg.stop if cfg.zdm else -1
                u, ev_stop = first_event(
                    m, ls[lane], OT[:, :, lane], h, True, skip, False, cfg.stop, a, roots
                )
            run = ls[lane]
            if not accept_step(run, h, flags[lane], u, ev_stop):  # (events accumulate)
                flags[lane] = FAILED
                todo[lane] = 0
                continue
            is_last = (flags[lane] & STEP_LAST) != 0
            h_acc = run.h_acc
            event = run.event
            dts[lane] = h_acc
            if (run.ks - run.k) * run.T + (run.ss - run.s) <= h_acc:
                run.n_stick = 0  # (sticking intervals are not recorded)
                take_samples(
                    m, run, XT[:, :, lane], pl[lane], h_acc, event, is_last, buf[lane], sticks, traj, xe
                )

        # The advance of every stepping lane to the end of its accepted part (eval_rows on vectors).
        advance_lanes(m, la, XT, dts, todo, kinds, nvar, acc)

        # Pass B, lane by lane: time, Lyapunov vectors, discontinuity map, impacts, the request's end.
        for lane in range(L):
            if flags[lane] == FAILED:  # the point failed (its status says why): the next point starts afresh
                store_release(out.status, ls[lane].point, ls[lane].status)
                ls[lane].stage = IDLE
                active -= 1
                continue
            if todo[lane] == 0:
                continue
            run = ls[lane]
            if not end_plain_step(run, cfg.lyapunov, m.nsens > 0):  # (the step's end has work to do)
                end_lane_step(
                    m, cfg, la, lane, XT[:, :, lane], (xl, Tp, xp, V, scratch, xe, gh, gv, fbuf), tables
                )
                if run.status != STATUS_OK:  # (a mode entered outside its region: impacts.check_region)
                    store_release(out.status, run.point, run.status)
                    run.stage = IDLE
                    active -= 1
                    continue
            n_samples = ls[lane].n_samples
            if ls[lane].isamp < n_samples:
                continue
            # The request is done (Runner.advance returns): on to the next stage of the point.
            if end_request(m, cfg, points, out, la, lane, budget, align):
                active -= 1


@njit(cache=True, inline="always")
def end_lane_step(m, cfg, la, lane, X, work, tables):
    """The end of a lane's step that has work to do (an event, a sample, the request's end, sliding):
    the scalar driver's :func:`~grazing.engine.driver.step.end_step` on the lane's state and
    coefficients ``X``, its impacts counted in ``la.counts`` while the point records.

    ``work`` = ``(xl, Tp, xp, V, scratch, xe, gh, gv, fbuf)``: one lane's state, the (empty) period
    terms and end_step's buffers; ``tables`` its (unused) tables.
    """
    xl, Tp, xp, V, scratch, xe, gh, gv, fbuf = work
    run = la.ls[lane]
    XS = la.XS
    n = m.nx
    ntot = xl.shape[0]
    recording = run.recording  # (before the step's end)
    nrows = ntot if (run.mode == 0 and run.use_var) else n
    for i in range(ntot):
        xl[i] = XS[i, lane]
    buffers = (xp, V, scratch, la.logs[lane], xe, gh, gv, fbuf)
    chatter_time = cfg.chatter_tol * run.T
    kicked, impact = end_step(m, run, xl, X, la.pl[lane], nrows, cfg, chatter_time, 0, Tp, buffers, tables)
    if recording and run.stage == FINAL:
        if kicked:
            la.counts[lane, cfg.stop] += 1
        if impact:
            la.counts[lane, run.ev_stop] += 1
    run.n_stick = 0  # (sticking intervals are not recorded)
    for i in range(ntot):
        XS[i, lane] = xl[i]


@njit(cache=True, inline="always")
def lane_coefficients(m, la, kinds, use_lanes, coeffs):
    """The Taylor coefficients of the lanes in free flight into ``XT``, ``OT``; returns how many have ``V``.

    ``kinds[lane]`` becomes 0 (idle or sticking), 1 (free flight) or 2 (with
    the variational equations); a kind with at least ``VECTOR_MIN_LANES``
    lanes is computed by the model's lane function (``use_lanes``), the
    others lane by lane.  ``coeffs`` = ``(XT, OT, SI, Xs, Os, xl, XM, OM)``:
    the lanes' coefficients, their local times, one lane's coefficients and
    state, and (a model with modes) the lanes' coefficients in one mode.
    """
    XT, OT, SI, Xs, Os, xl, _, _ = coeffs
    ls, XS, pl, PT = la.ls, la.XS, la.pl, la.PT
    n = m.nx
    nev = m.rows.shape[1]
    K = m.order + 1
    L = ls.shape[0]
    ntot = n + n * n
    nfree = 0
    nvar = 0
    for lane in range(L):
        kinds[lane] = 0
        if ls[lane].stage != IDLE and ls[lane].mode == 0:
            if ls[lane].use_var:
                kinds[lane] = 2
                nvar += 1
            else:
                kinds[lane] = 1
                nfree += 1
    for lane in range(L):
        SI[lane] = ls[lane].s
    if m.nmodes > 1:
        mode_coefficients(m, la, kinds, use_lanes, coeffs)
        return nvar
    for kind in (1, 2):
        count = nfree if kind == 1 else nvar
        rows = n if kind == 1 else ntot
        if count == 0:
            continue
        if use_lanes and count >= VECTOR_MIN_LANES:
            call_model(m.fns[TC_FREE_LANES if kind == 1 else TC_VAR_LANES], XS, 0.0, PT, XT, OT, SI, 0)
        elif L == 1:  # one lane: the lane arrays are the scalar function's arrays
            if kind == 1:
                tc_free(m, XS, SI[0], pl[0], XT, OT, 0)
            else:
                tc_var(m, XS, SI[0], pl[0], XT, OT, 0)
        else:  # lane by lane, into the lanes' columns
            for lane in range(L):
                if kinds[lane] == kind:
                    for i in range(rows):
                        xl[i] = XS[i, lane]
                    if kind == 1:
                        tc_free(m, xl, SI[lane], pl[lane], Xs, Os, 0)
                    else:
                        tc_var(m, xl, SI[lane], pl[lane], Xs, Os, 0)
                    to_lane(Xs, Os, rows, nev, K, XT, OT, lane)
    return nvar


@njit(cache=True)
def mode_coefficients(m, la, kinds, use_lanes, coeffs):
    """:func:`lane_coefficients` of a model with modes: the lanes grouped by kind and active mode.

    A group of at least ``VECTOR_MIN_LANES`` lanes is computed by the mode's
    lane function, which writes every lane: into ``XM``, ``OM``, from which
    the group's columns are copied; the others lane by lane, each in its
    own mode.
    """
    XT, OT, SI, Xs, Os, xl, XM, OM = coeffs
    ls, XS, pl, PT = la.ls, la.XS, la.pl, la.PT
    n = m.nx
    nev = m.rows.shape[1]
    K = m.order + 1
    L = ls.shape[0]
    ntot = n + n * n
    for kind in (1, 2):
        rows = n if kind == 1 else ntot
        for vf in range(m.nmodes):
            count = 0
            for lane in range(L):
                if kinds[lane] == kind and ls[lane].vf == vf:
                    count += 1
            if count == 0:
                continue
            if use_lanes and count >= VECTOR_MIN_LANES:
                call_model(m.fns[TC_FREE_LANES if kind == 1 else TC_VAR_LANES], XS, 0.0, PT, XM, OM, SI, vf)
                for lane in range(L):
                    if kinds[lane] == kind and ls[lane].vf == vf:
                        for i in range(rows):
                            for c in range(K):
                                XT[i, c, lane] = XM[i, c, lane]
                        for r in range(nev):
                            for c in range(K):
                                OT[r, c, lane] = OM[r, c, lane]
                continue
            for lane in range(L):
                if kinds[lane] == kind and ls[lane].vf == vf:
                    for i in range(rows):
                        xl[i] = XS[i, lane]
                    if kind == 1:
                        tc_free(m, xl, SI[lane], pl[lane], Xs, Os, vf)
                    else:
                        tc_var(m, xl, SI[lane], pl[lane], Xs, Os, vf)
                    to_lane(Xs, Os, rows, nev, K, XT, OT, lane)


@njit(cache=True, inline="always")
def lane_norms(m, ls, XT, OT, kinds, nvar, factor, norms):
    """The norms of the lanes' steps (as ``step_size``, row by row, on vectors) and the steps in free flight.

    ``norms`` holds five rows of ``L`` lanes, one after the other: the norms
    ``nx``, ``n1``, ``n2`` of :func:`~grazing.engine.stepping.step_from_norms`,
    the step (on vectors too: it calls no C function) and the lane's period.
    """
    L = XT.shape[2]
    if L == LANE_WIDTH:
        _lane_norms(m, ls, XT, OT, kinds, nvar, factor, norms, LANE_WIDTH)
    else:
        _lane_norms(m, ls, XT, OT, kinds, nvar, factor, norms, L)


@njit(cache=True, inline="always")
def _lane_norms(m, ls, XT, OT, kinds, nvar, factor, norms, nl):
    """:func:`lane_norms` over ``nl`` lanes (a constant: the rows' values stay in vector registers)."""
    n = m.nx
    order = m.order
    nev = m.rows.shape[1]  # (a mode's event rows: every stop's guard for one mode)
    ntot = n + n * n
    for lane in range(nl):
        norms[lane] = 0.0
        norms[nl + lane] = 0.0
        norms[2 * nl + lane] = 0.0
    for r in range(nev):
        for lane in range(nl):
            norms[nl + lane] = max(norms[nl + lane], abs(OT[r, order - 1, lane]))
            norms[2 * nl + lane] = max(norms[2 * nl + lane], abs(OT[r, order, lane]))
    for i in range(ntot if nvar > 0 else n):
        for lane in range(nl):
            if i < n or kinds[lane] == 2:
                norms[lane] = max(norms[lane], abs(XT[i, 0, lane]))
                norms[nl + lane] = max(norms[nl + lane], abs(XT[i, order - 1, lane]))
                norms[2 * nl + lane] = max(norms[2 * nl + lane], abs(XT[i, order, lane]))
    for lane in range(nl):  # (the first guard, up to GUARD_SCALE times the state's scale: step_size)
        norms[lane] = max(norms[lane], min(abs(OT[0, 0, lane]), GUARD_SCALE * max(1.0, norms[lane])))
        norms[4 * nl + lane] = ls[lane].T
    steps_from_norms(norms[:nl], norms[nl : 2 * nl], norms[2 * nl : 3 * nl], order, norms[4 * nl :],
                     factor, norms[3 * nl : 4 * nl])  # fmt: skip


@njit(cache=True, inline="always")
def map_row(m, cfg):
    """The event row left out of :func:`no_events_certain`: the discontinuity map's stop on a model of one
    mode (its rows are its stops), else -1.  With modes each lane's rows are its own mode's, the map's stop
    in none of them or in another row: every row is certified (the map's stop's row too, which only makes
    a lane searched, where :func:`.events.first_event` leaves that stop out)."""
    return cfg.stop if cfg.zdm and m.rows.shape[0] == 1 else -1


@njit(cache=True, inline="always")
def no_events_certain(m, cfg, OT, hs, plain, certs):
    """Clear ``plain[lane]`` where an event on the step of size ``hs[lane]`` is not excluded.

    ``event_certificate`` on vectors (the same coefficients as
    ``event_polynomial``): a lane stays ``plain`` where every guard's
    polynomial is certainly positive on its step.  A single lane is never
    plain (its search is as cheap).  ``certs`` holds five rows of ``L`` lanes
    (``a0, a1, a2``, the tail, the power of the step).
    """
    L = hs.shape[0]
    if L == 1:
        plain[0] = 0
    elif L == LANE_WIDTH:  # (on vectors: the loop over the coefficients keeps the lanes in registers)
        skip = map_row(m, cfg)
        for r in range(m.rows.shape[1]):  # (a mode's event rows; a padding row is a constant 1)
            if r != skip:
                certify_stop(OT, r, m.order + 1, hs, plain)
    else:
        _no_events_certain(m, cfg, OT, hs, plain, certs)


@njit(cache=True, inline="always")
def _no_events_certain(m, cfg, OT, hs, plain, certs):
    """:func:`no_events_certain` lane by lane in numba, for a lane count other than ``LANE_WIDTH``."""
    nev = m.rows.shape[1]
    K = m.order + 1
    nl = hs.shape[0]
    a1, a2, tl, hk = nl, 2 * nl, 3 * nl, 4 * nl
    skip = map_row(m, cfg)
    for r in range(nev):
        if r == skip:
            continue
        for lane in range(nl):
            certs[hk + lane] = 1.0
            certs[tl + lane] = 0.0
            certs[lane] = OT[r, 0, lane] * certs[hk + lane]
            certs[hk + lane] *= hs[lane]
            certs[a1 + lane] = OT[r, 1, lane] * certs[hk + lane]
            certs[hk + lane] *= hs[lane]
            certs[a2 + lane] = OT[r, 2, lane] * certs[hk + lane]
            certs[hk + lane] *= hs[lane]
        for j in range(3, K):
            for lane in range(nl):
                certs[tl + lane] += abs(OT[r, j, lane] * certs[hk + lane])
                certs[hk + lane] *= hs[lane]
        for lane in range(nl):
            bound = quadratic_bound(certs[lane], certs[a1 + lane], certs[a2 + lane], certs[tl + lane])
            if plain[lane] == 1 and not (certs[lane] > 0.0 and bound > 0.0):
                plain[lane] = 0


@njit(cache=True, inline="always")
def advance_lanes(m, la, XT, dts, todo, kinds, nvar, acc):
    """Every stepping lane to the end of its accepted part ``dts[lane]`` (``eval_rows`` on vectors).

    The state in all, the variational equations in free flight.
    """
    ls, XS = la.ls, la.XS
    n = m.nx
    order = m.order
    L = dts.shape[0]
    ntot = n + n * n
    if L == LANE_WIDTH:  # (on vectors: the sums stay in vector registers)
        for lane in range(LANE_WIDTH):
            acc[lane] = todo[lane]  # (the lanes whose state advances)
        advance_rows(XT, 0, n, order, dts, acc, XS)
        if nvar > 0:
            for lane in range(LANE_WIDTH):  # (... and their variational equations, in free flight)
                acc[lane] = 1 if todo[lane] == 1 and kinds[lane] == 2 and ls[lane].mode == 0 else 0
            advance_rows(XT, n, ntot, order, dts, acc, XS)
        return
    for lane in range(L):  # (lane by lane: the sums stay in registers, several lanes' chains overlap)
        if todo[lane] == 0:
            continue
        dt = dts[lane]
        rows = ntot if (nvar > 0 and kinds[lane] == 2 and ls[lane].mode == 0) else n
        for i in range(rows):
            v = XT[i, order, lane]
            for j in range(order - 1, -1, -1):
                v = v * dt + XT[i, j, lane]
            XS[i, lane] = v


@njit(cache=True, inline="always")
def plan_steps(m, cfg, la, zdms, norms, coeffs, factor, plan):
    """Each running lane's step: its size (from ``norms`` in free flight, the scalar sticking function
    otherwise) and where it ends (:func:`.step.step_end`), or its point's failure.

    ``plan`` = ``(hs, flags, todo, plain)``: the step, how it ends (or
    ``FAILED``), whether the lane steps, whether it may skip the event search
    (free flight, no known root at its start: :func:`no_events_certain`).
    """
    hs, flags, todo, plain = plan
    XT, OT, _, Xs, Os, xl, _, _ = coeffs
    ls, XS, pl = la.ls, la.XS, la.pl
    n = m.nx
    order = m.order
    nev = m.rows.shape[1]
    K = order + 1
    L = ls.shape[0]
    hfree = norms[3 * L : 4 * L]
    for lane in range(L):
        todo[lane] = 0
        flags[lane] = 0
        plain[lane] = 0
        if ls[lane].stage == IDLE:
            continue
        p = ls[lane].point
        T = ls[lane].T
        s = ls[lane].s
        mode = ls[lane].mode
        status = STATUS_OK
        if ls[lane].steps >= ls[lane].max_steps:
            status = STATUS_STEP_LIMIT
        for i in range(n):
            if not math.isfinite(XS[i, lane]):
                status = STATUS_NONFINITE
        if status != STATUS_OK:
            flags[lane] = FAILED
            ls[lane].status = status
            continue
        if mode == 1:
            stuck = ls[lane].stuck
            for i in range(n):
                xl[i] = XS[i, lane]
            tc_stick(m, xl, s, pl[lane], Xs, Os, stuck)
            to_lane(Xs, Os, n, nev, K, XT, OT, lane)
            h = step_size(Xs, n, Os, nev, contact_row(m, ls[lane].vf, stuck), math.inf, order, T, factor)
        else:
            h = hfree[lane]
        h, ends = step_end(ls[lane], h, cfg.zdm, zdms[p])
        flags[lane] = ends
        hs[lane] = h
        todo[lane] = 1
        plain[lane] = 1 if mode == 0 and ls[lane].defl == 0 else 0


@njit(cache=True)
def take_point(m, cfg, work, points, out, la, lane, budget, align, active):
    """An idle lane takes its job's next point, else the next job's first; returns the points now running.

    ``la`` holds the lanes' arrays (:class:`LaneArrays`); ``active`` counts the
    points this call is running (a thread with ``control[2]`` jobs running
    takes no other job).
    """
    n = m.nx
    nstops = m.nstops
    ls, XS, pl, PT, logs, counts = la.ls, la.XS, la.pl, la.PT, la.logs, la.counts
    pvs, Ts, sphase, tcarry, zdms = points.pvs, points.Ts, points.sphase, points.tcarry, points.zdms
    npv = pvs.shape[1]
    while ls[lane].stage == IDLE and ls[lane].job_end >= 0:
        p = ls[lane].point + 1
        carried = ls[lane].status == STATUS_OK and ls[lane].job_end > 0
        first = False
        if ls[lane].job_end == 0 or p >= ls[lane].job_end:
            if work.control[2] > 0 and active >= work.control[2]:
                break  # (this thread has its share of the jobs running)
            job = fetch_add(work.control, 0, 1)
            if job >= work.jobs.shape[0]:
                ls[lane].job_end = -1  # (no more jobs for this lane)
                break
            p = work.jobs[job, 0]
            ls[lane].job_end = work.jobs[job, 1]
            ls[lane].job = job
            carried = False
            first = True
        ls[lane].point = p
        T = Ts[p]
        ls[lane].T = T
        ls[lane].wrap = cfg.periodic
        if first:
            for i in range(n):
                XS[i, lane] = work.firsts[ls[lane].job, 1 + i]
            t0 = work.firsts[ls[lane].job, 0]
            ls[lane].vf = work.first_vf[ls[lane].job]
        elif cfg.fresh or not carried:
            for i in range(n):
                XS[i, lane] = work.x0[ls[lane].job, i]
            t0 = 0.0
            ls[lane].vf = work.x0_vf[ls[lane].job]
        else:  # (the previous point's end: its state, time and mode)
            t0 = tcarry[p] if cfg.periodic else out.t[p - 1]
        k0, s0, ks0, ss0 = start_times(t0, T, sphase[p], cfg.periodic)
        ls[lane].k = k0
        ls[lane].s = s0
        ls[lane].req_ks = ks0
        ls[lane].req_ss = ss0
        ls[lane].mode = 0
        ls[lane].stuck = 0
        ls[lane].status = STATUS_OK
        ls[lane].used = 0
        for j in range(npv):
            pl[lane, j] = pvs[p, j]
            PT[j, lane] = pvs[p, j]
        for j in range(nstops):
            counts[lane, j] = 0
        for j in range(n):
            logs[lane, j] = 0.0
        if budget > 0:
            blk = min(ADAPTIVE_BLOCK, budget)
            ls[lane].block = blk
            ls[lane].stage = TRANSIENT
            begin_request(m, ls[lane], blk, blk if cfg.adaptive else 0, False, T, zdms[p])
        else:
            ls[lane].stage = FINAL
            final_request(m, ls[lane], XS, n, lane, align, cfg, sphase[p], zdms[p])
        active += 1
    return active


@njit(cache=True)
def end_request(m, cfg, points, out, la, lane, budget, align):
    """The lane's request is done (``Runner.advance`` returns): on to its point's next stage.

    Returns True when the point is finished (its results written, or failed).
    """
    n = m.nx
    ls, XS, buf = la.ls, la.XS, la.buf
    Ts, sphase, zdms = points.Ts, points.sphase, points.zdms
    p = ls[lane].point
    T = Ts[p]
    n_samples = ls[lane].n_samples
    if cfg.periodic:
        ls[lane].req_ks += n_samples
    else:
        ls[lane].req_ss += n_samples * T
    stage = ls[lane].stage
    if stage == TRANSIENT:
        blk = ls[lane].block
        ls[lane].used += blk
        used = ls[lane].used
        nxt = -1
        if cfg.adaptive and blk == ADAPTIVE_BLOCK:
            per = repeats_with_period(buf[lane], blk, cfg.adaptive_tol, ADAPTIVE_MAX_PERIOD)
            if per > 0:
                extra = (budget - used) % per
                if extra:
                    ls[lane].used += extra
                    ls[lane].stage = EXTRA
                    begin_request(m, ls[lane], extra, 0, False, T, zdms[p])
                    return False
                nxt = 0
        if nxt < 0 and used < budget:
            blk = min(ADAPTIVE_BLOCK, budget - used)
            ls[lane].block = blk
            begin_request(m, ls[lane], blk, blk if cfg.adaptive else 0, False, T, zdms[p])
            return False
        ls[lane].stage = FINAL
        final_request(m, ls[lane], XS, n, lane, align, cfg, sphase[p], zdms[p])
        return False
    if stage == EXTRA:
        ls[lane].stage = FINAL
        final_request(m, ls[lane], XS, n, lane, align, cfg, sphase[p], zdms[p])
        return False
    return finish_point(m, cfg, out, la, lane, align)


@njit(cache=True)
def finish_point(m, cfg, out, la, lane, align):
    """The point of a lane at the end of its last request: its results, or its failure; returns True."""
    n = m.nx
    nstops = m.nstops
    ls, XS, logs, buf, counts = la.ls, la.XS, la.logs, la.buf, la.counts
    p = ls[lane].point
    T = ls[lane].T
    k = ls[lane].k
    s = ls[lane].s
    finite = True  # (a state that became non-finite on the last step fails the point)
    for i in range(n):
        finite = finite and math.isfinite(XS[i, lane])
    for r in range(cfg.periods):
        for c in range(n):
            finite = finite and math.isfinite(buf[lane, r, c])
    if not finite:
        ls[lane].status = STATUS_NONFINITE
        store_release(out.status, p, STATUS_NONFINITE)
        ls[lane].stage = IDLE
        return True
    for r in range(cfg.periods):
        for c in range(n):
            out.samples[p, r, c] = buf[lane, r, c]
    for j in range(nstops):
        out.by_stop[p, j] = counts[lane, j]
    lyap = math.nan
    if cfg.lyapunov:
        span = k * T + s - ls[lane].lyap_t0 if ls[lane].lyap_started else 0.0
        if ls[lane].jac_valid and span != 0.0:
            lyap = logs[lane, 0] / span
            for j in range(1, n):
                v = logs[lane, j] / span
                if math.isnan(lyap) or math.isnan(v):
                    lyap = math.nan
                elif v > lyap:
                    lyap = v
    out.lyap[p] = lyap
    out.used[p] = ls[lane].used + align
    for i in range(n):
        out.x[p, i] = XS[i, lane]
    out.t[p] = k * T + s
    out.vf[p] = ls[lane].vf
    store_release(out.status, p, STATUS_OK)  # (after its results: another thread may read them now)
    ls[lane].stage = IDLE
    return True


@njit(cache=True)
def final_request(m, st, XS, n, lane, align, cfg, s_phase, zdm_s):
    """The recorded stage of a point: with the variational equations (from the identity) for Lyapunov."""
    T = st.T
    if cfg.lyapunov:  # a new Runner at the current time, with the variational equations
        t0 = st.k * T + st.s
        k0, s0, ks0, ss0 = start_times(t0, T, s_phase, cfg.periodic)
        st.k = k0
        st.s = s0
        st.req_ks = ks0
        st.req_ss = ss0
        for i in range(n):
            for c in range(n):
                XS[n + i * n + c, lane] = 1.0 if i == c else 0.0
        begin_request(m, st, align + cfg.periods, cfg.periods, True, T, zdm_s)
    else:
        begin_request(m, st, cfg.periods, cfg.periods, False, T, zdm_s)
