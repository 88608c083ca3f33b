"""Resets that move the state off their guard on the GPU kernel under numba's CUDA simulator: equal to the
CPU lanes (``cases_reset_defl.py``, in a process of its own with ``NUMBA_ENABLE_CUDASIM=1``; in the
simulator the GPU does the CPU's arithmetic, so everything is equal to the bit, ``test_simulator.py``)."""

from __future__ import annotations

import pytest

from grazing.core.solution import Status
from tests.gpu.test_simulator import assert_gpu_equals_cpu, simulator_results

CASES = ("reset off the wall", "reset beyond the wall")


@pytest.fixture(scope="module")
def compared() -> dict[str, object]:
    """Every case's CPU and GPU results (one process under the simulator)."""
    return simulator_results("cases_reset_defl.py")


@pytest.mark.parametrize("case", CASES)
def test_resets_off_the_guard_on_the_gpu_equal_the_cpu_lanes(compared: dict, case: str) -> None:
    row = compared[case]
    assert_gpu_equals_cpu(row)
    assert row["cpu_points"] == 0  # (no point handed to the CPU lanes)


def test_the_cases_impact_and_one_point_ends_beyond_the_wall(compared: dict) -> None:
    """Not trivially equal: the points impact in their recorded span, and the reset beyond the wall ends
    its point with ``OUTSIDE_MODE`` (the other is computed)."""
    assert all(n[0] > 0 for n in compared["reset off the wall"]["cpu_impacts_by_stop"])
    assert all(s == int(Status.OK) for s in compared["reset off the wall"]["cpu_status"])
    statuses = sorted(compared["reset beyond the wall"]["cpu_status"])  # (in the order the sweep visits them)
    assert statuses == [int(Status.OK), int(Status.OUTSIDE_MODE)]
