"""Driver piece: the parts of a step that :mod:`.loop` and :mod:`.lanes` share, over a run's record.

Each takes the run's state (a :data:`.state.RUN_STATE` record): the one run
of :func:`.loop.integrate`, or one lane of :func:`.lanes.sweep_lanes`.
"""

import math

from numba import njit

from grazing.engine import timebase
from grazing.engine.driver.impacts import at_event, enter_contact, onto_guard
from grazing.engine.driver.state import STATUS_ZENO
from grazing.engine.driver.tangent import discontinuity_map, lyapunov_step, shift_period

STEP_LAST = 2
"""The step ends at the run's last sample."""
STEP_MAP = 4
"""The step ends at the discontinuity map's phase."""

map_period = njit(inline="always")(timebase.map_period)
"""The period in which a run starting at ``(k, s)`` first applies the discontinuity map (``timebase``')."""


@njit(cache=True, inline="always")
def step_end(r, h, zdm_on, zdm_s):
    """The step of run ``r`` from its time on, of size at most ``h``; returns ``(h, ends)``.

    The step is cut at the run's last sample (``ends & STEP_LAST``) and at
    the discontinuity map's local time ``zdm_s`` (``ends & STEP_MAP``).
    """
    T = r.T
    rem = (r.ks - r.k) * T + (r.ss - r.s)
    rem_z = (r.kz - r.k) * T + (zdm_s - r.s) if zdm_on else 0.0
    return cut_step(h, rem, r.isamp == r.n_samples - 1, zdm_on, rem_z)


@njit(cache=True, inline="always")
def cut_step(h, rem, last_sample, zdm_on, rem_z):
    """:func:`step_end` on numbers: a step of at most ``h`` cut ``rem`` on at the last sample (where it is
    the request's ``last_sample``) and ``rem_z`` on at the map's phase (``zdm_on``); returns ``(h, ends)``.
    """
    last = False
    if last_sample and h >= rem:
        h = rem
        last = True
    zdm_hit = False
    if zdm_on and rem_z <= h:
        h = rem_z
        zdm_hit = True
        last = last and rem_z >= rem
    return h, (STEP_LAST if last else 0) | (STEP_MAP if zdm_hit else 0)


@njit(cache=True, inline="always")
def map_reached(ends, event, u):
    """Whether a step cut at the discontinuity map's phase (``ends & STEP_MAP``) reaches it: not where an
    event (at ``u``, a fraction of the step) ends it first; the map is then the next step's.

    >>> map_reached(STEP_MAP, False, -1.0), map_reached(STEP_MAP, True, 0.5), map_reached(STEP_MAP, True, 1.0)
    (True, False, True)
    """
    return (ends & STEP_MAP) != 0 and not (event and u < 1.0)


@njit(cache=True, inline="always")
def accept_step(r, h, ends, u, ev_stop):
    """The accepted part of the step of run ``r`` (``h``, cut as ``ends`` says) and its event; False: none.

    ``u`` is the first event on the step as a fraction of it (``u < 0``:
    none), on stop ``ev_stop``.  Sets ``r.h_acc``, ``r.event``, ``r.ev_stop``
    and ``r.zdm_hit``.  An event at the very end of a step that ends at the
    run's last sample is left for the next run.  Returns False (``r.status``
    ``ZENO``) when more than three events in a row come at ``u = 0``.
    """
    event = u >= 0.0 and h > 0.0
    if event and u == 0.0:
        r.zero_events += 1
        if r.zero_events > 3:
            r.status = STATUS_ZENO
            return False
    else:
        r.zero_events = 0
    r.h_acc = u * h if event else h
    if event and (ends & STEP_LAST) != 0 and u >= 1.0:
        event = False
    r.event = event
    r.ev_stop = ev_stop
    r.zdm_hit = map_reached(ends, event, u)
    return True


@njit(cache=True, inline="always")
def end_plain_step(r, lyapunov, sensitivities):
    """The end of the step of run ``r`` where only time passes; False (nothing done) where there is more.

    Only time passes at a step without an event, sticking, a discontinuity map, the
    Lyapunov vectors to update (``lyapunov``) or the sensitivities' period
    term at a period boundary (``sensitivities``): the time, steps and
    ``defl`` as :func:`end_step` sets them.  It takes no array: numba counts
    the references to each array a function is given (an atomic increment and
    decrement), which at every step cost :func:`end_step`'s callers a tenth of
    their time; :func:`end_step` is called only where it has work to do.
    """
    if r.event or r.zdm_hit or r.mode == 1 or r.surface > 0:  # (sticking, sliding: put back on the stop)
        return False
    if r.use_var and r.mode == 0 and (lyapunov or (sensitivities and r.wrap and r.s + r.h_acc >= r.T)):
        return False
    r.s += r.h_acc
    if r.wrap and r.s >= r.T:
        r.s -= r.T
        r.k += 1
    r.steps += 1
    r.defl = 0
    r.span_dt = math.nan
    return True


@njit(cache=True, inline="always")
def end_step(m, r, x, X, pv, nrows, cfg, chatter_time, record_impacts, Tp, work, tables):
    """The end of the step of run ``r``, whose state ``x`` is already advanced; returns ``(zdm, impact)``.

    The step, its accepted part ``r.h_acc`` and its event (``r.event`` on
    stop ``r.ev_stop``, ``r.zdm_hit``) are those :func:`step_end` and the
    event search chose; ``X`` holds its Taylor coefficients, ``nrows`` the
    rows of ``x`` it advanced.  In order: the time (at a period boundary, the
    sensitivities' period term, ``Tp`` = dT/dp), the Lyapunov vectors (with
    ``cfg.lyapunov``), the discontinuity map (``cfg``'s), the event
    (:func:`.impacts.at_event`, chattering shorter than ``chatter_time``) or,
    sticking without an event, the state put back on the stop's contact
    manifold (:func:`.impacts.enter_contact`: the integrated state drifted off it
    step after step, the ball on a table by 3.6e-11 in 300 periods).
    Impacts (and kicks of the map) are recorded in ``tables`` as
    ``record_impacts`` says (0 none, 1 in the recorded span, 2 all).
    ``work`` holds the buffers ``(xp, V, scratch, logs, xe, gh, gv, f)``.
    Returns whether the map kicked and whether there was an impact.
    """
    xp, V, scratch, logs, xe, gh, gv, f = work
    ncol = m.nx + m.nsens
    mode = r.mode
    r.s += r.h_acc
    if r.wrap and r.s >= r.T:
        if m.nsens > 0 and r.use_var and mode == 0:
            shift_period(m, x, r.s, pv, Tp, ncol, f, r.vf)
        r.s -= r.T
        r.k += 1
    r.steps += 1
    r.defl = 0
    if r.surface > 0:  # sliding: back onto the surface, off which the integration drifts
        onto_guard(m, x, r.s, pv, r.surface - 1)
    if cfg.lyapunov and r.use_var and mode == 0:
        lyapunov_step(m, r, x, X, V, ncol, r.k * r.T + r.s, scratch, logs, xe)
    r.span_dt = math.nan
    record = record_impacts == 2 or (record_impacts == 1 and r.recording)
    kicked = False
    if r.zdm_hit:
        r.kz += 1
        kicked = discontinuity_map(m, r, x, pv, cfg, V, gh, gv, record, tables[0])
    impact = False
    if r.event:
        virtual = cfg.stop if cfg.zdm else -1  # (the map's stop, which the flow crosses: no region)
        impact = at_event(m, r, x, xp, pv, r.ev_stop, nrows, V, chatter_time, record, tables, virtual)
    elif mode == 1:  # sticking: back onto the stop, off which the integration drifts
        enter_contact(m, x, r.s, pv, r.stuck)
    return kicked, impact
