"""The report opens in headless Chromium with every image shown and every link live.

Skipped where no Chromium is installed (``apt-get install chromium``, or set
``$CHROMIUM``); ``make check-report`` runs the same check on ``report/``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from grazing.report.browser import check_page, find_chromium, main

pytestmark = pytest.mark.skipif(find_chromium() is None, reason="no Chromium installed")


def test_report_page_opens_with_all_images_and_links(built, tmp_path: Path) -> None:
    shot = tmp_path / "page.png"
    res = check_page(built.index, screenshot=shot)
    assert res.problems() == [] and res.ok
    assert res.images >= 10 and res.links >= 50 and "Piiroinen" in res.title
    assert shot.read_bytes().startswith(b"\x89PNG")


def test_a_missing_image_and_a_broken_link_are_reported(tmp_path: Path) -> None:
    page = tmp_path / "index.html"
    (tmp_path / "there.txt").write_text("x")
    page.write_text(
        '<!DOCTYPE html><html><head><title>t</title></head><body><img src="missing.png">'
        '<a href="there.txt">ok</a> <a href="gone.csv">gone</a> <a href="#nowhere">anchor</a>'
        '<p id="here"><a href="#here">fine</a></p></body></html>',
        encoding="utf-8",
    )
    res = check_page(page)
    assert res.broken_images == ["missing.png"]
    assert sorted(res.broken_links) == ["#nowhere", "gone.csv"]
    assert not res.ok and main([str(page)]) == 1
