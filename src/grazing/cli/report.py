"""``grazing report``: regenerate the paper's figures and tables into an HTML report."""

from __future__ import annotations

import time
from pathlib import Path

import click

from grazing.cli.common import check_folder
from grazing.cli.validate import path_type


@click.command()
@click.option("--out", type=path_type(file_okay=False), default=Path("report"),
              show_default=True, help="Output folder for index.html and figures: a report folder of "
              "grazing's, an empty folder, or a new one in an existing folder.")  # fmt: skip
@click.option("--only", "only", multiple=True, metavar="FIGURE",
              help="Rebuild only this figure or section (fig02, fig04, fig06 ... fig12, map, adding, "
                   "stops, attractors, switch, eq; repeatable) and re-render the page with the other figures "
                   "of earlier builds in --out.")  # fmt: skip
@click.option("--overwrite", is_flag=True,
              help="Build into a folder that is not a report folder of grazing's, replacing the files of "
              "the report's names in it.")  # fmt: skip
def report(out: Path, only: tuple[str, ...], overwrite: bool) -> None:
    """Regenerate the paper's figures and tables into an HTML report."""
    from grazing.report import build_report, select
    from grazing.report.folder import check_report_folder

    if only:
        try:
            select(only)
        except ValueError as exc:
            raise click.BadParameter(str(exc), param_hint="--only") from None
    check_folder(out)
    check_report_folder(out, overwrite=overwrite, hint="use another --out, or --overwrite to build into it")
    t0 = time.perf_counter()
    index = build_report(
        out, progress=lambda msg: click.echo(msg, err=True), only=only or None, overwrite=overwrite
    )
    click.echo(f"report written to {index} in {time.perf_counter() - t0:.1f} s")
