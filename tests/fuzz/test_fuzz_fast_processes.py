"""The fuzz's default-suite sample run as processes: closed pipes, /dev/full, a full disk, the environment
(issue 43; a file of its own so that it runs beside test_fuzz_fast.py)."""

from __future__ import annotations

import os

import pytest

from tests.fuzz.cases import all_cases, fast_sample
from tests.fuzz.check import check_case
from tests.fuzz.known import marks

pytestmark = pytest.mark.skipif(os.name != "posix", reason="pipes, rlimits, process groups")

CASES = [c for c in fast_sample(all_cases()) if c.process]


@pytest.mark.parametrize("case", [pytest.param(c, id=c.id, marks=marks(c)) for c in CASES])
def test_fast_process_case(case, template, tmp_path):
    check_case(case, template, tmp_path)
