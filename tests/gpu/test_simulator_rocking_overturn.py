"""The rocking block overturning on the GPU kernel under numba's CUDA simulator: equal to the CPU lanes.

A reset that changes the mode into the absorbing mode ``overturned`` (``cases_rocking_overturn.py``, in a
process of its own with ``NUMBA_ENABLE_CUDASIM=1``).  In the simulator the GPU does the CPU's arithmetic,
so everything is equal to the bit (``test_simulator.py``), and no point is handed to the CPU lanes.
"""

from __future__ import annotations

import math

import pytest

from grazing.models import rocking_block
from tests.gpu.test_simulator import assert_gpu_equals_cpu, simulator_results

CASES = ("overturn", "lyapunov overturn chained")


@pytest.fixture(scope="module")
def compared() -> dict[str, object]:
    """Every case's CPU and GPU results (one process under the simulator)."""
    return simulator_results("cases_rocking_overturn.py")


@pytest.mark.parametrize("case", CASES)
def test_overturning_on_the_gpu_equals_the_cpu_lanes_at_every_point(compared: dict, case: str) -> None:
    row = compared[case]
    assert_gpu_equals_cpu(row)
    assert row["cpu_points"] == 0  # (no point handed to the CPU lanes)


def test_the_cases_overturn(compared: dict) -> None:
    """The cases are not trivially equal: the fresh points rock on (mode 0) or overturn (the mode
    ``overturned``, as on the scalar driver), one of them in the recorded span (an impact on
    ``overturn_right``); in the chain the last point overturns, its exponent -inf (the reset to
    ``(pi/2, 0)`` collapses every direction), the others' finite and negative."""
    modes = rocking_block().mode_names
    fresh = compared["overturn"]
    assert [modes[k] for k in fresh["cpu_mode_final"]] == compared["scalar_modes"]
    assert compared["scalar_modes"] == ["right_corner", "overturned", "overturned"]
    assert fresh["cpu_impacts_by_stop"][1][rocking_block().stop_names.index("overturn_right")] == 1
    chain = compared["lyapunov overturn chained"]
    assert [modes[k] for k in chain["cpu_mode_final"]] == ["right_corner", "right_corner", "overturned"]
    *rocking, last = chain["cpu_lyapunov_values"]
    assert all(math.isfinite(v) and v < 0 for v in rocking) and last == -math.inf
