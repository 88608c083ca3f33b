"""Sweep stores: nothing grazing did not make is touched, one writer at a time, atomic creation,
damaged stores named, no process left behind, prompt Ctrl-C, clusters without workers."""

from __future__ import annotations

import json
import math
import multiprocessing as mp
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from grazing.cli import main
from grazing.models import pendulum
from grazing.sweeps import api, executor
from grazing.sweeps.api import run_sweep
from grazing.sweeps.lock import StoreBusyError
from grazing.sweeps.ownership import MARKER_GROUP, ForeignStoreError, remove_stale_builds
from grazing.sweeps.spec import SweepSpec
from grazing.sweeps.store import ZarrStore
from tests.processes import descendants, wait_until

M40 = pendulum("B", theta_hat=math.radians(40))
FORK = mp.get_context("fork")


def _spec(**kw):
    base = dict(model=M40, params=("eta",), points=tuple((float(v),) for v in np.linspace(0.44, 0.46, 6)),
                x0=(0.0, 0.0), transient=20, periods=5, chunk_size=2, lyapunov=False)  # fmt: skip
    base.update(kw)
    return SweepSpec(**base)


def _snapshot(root: Path) -> dict[str, bytes | None]:
    """Every file's bytes and every folder under ``root`` (and ``root`` itself)."""
    if root.is_file():
        return {".": root.read_bytes()}
    return {str(p.relative_to(root)): (p.read_bytes() if p.is_file() else None) for p in root.rglob("*")} | {
        ".": None
    }


def _hidden(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "grazing.cli", *args]


SWEEP = ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.46", "--num", "6", "--chunk-size", "2",
         "--transient", "20", "--periods", "5", "--no-lyapunov", "--workers", "1"]  # fmt: skip


# --------------------------------------------------------------------------
# Only grazing's own stores are opened; anything else is refused and left as it was


def _make_foreign(kind: str, path: Path) -> None:
    import xarray as xr

    if kind == "xarray store":
        xr.Dataset({"a": ("x", np.arange(5.0))}, attrs={"note": "mine"}).to_zarr(path, consolidated=False)
    elif kind == "empty folder":
        path.mkdir()
    elif kind == "file":
        path.write_bytes(b"not a store")
    elif kind == "earlier grazing store":  # what grazing wrote before the marker existed
        ds = xr.Dataset({"chunk_done": ("chunk", np.zeros(3, dtype=np.int8))})
        ds.attrs.update({"initialized": 1, "fingerprint": "0123"})
        ds.to_zarr(path, consolidated=False)
    elif kind == "store with a partial marker":
        xr.Dataset({"a": ("x", np.arange(5.0))}).to_zarr(path, consolidated=False)
        (path / MARKER_GROUP).mkdir()


FOREIGN = ["xarray store", "empty folder", "file", "earlier grazing store", "store with a partial marker"]


@pytest.mark.parametrize("kind", FOREIGN)
def test_anything_else_at_out_is_refused_and_untouched(kind, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "s.zarr"
    _make_foreign(kind, path)
    before = _snapshot(path)
    code = main([*SWEEP, "--out", str(path)])
    err = capsys.readouterr().err
    assert code == 1
    assert err.startswith("grazing: error: ") and err.count("\n") == 1
    assert "is not a grazing sweep store" in err
    if kind == "earlier grazing store":
        assert "earlier grazing" in err
    assert _snapshot(path) == before  # byte for byte, no file added or removed
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.zarr"]
    with pytest.raises(ForeignStoreError):
        ZarrStore(path, _spec())
    assert _snapshot(path) == before


def test_a_store_is_readable_by_xarray_without_warnings(tmp_path):
    import warnings

    import xarray as xr

    path = tmp_path / "s.zarr"
    with ZarrStore(path, _spec()) as store:
        run_sweep(_spec(), store=store, workers=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ds = xr.open_zarr(path, consolidated=False)
    assert ds.chunk_done.values.tolist() == [1, 1, 1]


# --------------------------------------------------------------------------
# Creation: all at once


@pytest.mark.parametrize("failure", [RuntimeError, KeyboardInterrupt])
def test_interrupted_creation_leaves_nothing(failure, tmp_path, monkeypatch):
    built = []

    def broken_build(self, folder):
        (folder / "period").mkdir()
        built.append(folder)
        raise failure("disk full")

    monkeypatch.setattr(ZarrStore, "_build", broken_build)
    with pytest.raises(failure):
        ZarrStore(tmp_path / "s.zarr", _spec())
    assert built and not built[0].exists()
    assert list(tmp_path.iterdir()) == []


def test_builds_left_by_dead_processes_are_removed(tmp_path):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    path = tmp_path / "s.zarr"
    stale = tmp_path / f".s.zarr.creating-{dead.pid}-abc"  # killed while building: marker written
    (stale / MARKER_GROUP).mkdir(parents=True)
    (stale / MARKER_GROUP / "zarr.json").write_text("{}")
    empty = tmp_path / f".s.zarr.creating-{dead.pid}-def"  # killed right after mkdtemp
    empty.mkdir()
    running = tmp_path / f".s.zarr.creating-{os.getpid()}-ghi"  # a live build: not ours to remove
    running.mkdir()
    foreign = tmp_path / f".s.zarr.creating-{dead.pid}-jkl"  # named like ours, holds something else
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    assert sorted(p.name for p in remove_stale_builds(path)) == sorted([stale.name, empty.name])
    assert running.exists() and (foreign / "notes.txt").read_text() == "mine"


def _race_child(path, spec, delay, results, release):
    time.sleep(delay)
    try:
        store = ZarrStore(path, spec)
    except StoreBusyError as exc:
        results.put(("busy", os.getpid(), str(exc)))
        return
    except BaseException as exc:  # anything else is a failure of the test
        results.put(("error", os.getpid(), f"{type(exc).__name__}: {exc}"))
        return
    results.put(("ok", os.getpid(), ""))
    release.wait(60)
    store.close()


@pytest.mark.parametrize("delay", [0.0, 0.002, 0.01, 0.03, 0.1])
def test_racing_creations_give_one_writer_and_one_whole_store(delay, tmp_path):
    """Three processes open the same new store, started ``delay`` apart (inside creation and after)."""
    path, spec = tmp_path / "s.zarr", _spec()
    results, release = FORK.Queue(), FORK.Event()
    procs = [
        FORK.Process(target=_race_child, args=(path, spec, k * delay, results, release)) for k in range(3)
    ]
    for p in procs:
        p.start()
    got = [results.get(timeout=120) for _ in procs]
    release.set()
    for p in procs:
        p.join(60)
    kinds = sorted(g[0] for g in got)
    assert kinds == ["busy", "busy", "ok"], got
    winner = next(g[1] for g in got if g[0] == "ok")
    for kind, _pid, msg in got:
        if kind == "busy":
            assert f"is being written by another grazing run (PID {winner})" in msg
    assert _hidden(tmp_path) == []  # no build left over
    with ZarrStore(path, spec) as store:  # a whole store, nothing done yet
        assert store.n_done == 0
        ds = run_sweep(spec, store=store, workers=1)
    ref = run_sweep(spec, workers=1)
    np.testing.assert_array_equal(ds.samples.values, ref.samples.values)


def _cli_race(tmp_path: Path, delay: float) -> None:
    out = tmp_path / f"race{delay}.zarr"
    args = "sweep --param eta --start 0.44 --stop 0.46 --num 12 --chunk-size 2 --transient 3000 --periods 5"
    args = [*args.split(), "--no-adaptive", "--no-lyapunov", "--workers", "1", "--out", str(out)]
    a = subprocess.Popen(_cli(*args), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    b = subprocess.Popen(_cli(*args), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    runs = [(p.pid, *p.communicate(timeout=300), p.returncode) for p in (a, b)]
    for pid, _out, err, code in runs:
        assert "Traceback" not in err
        if code != 0:
            other = a.pid if pid == b.pid else b.pid
            assert code == 1 and err.count("\n") == 1, err
            assert f"is being written by another grazing run (PID {other})" in err
    assert any(code == 0 for *_, code in runs)
    assert _hidden(tmp_path) == []
    import xarray as xr

    ds = xr.open_zarr(out, consolidated=False)
    assert ds.chunk_done.values.all() and (ds.period.values >= 0).all()


def test_two_cli_runs_racing_on_one_store(tmp_path):
    _cli_race(tmp_path, 0.2)


@pytest.mark.slow
@pytest.mark.parametrize("delay", [0.0, 0.05, 0.1, 0.3, 0.6, 1.0])
def test_two_cli_runs_racing_on_one_store_at_many_delays(delay, tmp_path):
    _cli_race(tmp_path, delay)


# --------------------------------------------------------------------------
# The lock: dead holders, forked workers, --wait


def _hold(path, spec, ready, release):
    store = ZarrStore(path, spec)
    ready.set()
    release.wait(120)
    store.close()


def test_a_lock_left_by_a_dead_process_is_taken_over(tmp_path):
    path, spec = tmp_path / "s.zarr", _spec()
    ready, release = FORK.Event(), FORK.Event()
    holder = FORK.Process(target=_hold, args=(path, spec, ready, release))
    holder.start()
    assert ready.wait(120)
    with pytest.raises(StoreBusyError, match=f"PID {holder.pid}"):
        ZarrStore(path, spec)
    os.kill(holder.pid, signal.SIGKILL)
    holder.join()
    with ZarrStore(path, spec) as store:  # taken over, no waiting
        assert (path / MARKER_GROUP / "lock").read_text().strip() == str(os.getpid())
        assert store.n_done == 0


def test_forked_children_do_not_keep_the_lock(tmp_path):
    path, spec = tmp_path / "s.zarr", _spec()
    store = ZarrStore(path, spec)
    release = FORK.Event()
    child = FORK.Process(target=release.wait, args=(120,))
    child.start()  # inherits the store's open files
    try:
        store.close()
        with ZarrStore(path, spec):  # would be busy if the child still held the lock
            pass
    finally:
        release.set()
        child.join()


def test_a_copy_of_the_lock_not_yet_closed_does_not_keep_it(tmp_path):
    """A child forked a moment before the store is closed may not have run yet (so not closed its
    copy of the lock): the holder unlocks, not only closes (the test above was flaky under load)."""
    from grazing.sweeps import lock

    path, spec = tmp_path / "s.zarr", _spec()
    store = ZarrStore(path, spec)
    (fd,) = lock._HELD
    copy = os.dup(fd)  # (what a forked child holds until it runs: the same open file description)
    try:
        store.close()
        with ZarrStore(path, spec):
            pass
    finally:
        os.close(copy)


def test_wait_waits_for_the_other_run_and_without_it_the_pid_is_named(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "w.zarr"
    argv = [*SWEEP, "--out", str(out)]
    captured = {}

    def capture(spec, **kw):
        captured["spec"] = spec
        raise KeyboardInterrupt

    monkeypatch.setattr(api, "run_sweep", capture)
    assert main(argv) == 130  # creates the store, computes nothing
    monkeypatch.undo()
    capsys.readouterr()
    ready, release = FORK.Event(), FORK.Event()
    holder = FORK.Process(target=_hold, args=(out, captured["spec"], ready, release))
    holder.start()
    try:
        assert ready.wait(120)
        busy = subprocess.run(_cli(*argv), capture_output=True, text=True, timeout=300)
        assert busy.returncode == 1 and busy.stdout == ""
        assert busy.stderr == (
            f"grazing: error: {out} is being written by another grazing run (PID {holder.pid}); "
            "wait for it to finish (--wait) or use another store (--out)\n"
        )
        waiter = subprocess.Popen(
            _cli(*argv, "--wait"), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        line = waiter.stderr.readline()
        assert f"(PID {holder.pid}); waiting" in line
        release.set()
        stdout, stderr = waiter.communicate(timeout=300)
        assert waiter.returncode == 0, stderr
        assert f"saved to {out}" in stdout
    finally:
        release.set()
        holder.join()


# --------------------------------------------------------------------------
# Damaged stores: one line naming the store and what to do


@pytest.mark.parametrize(("target", "json_out"), [("samples/c/1/0/0", True), ("chunk_done/c/0", False)])
def test_a_damaged_store_is_named_in_one_line(target, json_out, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "d.zarr"
    argv = [*SWEEP, "--out", str(out)] + (["--json"] if json_out else [])
    assert main(argv) == 0
    capsys.readouterr()
    (out / target).write_bytes(b"garbage")
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith(
        f"grazing: error: sweep store {out} is damaged (cannot read '{target.split('/')[0]}'"
    )
    assert err.rstrip().endswith("delete it (or move it away) and run the command again to recompute it")


# --------------------------------------------------------------------------
# Results stream to the store


def test_a_zarr_run_without_json_never_loads_the_results(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main([*SWEEP, "--direction", "down"]) == 0
    in_memory = capsys.readouterr().out
    monkeypatch.setattr(ZarrStore, "dataset", lambda self: pytest.fail("loaded the whole store"))
    assert main([*SWEEP, "--direction", "down", "--out", "s.zarr"]) == 0
    streamed = capsys.readouterr().out
    summary = [line for line in in_memory.splitlines() if line.startswith("  period")]
    assert summary and summary == [line for line in streamed.splitlines() if line.startswith("  period")]


# --------------------------------------------------------------------------
# No process left behind; Ctrl-C stops at once and keeps what is finished


def _slow_cli(out: Path) -> list[str]:
    # ~0.1-0.5 s per point, 400 points: the sweep is still running when the signal comes
    args = "sweep --param eta --start 0.44 --stop 0.49 --num 400 --chunk-size 1 --workers 2"
    args += " --transient 60000 --periods 10 --no-adaptive --no-lyapunov --out"
    return _cli(*args.split(), str(out))


def _chunks_done(out: Path) -> int:
    import zarr

    try:
        return int(np.sum(zarr.open_array(str(out / "chunk_done"), mode="r")[:]))
    except Exception:
        return 0


def test_a_local_sweep_starts_no_process(tmp_path):
    # The chunks are computed by threads of the sweep's own process: killed (SIGKILL, the OOM killer,
    # a closed terminal), it leaves nothing behind.
    out = tmp_path / "k.zarr"
    proc = subprocess.Popen(_slow_cli(out), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        assert wait_until(lambda: _chunks_done(out) >= 2), "no chunk was finished"
        assert descendants(proc.pid) == set()
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_ctrl_c_stops_at_once_and_keeps_the_finished_chunks(tmp_path):
    out = tmp_path / "c.zarr"
    # As from a terminal: Ctrl-C's default disposition (a test runner's worker may ignore SIGINT,
    # and a child started from it would inherit that and run to the end).
    proc = subprocess.Popen(_slow_cli(out), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=_default_sigint)  # fmt: skip
    try:
        assert wait_until(lambda: _chunks_done(out) >= 1)
        os.killpg(proc.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the whole process group
        _, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, (proc.returncode, err, _chunks_done(out))
    assert err.strip() == "grazing: interrupted"
    assert 1 <= _chunks_done(out) < 400  # what was finished is kept (and resumed by the same command)


def test_closing_a_local_sweep_stops_its_threads_at_once():
    # What Ctrl-C, or an error while writing a result, does: the threads return at their next step
    # (the 400 points would take minutes), the unfinished chunks are not reported.
    spec = _spec(points=tuple((float(v),) for v in np.linspace(0.44, 0.49, 400)), chunk_size=1,
                 transient=60000, periods=10, adaptive=False)  # fmt: skip
    results = executor.local_results([(spec, i) for i in range(spec.n_chunks)], 2)
    _, first = next(results)
    assert first.period.shape == (1,) and first.period[0] >= 1
    start = time.monotonic()
    results.close()
    assert time.monotonic() - start < 10.0
    assert [t.name for t in threading.enumerate() if t.name.startswith("grazing-sweep")] == []


# --------------------------------------------------------------------------
# A Dask cluster without workers


def test_a_cluster_without_workers_says_so_and_times_out(tmp_path, monkeypatch, capsys):
    from distributed import LocalCluster

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(executor, "DASK_NOTICE_AFTER", 0.0)
    with LocalCluster(n_workers=0, processes=False, dashboard_address=":0") as cluster:
        addr = cluster.scheduler_address
        code = main([*SWEEP[:-2], "--scheduler", addr, "--timeout", "1", "--out", "s.nc"])
    out, err = capsys.readouterr()
    assert code == 1 and out == ""
    lines = err.splitlines()
    assert lines == [
        f"grazing: no Dask worker is connected to {addr}: waiting for one (giving up after 1 s)",
        f"grazing: error: no Dask worker connected to {addr} within 1 s; start workers (dask worker ADDRESS) "
        "or run without a scheduler (--scheduler)",
    ]
    assert list(tmp_path.iterdir()) == []


def test_json_output_of_a_resumed_store_is_unchanged(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    argv = [*SWEEP, "--out", "r.zarr", "--json"]
    assert main(argv) == 0
    first = json.loads(capsys.readouterr().out)
    assert main(argv) == 0
    again = json.loads(capsys.readouterr().out)
    assert first["period"] == again["period"] and first["samples"] == again["samples"]


def test_without_flock_the_pid_in_the_lock_file_decides(tmp_path, monkeypatch):
    import errno

    from grazing.sweeps import lock as lock_module

    def no_flock(fd, op):
        raise OSError(errno.ENOLCK, "no locks available")

    monkeypatch.setattr(lock_module.fcntl, "flock", no_flock)
    path = tmp_path / "lock"
    path.write_text(f"{os.getppid()}\n")  # a live process holds it
    with pytest.raises(StoreBusyError, match=f"PID {os.getppid()}"):
        lock_module.StoreLock(path, "s.zarr").acquire()
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    path.write_text(f"{dead.pid}\n")  # its holder is gone: taken over
    held = lock_module.StoreLock(path, "s.zarr")
    held.acquire()
    assert path.read_text().strip() == str(os.getpid())
    held.release()
