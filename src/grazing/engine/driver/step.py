"""Driver piece: the parts of a step that :mod:`.loop` and :mod:`.lanes` share, over a run's record.

Each takes the run's state (a :data:`.state.RUN_STATE` record): the one run
of :func:`.loop.integrate`, or one lane of :func:`.lanes.sweep_lanes`.
"""

from numba import njit

STEP_LAST = 1
"""The step ends at the run's last sample."""
STEP_MAP = 4
"""The step ends at the discontinuity map's phase."""


@njit(cache=True, inline="always")
def step_end(r, h, zdm_on, zdm_s):
    """The step of run ``r`` from its time on, of size at most ``h``; returns ``(h, ends)``.

    The step is cut at the run's last sample (``ends & STEP_LAST``) and at
    the discontinuity map's local time ``zdm_s`` (``ends & STEP_MAP``).
    """
    T = r.T
    rem = (r.ks - r.k) * T + (r.ss - r.s)
    last = False
    if r.isamp == r.n_samples - 1 and h >= rem:
        h = rem
        last = True
    zdm_hit = False
    if zdm_on:
        rem_z = (r.kz - r.k) * T + (zdm_s - r.s)
        if rem_z <= h:
            h = rem_z
            zdm_hit = True
            last = last and rem_z >= rem
    return h, (STEP_LAST if last else 0) | (STEP_MAP if zdm_hit else 0)
