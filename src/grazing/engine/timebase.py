"""Time kept as ``k T + s``: where a run starts and samples, for the runner and the compiled driver alike.

Plain Python, which :class:`grazing.engine.runner.Runner` calls as it is and
the sweep driver (:mod:`grazing.engine.driver.lanes`) compiles with numba: one
definition, the same numbers.

Examples
--------
>>> start_times(7.5, 2.0, 0.5, True)  # period 3 at local time 1.5; samples from local time 0.5 of period 4
(3, 1.5, 4, 0.5)
>>> start_times(7.5, 2.0, 0.5, False)  # (no wrapping: the time itself, the first sample a period on)
(0, 7.5, 0, 9.5)
"""

from __future__ import annotations

import math

SNAP = 1e-9
"""A start within this fraction of a period below a boundary starts at the boundary (``s`` slightly < 0)."""


def start_times(t0: float, T: float, s_phase: float, periodic: bool) -> tuple[int, float, int, float]:
    """``(k, s, ks, ss)`` of a run starting at ``t0`` and sampled at local time ``s_phase``.

    For a periodic model the time is ``k T + s`` with ``s`` in ``[0, T)`` (or
    just below 0, from just below a period boundary), the first sample at
    local time ``ss = s_phase`` of period ``ks``, the first such instant not
    before the start (to ``SNAP`` of a period).  Otherwise ``k = 0``, ``s = t0``
    and the first sample a period after the start.
    """
    if not periodic:
        return 0, t0, 0, t0 + T
    snap = SNAP * T
    k0 = math.floor(t0 / T)
    s0 = t0 - k0 * T
    if s0 >= T - snap:  # just below a period boundary: keep s0 slightly negative
        k0 += 1
        s0 -= T
    ks = k0 if s0 < s_phase - snap else k0 + 1
    return k0, s0, ks, s_phase


def map_period(k: int, s: float, s_map: float, T: float) -> int:
    """The period ``k`` or ``k + 1`` whose local time ``s_map`` is the first not before time ``k T + s``
    (to ``SNAP`` of a period): where a run applies the discontinuity map at that phase first.

    Examples
    --------
    >>> map_period(3, 1.0, 1.5, 2.0), map_period(3, 1.5, 1.5, 2.0)  # (at the map's phase: the next period)
    (3, 4)
    """
    return k if s < s_map - SNAP * T else k + 1
