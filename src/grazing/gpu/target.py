"""The CUDA target: whether there is one, and the few operations whose device form differs from Python's.

numba's ``cuda.jit`` compiles for an NVIDIA GPU (numba-cuda, the optional
``gpu`` extra), or, with ``NUMBA_ENABLE_CUDASIM=1`` set before numba is
imported, runs kernels in Python threads (numba's CUDA simulator, where CI
checks the kernels' logic).  The bits of a double and the next double after
one are libdevice calls on a device and plain Python in the simulator: the
same numbers either way.
"""

from __future__ import annotations

import os
import struct
from typing import Any

from grazing.errors import GrazingError


class NoDeviceError(GrazingError):
    """``device="gpu"`` where no CUDA device (and no simulator) is available."""


SIMULATOR_ENV = "NUMBA_ENABLE_CUDASIM"
"""Set to 1 before numba is imported to run the kernels in numba's CUDA simulator."""


def simulated() -> bool:
    """Whether numba's CUDA simulator stands in for a device (``NUMBA_ENABLE_CUDASIM=1``)."""
    from numba import config

    return bool(getattr(config, "ENABLE_CUDASIM", 0)) or os.environ.get(SIMULATOR_ENV) == "1"


def cuda_module() -> Any:
    """``numba.cuda`` (numba-cuda where installed)."""
    from numba import cuda

    return cuda


def device_present() -> bool:
    """Whether a CUDA device is usable (never in the simulator)."""
    if simulated():
        return False
    try:
        return bool(cuda_module().is_available())
    except Exception:  # (no driver, no numba-cuda: no device)
        return False


def device_name() -> str:
    """The device the kernels run on, in words (the simulator says so)."""
    if simulated():
        return "numba CUDA simulator"
    if not device_present():
        return "none"
    dev = cuda_module().get_current_device()
    name = dev.name.decode() if isinstance(dev.name, bytes) else str(dev.name)
    return f"{name} (compute capability {dev.compute_capability[0]}.{dev.compute_capability[1]})"


def require_target() -> None:
    """Raise :class:`NoDeviceError` (one line) unless a CUDA device or the simulator is there."""
    if simulated() or device_present():
        return
    raise NoDeviceError(
        "the GPU device needs an NVIDIA GPU with CUDA and numba-cuda (pip install 'grazing[gpu]'); none is "
        "available here: run on the CPU (device=)"
    )


def device_function(fn: Any) -> Any:
    """``cuda.jit(device=True)(fn)``."""
    return cuda_module().jit(device=True)(fn)


def _py_bits_of(x: float) -> int:
    """The bits of the double ``x`` as an int64 (the simulator's form)."""
    return int(struct.unpack("<q", struct.pack("<d", float(x)))[0])


def _py_double_of(bits: int) -> float:
    """The double whose bits are the int64 ``bits`` (the simulator's form)."""
    return float(struct.unpack("<d", struct.pack("<q", int(bits)))[0])


def bit_casts() -> tuple[Any, Any]:
    """``(bits_of, double_of)`` as device functions: libdevice on a device, ``struct`` in the simulator."""
    if simulated():
        return device_function(_py_bits_of), device_function(_py_double_of)
    from numba.cuda import libdevice

    def bits_of(x: float) -> int:
        return libdevice.double_as_longlong(x)

    def double_of(bits: int) -> float:
        return libdevice.longlong_as_double(bits)

    return device_function(bits_of), device_function(double_of)


def nextafter_function() -> Any:
    """``nextafter(x, y)`` as a device function: libdevice's on a device, numpy's in the simulator."""
    if simulated():
        import numpy as np

        def py_nextafter(x: float, y: float) -> float:
            return float(np.nextafter(x, y))

        return device_function(py_nextafter)
    from numba.cuda import libdevice

    def nextafter(x: float, y: float) -> float:
        return libdevice.nextafter(x, y)

    return device_function(nextafter)
