"""Where a sweep runs: ``device="cpu"`` (the default), ``"gpu"`` or ``"auto"``.

``"auto"`` is the CPU unless a CUDA device is present and the sweep has at
least :data:`AUTO_MIN_POINTS` points.  ``"gpu"`` where no device (and no
simulator) is available is an error of one line.  Every sweep runs on the GPU:
Lyapunov exponents, sticking, models with modes, the discontinuity map and
chains of several chunks included.
"""

from __future__ import annotations

from typing import Any

from grazing.errors import InvalidParameterError

DEVICES = ("cpu", "gpu", "auto")
"""The values of ``device``."""
DEFAULT_DEVICE = "cpu"
"""Where a sweep runs unless told otherwise."""
AUTO_MIN_POINTS = 20_000
"""Fewest points for which ``device="auto"`` takes a present GPU (fewer finish in seconds on the cores)."""


def check_device(device: str, client: Any = None) -> None:
    """One line (:class:`~grazing.errors.InvalidParameterError`, or
    :class:`~grazing.gpu.target.NoDeviceError`) unless ``device`` can be used at all."""
    from grazing.gpu.target import require_target

    if device not in DEVICES:
        raise InvalidParameterError(f"device must be 'cpu', 'gpu' or 'auto', got {device!r}")
    if device == "gpu":
        if client is not None:
            raise InvalidParameterError("the GPU runs on this machine: give no Dask client (client=)")
        require_target()


def spec_device(device: str, spec: Any, client: Any = None) -> str:
    """``"cpu"`` or ``"gpu"``: where one of several sweeps of a computation runs (``device`` checked by
    :func:`check_device`): the GPU for ``"gpu"``, or ``"auto"`` with a device present and a large sweep,
    """
    from grazing.gpu.target import device_present

    if device == "cpu" or client is not None:
        return "cpu"
    if device == "gpu":
        return "gpu"
    return "gpu" if spec.n_points >= AUTO_MIN_POINTS and device_present() else "cpu"


def resolve_device(device: str, spec: Any, client: Any = None) -> str:
    """``"cpu"`` or ``"gpu"``: where ``spec`` runs for ``device`` (see the module).

    Examples
    --------
    >>> import grazing
    >>> from grazing.sweeps.spec import sweep_spec
    >>> spec = sweep_spec(grazing.models.pendulum("B"), "eta", [0.44, 0.45])
    >>> resolve_device("auto", spec), resolve_device("cpu", spec)
    ('cpu', 'cpu')
    >>> resolve_device("tpu", spec)
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: device must be 'cpu', 'gpu' or 'auto', got 'tpu'
    """
    check_device(device, client)
    return spec_device(device, spec, client)
