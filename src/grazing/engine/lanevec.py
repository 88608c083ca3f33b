"""Vector code for the sweep's lanes, written as LLVM IR inside the numba driver.

A loop over the lanes in numba is compiled lane by lane where its values
would have to stay in vector registers across an inner loop (the compiler
cannot tell the driver's work arrays apart, so each step of an inner loop
goes through memory, and its lanes are computed one after the other).  The
functions here are numba intrinsics: they emit the loop on vectors of
:data:`LANE_WIDTH` doubles directly, with the scalar path's operations in
the scalar path's order, so a lane computes the same doubles as the scalar
integrator (:mod:`grazing.engine.driver.events`), bit for bit.  They take
arrays whose last dimension is :data:`LANE_WIDTH` (the driver calls them
only then, and numba's loops otherwise).

Examples
--------
>>> import numpy as np
>>> from numba import njit
>>> W = LANE_WIDTH
>>> O = np.zeros((1, 6, W)); O[0, 0] = 1.0; O[0, 1] = -0.5    # guard 1 - 0.5 t (+ nothing)
>>> plain = np.ones(W, dtype=np.int64)
>>> hs = np.linspace(0.5, 4.0, W)                              # the guard reaches 0 at t = 2
>>> njit(lambda O, hs, plain: certify_stop(O, 0, 6, hs, plain))(O, hs, plain)
>>> plain.tolist() == [1 if h < 2.0 else 0 for h in hs]
True
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from grazing.engine.llvmgen import lane_width

LANE_WIDTH = lane_width()
"""Doubles per vector: this processor's lane width (the model's lane functions')."""

_DOUBLE = ir.DoubleType()
_VEC = ir.VectorType(_DOUBLE, LANE_WIDTH)
_I64VEC = ir.VectorType(ir.IntType(64), LANE_WIDTH)


def _splat(value: float) -> ir.Constant:
    return ir.Constant(_VEC, [value] * LANE_WIDTH)


def _load(builder: ir.IRBuilder, base: ir.Value, offset: ir.Value, ty: ir.Type = _VEC) -> ir.Value:
    """The vector at element ``offset`` (counted in lanes' elements) of the array data ``base``."""
    ptr = builder.gep(base, [offset])
    return builder.load(builder.bitcast(ptr, ty.as_pointer()), align=8)


def _fabs(module: ir.Module) -> ir.Function:
    """``llvm.fabs`` on vectors (numba's ``abs`` of a float)."""
    name = f"llvm.fabs.v{LANE_WIDTH}f64"
    existing = module.globals.get(name)
    return existing if existing is not None else ir.Function(module, ir.FunctionType(_VEC, [_VEC]), name=name)


def _min(builder: ir.IRBuilder, acc: ir.Value, v: ir.Value) -> ir.Value:
    """numba's ``min(acc, v)`` for floats (Python's: ``v if v < acc else acc``), lane by lane."""
    return builder.select(builder.fcmp_ordered("<", v, acc), v, acc)


@intrinsic
def certify_stop(typingctx, O, row, K, hs, plain):
    """Clear ``plain[lane]`` where the event polynomial of row ``row`` of ``O`` may vanish on the step.

    ``O`` holds the event rows' Taylor coefficients, ``(rows, K, LANE_WIDTH)``;
    ``hs`` the lanes' steps.  The polynomial ``sum_j O[row, j, lane] h^j`` is
    certainly positive on the step where ``a0 > 0`` and the quadratic bound of
    :func:`grazing.engine.polyroots.quadratic_bound` (its first three terms
    ``a0, a1, a2`` and ``tail = sum_{j>=3} |O[row, j] h^j|``) is positive: the
    operations of ``event_polynomial`` and ``event_certificate``, in their
    order, on vectors.
    """
    sig = types.void(O, row, K, hs, plain)

    def codegen(context, builder, signature, args):
        o_ty, _, _, h_ty, p_ty = signature.args
        o_arr, row_v, k_v, h_arr, p_arr = args
        o_data = context.make_array(o_ty)(context, builder, o_arr).data
        h_data = context.make_array(h_ty)(context, builder, h_arr).data
        p_data = context.make_array(p_ty)(context, builder, p_arr).data
        i64 = ir.IntType(64)
        row_v = context.cast(builder, row_v, signature.args[1], types.int64)
        k_v = context.cast(builder, k_v, signature.args[2], types.int64)
        width = ir.Constant(i64, LANE_WIDTH)
        first = builder.mul(builder.mul(row_v, k_v), width)  # element of O[row, 0, 0]
        h = _load(builder, h_data, ir.Constant(i64, 0))
        hk = _splat(1.0)
        terms = []
        for j in range(3):
            c = _load(builder, o_data, builder.add(first, ir.Constant(i64, j * LANE_WIDTH)))
            terms.append(builder.fmul(c, hk))
            hk = builder.fmul(hk, h)
        a0, a1, a2 = terms
        tail_slot = cgutils.alloca_once_value(builder, _splat(0.0))
        hk_slot = cgutils.alloca_once_value(builder, hk)
        with cgutils.for_range(builder, k_v, start=ir.Constant(i64, 3)) as loop:
            offset = builder.add(first, builder.mul(loop.index, width))
            c = builder.fmul(_load(builder, o_data, offset), builder.load(hk_slot))
            fabs = _fabs(builder.module)
            builder.store(builder.fadd(builder.load(tail_slot), builder.call(fabs, [c])), tail_slot)
            builder.store(builder.fmul(builder.load(hk_slot), h), hk_slot)
        tail = builder.load(tail_slot)
        # quadratic_bound(a0, a1, a2, tail)
        low = _min(builder, a0, builder.fadd(builder.fadd(a0, a1), a2))
        um = builder.fdiv(builder.fneg(a1), builder.fmul(_splat(2.0), a2))
        in_step = builder.and_(
            builder.fcmp_ordered("<", _splat(0.0), um), builder.fcmp_ordered("<", um, _splat(1.0))
        )
        inside = builder.and_(builder.fcmp_ordered(">", a2, _splat(0.0)), in_step)
        vertex = builder.fsub(a0, builder.fdiv(builder.fmul(a1, a1), builder.fmul(_splat(4.0), a2)))
        low = builder.select(inside, _min(builder, low, vertex), low)
        bound = builder.fsub(low, tail)
        positive = builder.fcmp_ordered(">", a0, _splat(0.0))
        keep = builder.and_(positive, builder.fcmp_ordered(">", bound, _splat(0.0)))
        p_ptr = builder.bitcast(p_data, _I64VEC.as_pointer())
        old = builder.load(p_ptr, align=8)
        builder.store(builder.select(keep, old, ir.Constant(_I64VEC, [0] * LANE_WIDTH)), p_ptr, align=8)
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def advance_rows(typingctx, X, first, last, order, dt, mask, out):
    """``out[i, lane]`` = the polynomial ``X[i, :order + 1, lane]`` at ``dt[lane]``, for ``first <= i < last``
    and the lanes where ``mask[lane]`` is not 0 (the others keep their value).

    ``X`` is ``(rows, K, LANE_WIDTH)``, ``out`` ``(rows, LANE_WIDTH)``; Horner's
    rule from the highest coefficient, as :func:`grazing.engine.stepping.eval_rows`.
    """
    sig = types.void(X, first, last, order, dt, mask, out)

    def codegen(context, builder, signature, args):
        x_ty, f_ty, l_ty, o_ty, d_ty, m_ty, out_ty = signature.args
        x_arr, first_v, last_v, order_v, d_arr, m_arr, out_arr = args
        i64 = ir.IntType(64)
        x_data = context.make_array(x_ty)(context, builder, x_arr).data
        d_data = context.make_array(d_ty)(context, builder, d_arr).data
        m_data = context.make_array(m_ty)(context, builder, m_arr).data
        out_data = context.make_array(out_ty)(context, builder, out_arr).data
        first_v = context.cast(builder, first_v, f_ty, types.int64)
        last_v = context.cast(builder, last_v, l_ty, types.int64)
        order_v = context.cast(builder, order_v, o_ty, types.int64)
        width = ir.Constant(i64, LANE_WIDTH)
        K = builder.add(order_v, ir.Constant(i64, 1))
        dt = _load(builder, d_data, ir.Constant(i64, 0))
        keep = builder.icmp_signed("!=", _load(builder, m_data, ir.Constant(i64, 0), _I64VEC),
                                   ir.Constant(_I64VEC, [0] * LANE_WIDTH))  # fmt: skip
        acc_slot = cgutils.alloca_once(builder, _VEC)
        with cgutils.for_range(builder, last_v, start=first_v) as row:
            base = builder.mul(builder.mul(row.index, K), width)  # element of X[i, 0, 0]
            builder.store(_load(builder, x_data, builder.add(base, builder.mul(order_v, width))), acc_slot)
            with cgutils.for_range(builder, order_v) as step:
                j = builder.sub(builder.sub(order_v, ir.Constant(i64, 1)), step.index)  # order - 1 down to 0
                c = _load(builder, x_data, builder.add(base, builder.mul(j, width)))
                builder.store(builder.fadd(builder.fmul(builder.load(acc_slot), dt), c), acc_slot)
            ptr = builder.bitcast(builder.gep(out_data, [builder.mul(row.index, width)]), _VEC.as_pointer())
            old = builder.load(ptr, align=8)
            builder.store(builder.select(keep, builder.load(acc_slot), old), ptr, align=8)
        return context.get_dummy_value()

    return sig, codegen
