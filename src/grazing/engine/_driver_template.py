"""Hybrid integration driver, appended to every generated model module.

This file is not imported on its own: :mod:`grazing.engine.compile` appends its
text to the module generated for a model, where the model functions it calls
(``tc_free``, ``tc_var``, ``tc_stick``, ``rhs``, ``guard``, ``reset`` ...) and
the constants ``NX``, ``NSENS``, ``ORDER`` (degree of the Taylor polynomials)
and ``HAS_STICK`` are defined.  Keeping the driver in the same module as the model
functions lets numba resolve them as globals and cache the compiled result on
disk.  What does not depend on the model is in :mod:`grazing.engine.stepping`
(and :mod:`grazing.engine.polyroots`), compiled once per machine.

Time is kept as ``k * T + s`` with ``s`` in [0, T) for models whose vector
field is T-periodic in time (``wrap``), so that the forcing phase does not lose
precision over long runs.

Status codes: 0 ok, 1 step limit, 2 non-finite state, 3 impacts accumulate but
the model has no sticking rule (or a zero-time event loop).
"""

STATUS_OK = 0
STATUS_STEP_LIMIT = 1
STATUS_NONFINITE = 2
STATUS_ZENO = 3


@njit(cache=True)
def _saltation(xm, xp, s, pv, V, ncol):
    """Apply the saltation matrix (paper eq. 14, with time and parameter terms) to V."""
    n = NX
    fm = np.empty(n)
    fp = np.empty(n)
    rhs(xm, s, pv, fm)
    rhs(xp, s, pv, fp)
    Gx = np.zeros((n, n))
    Gt = np.zeros(n)
    Gp = np.zeros((n, max(NSENS, 1)))
    reset_jac(xm, s, pv, Gx, Gt, Gp)
    hx = np.zeros(n)
    hp = np.zeros(max(NSENS, 1))
    ht = guard_grad(xm, s, pv, hx)
    guard_pgrad(xm, s, pv, hp)
    den = ht
    for i in range(n):
        den += hx[i] * fm[i]
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


@njit(cache=True)
def _shift_period(x, s, pv, Tp, ncol, f):
    """Parameter columns of V at a period boundary: ``V_p += f(x, s) dT/dp``.

    Time is kept as ``k T + s``; the variational equations give derivatives at
    fixed ``(k, s)``.  Relabelling ``(k, s)`` as ``(k + 1, s - T)`` keeps the
    time only at the current parameter values: where ``T`` depends on a
    parameter the two labels are different instants, ``dT/dp`` apart per
    period, and the state moves by ``f dT/dp`` between them.
    """
    rhs(x, s, pv, f)
    for i in range(NX):
        for c in range(NSENS):
            x[NX + i * ncol + NX + c] += f[i] * Tp[c]


@njit(cache=True)
def _enter_contact(x, s, pv):
    """Project x onto the contact manifold {h = 0, L_f h = 0}."""
    n = NX
    gx = np.zeros(n)
    for _ in range(3):
        hval = guard(x, s, pv)
        guard_grad(x, s, pv, gx)
        nn = 0.0
        for i in range(n):
            nn += gx[i] * gx[i]
        if nn == 0.0 or hval == 0.0:
            break
        for i in range(n):
            x[i] -= hval * gx[i] / nn
    e = np.zeros(n)
    contact_dir(x, s, pv, e)
    gr = np.zeros(n)
    for _ in range(3):
        vn = normal_rate(x, s, pv)
        normal_rate_grad(x, s, pv, gr)
        d = 0.0
        for i in range(n):
            d += gr[i] * e[i]
        if d == 0.0 or vn == 0.0:
            break
        for i in range(n):
            x[i] -= vn / d * e[i]


@njit(cache=True)
def integrate(
    x_init,
    V_init,
    k0,
    s0,
    mode0,
    pv,
    T,
    wrap,
    max_step,
    safety,
    max_steps,
    n_samples,
    ks,
    ss,
    n_keep,
    use_var,
    lyap,
    traj_dt,
    track_min,
    record_impacts,
    chatter_time,
    events,
    zdm,
    zdm_s,
    zdm_a,
    zdm_e,
    zdm_window,
    Tp,
    touch_start,
    touch_end,
):
    """Integrate until the ``n_samples``-th stroboscopic sample.

    Samples are taken at local times ``(ks, ss)``, ``(ks + 1, ss)``, ... (or
    ``ss``, ``ss + T``, ... without wrapping); the last ``n_keep`` are stored
    and define the recorded span (impacts, trajectory, minimum of the guard,
    Lyapunov sums).  ``mode0`` is 0 in free flight, 1 when sticking to the
    stop; the final mode is returned so that a run can be continued.  With
    ``events`` false the guard is ignored (the "virtual" flow through the stop),
    which is how nonimpacting orbits are continued past grazing.

    With ``zdm`` the flow ignores the stop and, once per period at local time
    ``zdm_s`` (the grazing phase), the state is corrected by Nordmark's
    zero-time discontinuity map at leading order: with ``v = L_f h``,
    ``delta = v^2 / (2 a) - h`` (how far the local parabola would reach past the
    stop, ``a = zdm_a = L_f^2 h`` at the grazing point), if ``delta > 0`` and
    ``|v| / a < zdm_window``: ``x <- x - zdm_e * sqrt(2 a delta)``.

    ``Tp`` holds ``dT/dp`` for the sensitivity parameters: the parameter
    columns of the variational matrix are derivatives at fixed ``(k, s)``, the
    instant ``k T(p) + s`` (see :func:`_shift_period`).

    ``touch_start`` / ``touch_end``: the run starts / ends in tangential contact
    with the stop (a grazing point: ``h = 0``, ``L_f h = 0``); that double root
    of the guard is divided out of the event polynomial of the first / last
    step, so the contact is not taken for an impact.

    With ``track_min`` the recorded span's smallest guard value is returned
    (``min_info[:2 + n]``: value, time, state) and so is its closest approach
    *away from contacts* (``min_info[2 + n:]``): the smallest local minimum of
    the guard in free flight, where ``L_f h`` changes sign from negative to
    positive.  An impacting orbit touches the stop (its guard minimum is 0);
    its closest approach tells how near it is to gaining an impact.
    """
    n = NX
    order = ORDER
    factor = step_factor(safety, order)
    ncol = n + NSENS
    nv = n * ncol if use_var else 0
    ntot = n + nv
    x = np.empty(ntot)
    for i in range(n):
        x[i] = x_init[i]
    if use_var:
        for i in range(n):
            for c in range(ncol):
                x[n + i * ncol + c] = V_init[i, c]
    X = np.zeros((ntot, order + 1))
    O = np.zeros((1, order + 1))
    work = np.zeros((ROOT_WORK_ROWS, max(order + 1, ROOT_WORK_MIN_COLS)))
    a = np.zeros(order + 1)
    gm = np.zeros(order + 1)
    xe = np.empty(ntot)
    xp = np.empty(ntot)
    V = np.empty((n, ncol))

    samples = np.empty((n_keep, n))
    imp = new_table(16, 2 + n)
    sticks = new_table(4, 2)
    traj = new_table(64 if traj_dt > 0.0 else 1, 1 + n)
    logs = np.zeros(n)
    scratch = np.zeros(n)
    min_info = np.full(2 * (2 + n), math.inf)
    slope_end = math.nan  # d guard / dt at the end of the previous free-flight step
    slope_first = math.nan  # ... at the start of the first recorded one
    fbuf = np.empty(n)
    shift_sens = use_var and NSENS > 0 and wrap

    k = k0
    s = s0
    mode = mode0
    defl = 2 if touch_start else 0
    isamp = 0
    keep_from = n_samples - n_keep
    recording = keep_from == 0
    lyap_t0 = k * T + s
    lyap_started = recording
    n_imp = 0
    n_imp_rec = 0
    n_stick = 0
    n_traj = 0
    kt = k
    st = s
    kz = k if s < zdm_s - 1e-9 * T else k + 1
    sz = zdm_s
    zdm_gh = np.zeros(n)
    zdm_gv = np.zeros(n)
    status = STATUS_OK
    nsteps = 0
    zero_events = 0
    jac_valid = True
    if recording and traj_dt > 0.0:
        append_row(traj, 0, k * T + s, x, n)
        n_traj = 1
        st += traj_dt
        while wrap and st >= T:
            st -= T
            kt += 1
    if recording and mode == 1:  # the recorded span starts while sticking
        append_pair(sticks, n_stick, k * T + s, math.nan)
        n_stick += 1

    while True:
        if nsteps >= max_steps:
            status = STATUS_STEP_LIMIT
            break
        for i in range(n):
            if not math.isfinite(x[i]):
                status = STATUS_NONFINITE
                break
        if status != STATUS_OK:
            break
        if mode == 0:
            if use_var:
                tc_var(x, s, pv, X, O)
            else:
                tc_free(x, s, pv, X, O)
            h = step_size(X, ntot, O, order, max_step, factor)
        else:
            tc_stick(x, s, pv, X, O)  # the first n rows only
            h = step_size(X, n, O, order, max_step, factor)
        rem = (ks - k) * T + (ss - s)
        is_last = False
        if isamp == n_samples - 1 and h >= rem:
            h = rem
            is_last = True
        zdm_hit = False
        if zdm:
            rem_z = (kz - k) * T + (sz - s)
            if rem_z <= h:
                h = rem_z
                zdm_hit = True
                is_last = is_last and rem_z >= rem

        # Event polynomial in the normalised step time u in [0, 1].
        sign = 1.0 if mode == 0 else -1.0
        hk = 1.0
        for j in range(order + 1):
            a[j] = sign * O[0, j] * hk
            hk *= h
        d = defl
        if mode == 0 and d == 0 and a[0] <= 0.0 and order >= 1 and a[1] > 0.0:
            d = 1  # on the surface (to rounding) and leaving it: not an impact
        for j in range(d):
            a[j] = 0.0
        while 0 < d < 3 and a[d] == 0.0:
            d += 1
        if d > 0:  # divide by u^d (a fresh reset or release: the root at u = 0 is known)
            for j in range(order + 1 - d):
                a[j] = a[j + d]
        deg = order - d
        if touch_end and is_last and mode == 0:
            deg = divide_double_root_at_one(a, deg)  # the final tangential contact at u = 1
        u = -1.0
        if events or mode == 1:
            # first_root, with its certificate on scalars (no array call): most steps stop here.
            tail = 0.0
            for j in range(3, deg + 1):
                tail += abs(a[j])
            if a[0] <= 0.0:
                u = 0.0
            elif quadratic_bound(a[0], a[1], a[2], tail) <= 0.0:
                u = isolate_first_root(a, deg, work)
        event = u >= 0.0 and h > 0.0
        if event and u == 0.0:
            zero_events += 1
            if zero_events > 3:
                status = STATUS_ZENO
                break
        else:
            zero_events = 0
        h_acc = u * h if event else h
        if event and is_last and u >= 1.0:
            event = False
        nrows = ntot if mode == 0 else n

        # Samples and trajectory points within (0, h_acc].
        while isamp < n_samples:
            dt = (ks - k) * T + (ss - s)
            if dt > h_acc or (event and dt == h_acc and not is_last):
                break
            if is_last and isamp == n_samples - 1:
                dt = h_acc
            if isamp >= keep_from:
                eval_rows(X, n, order, dt, xe)
                set_row(samples, isamp - keep_from, 0, xe, n)
            isamp += 1
            if wrap:
                ks += 1
            else:
                ss += T
            if isamp == keep_from and not recording and n_keep > 0:
                recording = True
                if mode == 1:  # recording starts while sticking: the interval starts here
                    append_pair(sticks, n_stick, k * T + s + dt, math.nan)
                    n_stick += 1
                if traj_dt > 0.0:
                    eval_rows(X, n, order, dt, xe)
                    append_row(traj, n_traj, k * T + s + dt, xe, n)
                    n_traj += 1
                    kt = k
                    st = s + dt + traj_dt
                    while wrap and st >= T:
                        st -= T
                        kt += 1
        if recording and traj_dt > 0.0:
            while True:
                dt = (kt - k) * T + (st - s)
                if dt > h_acc:
                    break
                eval_rows(X, n, order, dt, xe)
                append_row(traj, n_traj, k * T + s + dt, xe, n)
                n_traj += 1
                st += traj_dt
                while wrap and st >= T:
                    st -= T
                    kt += 1
        if recording and track_min and mode == 0 and h_acc > 0.0:
            # Minimum of the guard on [0, h_acc): the start point and an
            # interior critical point where its derivative turns positive.
            hk = 1.0
            for j in range(order + 1):
                gm[j] = O[0, j] * hk
                hk *= h
            if gm[0] < min_info[0]:
                min_info[0] = gm[0]
                min_info[1] = k * T + s
                set_slice(min_info, 2, x, n)
            if defl == 0:  # not leaving a contact
                if math.isnan(slope_first):
                    slope_first = gm[1] / h
                elif slope_end < 0.0 <= gm[1] and gm[0] < min_info[2 + n]:
                    min_info[2 + n] = gm[0]  # a local minimum exactly at the step boundary
                    min_info[3 + n] = k * T + s
                    set_slice(min_info, 4 + n, x, n)
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
                if gv < min_info[0] or gv < min_info[2 + n]:
                    eval_rows(X, n, order, um * h, xe)
                for base in (0, 2 + n):
                    if gv < min_info[base]:
                        min_info[base] = gv
                        min_info[base + 1] = k * T + s + um * h
                        set_slice(min_info, base + 2, xe, n)
            if event:
                slope_end = math.nan  # an impact or a release follows: no free-flight minimum here

        # Advance to the end of the accepted part of the step.
        eval_rows(X, nrows, order, h_acc, xe)
        for i in range(nrows):
            x[i] = xe[i]
        s += h_acc
        if wrap and s >= T:
            if shift_sens and mode == 0:
                _shift_period(x, s, pv, Tp, ncol, fbuf)
            s -= T
            k += 1
        nsteps += 1
        defl = 0
        if lyap and use_var and mode == 0:
            unpack_var(x, n, ncol, V)
            if recording and not lyap_started:
                lyap_started = True
                lyap_t0 = k * T + s
                orthonormalize(V, n, scratch)
            elif lyap_started:
                orthonormalize(V, n, logs)
            else:
                orthonormalize(V, n, scratch)  # transient: align V, discard growth
            pack_var(V, n, ncol, x)

        if zdm_hit:
            kz += 1
            hval = guard(x, s, pv)
            vn = normal_rate(x, s, pv)
            dz = vn * vn / (2.0 * zdm_a) - hval
            if dz > 0.0 and abs(vn) < zdm_window * zdm_a:
                sp_ = math.sqrt(2.0 * zdm_a * dz)
                if use_var:
                    # dD/dx = I - e (grad S)^T, grad S = a grad(delta) / S
                    guard_grad(x, s, pv, zdm_gh)
                    normal_rate_grad(x, s, pv, zdm_gv)
                    unpack_var(x, n, ncol, V)
                    for c in range(ncol):
                        gs = 0.0
                        for j in range(n):
                            gs += (vn * zdm_gv[j] - zdm_a * zdm_gh[j]) * V[j, c]
                        gs /= sp_
                        for i in range(n):
                            V[i, c] -= zdm_e[i] * gs
                    pack_var(V, n, ncol, x)
                if record_impacts == 2 or (record_impacts == 1 and recording):
                    append_record(imp, n_imp_rec, k * T + s, sp_, x, n)
                    n_imp_rec += 1
                n_imp += 1
                for i in range(n):
                    x[i] -= zdm_e[i] * sp_

        if event:
            if mode == 0:
                # Impact: x holds the state on the stop, just before the reset.
                vn = normal_rate(x, s, pv)
                reset(x, s, pv, xp)
                if use_var:
                    unpack_var(x, n, ncol, V)
                    _saltation(x, xp, s, pv, V, ncol)
                    pack_var(V, n, ncol, xp)
                if record_impacts == 2 or (record_impacts == 1 and recording):
                    append_record(imp, n_imp_rec, k * T + s, -vn, x, n)
                    n_imp_rec += 1
                if recording and traj_dt > 0.0:
                    append_row(traj, n_traj, k * T + s, x, n)
                    append_row(traj, n_traj + 1, k * T + s, xp, n)
                    n_traj += 2
                n_imp += 1
                for i in range(nrows):
                    x[i] = xp[i]
                defl = 1
                if HAS_STICK:
                    w = normal_rate(x, s, pv)
                    acc = normal_accel(x, s, pv)
                    speed = -vn
                    if acc < 0.0:
                        stick = False
                        dt_acc = 0.0
                        if speed <= 0.0 or w <= 0.0:
                            stick = True
                        else:
                            ratio = w / speed
                            if ratio < 1.0:
                                dt_acc = 2.0 * w / (-acc * (1.0 - ratio))
                                stick = dt_acc < chatter_time
                        if stick:
                            s += dt_acc
                            if wrap and s >= T:  # (the Jacobian is not valid after sticking)
                                s -= T
                                k += 1
                            _enter_contact(x, s, pv)
                            mode = 1
                            defl = 0
                            jac_valid = False
                            if recording:
                                append_pair(sticks, n_stick, k * T + s, math.nan)
                                n_stick += 1
            else:
                # Release from sticking: the contact force changes sign.
                mode = 0
                defl = 3
                if recording and n_stick > 0 and math.isnan(sticks[0][n_stick - 1, 1]):
                    sticks[0][n_stick - 1, 1] = k * T + s
        if isamp >= n_samples:
            break

    if track_min and mode == 0 and recording:
        g_end = guard(x, s, pv)
        if g_end < min_info[0]:
            min_info[0] = g_end
            min_info[1] = k * T + s
            set_slice(min_info, 2, x, n)
        # A run over whole periods of an orbit ends where it started: a minimum there.
        if slope_end < 0.0 <= slope_first and g_end < min_info[2 + n]:
            min_info[2 + n] = g_end
            min_info[3 + n] = k * T + s
            set_slice(min_info, 4 + n, x, n)
    if n_stick > 0 and math.isnan(sticks[0][n_stick - 1, 1]):
        sticks[0][n_stick - 1, 1] = k * T + s
    lyap_span = k * T + s - lyap_t0 if (lyap and lyap_started) else 0.0
    Vout = np.zeros((n, ncol))
    if use_var:
        unpack_var(x, n, ncol, Vout)
    return (
        status,
        x[:n].copy(),
        Vout,
        k,
        s,
        mode,
        nsteps,
        n_imp,
        samples[: max(0, min(n_keep, isamp - keep_from))].copy(),
        table_rows(imp, n_imp_rec),
        table_rows(sticks, n_stick),
        table_rows(traj, n_traj),
        logs,
        lyap_span,
        min_info,
        jac_valid,
    )
