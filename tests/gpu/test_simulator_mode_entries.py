"""The GPU kernel's region check where a mode is entered by the exit from sliding or by a reset within it:
under numba's CUDA simulator its statuses (OUTSIDE_MODE at the points that land outside) and results
equal the CPU lanes' to the bit (``cases_mode_entries.py``, run as ``test_simulator.py`` runs its cases).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from grazing.core.solution import Status

CASES = ("leave sliding", "reset within a mode", "lyapunov reset within a mode")
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def compared() -> dict[str, dict[str, object]]:
    """Every case's CPU and GPU results (one process under the simulator)."""
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1", "PYTHONWARNINGS": "ignore"}
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT / "src"), str(ROOT), env.get("PYTHONPATH")) if p)
    proc = subprocess.run(
        [sys.executable, str(Path(__file__).with_name("cases_mode_entries.py"))],
        capture_output=True, text=True, env=env, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


@pytest.mark.parametrize("case", CASES)
def test_the_gpu_checks_the_region_of_these_entries_as_the_cpu_lanes(
    compared: dict[str, dict[str, object]], case: str
) -> None:
    row = compared[case]
    for name in ("period", "impacts_by_stop", "status", "transient_used", "impacts", "mode_final"):
        assert row[f"gpu_{name}"] == row[f"cpu_{name}"], name
    assert row["samples_diff"] == 0.0 and row["x_final_diff"] == 0.0 and row["lyapunov_diff"] == 0.0
    assert row["cpu_points"] == 0  # (all on the GPU)
    # the points in the order the sweep visits them (up): the one inside first, then two outside
    assert row["cpu_status"] == [int(Status.OK), int(Status.OUTSIDE_MODE), int(Status.OUTSIDE_MODE)], row
