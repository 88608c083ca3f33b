"""The report's figures built side by side: jobs, relayed progress, the same results as one by one."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from grazing.report import FIGURES, errata, fig04, fig07, fig10, fig12
from grazing.report.folder import MARKER
from grazing.report.schedule import KERNELS, RESULTS, build_figures, groups
from tests.processes import all_gone, descendants, wait_until


def _ids(jobs):
    return [[m.FIGURE_ID for m in job] for job in jobs]


def test_fig_10_is_built_after_fig_7_in_its_process_and_every_figure_once():
    jobs = groups(FIGURES)
    assert ["7", "10"] in _ids(jobs)
    assert sorted(m.FIGURE_ID for job in jobs for m in job) == sorted(m.FIGURE_ID for m in FIGURES)
    assert _ids(groups([fig10, fig12])) == [["10"], ["12"]]  # without fig 7, fig 10 computes its own
    assert _ids(groups([fig07, fig12, fig10])) == [["7", "10"], ["12"]]


def _kept(out: Path) -> dict[str, dict]:
    found = {}
    for path in sorted((out / RESULTS).glob("*.json")):
        res = json.loads(path.read_text(encoding="utf-8"))
        found[path.stem] = {k: v for k, v in res.items() if k not in ("built", "seconds")}
    return found


def test_figures_built_on_two_processes_equal_those_built_here(tmp_path):
    results = {}
    for workers in (1, 2):
        out = tmp_path / f"w{workers}"
        (out / RESULTS).mkdir(parents=True)
        messages: list[str] = []
        ready = build_figures([fig04, errata], out, messages.append, "c0ffee", workers=workers)
        assert ready > 0
        assert [m for m in messages if m.startswith("kernels ready")] == [f"kernels ready in {ready:.1f} s"]
        done = [m.split()[1] for m in messages if m.startswith("figure ")]
        assert sorted(done) == ["4", "eq"]
        assert messages.index(next(m for m in messages if m.startswith("kernels ready"))) < min(
            messages.index(m) for m in messages if m.startswith("figure ")
        )
        assert any(not m.startswith(("kernels", "figure ")) for m in messages), "a figure's own messages"
        results[workers] = _kept(out)
        assert set(results[workers]) == {"4", "eq"}
        assert all(r["commit"] == "c0ffee" for r in results[workers].values())
        assert not [p.name for p in out.rglob(".*")], "no temporary file left"
    assert results[1] == results[2]


def test_the_kernels_are_those_of_the_figures():
    kinds = [k for k, _ in KERNELS]
    assert kinds[0] == "sweep" and {"flow", "tangent"} <= set(kinds)


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _complete_png(path: Path) -> bool:
    data = path.read_bytes()
    return data.startswith(b"\x89PNG") and data.endswith(b"IEND\xaeB`\x82")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_ctrl_c_stops_the_report_at_once_and_leaves_no_process(tmp_path):
    out = tmp_path / "report"
    cmd = [sys.executable, "-m", "grazing", "report", "--out", str(out)]
    # As from a terminal: Ctrl-C's default disposition, sent to the whole process group.
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=_default_sigint)  # fmt: skip
    try:
        assert wait_until(lambda: len(descendants(proc.pid)) >= 2, limit=300), "no worker was started"
        assert wait_until(lambda: any(out.glob("*.png")) or proc.poll() is not None, limit=300)
        workers = descendants(proc.pid)
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert err.strip().endswith("grazing: interrupted")
    assert all_gone(workers)
    assert not (out / "index.html").exists()  # the page is written last
    assert all(_complete_png(p) for p in out.glob("*.png"))
    assert not [p.name for p in out.rglob(".*") if p.name != MARKER], "a temporary file or folder left"
