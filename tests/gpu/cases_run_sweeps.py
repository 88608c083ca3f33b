"""Several sweeps run together by ``run_sweeps`` on the CPU and on the GPU under numba's CUDA simulator (a
script).

Run by ``tests/gpu/test_simulator_run_sweeps.py`` in a process of its own with ``NUMBA_ENABLE_CUDASIM=1`` (as
``simulator_cases.py``).  The sweeps: two fresh sweeps of the pendulum that share the model and settings (at
two stop angles: their chunks go into one launch), one carried sweep of two chunks a chain (settled on the
device), and the first given twice.  Prints one JSON object: per sweep, the variables of the two datasets
that differ, the periods, and the parts of each launch of the GPU by sweep.
"""

from __future__ import annotations

import json
import math
import os
import sys

import numpy as np

import grazing
from grazing.sweeps.api import run_sweep, run_sweeps
from grazing.sweeps.spec import SweepSpec, sweep_spec
from tests.gpu.cases_chains import counting_launches
from tests.gpu.simulator_cases import SHORT, differing


def specs() -> list[SweepSpec]:
    """Two fresh sweeps sharing a batch key, a carried sweep of two chunks a chain, the first again."""
    fresh = grazing.SweepSettings(**SHORT, fresh=True, chunk_size=2)
    a, b = (
        sweep_spec(grazing.models.pendulum("B", theta_hat=math.radians(deg)), "eta", [0.40, 0.44, 0.46],
                   settings=fresh)
        for deg in (30, 40)
    )  # fmt: skip
    carried = grazing.SweepSettings(**SHORT, fresh=False, chunk_size=2, phase=1.0)
    chain = sweep_spec(grazing.models.pendulum("C", theta_hat=math.radians(30)), "eta",
                       np.linspace(0.40, 0.50, 4), settings=carried)  # fmt: skip
    return [a, b, chain, a]


def main() -> None:
    given = specs()
    cpu = run_sweeps(given, workers=1, device="cpu")
    with counting_launches() as launches:
        gpu = run_sweeps(given, device="gpu")
    alone = [run_sweep(spec, workers=1, device="cpu") for spec in given]
    index = {id(spec): k for k, spec in reversed(list(enumerate(given)))}  # (a spec given twice: its first)
    out = {
        "differ": [differing(c, g) for c, g in zip(cpu, gpu)],
        "differ_alone": [differing(c, g) for c, g in zip(alone, gpu)],
        "variables": [sorted(c.data_vars) for c in cpu],
        "cpu_period": [c.period.values.tolist() for c in cpu],
        "gpu_period": [g.period.values.tolist() for g in gpu],
        "launches": [sorted(index[id(s)] for s, _ in parts if id(s) in index) for parts in launches],
        "chained": [bool(spec.carried and spec.n_chunks > spec.segments) for spec in given],
    }
    print(json.dumps(out))


if __name__ == "__main__":
    if os.environ.get("NUMBA_ENABLE_CUDASIM") != "1":
        sys.exit("run with NUMBA_ENABLE_CUDASIM=1 (set before numba is imported)")
    main()
