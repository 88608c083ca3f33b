"""Worker processes die with their parent: the report's pool, the initializer, and a pool stopped early."""

from __future__ import annotations

import multiprocessing as mp
import os
import signal
import time
from pathlib import Path

from grazing.parallel import init_worker
from tests.processes import all_gone, wait_until

FORK = mp.get_context("fork")


def _stuck(folder: str) -> None:
    Path(folder, str(os.getpid())).touch()
    time.sleep(600)


def _report_pool(folder: str) -> None:
    from grazing.report.diagrams import run_parallel

    run_parallel(_stuck, [folder, folder], workers=2)


def test_the_report_pool_dies_with_its_parent(tmp_path):
    parent = FORK.Process(target=_report_pool, args=(str(tmp_path),))
    parent.start()
    assert wait_until(lambda: len(list(tmp_path.iterdir())) == 2)
    workers = [int(p.name) for p in tmp_path.iterdir()]
    os.kill(parent.pid, signal.SIGKILL)  # no chance to clean up
    parent.join()
    assert all_gone(workers)


def _worker_of(parent_pid: int, folder: str) -> None:
    init_worker(parent_pid)
    _stuck(folder)


def _parent(folder: str) -> None:
    FORK.Process(target=_worker_of, args=(os.getpid(), folder)).start()
    time.sleep(600)


def test_a_worker_whose_parent_died_before_it_started_exits(tmp_path):
    marks = tmp_path / "marks"
    marks.mkdir()
    child = FORK.Process(target=_worker_of, args=(os.getpid() + 10**6, str(marks)))  # not its parent
    child.start()
    child.join(60)
    assert child.exitcode == 1 and list(marks.iterdir()) == []


def test_init_worker_kills_the_worker_with_its_parent(tmp_path):
    parent = FORK.Process(target=_parent, args=(str(tmp_path),))
    parent.start()
    assert wait_until(lambda: len(list(tmp_path.iterdir())) == 1)
    worker = int(next(tmp_path.iterdir()).name)
    os.kill(parent.pid, signal.SIGKILL)
    parent.join()
    assert all_gone([worker])


def _fast_or_stuck(i: int) -> int:
    if i == 0:
        return i
    marks = Path(os.environ["GRAZING_TEST_MARKS"])
    (marks / f"started-{i}").write_text(str(os.getpid()))
    time.sleep(600)  # a job in flight: it never finishes unless waited for
    (marks / f"finished-{i}").touch()
    return i


def test_stopping_the_pool_cancels_queued_jobs_and_kills_those_in_flight(tmp_path, monkeypatch):
    from grazing.parallel import map_unordered

    monkeypatch.setenv("GRAZING_TEST_MARKS", str(tmp_path))
    results = map_unordered(_fast_or_stuck, list(range(6)), 2)
    assert next(results) == 0
    assert wait_until(lambda: len(list(tmp_path.glob("started-*"))) == 2)  # both workers busy
    workers = [int(p.read_text()) for p in tmp_path.glob("started-*")]
    results.close()  # what Ctrl-C, or an error while using a result, does
    assert all_gone(workers)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["started-1", "started-2"]  # nothing else ran


def _stage(job: tuple[str, int]) -> tuple[str, int, int]:
    """A first job marks itself done after a while; a later job counts the marks it finds on starting."""
    kind, i = job
    marks = Path(os.environ["GRAZING_TEST_MARKS"])
    if kind == "first":
        time.sleep(0.2 * (i + 1))
        (marks / f"first-{i}").touch()
        return kind, i, os.getpid()
    return kind, len(list(marks.glob("first-*"))), os.getpid()


def test_first_jobs_finish_before_the_others_start_on_the_same_workers(tmp_path, monkeypatch):
    from grazing.parallel import map_unordered

    monkeypatch.setenv("GRAZING_TEST_MARKS", str(tmp_path))
    first = [("first", i) for i in range(3)]
    results = list(map_unordered(_stage, [("job", i) for i in range(5)], 2, first=first))
    assert [r[0] for r in results] == ["first"] * 3 + ["job"] * 5  # the first ones are yielded first
    assert [r[1] for r in results[3:]] == [3] * 5  # every job started after all the first ones ended
    assert len({r[2] for r in results}) == 2 and os.getpid() not in {r[2] for r in results}
    assert {r[2] for r in results[3:]} <= {r[2] for r in results[:3]}  # the same worker processes
