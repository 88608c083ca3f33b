"""``grazing sweep`` and ``grazing map`` with ``--device``: the GPU's results under numba's CUDA simulator
are the CPU's, and what cannot run is refused in one line before anything is written."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MAP = (
    "map --param1 eta --start1 0.44 --stop1 0.45 --num1 2 --param2 theta_hat --start2 30 --stop2 40 "
    "--num2 2 --periods 10 --transient 20"
).split()


def grazing(args: list[str], cwd: Path, simulator: bool = False) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT / "src"), str(ROOT), env.get("PYTHONPATH")) if p)
    env.pop("NUMBA_ENABLE_CUDASIM", None)
    if simulator:
        env["NUMBA_ENABLE_CUDASIM"] = "1"
    command = [sys.executable, "-m", "grazing", *args]
    return subprocess.run(command, capture_output=True, text=True, cwd=cwd, env=env, timeout=300)


def test_gpu_without_a_device_is_one_line_and_writes_nothing(tmp_path: Path) -> None:
    for extra in (["--no-lyapunov"], []):  # (no device, with or without Lyapunov exponents)
        run = grazing([*MAP, *extra, "--device", "gpu", "--out", "m.zarr"], tmp_path)
        assert run.returncode != 0
        assert len(run.stderr.strip().splitlines()) == 1 and "device" in run.stderr
        assert list(tmp_path.iterdir()) == []


def test_the_map_on_the_simulated_gpu_is_the_cpus(tmp_path: Path) -> None:
    """With Lyapunov exponents (the default): they are the CPU's too."""
    args = [*MAP, "--fresh", "--json"]
    cpu = grazing([*args, "--device", "cpu"], tmp_path)
    gpu = grazing([*args, "--device", "gpu"], tmp_path, simulator=True)
    assert cpu.returncode == 0 and gpu.returncode == 0, gpu.stderr
    a, b = json.loads(cpu.stdout), json.loads(gpu.stdout)
    a.pop("elapsed_s"), b.pop("elapsed_s")
    assert a == b
    assert all(isinstance(v, float) and v == v for line in a["lyapunov"] for v in line), a["lyapunov"]


BALL = "--model bouncing-ball --set r=0.8 --set omega=1 --set gravity=1".split()
GRID = "--x-range 0,6 --y-range=-4,4 --num 3,3 --transient 20 --periods 8 --no-lyapunov --refine 0".split()


def test_basins_and_attractors_take_device_and_refuse_gpu_without_one_in_one_line(tmp_path: Path) -> None:
    basins = ["basins", *BALL, "--set", "amplitude=0.8", *GRID, "--out", "b.nc"]
    along = ["--param", "amplitude", "--start", "0.7", "--stop", "0.8", "--num", "2"]
    grid = [g.replace("--num", "--num-grid") for g in GRID]
    attractors = ["attractors", *BALL, *along, *grid, "--out", "a.nc"]
    for args in (basins, attractors):
        run = grazing([*args, "--device", "gpu"], tmp_path)
        assert run.returncode != 0, run.stdout
        assert len(run.stderr.strip().splitlines()) == 1 and "device" in run.stderr, run.stderr
        assert list(tmp_path.iterdir()) == []


def test_basins_on_the_simulated_gpu_are_the_cpus(tmp_path: Path) -> None:
    args = ["basins", *BALL, "--set", "amplitude=0.8", *GRID, "--json"]
    cpu = grazing([*args, "--device", "cpu"], tmp_path)
    gpu = grazing([*args, "--device", "gpu"], tmp_path, simulator=True)
    assert cpu.returncode == 0 and gpu.returncode == 0, gpu.stderr
    a, b = json.loads(cpu.stdout), json.loads(gpu.stdout)
    a.pop("elapsed_s"), b.pop("elapsed_s")
    assert a == b and a["attractors"], a
