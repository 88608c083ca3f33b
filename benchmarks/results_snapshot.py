"""Fingerprints of a fixed set of results, to show that a change leaves them bit-identical.

Runs simulations (with impacts, Jacobians, sensitivities, Lyapunov exponents,
sticking), periodic orbits, a continuation with special points, grazing points,
a piece of the grazing curve, sweeps (one and two processes, the discontinuity
map) and a two-parameter map on the built-in models, and prints one SHA-256 of
the exact bytes of every result array.  Run it before and after a
restructuring and compare the output (``diff``)::

    python benchmarks/results_snapshot.py > before.txt
    ... change the code ...
    python benchmarks/results_snapshot.py > after.txt
    diff before.txt after.txt && echo identical
"""

from __future__ import annotations

import hashlib
import math

import numpy as np

import grazing
from grazing.models import bouncing_ball, impact_oscillator, pendulum
from grazing.normalform import find_grazing_point, normal_form_at, predict
from grazing.orbits import continue_orbit, find_grazings, find_orbit, grazing_curve
from grazing.orbits.palc import PalcSettings
from grazing.sweeps import parameter_map, sweep


def digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        h.update(
            np.ascontiguousarray(np.asarray(a, dtype=complex if np.iscomplexobj(a) else float)).tobytes()
        )
    return h.hexdigest()[:16]


def show(name: str, *arrays) -> None:
    print(f"{name:48s} {digest(*arrays)}")


def main() -> None:
    b40 = pendulum("B", eta=0.446, theta_hat=math.radians(40))
    s = grazing.simulate(b40, [0.0, 0.0], transient=300, periods=40, impacts="all", trajectory=20)
    show("simulate pendulum", s.samples, s.impacts.t, s.impacts.state, s.trajectory, [s.n_steps])
    x0 = [-0.30952407456611286, 0.4508808109843482]  # (a dense trajectory once broken by a refactoring)
    s = grazing.simulate(b40, x0, transient=600, periods=37, trajectory=400)
    show("simulate pendulum dense trajectory", s.trajectory, s.trajectory_t, s.samples)
    s = grazing.simulate(b40, [0.1, 0.2], periods=10, sensitivities=["eta", "theta_hat"])
    show("simulate pendulum sensitivities", s.jacobian, s.samples)
    s = grazing.simulate(b40, [0.1, 0.2], transient=50, periods=50, lyapunov=True)
    show("simulate pendulum lyapunov", s.lyapunov)
    show("simulate pendulum lyapunov: samples", s.samples)
    io = impact_oscillator(sigma=0.1, omega=2.0)
    s = grazing.simulate(
        io, [0.0, 0.5], t0=0.3, phase=1.0, periods=5, sensitivities=["omega"], guard_min=True
    )
    show("simulate oscillator omega", s.jacobian, s.samples, s.guard_min[0])
    s = grazing.simulate(bouncing_ball(amplitude=1.2), [0.0, 0.0], transient=3, periods=10)
    show("simulate ball sticking", s.sticking, s.samples, s.impacts.t)

    o = find_orbit(b40)
    show("orbit period 5", o.state, o.monodromy)
    br = continue_orbit(b40, "eta", 0.446, 0.44)
    show("continue period 5", br.values, br.states, [sp.param for sp in br.special])
    pts, _ = find_grazings(pendulum("B", theta_hat=math.radians(40)), "eta", 0.4, 0.6)
    show("grazings 40 deg", [p.model.params["eta"] for p in pts], [p.monodromy for p in pts])
    curve = grazing_curve(
        pendulum("B"), ("eta", "theta_hat"), math.radians(5.0), search=(0.2, 1.0),
        settings=PalcSettings(ds=0.02, ds_max=0.05, max_points=20),
    )  # fmt: skip
    show("grazing curve (20 points)", curve.values("eta"), curve.values("theta_hat"))
    pts, _ = find_grazings(io, "omega", 2.5, 4.0)
    show("grazing oscillator omega", [p.model.params["omega"] for p in pts])

    vals = np.linspace(0.44, 0.49, 60)
    for workers in (1, 2):
        ds = sweep(b40, "eta", vals, periods=40, transient=300, workers=workers, chunk_size=10)
        show(f"sweep eta ({workers} process(es))", ds.samples.values, ds.period.values)
        show(f"sweep eta ({workers} process(es)) lyapunov", ds.lyapunov.values)
    ds = sweep(io, "omega", np.linspace(3.3, 3.6, 20), periods=20, transient=150, phase=1.3, workers=1)
    show("sweep oscillator omega", ds.samples.values, ds.impacts.values)
    point = find_grazing_point(pendulum("B", theta_hat=math.radians(40)), "eta", 0.2, 1.0, "first")
    nf = normal_form_at(point, ("eta", "theta_hat"))
    show("normal form 40 deg", nf.monodromy, nf.direction, [nf.kappa], nf.unfolding["eta"][0])
    print(f"{'prediction 40 deg':48s} {predict(nf, 'eta').scenario}")
    ds = sweep(point.model, "eta", np.linspace(0.4452, 0.4462, 30), periods=40, transient=300,
               zdm=nf.discontinuity_map(), workers=1)  # fmt: skip
    show("sweep map method", ds.samples.values, ds.period.values)
    ds = parameter_map(pendulum("B"), "eta", np.linspace(0.42, 0.5, 8), "theta_hat",
                       np.radians(np.linspace(20, 45, 5)), periods=30, transient=200, workers=2)  # fmt: skip
    show("parameter map", ds.period.values, ds.samples.values)
    show("parameter map lyapunov", ds.lyapunov.values)


if __name__ == "__main__":
    main()
