"""The discontinuity map on a model with modes on the GPU kernel under numba's CUDA simulator: equal to the
CPU lanes.

The bumper oscillator (``tests/engine/zdm_modes_model.py``), the map standing for its bumper, a stop of
mode ``Taut_2`` (kicks past the grazing), or of mode ``Slack_1`` where at the map's phase the run is in
``Taut_2`` (no kick: the kernel's ``apply_map`` checks the mode, as ``tangent.discontinuity_map`` does).
In the simulator the GPU does the CPU's arithmetic: periods, kicks and statuses equal, samples, final
states and exponents equal to the bit.  The cases run in a process of their own (``cases_zdm_modes.py``).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.gpu.test_simulator import assert_gpu_equals_cpu, simulator_results

CASES = tuple(
    f"zdm modes bumper in {where}{lyap}" for where in ("Taut_2", "Slack_1") for lyap in ("", " lyapunov")
)
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def compared() -> dict[str, dict[str, object]]:
    """Every case's CPU and GPU results (one process under the simulator)."""
    return simulator_results("cases_zdm_modes.py")


@pytest.mark.parametrize("case", CASES)
def test_the_gpu_equals_the_cpu_lanes_with_the_map_on_a_model_with_modes(
    compared: dict[str, dict[str, object]], case: str
) -> None:
    row = compared[case]
    assert row["cpu_points"] == 0  # (every point the GPU's)
    assert_gpu_equals_cpu(row)


def test_the_map_kicks_in_its_stops_mode_only(compared: dict[str, dict[str, object]]) -> None:
    """Not trivially equal: in ``Taut_2`` no kick below the grazing, kicks past it; in ``Slack_1`` none."""
    for case in CASES:
        kicks = compared[case]["cpu_kicks"]
        if "Taut_2" in case:
            assert kicks[0] == 0 and min(kicks[1:]) > 0, (case, kicks)
        else:
            assert kicks == [0, 0, 0], (case, kicks)
