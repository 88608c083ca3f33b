"""The report's figures built side by side: independent figures on a process per core.

A figure is a few seconds of sweeps and continuations followed by drawing and
writing files; much of it runs on one core.  :func:`build_figures` therefore
hands the figures to a pool of processes (:func:`grazing.parallel.map_unordered`:
workers that die with the parent, stopped at once on Ctrl-C), each of which
builds its figures and keeps each result as ``results/<id>.json``.  The same
workers first compile (or, when cached, load) the kernel modules the figures
use, :data:`KERNELS`, shared among them, before any figure starts: each module
is compiled once, in parallel, and loaded once per worker.  Figures that
reuse another's computations in one process (fig 10 redraws fig 7's panel
sweeps, see ``BUILT_AFTER`` of a figure module) form one job, built in page
order.  The progress messages of the workers are relayed to the caller's
``progress`` in this process.

Examples
--------
>>> from grazing.report import FIGURES
>>> [[m.FIGURE_ID for m in g] for g in groups(FIGURES) if len(g) > 1]
[['7', '10']]
"""

from __future__ import annotations

import json
import os
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from datetime import datetime
from pathlib import Path
from types import ModuleType
from typing import Any

import grazing
from grazing.atomic import write_text_atomic
from grazing.core.options import SWEEP_TOL
from grazing.report.base import FigureResult, Say, number_rows

RESULTS = "results"
"""The folder of ``out`` holding each built figure's :class:`FigureResult` as ``<id>.json``."""

KERNELS: tuple[tuple[str, Any], ...] = (
    ("sweep", None),
    ("flow", SWEEP_TOL),
    ("tangent", ()),
    ("tangent", ("eta", "theta_hat")),
)
"""The kernel modules the figures use, the longest to compile first: the sweep driver (one for
every model), the flow at the sweeps' tolerance (its Taylor order differs from the default one),
and the tangent flows without and with parameter directions (one module serves one or two
parameters, see :func:`grazing.engine.codegen.direction_columns`)."""

RELAY_INTERVAL = 0.05
"""Seconds between two looks at the workers' messages."""

_RELAY: Any = None
"""In a worker: the queue that carries progress messages to the parent."""


def groups(modules: Sequence[ModuleType]) -> list[list[ModuleType]]:
    """The figures in jobs: a figure whose ``BUILT_AFTER`` figure is among ``modules`` joins its job.

    Page order is kept within each job and between the jobs' first figures.
    """
    jobs: list[list[ModuleType]] = []
    job_of: dict[str, int] = {}
    for m in modules:
        lead = getattr(m, "BUILT_AFTER", None)
        if lead in job_of:
            job_of[m.FIGURE_ID] = job_of[lead]
            jobs[job_of[lead]].append(m)
        else:
            job_of[m.FIGURE_ID] = len(jobs)
            jobs.append([m])
    return jobs


def build_one(module: ModuleType, out: Path, say: Say, commit: str) -> FigureResult:
    """Build one figure into ``out`` and keep its result as ``results/<id>.json`` (written at once)."""
    res = module.build(out, say)
    res = replace(
        res,
        comparisons=number_rows(res.figure_id, res.comparisons),
        built=datetime.now().astimezone().isoformat(timespec="seconds"),
        commit=commit,
    )
    text = json.dumps(res.to_json(), ensure_ascii=False)
    write_text_atomic(out / RESULTS / f"{res.figure_id}.json", lambda fh: fh.write(text))
    return res


def load_kernel(job: tuple[str, Any]) -> None:
    """Compile (or load) one kernel module of :data:`KERNELS` in this process."""
    import numpy as np

    from grazing.engine.runner import Runner

    kind, arg = job
    model = grazing.models.pendulum("B", eta=0.4, theta_hat=0.5)
    if kind == "sweep":
        from grazing.engine.native import load_sweep_lanes

        load_sweep_lanes()
    elif kind == "flow":
        grazing.simulate(model, [0.0, 0.0], periods=1, tol=arg)
    else:
        Runner(model, np.zeros(model.n_states), variational=True, sensitivities=arg).advance(1, 1)


def _init(parent_pid: int, relay: Any) -> None:
    """Worker initializer: die with the parent, leave Ctrl-C to it, send messages through ``relay``."""
    from grazing.parallel import init_worker

    global _RELAY
    init_worker(parent_pid)
    _RELAY = relay


def _build_job(job: tuple[str, tuple[str, ...], str]) -> list[tuple[str, float]]:
    """In a worker: build the figures ``ids`` into ``out``; each one's id and seconds."""
    from grazing.report import FIGURES

    out, ids, commit = job
    by_id = {m.FIGURE_ID: m for m in FIGURES}
    return [(i, build_one(by_id[i], Path(out), _RELAY.put, commit).seconds) for i in ids]


def _run(job: tuple[Callable[[Any], Any], Any]) -> Any:
    fn, arg = job
    return fn(arg)


def _relay(queue: Any, say: Callable[[str], None], stop: threading.Event) -> None:
    """Pass the messages of ``queue`` to ``say`` until ``stop`` is set and the queue is empty.

    Only this thread reads the queue; the parent never waits on its write lock,
    which a worker killed on Ctrl-C may hold for ever.
    """
    while True:
        if not queue.empty():
            say(queue.get())
        elif stop.is_set():
            return
        else:
            stop.wait(RELAY_INTERVAL)


def build_figures(
    modules: Sequence[ModuleType], out: Path, say: Say, commit: str, workers: int | None = None
) -> float:
    """Compile the :data:`KERNELS`, then build ``modules`` into ``out``, on up to ``workers`` processes.

    ``workers`` defaults to one per core.  Each figure's result is kept in
    ``out/results`` as it finishes; ``say`` receives every progress message,
    ``kernels ready in <s> s`` and ``figure <id> done in <s> s``.  With one
    worker, everything runs in this process.

    Returns
    -------
    float
        Seconds until the kernels were ready.
    """
    start = time.perf_counter()
    jobs = groups(modules)
    n = min(workers or os.cpu_count() or 1, max(len(jobs), len(KERNELS)))
    if n <= 1:
        for kernel in KERNELS:
            load_kernel(kernel)
        ready = time.perf_counter() - start
        say(f"kernels ready in {ready:.1f} s")
        for module in modules:
            res = build_one(module, out, say, commit)
            say(f"figure {module.FIGURE_ID} done in {res.seconds:.1f} s")
        return ready
    import multiprocessing as mp

    from grazing.parallel import map_unordered

    method = "fork" if "fork" in mp.get_all_start_methods() else "spawn"
    queue = mp.get_context(method).SimpleQueue()
    stop = threading.Event()
    relay = threading.Thread(target=_relay, args=(queue, say, stop), name="grazing-report-relay", daemon=True)
    relay.start()
    kernels = [(load_kernel, k) for k in KERNELS]
    figures = [(_build_job, (str(out), tuple(m.FIGURE_ID for m in job), commit)) for job in jobs]
    loaded, ready = 0, 0.0
    try:
        # (forked from this process, which has not loaded numba: no half-initialised state inherited)
        done = map_unordered(
            _run, figures, n, initializer=_init, initargs=(queue,), start_method=method, first=kernels
        )
        for finished in done:  # the kernels first, then the figures
            if loaded < len(kernels):
                loaded += 1
                if loaded == len(kernels):
                    ready = time.perf_counter() - start
                    queue.put(f"kernels ready in {ready:.1f} s")
                continue
            for figure_id, seconds in finished:  # (after the job's own messages, in the queue already)
                queue.put(f"figure {figure_id} done in {seconds:.1f} s")
    finally:
        stop.set()
        relay.join()
    return ready
