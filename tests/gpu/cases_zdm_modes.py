"""The discontinuity map on a model with modes, on the CPU lanes and the GPU kernel under numba's simulator.

A script, run by ``tests/gpu/test_simulator_zdm_modes.py`` in a process of its own with
``NUMBA_ENABLE_CUDASIM=1`` (set before numba is imported).  Prints one JSON object: per case, both sides'
results as ``simulator_cases.compare`` gives them and the kicks per point (the impacts counted on the map's
stop, whose impacts are not searched).  The model is ``tests/engine/zdm_modes_model.py``'s bumper
oscillator, the map the normal form's at the bumper's grazing (``tests/engine/test_zdm_modes.py``).
"""

from __future__ import annotations

import json
import os
import sys

import grazing
from grazing.engine.runner import DiscontinuityMap
from grazing.normalform import find_grazing_point, normal_form_at
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_zdm_modes import orbit_state
from tests.engine.zdm_modes_model import bumper_oscillator
from tests.gpu.simulator_cases import compare

MUS = (-1e-3, 1e-3, 1e-2)
"""Relative distances from the grazing in ``F_0``: below it (no kick), past it."""


def cases() -> dict[str, list[tuple[object, int]]]:
    """Each case's chunks: ``(spec, chunk index)`` pairs that share a batch."""
    point = find_grazing_point(bumper_oscillator(), "F_0", 0.2, 1.5, "first", "Bumper_9")
    zdm = normal_form_at(point, ("F_0",)).discontinuity_map()
    x0, _, _ = orbit_state(point, 0.0)
    values = [point.model.params["F_0"] * (1 + mu) for mu in MUS]
    out: dict[str, list[tuple[object, int]]] = {}
    for where in (
        "Taut_2",
        "Slack_1",
    ):  # (Slack_1: the map's stop in the mode the run is not in at its phase)
        model = bumper_oscillator(bumper_mode=where, initial_mode="Taut_2")
        z = DiscontinuityMap(
            zdm.phase, zdm.accel, zdm.direction, zdm.window, model.stop_names.index("Bumper_9")
        )
        for lyapunov in (True, False):
            settings = grazing.SweepSettings(transient=8, periods=8, lyapunov=lyapunov, fresh=not lyapunov,
                                             adaptive=False, chunk_size=0)  # fmt: skip
            name = f"zdm modes bumper in {where}{' lyapunov' if lyapunov else ''}"
            out[name] = [(sweep_spec(model, "F_0", values, x0=x0, zdm=z, settings=settings), 0)]
    return out


def main() -> None:
    out: dict[str, object] = {}
    for name, parts in cases().items():
        row = compare(parts)
        stop = int(parts[0][0].zdm.stop)  # type: ignore[attr-defined]
        row["cpu_kicks"] = [by_stop[stop] for by_stop in row["cpu_impacts_by_stop"]]  # type: ignore[union-attr]
        out[name] = row
    print(json.dumps(out))


if __name__ == "__main__":
    if os.environ.get("NUMBA_ENABLE_CUDASIM") != "1":
        sys.exit("run with NUMBA_ENABLE_CUDASIM=1 (set before numba is imported)")
    main()
