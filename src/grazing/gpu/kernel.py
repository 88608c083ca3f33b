"""The sweep kernel: one CUDA thread per job (a run of points, one point in a fresh sweep).

A thread takes the next job from a counter (as the CPU lanes take theirs) and
computes its points with the CPU lanes' protocol
(:mod:`grazing.engine.driver.lanes`): the transient in blocks of
:data:`~grazing.core.options.ADAPTIVE_BLOCK` periods, stopped once the samples
repeat (``adaptive``), then ``periods`` sampled periods; each point of a job
from the previous one's final state unless ``fresh`` or the previous point
failed.  A step is the CPU's: the model's Taylor coefficients (its generated
``tc_free``), the Jorba-Zou step from their last two terms (``step_size``),
the step cut at the request's last sample, every guard's Taylor polynomial
over the step searched for its certified first root (``event_polynomial``,
the quadratic certificate, then Bernstein subdivision and the check that the
root is the first), samples from the step's polynomials, the state advanced
to the accepted part, and at an event the stop's reset.  The helpers are the
CPU's own code as device functions (:mod:`grazing.gpu.ported`).

Complete chattering is summed to its accumulation point and continued as
sticking, as the CPU does (:func:`~grazing.engine.driver.impacts.at_event`):
steps of the stop's sticking kernel (its generated ``tc_stick``, the contact
force in the stop's event row), each step's end and sample put back on the
contact manifold (``impacts.enter_contact``), until the contact force changes
sign (the release) or another transition fires; no variational equations
while sticking (the Jacobian is marked invalid: a point that sticks in its
recorded span has no Lyapunov exponent).  The discontinuity map (a kernel of
its own, :func:`build_kernel`'s ``zdm_stop``): as the lanes', the stop it
stands for is not searched for events, each step is cut at the map's phase
too (``step.cut_step``), and there the map kicks the state
(``tangent.map_kick``) and, with Lyapunov exponents, the tangent vectors
(``tangent.kick_tangent``), a kick counted as an impact on that stop while the
point records.  After an impact within a mode (on any model) the state must
be inside the mode's region too (else ``OUTSIDE_MODE``: a reset beyond a
stop), and the root of the stop's guard at the next step's start is divided
out only where the reset leaves the state on that guard
(``transitions.roots_after_reset``, as the CPU).  A model with
modes: each thread carries its point's mode (its kernels, its event rows:
the transitions out of it); a switch without a reset changes the mode
(``impacts.switch_mode``), a reset may too (``impacts.change_mode``), each
followed by the CPU's test that the state is inside the new mode's region
(``impacts.check_region``: else the point's status is ``OUTSIDE_MODE``; so
after a reset within a mode and an exit from sliding); a crossing where the
far side's field pushes back enters Filippov's sliding pseudo-mode
(``impacts.enter_sliding``), kept on its surface at each step's end and
sample, left by its virtual exits (``impacts.leave_sliding``).  What these
do with the model's values (the mode after the transition, the region test,
the projection onto a guard, the saltation matrix) is the CPU's own code too
(:mod:`grazing.engine.driver.transitions`).
Lyapunov exponents are a kernel of their own (:func:`build_kernel`'s
``lyapunov``: the variational equations, their Gram-Schmidt after each step
and the saltation matrix at each impact, switch and entry into sliding,
:mod:`grazing.gpu.tangent`).

Each thread's arrays are local (sized by the model: constants of the
compiled kernel; with Lyapunov exponents :func:`tangent_bytes` more) except
the root search's work array, one slice per thread of a global array the
caller allocates; nothing is allocated in a kernel.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import cuda  # (the simulator's, where NUMBA_ENABLE_CUDASIM=1: a global, which it swaps in kernels)

from grazing.core.options import ADAPTIVE_BLOCK, ADAPTIVE_MAX_PERIOD
from grazing.core.solution import Status
from grazing.engine.driver.step import STEP_LAST
from grazing.engine.driver.transitions import ENTER_SLIDING, LEAVE_SLIDING, SWITCH
from grazing.engine.polyroots import work_shape
from grazing.engine.stepping import GUARD_SCALE

# The run state of a thread: integer fields of ``st``, float fields of ``sf`` (lanes' RUN_STATE names).
K, KS, ISAMP, N_SAMPLES, N_KEEP, RECORDING, STEPS, MAX_STEPS, ZERO_EVENTS, DEFL, DEFL_STOP = range(11)
STAGE, BLOCK, USED, REQ_KS, USE_VAR, LYAP_STARTED, JAC_VALID, VF, SURFACE = 11, 12, 13, 14, 15, 16, 17, 18, 19
STICKING, STUCK = 20, 21  # (the lanes' mode 1 and stuck: sticking to stop STUCK)
INT_FIELDS = 22
S, SS, REQ_SS, SPAN_DT, LYAP_T0 = range(5)
FLOAT_FIELDS = 5
KZ = INT_FIELDS  # the period of the discontinuity map's next kick (the lanes' ``kz``) ...
INT_FIELDS += 1
ZDM_S = FLOAT_FIELDS  # ... and its local time (the point's)
FLOAT_FIELDS += 1
TRANSIENT, EXTRA, FINAL = 1, 2, 3
"""A point's stages (as the lanes')."""

# The settings arrays: integers, floats.
FRESH, PERIODIC, TRANSIENT_PERIODS, PERIODS, ADAPTIVE, ALIGN = range(6)
ADAPTIVE_TOL, FACTOR, CHATTER_TOL = range(3)
ZDM_A, ZDM_WINDOW, ZDM_E = range(3)
"""The discontinuity map's settings array: ``L_f^2 h`` at the grazing point, the window, from ``ZDM_E`` on
its direction ``e`` (the lanes' ``zdm_a``, ``zdm_window``, ``zdm_e``)."""

STATUS_OK = int(Status.OK)
STATUS_STEP_LIMIT = int(Status.STEP_LIMIT)
STATUS_NONFINITE = int(Status.NONFINITE)
STATUS_ZENO = int(Status.ZENO)
STATUS_OUTSIDE_MODE = int(Status.OUTSIDE_MODE)

ROOT_WORK = work_shape(0)
"""The shape of one thread's work array of the root search."""


def keep_rows(periods: int) -> int:
    """Rows of a thread's sample buffer: the sampled periods, or an adaptive block (as the lanes')."""
    return max(int(periods), ADAPTIVE_BLOCK)


def tangent_bytes(nx: int, order: int) -> int:
    """Bytes of local memory a thread's variational arrays add to the kernel with Lyapunov exponents.

    The state's arrays (``x``, ``xe``, ``xp``: ``n`` to ``n + n^2`` doubles) and its Taylor coefficients
    (``n + n^2`` rows of ``order + 1``), the matrices ``V``, ``Vn``, ``Gx`` (``n x n``) and ``Gp``
    (``n x 1``), the vectors ``logs``, ``scratch``, ``before``, ``fm``, ``fp``, ``Gt``, ``hx``, ``w``,
    ``hv`` (``n`` each).

    Examples
    --------
    >>> tangent_bytes(2, 13)  # (the pendulum at tol 1e-10: Taylor order 13)
    800
    """
    nn = nx * nx
    return 8 * (3 * nn + nn * (order + 1) + 3 * nn + nx + 9 * nx)


_kernels: dict[tuple[str, int, int, bool, int], Any] = {}


def sweep_kernel(definition: Any, order: int, keep: int, lyapunov: bool = False, zdm_stop: int = -1) -> Any:
    """The kernel of a model definition at Taylor ``order`` with ``keep`` sample rows, built once;
    ``lyapunov``: with the variational equations, ``zdm_stop``: with the discontinuity map standing for
    that stop's impacts (:func:`build_kernel`)."""
    from grazing.gpu.model import model_functions

    key = (definition.identity(), int(order), int(keep), bool(lyapunov), int(zdm_stop))
    if key not in _kernels:
        _kernels[key] = build_kernel(model_functions(definition, order), keep, lyapunov, zdm_stop)
    return _kernels[key]


def build_kernel(dm: Any, keep: int, lyapunov: bool = False, zdm_stop: int = -1) -> Any:
    """The sweep kernel of the device model ``dm`` (:class:`~grazing.gpu.model.DeviceModel`).

    ``kernel[blocks, threads](jobs, control, x0, firsts, first_vf, x0_vf, pvs, Ts, sphase,
    tcarry, samples, by_stop, lyap, used, x_final, t_final, vf_final, status, work, iset,
    fset, zdms, zset)``: the arrays of :class:`~grazing.engine.records.LaneJobs`,
    :class:`~grazing.engine.records.LanePoints` and
    :class:`~grazing.engine.records.LaneResults` (``control[0]`` the next job,
    0 at the start), ``work`` the root search's arrays (one per thread),
    ``iset`` and ``fset`` the settings (the module's ``FRESH ...`` and
    ``ADAPTIVE_TOL ...`` positions; ``iset[TRANSIENT_PERIODS]`` the transient
    less the Lyapunov alignment ``iset[ALIGN]``), ``lyap`` the largest
    Lyapunov exponents.  With ``lyapunov`` (the lanes' ``final_request``) the
    recorded stage starts a new run with the variational equations from the
    identity (``tc_var``: the state's rows then the matrix's, row by row), its
    first ``iset[ALIGN]`` periods aligning the tangent vectors; each step
    ends with their Gram-Schmidt (:mod:`grazing.gpu.tangent`), each impact
    multiplies them by the saltation matrix; ``tangent_bytes`` more local
    memory per thread.  Without it the kernel has no variational arrays.
    With ``zdm_stop`` (-1: none) the discontinuity map stands for the
    impacts on that stop (the lanes' ``cfg.zdm``, see the module): ``zdms``
    its local time per point (:class:`~grazing.engine.records.LanePoints`'),
    ``zset`` its settings (the module's ``ZDM_A ...`` positions); without it
    the kernel has no map and reads neither.
    """
    from grazing.gpu.ported import device_helpers

    dj = cuda.jit(device=True)
    helpers = device_helpers()
    step_size = helpers["step_size"]
    event_polynomial = helpers["event_polynomial"]
    event_certificate = helpers["event_certificate"]
    isolate_first_root = helpers["isolate_first_root"]
    confirm_first_root = helpers["confirm_first_root"]
    eval_rows = helpers["eval_rows"]
    repeats_with_period = helpers["repeats_with_period"]
    step_limit = helpers["step_limit"]
    start_times = helpers["start_times"]
    unpack_var = helpers["unpack_var"]
    pack_var = helpers["pack_var"]
    map_period = helpers["map_period"]
    cut_step = helpers["cut_step"]
    map_reached = helpers["map_reached"]
    map_kick = helpers["map_kick"]
    kick_tangent = helpers["kick_tangent"]
    chatter_time_left = helpers["chatter_time_left"]
    along_contact_dir = helpers["along_contact_dir"]
    mode_after, outside_region, onto_zero_step, roots_after_reset = (
        helpers[k] for k in ("mode_after", "outside_region", "onto_zero_step", "roots_after_reset")
    )
    tc_free = dm.functions["mode_tc_free"]
    tc_var = dm.functions["mode_tc_var"]
    tc_stick = dm.functions["tc_stick"]  # (by the stop's index)
    contact_dir = dm.functions["contact_dir"]
    normal_rate_grad = dm.functions["normal_rate_grad"]
    reset = dm.functions["reset"]
    guard = dm.functions["guard"]
    guard_grad = dm.functions["guard_grad"]
    normal_rate = dm.functions["normal_rate"]
    normal_accel = dm.functions["normal_accel"]
    NX, NSTOPS, ORDER = dm.nx, dm.nstops, dm.order
    ROWS = np.array(dm.rows, dtype=np.int64)  # (a mode's event rows: its transitions; -1 padding)
    NEV = ROWS.shape[1]
    TARGETS = np.array(dm.targets, dtype=np.int64)
    RESETS = np.array(dm.resets, dtype=np.int64)
    BACK = np.array(dm.back, dtype=np.int64)
    SLIDE_ENTRY = np.array(dm.slide_entry, dtype=np.int64)
    KC = ORDER + 1
    LYAP = bool(lyapunov)
    NT = NX + NX * NX if LYAP else NX  # (rows of the state with the variational matrix)
    NV = NX if LYAP else 1  # (sides of the tangent arrays: one element without Lyapunov exponents)
    from grazing.gpu.tangent import LYAP_STARTED_NOW_AT_END, tangent_functions

    lyapunov_step, saltation = tangent_functions(dm)  # (without LYAP, in branches pruned at compilation)
    KEEP = int(keep)
    STICKS = np.array(dm.sticks, dtype=np.int64)
    ZSTOP = int(zdm_stop)
    ZDM = ZSTOP >= 0
    from numba import types

    float64, int64 = types.float64, types.int64

    @dj
    def first_event(O, h, vf, defl, defl_stop, sticking, stuck, a, work):
        """The first event on the step over mode ``vf``'s transitions: ``(u, stop)``, ``u < 0`` none
        (``events.first_event`` with every event watched, nothing skipped; ``sticking`` to stop ``stuck``:
        its row is the contact force)."""
        u = -1.0
        stop = 0
        for row in range(NEV):
            r = ROWS[vf, row]  # the row's stop (transition); -1: padding
            if r < 0 or r == ZSTOP:  # (the discontinuity map's stop: not searched)
                continue
            force = sticking and r == stuck
            defl_r = defl if r == defl_stop else 0
            deg, tail = event_polynomial(O, row, h, 1 if force else 0, defl_r, False, a, ORDER)
            ur = event_certificate(a, tail)
            if ur > 0.0:
                ur = confirm_first_root(a, deg, isolate_first_root(a, deg, work), work)
            if ur >= 0.0 and (u < 0.0 or ur < u):
                u = ur
                stop = r
        return u, stop

    @dj
    def sliding_guard(vf):
        """The transition whose guard is 0 on the surface of sliding pseudo-mode ``vf``, or -1
        (``impacts.sliding_guard``)."""
        first = ROWS[vf, 0]
        return BACK[first] if first >= NSTOPS else -1

    @dj
    def onto_guard(x, s, pv, j, gx):
        """``x`` onto the zero set of stop ``j``'s guard (``impacts.onto_guard``; ``gx`` a buffer)."""
        for i in range(NX):
            gx[i] = 0.0
        for _ in range(3):
            hval = guard(x, s, pv, j)
            guard_grad(x, s, pv, gx, j)
            if not onto_zero_step(x, NX, hval, gx):
                break

    @dj
    def contact_row(vf, j):
        """The event row of stop ``j`` in mode ``vf``'s kernels (``events.contact_row``)."""
        for row in range(NEV):
            if ROWS[vf, row] == j:
                return row
        return 0

    @dj
    def enter_contact(x, s, pv, j, gx, e):
        """``x`` onto stop ``j``'s contact manifold ``{h = 0, L_f h = 0}`` (``impacts.enter_contact``;
        ``gx``, ``e`` buffers)."""
        onto_guard(x, s, pv, j, gx)
        for i in range(NX):
            e[i] = 0.0
        contact_dir(x, s, pv, e, j)
        for i in range(NX):
            gx[i] = 0.0
        for _ in range(3):
            vn = normal_rate(x, s, pv, j)
            normal_rate_grad(x, s, pv, gx, j)
            if not along_contact_dir(x, e, gx, vn, NX):
                break

    @dj
    def outside_mode(x, s, pv, vf, known):
        """Whether ``x``, which has just entered mode ``vf``, is outside its region (``impacts.check_region``:
        a guard of the mode's own transitions other than ``known`` below ``-ON_STOP_TOL * max(1, |x|)``)."""
        row_guards = cuda.local.array(NEV, float64)
        for row in range(NEV):
            row_guards[row] = 0.0
            if 0 <= ROWS[vf, row] < NSTOPS:  # (-1: padding; from NSTOPS on: a sliding pseudo-mode's exits)
                row_guards[row] = guard(x, s, pv, ROWS[vf, row])
        return outside_region(x, NX, row_guards, ROWS[vf], NSTOPS, known)

    @dj
    def set_mode(st, j, how):
        """The thread's mode, surface and known roots after transition ``j`` (``impacts.set_mode``)."""
        vf, surface, defl, defl_stop = mode_after(j, how, TARGETS, BACK, SLIDE_ENTRY)
        st[VF] = vf
        st[SURFACE] = surface
        st[DEFL] = defl
        st[DEFL_STOP] = defl_stop

    @dj
    def begin_request(st, sf, periods, keep_n, use_var, T):
        """Start a request of ``periods`` samples keeping the last ``keep_n`` (``lanes.begin_request``)."""
        st[N_SAMPLES] = periods
        st[N_KEEP] = keep_n
        st[ISAMP] = 0
        st[RECORDING] = 1 if periods - keep_n == 0 else 0
        st[LYAP_STARTED] = st[RECORDING]
        sf[SPAN_DT] = math.nan
        st[JAC_VALID] = 1
        st[USE_VAR] = use_var
        sf[LYAP_T0] = st[K] * T + sf[S]
        st[STEPS] = 0
        st[MAX_STEPS] = step_limit(periods)
        st[ZERO_EVENTS] = 0
        st[DEFL] = 0
        st[SURFACE] = 1 + sliding_guard(st[VF])  # (0: not sliding)
        st[KS] = st[REQ_KS]
        sf[SS] = sf[REQ_SS]
        if ZDM:
            st[KZ] = map_period(st[K], sf[S], sf[ZDM_S], T)

    @dj
    def take_samples(st, sf, X, T, h_acc, event, is_last, buf, xe, wrap, pv, gx, ge):
        """The samples within ``(0, h_acc]`` of the step (``recording.take_samples``: while sticking put on
        the contact manifold, while sliding on the surface; ``gx``, ``ge`` buffers)."""
        n_samples = st[N_SAMPLES]
        keep_from = n_samples - st[N_KEEP]
        while st[ISAMP] < n_samples:
            dt = (st[KS] - st[K]) * T + (sf[SS] - sf[S])
            if dt > h_acc or (event and dt == h_acc and not is_last):
                break
            if is_last and st[ISAMP] == n_samples - 1:
                dt = h_acc
            if st[ISAMP] >= keep_from:
                eval_rows(X, NX, ORDER, dt, xe)
                if st[STICKING] != 0 or st[SURFACE] > 0:
                    s = sf[S] + dt
                    if wrap and s >= T:
                        s -= T
                    if st[STICKING] != 0:
                        enter_contact(xe, s, pv, st[STUCK], gx, ge)
                    else:
                        onto_guard(xe, s, pv, st[SURFACE] - 1, gx)
                for i in range(NX):
                    buf[st[ISAMP] - keep_from, i] = xe[i]
            st[ISAMP] += 1
            if wrap:
                st[KS] += 1
            else:
                sf[SS] += T
            if st[ISAMP] == keep_from and st[RECORDING] == 0 and st[N_KEEP] > 0:
                st[RECORDING] = 1
                sf[SPAN_DT] = dt  # (where the Lyapunov sums start)
                sf[LYAP_T0] = st[K] * T + sf[S] + dt

    @dj
    def apply_map(x, s, pv, var, zset, V, gh, gv, vf):
        """The discontinuity map at its phase (``tangent.discontinuity_map``): the state and, with ``var``,
        the tangent vectors kicked; returns whether it applied, never outside the stop's source mode
        (``events.tracked_in``: its guard not a row of mode ``vf``).  ``V``, ``gh``, ``gv``: buffers."""
        tracked = False
        for row in range(NEV):
            if ROWS[vf, row] == ZSTOP:
                tracked = True
        if not tracked:
            return False
        hval = guard(x, s, pv, ZSTOP)
        vn = normal_rate(x, s, pv, ZSTOP)
        a = zset[ZDM_A]
        sp_ = map_kick(hval, vn, a, zset[ZDM_WINDOW])
        if sp_ < 0.0:
            return False
        e = zset[ZDM_E:]
        if LYAP and var:
            guard_grad(x, s, pv, gh, ZSTOP)
            normal_rate_grad(x, s, pv, gv, ZSTOP)
            unpack_var(x, NX, NX, V)
            kick_tangent(V, NX, NX, vn, a, sp_, e, gh, gv)
            pack_var(V, NX, NX, x)
        for i in range(NX):
            x[i] -= e[i] * sp_
        return True

    @dj
    def run_request(st, sf, x, pv, T, wrap, final, fset, X, O, a, xe, xp, buf, counts, work, tw, zset):
        """Steps until the request's last sample; returns the point's status (OK: go on).

        ``tw`` = ``(V, logs, scratch, before, fm, fp, Gx, Gt, Gp, hx, w, hv, Vn, gx, ge)``: the tangent
        arrays, the guard's gradient and the contact direction; ``zset`` the discontinuity map's settings.
        """
        V, logs, scratch, before, fm, fp, Gx, Gt, Gp, hx, w, hv, Vn, gx, ge = tw
        factor = fset[FACTOR]
        chatter_time = fset[CHATTER_TOL] * T
        while st[ISAMP] < st[N_SAMPLES]:
            if st[STEPS] >= st[MAX_STEPS]:
                return STATUS_STEP_LIMIT
            for i in range(NX):
                if not math.isfinite(x[i]):
                    return STATUS_NONFINITE
            s = sf[S]
            var = False
            if LYAP:
                var = st[USE_VAR] != 0
            vf = st[VF]
            sticking = st[STICKING] != 0
            free_var = var and not sticking  # (sticking has no variational equations: lanes' kinds)
            if sticking:  # the sticking field, the contact force in the stop's row (lanes.plan_steps)
                tc_stick(x, s, pv, X, O, st[STUCK])
                h = step_size(X, NX, O, NEV, contact_row(vf, st[STUCK]), math.inf, ORDER, T, factor)
            elif LYAP and var:
                tc_var(x, s, pv, X, O, vf)
                h = step_size(X, NT, O, NEV, 0, GUARD_SCALE, ORDER, T, factor)
            else:
                tc_free(x, s, pv, X, O, vf)
                h = step_size(X, NX, O, NEV, 0, GUARD_SCALE, ORDER, T, factor)
            rem = (st[KS] - st[K]) * T + (sf[SS] - s)  # (step.step_end)
            rem_z = (st[KZ] - st[K]) * T + (sf[ZDM_S] - s) if ZDM else 0.0
            h, ends = cut_step(h, rem, st[ISAMP] == st[N_SAMPLES] - 1, ZDM, rem_z)
            last = (ends & STEP_LAST) != 0
            u, ev_stop = first_event(O, h, vf, st[DEFL], st[DEFL_STOP], sticking, st[STUCK], a, work)
            event = u >= 0.0 and h > 0.0  # (step.accept_step)
            if event and u == 0.0:
                st[ZERO_EVENTS] += 1
                if st[ZERO_EVENTS] > 3:
                    return STATUS_ZENO
            else:
                st[ZERO_EVENTS] = 0
            h_acc = u * h if event else h
            if event and last and u >= 1.0:
                event = False
            if (st[KS] - st[K]) * T + (sf[SS] - s) <= h_acc:
                take_samples(st, sf, X, T, h_acc, event, last, buf, xe, wrap, pv, gx, ge)
            recording = st[RECORDING]
            eval_rows(X, NT if free_var else NX, ORDER, h_acc, x)  # (the lanes' advance)
            sf[S] = s + h_acc  # (step.end_step)
            if wrap and sf[S] >= T:
                sf[S] -= T
                st[K] += 1
            st[STEPS] += 1
            st[DEFL] = 0
            if st[SURFACE] > 0:  # sliding: back onto the surface, off which the integration drifts
                onto_guard(x, sf[S], pv, st[SURFACE] - 1, gx)
            if LYAP and free_var:  # the Lyapunov vectors (tangent.lyapunov_step)
                started = lyapunov_step(st[LYAP_STARTED] != 0, st[RECORDING] != 0, sf[SPAN_DT], x, X, V,
                                        scratch, logs, xe, before)  # fmt: skip
                if started != 0:
                    st[LYAP_STARTED] = 1
                    if started == LYAP_STARTED_NOW_AT_END:
                        sf[LYAP_T0] = st[K] * T + sf[S]
            sf[SPAN_DT] = math.nan
            if ZDM and map_reached(ends, event, u):  # the discontinuity map's phase (step.end_step)
                st[KZ] += 1
                if apply_map(x, sf[S], pv, var, zset, V, gx, hx, st[VF]) and recording != 0 and final:
                    counts[ZSTOP] += 1  # (a kick, counted as an impact on its stop: lanes.end_lane_step)
            if event and sticking and ev_stop != st[STUCK]:  # another transition fires: the contact ends
                st[STICKING] = 0  # (impacts.at_event; a switch from the contact, off which the step drifted)
                if RESETS[ev_stop] == 0:
                    enter_contact(x, sf[S], pv, st[STUCK], gx, ge)
            if event and sticking and ev_stop == st[STUCK]:  # the contact force changes sign: the release
                st[STICKING] = 0
                st[DEFL] = 3
                st[DEFL_STOP] = ev_stop
            elif (
                event and ev_stop >= NSTOPS
            ):  # sliding ends at a tangency, to that side (impacts.leave_sliding)
                set_mode(st, ev_stop, LEAVE_SLIDING)
                if outside_mode(x, sf[S], pv, st[VF], BACK[ev_stop]):
                    return STATUS_OUTSIDE_MODE
            elif (
                event
                and SLIDE_ENTRY[ev_stop] >= 0
                and st[SURFACE] == 0
                and normal_rate(x, sf[S], pv, BACK[ev_stop]) < 0.0
            ):  # the far side's field pushes back: sliding (impacts.enter_sliding)
                s = sf[S]
                target = TARGETS[SLIDE_ENTRY[ev_stop]]
                if LYAP and var:  # (the saltation matrix of a switch into Filippov's field)
                    if not saltation(x, x, s, pv, ev_stop, V, fm, fp, Gx, Gt, Gp, hx, w, hv, Vn, vf, target):
                        st[JAC_VALID] = 0
                onto_guard(x, s, pv, ev_stop, gx)
                set_mode(st, ev_stop, ENTER_SLIDING)
            elif event and RESETS[ev_stop] == 0:  # a switch of vector field, no reset (impacts.switch_mode)
                s = sf[S]
                target = TARGETS[ev_stop]
                if LYAP and var:  # (the saltation matrix of a switch: the identity reset)
                    if not saltation(x, x, s, pv, ev_stop, V, fm, fp, Gx, Gt, Gp, hx, w, hv, Vn, vf, target):
                        st[JAC_VALID] = 0
                set_mode(st, ev_stop, SWITCH)
                if outside_mode(x, s, pv, st[VF], BACK[ev_stop]):
                    return STATUS_OUTSIDE_MODE
            elif event:  # an impact on stop ev_stop (impacts.at_event, apply_impact)
                s = sf[S]
                vn = normal_rate(x, s, pv, ev_stop)
                reset(x, s, pv, xp, ev_stop)
                if LYAP and var:  # (the variational matrix times the saltation matrix)
                    if not saltation(
                        x, xp, s, pv, ev_stop, V, fm, fp, Gx, Gt, Gp, hx, w, hv, Vn, vf, TARGETS[ev_stop]
                    ):
                        st[JAC_VALID] = 0  # (an impact at zero normal speed has no Jacobian)
                for i in range(NT if free_var else NX):
                    x[i] = xp[i]
                if recording != 0 and final:
                    counts[ev_stop] += 1
                if TARGETS[ev_stop] != vf:  # a reset that also changes the mode (impacts.change_mode)
                    set_mode(st, ev_stop, SWITCH)
                    if outside_mode(x, s, pv, st[VF], -1):
                        return STATUS_OUTSIDE_MODE
                else:  # a reset within a mode: inside its region, on its guard or off it (at_event)
                    if outside_mode(x, s, pv, vf, ZSTOP):
                        return STATUS_OUTSIDE_MODE
                    st[DEFL] = roots_after_reset(guard(x, s, pv, ev_stop), x, NX)
                    st[DEFL_STOP] = ev_stop
                if STICKS[ev_stop] != 0:  # complete chattering: to its accumulation point, then sticking
                    w_out = normal_rate(x, s, pv, ev_stop)
                    dt_acc = chatter_time_left(w_out, normal_accel(x, s, pv, ev_stop), -vn, chatter_time)
                    if dt_acc >= 0.0:  # (impacts.at_event)
                        sf[S] += dt_acc
                        if wrap and sf[S] >= T:
                            sf[S] -= T
                            st[K] += 1
                        enter_contact(x, sf[S], pv, ev_stop, gx, ge)
                        st[STICKING] = 1
                        st[STUCK] = ev_stop
                        st[DEFL] = 0
                        st[JAC_VALID] = 0  # (the Jacobian is not valid after sticking)
            elif sticking:  # no event: back onto the stop, off which the integration drifts (step.end_step)
                enter_contact(x, sf[S], pv, st[STUCK], gx, ge)
        return STATUS_OK

    @dj
    def final_request(st, sf, x, T, iset, s_phase, logs):
        """The recorded stage (``lanes.final_request``): with Lyapunov exponents a new run at the current
        time, the variational matrix the identity, ``iset[ALIGN]`` periods before the recorded ones."""
        periods = iset[PERIODS]
        if LYAP:
            k0, s0, ks0, ss0 = start_times(st[K] * T + sf[S], T, s_phase, iset[PERIODIC] != 0)
            st[K] = k0
            sf[S] = s0
            st[REQ_KS] = ks0
            sf[REQ_SS] = ss0
            for i in range(NX):
                logs[i] = 0.0
                for c in range(NX):
                    x[NX + i * NX + c] = 1.0 if i == c else 0.0
            begin_request(st, sf, iset[ALIGN] + periods, periods, 1, T)
        else:
            begin_request(st, sf, periods, periods, 0, T)

    @dj
    def run_point(st, sf, x, pv, T, s_phase, iset, fset, X, O, a, xe, xp, buf, counts, work, tw, zset):
        """The point's protocol (``lanes.take_point``, ``end_request``); returns its status."""
        wrap = iset[PERIODIC] != 0
        budget = iset[TRANSIENT_PERIODS]
        adaptive = iset[ADAPTIVE] != 0
        logs = tw[1]
        for j in range(NSTOPS):
            counts[j] = 0
        st[USED] = 0
        st[STICKING] = 0  # (a point starts in free flight: lanes.take_point)
        st[STUCK] = 0
        if budget > 0:
            blk = min(ADAPTIVE_BLOCK, budget)
            st[BLOCK] = blk
            st[STAGE] = TRANSIENT
            begin_request(st, sf, blk, blk if adaptive else 0, 0, T)
        else:
            st[STAGE] = FINAL
            final_request(st, sf, x, T, iset, s_phase, logs)
        while True:
            status = run_request(st, sf, x, pv, T, wrap, st[STAGE] == FINAL, fset, X, O, a, xe, xp, buf,
                                 counts, work, tw, zset)  # fmt: skip
            if status != STATUS_OK:
                return status
            if wrap:
                st[REQ_KS] += st[N_SAMPLES]
            else:
                sf[REQ_SS] += st[N_SAMPLES] * T
            stage = st[STAGE]
            if stage == FINAL:
                return STATUS_OK
            if stage == EXTRA:
                st[STAGE] = FINAL
                final_request(st, sf, x, T, iset, s_phase, logs)
                continue
            blk = st[BLOCK]
            st[USED] += blk
            used = st[USED]
            nxt = -1
            if adaptive and blk == ADAPTIVE_BLOCK:
                per = repeats_with_period(buf, blk, fset[ADAPTIVE_TOL], ADAPTIVE_MAX_PERIOD)
                if per > 0:
                    extra = (budget - used) % per
                    if extra:
                        st[USED] += extra
                        st[STAGE] = EXTRA
                        begin_request(st, sf, extra, 0, 0, T)
                        continue
                    nxt = 0
            if nxt < 0 and used < budget:
                blk = min(ADAPTIVE_BLOCK, budget - used)
                st[BLOCK] = blk
                begin_request(st, sf, blk, blk if adaptive else 0, 0, T)
                continue
            st[STAGE] = FINAL
            final_request(st, sf, x, T, iset, s_phase, logs)

    @cuda.jit
    def kernel(jobs, control, x0, firsts, first_vf, x0_vf, pvs, Ts, sphase, tcarry, samples, by_stop, lyap,
               used, x_final, t_final, vf_final, status, work, iset, fset, zdms, zset):  # fmt: skip
        tid = cuda.grid(1)
        if tid >= work.shape[0]:
            return
        st = cuda.local.array(INT_FIELDS, int64)
        sf = cuda.local.array(FLOAT_FIELDS, float64)
        x = cuda.local.array(NT, float64)
        X = cuda.local.array((NT, KC), float64)
        O = cuda.local.array((NEV, KC), float64)
        a = cuda.local.array(KC, float64)
        xe = cuda.local.array(NT, float64)
        xp = cuda.local.array(NT, float64)
        tw = (
            cuda.local.array((NV, NV), float64),  # V
            cuda.local.array(NV, float64),  # logs
            cuda.local.array(NV, float64),  # scratch
            cuda.local.array(NV, float64),  # before
            cuda.local.array(NV, float64),  # fm
            cuda.local.array(NV, float64),  # fp
            cuda.local.array((NV, NV), float64),  # Gx
            cuda.local.array(NV, float64),  # Gt
            cuda.local.array((NV, 1), float64),  # Gp
            cuda.local.array(NV, float64),  # hx
            cuda.local.array(NV, float64),  # w
            cuda.local.array(NV, float64),  # hv
            cuda.local.array((NV, NV), float64),  # Vn
            cuda.local.array(NX, float64),  # gx (the guard's gradient, sliding)
            cuda.local.array(NX, float64),  # ge (the contact direction, sticking)
        )
        buf = cuda.local.array((KEEP, NX), float64)
        counts = cuda.local.array(NSTOPS, int64)
        mine = work[tid]
        periods = iset[PERIODS]
        while True:
            job = cuda.atomic.add(control, 0, 1)
            if job >= jobs.shape[0]:
                return
            ok = False
            for p in range(jobs[job, 0], jobs[job, 1]):
                T = Ts[p]
                if p == jobs[job, 0]:
                    for i in range(NX):
                        x[i] = firsts[job, 1 + i]
                    t0 = firsts[job, 0]
                    st[VF] = first_vf[job]
                elif iset[FRESH] != 0 or not ok:
                    for i in range(NX):
                        x[i] = x0[job, i]
                    t0 = 0.0
                    st[VF] = x0_vf[job]
                elif iset[PERIODIC] != 0:  # (the previous point's end: its state and time)
                    t0 = tcarry[p]
                else:
                    t0 = t_final[p - 1]
                k0, s0, ks0, ss0 = start_times(t0, T, sphase[p], iset[PERIODIC] != 0)
                st[K] = k0
                sf[S] = s0
                st[REQ_KS] = ks0
                sf[REQ_SS] = ss0
                if ZDM:
                    sf[ZDM_S] = zdms[p]
                code = run_point(st, sf, x, pvs[p], T, sphase[p], iset, fset, X, O, a, xe, xp, buf, counts,
                                 mine, tw, zset)  # fmt: skip
                if code == STATUS_OK:  # (lanes.finish_point)
                    for i in range(NX):
                        if not math.isfinite(x[i]):
                            code = STATUS_NONFINITE
                    for r in range(periods):
                        for c in range(NX):
                            if not math.isfinite(buf[r, c]):
                                code = STATUS_NONFINITE
                if code == STATUS_OK:
                    for r in range(periods):
                        for c in range(NX):
                            samples[p, r, c] = buf[r, c]
                    for j in range(NSTOPS):
                        by_stop[p, j] = counts[j]
                    used[p] = st[USED] + iset[ALIGN]
                    if LYAP:  # (lanes.finish_point)
                        logs = tw[1]
                        ex = math.nan
                        span = st[K] * T + sf[S] - sf[LYAP_T0] if st[LYAP_STARTED] != 0 else 0.0
                        if st[JAC_VALID] != 0 and span != 0.0:
                            ex = logs[0] / span
                            for j in range(1, NX):
                                v = logs[j] / span
                                if math.isnan(ex) or math.isnan(v):
                                    ex = math.nan
                                elif v > ex:
                                    ex = v
                        lyap[p] = ex
                    for i in range(NX):
                        x_final[p, i] = x[i]
                    t_final[p] = st[K] * T + sf[S]
                    vf_final[p] = st[VF]
                status[p] = code
                ok = code == STATUS_OK

    return kernel
