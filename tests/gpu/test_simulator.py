"""The GPU kernel's logic under numba's CUDA simulator: its sweeps equal the CPU lanes' at every point.

The simulator runs each CUDA thread as a Python thread executing the kernel's Python text; the
model's functions are the same generated text as the CPU's compiled code, with grazing's own sin and
cos, and the step size and event location are the CPU driver's own functions.  So in the simulator
the GPU does the CPU's arithmetic: periods, impacts per stop, statuses and transient periods must be
equal and the samples and final states equal to the bit (:data:`SAMPLE_TOL`; on a device, where the
compiler fuses multiply-adds, ``test_device.py`` allows more).  The cases run in one process of their
own with ``NUMBA_ENABLE_CUDASIM=1`` (``simulator_cases.py``), so the simulator never reaches another
test.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from grazing.errors import InvalidParameterError

SAMPLE_TOL = 0.0
"""Largest difference of the samples (and final states) of the GPU in the simulator and the CPU lanes."""

LYAPUNOV_CASES = ("lyapunov pendulum B", "lyapunov pendulum C chained", "lyapunov impact oscillator")
MODE_CASES = ("soft impact modes", "lyapunov soft impact chained", "rocking block",
              "lyapunov rocking block chained", "soft impact start modes", "friction sliding",
              "lyapunov friction chained", "diagonal sliding")  # fmt: skip
CASES = ("pendulum B fresh", "pendulum C chained", "pendulum A map", "pendulum huge forcing",
         "impact oscillator", "bouncing ball", *LYAPUNOV_CASES, *MODE_CASES)  # fmt: skip
ROOT = Path(__file__).resolve().parents[2]


def simulator_results(script: str) -> dict[str, dict[str, object]]:
    """The JSON object a script of ``tests/gpu`` prints, run in a process of its own under the simulator."""
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1", "PYTHONWARNINGS": "ignore"}
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT / "src"), str(ROOT), env.get("PYTHONPATH")) if p)
    proc = subprocess.run(
        [sys.executable, str(Path(__file__).with_name(script))],
        capture_output=True, text=True, env=env, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


def assert_gpu_equals_cpu(row: dict[str, object]) -> None:
    """One case's GPU results equal its CPU lanes' (``simulator_cases.compare``'s row): periods, impacts,
    statuses, transients and final modes equal, samples, final states and exponents within
    :data:`SAMPLE_TOL` (the bit)."""
    for name in ("period", "impacts_by_stop", "status", "transient_used", "impacts", "mode_final"):
        assert row[f"gpu_{name}"] == row[f"cpu_{name}"], name
    assert row["samples_diff"] <= SAMPLE_TOL  # type: ignore[operator]
    assert row["x_final_diff"] <= SAMPLE_TOL  # type: ignore[operator]
    assert row["lyapunov_diff"] <= SAMPLE_TOL  # type: ignore[operator]  # (NaN on one side only: inf)


@pytest.fixture(scope="module")
def compared() -> dict[str, dict[str, object]]:
    """Every case's CPU and GPU results (one process under the simulator)."""
    return simulator_results("simulator_cases.py")


@pytest.mark.parametrize("case", CASES)
def test_the_gpu_equals_the_cpu_lanes_at_every_point(
    compared: dict[str, dict[str, object]], case: str
) -> None:
    row = compared[case]
    assert_gpu_equals_cpu(row)


def test_the_lyapunov_cases_have_exponents_of_both_signs(compared: dict[str, dict[str, object]]) -> None:
    """The exponents compared are real ones: finite at every point, negative on the periodic orbits and
    positive at the last point of case B at 40 degrees (chaos: fig 7; the second point, aperiodic over
    these few periods, is still settling)."""
    for case in LYAPUNOV_CASES:
        values = compared[case]["cpu_lyapunov_values"]
        assert all(math.isfinite(v) for v in values), (case, values)
        assert all(v < 0 for v, p in zip(values, compared[case]["cpu_period"]) if p > 0), (case, values)
    b = compared["lyapunov pendulum B"]
    assert b["cpu_period"][-1] == 0 and b["cpu_lyapunov_values"][-1] > 0, b
    assert all(sum(map(sum, compared[case]["cpu_impacts_by_stop"])) > 0 for case in LYAPUNOV_CASES)


def test_the_cases_reach_what_they_are_for(compared: dict[str, dict[str, object]]) -> None:
    """The cases are not trivially equal: impacts, chaos (period 0), a failed point, several periods."""
    assert compared["pendulum B fresh"]["cpu_period"] == [1, 0, 3, 0]  # (fig 7 at 40 degrees, case B)
    assert compared["pendulum huge forcing"]["cpu_status"] == [0, 2]  # (non-finite state)
    switching = ("soft", "friction", "diagonal")  # (switches and sliding, no impacts)
    impacting = [case for case in CASES if not any(word in case for word in switching)]
    assert all(sum(map(sum, compared[case]["cpu_impacts_by_stop"])) > 0 for case in impacting)
    assert len(set(compared["pendulum C chained"]["cpu_period"])) >= 3


def test_the_mode_cases_reach_what_they_are_for(compared: dict[str, dict[str, object]]) -> None:
    """Points end in either mode (switches without a reset), the block impacts both corners (resets that
    change the mode) and one of its points fails (accumulating impacts), the exponents are finite, and the
    start modes are used: their points end in the mode they started in after one period (a state in
    contact started in the free mode would be outside its region); the friction oscillator's points end
    sliding (its pseudo-mode, 2) or slipping, the diagonal model's sliding."""
    assert set(compared["soft impact modes"]["cpu_mode_final"]) == {0, 1}
    block = compared["rocking block"]
    from grazing.models import rocking_block

    names = rocking_block().stop_names  # (landings on both corners, no overturn)
    landings = [
        [row[names.index(n)] for n in ("onto_left", "onto_right")] for row in block["cpu_impacts_by_stop"]
    ]
    overturns = [
        [row[names.index(n)] for n in ("overturn_right", "overturn_left")]
        for row in block["cpu_impacts_by_stop"]
    ]
    assert (
        block["cpu_status"] == [3, 0, 0]
        and landings[1:] == [[8, 8], [8, 8]]
        and overturns[1:] == [[0, 0]] * 2
    ), block
    for case in (
        "lyapunov soft impact chained",
        "lyapunov rocking block chained",
        "lyapunov friction chained",
    ):
        assert all(math.isfinite(v) and v < 0 for v in compared[case]["cpu_lyapunov_values"]), case
    assert set(compared["friction sliding"]["cpu_mode_final"]) == {1, 2}
    assert 2 in compared["lyapunov friction chained"]["cpu_mode_final"]
    assert compared["diagonal sliding"]["cpu_mode_final"] == [2, 2, 2]
    starts = compared["soft impact start modes"]
    assert starts["cpu_status"] == [0, 0, 0] and starts["cpu_mode_final"] == [1, 1, 1], starts


def test_no_point_goes_to_the_cpu(compared: dict[str, dict[str, object]]) -> None:
    """Every point is the GPU's, the bouncing ball's that chatter and stick among them (sticking on the GPU:
    ``test_simulator_stick.py``)."""
    assert all(compared[case]["cpu_points"] == 0 for case in CASES)


def test_the_ported_code_calls_only_device_functions(compared: dict[str, dict[str, object]]) -> None:
    """Every name the device code reads is a device function, a constant or ``math`` (a CPU function
    there would run in the simulator but not compile for a device)."""
    assert compared["foreign names"] == []


def test_parameter_map_on_the_gpu_is_the_same_dataset(compared: dict[str, dict[str, object]]) -> None:
    """``parameter_map(device="gpu")``: every variable equals ``device="cpu"``'s (shared downstream)."""
    row = compared["api map"]
    assert {"period", "samples", "status", "impacts"} <= set(row["variables"])
    assert row["differ"] == []
    assert len({p for line in row["period"] for p in line}) >= 2  # (not all alike)


def test_basins_on_the_gpu_are_the_same_dataset(compared: dict[str, dict[str, object]]) -> None:
    """``basins(device="gpu")``: every variable equals ``device="cpu"``'s, the Lyapunov exponents among them,
    computed on the GPU (the refined runs' last and the periodic orbit's run)."""
    row = compared["api basins"]
    assert {"label", "fraction", "kind", "period", "lyapunov"} <= set(row["variables"])
    assert row["differ"] == []
    assert len(row["lyapunov_on_gpu"]) >= 2 and "periodic" in row["kinds"], row
    assert any(math.isfinite(v) for v in row["lyapunov"]), row


def test_basins_of_a_model_with_modes_on_the_gpu_are_the_same_dataset(
    compared: dict[str, dict[str, object]],
) -> None:
    row = compared["api basins modes"]
    assert row["differ"] == [] and sum(row["launched"]) >= 9, row  # (the grid's 9 points on the GPU)


def test_the_simulator_does_not_leak_into_this_process() -> None:
    from numba import config

    assert os.environ.get("NUMBA_ENABLE_CUDASIM") != "1"
    assert not config.ENABLE_CUDASIM


def test_device_gpu_takes_models_with_modes_and_lyapunov_exponents() -> None:
    import grazing
    from grazing.gpu.device import spec_device
    from grazing.sweeps.spec import sweep_spec

    for model in (grazing.models.rocking_block(), grazing.models.friction_oscillator()):
        modes = sweep_spec(model, "a", [0.2], settings=grazing.SweepSettings())
        assert spec_device("gpu", modes) == "gpu"  # (switches, resets, sliding: the GPU's)
    lyapunov = sweep_spec(grazing.models.pendulum("B"), "eta", [0.44], settings=grazing.SweepSettings())
    assert lyapunov.lyapunov and spec_device("gpu", lyapunov) == "gpu"  # (exponents too)


def test_no_device_is_one_line() -> None:
    import grazing
    from grazing.gpu.target import NoDeviceError, device_present
    from grazing.sweeps import sweep

    if device_present():
        pytest.skip("a CUDA device is present")
    with pytest.raises(NoDeviceError) as info:
        sweep(grazing.models.pendulum("B"), "eta", [0.44], lyapunov=False, fresh=True, device="gpu")
    assert "\n" not in str(info.value) and "(device=)" in str(info.value)


def test_device_auto_without_a_gpu_is_the_cpu() -> None:
    import grazing
    from grazing.sweeps import sweep

    m = grazing.models.pendulum("B")
    ds = sweep(m, "eta", [0.44, 0.45], transient=40, periods=10, lyapunov=False, workers=1, device="auto")
    assert ds.status.values.tolist() == [0, 0]
    with pytest.raises(InvalidParameterError, match=r"^device must be"):
        sweep(m, "eta", [0.44], device="GPU")
