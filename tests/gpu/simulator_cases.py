"""Sweeps on the CPU lanes and on the GPU kernel under numba's CUDA simulator, side by side (run as a script).

Run by ``tests/gpu/test_simulator.py`` in a process of its own with ``NUMBA_ENABLE_CUDASIM=1`` (set
before numba is imported: the simulator must not leak into other tests).  Prints one JSON object: per
case, both sides' periods, impacts by stop, statuses, transient periods used, the largest difference of
their samples and final states, and how many points the GPU batch handed to the CPU lanes (none: sticking is
the GPU's too).
A few points and a few periods each: the simulator runs every CUDA thread as a Python thread.
"""

from __future__ import annotations

import json
import math
import os
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

import grazing
from grazing.gpu.batch import GpuLaneBatch
from grazing.sweeps.run import run_parts
from grazing.sweeps.spec import map_spec, sweep_spec
from tests.engine.test_lanes_sliding import diagonal

SHORT = {"transient": 64, "periods": 16, "lyapunov": False}
LYAP = {"transient": 64, "periods": 16, "lyapunov": True}
MODES = {"transient": 24, "periods": 8, "adaptive": False}


@dataclass(frozen=True)
class Scale:
    """How big a case is: its own few points and short settings (the default: the simulator's), or
    ``points`` spread over its range with ``transient`` and ``periods`` of their own (a real device:
    ``test_device.py``)."""

    points: int | None = None
    transient: int | None = None
    periods: int | None = None

    def values(self, few: Any) -> Any:
        """A case's parameter values: its own ``few``, or ``points`` from the least to the greatest."""
        if self.points is None:
            return few
        return np.linspace(min(few), max(few), self.points)

    def settings(self, base: dict[str, Any], **more: Any) -> grazing.SweepSettings:
        """A case's settings: ``base`` (:data:`SHORT`, :data:`LYAP`, :data:`MODES`) and ``more``, with this
        scale's transient and periods where given."""
        own = {k: v for k, v in (("transient", self.transient), ("periods", self.periods)) if v is not None}
        return grazing.SweepSettings(**{**base, **more, **own})


SIMULATOR = Scale()
"""The simulator's scale: each case's own few points and periods."""


def every_chunk(spec: Any) -> list[tuple[object, int]]:
    """The parts of every chunk of ``spec``."""
    return [(spec, i) for i in range(spec.n_chunks)]


def b40() -> grazing.HybridModel:
    """Case B at 40 degrees (fig 7)."""
    return grazing.models.pendulum("B", theta_hat=math.radians(40))


def c30() -> grazing.HybridModel:
    """Case C at 30 degrees."""
    return grazing.models.pendulum("C", theta_hat=math.radians(30))


# Each case's chunks at a scale: ``(spec, chunk index)`` pairs that share a batch.
BUILDERS: dict[str, Callable[[Scale], list[tuple[object, int]]]] = {
    # fig 7's first grazing at 40 degrees: period 1 free of the stop, period 4, chaos (case B)
    "pendulum B fresh": lambda sc: every_chunk(
        sweep_spec(b40(), "eta", sc.values(np.linspace(0.44, 0.46, 4)),
                   settings=sc.settings(SHORT, fresh=True))
    ),
    # case C, each point from the previous one's end, two chains (chunks) in one batch, sampled at phase 1
    "pendulum C chained": lambda sc: every_chunk(
        sweep_spec(c30(), "eta", sc.values(np.linspace(0.40, 0.50, 6)),
                   settings=sc.settings(SHORT, fresh=False, chunk_size=3, phase=1.0))
    ),
    # the equal-work map's settings (no adaptive transient, tol 1e-10), eta x theta_hat, case A
    "pendulum A map": lambda sc: every_chunk(
        map_spec(grazing.models.pendulum("A"), "eta", sc.values([0.44, 0.47]), "theta_hat",
                 [math.radians(30), math.radians(40)],
                 settings=sc.settings(SHORT, fresh=True, adaptive=False, tol=1e-10, chunk_size=0))
    ),
    # a point that blows up (status non-finite) between two that do not
    "pendulum huge forcing": lambda sc: every_chunk(
        sweep_spec(b40(), "alpha", [0.2254, 1e300], settings=sc.settings(SHORT, fresh=True))
    ),
    "impact oscillator": lambda sc: every_chunk(
        sweep_spec(grazing.models.impact_oscillator(), "omega", sc.values([2.6, 2.8, 3.0]),
                   settings=sc.settings(SHORT, fresh=True))
    ),
    # chattering continued as sticking from the third point on, each point from the previous one's end
    "bouncing ball": lambda sc: [
        (sweep_spec(grazing.models.bouncing_ball(), "amplitude", sc.values([1.2, 1.5, 2.0, 2.5]),
                    x0=[0.0, 3.0], settings=sc.settings(SHORT, chunk_size=sc.points or 4)), 0)
    ],
    # Lyapunov exponents (tangent vectors through impacts by the saltation matrix): case B at 40 degrees
    # (period 1 free of the stop, period 4, chaos), case C each point from the previous one's end, the
    # impact oscillator
    "lyapunov pendulum B": lambda sc: every_chunk(
        sweep_spec(b40(), "eta", sc.values(np.linspace(0.44, 0.46, 4)),
                   settings=sc.settings(LYAP, fresh=True))
    ),
    "lyapunov pendulum C chained": lambda sc: every_chunk(
        sweep_spec(c30(), "eta", sc.values(np.linspace(0.40, 0.50, 4)),
                   settings=sc.settings(LYAP, fresh=False, chunk_size=0, phase=1.0))
    ),
    "lyapunov impact oscillator": lambda sc: every_chunk(
        sweep_spec(grazing.models.impact_oscillator(), "omega", sc.values([2.6, 2.8, 3.0]),
                   settings=sc.settings(LYAP, fresh=True))
    ),
    # models with modes: switches of vector field without a reset (fresh, points ending in either
    # mode), Lyapunov exponents through them (each point from the previous one's end), mode-changing
    # resets (the rocking block's corners), and each point from its own start in its own mode
    "soft impact modes": lambda sc: every_chunk(
        sweep_spec(grazing.models.soft_impact_oscillator(), "omega", sc.values([0.9, 1.2, 1.5]),
                   settings=sc.settings(MODES, fresh=True, lyapunov=False, chunk_size=0))
    ),
    "lyapunov soft impact chained": lambda sc: every_chunk(
        sweep_spec(grazing.models.soft_impact_oscillator(), "omega", sc.values([0.9, 1.2, 1.5]),
                   settings=sc.settings(MODES, lyapunov=True, chunk_size=0))
    ),
    # accumulating impacts, then impacts on both corners at periods 1 and 0
    "rocking block": lambda sc: every_chunk(
        sweep_spec(grazing.models.rocking_block(), "a", sc.values([0.21, 0.22, 0.29]),
                   settings=sc.settings(MODES, fresh=True, lyapunov=False, chunk_size=0))
    ),
    "lyapunov rocking block chained": lambda sc: every_chunk(
        sweep_spec(grazing.models.rocking_block(), "a", sc.values([0.22, 0.25, 0.28]),
                   settings=sc.settings(MODES, lyapunov=True, chunk_size=0))
    ),
    "soft impact start modes": lambda sc: [(start_modes_spec(), 0)],  # (its own three starts, at any scale)
    # sliding (Filippov's pseudo-mode of the friction oscillator: stick-slip), fresh and with Lyapunov
    # exponents from the previous point's end
    "friction sliding": lambda sc: every_chunk(
        sweep_spec(grazing.models.friction_oscillator(), "a", sc.values([0.6, 1.1, 1.6]),
                   settings=sc.settings(MODES, fresh=True, lyapunov=False, chunk_size=0))
    ),
    # sliding on a diagonal surface, where Filippov's field leaves it by its rounding unless each step's
    # end and sample is put back on it (tests/engine/test_lanes_sliding.py's model)
    "diagonal sliding": lambda sc: every_chunk(
        sweep_spec(diagonal(), "c", sc.values([0.5, 1.0, 1.5]), x0=(1.0, 0.0),
                   settings=sc.settings(MODES, fresh=True, lyapunov=False, chunk_size=0))
    ),
    "lyapunov friction chained": lambda sc: every_chunk(
        sweep_spec(grazing.models.friction_oscillator(), "mu", sc.values([0.3, 0.6, 0.9]),
                   settings=sc.settings(MODES, lyapunov=True, chunk_size=0))
    ),
}  # fmt: skip


def cases(scale: Scale = SIMULATOR) -> dict[str, list[tuple[object, int]]]:
    """Each case's chunks (:data:`BUILDERS`) at ``scale``: ``(spec, chunk index)`` pairs sharing a batch."""
    return {name: build(scale) for name, build in BUILDERS.items()}


def start_modes_spec() -> object:
    """A fresh sweep of the soft-impact oscillator, each point from its own state: two in contact (mode 1),
    one free (mode 0)."""
    import dataclasses

    m = grazing.models.soft_impact_oscillator()
    gap = m.params["gap"]
    starts = np.array([[gap + 0.2, -0.5], [0.0, 0.0], [gap + 0.1, 0.3]])
    settings = grazing.SweepSettings(transient=1, periods=4, adaptive=False, fresh=True, lyapunov=False)
    spec = sweep_spec(m, "omega", [1.0, 1.0, 1.0], settings=settings)
    return dataclasses.replace(spec, starts=starts, start_modes=np.array([1, 0, 1]), chunk_size=0)


def compare(parts: list[tuple[object, int]]) -> dict[str, object]:
    """Both sides of one case."""
    cpu = run_parts(parts)
    batch = GpuLaneBatch(parts)
    handed: list[int] = []  # (the points of each call of the CPU lanes while the GPU batch runs)
    run_jobs = batch.run_jobs

    def counted(work: object) -> None:
        handed.append(int(sum(b - a for a, b in work.jobs)))
        run_jobs(work)

    batch.run_jobs = counted  # type: ignore[method-assign]
    batch.run()
    gpu = batch.results(range(len(parts)))
    row: dict[str, object] = {"cpu_points": sum(handed)}
    for name in ("period", "impacts_by_stop", "status", "transient_used", "impacts", "mode_final"):
        row[f"cpu_{name}"] = np.concatenate([getattr(r, name) for r in cpu]).tolist()
        row[f"gpu_{name}"] = np.concatenate([getattr(r, name) for r in gpu]).tolist()
    for name in ("samples", "x_final", "lyapunov"):
        a = np.concatenate([getattr(r, name) for r in cpu])
        b = np.concatenate([getattr(r, name) for r in gpu])
        same_nans = np.array_equal(np.isnan(a), np.isnan(b))  # (a NaN on one side only: inf)
        row[f"{name}_diff"] = float(np.nanmax(np.abs(a - b), initial=0.0)) if same_nans else math.inf
    row["cpu_lyapunov_values"] = np.concatenate([r.lyapunov for r in cpu]).tolist()
    return row


def differing(cpu: Any, gpu: Any) -> list[str]:
    """The variables of two datasets that are not equal (to the bit, NaN where NaN), or in one only."""
    names = set(cpu.data_vars) | set(gpu.data_vars)
    return sorted(name for name in names if not (name in cpu and name in gpu and cpu[name].equals(gpu[name])))


def foreign_names() -> list[str]:
    """Names the device code reads that are neither device functions nor constants (nor ``math``)."""
    import types

    from grazing.gpu.model import model_functions
    from grazing.gpu.ported import device_helpers

    def python_function(obj: object) -> object:
        return getattr(obj, "py_func", None) or getattr(obj, "fn", None)

    found = set()
    spaces = [device_helpers()["namespace"]]
    for model in (grazing.models.pendulum("B"), grazing.models.bouncing_ball()):
        fns = model_functions(model._def, 13).functions
        spaces.append(python_function(next(iter(fns.values()))).__globals__)
    for space in spaces:
        for value in list(space.values()):
            fn = python_function(value)
            if not isinstance(fn, types.FunctionType) or fn.__module__ == "grazing.gpu.target":
                continue  # (target's are the simulator's forms of libdevice calls)
            for name in fn.__code__.co_names:
                obj = fn.__globals__.get(name)
                device = python_function(obj) is not None
                constant = isinstance(obj, (int, float, np.ndarray)) or obj is math
                if name in fn.__globals__ and not (device or constant):
                    found.add(f"{fn.__name__}: {name}")
    return sorted(found)


def api_map() -> dict[str, object]:
    """``parameter_map(device="gpu")`` against ``device="cpu"``: every variable of the two datasets."""
    from grazing.sweeps import parameter_map

    args = (grazing.models.pendulum("B"), "eta", [0.44, 0.46], "theta_hat", np.radians([30.0, 40.0]))
    kw = {"transient": 64, "periods": 16, "lyapunov": False, "workers": 1}
    cpu = parameter_map(*args, **kw, device="cpu")
    gpu = parameter_map(*args, **kw, device="gpu")
    differ = differing(cpu, gpu)
    return {"differ": differ, "variables": sorted(cpu.data_vars), "period": cpu.period.values.tolist()}


def api_basins() -> dict[str, object]:
    """``basins(device="gpu")`` against ``device="cpu"`` (the orbits' Lyapunov runs on the GPU too): every
    variable of the two datasets."""
    from grazing.attractors import basins

    model = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    args = (model, (-1.5, math.radians(40)), (-2.0, 2.0), (3, 3))
    kw = {"transient": 64, "periods": 16, "workers": 1}
    cpu = basins(*args, **kw, device="cpu")
    launched: list[int] = []  # (the points of each GPU launch with Lyapunov exponents)
    run = GpuLaneBatch.run

    def counted(batch: GpuLaneBatch) -> None:
        if batch._spec0.lyapunov:
            launched.append(len(batch.status))
        run(batch)

    GpuLaneBatch.run = counted  # type: ignore[method-assign]
    try:
        gpu = basins(*args, **kw, device="gpu")
    finally:
        GpuLaneBatch.run = run  # type: ignore[method-assign]
    differ = differing(cpu, gpu)
    return {"differ": differ, "variables": sorted(cpu.data_vars), "kinds": cpu.kind.values.tolist(),
            "lyapunov_on_gpu": launched, "lyapunov": cpu.lyapunov.values.tolist()}  # fmt: skip


def api_basins_modes() -> dict[str, object]:
    """``basins(device="gpu")`` against ``device="cpu"`` on a model with modes (a grid of initial states on
    both sides of the soft impact's contact, each point in its own mode): every variable, and the points
    the GPU launched."""
    from grazing.attractors import basins

    args = (grazing.models.soft_impact_oscillator(), (-1.5, 1.5), (-1.0, 1.0), (3, 3))
    kw = {"transient": 24, "periods": 8, "workers": 1}
    cpu = basins(*args, **kw, device="cpu")
    launched: list[int] = []
    run = GpuLaneBatch.run

    def counted(batch: GpuLaneBatch) -> None:
        launched.append(len(batch.status))
        run(batch)

    GpuLaneBatch.run = counted  # type: ignore[method-assign]
    try:
        gpu = basins(*args, **kw, device="gpu")
    finally:
        GpuLaneBatch.run = run  # type: ignore[method-assign]
    differ = differing(cpu, gpu)
    return {"differ": differ, "launched": launched}


def main(names: list[str]) -> None:
    table = cases()
    out: dict[str, object] = {name: compare(table[name]) for name in (names or list(table))}
    out["foreign names"] = foreign_names()
    out["api map"] = api_map()
    out["api basins"] = api_basins()
    out["api basins modes"] = api_basins_modes()
    print(json.dumps(out))


if __name__ == "__main__":
    if os.environ.get("NUMBA_ENABLE_CUDASIM") != "1":
        sys.exit("run with NUMBA_ENABLE_CUDASIM=1 (set before numba is imported)")
    main(sys.argv[1:])
