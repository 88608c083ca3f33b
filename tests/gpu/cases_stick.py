"""Sticking on the GPU kernel under numba's CUDA simulator against the CPU lanes (run as a script).

Run by ``tests/gpu/test_simulator_stick.py`` in a process of its own with ``NUMBA_ENABLE_CUDASIM=1``.
Complete chattering summed and continued as sticking until the contact force releases it: the bouncing
ball, the impact oscillator on a stop at its rest position, and the forced masses on a rigid floor of
``tests/engine/test_sticking_modes.py`` (models with modes: released into a spring region, a switch
while sticking, the floor a mode's second transition), with and without Lyapunov exponents.  Prints one
JSON object: per case :func:`tests.gpu.simulator_cases.compare`'s row, and the sticking intervals that
the scalar driver finds in each point's recorded span (from the sweep's start, a fresh point's).
A few points and periods each: the simulator runs every CUDA thread as a Python thread.
"""

from __future__ import annotations

import json
import os
import sys

import sympy as sp

import grazing
from grazing import HybridModel, Parameter, Stop
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_sticking_modes import stick_lift, stick_spring, stick_spring_floor_second
from tests.gpu.simulator_cases import compare

SHORT = {"transient": 12, "periods": 6, "adaptive": False}


def cases() -> dict[str, tuple[object, dict[str, object]]]:
    """Each case's spec (one chunk), and ``x0`` with each point's model for the scalar driver's check."""
    fresh = grazing.SweepSettings(**SHORT, fresh=True, lyapunov=False, chunk_size=0)
    chained = grazing.SweepSettings(**SHORT, fresh=False, lyapunov=False, chunk_size=0)
    lyap = grazing.SweepSettings(**SHORT, fresh=True, lyapunov=True, chunk_size=0)
    lyap_chained = grazing.SweepSettings(**SHORT, fresh=False, lyapunov=True, chunk_size=0)
    ball = grazing.models.bouncing_ball()
    oscillator = grazing.models.impact_oscillator(sigma=0.0, r=0.5)
    table = {
        # the ball rides the table until its downward acceleration exceeds gravity, once a period
        "ball": (ball, "amplitude", [1.05, 1.3, 2.0], (0.0, 0.5), fresh),
        "lyapunov ball chained": (ball, "amplitude", [1.2, 1.5, 2.0], (0.0, 3.0), lyap_chained),
        # the impact oscillator's mass chatters onto its stop at rest and is pulled off by the forcing
        "impact oscillator": (oscillator, "omega", [0.5, 0.7], (-1.0, 0.0), fresh),
        "lyapunov impact oscillator": (oscillator, "omega", [0.5, 0.7], (-1.0, 0.0), lyap),
        # the table as stop 1 (its force in row 1)
        "ball under a ceiling": (ball_under_a_ceiling(), "amplitude", [1.05, 1.3], (0.0, 0.5), fresh),
        # models with modes: sticks, released by the forcing, enters the spring; the floor as transition 1;
        # the lift's time switch firing while the mass sticks
        "stick spring chained": (stick_spring(), "a", [1.6, 2.0, 2.4], (0.3, 0.0), chained),
        "stick spring floor second": (stick_spring_floor_second(), "a", [1.6, 2.4], (0.3, 0.0), fresh),
        "stick lift": (stick_lift(), "a", [1.6, 1.9], (0.3, 0.0), fresh),
        "lyapunov stick spring": (stick_spring(), "a", [1.6, 2.4], (0.3, 0.0), lyap),
    }
    return {
        name: (sweep_spec(model, param, values, x0=x0, settings=settings), {"x0": x0, "param": param})
        for name, (model, param, values, x0, settings) in table.items()
    }


def ball_under_a_ceiling() -> HybridModel:
    """The bouncing ball (restitution 0.3) with a ceiling far above it as stop 0: the table is stop 1, its
    contact force row 1 of the sticking kernel."""
    y, v, t = sp.symbols("y v t")
    amplitude, omega, gravity, r = sp.symbols("amplitude omega gravity r")
    table = amplitude * sp.sin(omega * t)
    stops = [
        Stop("ceiling", 100 - y, [y, -v]),
        Stop("table", y - table, [y, (1 + r) * sp.diff(table, t) - r * v], contact_direction=[0, 1]),
    ]
    params = [
        Parameter("amplitude", 1.2),
        Parameter("omega", 1.0),
        Parameter("gravity", 1.0),
        Parameter("r", 0.3),
    ]
    return HybridModel("ball-ceiling", [y, v], t, params, vector_field=[v, -gravity], stops=stops,
                       period=2 * sp.pi / omega)  # fmt: skip


def scalar_sticking(spec: object, x0: tuple[float, float], param: str) -> list[int]:
    """The sticking intervals of each point's recorded span on the scalar driver, from ``x0`` at time 0."""
    out = []
    for (value,) in spec.points:
        model = spec.model.with_params(**{param: float(value)})
        sol = grazing.simulate(model, list(x0), transient=SHORT["transient"], periods=SHORT["periods"])
        out.append(len(sol.sticking))
    return out


def main(names: list[str]) -> None:
    table = cases()
    out: dict[str, object] = {}
    for name in names or list(table):
        spec, info = table[name]
        row = compare([(spec, 0)])
        row["scalar_sticking"] = scalar_sticking(spec, info["x0"], info["param"])
        out[name] = row
    print(json.dumps(out))


if __name__ == "__main__":
    if os.environ.get("NUMBA_ENABLE_CUDASIM") != "1":
        sys.exit("run with NUMBA_ENABLE_CUDASIM=1 (set before numba is imported)")
    main(sys.argv[1:])
