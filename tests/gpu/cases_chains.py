"""Carried sweeps of several chunks a chain on the CPU and on the GPU under numba's CUDA simulator (a script).

Run by ``tests/gpu/test_simulator_chains.py`` in a process of its own with ``NUMBA_ENABLE_CUDASIM=1`` (as
``simulator_cases.py``).  Each case is one sweep run by :func:`grazing.sweeps.api.run_sweep` with
``device="cpu"`` and with ``device="gpu"``: both settle the chunks into the chain
(:func:`grazing.sweeps.chain.settle`), the GPU's rounds computed by the kernel.  Prints one JSON object:
per case, the variables of the two datasets that differ, the periods and statuses, the parts each round
launched on the GPU (first points checked, chunks run again or shifted), how many chunks' guesses (run
from ``x0``) are not the chain's, and the periods of the one-chunk chain on the CPU.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import os
import sys
from collections.abc import Iterator
from typing import Any

import numpy as np

import grazing
import grazing.gpu.batch as gpu_batch
from grazing.sweeps.api import run_sweep
from grazing.sweeps.run import run_parts
from grazing.sweeps.spec import SweepSpec, sweep_spec
from tests.gpu.simulator_cases import SHORT, differing


def case_c(direction: str = "up") -> SweepSpec:
    """Case C at 30 degrees from period 1 through periods 3 and 2 and back, sampled at phase 1, two points a
    chunk: the guesses of the chunks in the periodic window end at another point of the orbit, or on another
    orbit, than the chain does (so they are shifted or run again)."""
    model = grazing.models.pendulum("C", theta_hat=math.radians(30))
    settings = grazing.SweepSettings(**SHORT, fresh=False, chunk_size=2, phase=1.0)
    return sweep_spec(model, "eta", np.linspace(0.40, 0.50, 6), settings=settings, direction=direction)


def cases() -> dict[str, SweepSpec]:
    """The carried sweeps compared."""
    return {"pendulum C both directions": case_c("both")}


def launched_parts(spec: SweepSpec, launches: list[list[tuple[Any, int]]]) -> list[dict[str, int]]:
    """Per launch of the GPU, its parts: chunks of ``spec`` (guesses, from ``x0``), first points checked from
    a chain's start, and chunks run from a start (again, or shifted along an orbit)."""
    rows = []
    for parts in launches:
        derived = [s for s, _ in parts if s is not spec]
        rows.append({
            "guesses": len(parts) - len(derived),
            "checks": sum(1 for s in derived if s.n_points == 1),
            "runs": sum(1 for s in derived if s.n_points > 1),
            "from_start": sum(1 for s in derived if s.resume is not None),
        })  # fmt: skip
    return rows


def missed_guesses(spec: SweepSpec, settled: Any) -> int:
    """How many chunks' guesses (each chunk run from ``x0`` on the CPU lanes) differ from the chain's results
    ``settled`` (the dataset's points in visiting order) in their samples or periods."""
    flat_samples = np.asarray(settled.samples.values).reshape(spec.n_points, spec.periods, -1)
    flat_period = np.asarray(settled.period.values).reshape(spec.n_points)
    if "direction" in settled.period.dims:  # (each direction sorted by value: down is visited the other way)
        half = spec.n_points // 2
        flat_samples = np.concatenate([flat_samples[:half], flat_samples[half:][::-1]])
        flat_period = np.concatenate([flat_period[:half], flat_period[half:][::-1]])
    missed = 0
    for res in run_parts([(spec, i) for i in range(spec.n_chunks)]):
        sl = spec.chunk(res.index)
        same = np.array_equal(res.samples, flat_samples[sl], equal_nan=True)
        missed += not (same and res.period.tolist() == flat_period[sl].tolist())
    return missed


@contextlib.contextmanager
def counting_launches() -> Iterator[list[list[tuple[Any, int]]]]:
    """The parts of each launch of the GPU (:func:`~grazing.gpu.batch.run_parts_gpu`) while in the block."""
    launches: list[list[tuple[Any, int]]] = []
    run = gpu_batch.run_parts_gpu

    def counted(parts: Any, threads: int | None = None) -> Any:
        launches.append(list(parts))
        return run(parts, threads)

    gpu_batch.run_parts_gpu = counted  # type: ignore[assignment]
    try:
        yield launches
    finally:
        gpu_batch.run_parts_gpu = run  # type: ignore[assignment]


def compare(spec: SweepSpec) -> dict[str, object]:
    """``run_sweep(device="gpu")`` against ``device="cpu"`` on ``spec``, with the GPU's launches."""
    cpu = run_sweep(spec, workers=1, device="cpu")
    with counting_launches() as launches:
        gpu = run_sweep(spec, device="gpu")
    whole = run_sweep(dataclasses.replace(spec, chunk_size=0), workers=1, device="cpu")
    return {
        "differ": differing(cpu, gpu),
        "variables": sorted(cpu.data_vars),
        "cpu_period": cpu.period.values.tolist(),
        "gpu_period": gpu.period.values.tolist(),
        "cpu_status": cpu.status.values.tolist(),
        "whole_period": whole.period.values.tolist(),
        "launches": launched_parts(spec, launches),
        "missed_guesses": missed_guesses(spec, cpu),
        "n_chunks": spec.n_chunks,
        "segments": spec.segments,
    }


def stored(spec: SweepSpec) -> dict[str, object]:
    """``run_sweep(device="gpu")`` into a Zarr store, one chunk held at a time (:func:`~grazing.gpu.batch.
    gpu_chain_window` with a launch of one chunk's points), against ``device="cpu"`` in memory."""
    import tempfile
    from pathlib import Path

    cpu = run_sweep(spec, workers=1, device="cpu")
    batch_points = gpu_batch.BATCH_POINTS
    gpu_batch.BATCH_POINTS = spec.size
    try:
        window = gpu_batch.gpu_chain_window(spec, False)
        with tempfile.TemporaryDirectory() as tmp, counting_launches() as launches:
            gpu = run_sweep(spec, store=Path(tmp) / "chain.zarr", device="gpu").load()
    finally:
        gpu_batch.BATCH_POINTS = batch_points
    return {"differ": differing(cpu, gpu), "window": window, "launches": launched_parts(spec, launches)}


def batched(spec: SweepSpec) -> dict[str, object]:
    """:func:`~grazing.gpu.batch.gpu_parts` in launches of at most one point, against the CPU lanes: each part
    handed back (the caller's own tuple, in order) with its result."""
    from grazing.sweeps.chain import from_start

    start = (0.5, (-0.1, 0.0))  # (a chain's start: a chunk run from there, its first point checked there)
    parts = [(spec, 1), from_start(spec, 2, start), from_start(spec, 0, start, 1)]
    cpu = run_parts(parts)
    got = list(gpu_batch.gpu_parts(parts, max_points=1))
    same = [
        all(np.array_equal(getattr(a, name), getattr(b, name), equal_nan=True) for name in RESULT_FIELDS)
        for a, (_, b) in zip(cpu, got)
    ]
    return {"same_parts": [p is q for p, (q, _) in zip(parts, got)], "same_results": same}


RESULT_FIELDS = ("samples", "period", "impacts_by_stop", "status", "x_final", "t_final", "transient_used")
"""The fields of a chunk's result compared."""


def main(names: list[str]) -> None:
    table = cases()
    out: dict[str, object] = {name: compare(table[name]) for name in (names or list(table))}
    out["stored"] = stored(case_c())
    out["batched"] = batched(case_c())
    print(json.dumps(out))


if __name__ == "__main__":
    if os.environ.get("NUMBA_ENABLE_CUDASIM") != "1":
        sys.exit("run with NUMBA_ENABLE_CUDASIM=1 (set before numba is imported)")
    main(sys.argv[1:])
