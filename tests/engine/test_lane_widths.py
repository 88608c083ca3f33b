"""The vector code of processors with narrower registers than this one (``GRAZING_LANE_WIDTH``).

The lanes are as wide as the processor's widest vector registers (8 doubles with AVX-512, 4 with
AVX, 2 otherwise), and the default suite checks the lanes against the scalar path at that width
only.  ``GRAZING_LANE_WIDTH`` narrows them, so that this machine runs (and checks, bit for bit)
the code a narrower processor would run; the kernels and the driver are compiled for that width
(their cache keys hold it).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from grazing.engine import llvmgen
from grazing.errors import GrazingError

ROOT = Path(__file__).resolve().parents[2]
LANE_TESTS = ["tests/engine/test_lanes.py", "tests/engine/test_lanevec.py", "tests/engine/test_sincos.py"]


@pytest.mark.slow
@pytest.mark.parametrize("width", [2, 4])
def test_the_lanes_of_a_narrower_processor_equal_the_scalar_path(width) -> None:
    if width >= llvmgen.lane_width():
        pytest.skip(f"this processor's lanes are {llvmgen.lane_width()} wide: the default suite runs them")
    env = {**os.environ, llvmgen.LANE_WIDTH_ENV: str(width)}
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-m", "not slow", *LANE_TESTS]
    out = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True, timeout=1800)
    assert out.returncode == 0, out.stdout[-4000:] + out.stderr[-2000:]


def test_the_lane_width_asked_for_is_checked(monkeypatch) -> None:
    widest = llvmgen.lane_width.__wrapped__()  # (lane_width itself is cached for the process)
    for asked in ("2", " 2 ", str(widest)):
        monkeypatch.setenv(llvmgen.LANE_WIDTH_ENV, asked)
        assert llvmgen.lane_width.__wrapped__() == int(asked)
    for asked in ("3", "16", "eight", "0", str(2 * widest)):
        monkeypatch.setenv(llvmgen.LANE_WIDTH_ENV, asked)
        with pytest.raises(GrazingError, match="GRAZING_LANE_WIDTH"):
            llvmgen.lane_width.__wrapped__()
    monkeypatch.setenv(llvmgen.LANE_WIDTH_ENV, "")
    assert llvmgen.lane_width.__wrapped__() == widest
