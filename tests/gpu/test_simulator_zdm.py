"""The discontinuity map on the GPU kernel under numba's CUDA simulator: its sweeps equal the CPU lanes'.

The map (Nordmark's, built at the pendulum's first grazing, case B at 40 degrees: ``grazing sweep
--method map``) stands for the impacts on its stop: the kernel cuts each step at the map's phase, kicks
the state and, with Lyapunov exponents, the tangent vectors there, from the CPU driver's own functions
(``step.cut_step``, ``tangent.map_kick`` and ``kick_tangent``, :mod:`grazing.gpu.ported`).  In the
simulator the GPU does the CPU's arithmetic, so periods, kicks, statuses and transients are equal and
samples, final states and exponents equal to the bit.  The cases run in a process of their own with
``NUMBA_ENABLE_CUDASIM=1`` (``cases_zdm.py``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from tests.gpu.test_cli_device import grazing as run_grazing
from tests.gpu.test_simulator import assert_gpu_equals_cpu, simulator_results

CASES = ("zdm pendulum B chained", "zdm pendulum B fresh")
ALL_CASES = (*CASES, "zdm twin rattle")
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def compared() -> dict[str, dict[str, object]]:
    """Every case's CPU and GPU results (one process under the simulator)."""
    return simulator_results("cases_zdm.py")


@pytest.mark.parametrize("case", ALL_CASES)
def test_the_gpu_equals_the_cpu_lanes_with_the_map_at_every_point(
    compared: dict[str, dict[str, object]], case: str
) -> None:
    row = compared[case]
    assert row["cpu_points"] == 0  # (every point the GPU's: no sticking here)
    assert_gpu_equals_cpu(row)


def test_the_map_kicks_past_the_grazing_and_not_before(compared: dict[str, dict[str, object]]) -> None:
    """The cases are not trivially equal: below the grazing (eta = 0.44512) the orbit of period 1 never
    reaches the map's window (no kick), past it the map kicks (each impact counted on its stop is a kick:
    that stop's impacts are not searched); the back face is never hit; the exponents through the kicks
    are finite, negative on the orbit of period 1."""
    for case in CASES:
        row = compared[case]
        kicks = row["cpu_kicks"]
        assert kicks[0] == 0 and all(k > 0 for k in kicks[1:]), (case, kicks)
        assert all(by_stop[1] == 0 for by_stop in row["cpu_impacts_by_stop"]), row
        assert row["cpu_status"] == [0, 0, 0, 0] and row["cpu_period"][0] == 1, row
    values = compared["zdm pendulum B chained"]["cpu_lyapunov_values"]
    assert all(math.isfinite(v) for v in values) and values[0] < 0, values


def test_a_sweep_of_the_map_is_the_gpus() -> None:
    """Nothing in a sweep of the map is refused on the GPU; without a device ``auto`` is the CPU."""
    import grazing
    from grazing.gpu.device import resolve_device, spec_device
    from grazing.normalform import find_grazing_point, normal_form_at
    from grazing.sweeps.spec import sweep_spec

    model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    zdm = normal_form_at(find_grazing_point(model, "eta", 0.2, 1.0, "first"), ("eta", "theta_hat"))
    spec = sweep_spec(model, "eta", [0.4452], settings=grazing.SweepSettings(), zdm=zdm.discontinuity_map())
    assert spec.zdm is not None and spec_device("gpu", spec) == "gpu"
    assert resolve_device("auto", spec) == "cpu"


SWEEP = (
    "sweep --param eta --theta-hat 40 --method map --start 0.4446 --stop 0.4462 --num 4 --transient 32 "
    "--periods 8 --chunk-size 0 --json"
).split()


def test_the_cli_sweep_of_the_map_on_the_simulated_gpu_is_the_cpus(tmp_path: Path) -> None:
    """``grazing sweep --method map --device gpu`` (Lyapunov exponents, the default): the same JSON as the
    CPU's, the map kicking past the grazing."""
    cpu = run_grazing([*SWEEP, "--device", "cpu"], tmp_path)
    gpu = run_grazing([*SWEEP, "--device", "gpu"], tmp_path, simulator=True)
    assert cpu.returncode == 0 and gpu.returncode == 0, gpu.stderr
    a, b = json.loads(cpu.stdout), json.loads(gpu.stdout)
    a.pop("elapsed_s"), b.pop("elapsed_s")
    assert a == b
    kicks = a["impacts_per_period"]
    assert a["method"] == "map" and kicks[0] == 0 and min(kicks[1:]) > 0, a
    assert all(isinstance(v, float) and math.isfinite(v) for v in a["lyapunov"]), a["lyapunov"]


def test_the_twin_rattle_kicks_and_hits_its_other_stop(compared: dict[str, dict[str, object]]) -> None:
    """Both stops in every point of the two-stop case: kicks on the map's stop, impacts on the other."""
    row = compared["zdm twin rattle"]
    assert all(a > 0 and b > 0 for a, b in row["cpu_impacts_by_stop"]), row["cpu_impacts_by_stop"]
