"""The rules that turn a computed number into a verdict, and the records they produce.

Three kinds of rule, each stated in words in the row it decides:

* a number against a number: ``agree`` exactly when ``|ours − paper| <= tolerance``
  (:func:`numeric_row`; a complex multiplier: the distance in the complex plane,
  :func:`complex_row`).  Unless a row says otherwise, the tolerance is half a
  unit of the paper's last printed digit (ours rounds to the paper's number),
  one unit where the paper writes "≈", "about" or "close to";
* windows against windows: a window of the reference (the simulation, or the
  paper's stated interval) is *matched* when the other sweep has a window of
  the same period whose η interval overlaps it (:func:`match_windows`); a
  figure-level ``agree`` needs more than half of the reference windows matched
  (:func:`majority`);
* a stated criterion (a period, a sequence, an inequality): :func:`criterion_row`.

Examples
--------
>>> from grazing.report.paper import Printed
>>> row = numeric_row("6", "grazing η", Printed("0.4450", "fig 6"), 0.445011, kind="paper")
>>> row.verdict, row.tolerance, row.delta_text
('agree', 5e-05, '+1.1e−05')
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from grazing.report.base import Comparison, Kind, Value, Verdict, intervals_overlap
from grazing.report.paper import Printed, PrintedComplex
from grazing.sweeps.windows import Window


def minus(text: str) -> str:
    """Replace ASCII hyphen-minus by the minus sign (−)."""
    return text.replace("-", "−")


def fmt(x: float, decimals: int) -> str:
    """``x`` with ``decimals`` decimals and a proper minus sign.

    Examples
    --------
    >>> fmt(-0.01234, 3), fmt(2.0, 0)
    ('−0.012', '2')
    """
    return minus(f"{x:.{decimals}f}")


def fmt_delta(d: float, decimals: int | None = None) -> str:
    """A signed difference: ``+0.0012``, ``−1.2e−05``; two significant digits below 10⁻³.

    Examples
    --------
    >>> fmt_delta(0.00123), fmt_delta(-1.23e-5), fmt_delta(0.0264, 4)
    ('+0.0012', '−1.2e−05', '+0.0264')
    """
    if not math.isfinite(d):
        return "—"
    if decimals is not None and abs(d) >= 10 ** (1 - decimals):  # at least two significant digits
        return minus(f"{d:+.{decimals}f}")
    if d == 0:
        return "0"
    if abs(d) >= 1e-3:
        return minus(f"{d:+.2g}" if abs(d) < 0.01 else f"{d:+.4f}".rstrip("0"))
    return minus(f"{d:+.1e}")


def _tolerance_words(p: Printed, tol: float) -> str:
    if tol == p.unit and p.approximate:
        return f"one unit of the paper's last printed digit, as it writes “≈” or “about”: {tol:g}"
    if tol == p.half_unit:
        return f"half a unit of the paper's last printed digit (ours rounds to it): {tol:g}"
    return f"{tol:g}"


def numeric_row(
    figure: str,
    quantity: str,
    paper: Printed | float,
    ours: float,
    *,
    kind: Kind,
    tolerance: float | None = None,
    why_tolerance: str = "",
    decimals: int | None = None,
    source: str = "",
    note: str = "",
    headline: str = "",
    erratum: bool = False,
    paper_text: str = "",
    ours_text: str = "",
    synthetic: bool = False,
    reference: str = "",
) -> Comparison:
    """A number against a number: ``agree`` exactly when ``|ours − paper| <= tolerance``.

    ``tolerance`` defaults to the printed number's :attr:`Printed.tolerance`;
    ``decimals`` (for display) to one more than the paper prints.

    Examples
    --------
    >>> numeric_row("4", "D", Printed("0.07", "§2.1"), 0.0964, kind="paper").verdict
    'differ'
    """
    if isinstance(paper, Printed):
        p_val = paper.value
        tol = paper.tolerance if tolerance is None else tolerance
        words = why_tolerance or _tolerance_words(paper, tol)
        p_text = paper_text or paper.text
        dec = paper.decimals + 1 if decimals is None else decimals
        source = source or paper.source
    else:
        if tolerance is None:
            raise ValueError("a plain-number paper value needs an explicit tolerance")
        p_val, tol, words = float(paper), tolerance, why_tolerance or f"{tolerance:g}"
        dec = 4 if decimals is None else decimals
        p_text = paper_text or fmt(p_val, dec)
    ours = float(ours)
    d = ours - p_val
    verdict: Verdict = "agree" if abs(d) <= tol else "differ"
    return Comparison(
        figure=figure,
        quantity=quantity,
        paper=p_val,
        ours=ours,
        kind=kind,
        rule=f"agree when |ours − paper| ≤ {words}",
        verdict=verdict,
        tolerance=tol,
        source=source,
        note=note,
        paper_text=p_text,
        ours_text=ours_text or fmt(ours, dec),
        delta=d,
        delta_text=fmt_delta(d, dec),
        synthetic=synthetic,
        headline=headline if verdict != "agree" else "",
        erratum=erratum and verdict != "agree",
        reference=reference,
    )


def complex_text(z: complex, decimals: int = 4) -> str:
    """``0.4612 ± 0.2127i`` (the conjugate pair), with a proper minus sign."""
    return minus(f"{z.real:.{decimals}f} ± {abs(z.imag):.{decimals}f}i")


def complex_row(
    figure: str,
    quantity: str,
    paper: PrintedComplex,
    ours: complex,
    *,
    kind: Kind,
    source: str = "",
    note: str = "",
    headline: str = "",
    erratum: bool = False,
    paper_text: str = "",
) -> Comparison:
    """A complex-conjugate pair of multipliers: ``agree`` when ``|ours − paper| <= half a unit · √2``.

    The pair is compared through its member with positive imaginary part.
    """
    ours = complex(ours.real, abs(ours.imag))
    d = abs(ours - paper.value)
    tol = paper.tolerance
    verdict: Verdict = "agree" if d <= tol else "differ"
    return Comparison(
        figure=figure,
        quantity=quantity,
        paper=paper_text or paper.text,
        ours=complex_text(ours, paper.real.decimals + 1),
        kind=kind,
        rule=(
            f"agree when |ours − paper| ≤ {tol:.2g}: the distance in the complex plane, half a unit of the "
            "last printed digit in each part"
        ),
        verdict=verdict,
        tolerance=tol,
        source=source or paper.real.source,
        note=note,
        delta=d,
        delta_text=f"|Δ| = {d:.1e}",
        headline=headline if verdict != "agree" else "",
        erratum=erratum and verdict != "agree",
    )


def criterion_row(
    figure: str,
    quantity: str,
    paper: Value,
    ours: Value,
    holds: bool | None,
    *,
    kind: Kind,
    rule: str,
    source: str = "",
    note: str = "",
    headline: str = "",
    erratum: bool = False,
    paper_text: str = "",
    ours_text: str = "",
    delta: float | None = None,
    delta_text: str = "",
    synthetic: bool = False,
    reference: str = "",
) -> Comparison:
    """A stated criterion: ``agree`` when it holds, ``differ`` when not, ``not comparable`` for None."""
    verdict: Verdict = "not comparable" if holds is None else ("agree" if holds else "differ")
    return Comparison(
        figure=figure,
        quantity=quantity,
        paper=paper,
        ours=ours,
        kind=kind,
        rule=rule,
        verdict=verdict,
        source=source,
        note=note,
        paper_text=paper_text,
        ours_text=ours_text,
        delta=delta,
        delta_text=delta_text,
        synthetic=synthetic,
        headline=headline if verdict != "agree" else "",
        erratum=erratum and verdict == "differ",
        reference=reference,
    )


# ---------------------------------------------------------------------------- windows


def span(w: Window) -> tuple[float, float]:
    """The η interval ``(start, stop)`` of a window: its first and last sweep point."""
    return (w.start, w.stop)


def overlap_length(a: Sequence[float], b: Sequence[float]) -> float:
    """Length of the intersection of two closed intervals (negative: the gap between them).

    Examples
    --------
    >>> overlap_length((0.0, 2.0), (1.0, 3.0)), overlap_length((0.0, 1.0), (2.0, 3.0))
    (1.0, -1.0)
    """
    return min(a[1], b[1]) - max(a[0], b[0])


@dataclass(frozen=True)
class WindowMatch:
    """A reference window and the other sweep's window that matches it, if any.

    Attributes
    ----------
    reference
        The window to be matched (e.g. in the direct simulation).
    match
        The other sweep's window of the same period (and impacting or not) whose η interval
        overlaps the reference's, the one with the largest overlap; None if there is none.
    elsewhere
        Where there is no match: the nearest window of the same period that does not overlap (it
        does not count as a match); None otherwise.
    """

    reference: Window
    match: Window | None
    elsewhere: Window | None = None

    @property
    def matched(self) -> bool:
        return self.match is not None


def match_windows(reference: Sequence[Window], other: Sequence[Window]) -> list[WindowMatch]:
    """Match every reference window with an *overlapping* window of the same period in ``other``.

    A window of the same period elsewhere (not overlapping) is not a match; it
    is recorded as ``elsewhere``.  A partial overlap is a match.

    Examples
    --------
    >>> w = lambda p, a, b: Window(p, True, 0, 1, a, b, a, b)
    >>> sim = [w(4, 0.439, 0.4394), w(2, 0.464, 0.478)]
    >>> m = match_windows(sim, [w(4, 0.442, 0.4421), w(2, 0.458, 0.4624)])
    >>> [x.matched for x in m], m[0].elsewhere.start
    ([False, False], 0.442)
    >>> match_windows([w(3, 0.45, 0.459)], [w(3, 0.4517, 0.4556)])[0].matched
    True
    """
    out = []
    for ref in reference:
        same = [o for o in other if o.period == ref.period and o.impacting == ref.impacting]
        hits = [o for o in same if intervals_overlap(span(ref), span(o))]
        if hits:
            best = max(hits, key=lambda o: overlap_length(span(ref), span(o)))
            out.append(WindowMatch(ref, best))
        else:
            near = min(same, key=lambda o: -overlap_length(span(ref), span(o)), default=None)
            out.append(WindowMatch(ref, None, near))
    return out


def majority(matches: Sequence[WindowMatch], fraction: float = 0.5) -> tuple[int, int, Verdict]:
    """``(matched, total, verdict)``: ``agree`` when more than ``fraction`` of the windows are matched.

    Examples
    --------
    >>> w = Window(2, True, 0, 1, 0.0, 1.0, 0.0, 1.0)
    >>> majority([WindowMatch(w, w)] * 5 + [WindowMatch(w, None)])
    (5, 6, 'agree')
    >>> majority([WindowMatch(w, w)] + [WindowMatch(w, None)] * 4)
    (1, 5, 'differ')
    >>> majority([])
    (0, 0, 'not comparable')
    """
    n = len(matches)
    k = sum(m.matched for m in matches)
    if n == 0:
        return 0, 0, "not comparable"
    return k, n, "agree" if k > fraction * n else "differ"


# ---------------------------------------------------------------------------- curves on a map (issue 27)


@dataclass(frozen=True)
class CurveOnMap:
    """A continued curve checked against a brute-force map (:func:`curve_on_map`).

    Attributes
    ----------
    inside
        The curve's points at least one cell from the map's edge (where both sides can be read).
    holds
        Those of them where the map's cells one cell width on either side across the curve differ.
    failed
        The points where they do not: ``(x, y, class on one side, class on the other)``.
    """

    inside: int
    holds: int
    failed: tuple[tuple[float, float, int, int], ...]

    @property
    def fraction(self) -> float:
        return self.holds / self.inside if self.inside else math.nan

    @property
    def verdict(self) -> Verdict:
        """``agree`` when it holds at every point inside the map; ``not comparable`` with none inside."""
        if self.inside == 0:
            return "not comparable"
        return "agree" if self.holds == self.inside else "differ"


def curve_on_map(
    x: Sequence[float],
    y: Sequence[float],
    grid_x: Sequence[float],
    grid_y: Sequence[float],
    classes: Any,
    where: Sequence[bool] | None = None,
) -> CurveOnMap:
    """Whether a curve lies on a change of class in a map, within the map's resolution.

    At each point of the curve (``x``, ``y``, in the units of the map's cell centres ``grid_x``,
    ``grid_y``, both equally spaced) the curve's normal is taken in cell units (one cell width
    along each axis counts the same); the rule holds there when the cells one cell width away on
    either side along the normal (``classes[row, column]``, nearest cell) differ.  Points less
    than one cell from the map's edge are left out, and those where ``where`` is false (they
    still set the normal of their neighbours).

    Examples
    --------
    A map that changes from class 0 to class 1 at x = 2.5, and a vertical curve on it and off it:

    >>> import numpy as np
    >>> classes = (np.arange(6)[None, :] > 2).astype(int).repeat(5, axis=0)
    >>> on = curve_on_map([2.5] * 5, [0, 1, 2, 3, 4], range(6), range(5), classes)
    >>> on.inside, on.holds, on.verdict
    (3, 3, 'agree')
    >>> off = curve_on_map([4.0] * 5, [0, 1, 2, 3, 4], range(6), range(5), classes)
    >>> off.holds, off.verdict, off.failed[0]
    (0, 'differ', (4.0, 1.0, 1, 1))
    """
    cls = np.asarray(classes)
    gx, gy = np.asarray(grid_x, dtype=float), np.asarray(grid_y, dtype=float)
    u = (np.asarray(x, dtype=float) - gx[0]) / (gx[1] - gx[0])
    v = (np.asarray(y, dtype=float) - gy[0]) / (gy[1] - gy[0])
    if len(u) < 2:
        return CurveOnMap(0, 0, ())
    tu, tv = np.gradient(u), np.gradient(v)
    norm = np.hypot(tu, tv)
    norm[norm == 0] = 1.0
    nu, nv = -tv / norm, tu / norm
    ny, nx = cls.shape
    inside = holds = 0
    failed = []
    checked = np.ones(len(u), dtype=bool) if where is None else np.asarray(where, dtype=bool)
    for i in range(len(u)):
        if not (checked[i] and 1 <= u[i] <= nx - 2 and 1 <= v[i] <= ny - 2):
            continue
        inside += 1
        a = cls[_nearest(v[i] + nv[i]), _nearest(u[i] + nu[i])]
        b = cls[_nearest(v[i] - nv[i]), _nearest(u[i] - nu[i])]
        if a != b:
            holds += 1
        else:
            failed.append((float(x[i]), float(y[i]), int(a), int(b)))
    return CurveOnMap(inside, holds, tuple(failed))


def _nearest(z: float) -> int:
    """The index of the cell centre nearest to ``z`` (in cell units; halves round up)."""
    return math.floor(z + 0.5)
