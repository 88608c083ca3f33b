"""What a curve's status says about each of its ends, read from the words (docs/bifurcation-curves.md), to
check the :class:`~grazing.orbits.curve_data.CurveEnd` recorded beside it."""

from __future__ import annotations

from grazing.orbits.curve_data import CurveEnd

STATUS_STARTS = (
    ("reached the bound ", CurveEnd.BOUND),
    ("ended at a grazing at ", CurveEnd.GRAZING),
    ("ended at a double grazing at ", CurveEnd.DOUBLE_GRAZING),
    ("ended at a 1:1 resonance at ", CurveEnd.RESONANCE_1_1),
    ("ended at a 1:2 resonance at ", CurveEnd.RESONANCE_1_2),
    ("shift = ", CurveEnd.NOT_PERSISTENT),
    ("step size fell below ", CurveEnd.STUCK),
    (
        "an impact approaches the section and the orbit could not be found on another section",
        CurveEnd.NO_SECTION,
    ),
    ("an impact approaches the section", CurveEnd.RESECTION),
    ("maximum number of points reached", CurveEnd.MAX_POINTS),
    ("the curve came back to its start ", CurveEnd.CLOSED),
)
"""How the status of one end of a curve starts, and the outcome that says the same (the first that
matches: the section that could not be moved before the section that had to)."""


def said(status: str) -> CurveEnd:
    """The outcome the status of one end of a curve says."""
    for start, outcome in STATUS_STARTS:
        if status.startswith(start):
            return outcome
    raise AssertionError(f"a curve's end that no outcome says: {status!r}")


def ends(status: str) -> tuple[str, str]:
    """The status of the curve's first and last ends."""
    first, last = status.removeprefix("at the first point: ").split("; at the last point: ")
    return first, last
