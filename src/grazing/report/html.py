"""Render the report page from a list of :class:`~grazing.report.base.FigureResult`.

The page is one HTML file with its style sheet inline; the images are PNG
files next to it, referenced by relative file name.  All text coming from the
figure modules is plain text and is escaped here.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass

from grazing.report.base import Comparison, FigureResult

PAPER = (
    "P. T. Piiroinen, L. N. Virgin, A. R. Champneys, “Chaos and period-adding: experimental and numerical "
    "verification of the grazing bifurcation”, J. Nonlinear Sci. 14 (2004) 383–404"
)

_CSS = """
body { font: 15px/1.5 system-ui, -apple-system, "Segoe UI", sans-serif; color: #222;
       max-width: 1100px; margin: 2em auto; padding: 0 1em; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { font-size: 1.3em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 2em; }
dl.meta { display: grid; grid-template-columns: max-content auto; gap: 0.1em 1em; }
dl.meta dt { font-weight: 600; }
dl.meta dd { margin: 0; }
.callout { background: #f3f7fb; border-left: 4px solid #4a7fb5; padding: 0.5em 1em; }
figure { margin: 1.5em 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.92em; color: #444; margin-top: 0.3em; }
table { border-collapse: collapse; width: 100%; font-size: 0.92em; margin: 1em 0; }
th, td { border: 1px solid #ccc; padding: 0.35em 0.5em; vertical-align: top; text-align: left; }
th { background: #f0f0f0; }
td.agree { background: #e6f4e6; font-weight: 600; }
td.differ { background: #fbe6e6; font-weight: 600; }
td.na { background: #f4f4f4; }
.small { font-size: 0.85em; color: #555; }
"""


@dataclass(frozen=True)
class ReportMeta:
    """What the page header states about the run.

    Attributes
    ----------
    version
        ``grazing.__version__``.
    date
        When the report was built (ISO format, local time with offset).
    seconds
        Total build time.
    platform
        Python and OS, e.g. ``"Python 3.11.9 on Linux-6.1-x86_64"``.
    pending
        Figure numbers of the paper not (yet) in the report.
    """

    version: str
    date: str
    seconds: float
    platform: str = ""
    pending: tuple[str, ...] = ()


def _e(text: str) -> str:
    return html.escape(text, quote=True)


def _verdict_cell(agrees: bool | None) -> str:
    if agrees is None:
        return '<td class="na">not comparable</td>'
    return '<td class="agree">agree</td>' if agrees else '<td class="differ">differ</td>'


def comparison_table(rows: Sequence[Comparison]) -> str:
    """The paper-versus-ours table as an HTML ``<table>`` (empty string for no rows).

    Examples
    --------
    >>> row = Comparison("fig 9(b)", "period-5", "fig 9 caption", "period-5 (λ₁ = −0.034)", True)
    >>> "agree" in comparison_table([row])
    True
    """
    if not rows:
        return ""
    out = [
        '<table class="comparison">',
        "<thead><tr><th>case</th><th>paper says</th><th>where</th><th>we compute</th>"
        "<th>verdict</th><th>why</th></tr></thead><tbody>",
    ]
    for r in rows:
        out.append(
            f"<tr><td>{_e(r.item)}</td><td>{_e(r.paper)}</td><td class='small'>{_e(r.source)}</td>"
            f"<td>{_e(r.ours)}</td>{_verdict_cell(r.agrees)}<td class='small'>{_e(r.note)}</td></tr>"
        )
    out.append("</tbody></table>")
    return "\n".join(out)


def _tally(rows: Sequence[Comparison]) -> str:
    agree = sum(r.agrees is True for r in rows)
    differ = sum(r.agrees is False for r in rows)
    return f"{agree} agree, {differ} differ" if rows else "no comparisons"


def figure_section(fig: FigureResult) -> str:
    """One ``<section>`` for a figure: summary, images with captions, comparison table, notes."""
    parts = [f'<section id="fig{_e(fig.figure_id)}">', f"<h2>{_e(fig.title)}</h2>"]
    if fig.summary:
        parts.append(f"<p>{_e(fig.summary)}</p>")
    for img in fig.images:
        parts.append(
            f'<figure><img src="{_e(img.filename)}" alt="{_e(img.alt or img.caption)}">'
            f"<figcaption>{_e(img.caption)}</figcaption></figure>"
        )
    if fig.comparisons:
        parts.append("<h3>The paper beside our computation</h3>")
        parts.append(comparison_table(fig.comparisons))
    if fig.notes:
        parts.append("<h3>Notes</h3>")
        parts.extend(f"<p>{_e(n)}</p>" for n in fig.notes)
    parts.append(f'<p class="small">Built in {fig.seconds:.1f} s.</p>')
    parts.append("</section>")
    return "\n".join(parts)


def render(figures: Sequence[FigureResult], meta: ReportMeta) -> str:
    """The whole page.

    Examples
    --------
    >>> page = render([], ReportMeta(version="0.1.0", date="2024-01-01T00:00:00", seconds=1.0))
    >>> page.startswith("<!DOCTYPE html>") and "0.1.0" in page
    True
    """
    contents = "\n".join(
        f'<li><a href="#fig{_e(f.figure_id)}">{_e(f.title)}</a> '
        f'<span class="small">({_e(_tally(f.comparisons))})</span></li>'
        for f in figures
    )
    pending = (
        f"<li>Not yet in this report: figure{'s' if len(meta.pending) > 1 else ''} "
        f"{_e(', '.join(meta.pending))}.</li>"
        if meta.pending
        else ""
    )
    platform = f"<dt>platform</dt><dd>{_e(meta.platform)}</dd>" if meta.platform else ""
    head = f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>grazing {_e(meta.version)}: reproduction of Piiroinen, Virgin &amp; Champneys (2004)</title>
<style>{_CSS}</style>
</head>
<body>
<header>
<h1>Reproducing the grazing pendulum paper with <code>grazing</code></h1>
<p>This report recomputes the numerical figures of {_e(PAPER)} with the <code>grazing</code> package and
sets the paper's statements beside our numbers.</p>
<p class="callout">Every figure and every number under “we compute” was computed by this run; nothing
is copied from the paper except the quoted statements in the “paper says” column, each with its
section or figure. Regenerate with <code>make reproduce</code> (or <code>grazing report --out DIR</code>).</p>
<dl class="meta">
<dt>grazing version</dt><dd>{_e(meta.version)}</dd>
<dt>built</dt><dd>{_e(meta.date)}</dd>
<dt>build time</dt><dd>{meta.seconds:.1f} s</dd>
{platform}
</dl>
</header>
<nav><h2>Contents</h2><ul>
{contents}
{pending}
</ul></nav>
"""
    body = "\n".join(figure_section(f) for f in figures)
    return head + body + "\n</body>\n</html>\n"
