"""Driver piece: the location of events on a step.

On every step every stop's guard ``h`` (or, for the stop it sticks to, the
contact force) is expanded as a Taylor polynomial alongside the state; written
in the normalised step time ``u`` in ``[0, 1]``, the first root of any of them
is the first event of the step (of roots at the same ``u``, the first stop's).
Roots known in advance are divided out first: the one at ``u = 0`` just after
an impact (``h = 0``), a release (force 0) or a start at a grazing contact
(``h = L_f h = 0``), and the one at ``u = 1`` of a run that ends at a grazing
contact.
"""

import math  # noqa: F401 - the names the pieces share in the generated module

import numpy as np  # noqa: F401
from numba import njit

from grazing.engine.polyroots import confirm_first_root, isolate_first_root, quadratic_bound
from grazing.engine.stepping import divide_double_root_at_one


@njit(cache=True, inline="always")
def event_polynomial(O, row, h, mode, defl, end_contact, a, order):
    """Event row ``row`` over the step as ``a[0] + a[1] u + ...``; returns ``(degree, tail)``.

    ``defl`` roots at ``u = 0`` are known (1 after an impact, 2 at a grazing
    contact, 3 after a release) and divided out, and so is a root at ``u = 0``
    of a trajectory on the surface and leaving it; with ``end_contact`` the
    double root at ``u = 1`` of a run ending at a grazing contact.  ``tail`` is
    ``sum |a_j|`` for ``j >= 3``, which :func:`event_certificate` needs
    (summed while the coefficients are written, on the common path).
    """
    hk = 1.0
    for j in range(min(3, order + 1)):
        a[j] = O[row, j] * hk
        hk *= h
    tail = 0.0
    for j in range(3, order + 1):
        c = O[row, j] * hk
        a[j] = c
        tail += abs(c)
        hk *= h
    if mode == 1:  # the stop it sticks to: the event is the contact force reaching zero from above
        for j in range(order + 1):
            a[j] = -a[j]
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
    if end_contact:
        deg = divide_double_root_at_one(a, deg)  # the final tangential contact at u = 1
    if deg != order:  # the coefficients moved: sum the tail again
        tail = 0.0
        for j in range(3, deg + 1):
            tail += abs(a[j])
    return deg, tail


@njit(cache=True, inline="always")
def event_certificate(a, tail):
    """0 if the event polynomial starts at or below zero, -1 if it has no root on the step, else 1.

    A quadratic lower bound on scalars (``tail`` bounds the terms of degree 3
    and more) clears most steps; the rest (1) need Bernstein subdivision
    (``isolate_first_root``), which the loop calls, and the root it finds is checked to be the first
    (``confirm_first_root``: no earlier sign change of the guard on the step).
    """
    if a[0] <= 0.0:
        return 0.0
    if quadratic_bound(a[0], a[1], a[2], tail) <= 0.0:
        return 1.0
    return -1.0


@njit(cache=True, inline="always")
def first_event(m, run, O, h, events, skip, end_contact, end_stop, a, work):
    """The first event on the step of ``run`` over every stop: ``(u, stop)``, ``u < 0`` when there is none.

    ``run`` is the run's state (:data:`.state.RUN_STATE`): ``run.mode`` 1 is
    sticking to stop ``run.stuck`` (its row is the contact force); the known
    roots at ``u = 0`` (``run.defl``) belong to stop ``run.defl_stop``, a
    final grazing contact (``end_contact``) to ``end_stop``.  Without
    ``events`` the transitions with a reset (impacts) are not watched: the
    contact force, the switches of vector field without a reset and the exits
    of sliding are; stop ``skip`` (the one the discontinuity map stands for;
    -1: none) is not.
    """
    u = -1.0
    stop = 0
    mode = run.mode
    stuck = run.stuck
    defl = run.defl
    defl_stop = run.defl_stop
    vf = run.vf
    for row in range(m.rows.shape[1]):
        r = m.rows[vf, row]  # the row's stop (transition); -1: padding
        if r < 0:
            continue
        force = mode == 1 and r == stuck
        if not (events or force or not m.resets[r]) or r == skip:  # (no events: no reset transitions)
            continue
        defl_r = defl if r == defl_stop else 0
        end_r = end_contact and r == end_stop
        deg, tail = event_polynomial(O, row, h, 1 if force else 0, defl_r, end_r, a, m.order)
        ur = event_certificate(a, tail)
        if ur > 0.0:  # rarely: the certificate cannot exclude a root on the step
            ur = confirm_first_root(a, deg, isolate_first_root(a, deg, work), work)
        if ur >= 0.0 and (u < 0.0 or ur < u):
            u = ur
            stop = r
    return u, stop


@njit(cache=True, inline="always")
def contact_row(m, vf, j):
    """The event row of stop ``j`` in mode ``vf``'s kernels: the contact force's while sticking to it.

    For a model of one mode, ``j`` itself (every stop's guard is a row).
    """
    for row in range(m.rows.shape[1]):
        if m.rows[vf, row] == j:
            return row
    return 0


@njit(cache=True, inline="always")
def tracked_in(m, vf, j):
    """Whether transition ``j``'s guard is an event row of mode ``vf``'s kernels (``vf`` is its source mode,
    or a sliding pseudo-mode on a surface beside it)."""
    for row in range(m.rows.shape[1]):
        if m.rows[vf, row] == j:
            return True
    return False
