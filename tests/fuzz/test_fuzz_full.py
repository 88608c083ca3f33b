"""Every fuzz case the default suite does not run (issue 43): ``make test-all``."""

from __future__ import annotations

import os

import pytest

from tests.fuzz.cases import all_cases, fast_sample
from tests.fuzz.check import check_case
from tests.fuzz.known import marks

pytestmark = [pytest.mark.slow, pytest.mark.skipif(os.name != "posix", reason="pipes, rlimits")]

_FAST = {c.id for c in fast_sample(all_cases())}
CASES = [c for c in all_cases() if c.id not in _FAST]


@pytest.mark.parametrize("case", [pytest.param(c, id=c.id, marks=marks(c)) for c in CASES])
def test_full_case(case, template, tmp_path):
    check_case(case, template, tmp_path)
