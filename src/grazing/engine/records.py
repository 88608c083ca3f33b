"""The records the compiled driver takes and returns: :class:`Start`, :class:`Config`,
:class:`Kernels`, :class:`RunOutput`, :class:`Result`; and the sweep driver's :class:`LaneSettings`,
:class:`LaneJobs`, :class:`LanePoints`, :class:`LaneResults`.

Named tuples, which numba compiles as structs: the driver,
``integrate(start, pv, config, kernels, output)``, reads its settings by name
(no positional argument lists) and writes its run into one record,
:class:`RunOutput`, of arrays the caller allocates, from which the runner
reads a :class:`Result` by name.  Built by :class:`grazing.engine.runner.Runner`
(the kernels by :mod:`grazing.engine.codegen`, the outputs by
:mod:`grazing.engine.outputs`).  The sweep driver,
``sweep_lanes(kernels, settings, jobs, points, results)``, takes the records
of a sweep (built by :class:`grazing.sweeps.run.LaneBatch`).  The records'
arrays are annotated with their dtype and dimensions (:data:`SWEEP_RECORDS`,
:data:`INTEGRATE_ARGUMENTS`), from which :mod:`grazing.engine.native` derives
the machine code's argument layout and its checks, for both.
"""

from __future__ import annotations

from typing import Annotated, NamedTuple

import numpy as np

I8_1 = Annotated[np.ndarray, ("i8", 1)]
I8_2 = Annotated[np.ndarray, ("i8", 2)]
F8_1 = Annotated[np.ndarray, ("f8", 1)]
F8_2 = Annotated[np.ndarray, ("f8", 2)]
F8_3 = Annotated[np.ndarray, ("f8", 3)]
BOOL_1 = Annotated[np.ndarray, ("?", 1)]

RUN_TOTALS = np.dtype(
    [
        ("status", "i8"),  # a grazing.core.solution.Status code
        ("k", "i8"),  # the end: whole periods ...
        ("s", "f8"),  # ... and local time
        ("mode", "i8"),  # the contact mode at the end
        ("vf", "i8"),  # the active mode (vector field) at the end
        ("steps", "i8"),
        ("n_impacts", "i8"),  # over the whole run
        ("samples_kept", "i8"),  # rows of RunOutput.samples written
        ("impact_rows", "i8"),  # rows the tables need (they hold them if they have room) ...
        ("sticking_rows", "i8"),
        ("trajectory_rows", "i8"),
        ("lyap_span", "f8"),  # the time the Lyapunov sums are over
        ("jacobian_valid", "?"),
        ("switch_rows", "i8"),  # rows the switches table needs
        ("vf_span", "i8"),  # the active mode when the recorded span started
    ],
    align=True,
)
"""The single values a run writes (:attr:`RunOutput.totals`, a structured array of one element)."""

TOTALS_1 = Annotated[np.ndarray, (RUN_TOTALS, 1)]
"""C-contiguous arrays of a dtype (numpy's) and number of dimensions, as the driver takes them."""


class Start(NamedTuple):
    """Where a run starts: state, variational matrix, time ``k T + s`` and contact mode."""

    x: F8_1  # state, (n,)
    V: F8_2  # variational matrix, (n, n + directions)
    k: int  # whole periods
    s: float  # local time in [0, T) (periodic models) or the time
    mode: int  # 0 free flight, 1 + j sticking to stop j
    vf: int  # the active mode (vector field) of a model with modes (0 for one mode)


class Config(NamedTuple):
    """Everything else a run needs, but the parameter vector (see the driver's ``integrate``).

    The parameter values (then the sensitivity directions, row by row) are the
    driver's second argument: an array taken out of a record on every step
    would be reference-counted on every step.  The fields that change from
    call to call come first; :class:`~grazing.engine.runner.Runner` keeps the
    others (:data:`STATIC`) as a tuple, so that a call builds its record in
    one step.
    """

    # -- this call
    max_steps: int
    n_samples: int  # the run ends at the n_samples-th stroboscopic sample
    ks: int  # first sample at (ks, ss), then one per period
    ss: float
    n_keep: int  # the last n_keep samples are kept and define the recorded span
    lyapunov: bool  # Lyapunov sums over the recorded span
    traj_dt: float  # trajectory spacing (0: no trajectory)
    track_min: bool  # smallest guard value and closest approach over the recorded span
    record_impacts: int  # 0 none, 1 in the recorded span, 2 all
    touch_start: bool  # the run starts at a grazing contact (not an impact)
    touch_end: bool  # the run ends at a grazing contact (not an impact)
    # -- the trajectory's (STATIC)
    T: float  # forcing period
    wrap: bool  # keep time as k T + s (periodic models)
    max_step: float
    safety: float  # step safety exponent (see runner.step_safety)
    use_var: bool  # integrate the variational equations
    events: bool  # apply impacts (False: the flow passes through the stop)
    chatter_time: float  # chattering shorter than this is summed and continued as sticking
    zdm: bool  # apply the discontinuity map once per period instead of the impacts
    zdm_s: float  # its local time
    zdm_a: float  # L_f^2 h at the grazing point
    zdm_e: F8_1  # its direction e
    zdm_window: float  # largest |L_f h| / a for which it is applied
    Tp: F8_1  # dT/dp along each sensitivity direction
    stop: int  # the stop a grazing analysis looks at (tracked guard, grazing contacts, discontinuity map)
    # -- Ctrl-C (appended by grazing.engine.codegen.ModelKernels.integrate, see grazing.engine.interrupts)
    sigints: I8_1  # (1,): SIGINTs counted by the machine-code handler
    sigints_seen: int  # the count when the call started: the driver stops when it changes


CALL = Config._fields[: Config._fields.index("T")]
"""The fields of :class:`Config` that each call sets (built by name by the runner)."""

STATIC = Config._fields[Config._fields.index("T") : Config._fields.index("stop") + 1]
"""The fields of :class:`Config` that stay the same for every call on one trajectory."""

INTERRUPT = Config._fields[Config._fields.index("sigints") :]
"""The fields of :class:`Config` about Ctrl-C, added to every call's record last."""


class Kernels(NamedTuple):
    """A model's compiled functions as the driver sees them: their addresses and the model's sizes."""

    fns: I8_1  # int64 addresses, in the order of grazing.engine.abi.SLOTS then LANE_SLOTS
    nx: int  # states
    nsens: int  # sensitivity directions (columns of V after the first nx)
    nstops: int
    order: int  # of the Taylor polynomials
    sticks: BOOL_1  # bool per stop: the stop has a sticking mode
    lanes: int  # lanes of the lane functions (0: none)
    nmodes: int  # modes (vector fields): the flow's functions take the active one as their last argument
    rows: I8_2  # (modes, event rows): the transition (stop) of each row of a mode's kernels, -1 padding
    targets: I8_1  # per transition (stop): the mode it enters
    resets: BOOL_1  # per transition (stop): it has a reset (an impact); else a switch of vector field
    back: I8_1  # per switch: the transition whose guard is 0 just after it (-1: none)
    slide_entry: I8_1  # per transition: the virtual transition into sliding replacing its crossing (-1: none)


class Result(NamedTuple):
    """What a run returns (read from its :class:`RunOutput`)."""

    status: int  # a grazing.core.solution.Status code
    x: np.ndarray
    V: np.ndarray
    k: int
    s: float
    mode: int
    vf: int  # the active mode (vector field)
    steps: int
    n_impacts: int  # over the whole run
    samples: np.ndarray  # (kept samples, n)
    impacts: np.ndarray  # rows [t, speed, state..., stop]
    sticking: np.ndarray  # rows [start, end]
    trajectory: np.ndarray  # rows [t, state...]
    log_sums: np.ndarray  # Lyapunov sums
    lyap_span: float
    guard_min: np.ndarray  # per stop (rows): [h, t, state..., h_approach, t_approach, state...]
    jacobian_valid: bool
    switches: np.ndarray  # rows [t, transition, state...]: changes of mode (state after any reset)
    sample_modes: np.ndarray  # (kept samples,): the mode (vector field) of each kept sample
    vf_span: int  # the active mode when the recorded span started


class RunOutput(NamedTuple):
    """What a run writes (the caller allocates it; :class:`Result` is read from it).

    A table (impacts, sticking intervals, trajectory) holds its rows if it has
    room for them: the rows a run needs are counted in :attr:`totals` all the
    same, so that a caller whose table was too short runs it again with room
    for them all (the run is the same, bit for bit).
    """

    totals: TOTALS_1  # (1,): status, the end, counts (RUN_TOTALS)
    x: F8_1  # (n,): the final state
    V: F8_2  # (n, n + directions): the variational matrix at the end (zero without it)
    samples: F8_2  # (n_keep, n): the kept samples, the first totals.samples_kept rows
    impacts: F8_2  # (rows, 3 + n): [t, speed, state..., stop]
    sticking: F8_2  # (rows, 2): [start, end]
    trajectory: F8_2  # (rows, 1 + n): [t, state...]
    log_sums: F8_1  # (n,): Lyapunov sums
    guard_min: F8_2  # (stops, 2 (2 + n)): per stop [h, t, state..., h_approach, t_approach, state...]
    switches: F8_2  # (rows, 2 + n): [t, transition, state...] at each change of mode (state after any reset)
    sample_modes: I8_1  # (n_keep,): the mode (vector field) of each kept sample, as samples


INTEGRATE_ARGUMENTS = (Start, ("pv", F8_1), Config, Kernels, RunOutput)
"""The arguments of :func:`grazing.engine.driver.loop.integrate`, in order: records (as plain
tuples) and the parameter vector, an array of its own (see :class:`Config`)."""


class LaneSettings(NamedTuple):
    """How the sweep driver computes every point (:mod:`grazing.engine.driver.lanes`)."""

    lanes: int  # lanes (the lane functions' width, or 1)
    fresh: bool  # every point from its job's x0 at time 0 (else from the previous point's end)
    periodic: bool  # the model is periodically forced (time kept as k T + s)
    transient: int  # periods run before the samples ...
    periods: int  # ... and sampled
    adaptive: bool  # transients end early once the samples repeat ...
    adaptive_tol: float  # ... to this
    lyapunov: bool  # the largest Lyapunov exponent over the sampled periods
    safety: float  # step safety exponent (grazing.engine.runner.step_safety)
    chatter_tol: float  # chattering shorter than this fraction of a period is continued as sticking
    zdm: bool  # the discontinuity map instead of the impacts on stop ``stop``
    zdm_a: float  # its L_f^2 h at the grazing point
    zdm_e: F8_1  # its direction e, (nx,)
    zdm_window: float  # largest |L_f h| / a for which it is applied
    stop: int  # the stop the discontinuity map stands for


class LaneJobs(NamedTuple):
    """The jobs of a sweep driver call: runs of consecutive points, taken by the lanes in turn."""

    jobs: I8_2  # (jobs, 2): each job's first point and the end of its points
    control: I8_1  # (3,): the next job, stop (1), most jobs at a time per thread (0: one per lane)
    x0: F8_2  # (jobs, nx): a point's start after a failed one (and every point's when fresh), at time 0
    firsts: F8_2  # (jobs, 1 + nx): the time and state each job's first point starts from
    first_vf: I8_1  # (jobs,): the mode (vector field) each job's first point starts in
    x0_vf: I8_1  # (jobs,): the mode of x0 (a point's start after a failed one, or when fresh)


class LanePoints(NamedTuple):
    """Per point of a sweep driver call."""

    pvs: F8_2  # (points, parameters): the parameter vector
    Ts: F8_1  # the forcing period
    sphase: F8_1  # the sampling phase (local time)
    tcarry: F8_1  # the start time of a point continued from the previous one (periodic models)
    zdms: F8_1  # the discontinuity map's local time


class LaneResults(NamedTuple):
    """What the sweep driver writes per point (the caller allocates it)."""

    samples: F8_3  # (points, periods, nx)
    by_stop: I8_2  # (points, stops): impacts on each stop over the sampled periods
    lyap: F8_1  # the largest Lyapunov exponent (nan: none)
    used: I8_1  # transient periods run
    x: F8_2  # (points, nx): the final state ...
    t: F8_1  # ... and time
    status: I8_1  # the point's grazing.core.solution.Status code once finished (the caller sets -1)
    vf: I8_1  # the mode (vector field) the point ends in


SWEEP_RECORDS = (Kernels, LaneSettings, LaneJobs, LanePoints, LaneResults)
"""The records :func:`grazing.engine.driver.lanes.sweep_lanes` takes, in order (as plain tuples)."""
