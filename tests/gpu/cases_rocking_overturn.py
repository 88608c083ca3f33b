"""The rocking block overturning, on the GPU kernel under numba's CUDA simulator against the CPU lanes.

Run by ``tests/gpu/test_simulator_rocking_overturn.py`` as a script in a process of its own with
``NUMBA_ENABLE_CUDASIM=1``.  The block forced hard (``a`` beyond ``tan(alpha)``) rocks on both corners and
overturns at ``|theta| = pi/2`` into its absorbing mode ``overturned`` (a reset that changes the mode into a
mode of field 0), fresh and with Lyapunov exponents from the previous point's end.  Prints one JSON object:
per case :func:`tests.gpu.simulator_cases.compare`'s row, and the mode each point ends in on the scalar
driver (a fresh point's run).  A few points and periods each: the simulator runs every CUDA thread as a
Python thread.
"""

from __future__ import annotations

import json
import os
import sys

import grazing
from grazing.models import rocking_block
from grazing.sweeps.spec import sweep_spec
from tests.gpu.simulator_cases import compare

SHORT = {"transient": 4, "periods": 6, "adaptive": False}
BLOCK = {"alpha": 0.3, "p": 1.5, "omega": 3.0}
VALUES = [0.35, 0.5, 1.0]  # (rocks on; overturns after 6 landings; after 5)
X0 = (0.1, 0.0)


def cases() -> dict[str, object]:
    """Each case's spec (one chunk)."""
    fresh = grazing.SweepSettings(**SHORT, fresh=True, lyapunov=False, chunk_size=0)
    lyap = grazing.SweepSettings(**SHORT, fresh=False, lyapunov=True, chunk_size=0)
    model = rocking_block(**BLOCK)
    return {
        "overturn": sweep_spec(model, "a", VALUES, x0=X0, settings=fresh),
        "lyapunov overturn chained": sweep_spec(model, "a", VALUES, x0=X0, settings=lyap),
    }


def scalar_modes() -> list[str]:
    """The mode each fresh point ends in on the scalar driver."""
    out = []
    for value in VALUES:
        sol = grazing.simulate(
            rocking_block(**BLOCK, a=value), list(X0), **{k: SHORT[k] for k in ("transient", "periods")}
        )
        out.append(sol.mode_final)
    return out


def main(names: list[str]) -> None:
    table = cases()
    out: dict[str, object] = {name: compare([(table[name], 0)]) for name in names or list(table)}
    out["scalar_modes"] = scalar_modes()
    print(json.dumps(out))


if __name__ == "__main__":
    if os.environ.get("NUMBA_ENABLE_CUDASIM") != "1":
        sys.exit("run with NUMBA_ENABLE_CUDASIM=1 (set before numba is imported)")
    main(sys.argv[1:])
