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

import numpy as np

import grazing
from grazing.gpu.batch import GpuLaneBatch
from grazing.sweeps.run import run_parts
from grazing.sweeps.spec import map_spec, sweep_spec
from tests.engine.test_lanes_sliding import diagonal

SHORT = {"transient": 64, "periods": 16, "lyapunov": False}
LYAP = {"transient": 64, "periods": 16, "lyapunov": True}
MODES = {"transient": 24, "periods": 8, "adaptive": False}


def cases() -> dict[str, list[tuple[object, int]]]:
    """Each case's chunks: ``(spec, chunk index)`` pairs that share a batch."""
    B40 = grazing.models.pendulum("B", theta_hat=math.radians(40))
    fresh = grazing.SweepSettings(**SHORT, fresh=True)
    chained = grazing.SweepSettings(**SHORT, fresh=False, chunk_size=3, phase=1.0)
    lyap = grazing.SweepSettings(**LYAP, fresh=True)
    modes = grazing.SweepSettings(**MODES, fresh=True, lyapunov=False, chunk_size=0)
    equal_work = grazing.SweepSettings(**SHORT, fresh=True, adaptive=False, tol=1e-10, chunk_size=0)
    out = {
        # fig 7's first grazing at 40 degrees: period 1 free of the stop, period 4, chaos (case B)
        "pendulum B fresh": [(sweep_spec(B40, "eta", np.linspace(0.44, 0.46, 4), settings=fresh), 0)],
        # case C, each point from the previous one's end, two chains (chunks) in one batch, sampled at phase 1
        "pendulum C chained": [
            (spec, i)
            for spec in [
                sweep_spec(
                    grazing.models.pendulum("C", theta_hat=math.radians(30)),
                    "eta",
                    np.linspace(0.40, 0.50, 6),
                    settings=chained,
                )
            ]
            for i in range(2)
        ],
        # the equal-work map's settings (no adaptive transient, tol 1e-10), eta x theta_hat, case A
        "pendulum A map": [
            (
                map_spec(
                    grazing.models.pendulum("A"),
                    "eta",
                    [0.44, 0.47],
                    "theta_hat",
                    [math.radians(30), math.radians(40)],
                    settings=equal_work,
                ),
                i,
            )
            for i in range(2)
        ],
        # a point that blows up (status non-finite) between two that do not
        "pendulum huge forcing": [
            (sweep_spec(B40, "alpha", [0.2254, 1e300], settings=fresh), 0),
        ],
        "impact oscillator": [
            (sweep_spec(grazing.models.impact_oscillator(), "omega", [2.6, 2.8, 3.0], settings=fresh), 0)
        ],
        # chattering continued as sticking from the third point on, each point from the previous one's end
        "bouncing ball": [
            (
                sweep_spec(
                    grazing.models.bouncing_ball(),
                    "amplitude",
                    [1.2, 1.5, 2.0, 2.5],
                    x0=[0.0, 3.0],
                    settings=grazing.SweepSettings(**SHORT, chunk_size=4),
                ),
                0,
            )
        ],
        # Lyapunov exponents (tangent vectors through impacts by the saltation matrix): case B at 40 degrees
        # (period 1 free of the stop, period 4, chaos), case C each point from the previous one's end, the
        # impact oscillator
        "lyapunov pendulum B": [(sweep_spec(B40, "eta", np.linspace(0.44, 0.46, 4), settings=lyap), 0)],
        "lyapunov pendulum C chained": [
            (
                sweep_spec(
                    grazing.models.pendulum("C", theta_hat=math.radians(30)),
                    "eta",
                    np.linspace(0.40, 0.50, 4),
                    settings=grazing.SweepSettings(**LYAP, fresh=False, chunk_size=0, phase=1.0),
                ),
                0,
            )
        ],
        "lyapunov impact oscillator": [
            (sweep_spec(grazing.models.impact_oscillator(), "omega", [2.6, 2.8, 3.0], settings=lyap), 0)
        ],
        # models with modes: switches of vector field without a reset (fresh, points ending in either
        # mode), Lyapunov exponents through them (each point from the previous one's end), mode-changing
        # resets (the rocking block's corners), and each point from its own start in its own mode
        "soft impact modes": [
            (sweep_spec(grazing.models.soft_impact_oscillator(), "omega", [0.9, 1.2, 1.5], settings=modes), 0)
        ],
        "lyapunov soft impact chained": [
            (
                sweep_spec(
                    grazing.models.soft_impact_oscillator(),
                    "omega",
                    [0.9, 1.2, 1.5],
                    settings=grazing.SweepSettings(**MODES, lyapunov=True, chunk_size=0),
                ),
                0,
            )
        ],
        "rocking block": [  # (accumulating impacts, then impacts on both corners at periods 1 and 0)
            (sweep_spec(grazing.models.rocking_block(), "a", [0.21, 0.22, 0.29], settings=modes), 0)
        ],
        "lyapunov rocking block chained": [
            (
                sweep_spec(
                    grazing.models.rocking_block(),
                    "a",
                    [0.22, 0.25, 0.28],
                    settings=grazing.SweepSettings(**MODES, lyapunov=True, chunk_size=0),
                ),
                0,
            )
        ],
        "soft impact start modes": [(start_modes_spec(), 0)],
        # sliding (Filippov's pseudo-mode of the friction oscillator: stick-slip), fresh and with Lyapunov
        # exponents from the previous point's end
        "friction sliding": [
            (sweep_spec(grazing.models.friction_oscillator(), "a", [0.6, 1.1, 1.6], settings=modes), 0)
        ],
        # sliding on a diagonal surface, where Filippov's field leaves it by its rounding unless each step's
        # end and sample is put back on it (tests/engine/test_lanes_sliding.py's model)
        "diagonal sliding": [
            (sweep_spec(diagonal(), "c", [0.5, 1.0, 1.5], x0=(1.0, 0.0), settings=modes), 0)
        ],
        "lyapunov friction chained": [
            (
                sweep_spec(
                    grazing.models.friction_oscillator(),
                    "mu",
                    [0.3, 0.6, 0.9],
                    settings=grazing.SweepSettings(**MODES, lyapunov=True, chunk_size=0),
                ),
                0,
            )
        ],
    }
    return out


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
    differ = sorted(name for name in cpu.data_vars if not cpu[name].equals(gpu[name]))
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
    differ = sorted(name for name in cpu.data_vars if not cpu[name].equals(gpu[name]))
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
    differ = sorted(name for name in cpu.data_vars if not cpu[name].equals(gpu[name]))
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
