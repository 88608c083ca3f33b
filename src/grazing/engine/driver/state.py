"""Driver piece: the state of a run, one named record per lane.

:func:`.loop.integrate` keeps its run in one record of :data:`RUN_STATE`
(an array of one), :func:`.lanes.sweep_lanes` one per lane; the pieces a step
uses (:mod:`.recording` ...) read and update it by name.  numba compiles a
record of a structured array as a struct: ``r.k`` is a load, ``r.k += 1`` a
store, and a record passed to a function is a pointer to it.  A record does
not keep its array alive: numba frees an array after the last use of its
name, so the function that makes the array reads it again after the last
use of its records (``tests/engine/test_state_lifetime.py`` checks it).

Examples
--------
>>> states = new_state(2)  # (from Python: a structured array, its fields by name)
>>> states["k"].tolist(), states["recording"].tolist(), states.dtype["s"].name
([0, 0], [False, False], 'float64')
"""

import numpy as np
from numba import njit

from grazing.core.solution import Status

STATUS_OK = int(Status.OK)
STATUS_STEP_LIMIT = int(Status.STEP_LIMIT)
STATUS_NONFINITE = int(Status.NONFINITE)
STATUS_ZENO = int(Status.ZENO)
STATUS_INTERRUPTED = int(Status.INTERRUPTED)
STATUS_OUTSIDE_MODE = int(Status.OUTSIDE_MODE)

RUN_STATE = np.dtype(
    [
        # the run's settings that may differ from lane to lane
        ("T", np.float64),  # forcing period
        ("wrap", np.bool_),  # keep time as k T + s (periodic models)
        ("traj_dt", np.float64),  # trajectory spacing (0: no trajectory)
        # time and mode
        ("k", np.int64),  # time k T + s (s in [0, T) for periodic models, else the time and k = 0)
        ("s", np.float64),
        ("mode", np.int64),  # 0 free flight, 1 sticking
        ("stuck", np.int64),  # the stop it sticks to
        ("vf", np.int64),  # the active mode (vector field) of a model with modes (0 for one mode)
        ("defl", np.int64),  # known roots at u = 0 of the next step's event polynomial (0 none)
        ("defl_stop", np.int64),  # ... of this stop's guard
        ("surface", np.int64),  # sliding: 1 + the transition whose guard (0 on the surface) it is kept on
        ("steps", np.int64),
        ("max_steps", np.int64),
        ("zero_events", np.int64),  # consecutive events at u = 0
        ("status", np.int64),  # a grazing.core.solution.Status code
        ("use_var", np.bool_),  # with the variational equations
        ("jac_valid", np.bool_),  # no impact without a Jacobian, no sticking so far
        # samples: the run ends at the n_samples-th, the last n_keep are kept and define the recorded span
        ("ks", np.int64),  # the next sample at (ks, ss): local time ss of period ks (or time ss)
        ("ss", np.float64),
        ("isamp", np.int64),  # samples taken
        ("n_samples", np.int64),
        ("n_keep", np.int64),
        ("recording", np.bool_),  # the recorded span has started
        ("vf_span", np.int64),  # the active mode when it started
        ("lyap_started", np.bool_),  # the Lyapunov sums have started, at lyap_t0
        ("lyap_t0", np.float64),
        ("span_dt", np.float64),  # the recorded span started this long into this step (nan: not in this step)
        ("kz", np.int64),  # the discontinuity map's next period
        # what the current step decided (step.end_step)
        ("h_acc", np.float64),  # its accepted part
        ("event", np.bool_),  # it ends at an event ...
        ("ev_stop", np.int64),  # ... on this stop
        ("zdm_hit", np.bool_),  # it ends at the discontinuity map's phase
        # what is recorded (loop.integrate): counts and the next trajectory point at (kt, st)
        ("n_imp", np.int64),  # impacts
        ("n_imp_rec", np.int64),  # ... recorded
        ("n_stick", np.int64),  # sticking intervals recorded
        ("n_traj", np.int64),  # trajectory points recorded
        ("n_switch", np.int64),  # switches of vector field recorded
        ("kt", np.int64),
        ("st", np.float64),
        # a sweep's point (lanes.sweep_lanes)
        ("stage", np.int64),  # lanes.IDLE, TRANSIENT, EXTRA or FINAL
        ("point", np.int64),  # the point the lane computes
        ("job", np.int64),  # the job (run of points) it follows
        ("job_end", np.int64),  # the end of that job's points (0: none taken yet, -1: no more jobs)
        ("block", np.int64),  # periods of the transient's current block
        ("used", np.int64),  # transient periods run so far
        ("req_ks", np.int64),  # the current request's first sample at (req_ks, req_ss) (Runner's ks, ss)
        ("req_ss", np.float64),
    ],
    align=True,  # (each field at a multiple of its size, each record at a multiple of 8 bytes: aligned loads)
)
"""The fields of a run's state (see the comments); every field is zero (False) in a new one."""


@njit(cache=True)
def new_state(lanes):
    """The states of ``lanes`` runs, every field zero."""
    return np.zeros(lanes, dtype=RUN_STATE)
