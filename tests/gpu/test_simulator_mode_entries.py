"""The GPU kernel's region check where a mode is entered by the exit from sliding or by a reset within it:
under numba's CUDA simulator its statuses (OUTSIDE_MODE at the points that land outside) and results
equal the CPU lanes' to the bit (``cases_mode_entries.py``, run as ``test_simulator.py`` runs its cases).
"""

from __future__ import annotations

import pytest

from grazing.core.solution import Status
from tests.gpu.test_simulator import assert_gpu_equals_cpu, simulator_results

CASES = ("leave sliding", "reset within a mode", "lyapunov reset within a mode")


@pytest.fixture(scope="module")
def compared() -> dict[str, dict[str, object]]:
    """Every case's CPU and GPU results (one process under the simulator)."""
    return simulator_results("cases_mode_entries.py")


@pytest.mark.parametrize("case", CASES)
def test_the_gpu_checks_the_region_of_these_entries_as_the_cpu_lanes(
    compared: dict[str, dict[str, object]], case: str
) -> None:
    row = compared[case]
    assert_gpu_equals_cpu(row)
    assert row["cpu_points"] == 0  # (all on the GPU)
    # the points in the order the sweep visits them (up): the one inside first, then two outside
    assert row["cpu_status"] == [int(Status.OK), int(Status.OUTSIDE_MODE), int(Status.OUTSIDE_MODE)], row
