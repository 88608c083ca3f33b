"""Sticking on the GPU kernel under numba's CUDA simulator: its sweeps equal the CPU lanes' at every point.

Complete chattering summed to its accumulation point and continued as sticking, the release by the contact
force, a switch or another stop while sticking, on models of one mode and with modes, with and without
Lyapunov exponents (``cases_stick.py``, in a process of its own with ``NUMBA_ENABLE_CUDASIM=1``).  In the
simulator the GPU does the CPU's arithmetic, so everything is equal to the bit (``test_simulator.py``), and
no point is handed to the CPU lanes.
"""

from __future__ import annotations

import math

import pytest

from tests.gpu.test_simulator import assert_gpu_equals_cpu, simulator_results

LYAPUNOV_CASES = ("lyapunov ball chained", "lyapunov impact oscillator", "lyapunov stick spring")
FRESH_CASES = ("ball", "ball under a ceiling", "impact oscillator", "stick spring floor second", "stick lift")
MODE_CASES = ("stick spring chained", "stick spring floor second", "stick lift", "lyapunov stick spring")
CASES = (*FRESH_CASES, "stick spring chained", *LYAPUNOV_CASES)


@pytest.fixture(scope="module")
def compared() -> dict[str, dict[str, object]]:
    """Every case's CPU and GPU results (one process under the simulator)."""
    return simulator_results("cases_stick.py")


@pytest.mark.parametrize("case", CASES)
def test_sticking_on_the_gpu_equals_the_cpu_lanes_at_every_point(
    compared: dict[str, dict[str, object]], case: str
) -> None:
    row = compared[case]
    assert_gpu_equals_cpu(row)


def test_no_point_that_sticks_goes_to_the_cpu(compared: dict[str, dict[str, object]]) -> None:
    """The GPU batch calls the CPU lanes for no point: sticking is the kernel's."""
    assert all(compared[case]["cpu_points"] == 0 for case in CASES)


def test_the_cases_stick_and_release(compared: dict[str, dict[str, object]]) -> None:
    """Every point of the fresh cases sticks in its recorded span (the scalar driver's sticking intervals)
    and is released again (its samples are not all on the stop: impacts in the span, a period), as do the
    first points of the chains; the points all succeed."""
    for case in CASES:
        row = compared[case]
        assert set(row["cpu_status"]) == {0}, (case, row["cpu_status"])
        sticks = row["scalar_sticking"] if case in FRESH_CASES else row["scalar_sticking"][:1]
        if case not in ("lyapunov ball chained", "impact oscillator", "lyapunov impact oscillator"):
            assert all(n > 0 for n in sticks), (case, row["scalar_sticking"])
        assert all(sum(counts) > 0 for counts in row["cpu_impacts_by_stop"]), case
    for case in ("impact oscillator", "lyapunov impact oscillator"):
        assert compared[case]["scalar_sticking"][0] > 0  # (omega = 0.5 sticks; 0.7 only chatters)
    assert compared["lyapunov ball chained"]["scalar_sticking"][-1] > 0


def test_the_floor_is_found_by_its_stop_index(compared: dict[str, dict[str, object]]) -> None:
    """With the floor as transition 1 (the sticking kernel dispatched by the stop's index, its force in row
    0 of its mode) the impacts are on stop 1, as they are on stop 0 where the floor is transition 0; the
    ball's table as stop 1 of one mode (its force in row 1) takes every impact."""
    assert all(
        c[1] > 0 and c[0] == c[2] == 0 for c in compared["stick spring floor second"]["cpu_impacts_by_stop"]
    )
    assert all(c[0] > 0 for c in compared["stick spring chained"]["cpu_impacts_by_stop"])
    assert all(c == [0, c[1]] and c[1] > 0 for c in compared["ball under a ceiling"]["cpu_impacts_by_stop"])


def test_an_exponent_only_where_the_recorded_span_does_not_stick(
    compared: dict[str, dict[str, object]],
) -> None:
    """Sticking has no variational equations: a point that sticks in its recorded span has no exponent
    (NaN), one that does not stick has a finite one, on both sides alike (the equality test)."""
    ball = compared["lyapunov ball chained"]["cpu_lyapunov_values"]
    assert all(math.isfinite(v) for v in ball[:2]) and math.isnan(ball[2]), ball
    oscillator = compared["lyapunov impact oscillator"]["cpu_lyapunov_values"]
    assert math.isnan(oscillator[0]) and math.isfinite(oscillator[1]) and oscillator[1] < 0, oscillator
    assert all(math.isnan(v) for v in compared["lyapunov stick spring"]["cpu_lyapunov_values"])
