"""Chains of several chunks on the GPU under numba's CUDA simulator: settled as on the CPU, the same dataset.

A carried sweep split into more chunks than chains is settled into its chains
(:func:`grazing.sweeps.chain.settle`: every chunk from a guess, then its first point checked from the chain's
start, shifted along an orbit or run again); on the GPU each round's parts are launched by
:func:`grazing.gpu.batch.gpu_parts`.  In the simulator the GPU does the CPU's arithmetic, so
``run_sweep(device="gpu")`` must give every variable of ``device="cpu"``'s dataset to the bit.  The cases run
in a process of their own with ``NUMBA_ENABLE_CUDASIM=1`` (``cases_chains.py``).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.gpu.test_simulator import simulator_results

ROOT = Path(__file__).resolve().parents[2]
CASES = ("pendulum C both directions",)


@pytest.fixture(scope="module")
def compared() -> dict[str, dict[str, object]]:
    """Every case's CPU and GPU datasets compared (one process under the simulator)."""
    return simulator_results("cases_chains.py")


@pytest.mark.parametrize("case", CASES)
def test_a_chain_of_several_chunks_on_the_gpu_is_the_cpus(
    compared: dict[str, dict[str, object]], case: str
) -> None:
    row = compared[case]
    assert {"period", "samples", "status", "impacts", "x_final", "transient_used"} <= set(row["variables"])
    assert row["differ"] == [], row["differ"]
    assert row["gpu_period"] == row["cpu_period"]


@pytest.mark.parametrize("case", CASES)
def test_the_chain_is_settled_on_the_gpu(compared: dict[str, dict[str, object]], case: str) -> None:
    """The GPU launched every chunk from its guess first, then checked first points from the chains' starts
    and ran chunks from there (again, or shifted along their orbit); one chunk's guess is not the chain's,
    so a GPU that ignored the starts, or handed back another part's result, would differ from the CPU."""
    row = compared[case]
    launches = row["launches"]
    assert launches[0] == {"guesses": row["n_chunks"], "checks": 0, "runs": 0, "from_start": 0}, launches
    later = launches[1:]
    assert all(launch["guesses"] == 0 for launch in later)
    assert sum(launch["checks"] for launch in later) >= row["n_chunks"] - row["segments"]
    assert sum(launch["runs"] for launch in later) >= 1
    assert all(launch["from_start"] == launch["checks"] + launch["runs"] for launch in later)
    assert row["missed_guesses"] >= 1


@pytest.mark.parametrize("case", CASES)
def test_the_settled_chain_is_the_one_chunk_chains(compared: dict[str, dict[str, object]], case: str) -> None:
    """The chain's answer: the periods of each direction run as one chunk on the CPU; several periods."""
    row = compared[case]
    assert row["gpu_period"] == row["whole_period"]
    assert row["cpu_status"] == [[0] * 6, [0] * 6]
    assert {1, 2, 3} <= {p for line in row["cpu_period"] for p in line}


def test_a_chain_into_a_store_one_chunk_at_a_time_is_the_same(compared: dict[str, dict[str, object]]) -> None:
    """Into a Zarr store with a window of one chunk (:func:`~grazing.gpu.batch.gpu_chain_window`): the same
    dataset, no launch holding more than one chunk's guess."""
    row = compared["stored"]
    assert row["window"] == 1 and row["differ"] == [], row
    assert all(launch["guesses"] <= 1 for launch in row["launches"]) and len(row["launches"]) >= 3, row


def test_gpu_parts_hands_back_each_part_with_its_result(compared: dict[str, dict[str, object]]) -> None:
    """Launches of one point each: every part (a chunk, a chunk from a start, a first point checked there) is
    handed back as the caller's tuple, in order, with the CPU lanes' result."""
    row = compared["batched"]
    assert row["same_parts"] == [True] * 3 and row["same_results"] == [True] * 3, row


def test_a_chain_of_several_chunks_is_no_longer_refused() -> None:
    """``device="gpu"`` on a chain of several chunks: where no device is present, the only error is that."""
    import grazing
    from grazing.gpu.device import spec_device
    from grazing.gpu.target import NoDeviceError, device_present
    from grazing.sweeps import sweep
    from grazing.sweeps.spec import sweep_spec

    m = grazing.models.pendulum("B")
    chained = sweep_spec(
        m, "eta", [0.44, 0.45, 0.46], settings=grazing.SweepSettings(lyapunov=False, chunk_size=2)
    )
    assert chained.n_chunks == 2 and spec_device("gpu", chained) == "gpu"
    if device_present():
        pytest.skip("a CUDA device is present")
    with pytest.raises(NoDeviceError) as info:
        sweep(m, "eta", [0.44, 0.45, 0.46], lyapunov=False, chunk_size=2, device="gpu")
    assert "\n" not in str(info.value) and "(device=)" in str(info.value)
