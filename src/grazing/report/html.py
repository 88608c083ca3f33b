"""Render the report page from the figures' results.

The page is one HTML file with its style sheet inline; the images and data
files sit next to it, referenced by relative file name.  All text coming from
the figure modules is plain text and is escaped here.  From the top: what the
report is, the scoreboard of verdicts by kind, the differences from the paper
(each linked to its row), the paper's parameter cases, the documents, the
provenance (commit, versions, machine, compile and compute times), then one
section per figure.
"""

from __future__ import annotations

import html
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field

from grazing.report import paper
from grazing.report.base import KINDS, REFERENCE, Comparison, FigureResult, is_interval, is_number

_CSS = """
body { font: 15px/1.5 system-ui, -apple-system, "Segoe UI", sans-serif; color: #222;
       max-width: 1280px; margin: 2em auto; padding: 0 1em; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { font-size: 1.3em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 2em; }
h3 { font-size: 1.08em; margin: 1.2em 0 0.4em; }
dl.meta { display: grid; grid-template-columns: max-content auto; gap: 0.1em 1em; }
dl.meta dt { font-weight: 600; }
dl.meta dd { margin: 0; }
.callout { background: #f3f7fb; border-left: 4px solid #4a7fb5; padding: 0.5em 1em; }
.differences { background: #fff8ec; border: 1px solid #e0b867; border-radius: 4px;
               padding: 0.3em 1.2em 0.8em; }
.differences li { margin: 0.25em 0; }
figure { margin: 1.5em 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.92em; color: #444; margin-top: 0.3em; }
table { border-collapse: collapse; font-size: 0.9em; margin: 0; }
table.rows { width: 100%; min-width: 46em; }
.scroll { overflow-x: auto; max-width: 100%; margin: 0.8em 0; -webkit-overflow-scrolling: touch; }
code { overflow-wrap: anywhere; }
@media (max-width: 600px) {
  body { padding: 0 0.5em; margin: 1em auto; font-size: 14px; }
  dl.meta { grid-template-columns: auto; }
  dl.meta dd { margin-bottom: 0.4em; overflow-wrap: anywhere; }
  figcaption a.full { display: inline-block; padding: 0.3em 0; font-weight: 600; }
}
th, td { border: 1px solid #ccc; padding: 0.3em 0.45em; vertical-align: top; text-align: left; }
th { background: #f0f0f0; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.agree { background: #e6f4e6; font-weight: 600; }
td.differ { background: #fbe6e6; font-weight: 600; }
td.na { background: #f4f4f4; }
tr:target { outline: 3px solid #e0a000; }
.kind { display: inline-block; font-size: 0.78em; border-radius: 3px; padding: 0 0.35em; margin-right: 0.3em;
        color: #fff; }
.kind-paper { background: #4a7fb5; } .kind-experiment { background: #8a5bb5; }
.kind-self-check { background: #777; }
.kind-erratum { background: #b5651d; }
.synthetic { background: #c0392b; }
.small { font-size: 0.85em; color: #555; }
details summary { cursor: pointer; color: #4a6b8a; }
a.anchor { color: #888; text-decoration: none; font-size: 0.85em; }
"""


@dataclass(frozen=True)
class ReportMeta:
    """What the page header states about the build.

    Attributes
    ----------
    version
        ``grazing.__version__``.
    date
        When the page was rendered (ISO format, local time with offset).
    seconds
        Wall time of this build (compilation and computation).
    compile_seconds
        Wall time of the kernel compilation phase (loading from the disk cache when already compiled).
    commit
        The git commit of the source tree.
    versions
        Package versions (``{"python": ..., "numpy": ..., ...}``).
    cpu, cores, system
        The machine.
    vector_width
        Doubles per vector register the kernels use on this processor (0: unknown).
    dirty
        True when the source tree had uncommitted changes under ``src/``.
    docs
        ``(title, relative link)`` of the documents linked from the top.
    pending
        Figure numbers of the paper not (yet) in the report.

    Examples
    --------
    >>> from grazing.report.html import render
    >>> meta = ReportMeta(version="0.2.0", date="2026-11-28T09:00:00+00:00", seconds=97.0, cpu="AMD EPYC",
    ...                   cores=2, pending=("5",))
    >>> page = render([], meta)
    >>> "AMD EPYC" in page, "Not in this report: figure 5." in page
    (True, True)
    """

    version: str
    date: str
    seconds: float
    compile_seconds: float = 0.0
    commit: str = ""
    versions: dict[str, str] = field(default_factory=dict)
    cpu: str = ""
    cores: int = 0
    system: str = ""
    vector_width: int = 0
    dirty: bool = False
    docs: tuple[tuple[str, str], ...] = ()
    pending: tuple[str, ...] = ()


def _e(text: object) -> str:
    return html.escape(str(text), quote=True)


# ---------------------------------------------------------------------------- rows


def value_text(v: object) -> str:
    """A compared value as short text: numbers as given, intervals as ``lo–hi``."""
    if is_interval(v):
        lo, hi = v  # type: ignore[misc]
        return f"{lo:g}–{hi:g}"
    if is_number(v):
        return f"{v:g}"
    return "—" if v is None else str(v)


def _verdict_cell(verdict: str) -> str:
    cls = {"agree": "agree", "differ": "differ"}.get(verdict, "na")
    return f'<td class="{cls}">{_e(verdict)}</td>'


def row_label(row: Comparison) -> str:
    """``"7.3"`` for ``row-7-3``."""
    return row.id.removeprefix("row-").replace("-", ".") if row.id else ""


def scrolling(table: str) -> str:
    """A table in a box of its own that scrolls sideways when the page is narrower than the table."""
    return f'<div class="scroll">{table}</div>' if table else ""


def comparison_table(rows: Sequence[Comparison], reference: str = "paper") -> str:
    """The comparison records as an HTML ``<table>`` (empty string for no rows), in a scrolling box.

    ``reference`` heads the column of what ours is compared with: ``"paper"`` for
    rows against the paper or its measurements, ``"reference"`` for self-checks,
    whose cells then name what their reference is (:attr:`Comparison.reference`).

    Examples
    --------
    >>> r = Comparison("9", "(b) period", "period-5", "period-5", "paper", "same", "agree", id="row-9-1")
    >>> page = comparison_table([r])
    >>> 'id="row-9-1"' in page and 'class="agree"' in page and "<th>paper</th>" in page
    True
    >>> c = Comparison("s", "ω", 0.5, 0.5, "self-check", "same", "agree", reference="closed form")
    >>> page = comparison_table([c], reference="reference")
    >>> "<th>reference</th>" in page and "closed form" in page and "<th>paper</th>" not in page
    True
    """
    if not rows:
        return ""
    out = [
        '<table class="rows">',
        f"<thead><tr><th>#</th><th>quantity</th><th>{_e(reference)}</th><th>ours</th><th>Δ</th>"
        "<th>verdict</th><th>rule, and why</th></tr></thead><tbody>",
    ]
    for r in rows:
        badge = f'<span class="kind kind-{_e(r.kind)}">{_e(r.kind)}</span>'
        if r.synthetic:
            badge += '<span class="kind synthetic">synthetic data</span>'
        if r.erratum:
            badge += '<span class="kind kind-erratum">erratum</span>'
        src = f'<br><span class="small">{_e(r.source)}</span>' if r.source else ""
        own = r.kind == "self-check"
        label = f'<span class="small">{_e(r.reference or REFERENCE)}:</span> ' if own else ""
        delta = r.delta_text or ""
        if r.tolerance is not None:
            delta += f'<br><span class="small">tol {r.tolerance:.2g}</span>'
        why = f"<details><summary>why</summary>{_e(r.note)}</details>" if r.note else ""
        out.append(
            f'<tr id="{_e(r.id)}"><td><a class="anchor" href="#{_e(r.id)}">{_e(row_label(r))}</a></td>'
            f"<td>{badge}{_e(r.quantity)}</td>"
            f"<td>{label}{_e(r.paper_text or value_text(r.paper))}{src}</td>"
            f"<td>{_e(r.ours_text or value_text(r.ours))}</td>"
            f'<td class="num">{delta}</td>{_verdict_cell(r.verdict)}'
            f'<td class="small">{_e(r.rule)}{why}</td></tr>'
        )
    out.append("</tbody></table>")
    return scrolling("\n".join(out))


COUNTS: tuple[str, ...] = ("agree", "differ", "erratum", "not comparable")
"""The scoreboard's columns: a row that differs because the paper is in error counts as ``erratum``,
not among the disagreements (``differ``)."""


def count_key(row: Comparison) -> str:
    """The scoreboard column of a row: its verdict, or ``"erratum"`` for an erratum of the paper."""
    return "erratum" if row.erratum else row.verdict


def scoreboard(rows: Sequence[Comparison]) -> dict[str, dict[str, int]]:
    """Counts per kind and :data:`COUNTS`: ``{"paper": {"agree": 12, "differ": 5, "erratum": 2, ...}, ...}``.

    Examples
    --------
    >>> r = Comparison("9", "q", "a", "a", "paper", "same", "agree")
    >>> e = Comparison("9", "q", "a", "b", "paper", "same", "differ", erratum=True)
    >>> board = scoreboard([r, r, e])
    >>> board["paper"]["agree"], board["paper"]["differ"], board["paper"]["erratum"]
    (2, 0, 1)
    """
    c = Counter((r.kind, count_key(r)) for r in rows)
    return {k: {v: c[(k, v)] for v in COUNTS} for k in KINDS}


def scoreboard_table(rows: Sequence[Comparison]) -> str:
    board = scoreboard(rows)
    names = {
        "paper": "against the paper's numbers and figures",
        "experiment": "against the paper's measurements (§2)",
        "self-check": "our own consistency (map vs simulation, synthetic pipeline)",
    }
    out = [
        '<table class="score"><thead><tr><th>kind</th><th>agree</th><th>differ</th>'
        "<th>erratum in the paper</th><th>not comparable</th><th>rows</th></tr></thead><tbody>"
    ]
    for k in KINDS:
        b = board[k]
        cells = "".join(f'<td class="num">{b[c]}</td>' for c in COUNTS)
        out.append(
            f'<tr><td><span class="kind kind-{k}">{k}</span> <span class="small">{_e(names[k])}</span></td>'
            f'{cells}<td class="num">{sum(b.values())}</td></tr>'
        )
    out.append("</tbody></table>")
    return scrolling("\n".join(out))


def _grouped(rows: Sequence[Comparison]) -> list[tuple[str, list[Comparison]]]:
    groups: dict[str, list[Comparison]] = {}
    for r in rows:
        groups.setdefault(r.headline or r.quantity, []).append(r)
    return list(groups.items())


def _figures_of(rows: Sequence[Comparison]) -> str:
    figs = list(dict.fromkeys(r.figure for r in rows))
    names = [f"fig {f}" if f.isdigit() else f for f in figs]
    return ", ".join(names)


def _difference_list(rows: Sequence[Comparison], by_quantity: bool = False) -> str:
    if not rows:
        return "<p>None.</p>"
    items = []
    groups = [(f"{r.quantity}", [r]) for r in rows] if by_quantity else _grouped(rows)
    for head, members in groups:
        links = " ".join(f'<a href="#{_e(r.id)}">{_e(row_label(r))}</a>' for r in members)
        items.append(
            f"<li><b>{_e(_figures_of(members))}</b>: {_e(head)} <span class='small'>— rows "
            f"{links}</span></li>"
        )
    return "<ul>" + "\n".join(items) + "</ul>"


def _errata_link(doc: str) -> str:
    return f' Explained in <a href="{_e(doc)}">the equations, units and errata</a>.' if doc else ""


ERRATA_INTRO = (
    "Each erratum is computed in the row it links to: what the printed number or formula gives, set against "
    "what the paper's own other numbers, or its apparatus (§2.1), need. They count apart from the "
    "disagreements on the scoreboard."
)


def differences_box(rows: Sequence[Comparison], errata_doc: str = "") -> str:
    """The “where we differ” box: differences with the paper and experiment, errata, failed self-checks.

    Each line is one headline, linked to every row it summarises; ``errata_doc``
    is the relative link of the document that explains the errata (none: the
    page's rows alone).

    Examples
    --------
    >>> e = Comparison("eq", "q", 1.0, 2.0, "paper", "r", "differ", erratum=True, headline="h", id="row-eq-1")
    >>> box = differences_box([e], "docs/equations.md")
    >>> "SPEC" in box, 'href="#row-eq-1"' in box, 'href="docs/equations.md"' in box
    (False, True, True)
    """
    differ = [r for r in rows if r.verdict == "differ"]
    errata = [r for r in differ if r.erratum]
    against = [r for r in differ if not r.erratum and r.kind in ("paper", "experiment")]
    own = [r for r in differ if not r.erratum and r.kind == "self-check"]
    nc = [r for r in rows if r.verdict == "not comparable"]
    parts = [
        '<div class="differences" id="differences">',
        "<h3>Where we differ from the paper, and why</h3>",
        _difference_list(against),
        "<h3>Errata in the paper</h3>",
        f'<p class="small">{_e(ERRATA_INTRO)}{_errata_link(errata_doc)}</p>',
        _difference_list(errata),
        "<h3>Our own checks that fail</h3>",
        _difference_list(own),
    ]
    if nc:
        parts += ["<h3>Not comparable</h3>", _difference_list(nc, by_quantity=True)]
    parts.append("</div>")
    return "\n".join(parts)


RULES_TEXT = (
    "Every row states its rule. Unless it says otherwise: a number agrees when |ours − paper| is at most "
    "half a "
    "unit of the paper's last printed digit (ours rounds to the paper's number), one unit where the paper "
    "writes “≈”, “about” or “close to”; a multiplier pair agrees when the distance in the complex plane is "
    "at "
    "most half a unit in each part; a window of a sweep matches another only when their η intervals overlap "
    "and they have the same period, and a panel agrees when more than half of its windows match; rows "
    "computed from synthetic recordings are self-checks and never agree with the paper. All rows are in "
    "comparisons.json."
)


# ---------------------------------------------------------------------------- sections


ERRATA_DOC = "equations.md"
"""The document of ``docs/`` that explains the equations, the units and the paper's errata."""


def _cases_table() -> str:
    out = [
        "<table><thead><tr><th>case</th><th>r</th><th>β</th><th>α</th><th>used in</th></tr></thead><tbody>"
    ]
    for name, c in paper.CASES.items():
        out.append(
            f"<tr><td>{_e(name)}</td><td class='num'>{_e(c['r'])}</td><td class='num'>{_e(c['beta'])}</td>"
            f"<td class='num'>{_e(c['alpha'])}</td><td>{_e(c['used'])}</td></tr>"
        )
    out.append("</tbody></table>")
    return "\n".join(out)


def _timing_table(figures: Sequence[FigureResult], meta: ReportMeta) -> str:
    out = [
        "<table><thead><tr><th>figure</th><th>compute "
        "(s)</th><th>built</th><th>commit</th></tr></thead><tbody>",
        f"<tr><td>kernel compilation (or loading from the cache)</td><td "
        f"class='num'>{meta.compile_seconds:.1f}</td>"
        f"<td>{_e(meta.date)}</td><td><code>{_e(meta.commit[:12])}</code></td></tr>",
    ]
    for f in figures:
        stale = " (another commit)" if f.commit and meta.commit and f.commit != meta.commit else ""
        out.append(
            f'<tr><td><a href="#fig{_e(f.figure_id)}">{_e(f.figure_id)}</a></td>'
            f"<td class='num'>{f.seconds:.1f}</td><td>{_e(f.built)}</td>"
            f"<td><code>{_e(f.commit[:12])}</code>{_e(stale)}</td></tr>"
        )
    out.append("</tbody></table>")
    return "\n".join(out)


def figure_section(fig: FigureResult) -> str:
    """One ``<section>`` for a figure: summary, linked images, data files, comparison table, notes."""
    parts = [f'<section id="fig{_e(fig.figure_id)}">', f"<h2>{_e(fig.title)}</h2>"]
    if fig.summary:
        parts.append(f"<p>{_e(fig.summary)}</p>")
    for img in fig.images:
        src = _e(img.filename)
        parts.append(
            f'<figure><a href="{src}"><img src="{src}" alt="{_e(img.alt or img.caption)}"></a>'
            f'<figcaption>{_e(img.caption)} <a class="full" href="{src}">Open the full-size image</a>.'
            "</figcaption></figure>"
        )
    if fig.data:
        items = "".join(
            f'<li><a href="{_e(d.filename)}">{_e(d.filename)}</a>: {_e(d.description)}</li>' for d in fig.data
        )
        parts.append(f'<p class="small">Data of this figure:</p><ul class="small">{items}</ul>')
    if fig.comparisons:
        board = scoreboard(fig.comparisons)
        tally = "; ".join(
            f"{k}: " + ", ".join(f"{n} {v}" for v, n in board[k].items() if n)
            for k in KINDS
            if any(board[k].values())
        )
        against = [r for r in fig.comparisons if r.kind != "self-check"]
        own = [r for r in fig.comparisons if r.kind == "self-check"]
        parts.append(f"<h3>The paper beside our computation</h3><p class='small'>{_e(tally)}</p>")
        parts.append(comparison_table(against))
        if own:
            if against:
                parts.append("<h3>Our own checks</h3>")
            parts.append(
                "<p class='small'>Checked against a reference of our own (named in each row), not against "
                "the paper.</p>"
            )
            parts.append(comparison_table(own, reference="reference"))
    if fig.notes:
        parts.append("<h3>Notes</h3>")
        parts.extend(f"<p>{_e(n)}</p>" for n in fig.notes)
    parts.append(f'<p class="small">Computed in {fig.seconds:.1f} s (kernels already compiled).</p>')
    parts.append("</section>")
    return "\n".join(parts)


def render(figures: Sequence[FigureResult], meta: ReportMeta) -> str:
    """The whole page.

    Examples
    --------
    >>> page = render([], ReportMeta(version="0.1.0", date="2024-01-01T00:00:00", seconds=1.0))
    >>> page.startswith("<!DOCTYPE html>") and "0.1.0" in page and "scoreboard" in page
    True
    """
    rows = [r for f in figures for r in f.comparisons]
    contents = "\n".join(f'<li><a href="#fig{_e(f.figure_id)}">{_e(f.title)}</a></li>' for f in figures)
    pending = (
        f"<li>Not in this report: figure{'s' if len(meta.pending) > 1 else ''} "
        f"{_e(', '.join(meta.pending))}.</li>"
        if meta.pending
        else ""
    )
    versions = ", ".join(f"{k} {v}" for k, v in meta.versions.items())
    timing = scrolling(_timing_table(figures, meta))
    tree = (
        "uncommitted changes under src/ (dirty): this build is not exactly the commit"
        if meta.dirty
        else ("clean (no uncommitted changes under src/)" if meta.commit else "not a git checkout")
    )
    lanes = (
        f"vector registers of {meta.vector_width} doubles (the kernels' lanes)"
        if meta.vector_width
        else "vector width unknown"
    )
    docs = " · ".join(f'<a href="{_e(link)}">{_e(title)}</a>' for title, link in meta.docs) or "—"
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
<p>This report recomputes the numerical figures of {_e(paper.CITATION)}
(<a href="https://doi.org/{_e(paper.DOI)}">doi:{_e(paper.DOI)}</a>) with the <code>grazing</code> package
and sets every number the paper gives beside ours, with the rule that decides whether they agree.</p>
<p class="callout">Every figure and every number under “ours” was computed by this build; nothing is copied
from the paper except its numbers and quotations in the “paper” column, each with its section or figure
(all in <code>grazing/report/paper.py</code>). Regenerate with <code>make reproduce</code>
(<code>grazing report --out DIR</code>; one figure: <code>grazing report --only fig07</code>).
Every row: <a href="comparisons.json">comparisons.json</a>.</p>
</header>
<section id="scoreboard">
<h2>What we reproduce and what we do not</h2>
{scoreboard_table(rows)}
<p class="small">{_e(RULES_TEXT)}</p>
{differences_box(rows, next((link for _, link in meta.docs if link.endswith(ERRATA_DOC)), ""))}
</section>
<section id="cases">
<h2>The paper's parameter cases</h2>
<p>θ″ + (2β/η)θ′ + sin θ/(4η²) = α cos θ sin τ while θ &lt; θ̂; θ′ ← −r θ′ at θ = θ̂ (eqs. 4–5). η = ω/ω0 is
swept; θ̂ is the stop angle.</p>
{scrolling(_cases_table())}
<p class="small">α is printed as 0.2254 in the captions and as 0.2258 in §3; A/L = 50.8/225 = 0.225778. Our
figures use 0.2254; fig 6's printed numbers and fig 9(a) fit A/L (see the rows).</p>
<p>Documents: {docs}.</p>
</section>
<section id="provenance">
<h2>How this report was built</h2>
<dl class="meta">
<dt>paper</dt><dd><a href="https://doi.org/{_e(paper.DOI)}">doi:{_e(paper.DOI)}</a></dd>
<dt>commit</dt><dd><code>{_e(meta.commit or "unknown")}</code></dd>
<dt>source tree</dt><dd>{tree}</dd>
<dt>grazing</dt><dd>{_e(meta.version)}</dd>
<dt>versions</dt><dd>{_e(versions)}</dd>
<dt>machine</dt><dd>{_e(meta.cpu)}, {meta.cores} cores usable, {lanes}; {_e(meta.system)}</dd>
<dt>rendered</dt><dd>{_e(meta.date)}</dd>
<dt>this build</dt><dd>{meta.seconds:.1f} s, of which {meta.compile_seconds:.1f} s compiling the kernels</dd>
</dl>
{timing}
</section>
<nav><h2>Contents</h2><ul>
{contents}
{pending}
</ul></nav>
"""
    body = "\n".join(figure_section(f) for f in figures)
    return head + body + "\n</body>\n</html>\n"
