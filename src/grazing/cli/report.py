"""``grazing report``: regenerate the paper's figures and tables into an HTML report."""

from __future__ import annotations

import time
from pathlib import Path

import click

from grazing.cli.validate import path_type


@click.command()
@click.option("--out", type=path_type(file_okay=False), default=Path("report"),
              show_default=True, help="Output folder for index.html and figures.")  # fmt: skip
@click.option("--only", "only", multiple=True, metavar="FIGURE",
              help="Rebuild only this figure (fig02, fig04, fig06 ... fig12, figmap, eq; repeatable) and "
                   "re-render the page with the other figures of earlier builds in --out.")  # fmt: skip
def report(out: Path, only: tuple[str, ...]) -> None:
    """Regenerate the paper's figures and tables into an HTML report."""
    from grazing.report import build_report, select

    if only:
        try:
            select(only)
        except ValueError as exc:
            raise click.BadParameter(str(exc), param_hint="--only") from None
    t0 = time.perf_counter()
    index = build_report(out, progress=lambda msg: click.echo(msg, err=True), only=only or None)
    click.echo(f"report written to {index} in {time.perf_counter() - t0:.1f} s")
