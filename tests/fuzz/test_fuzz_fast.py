"""The fuzz's default-suite sample run in this process (issue 43; the rest: test_fuzz_full.py)."""

from __future__ import annotations

import pytest

from tests.fuzz.cases import all_cases, fast_sample
from tests.fuzz.check import check_case
from tests.fuzz.known import marks

CASES = [c for c in fast_sample(all_cases()) if not c.process]


@pytest.mark.parametrize("case", [pytest.param(c, id=c.id, marks=marks(c)) for c in CASES])
def test_fast_case(case, template, tmp_path):
    check_case(case, template, tmp_path)
