"""Fuzz cases of known bugs not fixed yet: marked xfail by name, not skipped (none at present).

Each entry of :data:`KNOWN` names one bug and says which cases show it (with :func:`_value` and
:func:`_env`); once it is fixed, delete the entry: the cases then must pass.  Issue 43's list, and the
subnormal box of ``basins``/``attractors`` the fuzz found, are fixed.
"""

from __future__ import annotations

from collections.abc import Callable

import pytest

from tests.fuzz.cases import Case

REASON = "a known bug, not fixed yet"


def _value(case: Case, option: str) -> str | None:
    """The last value ``option`` is given in ``case``, or None."""
    values = [case.argv[i + 1] for i in range(len(case.argv) - 1) if case.argv[i] == option]
    return values[-1] if values else None


def _env(case: Case, name: str) -> str | None:
    return dict(case.env).get(name)


KNOWN: dict[str, Callable[[Case], bool]] = {}
"""Each known bug -> whether a case shows it."""

FOUND: dict[str, Callable[[Case], bool]] = {}
"""Bugs the fuzz found that are not fixed yet (reported in issue 43's follow-up), marked the same way."""


def known_bugs(case: Case) -> list[str]:
    """The known bugs ``case`` shows."""
    return [name for name, shows in {**KNOWN, **FOUND}.items() if shows(case)]


def marks(case: Case) -> list[pytest.MarkDecorator]:
    """``case``'s xfail mark if it shows a known bug (not strict: it may pass, once fixed)."""
    bugs = known_bugs(case)
    if not bugs:
        return []
    why = REASON if any(KNOWN.get(b) for b in bugs) else "found by the fuzz, not fixed yet"
    return [pytest.mark.xfail(strict=False, reason=f"{why}: {'; '.join(bugs)}")]
