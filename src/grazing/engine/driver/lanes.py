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
impacts or sticks holds up no other.  Every lane's arithmetic is the scalar
path's: the results are the same numbers, bit for bit.

A point is the protocol of :func:`grazing.sweeps.run.run_point`: the
transient in blocks of ``ADAPTIVE_BLOCK`` periods (stopped early, at the
point of the cycle where it would have ended, once the samples repeat with a
period of at most ``ADAPTIVE_MAX_PERIOD``, when ``adaptive``), then either
``periods`` sampled periods, or (``lyapunov``) ``align + periods`` with the
variational equations from the identity, the Lyapunov sums taken over the
last ``periods``.  ``jobs`` are runs of consecutive points; within a job each
point starts from the previous one's final state (unless ``fresh``, or the
previous point failed), every job from ``x0`` at time 0.
"""

import math

import numpy as np
from numba import njit

from grazing.engine.abi import TC_FREE_LANES, TC_VAR_LANES, call_model
from grazing.engine.driver.calls import tc_free, tc_stick, tc_var
from grazing.engine.driver.events import first_event
from grazing.engine.driver.impacts import apply_impact, chatter_remaining, enter_contact
from grazing.engine.driver.recording import take_samples
from grazing.engine.driver.tangent import discontinuity_map, lyapunov_step
from grazing.engine.polyroots import work_shape
from grazing.engine.records import Kernels
from grazing.engine.stepping import eval_rows, new_table, step_factor, step_size

LANE_ROOT_ROWS, LANE_ROOT_MIN_COLS = work_shape(0)
ADAPTIVE_BLOCK = 32  # (grazing.sweeps.run.ADAPTIVE_BLOCK)
ADAPTIVE_MAX_PERIOD = 16
ADAPTIVE_TOL = 1e-9
LYAPUNOV_ALIGN = 16
VECTOR_MIN_LANES = 3
"""Fewest lanes of a kind for which the lane function is called (else the scalar one, lane by lane)."""

# A lane's stage in its point's protocol.
IDLE, TRANSIENT, EXTRA, FINAL = 0, 1, 2, 3
# Integer state of a lane (columns of ``li``).
(
    L_K,
    L_MODE,
    L_STUCK,
    L_DEFL,
    L_DEFL_STOP,
    L_KS,
    L_ISAMP,
    L_NSAMP,
    L_NKEEP,
    L_REC,
    L_LSTART,
    L_STEPS,
    L_MAXSTEPS,
    L_ZERO,
    L_JAC,
    L_VAR,
    L_KZ,
    L_STATUS,
    L_STAGE,
    L_POINT,
    L_JOBEND,
    L_USED,
    L_BUDGET,
    L_BLOCK,
    L_RKS,
    L_NLI,
) = range(26)
# Float state of a lane (columns of ``lf``).
F_S, F_SS, F_LT0, F_RSS, F_NLF = range(5)


@njit(cache=True)
def repeats_with_period(samples, count, n, tol, max_period):
    """Smallest ``p <= max_period`` with ``samples[:count]`` p-periodic to ``tol`` (as ``detect_period``)."""
    for p in range(1, min(max_period, count // 2) + 1):
        ok = True
        for i in range(count - p):
            for c in range(n):
                if not abs(samples[i + p, c] - samples[i, c]) <= tol:  # (NaN: not periodic)
                    ok = False
                    break
            if not ok:
                break
        if ok:
            return p
    return 0


@njit(cache=True)
def start_times(t0, T, s_phase, periodic):
    """``(k, s, ks, ss)`` of a run starting at ``t0`` sampled at local time ``s_phase`` (as ``Runner``)."""
    if not periodic:
        return 0, t0, 0, t0 + T
    snap = 1e-9 * T
    k0 = math.floor(t0 / T)
    s0 = t0 - k0 * T
    if s0 >= T - snap:
        k0 += 1
        s0 -= T
    ks = k0 if s0 < s_phase - snap else k0 + 1
    return k0, s0, ks, s_phase


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
def begin_request(m, li, lf, xs, lane, periods, keep, use_var, T, zdm_s):
    """Start lane ``lane`` on ``periods`` samples keeping the last ``keep`` (``Runner.advance``)."""
    li[lane, L_NSAMP] = periods
    li[lane, L_NKEEP] = keep
    li[lane, L_ISAMP] = 0
    li[lane, L_REC] = 1 if periods - keep == 0 else 0
    li[lane, L_LSTART] = li[lane, L_REC]
    li[lane, L_STEPS] = 0
    li[lane, L_MAXSTEPS] = 20000 * periods + 100_000
    li[lane, L_ZERO] = 0
    li[lane, L_JAC] = 1
    li[lane, L_VAR] = 1 if use_var else 0
    li[lane, L_DEFL] = 0
    li[lane, L_KS] = li[lane, L_RKS]
    lf[lane, F_SS] = lf[lane, F_RSS]
    k = li[lane, L_K]
    s = lf[lane, F_S]
    lf[lane, F_LT0] = k * T + s
    li[lane, L_KZ] = k if s < zdm_s - 1e-9 * T else k + 1


@njit(cache=True)
def sweep_lanes(
    m,
    lanes,
    jobs,
    fresh,
    periodic,
    x0,
    pvs,
    Ts,
    sphase,
    tcarry,
    zdms,
    transient,
    periods,
    adaptive,
    lyapunov,
    safety,
    chatter_tol,
    zdm_on,
    zdm_a,
    zdm_e,
    zdm_window,
    watch,
    out_samples,
    out_by_stop,
    out_lyap,
    out_used,
    out_x,
    out_t,
    out_ok,
):
    """Compute the sweep points of ``jobs`` on ``lanes`` lanes (see the module); results into ``out_*``.

    Per point ``p``: parameter vector ``pvs[p]``, period ``Ts[p]``, sampling
    phase ``sphase[p]`` (local time), start time of a point continued from
    the previous one ``tcarry[p]`` (periodic models), local time of the
    discontinuity map ``zdms[p]``.  ``out_ok[p]`` is 0 where the point failed.
    """
    m = Kernels(*m)
    n = m.nx
    order = m.order
    nstops = m.nstops
    K = order + 1
    L = lanes
    ncol = n
    ntot = n + n * ncol
    npv = pvs.shape[1]
    factor = step_factor(safety, order)
    align = min(LYAPUNOV_ALIGN, transient) if lyapunov else 0
    budget = transient - align
    keep_max = max(periods, ADAPTIVE_BLOCK)
    use_lanes = L > 1 and m.fns[TC_FREE_LANES] != 0

    li = np.zeros((L, L_NLI), dtype=np.int64)
    lf = np.zeros((L, F_NLF))
    xs = np.zeros((L, ntot))
    Xs = np.zeros((ntot, K))  # one lane's coefficients from a scalar function
    Os = np.zeros((nstops, K))
    pl = np.zeros((L, npv))
    logs = np.zeros((L, n))
    buf = np.zeros((L, keep_max, n))
    counts = np.zeros((L, nstops), dtype=np.int64)
    XI = np.zeros((ntot, L))
    SI = np.zeros(L)
    PT = np.zeros((npv, L))
    XT = np.zeros((ntot, K, L))
    OT = np.zeros((nstops, K, L))
    work = np.zeros((LANE_ROOT_ROWS, max(K, LANE_ROOT_MIN_COLS)))
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
    kinds = np.zeros(L, dtype=np.int64)  # 0 sticking or idle, 1 free flight, 2 with the variational equations

    next_job = 0
    active = 0
    for lane in range(L):
        li[lane, L_STAGE] = IDLE
    while True:
        # Idle lanes take the next point: their job's next one, else the next job's first.
        for lane in range(L):
            while li[lane, L_STAGE] == IDLE:
                p = li[lane, L_POINT] + 1
                carried = li[lane, L_STATUS] == 0 and li[lane, L_JOBEND] > 0
                if li[lane, L_JOBEND] == 0 or p >= li[lane, L_JOBEND]:
                    if next_job >= jobs.shape[0]:
                        break
                    p = jobs[next_job, 0]
                    li[lane, L_JOBEND] = jobs[next_job, 1]
                    next_job += 1
                    carried = False
                li[lane, L_POINT] = p
                T = Ts[p]
                if fresh or not carried:
                    for i in range(n):
                        xs[lane, i] = x0[i]
                    t0 = 0.0
                else:
                    t0 = tcarry[p] if periodic else out_t[p - 1]
                k0, s0, ks0, ss0 = start_times(t0, T, sphase[p], periodic)
                li[lane, L_K] = k0
                lf[lane, F_S] = s0
                li[lane, L_RKS] = ks0
                lf[lane, F_RSS] = ss0
                li[lane, L_MODE] = 0
                li[lane, L_STUCK] = 0
                li[lane, L_STATUS] = 0
                li[lane, L_USED] = 0
                for j in range(npv):
                    pl[lane, j] = pvs[p, j]
                    PT[j, lane] = pvs[p, j]
                for j in range(nstops):
                    counts[lane, j] = 0
                for j in range(n):
                    logs[lane, j] = 0.0
                if budget > 0:
                    blk = min(ADAPTIVE_BLOCK, budget)
                    li[lane, L_BLOCK] = blk
                    li[lane, L_STAGE] = TRANSIENT
                    begin_request(m, li, lf, xs, lane, blk, blk if adaptive else 0, False, T, zdms[p])
                else:
                    li[lane, L_STAGE] = FINAL
                    final_request(
                        m, li, lf, xs, lane, align, periods, lyapunov, T, sphase[p], periodic, zdms[p]
                    )
                active += 1
        if active == 0:
            break

        # The Taylor coefficients: lanes in free flight by kind, on vectors where there are enough of them.
        nfree = 0
        nvar = 0
        for lane in range(L):
            kinds[lane] = 0
            if li[lane, L_STAGE] != IDLE and li[lane, L_MODE] == 0:
                if li[lane, L_VAR] == 1:
                    kinds[lane] = 2
                    nvar += 1
                else:
                    kinds[lane] = 1
                    nfree += 1
        for kind in (1, 2):
            count = nfree if kind == 1 else nvar
            rows = n if kind == 1 else ntot
            if count == 0:
                continue
            if use_lanes and count >= VECTOR_MIN_LANES:
                for lane in range(L):
                    SI[lane] = lf[lane, F_S]
                    for i in range(rows):
                        XI[i, lane] = xs[lane, i]
                call_model(m.fns[TC_FREE_LANES if kind == 1 else TC_VAR_LANES], XI, 0.0, PT, XT, OT, SI, 0)
            else:  # lane by lane, into the lanes' columns
                for lane in range(L):
                    if kinds[lane] == kind:
                        if kind == 1:
                            tc_free(m, xs[lane], lf[lane, F_S], pl[lane], Xs, Os)
                        else:
                            tc_var(m, xs[lane], lf[lane, F_S], pl[lane], Xs, Os)
                        to_lane(Xs, Os, rows, nstops, K, XT, OT, lane)

        # One step of every lane (the step of the loop's integrate, for a sweep's settings).
        for lane in range(L):
            if li[lane, L_STAGE] == IDLE:
                continue
            p = li[lane, L_POINT]
            T = Ts[p]
            x = xs[lane]
            X = XT[:, :, lane]
            O = OT[:, :, lane]
            pv = pl[lane]
            k = li[lane, L_K]
            s = lf[lane, F_S]
            mode = li[lane, L_MODE]
            stuck = li[lane, L_STUCK]
            use_var = li[lane, L_VAR] == 1
            n_samples = li[lane, L_NSAMP]
            n_keep = li[lane, L_NKEEP]
            keep_from = n_samples - n_keep
            isamp = li[lane, L_ISAMP]
            ks = li[lane, L_KS]
            ss = lf[lane, F_SS]
            recording = li[lane, L_REC] == 1
            defl = li[lane, L_DEFL]
            defl_stop = li[lane, L_DEFL_STOP]
            nrows = ntot if (mode == 0 and use_var) else n
            status = 0
            if li[lane, L_STEPS] >= li[lane, L_MAXSTEPS]:
                status = 1
            for i in range(n):
                if not math.isfinite(x[i]):
                    status = 2
            if status == 0:
                if mode == 1:
                    tc_stick(m, x, s, pv, Xs, Os, stuck)
                    to_lane(Xs, Os, n, nstops, K, XT, OT, lane)
                    h = step_size(X, n, O, nstops, stuck, order, T, factor)
                else:
                    h = step_size(X, nrows, O, nstops, 0, order, T, factor)
                rem = (ks - k) * T + (ss - s)
                is_last = False
                if isamp == n_samples - 1 and h >= rem:
                    h = rem
                    is_last = True
                zdm_hit = False
                kz = li[lane, L_KZ]
                sz = zdms[p]
                if zdm_on:
                    rem_z = (kz - k) * T + (sz - s)
                    if rem_z <= h:
                        h = rem_z
                        zdm_hit = True
                        is_last = is_last and rem_z >= rem
                u, ev_stop = first_event(
                    m,
                    O,
                    h,
                    mode,
                    stuck,
                    True,
                    watch if zdm_on else -1,
                    defl,
                    defl_stop,
                    False,
                    watch,
                    a,
                    work,
                )
                event = u >= 0.0 and h > 0.0
                if event and u == 0.0:
                    li[lane, L_ZERO] += 1
                    if li[lane, L_ZERO] > 3:
                        status = 3
                else:
                    li[lane, L_ZERO] = 0
            if status == 0:
                h_acc = u * h if event else h
                if event and is_last and u >= 1.0:
                    event = False
                if (ks - k) * T + (ss - s) <= h_acc:
                    isamp, ks, ss, recording, _, _, _, _ = take_samples(
                        m,
                        T,
                        periodic,
                        n_samples,
                        n_keep,
                        0.0,
                        X,
                        k,
                        s,
                        h_acc,
                        event,
                        is_last,
                        mode,
                        isamp,
                        ks,
                        ss,
                        keep_from,
                        recording,
                        buf[lane],
                        sticks,
                        0,
                        traj,
                        0,
                        k,
                        s,
                        xe,
                    )
                eval_rows(X, nrows, order, h_acc, xe)
                for i in range(nrows):
                    x[i] = xe[i]
                s += h_acc
                if periodic and s >= T:
                    s -= T
                    k += 1
                li[lane, L_STEPS] += 1
                defl = 0
                if lyapunov and use_var and mode == 0:
                    started, lt0 = lyapunov_step(
                        m,
                        x,
                        V,
                        ncol,
                        recording,
                        li[lane, L_LSTART] == 1,
                        lf[lane, F_LT0],
                        k * T + s,
                        scratch,
                        logs[lane],
                    )
                    li[lane, L_LSTART] = 1 if started else 0
                    lf[lane, F_LT0] = lt0
                if zdm_hit:
                    li[lane, L_KZ] = kz + 1
                    applied, _ = discontinuity_map(
                        m,
                        x,
                        s,
                        k * T + s,
                        pv,
                        watch,
                        zdm_a,
                        zdm_e,
                        zdm_window,
                        use_var,
                        ncol,
                        V,
                        gh,
                        gv,
                        False,
                        imp,
                        0,
                    )
                    if applied and recording and li[lane, L_STAGE] == FINAL:
                        counts[lane, watch] += 1
                if event:
                    if mode == 1 and ev_stop == stuck:
                        mode = 0
                        defl = 3
                        defl_stop = stuck
                    else:
                        mode = 0
                        speed, _, _, salt_ok = apply_impact(
                            m,
                            x,
                            xp,
                            s,
                            k * T + s,
                            pv,
                            ev_stop,
                            use_var,
                            ncol,
                            nrows,
                            V,
                            False,
                            imp,
                            0,
                            False,
                            traj,
                            0,
                        )
                        if not salt_ok:
                            li[lane, L_JAC] = 0
                        if recording and li[lane, L_STAGE] == FINAL:
                            counts[lane, ev_stop] += 1
                        defl = 1
                        defl_stop = ev_stop
                        if m.sticks[ev_stop]:
                            dt_acc = chatter_remaining(m, x, s, pv, ev_stop, speed, chatter_tol * T)
                            if dt_acc >= 0.0:
                                s += dt_acc
                                if periodic and s >= T:
                                    s -= T
                                    k += 1
                                enter_contact(m, x, s, pv, ev_stop)
                                mode = 1
                                stuck = ev_stop
                                defl = 0
                                li[lane, L_JAC] = 0
            li[lane, L_K] = k
            lf[lane, F_S] = s
            li[lane, L_MODE] = mode
            li[lane, L_STUCK] = stuck
            li[lane, L_ISAMP] = isamp
            li[lane, L_KS] = ks
            lf[lane, F_SS] = ss
            li[lane, L_REC] = 1 if recording else 0
            li[lane, L_DEFL] = defl
            li[lane, L_DEFL_STOP] = defl_stop
            if status != 0:  # the point failed: the next point starts afresh
                out_ok[p] = 0
                li[lane, L_STATUS] = status
                li[lane, L_STAGE] = IDLE
                active -= 1
                continue
            if isamp < n_samples:
                continue
            # The request is done (Runner.advance returns): on to the next stage of the point.
            if periodic:
                li[lane, L_RKS] += n_samples
            else:
                lf[lane, F_RSS] += n_samples * T
            stage = li[lane, L_STAGE]
            if stage == TRANSIENT:
                blk = li[lane, L_BLOCK]
                li[lane, L_USED] += blk
                used = li[lane, L_USED]
                nxt = -1
                if adaptive and blk == ADAPTIVE_BLOCK:
                    per = repeats_with_period(buf[lane], blk, n, ADAPTIVE_TOL, ADAPTIVE_MAX_PERIOD)
                    if per > 0:
                        extra = (budget - used) % per
                        if extra:
                            li[lane, L_USED] += extra
                            li[lane, L_STAGE] = EXTRA
                            begin_request(m, li, lf, xs, lane, extra, 0, False, T, zdms[p])
                            continue
                        nxt = 0
                if nxt < 0 and used < budget:
                    blk = min(ADAPTIVE_BLOCK, budget - used)
                    li[lane, L_BLOCK] = blk
                    begin_request(m, li, lf, xs, lane, blk, blk if adaptive else 0, False, T, zdms[p])
                    continue
                li[lane, L_STAGE] = FINAL
                final_request(m, li, lf, xs, lane, align, periods, lyapunov, T, sphase[p], periodic, zdms[p])
                continue
            if stage == EXTRA:
                li[lane, L_STAGE] = FINAL
                final_request(m, li, lf, xs, lane, align, periods, lyapunov, T, sphase[p], periodic, zdms[p])
                continue
            # FINAL: the point's results.
            for r in range(periods):
                for c in range(n):
                    out_samples[p, r, c] = buf[lane, r, c]
            for j in range(nstops):
                out_by_stop[p, j] = counts[lane, j]
            lyap = math.nan
            if lyapunov:
                span = k * T + s - lf[lane, F_LT0] if li[lane, L_LSTART] == 1 else 0.0
                if li[lane, L_JAC] == 1 and span != 0.0:
                    lyap = logs[lane, 0] / span
                    for j in range(1, n):
                        v = logs[lane, j] / span
                        if math.isnan(lyap) or math.isnan(v):
                            lyap = math.nan
                        elif v > lyap:
                            lyap = v
            out_lyap[p] = lyap
            out_used[p] = li[lane, L_USED] + align
            for i in range(n):
                out_x[p, i] = x[i]
            out_t[p] = k * T + s
            out_ok[p] = 1
            li[lane, L_STAGE] = IDLE
            active -= 1


@njit(cache=True)
def final_request(m, li, lf, xs, lane, align, periods, lyapunov, T, s_phase, periodic, zdm_s):
    """The recorded stage of a point: with the variational equations (from the identity) for Lyapunov."""
    if lyapunov:  # a new Runner at the current time (as run_point's ``var``)
        n = m.nx
        t0 = li[lane, L_K] * T + lf[lane, F_S]
        k0, s0, ks0, ss0 = start_times(t0, T, s_phase, periodic)
        li[lane, L_K] = k0
        lf[lane, F_S] = s0
        li[lane, L_RKS] = ks0
        lf[lane, F_RSS] = ss0
        for i in range(n):
            for c in range(n):
                xs[lane, n + i * n + c] = 1.0 if i == c else 0.0
        begin_request(m, li, lf, xs, lane, align + periods, periods, True, T, zdm_s)
    else:
        begin_request(m, li, lf, xs, lane, periods, periods, False, T, zdm_s)
