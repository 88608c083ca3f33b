"""The calling convention between the compiled driver and a model's compiled functions.

Every model function has the same C signature::

    double f(double *x, double s, double *pv, double *a, double *b, double *c, int64 j)

(state, local time, parameter vector, up to three output arrays, stop index;
unused arguments are null or 0).  The driver is compiled once per machine and
reaches a model's functions through a table of their addresses (:data:`SLOTS`)
that it receives at run time, so a new model, parameter set or Taylor order
costs no numba compilation at all.  :func:`call_model` is the call, inlined in
the driver.
"""

from __future__ import annotations

import ctypes

C_SIGNATURE = (
    ctypes.c_void_p, ctypes.c_double, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
    ctypes.c_void_p, ctypes.c_int64,
)  # fmt: skip
"""The argument types of every model function (ctypes), as documented above."""

ARITY = 3
"""Output arrays a model function can take (``a``, ``b``, ``c``)."""

SLOTS = (
    "tc_free", "tc_var", "tc_stick", "rhs", "guard", "guard_grad", "guard_pgrad", "reset", "reset_jac",
    "normal_rate", "normal_accel", "normal_rate_grad", "contact_dir", "period_grad",
)  # fmt: skip
"""The model functions, in the order of the address table the driver receives."""

LANE_SLOTS = ("tc_free_lanes", "tc_var_lanes")
"""The lane (SIMD) versions of the Taylor kernels, after :data:`SLOTS` in the table (address 0 if absent).

A lane function computes its kernel for ``L`` points at once: every array
element holds ``L`` lanes (lane ``l`` of element ``e`` at ``e * L + l``),
the lanes' times come in ``c`` (``L`` doubles) and ``s`` is unused.
"""

(
    TC_FREE, TC_VAR, TC_STICK, RHS, GUARD, GUARD_GRAD, GUARD_PGRAD, RESET, RESET_JAC, NORMAL_RATE,
    NORMAL_ACCEL, NORMAL_RATE_GRAD, CONTACT_DIR, PERIOD_GRAD, TC_FREE_LANES, TC_VAR_LANES,
) = range(len(SLOTS) + len(LANE_SLOTS))  # fmt: skip


def _call_model_intrinsic():  # pragma: no cover - compiled
    from llvmlite import ir
    from numba import types
    from numba.extending import intrinsic

    @intrinsic
    def call_model(typingctx, addr, x, s, pv, a, b, c, j):
        """``f(x, s, pv, a, b, c, j)`` for the function at ``addr`` (arrays passed as data pointers)."""
        sig = types.float64(addr, x, s, pv, a, b, c, j)

        def codegen(context, builder, signature, args):
            dbl = ir.DoubleType()
            ptr = dbl.as_pointer()
            fnty = ir.FunctionType(dbl, [ptr, dbl, ptr, ptr, ptr, ptr, ir.IntType(64)])
            tys = signature.args

            def data(i):
                if isinstance(tys[i], types.Array):
                    arr = context.make_array(tys[i])(context, builder, args[i])
                    return builder.bitcast(arr.data, ptr)
                return ir.Constant(ptr, None)

            fn = builder.inttoptr(context.cast(builder, args[0], tys[0], types.int64), fnty.as_pointer())
            return builder.call(
                fn,
                [
                    data(1),
                    context.cast(builder, args[2], tys[2], types.float64),
                    data(3), data(4), data(5), data(6),
                    context.cast(builder, args[7], tys[7], types.int64),
                ],
            )  # fmt: skip

        return sig, codegen

    return call_model


def __getattr__(name: str) -> object:
    # ``call_model`` is made on first use (the compiled driver imports it): numba, about 0.25 s
    # to import, is not needed by a process that only hands work to others (a sweep's parent).
    if name == "call_model":
        globals()["call_model"] = fn = _call_model_intrinsic()
        return fn
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
