"""Resets that move the state off their guard, on the GPU kernel under numba's CUDA simulator against the
CPU lanes.

Run by ``tests/gpu/test_simulator_reset_defl.py`` as a script in a process of its own with
``NUMBA_ENABLE_CUDASIM=1``.  The ``wobbler`` of ``tests/engine/test_reset_off_guard.py`` (its wall's reset
moves it back by ``kick``: the root at the next step's start is not divided out), fresh points, one of
them with a reset beyond the wall (``OUTSIDE_MODE``).  Prints one JSON object: per case
:func:`tests.gpu.simulator_cases.compare`'s row.  A few points and periods: the simulator runs every CUDA
thread as a Python thread.
"""

from __future__ import annotations

import json
import os
import sys

import grazing
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_reset_off_guard import wobbler
from tests.gpu.simulator_cases import compare

SHORT = {"transient": 2, "periods": 4, "adaptive": False}


def cases() -> dict[str, object]:
    """Each case's spec (one chunk)."""
    fresh = grazing.SweepSettings(**SHORT, fresh=True, lyapunov=False, chunk_size=0)
    return {
        "reset off the wall": sweep_spec(wobbler(), "rest", [0.01, 0.02, 0.3], x0=(0.0, 0.0), settings=fresh),
        "reset beyond the wall": sweep_spec(wobbler(), "kick", [0.05, -0.05], x0=(0.0, 0.0), settings=fresh),
    }


def main(names: list[str]) -> None:
    table = cases()
    out: dict[str, object] = {name: compare([(table[name], 0)]) for name in names or list(table)}
    print(json.dumps(out))


if __name__ == "__main__":
    if os.environ.get("NUMBA_ENABLE_CUDASIM") != "1":
        sys.exit("run with NUMBA_ENABLE_CUDASIM=1 (set before numba is imported)")
    main(sys.argv[1:])
