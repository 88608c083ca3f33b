"""The building blocks every figure module of the report returns.

A figure module (``fig09.py``, later ``fig04.py``, ...) exposes
``build(out_dir, progress) -> FigureResult``: it computes everything it shows,
writes its PNG files into ``out_dir`` and returns a :class:`FigureResult`
describing them, with the paper's statements beside ours as
:class:`Comparison` rows.  :mod:`grazing.report.html` renders a list of those.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

Progress = Callable[[str], None]
"""A callback that receives one-line progress messages."""

DPI = 150
"""Resolution of every PNG in the report."""

CHAOS_THRESHOLD = 1e-3
"""Largest Lyapunov exponent (per unit time) above which an aperiodic run counts as chaotic."""


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
    """

    filename: str
    caption: str
    alt: str = ""


@dataclass(frozen=True)
class Comparison:
    """One row of the paper-versus-ours table.

    Attributes
    ----------
    item
        What is compared, with its parameters (e.g. ``"fig 9(b): θ̂ = 40°, η = 0.446"``).
    paper
        What the paper states.
    source
        Where the paper states it (section, figure, caption).
    ours
        What this run computed (plain text, with the numbers).
    agrees
        True, False, or None when the two are not directly comparable.
    note
        Why they agree or differ.
    """

    item: str
    paper: str
    source: str
    ours: str
    agrees: bool | None
    note: str = ""


@dataclass(frozen=True)
class FigureResult:
    """Everything the report shows for one figure of the paper.

    Attributes
    ----------
    figure_id
        The paper's figure number as text (``"9"``); also the HTML anchor.
    title
        Section heading.
    images
        The image files written, in display order.
    summary
        A paragraph saying what was computed and how (plain text).
    comparisons
        The paper's statements beside ours.
    notes
        Further remarks (plain text paragraphs).
    seconds
        Wall time spent building the figure.
    """

    figure_id: str
    title: str
    images: tuple[Image, ...]
    summary: str = ""
    comparisons: tuple[Comparison, ...] = ()
    notes: tuple[str, ...] = ()
    seconds: float = 0.0


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
    """Save a matplotlib figure as a PNG of :data:`DPI` dots per inch and return the path."""
    fig.savefig(path, dpi=DPI, format="png", metadata={"Software": None})
    return path
