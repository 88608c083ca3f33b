"""Each sweep point's outcome: ok, or why it failed (a :class:`~grazing.core.solution.Status` code).

A sweep keeps one ``status`` per point (the dataset's variable ``status``,
stored with the other results in a Zarr store and a NetCDF file); a failed
point has ``period`` -1 and NaN samples.  The codes are the engine's
:class:`~grazing.core.solution.Status`; -1 is a point a store has not
computed yet.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from grazing.core.solution import Status

NOT_COMPUTED = -1
"""The status of a point of a store whose chunk is not computed yet."""

STATUS_DTYPE = np.int8
"""The dtype of the ``status`` variable."""

POINT_STATUSES = (Status.OK, Status.STEP_LIMIT, Status.NONFINITE, Status.ZENO, Status.OUTSIDE_MODE)
"""The outcomes a computed point can have (an interrupted sweep keeps no point of its unfinished chunks)."""


def status_attrs() -> dict[str, Any]:
    """The attributes of the ``status`` variable: its codes and their meanings (CF flag conventions).

    Examples
    --------
    >>> a = status_attrs()
    >>> a["flag_values"].tolist(), a["flag_meanings"]
    ([-1, 0, 1, 2, 3, 5], 'not_computed ok step_limit non_finite_state accumulating_impacts outside_its_mode')
    """
    codes = [NOT_COMPUTED, *(int(s) for s in POINT_STATUSES)]
    words = ["not computed", *(s.reason for s in POINT_STATUSES)]
    meanings = "; ".join(f"{int(s)} {s.reason}: {s.explanation}" for s in POINT_STATUSES)
    return {
        "flag_values": np.array(codes, dtype=STATUS_DTYPE),
        "flag_meanings": " ".join(w.replace(" ", "_").replace("-", "_") for w in words),
        "description": f"the point's outcome (a failed point has period -1 and no samples): {meanings}; "
        f"{NOT_COMPUTED} not computed (yet: in a store)",
    }


def reason(code: int) -> str:
    """The words for a status code: ``'ok'``, ``'step limit'`` ... (``'not computed'`` for -1).

    Examples
    --------
    >>> reason(0), reason(2), reason(-1)
    ('ok', 'non-finite state', 'not computed')
    """
    return "not computed" if code == NOT_COMPUTED else Status(int(code)).reason


def reasons(status: np.ndarray) -> Any:
    """``status`` (any shape) as nested lists of :func:`reason` words (as ``--json`` prints them).

    Examples
    --------
    >>> reasons(np.array([[0, 1], [3, 0]]))
    [['ok', 'step limit'], ['accumulating impacts', 'ok']]
    """
    words = np.array([reason(c) for c in range(NOT_COMPUTED, len(Status))], dtype=object)
    return words[np.asarray(status, dtype=int) - NOT_COMPUTED].tolist()


def failures(status: np.ndarray) -> dict[str, int]:
    """The failed points (status other than ok) counted by reason, most frequent first.

    Examples
    --------
    >>> failures(np.array([0, 1, 2, 1, 0]))
    {'step limit': 2, 'non-finite state': 1}
    """
    codes, counts = np.unique(np.asarray(status, dtype=int).ravel(), return_counts=True)
    found = [(reason(c), int(n)) for c, n in zip(codes, counts) if c != int(Status.OK)]
    return dict(sorted(found, key=lambda item: -item[1]))


def failure_text(status: np.ndarray, label: str = "failed: ") -> str:
    """The failed points and their reasons in a few words, as the command line's summaries print them.

    Examples
    --------
    >>> failure_text(np.array([1, 1, 2, 0]))
    'failed: 3 (step limit: 2, non-finite state: 1)'
    >>> failure_text(np.zeros(4, dtype=int))
    'failed: 0'
    """
    found = failures(status)
    total = sum(found.values())
    detail = ", ".join(f"{why}: {n}" for why, n in found.items())
    return f"{label}{total}" + (f" ({detail})" if total else "")
