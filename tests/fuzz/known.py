"""The fuzz cases of the bugs of issue 43 being fixed on branch fix43: marked xfail by name, not skipped.

Each entry of :data:`KNOWN` names one bug and says which cases show it.  Once fix43 is merged, delete
the entries it fixed (or all of :data:`KNOWN`): the cases then must pass.
"""

from __future__ import annotations

from collections.abc import Callable

import pytest

from tests.fuzz.cases import HUGE_INT, Case

REASON = "issue 43: fixed on branch fix43"


def _value(case: Case, option: str) -> str | None:
    """The last value ``option`` is given in ``case``, or None."""
    values = [case.argv[i + 1] for i in range(len(case.argv) - 1) if case.argv[i] == option]
    return values[-1] if values else None


def _env(case: Case, name: str) -> str | None:
    return dict(case.env).get(name)


HUGE_VALUES = {"--x-range": "-1e308,1e308", "--y-range": "-1e308,1e308", "--noise": "1e308"}
"""Options and values whose arithmetic overflows (numpy's RuntimeWarning printed before the error line)."""


KNOWN: dict[str, Callable[[Case], bool]] = {
    "analyze --cutoff-hz tiny: a traceback": lambda c: (
        c.command == "analyze" and _value(c, "--cutoff-hz") in ("1e-320", "1e-300")
    ),
    "analyze --phase 1e308: a traceback": lambda c: (
        c.command == "analyze" and _value(c, "--phase") in ("1e308", "-1e308", "99999999999999999999")
    ),
    "normal-form on a model without contact_direction: a traceback": lambda c: (
        c.command == "normal-form" and "nocd.py:nocd" in c.argv
    ),
    "a model file raising BaseException: a traceback": lambda c: any(
        f"{f}.py:model" in c.argv for f in ("base", "basecall", "genexit")
    ),
    "attractors --num 1000000000: memory grows, no refusal": lambda c: (
        c.command == "attractors" and _value(c, "--num") == HUGE_INT
    ),
    "a NetCDF file whose attributes a user edited replaced without --overwrite": lambda c: (
        "edited-attrs.nc" in c.argv and not c.overwrite
    ),
    "stdout on a full disk without PYTHONUNBUFFERED: exit 120 and Python's own lines": lambda c: (
        c.stdout == "full" and _env(c, "PYTHONUNBUFFERED") is None
    ),
    "numpy's RuntimeWarning before the error line for huge values": lambda c: (
        c.command in ("basins", "attractors", "synthesize")
        and any(_value(c, option) == value for option, value in HUGE_VALUES.items())
    ),
    "--initial '' ignored by continue and curve": lambda c: (
        c.command in ("continue", "curve") and _value(c, "--initial") == ""
    ),
}
"""Each known bug of issue 43 -> whether a case shows it."""

FOUND: dict[str, Callable[[Case], bool]] = {
    "basins/attractors --x-range or --y-range of a subnormal width (0,1e-320): exit 0 after numpy's "
    "RuntimeWarning (attractors/classify.py divides by a zero cell)": lambda c: (
        c.command in ("basins", "attractors")
        and "0,1e-320" in (_value(c, "--x-range"), _value(c, "--y-range"))
    ),
}
"""Bugs the fuzz found that are not fixed yet (reported in issue 43's follow-up), marked the same way."""


def known_bugs(case: Case) -> list[str]:
    """The known bugs ``case`` shows."""
    return [name for name, shows in {**KNOWN, **FOUND}.items() if shows(case)]


def marks(case: Case) -> list[pytest.MarkDecorator]:
    """``case``'s xfail mark if it shows a known bug (not strict: it may pass, once fixed)."""
    bugs = known_bugs(case)
    if not bugs:
        return []
    why = REASON if any(KNOWN.get(b) for b in bugs) else "issue 43: found by the fuzz, not fixed yet"
    return [pytest.mark.xfail(strict=False, reason=f"{why}: {'; '.join(bugs)}")]
