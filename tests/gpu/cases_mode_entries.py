"""The region check at the exit from sliding and at a reset within a mode, on the CPU lanes and on the GPU
kernel under numba's CUDA simulator (run as a script, as ``simulator_cases.py``).

Run by ``tests/gpu/test_simulator_mode_entries.py`` with ``NUMBA_ENABLE_CUDASIM=1``; prints one JSON
object, per case both sides' results (``simulator_cases.compare``).  Three points a case, a few periods.
"""

from __future__ import annotations

import json
import os
import sys

import grazing
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_mode_region_entries import slide_then_leave, wall
from tests.gpu.simulator_cases import compare

SETTINGS = {"transient": 4, "periods": 2, "fresh": True, "adaptive": False, "chunk_size": 0}


def cases() -> dict[str, list[tuple[object, int]]]:
    """Each case's chunks: ``(spec, chunk index)`` pairs."""
    plain = grazing.SweepSettings(**SETTINGS, lyapunov=False)
    lyap = grazing.SweepSettings(**SETTINGS, lyapunov=True)
    # the trap's level 3 and 2.5: the exit from sliding (at y = 2) lands outside 'below'; 1.5: inside
    leave = sweep_spec(slide_then_leave(True), "c", [3.0, 1.5, 2.5], x0=[1.0, 0.0], settings=plain)
    # restitution 12 and 11: the first bounce lands past the overspeed guard; 0.8: inside
    reset = [sweep_spec(wall(0.8), "e", [12.0, 0.8, 11.0], x0=[0.0, -1.0], settings=s) for s in (plain, lyap)]
    return {
        "leave sliding": [(leave, 0)],
        "reset within a mode": [(reset[0], 0)],
        "lyapunov reset within a mode": [(reset[1], 0)],
    }


def main(names: list[str]) -> None:
    table = cases()
    print(json.dumps({name: compare(table[name]) for name in (names or list(table))}))


if __name__ == "__main__":
    if os.environ.get("NUMBA_ENABLE_CUDASIM") != "1":
        sys.exit("run with NUMBA_ENABLE_CUDASIM=1 (set before numba is imported)")
    main(sys.argv[1:])
