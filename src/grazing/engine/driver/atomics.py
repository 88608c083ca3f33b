"""Driver piece: atomic operations on int64 arrays, for a sweep shared by several threads.

The threads of one sweep (:mod:`grazing.sweeps.run`) call
:func:`.lanes.sweep_lanes` on the same arrays: they take jobs from one
counter (:func:`fetch_add`), look at a stop flag the caller may raise
(:func:`load_acquire`), and publish a point as finished only after its
results are written (:func:`store_release`), so that the caller, reading
the flag, reads the results too.  Each is one LLVM atomic instruction.

Examples
--------
>>> import numpy as np
>>> from numba import njit
>>> take = njit(lambda a: fetch_add(a, 0, 1))
>>> a = np.zeros(2, dtype=np.int64)
>>> take(a), take(a), int(a[0])
(0, 1, 2)
"""

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic


def _item_pointer(context, builder, array_type, array, index):
    """The address of ``array[index]`` (no bounds check: the driver's indices are its own)."""
    ary = context.make_array(array_type)(context, builder, array)
    return cgutils.get_item_pointer(context, builder, array_type, ary, [index], wraparound=False)


@intrinsic
def fetch_add(typingctx, array, index, value):
    """``array[index] += value`` at once for every thread; the value before the addition."""
    if not (isinstance(array, types.Array) and array.dtype == types.int64 and array.ndim == 1):
        return None

    def codegen(context, builder, signature, args):
        i = context.cast(builder, args[1], signature.args[1], types.intp)
        v = context.cast(builder, args[2], signature.args[2], types.int64)
        ptr = _item_pointer(context, builder, signature.args[0], args[0], i)
        return builder.atomic_rmw("add", ptr, v, "seq_cst")

    return types.int64(array, index, value), codegen


@intrinsic
def load_acquire(typingctx, array, index):
    """``array[index]``, seeing every write another thread made before its :func:`store_release`."""
    if not (isinstance(array, types.Array) and array.dtype == types.int64 and array.ndim == 1):
        return None

    def codegen(context, builder, signature, args):
        i = context.cast(builder, args[1], signature.args[1], types.intp)
        ptr = _item_pointer(context, builder, signature.args[0], args[0], i)
        return builder.load_atomic(ptr, "acquire", 8)

    return types.int64(array, index), codegen


@intrinsic
def store_release(typingctx, array, index, value):
    """``array[index] = value`` after every write this thread made before it (see :func:`load_acquire`)."""
    if not (isinstance(array, types.Array) and array.dtype == types.int64 and array.ndim == 1):
        return None

    def codegen(context, builder, signature, args):
        i = context.cast(builder, args[1], signature.args[1], types.intp)
        v = context.cast(builder, args[2], signature.args[2], types.int64)
        ptr = _item_pointer(context, builder, signature.args[0], args[0], i)
        builder.store_atomic(v, ptr, "release", 8)
        return context.get_dummy_value()

    return types.void(array, index, value), codegen
