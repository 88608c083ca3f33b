"""Every curve the orbit tests follow records, at each end, the outcome its status says."""

from __future__ import annotations

import pytest

from tests.orbits.curve_outcomes import said


@pytest.fixture(autouse=True)
def _each_curve_end_has_the_outcome_its_status_says(monkeypatch):
    from grazing.orbits.curves import _Follower

    run = _Follower.run

    def checked(self, *args, **kwargs):
        direction = run(self, *args, **kwargs)
        assert direction.outcome is said(direction.status), (direction.outcome, direction.status)
        return direction

    monkeypatch.setattr(_Follower, "run", checked)
