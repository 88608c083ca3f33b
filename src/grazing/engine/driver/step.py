"""Driver piece: the parts of a step that :mod:`.loop` and :mod:`.lanes` share, over a run's record.

Each takes the run's state (a :data:`.state.RUN_STATE` record): the one run
of :func:`.loop.integrate`, or one lane of :func:`.lanes.sweep_lanes`.
"""

from numba import njit

STEP_LAST = 1
"""The step ends at the run's last sample."""
STEP_SPAN = 2
"""The step ends at the sample the recorded span starts from (with Lyapunov sums)."""
STEP_MAP = 4
"""The step ends at the discontinuity map's phase."""


@njit(cache=True, inline="always")
def step_end(r, h, lyapunov, zdm_on, zdm_s):
    """The step of run ``r`` from its time on, of size at most ``h``; returns ``(h, ends)``.

    The step is cut at the run's last sample (``ends & STEP_LAST``), at the
    discontinuity map's local time ``zdm_s`` (``STEP_MAP``) and, with
    ``lyapunov`` sums, at the sample where the recorded span starts
    (``STEP_SPAN``): the sums then start there, wherever a run is cut into
    calls (a call ends at its last sample, and the next one starts recording
    there).  A step cut at a sample keeps an event at its very end for the
    next step (as a step at the end of a call does).
    """
    T = r.T
    rem = (r.ks - r.k) * T + (r.ss - r.s)
    last = False
    span = False
    if r.isamp == r.n_samples - 1 and h >= rem:
        h = rem
        last = True
    elif lyapunov and r.use_var and r.n_keep > 0 and not r.recording and h >= rem:
        if r.isamp == r.n_samples - r.n_keep - 1:
            h = rem
            span = True
    zdm_hit = False
    if zdm_on:
        rem_z = (r.kz - r.k) * T + (zdm_s - r.s)
        if rem_z <= h:
            h = rem_z
            zdm_hit = True
            last = last and rem_z >= rem
            span = span and rem_z >= rem
    ends = (STEP_LAST if last else 0) | (STEP_SPAN if span else 0) | (STEP_MAP if zdm_hit else 0)
    return h, ends
