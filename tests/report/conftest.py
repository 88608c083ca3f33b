"""Quick resolutions for the expensive report figures, for every test under tests/report.

The report's defaults (1000 values per diagram, a 160 x 60 map) take most of
a minute; the tests check the page and the computed numbers at a few hundred
points instead.  Tests that need a finer sweep compute it themselves.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from grazing.report import diagrams, fig07, fig08, fig12, figmap

QUICK_DIAGRAMS = diagrams.Settings(points=150, zoom_points=80, overview_points=80, transient=300, periods=60)
QUICK_FIG08 = fig08.Settings(points=150, transient=300, periods=60)
QUICK_MAP = figmap.Settings(eta=(0.3, 0.9, 24), theta_hat_deg=(5.0, 58.0, 10), transient=300, periods=40)


@pytest.fixture(scope="session", autouse=True)
def quick_report_figures() -> Iterator[None]:
    """Patch the figure modules' default settings to the quick ones for the whole session."""
    mp = pytest.MonkeyPatch()
    mp.setattr(fig07, "SETTINGS", QUICK_DIAGRAMS)
    mp.setattr(fig12, "SETTINGS", QUICK_DIAGRAMS)
    mp.setattr(fig08, "SETTINGS", QUICK_FIG08)
    mp.setattr(figmap, "SETTINGS", QUICK_MAP)
    yield
    mp.undo()
