"""The HTML report: the page, its images and data files, its provenance, and rebuilding one figure."""

from __future__ import annotations

import json
import math
import re
import shutil
from pathlib import Path

import pytest
import xarray as xr
from click.testing import CliRunner

import grazing
from grazing.cli import cli
from grazing.report import FIGURES, PAPER_FIGURES, build_report, fig09, select
from grazing.report.base import Comparison, Dynamics, FigureResult, Image, signed
from grazing.report.html import ReportMeta, comparison_table, render

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_index_written(built) -> None:
    index, page, messages = built.index, built.page, built.messages
    assert index.name == "index.html" and index.is_file()
    assert page.startswith("<!DOCTYPE html>") and page.rstrip().endswith("</html>")
    assert grazing.__version__ in page
    assert messages, "progress was never reported"
    assert not list(index.parent.glob(".*.tmp")), "temporary file left behind"
    assert not any(m.startswith("report written") for m in messages), "the CLI says it, once"
    leftover = re.findall(r"\{[A-Za-z_][^}]*\}", page)
    assert not leftover, f"unformatted placeholders on the page: {leftover[:3]}"


def test_every_image_referenced_exists_is_png_and_links_to_itself(built) -> None:
    page = built.page
    sources = re.findall(r'<img src="([^"]+)"', page)
    assert len(sources) >= 10
    for src in sources:
        data = (built.out / src).read_bytes()
        assert data.startswith(PNG_SIGNATURE), src
        assert 10_000 < len(data) < 2_000_000, (src, len(data))
        assert f'<a href="{src}"><img src="{src}"' in page, f"{src} is not linked to its full size"
    on_disk = {p.name for p in built.out.glob("*.png")}
    assert on_disk == set(sources), "images written but not shown, or shown but not written"


def test_every_figure_writes_and_links_its_data(built) -> None:
    results = [json.loads(p.read_text()) for p in (built.out / "results").glob("*.json")]
    with_images = [r for r in results if r["images"]]
    assert with_images and all(r["data"] for r in with_images), "a figure without data files"
    for r in results:
        for d in r["data"]:
            path = built.out / d["filename"]
            assert path.is_file() and path.stat().st_size > 0, d["filename"]
            assert f'href="{d["filename"]}"' in built.page
            assert d["description"]
    # the sweeps open as NetCDF groups, with the swept values and the samples
    ds = xr.open_dataset(built.out / "fig07_sweeps.nc", group="d_main", engine="h5netcdf")
    assert {"theta", "period", "impacts_per_period"} <= set(ds.data_vars)
    assert ds.attrs["theta_hat_deg"] == 40.0
    assert ds["eta"].values[0] == fig_range("7", "d")[0]
    ds.close()
    # every image has a data file of its own figure beside it (fig03 was the one without, issue 30)
    data_names = {d["filename"] for r in results for d in r["data"]}
    for r in results:
        for img in r["images"]:
            prefix = img["filename"].split("_")[0]
            assert any(n.startswith((prefix + "_", prefix + ".")) for n in data_names), (
                f"{img['filename']}: no data file"
            )
    with xr.open_dataset(built.out / "fig03_synthetic_series.nc", group="a", engine="h5netcdf") as ds:
        assert ds.attrs["synthetic"] == 1 and (ds.attrs["theta_hat_deg"], ds.attrs["eta"]) == (10.0, 0.35)
        assert ds["theta_filtered"].size == ds["t"].size > 100


def fig_range(fid: str, key: str) -> tuple[float, float]:
    module = next(m for m in FIGURES if m.FIGURE_ID == fid)
    return next(p.eta_range for p in module.PANELS if p.key == key)


def test_provenance_on_the_page(built) -> None:
    page = built.page
    for name in ("python", "numpy", "scipy", "numba", "sympy", "xarray"):
        assert re.search(rf"\b{name} \d", page), name
    assert "cores usable" in page and "compiling the kernels" in page
    assert "kernel compilation (or loading from the cache)" in page
    for m in FIGURES:
        assert f'<a href="#fig{m.FIGURE_ID}">{m.FIGURE_ID}</a>' in page  # a compute-time row per figure
    assert re.search(r"<dt>commit</dt><dd><code>([0-9a-f]{40}(\+dirty)?|unknown)</code>", page)
    # issue 30: llvmlite, the vector width, the state of the tree and the paper's DOI
    assert re.search(r"\bllvmlite \d", page)
    assert re.search(r"vector registers of [248] doubles", page)
    dirty = re.search(r"<dt>source tree</dt><dd>([^<]+)</dd>", page)
    assert dirty is not None
    committed = re.search(r"<dt>commit</dt><dd><code>([^<]+)</code>", page).group(1)
    assert ("dirty" in dirty.group(1)) == committed.endswith("+dirty")
    assert 'href="https://doi.org/10.1007/s00332-004-0616-y"' in page
    data = json.loads((built.out / "comparisons.json").read_text())
    assert data["doi"] == "10.1007/s00332-004-0616-y" and data["vector_width"] in (2, 4, 8)


def test_the_page_names_no_document_outside_the_report(built) -> None:
    """No "SPEC" (a document not in the repository), no markdown backticks shown raw."""
    text = re.sub(r"<[^>]+>", " ", built.page)
    assert "SPEC" not in text
    assert "`" not in text
    for link in re.findall(r'href="(docs/[^"#]+)', built.page):
        assert (built.out / link).is_file(), link


def test_tables_scroll_and_figures_open_full_size_on_a_phone(built) -> None:
    page = built.page
    assert re.search(r"\.scroll \{[^}]*overflow-x: auto", page)
    tables = page.count("<table")
    assert tables >= 10 and page.count('<div class="scroll"><table') == tables, "a table outside its box"
    for src in re.findall(r'<img src="([^"]+)"', page):
        assert f'<a class="full" href="{src}">' in page, src


def test_top_of_page_scoreboard_differences_cases_docs(built) -> None:
    page = built.page
    top = page[: page.index('<section id="fig')]
    assert 'id="scoreboard"' in top and 'id="differences"' in top
    assert "Where we differ from the paper, and why" in top and "Errata in the paper" in top
    for case in ("A", "B", "C", "D", "A-reduced"):
        assert f"<td>{case}</td>" in top
    assert 'href="docs/normal-form.md"' in top and 'href="docs/experiment.md"' in top
    assert (built.out / "docs" / "normal-form.md").is_file()
    # every link of the box points to a row of the page
    for target in re.findall(r'<a href="#(row-[^"]+)"', top):
        assert f'<tr id="{target}">' in page, target


def test_every_paper_figure_has_a_section(built) -> None:
    page = built.page
    done = {m.FIGURE_ID for m in FIGURES}
    assert set(PAPER_FIGURES) <= done and "Not in this report" not in page
    for fid in done:
        assert f'<section id="fig{fid}">' in page


def test_table_holds_our_computed_periods(built) -> None:
    rows = json.loads((built.out / "comparisons.json").read_text())["rows"]
    # fig 9(b): our own period detection, independently of the report's code path
    m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    p = grazing.simulate(m, [0.0, 0.0], transient=1000, periods=200).period()
    assert p == 5
    row = next(r for r in rows if r["figure"] == "9" and r["quantity"].startswith("(b)"))
    assert row["ours"] == f"period-{p}" and row["verdict"] == "agree"
    # fig 9(a) as tabulated (alpha = 0.2254) does not reach the stop: a difference, explained by an
    # inference (the paper most likely used A/L), which is no erratum: nothing printed is shown wrong
    row_a = next(
        r for r in rows if r["figure"] == "9" and "0.2254" in r["quantity"] and "10°" in r["quantity"]
    )
    assert row_a["ours"] == "period-1" and row_a["verdict"] == "differ" and not row_a["erratum"]
    assert "inference" in row_a["headline"]


def test_only_rebuilds_one_figure_and_keeps_the_others(built, tmp_path: Path) -> None:
    out = tmp_path / "copy"
    shutil.copytree(built.out, out)
    before = json.loads((out / "results" / "7.json").read_text())
    res = CliRunner().invoke(cli, ["report", "--out", str(out), "--only", "eq"])
    assert res.exit_code == 0, res.output
    assert res.output.count("report written") == 1
    page = (out / "index.html").read_text()
    for m in FIGURES:
        assert f'<section id="fig{m.FIGURE_ID}">' in page
    assert json.loads((out / "results" / "7.json").read_text()) == before
    rows = json.loads((out / "comparisons.json").read_text())["rows"]
    assert {r["figure"] for r in rows} == {m.FIGURE_ID for m in FIGURES}
    bad = CliRunner().invoke(cli, ["report", "--out", str(out), "--only", "fig99"])
    assert bad.exit_code != 0 and "fig99" in bad.output


def test_select_names() -> None:
    assert [m.FIGURE_ID for m in select(["fig07", "fig7", "7"])] == ["7"]
    assert [m.FIGURE_ID for m in select(["map", "fig12", "fig02"])] == ["2", "12", "map"]
    assert [m.FIGURE_ID for m in select(["adding", "figadding", "map"])] == ["map", "adding"]  # issue 27
    with pytest.raises(ValueError, match="no figure"):
        select(["fig5"])


def test_render_escapes_text() -> None:
    row = Comparison("0", "<script>", "p", "o", "paper", "a rule", "not comparable", note="n", id="row-0-1")
    fig = FigureResult(
        figure_id="0",
        title="a <b> title",
        images=(Image("x.png", "caption & <i>"),),
        comparisons=(row,),
        notes=("1 < 2",),
    )
    page = render([fig], ReportMeta(version="9.9", date="today", seconds=0.5))
    assert "<script>" not in page and "&lt;script&gt;" in page
    assert "a &lt;b&gt; title" in page and "caption &amp; &lt;i&gt;" in page
    assert "not comparable" in page
    assert comparison_table([]) == ""


def test_dynamics_verdicts() -> None:
    assert Dynamics(5, -0.03, 0.2).verdict == "period-5"
    assert Dynamics(0, 0.05, 0.8).verdict == "chaotic"
    assert Dynamics(0, 0.0, 0.8).verdict.startswith("aperiodic")
    assert "no impacts" in Dynamics(1, -0.14, 0.0).describe()
    assert signed(-0.5, 3) == "−0.5" and signed(2e-5, 2).startswith("+2.0e")


def test_grazing_eta_brackets_the_first_contact() -> None:
    th = math.radians(10)
    eta_g = fig09.grazing_eta(th, 0.2254)
    for eta, impacts in ((eta_g - 2e-5, False), (eta_g + 2e-5, True)):
        m = grazing.models.pendulum("B", eta=eta, theta_hat=th)
        sol = grazing.simulate(m, [0.0, 0.0], transient=600, periods=20)
        assert (len(sol.impacts) > 0) is impacts, eta
    with pytest.raises(ValueError, match="already reaches"):
        fig09.grazing_eta(math.radians(1), 0.2254, eta_lo=0.45)


def test_build_report_only_unknown_name_fails_before_computing(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="no figure"):
        build_report(tmp_path, only=["nope"])
    assert not (tmp_path / "index.html").exists()


def test_report_only_help_names_every_figure() -> None:
    """``grazing report --help`` lists every name ``--only`` takes (each one selects its figure)."""
    from grazing.cli.report import report
    from grazing.report import FIGURES, select

    (only,) = [p for p in report.params if p.name == "only"]
    for m in FIGURES:
        name = f"fig{m.FIGURE_ID.zfill(2)}" if m.FIGURE_ID.isdigit() else m.FIGURE_ID
        assert select([name]) == [m]
        if m.FIGURE_ID.isdigit() and name not in ("fig02", "fig04", "fig06", "fig12"):
            continue  # (fig06 ... fig12: the numbered figures in between)
        assert name in only.help, name
