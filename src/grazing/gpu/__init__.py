"""Sweeps on an NVIDIA GPU, one CUDA thread per point, from the same generated model as the CPU kernels.

* :mod:`.target` -- whether a device (or numba's CUDA simulator) is there, and the device forms of the
  few operations that differ from Python's;
* :mod:`.ported` -- the CPU driver's step size, event location and period test as device functions,
  made from their own source;
* :mod:`.model` -- a model's generated functions as device functions;
* :mod:`.tangent` -- the Lyapunov vectors' step and the saltation matrix at an impact or a switch;
* :mod:`.kernel` -- the sweep kernel (impacts, switches of mode, sliding, Lyapunov exponents);
* :mod:`.batch` -- a sweep's chunks on the GPU, as the CPU lanes' :class:`~grazing.sweeps.run.LaneBatch`.

Nothing here is imported by the CPU path; numba-cuda (the ``gpu`` extra) is needed only on a device.
"""
