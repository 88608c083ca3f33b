"""Driver piece: the location of events on a step (appended to each kernel module).

On every step the guard ``h`` (or, while sticking, the contact force) is
expanded as a Taylor polynomial alongside the state; written in the normalised
step time ``u`` in ``[0, 1]`` its first root is the first event of the step.
Roots known in advance are divided out first: the one at ``u = 0`` just after
an impact (``h = 0``), a release (force 0) or a start at a grazing contact
(``h = L_f h = 0``), and the one at ``u = 1`` of a run that ends at a grazing
contact.
"""

import math  # noqa: F401 - the names the pieces share in the generated module

import numpy as np  # noqa: F401
from numba import njit

from grazing.engine.polyroots import quadratic_bound
from grazing.engine.stepping import divide_double_root_at_one


@njit(cache=True, inline="always")
def event_polynomial(O, h, mode, defl, end_contact, a):
    """The event function over the step as ``a[0] + a[1] u + ...``; returns ``(degree, tail)``.

    ``defl`` roots at ``u = 0`` are known (1 after an impact, 2 at a grazing
    contact, 3 after a release) and divided out, and so is a root at ``u = 0``
    of a trajectory on the surface and leaving it; with ``end_contact`` the
    double root at ``u = 1`` of a run ending at a grazing contact.  ``tail`` is
    ``sum |a_j|`` for ``j >= 3``, which :func:`event_certificate` needs
    (summed while the coefficients are written, on the common path).
    """
    order = ORDER
    hk = 1.0
    for j in range(min(3, order + 1)):
        a[j] = O[0, j] * hk
        hk *= h
    tail = 0.0
    for j in range(3, order + 1):
        c = O[0, j] * hk
        a[j] = c
        tail += abs(c)
        hk *= h
    if mode == 1:  # sticking: the event is the contact force reaching zero from above
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
    (``isolate_first_root``), which the loop calls.
    """
    if a[0] <= 0.0:
        return 0.0
    if quadratic_bound(a[0], a[1], a[2], tail) <= 0.0:
        return 1.0
    return -1.0
