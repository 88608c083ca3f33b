"""Driver piece: the record-free cores of a transition, shared by the CPU driver and the GPU kernel.

A switch of mode, an entry into sliding or an exit from it, an impact's
saltation matrix, the projection onto a guard's surface and the test that a
mode was entered inside its region: the model's functions are called, and the
run's record read and written, by the callers (:mod:`.impacts` on the CPU,
:mod:`grazing.gpu.kernel` and :mod:`grazing.gpu.tangent` on a device); what
they do with the values is here, over plain arrays and numbers, allocating
nothing, so that :mod:`grazing.gpu.ported` compiles the very same text for the
device.  Nothing of it is written twice.
"""

from numba import njit

from grazing.core.model import ON_STOP_TOL

SWITCH, ENTER_SLIDING, LEAVE_SLIDING = 0, 1, 2
"""How a transition changes the mode (:func:`mode_after`): a switch or a reset into the transition's
target, the entry into the sliding pseudo-mode of its surface, the exit from a pseudo-mode."""


@njit(cache=True)
def mode_after(j, how, targets, back, slide_entry):
    """The run's mode after transition ``j``: ``(vf, surface, defl, defl_stop)``.

    ``how`` is :data:`SWITCH` (a switch of field or a reset into ``j``'s
    target: the transition back, ``back[j]``, has its guard 0 there, a known
    root at ``u = 0``), :data:`ENTER_SLIDING` (crossing ``j``'s surface where
    the far side pushes back: the pseudo-mode of ``slide_entry[j]``, on
    surface ``1 + j``; no root known) or :data:`LEAVE_SLIDING` (the virtual
    exit ``j``, at a tangency: the guard of the surface's transition from that
    side starts with a double root at ``u = 0``).  ``surface`` is 0 off a
    sliding surface, ``defl`` how many roots at ``u = 0`` are known, of
    transition ``defl_stop``'s guard.

    Examples
    --------
    >>> import numpy as np
    >>> targets, back, entry = np.array([1, 0, 0]), np.array([1, 0, -1]), np.array([2, -1, -1])
    >>> mode_after(0, SWITCH, targets, back, entry), mode_after(1, LEAVE_SLIDING, targets, back, entry)
    ((1, 0, 1, 1), (0, 0, 2, 0))
    """
    if how == ENTER_SLIDING:
        return targets[slide_entry[j]], 1 + j, 0, -1
    if how == LEAVE_SLIDING:
        return targets[j], 0, 2, back[j]
    return targets[j], 0, 1 if back[j] >= 0 else 0, back[j]


@njit(cache=True)
def outside_region(x, n, row_guards, mode_rows, nstops, known):
    """Whether ``x``, where a run has just entered a mode, is outside that mode's region.

    ``mode_rows`` are the mode's event rows (its transitions; -1 padding, from
    ``nstops`` on a sliding pseudo-mode's virtual exits), ``row_guards`` each
    real row's guard at ``x``.  Outside: a guard other than transition
    ``known``'s (the way back after a switch, whose guard is 0 there; -1: none)
    below ``-ON_STOP_TOL * max(1, |x|)``, as
    :meth:`~grazing.core.model.HybridModel.check_state` refuses an initial state.

    Examples
    --------
    >>> import numpy as np
    >>> x, rows = np.array([0.5, 2.0]), np.array([3, 1, -1])
    >>> outside_region(x, 2, np.array([-1.0, -1e-9, 0.0]), rows, 3, -1)  # (row 0: a virtual exit)
    False
    >>> outside_region(x, 2, np.array([0.0, -1e-8, 0.0]), rows, 3, -1), outside_region(
    ...     x, 2, np.array([0.0, -1e-8, 0.0]), rows, 3, 1)
    (True, False)
    """
    scale = state_scale(x, n)
    for row in range(mode_rows.shape[0]):
        k = mode_rows[row]
        if k < 0 or k >= nstops or k == known:
            continue
        if row_guards[row] < -ON_STOP_TOL * scale:
            return True
    return False


@njit(cache=True)
def state_scale(x, n):
    """``max(1, |x_i|)`` over the first ``n`` components: the scale of the tolerance ``ON_STOP_TOL`` of a
    guard's value at ``x`` (what counts as on a stop)."""
    scale = 1.0
    for i in range(n):
        scale = max(scale, abs(x[i]))
    return scale


@njit(cache=True)
def roots_after_reset(hval, x, n):
    """The roots at ``u = 0`` known of an impact's guard after its reset: 1 where the state ``x`` after
    the reset is on the guard (its value ``hval`` there within ``ON_STOP_TOL * max(1, |x|)`` of 0), else 0.

    A reset that keeps the state on its guard (``v <- -r v``) leaves the root of the next step's guard
    polynomial at ``u = 0`` known, and the event search divides it out
    (:func:`~grazing.engine.driver.events.event_polynomial`); a reset that moves the state off the guard
    (``h(g(x)) != 0``: a shift of the position, a landing on another stop) leaves no root there, and
    dividing one out would put a spurious event where the guard comes back to its value after the reset.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([0.25, -3.0])
    >>> roots_after_reset(2e-9, x, 2), roots_after_reset(-4e-9, x, 2), roots_after_reset(0.05, x, 2)
    (1, 0, 0)
    """
    return 1 if abs(hval) <= ON_STOP_TOL * state_scale(x, n) else 0


@njit(cache=True)
def onto_zero_step(x, n, hval, gx):
    """One Newton step of ``x`` onto the zero set of a guard along its gradient; False: none taken.

    ``hval`` is the guard at ``x``, ``gx`` its gradient; no step where either is 0.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([3.0, 4.0])
    >>> onto_zero_step(x, 2, 2.0, np.array([1.0, 1.0])), x.tolist()
    (True, [2.0, 3.0])
    """
    nn = 0.0
    for i in range(n):
        nn += gx[i] * gx[i]
    if nn == 0.0 or hval == 0.0:
        return False
    for i in range(n):
        x[i] -= hval * gx[i] / nn
    return True


@njit(cache=True)
def saltation_vector(fm, fp, Gx, Gt, hx, ht, n, w):
    """``w = (f+ - G_t - G_x f-) / (h_x f- + h_t)`` of a saltation matrix (paper eq. 14); False, ``w``
    left alone, at zero normal speed (``h_x f- + h_t = 0``: the matrix is unbounded there).

    ``fm``, ``fp`` are the fields before and after, ``Gx``, ``Gt`` the reset's
    derivatives (the identity and 0 for a switch), ``hx``, ``ht`` the guard's.

    Examples
    --------
    >>> import numpy as np
    >>> w = np.zeros(1)
    >>> saltation_vector(np.array([-2.0]), np.array([1.0]), np.eye(1), np.zeros(1), np.ones(1), 0.0, 1, w), w
    (True, array([-1.5]))
    """
    den = ht
    for i in range(n):
        den += hx[i] * fm[i]
    if den == 0.0:
        return False
    for i in range(n):
        acc = fp[i] - Gt[i]
        for j in range(n):
            acc -= Gx[i, j] * fm[j]
        w[i] = acc / den
    return True


@njit(cache=True)
def apply_saltation(V, Gx, Gp, hx, hp, w, n, ncol, hv, Vn):
    """``V <- G_x V + w (h_x V)`` (plus ``G_p + w h_p`` on the parameter columns, ``n`` to ``ncol``).

    The saltation matrix ``S = G_x + w h_x`` (``w`` from :func:`saltation_vector`)
    applied to the variational matrix; ``hv`` (``ncol``) and ``Vn``
    (``n x ncol``) are work arrays.  Without parameter columns (``ncol = n``)
    ``Gp`` and ``hp`` are not read.

    Examples
    --------
    >>> import numpy as np
    >>> V, Gp, hp, hv, Vn = np.eye(2), np.zeros((2, 1)), np.zeros(1), np.zeros(2), np.zeros((2, 2))
    >>> apply_saltation(V, -np.eye(2), Gp, np.array([1.0, 0.0]), hp, np.array([0.5, 0.0]), 2, 2, hv, Vn)
    >>> V.tolist()
    [[-0.5, 0.0], [0.0, -1.0]]
    """
    for c in range(ncol):
        acc = 0.0
        for j in range(n):
            acc += hx[j] * V[j, c]
        if c >= n:
            acc += hp[c - n]
        hv[c] = acc
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
