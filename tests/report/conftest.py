"""Quick resolutions for the expensive report figures, and one quick report shared by the tests.

The report's defaults (1000 values per diagram, a 160 x 60 map) take minutes;
the tests check the page, the records and the computed numbers at a few
hundred points instead.  Tests that need a finer sweep compute it themselves.
The report is built once per session (:func:`built`) and read by
test_report.py, test_comparisons.py and test_browser.py.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from grazing.report import (
    build_report,
    diagrams,
    fig07,
    fig08,
    fig12,
    figadding,
    figattractors,
    figmap,
    figstops,
)

QUICK_DIAGRAMS = diagrams.Settings(points=150, zoom_points=80, overview_points=80, transient=300, periods=60)
QUICK_FIG08 = fig08.Settings(points=150, transient=300, periods=60)
QUICK_MAP = figmap.Settings(eta=(0.3, 0.9, 24), theta_hat_deg=(5.0, 58.0, 10), transient=300, periods=40)
QUICK_STOPS = figstops.Settings(values=(0.5, 1.6, 45), transient=150, periods=16)
QUICK_ATTRACTORS = figattractors.Settings(eta=(0.50, 0.70, 41), grid=(30, 30), checked_cells=6)  # issue 28
QUICK_ADDING = figadding.Settings(
    eta=(0.44, 0.48, 41), theta_hat_deg=(36.0, 44.0, 5), transient=300, periods=40
)
"""issue 27: the windows of period 2-5 at 40 degrees (their curves end at 36 and 44 degrees)."""


@pytest.fixture(scope="session", autouse=True)
def quick_report_figures() -> Iterator[None]:
    """Patch the figure modules' default settings to the quick ones for the whole session."""
    mp = pytest.MonkeyPatch()
    mp.setattr(fig07, "SETTINGS", QUICK_DIAGRAMS)
    mp.setattr(fig12, "SETTINGS", QUICK_DIAGRAMS)
    mp.setattr(fig08, "SETTINGS", QUICK_FIG08)
    mp.setattr(figmap, "SETTINGS", QUICK_MAP)
    mp.setattr(figstops, "SETTINGS", QUICK_STOPS)
    mp.setattr(figattractors, "SETTINGS", QUICK_ATTRACTORS)
    mp.setattr(figadding, "SETTINGS", QUICK_ADDING)  # issue 27
    yield
    mp.undo()


@dataclass(frozen=True)
class Built:
    """A report built at the quick resolutions: its page, its text and the progress messages."""

    index: Path
    page: str
    messages: list[str]

    @property
    def out(self) -> Path:
        return self.index.parent


@pytest.fixture(scope="session")
def built(quick_report_figures: None, tmp_path_factory: pytest.TempPathFactory) -> Built:
    """The whole report, built once per session (about a minute on two cores)."""
    out = tmp_path_factory.mktemp("report") / "nested" / "report"
    messages: list[str] = []
    index = build_report(out, messages.append)
    return Built(index, index.read_text(encoding="utf-8"), messages)
