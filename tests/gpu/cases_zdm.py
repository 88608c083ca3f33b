"""Sweeps of the discontinuity map on the CPU lanes and on the GPU kernel under numba's CUDA simulator.

A script, run by ``tests/gpu/test_simulator_zdm.py`` in a process of its own with
``NUMBA_ENABLE_CUDASIM=1`` (set before numba is imported).  Prints one JSON object: per case, both
sides' results as ``simulator_cases.compare`` gives them, and the map's kicks per point (the impacts
counted on the stop it stands for, whose impacts are not searched: every one of them is a kick).
"""

from __future__ import annotations

import json
import math
import os
import sys

import grazing
from grazing.normalform import find_grazing_point, normal_form_at
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_zdm_several_stops import free_motion, twin_rattle
from tests.gpu.simulator_cases import compare

SHORT = {"transient": 64, "periods": 16}
"""Shorter than ``grazing sweep --method map``'s 500 + 100 periods; its other settings are the defaults
(Lyapunov exponents, the adaptive transient, tol 1e-10, each point from the previous one's end)."""
ETAS = (0.4446, 0.4452, 0.4457, 0.4462)
"""Case B at 40 degrees around its first grazing (eta = 0.44512): the first point below it, the others
past it, where the map kicks."""


def grazing_map() -> tuple[object, object]:
    """The pendulum (case B, 40 degrees) at its first grazing in eta and the map there (the CLI's
    ``sweep --method map``: ``cli.sweeps._map_for_sweep``)."""
    model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    point = find_grazing_point(model, "eta", 0.2, 1.0, "first")
    return model, normal_form_at(point, ("eta", "theta_hat")).discontinuity_map()


def twin_rattle_map() -> list[tuple[object, int]]:
    """Two rattlers, the map on one, the other's stop hit a moment before the map's phase
    (``tests/engine/test_zdm_several_stops.py``): a sweep of three ledges, each point from its own start."""
    from grazing.engine.runner import DiscontinuityMap

    base = twin_rattle()
    amplitude, lag, t_star = free_motion(base)
    model = base.with_params(g_1=0.999 * amplitude)
    om = model.params["Om"]
    zdm = DiscontinuityMap(phase=t_star, accel=om**2 * amplitude, direction=(0.0, 1.8, 0.0, 0.0),
                           window=model.period / 4, stop=0)  # fmt: skip
    x0 = [amplitude * math.cos(lag), amplitude * math.sin(lag)] * 2
    settings = grazing.SweepSettings(transient=8, periods=8, adaptive=False, fresh=True, chunk_size=0)
    ledges = [0.98 * amplitude, 0.99 * amplitude, 0.999 * amplitude]
    return [(sweep_spec(model, "g_2", ledges, x0=x0, zdm=zdm, settings=settings), 0)]


def cases() -> dict[str, list[tuple[object, int]]]:
    """Each case's chunks: ``(spec, chunk index)`` pairs that share a batch."""
    model, zdm = grazing_map()
    chained = grazing.SweepSettings(**SHORT, chunk_size=0)  # (one chain: the GPU takes no chain of chunks)
    fresh = grazing.SweepSettings(**SHORT, fresh=True, lyapunov=False, phase=1.0, chunk_size=2)
    chunks = sweep_spec(model, "eta", ETAS, settings=fresh, zdm=zdm)
    return {
        # the map's default sweep, short: Lyapunov exponents through the kicks, a chain of points
        "zdm pendulum B chained": [(sweep_spec(model, "eta", ETAS, settings=chained, zdm=zdm), 0)],
        # every point from x0, no exponents, sampled at phase 1, two chunks in one batch
        "zdm pendulum B fresh": [(chunks, 0), (chunks, 1)],
        # a model of two stops, the other one hit within the step that ends at the map's phase
        "zdm twin rattle": twin_rattle_map(),
    }


def main() -> None:
    out: dict[str, object] = {}
    for name, parts in cases().items():
        row = compare(parts)
        stop = int(parts[0][0].zdm.stop)  # type: ignore[attr-defined]
        row["cpu_kicks"] = [by_stop[stop] for by_stop in row["cpu_impacts_by_stop"]]  # type: ignore[union-attr]
        row["n_stops"] = len(row["cpu_impacts_by_stop"][0])  # type: ignore[index]
        out[name] = row
    print(json.dumps(out))


if __name__ == "__main__":
    if os.environ.get("NUMBA_ENABLE_CUDASIM") != "1":
        sys.exit("run with NUMBA_ENABLE_CUDASIM=1 (set before numba is imported)")
    main()
