"""A sweep's chunks on the GPU: the CPU lanes' batch, its points computed by the CUDA kernel.

:class:`GpuLaneBatch` is a :class:`~grazing.sweeps.run.LaneBatch` (the same
table of points, jobs and result arrays, the same :meth:`results`: period
detection, polishing and the :class:`~grazing.sweeps.spec.ChunkResult` records
are the CPU's, not a copy) whose :meth:`run` launches
:func:`grazing.gpu.kernel.build_kernel`'s kernel, one thread per job: every
point is the kernel's (chattering and sticking among them).

A carried sweep whose chains have several chunks is settled into its chains
(:func:`grazing.sweeps.chain.settle`) as on the CPU, its rounds' chunks,
checks, shifts and runs computed by :func:`gpu_parts`.

Lyapunov exponents are the kernel's too (its variational build), and so is
the discontinuity map (its build with the map, from the settings the CPU
lanes get: :meth:`~grazing.sweeps.run.LaneBatch.settings`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np

from grazing.core.options import LYAPUNOV_ALIGN
from grazing.sweeps.run import LaneBatch, batch_key
from grazing.sweeps.spec import ChunkResult, SweepSpec

Part = tuple[SweepSpec, int]
"""A chunk of a sweep: the spec and the chunk's index."""
THREADS_PER_BLOCK = 128
"""CUDA threads per block of the sweep kernel."""
BATCH_POINTS = 1 << 20
"""Most points of one launch of :func:`gpu_parts` (their samples: 1.6 GB at 100 periods of 2 states)."""
MAX_THREADS = 1 << 17
"""Most threads of one launch: each takes jobs until none is left, with a root-search work array of its
own (33 kB: 4.4 GB for this many)."""


class GpuLaneBatch(LaneBatch):
    """A :class:`~grazing.sweeps.run.LaneBatch` computed by the GPU kernel (see the module).

    ``threads`` caps the threads of a launch (default :data:`MAX_THREADS`).
    """

    def __init__(self, parts: Sequence[tuple[SweepSpec, int]], threads: int | None = None) -> None:
        from grazing.gpu.target import require_target

        require_target()
        super().__init__(parts)
        self.max_threads = MAX_THREADS if threads is None else max(1, int(threads))

    def run(self) -> None:
        """Compute the batch's points on the GPU."""
        from grazing.engine.runner import step_safety
        from grazing.engine.stepping import step_factor
        from grazing.gpu.kernel import ROOT_WORK, keep_rows, sweep_kernel
        from grazing.gpu.target import cuda_module

        spec = self._spec0
        cuda = cuda_module()
        cfg = self.settings(len(self.jobs))  # (the discontinuity map's settings, as the lanes get them)
        zdm_stop = cfg.stop if cfg.zdm else -1
        zset = np.array([cfg.zdm_a, cfg.zdm_window, *cfg.zdm_e], dtype=np.float64)  # (kernel.ZDM_A ...)
        kernel = sweep_kernel(
            spec.model._def, self._order, keep_rows(spec.periods), bool(spec.lyapunov), zdm_stop
        )
        njobs = len(self.jobs)
        threads = min(njobs, self.max_threads)
        align = min(LYAPUNOV_ALIGN, spec.transient) if spec.lyapunov else 0  # (as the lanes')
        iset = np.array(
            [self.fresh, spec.model.periodic, spec.transient - align, spec.periods, spec.adaptive, align],
            dtype=np.int64,
        )
        factor = step_factor(step_safety(spec.tol, self._order), self._order)
        fset = np.array([spec.adaptive_tol, factor, spec.chatter_tol], dtype=np.float64)
        outputs = (self.samples, self.by_stop, self.lyap, self.used, self.x_final, self.t_final,
                   self.vf_final, self.status)  # fmt: skip
        counter = np.zeros(1, dtype=np.int64)  # (the next job)
        inputs = (self.jobs, counter, self.x0, self.firsts, self.first_vf, self.x0_vf, self.pvs, self.Ts,
                  self.sphase, self.tcarry)  # fmt: skip
        d_in = [cuda.to_device(np.ascontiguousarray(a)) for a in inputs]
        d_out = [cuda.to_device(a) for a in outputs]
        work = cuda.device_array((threads, *ROOT_WORK), dtype=np.float64)
        per_block = min(THREADS_PER_BLOCK, threads)
        blocks = math.ceil(threads / per_block)
        kernel[blocks, per_block](*d_in, *d_out, work, cuda.to_device(iset), cuda.to_device(fset),
                                  cuda.to_device(self.zdms), cuda.to_device(zset))  # fmt: skip
        cuda.synchronize()
        for host, dev in zip(outputs, d_out):
            dev.copy_to_host(host)


def run_parts_gpu(parts: Sequence[tuple[SweepSpec, int]], threads: int | None = None) -> list[ChunkResult]:
    """:func:`grazing.sweeps.run.run_parts` on the GPU: the chunks ``parts`` computed together; in order."""
    start = time.perf_counter()
    batch = GpuLaneBatch(parts, threads)
    batch.run()
    results = batch.results(range(len(parts)))
    seconds = time.perf_counter() - start
    for res in results:
        res.seconds = seconds / len(results)
    return results


def gpu_results(
    spec: SweepSpec, indices: Sequence[int], max_points: int = BATCH_POINTS
) -> Iterator[ChunkResult]:
    """The results of the chunks ``indices`` of ``spec`` computed on the GPU, in that order, a batch of
    at most ``max_points`` points at a time (at least one chunk)."""
    for _, res in gpu_parts([(spec, i) for i in indices], max_points):
        yield res


def gpu_parts(parts: Sequence[Part], max_points: int = BATCH_POINTS) -> Iterator[tuple[Part, ChunkResult]]:
    """Each of ``parts`` (the caller's own tuples) with its result computed on the GPU: the parts that share
    a :func:`~grazing.sweeps.run.batch_key` in their order, a launch of at most ``max_points`` points at a
    time (at least one part).  What :func:`grazing.sweeps.chain.settle` computes a carried sweep's rounds
    with on the GPU, as :func:`grazing.sweeps.executor.local_results` does on the cores.

    Examples
    --------
    No parts, no launch (and no device needed):

    >>> list(gpu_parts([]))
    []
    """
    groups: dict[tuple[Any, ...], list[Part]] = {}
    for part in parts:
        groups.setdefault(batch_key(part[0]), []).append(part)
    for group in groups.values():
        batch: list[Part] = []
        size = 0
        for part in group:
            chunk = part[0].chunk(part[1])
            batch.append(part)
            size += chunk.stop - chunk.start
            if size >= max_points:
                yield from zip(batch, run_parts_gpu(batch))
                batch, size = [], 0
        if batch:
            yield from zip(batch, run_parts_gpu(batch))


def gpu_chain_window(spec: SweepSpec, memory: bool) -> int:
    """Most chunks of the carried sweep ``spec`` held at a time while they are settled on the GPU
    (:func:`grazing.sweeps.chain.settle`; its results do not depend on it): all of them when the results are
    kept in memory anyway, else a launch's worth (:data:`BATCH_POINTS` points).

    Examples
    --------
    >>> import grazing
    >>> from grazing.sweeps.spec import sweep_spec
    >>> spec = sweep_spec(grazing.models.pendulum("B"), "eta", [0.44, 0.45, 0.46])
    >>> gpu_chain_window(spec, memory=False) == BATCH_POINTS // spec.size
    True
    >>> gpu_chain_window(spec, memory=True) > 10**9
    True
    """
    if memory:
        return 1 << 62
    return max(1, BATCH_POINTS // spec.size)


def run_chunks_gpu(spec: SweepSpec, indices: Sequence[int], threads: int | None = None) -> list[ChunkResult]:
    """:func:`grazing.sweeps.run.run_chunks` on the GPU: the chunks ``indices`` of ``spec``, in that order."""
    return run_parts_gpu([(spec, i) for i in indices], threads)
