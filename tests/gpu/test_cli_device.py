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
    for extra in (["--no-lyapunov"], []):  # (no device; Lyapunov exponents not on the GPU yet)
        run = grazing([*MAP, *extra, "--device", "gpu", "--out", "m.zarr"], tmp_path)
        assert run.returncode != 0
        assert len(run.stderr.strip().splitlines()) == 1 and "device" in run.stderr
        assert list(tmp_path.iterdir()) == []


def test_the_map_on_the_simulated_gpu_is_the_cpus(tmp_path: Path) -> None:
    args = [*MAP, "--no-lyapunov", "--fresh", "--json"]
    cpu = grazing([*args, "--device", "cpu"], tmp_path)
    gpu = grazing([*args, "--device", "gpu"], tmp_path, simulator=True)
    assert cpu.returncode == 0 and gpu.returncode == 0, gpu.stderr
    a, b = json.loads(cpu.stdout), json.loads(gpu.stdout)
    a.pop("elapsed_s"), b.pop("elapsed_s")
    assert a == b
