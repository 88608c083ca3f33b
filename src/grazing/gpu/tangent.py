"""The tangent dynamics of the sweep kernel: the Lyapunov vectors' step and the saltation matrix at an impact.

The CPU driver's :func:`~grazing.engine.driver.tangent.lyapunov_step` as a
device function, operation for operation (the same sums in the same order),
over arrays the kernel's thread owns: the CPU version allocates its small
buffers and reads the run's record, which a device function cannot.  The
saltation matrix (:func:`~grazing.engine.driver.impacts.saltation`) is the
model's derivatives, evaluated into the thread's arrays, handed to the CPU's
own cores (:func:`~grazing.engine.driver.transitions.saltation_vector`,
:func:`~grazing.engine.driver.transitions.apply_saltation`), as are the
Gram-Schmidt step (:func:`~grazing.engine.stepping.orthonormalize`) and the
(un)packing of the variational matrix (:mod:`grazing.gpu.ported`); the
model's field, reset Jacobian and guard gradient its generated functions
(:mod:`grazing.gpu.model`, a mode's by its index).  No sensitivity columns: the variational
matrix is ``n x n`` (``ncol = n``, as on the CPU lanes).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

LYAP_STARTED_NOW_AT_END, LYAP_STARTED_NOW_AT_SPAN = 1, 2
"""What :func:`tangent_functions`' ``lyapunov_step`` reports: the sums started at the step's end (the
span started in an earlier step) or at the span's start inside the step; 0: nothing changed."""


class TangentFunctions(NamedTuple):
    """The device functions of :func:`tangent_functions`."""

    lyapunov_step: Any
    saltation: Any


def tangent_functions(dm: Any) -> TangentFunctions:
    """The tangent dynamics' device functions of the device model ``dm`` (see the module)."""
    from grazing.gpu.ported import device_helpers
    from grazing.gpu.target import device_function

    helpers = device_helpers()
    orthonormalize = helpers["orthonormalize"]
    unpack_var = helpers["unpack_var"]
    pack_var = helpers["pack_var"]
    eval_rows = helpers["eval_rows"]
    saltation_vector = helpers["saltation_vector"]
    apply_saltation = helpers["apply_saltation"]
    rhs = dm.functions["mode_rhs"]
    reset_jac = dm.functions["reset_jac"]
    guard_grad = dm.functions["guard_grad"]
    NX, ORDER = dm.nx, dm.order
    NT = NX + NX * NX

    def lyapunov_step(started, recording, span_dt, x, X, V, scratch, logs, xe, before):
        """Gram-Schmidt on the tangent vectors after a step (``tangent.lyapunov_step``, ``ncol = n``).

        ``started``, ``recording``: whether the sums have started and the
        span is recorded; ``span_dt`` where the span started in the step
        (NaN: not in it).  Returns :data:`LYAP_STARTED_NOW_AT_END`,
        :data:`LYAP_STARTED_NOW_AT_SPAN` or 0.
        """
        code = 0
        if recording and not started:
            if math.isnan(span_dt):  # (the span started in an earlier step, while sticking)
                code = LYAP_STARTED_NOW_AT_END
                unpack_var(x, NX, NX, V)
                orthonormalize(V, NX, scratch)
            else:
                code = LYAP_STARTED_NOW_AT_SPAN
                eval_rows(X, NT, ORDER, span_dt, xe)
                unpack_var(xe, NX, NX, V)
                for c in range(NX):
                    before[c] = 0.0
                orthonormalize(V, NX, before)  # the vectors' growth before the span ...
                unpack_var(x, NX, NX, V)
                orthonormalize(V, NX, logs)
                for c in range(NX):
                    logs[c] -= before[c]  # ... is not the span's
                    if before[c] == -math.inf:  # a direction already collapsed: it stays collapsed
                        logs[c] = -math.inf
        elif started:
            unpack_var(x, NX, NX, V)
            orthonormalize(V, NX, logs)
        else:
            unpack_var(x, NX, NX, V)
            orthonormalize(V, NX, scratch)  # before the span: align V, discard growth
        pack_var(V, NX, NX, x)
        return code

    def saltation(xm, xp, s, pv, j, V, fm, fp, Gx, Gt, Gp, hx, w, hv, Vn, vf_from, vf_to):
        """The variational matrix in ``xm`` times the saltation matrix of stop ``j``, into ``xp``
        (``impacts.saltation`` between ``unpack_var`` and ``pack_var``, no parameter columns); False, the
        matrix carried unchanged, at zero normal speed.  ``f-`` is mode ``vf_from``'s field at ``xm``,
        ``f+`` mode ``vf_to``'s at ``xp``; ``V`` and the rest are the thread's buffers."""
        unpack_var(xm, NX, NX, V)
        rhs(xm, s, pv, fm, vf_from)
        rhs(xp, s, pv, fp, vf_to)
        for i in range(NX):
            Gt[i] = 0.0
            Gp[i, 0] = 0.0
            hx[i] = 0.0
            for c in range(NX):
                Gx[i, c] = 0.0
        reset_jac(xm, s, pv, Gx, Gt, Gp, j)
        ht = guard_grad(xm, s, pv, hx, j)
        ok = saltation_vector(fm, fp, Gx, Gt, hx, ht, NX, w)
        if ok:
            apply_saltation(V, Gx, Gp, hx, Gt, w, NX, NX, hv, Vn)  # (no parameter columns: Gp, Gt not read)
        pack_var(V, NX, NX, xp)
        return ok

    return TangentFunctions(device_function(lyapunov_step), device_function(saltation))
