"""``run_sweeps(device="gpu")`` under numba's CUDA simulator: each sweep's dataset is ``device="cpu"``'s.

Several sweeps run together: the chunks of those sharing the model and settings go into the same launches
(:func:`grazing.gpu.batch.gpu_parts`), a carried sweep of several chunks a chain is settled on the device
(:func:`grazing.sweeps.chain.settle`).  In the simulator the GPU does the CPU's arithmetic, so every variable
must be equal to the bit.  The cases run in a process of their own with ``NUMBA_ENABLE_CUDASIM=1``
(``cases_run_sweeps.py``).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.gpu.test_simulator import simulator_results

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def compared() -> dict[str, object]:
    """The CPU's and the GPU's datasets of the sweeps compared (one process under the simulator)."""
    return simulator_results("cases_run_sweeps.py")


def test_run_sweeps_on_the_gpu_is_the_cpus(compared: dict[str, object]) -> None:
    """Every sweep's dataset on the GPU equals the CPU's (run together, and each run alone)."""
    assert compared["chained"] == [False, False, True, False]
    assert all({"period", "samples", "status", "x_final"} <= set(v) for v in compared["variables"])
    assert compared["differ"] == [[]] * 4, compared["differ"]
    assert compared["differ_alone"] == [[]] * 4, compared["differ_alone"]
    assert compared["gpu_period"] == compared["cpu_period"]
    assert len({p for line in compared["cpu_period"] for p in line}) >= 3  # (periods 1, 2, 3 and chaos)


def test_sweeps_sharing_settings_share_a_launch(compared: dict[str, object]) -> None:
    """The two fresh sweeps' chunks went to the GPU in one launch; the chain's in launches of its own."""
    launches = compared["launches"]
    assert launches and launches[0] == [0, 0, 1, 1], launches
    assert any(2 in parts for parts in launches[1:]) and all(2 not in parts for parts in launches[:1])


def test_run_sweeps_refuses_a_bad_device() -> None:
    """A device that is not one: the one-line error of ``run_sweep``, before anything runs."""
    import math

    import grazing
    from grazing.errors import InvalidParameterError
    from grazing.sweeps.api import run_sweeps
    from grazing.sweeps.spec import sweep_spec

    spec = sweep_spec(grazing.models.pendulum("B", theta_hat=math.radians(40)), "eta", [0.44])
    with pytest.raises(InvalidParameterError, match="device must be 'cpu', 'gpu' or 'auto', got 'tpu'"):
        run_sweeps([spec], device="tpu")
    ds = run_sweeps([spec], workers=1, device="auto")[0]  # (one point: auto keeps it on the CPU)
    assert ds.period.values.tolist() == run_sweeps([spec], workers=1)[0].period.values.tolist()
