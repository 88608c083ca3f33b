"""The building blocks every figure module of the report returns.

A figure module (``fig07.py``, ...) exposes ``build(out_dir, progress) -> FigureResult``:
it computes everything it shows, writes its PNG files and its data into
``out_dir`` and returns a :class:`FigureResult` describing them, with every
comparison a :class:`Comparison` record: what the paper states, what we
compute, the rule that decides, and the verdict the rule gives.
:mod:`grazing.report.rules` builds such records; :mod:`grazing.report.html`
renders them; :func:`grazing.report.build_report` writes them all to
``comparisons.json``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from grazing.core.options import CHAOS_THRESHOLD as LYAPUNOV_CHAOS

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

Say = Callable[[str], None]
"""A callback that receives one-line progress messages (a figure saying how far it has got)."""

DPI = 150
"""Resolution of every PNG in the report."""

CHAOS_THRESHOLD = LYAPUNOV_CHAOS
"""Largest Lyapunov exponent (per unit time) above which an aperiodic run counts as chaotic."""

Kind = Literal["paper", "experiment", "self-check"]
Verdict = Literal["agree", "differ", "not comparable"]
KINDS: tuple[str, ...] = ("paper", "experiment", "self-check")
"""``paper``: against the paper's numbers or figures; ``experiment``: against the paper's measurements
(§2); ``self-check``: our own consistency (map against simulation, synthetic pipeline against model)."""
VERDICTS: tuple[str, ...] = ("agree", "differ", "not comparable")
REFERENCE = "reference"
"""What the reference column of a self-check holds when its row does not say."""

Value = float | int | str | tuple[float, float] | None
"""A compared value: a number, an interval ``(lo, hi)``, or text as the paper states it."""


def plain(v: Any) -> Any:
    """Numpy scalars as Python numbers, lists and arrays of two as tuples: what JSON and the checks expect.

    Examples
    --------
    >>> import numpy as np
    >>> plain(np.int32(3)), plain([np.float64(0.5), 1.0]), plain(np.bool_(True))
    (3, (0.5, 1.0), True)
    """
    if hasattr(v, "item") and getattr(v, "ndim", 1) == 0:
        return v.item()
    if isinstance(v, (list, tuple)) or (hasattr(v, "tolist") and getattr(v, "ndim", 0) == 1):
        return tuple(plain(x) for x in (v.tolist() if hasattr(v, "tolist") else v))
    return v


def is_number(v: Any) -> bool:
    """True for a finite real number (not a bool).

    Examples
    --------
    >>> is_number(0.5), is_number(True), is_number("0.5"), is_number(float("nan"))
    (True, False, False, False)
    """
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def is_interval(v: Any) -> bool:
    """True for a pair of numbers ``(lo, hi)`` with ``lo <= hi``."""
    return isinstance(v, (tuple, list)) and len(v) == 2 and all(is_number(x) for x in v) and v[0] <= v[1]


def intervals_overlap(a: Sequence[float], b: Sequence[float]) -> bool:
    """Whether the closed intervals ``a`` and ``b`` share at least one point.

    Examples
    --------
    >>> intervals_overlap((0, 1), (1, 2)), intervals_overlap((0, 1), (1.5, 2))
    (True, False)
    """
    return max(a[0], b[0]) <= min(a[1], b[1])


@dataclass(frozen=True)
class Comparison:
    """One comparison: the paper's statement, ours, the rule and its verdict.

    Attributes
    ----------
    figure
        The figure it belongs to (``"7"``; ``"eq"`` for the equations).
    quantity
        What is compared, with the panel and parameters (``"(d) θ̂ = 40°: first grazing η"``).
    paper
        What the paper states, as it states it: a number, an interval ``(lo, hi)`` or text.  For a
        self-check, the reference value of the check (e.g. 0 for a distance).
    ours
        What this run computed: a number, an interval or text.
    kind
        One of :data:`KINDS`.
    rule
        The criterion in words a reader can apply, with its tolerance.
    verdict
        One of :data:`VERDICTS`.  Where ``paper`` and ``ours`` are numbers and ``tolerance`` is set,
        ``"agree"`` holds exactly when ``|ours − paper| <= tolerance`` (checked on construction).
    tolerance
        The numeric tolerance of the rule, where it has one.
    source
        Where the paper states it.
    note
        Why they agree or differ (plain text).
    paper_text, ours_text
        Short display forms (default: the values formatted).
    delta
        A numeric distance between ours and the paper where the rule uses one (``ours − paper`` for
        numbers; ``|ours − paper|`` for complex numbers); its tolerance is ``tolerance``.
    delta_text
        Display form of the difference.
    synthetic
        True when ``ours`` comes from synthetic recordings (such a row is always a self-check).
    headline
        One line for the “where we differ” box; rows with the same headline are listed together.
    erratum
        True when the difference is an error in the paper (listed under the errata, and counted apart
        from the disagreements on the scoreboard).
    reference
        For a self-check, what ``paper`` holds (``"closed form"``, ``"simulation"``): the page shows
        self-checks in a table of their own whose column is headed "reference", each cell with this
        label (default :data:`REFERENCE`).
    id
        The HTML anchor of the row (set by :func:`number_rows`).

    Examples
    --------
    The paper's first grazing at θ̂ = 40° and ours; a verdict the numbers do
    not support is refused when the row is made:

    >>> from grazing.report import Comparison
    >>> row = Comparison("7", "(d) θ̂ = 40°: first grazing η", 0.4451, 0.445121, "paper",
    ...                  "|ours − paper| ≤ 1e-4 (the paper's four digits)", "agree", tolerance=1e-4)
    >>> row.verdict, Comparison.from_json(row.to_json()) == row
    ('agree', True)
    >>> Comparison("7", "q", 0.4451, 0.4461, "paper", "|ours − paper| ≤ 1e-4", "agree", tolerance=1e-4)
    Traceback (most recent call last):
    ...
    ValueError: comparison 'q': |ours − paper| = 0.001 > tolerance 0.0001 but the verdict is agree
    """

    figure: str
    quantity: str
    paper: Value
    ours: Value
    kind: Kind
    rule: str
    verdict: Verdict
    tolerance: float | None = None
    source: str = ""
    note: str = ""
    paper_text: str = ""
    ours_text: str = ""
    delta: float | None = None
    delta_text: str = ""
    synthetic: bool = False
    headline: str = ""
    erratum: bool = False
    reference: str = ""
    id: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"kind must be one of {KINDS}, got {self.kind!r}")
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict must be one of {VERDICTS}, got {self.verdict!r}")
        if self.synthetic and self.kind != "self-check":
            raise ValueError("a row computed from synthetic recordings must be a self-check")
        if self.reference and self.kind != "self-check":
            raise ValueError("only a self-check has a reference other than the paper")
        if self.erratum and self.verdict != "differ":
            raise ValueError("an erratum is a row that differs from the paper")
        if not self.rule:
            raise ValueError(f"comparison {self.quantity!r} has no rule")
        for name in ("paper", "ours", "tolerance", "delta"):
            object.__setattr__(self, name, plain(getattr(self, name)))
        problem = consistency_problem(self)
        if problem:
            raise ValueError(f"comparison {self.quantity!r}: {problem}")

    def to_json(self) -> dict[str, Any]:
        """The record as plain JSON data (intervals as two-element lists)."""
        out = asdict(self)
        for key in ("paper", "ours"):
            if isinstance(out[key], tuple):
                out[key] = list(out[key])
        return out

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Comparison:
        """Inverse of :meth:`to_json`."""
        return cls(**data)


def consistency_problem(row: Comparison | dict[str, Any]) -> str:
    """What is wrong with a row's verdict given its numbers (empty string: nothing).

    * numbers with a tolerance: ``agree`` exactly when ``|ours − paper| <= tolerance``;
    * a ``delta`` with a tolerance: ``agree`` exactly when ``|delta| <= tolerance``;
    * two intervals: ``agree`` only when they overlap;
    * a synthetic row must be a self-check.

    Examples
    --------
    >>> consistency_problem({"paper": 1.0, "ours": 1.2, "tolerance": 0.1, "verdict": "agree"})
    '|ours − paper| = 0.2 > tolerance 0.1 but the verdict is agree'
    >>> consistency_problem({"paper": [0, 1], "ours": [2, 3], "verdict": "agree"})
    'the intervals do not overlap but the verdict is agree'
    """
    get = row.get if isinstance(row, dict) else lambda k, d=None: getattr(row, k, d)
    paper, ours, tol, verdict = get("paper"), get("ours"), get("tolerance"), get("verdict")
    delta = get("delta")
    if get("synthetic", False) and get("kind") in ("paper", "experiment"):
        return "a synthetic-data row of kind paper or experiment"
    if tol is not None:
        if not (is_number(tol) and tol >= 0):
            return f"tolerance {tol!r} is not a non-negative number"
        if is_number(paper) and is_number(ours):
            d = abs(ours - paper)
            holds = d <= tol
            if holds != (verdict == "agree"):
                rel = "<=" if holds else ">"
                return f"|ours − paper| = {d:.3g} {rel} tolerance {tol:.3g} but the verdict is {verdict}"
            if delta is not None and not math.isclose(abs(delta), d, rel_tol=1e-9, abs_tol=1e-15):
                return f"delta {delta!r} is not ours − paper = {ours - paper!r}"
        elif delta is not None:
            if not is_number(delta):
                return f"delta {delta!r} is not a number"
            holds = abs(delta) <= tol
            if holds != (verdict == "agree"):
                rel = "<=" if holds else ">"
                return f"|delta| = {abs(delta):.3g} {rel} tolerance {tol:.3g} but the verdict is {verdict}"
    if is_interval(paper) and is_interval(ours) and verdict == "agree" and not intervals_overlap(paper, ours):
        return "the intervals do not overlap but the verdict is agree"
    return ""


def number_rows(figure_id: str, rows: Sequence[Comparison]) -> tuple[Comparison, ...]:
    """Give every row its anchor ``row-<figure>-<n>`` (1-based) and its figure id.

    Examples
    --------
    >>> r = Comparison("7", "q", 1.0, 1.0, "paper", "|Δ| ≤ 0", "agree", tolerance=0.0)
    >>> number_rows("7", [r, r])[1].id
    'row-7-2'
    """
    return tuple(replace(r, figure=figure_id, id=f"row-{figure_id}-{i}") for i, r in enumerate(rows, start=1))


@dataclass(frozen=True)
class Image:
    """One image file of a figure.

    Attributes
    ----------
    filename
        File name relative to the report directory (a PNG).
    caption
        What the image shows (plain text).
    alt
        Short alternative text for the ``<img>`` tag.

    Examples
    --------
    >>> Image("fig07_bifurcation.png", "θ against η at four stop angles", alt="fig 7")
    Image(filename='fig07_bifurcation.png', caption='θ against η at four stop angles', alt='fig 7')
    """

    filename: str
    caption: str
    alt: str = ""


@dataclass(frozen=True)
class DataFile:
    """A data file written beside a figure (NetCDF or CSV) for the reader to reuse.

    Attributes
    ----------
    filename
        File name relative to the report directory.
    description
        What it holds and how to read it (plain text).

    Examples
    --------
    >>> DataFile("fig07_sweeps.nc", "the four sweeps: xarray.open_dataset(path, group='40')").filename
    'fig07_sweeps.nc'
    """

    filename: str
    description: str


@dataclass(frozen=True)
class FigureResult:
    """Everything the report shows for one figure of the paper.

    Attributes
    ----------
    figure_id
        The paper's figure number as text (``"9"``); also the HTML anchor ``fig9``.
    title
        Section heading.
    images
        The image files written, in display order.
    summary
        A paragraph saying what was computed and how (plain text).
    comparisons
        The comparison records.
    notes
        Further remarks (plain text paragraphs).
    seconds
        Wall time spent computing and drawing the figure (kernels already compiled).
    data
        The data files written beside the figure.
    built
        When the figure was built (ISO time) and from which commit: set by
        :func:`grazing.report.build_report`.
    commit
        The git commit of the build (empty when unknown).

    Examples
    --------
    A figure's result goes to JSON and back unchanged (``grazing report
    --only`` keeps the other figures' results so):

    >>> from grazing.report import Comparison
    >>> row = Comparison("7", "(d) θ̂ = 40°: first grazing η", 0.4451, 0.445121, "paper",
    ...                  "|ours − paper| ≤ 1e-4 (the paper's four digits)", "agree", tolerance=1e-4)
    >>> fig = FigureResult("7", "Fig 7: bifurcation diagrams",
    ...                    (Image("fig07_bifurcation.png", "θ against η"),), comparisons=(row,),
    ...                    data=(DataFile("fig07_sweeps.nc", "the sweeps"),))
    >>> FigureResult.from_json(fig.to_json()) == fig
    True
    """

    figure_id: str
    title: str
    images: tuple[Image, ...]
    summary: str = ""
    comparisons: tuple[Comparison, ...] = ()
    notes: tuple[str, ...] = ()
    seconds: float = 0.0
    data: tuple[DataFile, ...] = ()
    built: str = ""
    commit: str = ""

    def to_json(self) -> dict[str, Any]:
        """The result as plain JSON data (what ``grazing report --only`` keeps between builds)."""
        out = asdict(self)
        out["comparisons"] = [c.to_json() for c in self.comparisons]
        return out

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> FigureResult:
        """Inverse of :meth:`to_json`."""
        d = dict(data)
        d["images"] = tuple(Image(**i) for i in d.get("images", ()))
        d["data"] = tuple(DataFile(**f) for f in d.get("data", ()))
        d["comparisons"] = tuple(Comparison.from_json(c) for c in d.get("comparisons", ()))
        d["notes"] = tuple(d.get("notes", ()))
        return cls(**d)


@dataclass(frozen=True)
class Dynamics:
    """The long-time behaviour of one run, as the comparison tables state it.

    Attributes
    ----------
    period
        Period of the stroboscopic samples (0: none up to the detection limit).
    lyapunov
        Largest Lyapunov exponent per unit time.
    impacts_per_period
        Mean number of impacts per forcing period over the sampled span.

    Examples
    --------
    >>> Dynamics(5, -0.0337, 0.2).short(), Dynamics(0, 0.0466, 0.79).short()
    ('period-5, λ₁ = −0.0337', 'chaotic, λ₁ = +0.0466')
    """

    period: int
    lyapunov: float
    impacts_per_period: float

    @property
    def verdict(self) -> str:
        """``"period-p"``, ``"chaotic"`` or ``"aperiodic, λ₁ ≈ 0"``.

        Examples
        --------
        >>> Dynamics(5, -0.03, 1.0).verdict, Dynamics(0, 0.05, 0.8).verdict
        ('period-5', 'chaotic')
        """
        if self.period > 0:
            return f"period-{self.period}"
        if self.lyapunov > CHAOS_THRESHOLD:
            return "chaotic"
        return "aperiodic, λ₁ ≈ 0"

    def describe(self) -> str:
        """The verdict with its evidence, e.g. ``"period-5 (λ₁ = −0.0337, 2.00 impacts/period)"``.

        Examples
        --------
        >>> Dynamics(0, 0.0466, 0.79).describe()
        'chaotic (no period ≤ 64; λ₁ = +0.0466 per unit τ; 0.79 impacts per period)'
        """
        evidence = "no period ≤ 64; " if self.period == 0 else ""
        imp = (
            "no impacts"
            if self.impacts_per_period == 0
            else f"{self.impacts_per_period:.2f} impacts per period"
        )
        return f"{self.verdict} ({evidence}λ₁ = {signed(self.lyapunov, 4)} per unit τ; {imp})"

    def short(self) -> str:
        """The verdict with λ₁ only: ``"chaotic, λ₁ = +0.0466"``."""
        return f"{self.verdict}, λ₁ = {signed(self.lyapunov, 3)}"


def signed(value: float, digits: int) -> str:
    """Format with an explicit sign and a proper minus sign.

    Examples
    --------
    >>> signed(-0.03374, 3), signed(0.0466, 3)
    ('−0.0337', '+0.0466')
    """
    if not math.isfinite(value):
        return str(value)
    text = f"{value:+.{digits}g}" if abs(value) >= 1e-3 else f"{value:+.{max(digits - 1, 0)}e}"
    return text.replace("-", "−")


def save_png(fig: Figure, path: Path) -> Path:
    """Save a matplotlib figure as a PNG of :data:`DPI` dots per inch (all at once, marked); return the path.

    Like every output it replaces only a file of grazing's
    (:func:`grazing.outputs.check_replaceable`); in the folder of a report being
    built, any file (the folder as a whole is grazing's).
    """
    from grazing.outputs import save_png as save_marked_png

    return save_marked_png(fig, path, dpi=DPI)


def new_figure(nrows: int, ncols: int, size: tuple[float, float]) -> tuple[Figure, Any]:
    """A matplotlib :class:`~matplotlib.figure.Figure` (no pyplot state) with a 2-D array of axes."""
    import numpy as np
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    axes = np.atleast_2d(fig.subplots(nrows, ncols, squeeze=False))
    return fig, axes


def finish_figure(fig: Figure | None, path: str | Path | None, dpi: int = DPI) -> str | None:
    """Save ``fig`` at ``path`` (if both are given, all at once); the path written, or None.

    A PNG (or a name without a suffix, which gets ``.png``) carries grazing's
    mark and replaces only what :func:`save_png` replaces; other formats are
    written as matplotlib makes them.
    """
    import io

    from grazing.atomic import write_bytes_atomic
    from grazing.outputs import save_png as save_marked_png

    if fig is None or path is None:
        return None
    path = Path(path)
    if path.suffix.lower() in ("", ".png"):
        path = path if path.suffix else path.with_suffix(".png")
        return str(save_marked_png(fig, path, dpi=dpi))
    buf = io.BytesIO()
    fig.savefig(buf, dpi=dpi, format=path.suffix[1:])
    write_bytes_atomic(path, buf.getvalue())
    return str(path)
