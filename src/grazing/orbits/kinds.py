"""The kinds of special points of a branch and of bifurcation curves, each spelled once.

A :class:`SpecialKind` is what :func:`~grazing.orbits.continuation.continue_orbit` locates on a
branch (:attr:`~grazing.orbits.continuation.SpecialPoint.kind`); a :class:`CurveKind` is what
:func:`~grazing.orbits.curves.follow_curve` follows in two parameters (the command line's
``--kind``).  Both are strings whose values are the words that ``--json`` and the datasets write
(``"branch point"`` on a branch, ``"branch-point"`` as a curve's kind), so they compare equal to
those words and print as them; a curve's kind names the special point it starts from
(:attr:`CurveKind.start`), matched by the member's name.
"""

from __future__ import annotations

import enum


class TextEnum(str, enum.Enum):
    """A string enum that prints as its value in every Python version (``str``, ``format``, f-strings: from
    Python 3.12 a plain ``(str, Enum)`` formats as ``Class.MEMBER``) and compares equal to it; its
    ``repr`` is the value's too, so that lists of kinds print as they did when kinds were strings (and
    code printed from them runs).

    Examples
    --------
    >>> [SpecialKind.GRAZING], type(SpecialKind.GRAZING).__name__
    (['grazing'], 'SpecialKind')
    """

    def __repr__(self) -> str:
        return repr(str(self.value))

    def __str__(self) -> str:
        return str(self.value)

    def __format__(self, spec: str) -> str:
        return format(str(self.value), spec)


class SpecialKind(TextEnum):
    """The kind of a special point of a branch (its ``--json`` ``kind``).

    Examples
    --------
    >>> SpecialKind.BRANCH_POINT == "branch point", f"{SpecialKind.NEIMARK_SACKER}"
    (True, 'neimark-sacker')
    >>> SpecialKind("period-doubling") is SpecialKind.PERIOD_DOUBLING
    True
    """

    FOLD = "fold"
    BRANCH_POINT = "branch point"
    PERIOD_DOUBLING = "period-doubling"
    NEIMARK_SACKER = "neimark-sacker"
    GRAZING = "grazing"
    GRAZING_SLIDING = "grazing-sliding"
    """A sliding segment appears where the orbit touches a sliding surface from outside
    (:mod:`grazing.orbits.sliding_bifurcations`, as the three that follow)."""
    CROSSING_SLIDING = "crossing-sliding"
    """A crossing of the surface turns into a short sliding segment between the two sides."""
    SWITCHING_SLIDING = "switching-sliding"
    """An entry into sliding turns into a crossing and a short excursion before the entry."""
    ADDING_SLIDING = "adding-sliding"
    """A short excursion off the surface splits a sliding segment in two."""
    DOUBLE_GRAZING = "double grazing"
    """The orbit grazes two surfaces at once (codimension two, but for a symmetry that maps one contact
    onto the other): a branch ends there."""
    UNLOCATED = "unlocated"
    """A stability change that no located point explains (never silent)."""

    @property
    def curve(self) -> CurveKind | None:
        """The curve that follows this point in two parameters (None for an unlocated change).

        >>> SpecialKind.BRANCH_POINT.curve is CurveKind.BRANCH_POINT
        True
        """
        return CurveKind.__members__.get(self.name)


class CurveKind(TextEnum):
    """The kind of a bifurcation curve (the command line's ``--kind``, a curve's ``kind``).

    Examples
    --------
    >>> CurveKind("branch-point").start is SpecialKind.BRANCH_POINT
    True
    >>> [str(k) for k in CurveKind]
    ['fold', 'period-doubling', 'neimark-sacker', 'branch-point', 'grazing']
    """

    FOLD = "fold"
    PERIOD_DOUBLING = "period-doubling"
    NEIMARK_SACKER = "neimark-sacker"
    BRANCH_POINT = "branch-point"
    GRAZING = "grazing"

    @property
    def start(self) -> SpecialKind:
        """The one-parameter special point the curve starts from."""
        return SpecialKind[self.name]
