"""The benchmark numbers of README.md and benchmarks/README.md are those of the saved run.

``benchmarks/run_all.py`` saves one run in ``benchmarks/results/latest.json`` and
``benchmarks/tables.py`` writes the tables between the ``<!-- bench:NAME -->`` markers from it.
These tests run no benchmark: they compare the documents' text with the saved JSON.
"""

from __future__ import annotations

import copy
import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def tables():
    spec = importlib.util.spec_from_file_location("bench_tables", ROOT / "benchmarks" / "tables.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def record(tables):
    return tables.load()


def test_the_saved_run_names_its_date_machine_and_vector_width(record):
    assert re.fullmatch(r"\d{4}-\d{2}-\d{2} \d{2}:\d{2} UTC", record["date"])
    machine = record["machine"]
    assert machine["cpu"] and machine["cores"] >= 1
    assert machine["vector_isa"] in ("AVX-512", "AVX2", "AVX", "SSE2", "unknown")
    assert machine["heyoka_simd_size"] >= 1 and machine["grazing_lanes"] >= 1
    assert set(record["parts"]) == {"equal-work", "sweep", "simulate", "grazing-curve", "curves", "scaling"}


def test_every_timing_of_the_equal_work_comparison_is_a_median_with_its_spread(record):
    ew = record["parts"]["equal-work"]
    for mode in ("whole_process", "in_process", "in_process_one_core"):
        for config in ew[mode]["configs"].values():
            s = config["seconds"]
            runs = sorted(s["runs"])
            assert len(runs) == ew["settings"]["repeats"]
            assert s["min"] == runs[0] and s["max"] == runs[-1]
            assert s["median"] == pytest.approx((runs[(len(runs) - 1) // 2] + runs[len(runs) // 2]) / 2)
        best = ew[mode]["heyoka_best"]
        medians = {k: c["seconds"]["median"] for k, c in ew[mode]["configs"].items() if k != "grazing"}
        assert medians[best] == min(medians.values())  # heyoka's best lane count is kept


def test_the_readme_tables_are_those_of_the_saved_run(tables, record):
    assert tables.stale(record) == [], "run `python benchmarks/tables.py` (or `make bench-all`)"


def test_a_number_changed_in_the_saved_run_makes_the_tables_stale(tables, record):
    changed = copy.deepcopy(record)
    grazing = changed["parts"]["equal-work"]["whole_process"]["configs"]["grazing"]["seconds"]
    grazing["median"] *= 1.5
    assert "README.md: equal-work" in tables.stale(changed)
    texts = {path: path.read_text() for path in tables.BLOCKS}
    rewritten = {path: tables.rewrite(text, tables.rendered(changed, path)) for path, text in texts.items()}
    assert tables.stale(changed, rewritten) == []
    assert tables.stale(record, rewritten) != []


def test_text_outside_the_markers_is_kept(tables, record):
    text = "before\n<!-- bench:simulate -->\nold\n<!-- /bench:simulate -->\nafter <!-- bench:x -->\n"
    new = tables.rewrite(text, {"simulate": "new\n"})
    assert new == "before\n<!-- bench:simulate -->\nnew\n<!-- /bench:simulate -->\nafter <!-- bench:x -->\n"
    with pytest.raises(ValueError, match="no markers for block"):
        tables.rewrite("no blocks here", {"simulate": "new\n"})


def test_the_first_run_names_its_date_and_machine_and_is_quoted_where_its_block_is(tables):
    """The first compile and the report's time (README.md, docs/installation.md) come from
    benchmarks/results/first_run.json, a run of benchmarks/bench_first_run.py."""
    import json

    run = json.loads(tables.FIRST_RUN.read_text())
    assert re.fullmatch(r"\d{4}-\d{2}-\d{2} \d{2}:\d{2} UTC", run["date"])
    assert run["machine"]["cpu"] and run["machine"]["cores"] >= 1 and run["machine"]["loadavg_end"]
    assert {"first_compile", "cached", "new_model"} <= set(run["steps"])
    assert run["steps"]["cached"]["wall_s"] < run["steps"]["first_compile"]["wall_s"]
    text = tables.readme_first_run({})
    assert f"{run['steps']['first_compile']['wall_s']:.0f} s" in text and run["machine"]["cpu"] in text
    for path in (tables.README, tables.INSTALLATION):
        assert tables.blocks(path.read_text())["first-run"] == text + "\n"
