"""The discontinuity map on a model with modes on the GPU kernel under numba's CUDA simulator: equal to the
CPU lanes.

The bumper oscillator (``tests/engine/zdm_modes_model.py``), the map standing for its bumper, a stop of
mode ``Taut_2`` (kicks past the grazing), or of mode ``Slack_1`` where at the map's phase the run is in
``Taut_2`` (no kick: the kernel's ``apply_map`` checks the mode, as ``tangent.discontinuity_map`` does).
In the simulator the GPU does the CPU's arithmetic: periods, kicks and statuses equal, samples, final
states and exponents equal to the bit.  The cases run in a process of their own (``cases_zdm_modes.py``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.gpu.test_simulator import SAMPLE_TOL

CASES = tuple(
    f"zdm modes bumper in {where}{lyap}" for where in ("Taut_2", "Slack_1") for lyap in ("", " lyapunov")
)
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def compared() -> dict[str, dict[str, object]]:
    """Every case's CPU and GPU results (one process under the simulator)."""
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1", "PYTHONWARNINGS": "ignore"}
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT / "src"), str(ROOT), env.get("PYTHONPATH")) if p)
    proc = subprocess.run(
        [sys.executable, str(Path(__file__).with_name("cases_zdm_modes.py"))],
        capture_output=True, text=True, env=env, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


@pytest.mark.parametrize("case", CASES)
def test_the_gpu_equals_the_cpu_lanes_with_the_map_on_a_model_with_modes(
    compared: dict[str, dict[str, object]], case: str
) -> None:
    row = compared[case]
    assert row["cpu_points"] == 0  # (every point the GPU's)
    for name in ("period", "impacts_by_stop", "status", "transient_used", "impacts", "mode_final"):
        assert row[f"gpu_{name}"] == row[f"cpu_{name}"], name
    assert row["samples_diff"] <= SAMPLE_TOL
    assert row["x_final_diff"] <= SAMPLE_TOL
    assert row["lyapunov_diff"] <= SAMPLE_TOL


def test_the_map_kicks_in_its_stops_mode_only(compared: dict[str, dict[str, object]]) -> None:
    """Not trivially equal: in ``Taut_2`` no kick below the grazing, kicks past it; in ``Slack_1`` none."""
    for case in CASES:
        kicks = compared[case]["cpu_kicks"]
        if "Taut_2" in case:
            assert kicks[0] == 0 and min(kicks[1:]) > 0, (case, kicks)
        else:
            assert kicks == [0, 0, 0], (case, kicks)
