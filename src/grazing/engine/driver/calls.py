"""Driver piece: the model's functions, called through the address table of the model record.

``m`` is a :class:`~grazing.engine.records.Kernels` record: the addresses of the
model's compiled functions (in the order of :data:`grazing.engine.abi.SLOTS`)
and its sizes.  Each wrapper is inlined: a call is one indirect call with the
arrays passed as data pointers (:func:`grazing.engine.abi.call_model`).
"""

from numba import njit

from grazing.engine.abi import (
    CONTACT_DIR,
    GUARD,
    GUARD_GRAD,
    GUARD_PGRAD,
    NORMAL_ACCEL,
    NORMAL_RATE,
    NORMAL_RATE_GRAD,
    RESET,
    RESET_JAC,
    RHS,
    TC_FREE,
    TC_STICK,
    TC_VAR,
    call_model,
)


@njit(cache=True, inline="always")
def tc_free(m, x, s, pv, X, O, vf):
    """Taylor coefficients of free flight in mode ``vf`` (state rows of ``X``, its guards in ``O``)."""
    call_model(m.fns[TC_FREE], x, s, pv, X, O, None, vf)


@njit(cache=True, inline="always")
def tc_var(m, x, s, pv, X, O, vf):
    """Taylor coefficients of free flight in mode ``vf`` with the variational equations."""
    call_model(m.fns[TC_VAR], x, s, pv, X, O, None, vf)


@njit(cache=True, inline="always")
def tc_stick(m, x, s, pv, X, O, j):
    """Taylor coefficients while sticking to stop ``j`` (its row of ``O`` is the contact force)."""
    call_model(m.fns[TC_STICK], x, s, pv, X, O, None, j)


@njit(cache=True, inline="always")
def rhs(m, x, s, pv, out, vf):
    """The vector field of mode ``vf`` into ``out``."""
    call_model(m.fns[RHS], x, s, pv, out, None, None, vf)


@njit(cache=True, inline="always")
def guard(m, x, s, pv, j):
    """``h(x, s)`` of stop ``j``."""
    return call_model(m.fns[GUARD], x, s, pv, None, None, None, j)


@njit(cache=True, inline="always")
def guard_grad(m, x, s, pv, gx, j):
    """``dh/dx`` of stop ``j`` into ``gx``; returns ``dh/dt``."""
    return call_model(m.fns[GUARD_GRAD], x, s, pv, gx, None, None, j)


@njit(cache=True, inline="always")
def guard_pgrad(m, x, s, pv, hp, j):
    """The derivatives of stop ``j``'s guard along the sensitivity directions into ``hp``."""
    call_model(m.fns[GUARD_PGRAD], x, s, pv, hp, None, None, j)


@njit(cache=True, inline="always")
def reset(m, x, s, pv, out, j):
    """The reset of stop ``j`` into ``out``."""
    call_model(m.fns[RESET], x, s, pv, out, None, None, j)


@njit(cache=True, inline="always")
def reset_jac(m, x, s, pv, Gx, Gt, Gp, j):
    """The reset's derivatives (state, time, sensitivity directions) of stop ``j``."""
    call_model(m.fns[RESET_JAC], x, s, pv, Gx, Gt, Gp, j)


@njit(cache=True, inline="always")
def normal_rate(m, x, s, pv, j):
    """``L_f h`` of stop ``j``."""
    return call_model(m.fns[NORMAL_RATE], x, s, pv, None, None, None, j)


@njit(cache=True, inline="always")
def normal_accel(m, x, s, pv, j):
    """``L_f^2 h`` of stop ``j``."""
    return call_model(m.fns[NORMAL_ACCEL], x, s, pv, None, None, None, j)


@njit(cache=True, inline="always")
def normal_rate_grad(m, x, s, pv, gr, j):
    """``d(L_f h)/dx`` of stop ``j`` into ``gr``."""
    call_model(m.fns[NORMAL_RATE_GRAD], x, s, pv, gr, None, None, j)


@njit(cache=True, inline="always")
def contact_dir(m, x, s, pv, e, j):
    """The contact direction of stop ``j`` into ``e``."""
    call_model(m.fns[CONTACT_DIR], x, s, pv, e, None, None, j)
