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


def _int64_vector(array):
    """Whether numba type ``array`` is a one-dimensional int64 array (else the intrinsic does not apply)."""
    return isinstance(array, types.Array) and array.dtype == types.int64 and array.ndim == 1


def _item_pointer(context, builder, signature, args):
    """The address of ``array[index]``, ``args = (array, index, ...)`` (no bounds check: the driver's)."""
    array_type = signature.args[0]
    index = context.cast(builder, args[1], signature.args[1], types.intp)
    ary = context.make_array(array_type)(context, builder, args[0])
    return cgutils.get_item_pointer(context, builder, array_type, ary, [index], wraparound=False)


@intrinsic
def fetch_add(typingctx, array, index, value):
    """``array[index] += value`` at once for every thread; the value before the addition."""
    if not _int64_vector(array):
        return None

    def codegen(context, builder, signature, args):
        v = context.cast(builder, args[2], signature.args[2], types.int64)
        return builder.atomic_rmw("add", _item_pointer(context, builder, signature, args), v, "seq_cst")

    return types.int64(array, index, value), codegen


@intrinsic
def load_acquire(typingctx, array, index):
    """``array[index]``, seeing every write another thread made before its :func:`store_release`."""
    if not _int64_vector(array):
        return None

    def codegen(context, builder, signature, args):
        return builder.load_atomic(_item_pointer(context, builder, signature, args), "acquire", 8)

    return types.int64(array, index), codegen


@intrinsic
def store_release(typingctx, array, index, value):
    """``array[index] = value`` after every write this thread made before it (see :func:`load_acquire`)."""
    if not _int64_vector(array):
        return None

    def codegen(context, builder, signature, args):
        v = context.cast(builder, args[2], signature.args[2], types.int64)
        builder.store_atomic(v, _item_pointer(context, builder, signature, args), "release", 8)
        return context.get_dummy_value()

    return types.void(array, index, value), codegen
