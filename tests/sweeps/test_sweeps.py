"""Sweeps: known windows, Lyapunov exponents, adaptive transients, storage, clusters."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import grazing
from grazing.cli import main
from grazing.core.period import orbit_impacts
from grazing.models import pendulum
from grazing.orbits import find_orbit
from grazing.sweeps import parameter_map, sweep
from grazing.sweeps.run import run_chunk
from grazing.sweeps.spec import SweepSpec
from grazing.sweeps.store import StoreMismatchError, ZarrStore
from tests.sweeps.dask_cluster import loopback_client

DEG = math.pi / 180
M40 = pendulum("B", theta_hat=40 * DEG)


# --------------------------------------------------------------------------
# Periods of known windows, cross-checked by shooting


# Points well inside the windows of the reverse period-adding cascade at theta_hat = 40 deg (fig 7d)
# and in the middle of the two wide chaotic bands, as a fine sweep (1e-5 apart) shows them:
# nonimpacting period 1 up to the grazing at 0.44512, then period 6 (0.44516-0.44534), 5
# (0.44542-0.44619), 4 (0.44671-0.44923), chaos (0.44924-0.45163), 3 (0.45176-0.45769), chaos
# (0.45780-0.46364), 2 (0.46383-0.47825), impacting period 1.  Each point is at least 9e-5 (a
# tenth of its window or more) from the window's edges, so the periods do not depend on the
# sweep's details (checked: the same with the points shifted by 2e-6 or -3e-6, a transient of
# 700 or 950, from x0 = (0.01, 0) or (-0.2, 0.1)); the narrow chaotic band between periods 6
# and 5 (6e-5 wide, with periodic windows inside) is not asserted on.
WINDOWS = {0.440: 1, 0.44525: 6, 0.4458: 5, 0.4480: 4, 0.4505: 0, 0.4550: 3, 0.4600: 0, 0.4700: 2, 0.5000: 1}


@pytest.fixture(scope="module")
def window_sweep():
    etas = np.array(list(WINDOWS))
    # 120 sampled periods: whole cycles of every period up to 6
    return etas, sweep(M40, "eta", etas, fresh=True, workers=1, transient=800, periods=120)


def test_periods_of_the_period_adding_windows(window_sweep):
    """theta_hat = 40 deg (fig 7d): nonimpacting period 1 before grazing (eta = 0.44512), then the
    reverse period-adding cascade 6, 5, 4, 3, 2 with chaotic bands between 4 and 3 and between
    3 and 2, and the period-1 impacting orbit."""
    _, ds = window_sweep
    assert ds.period.values.tolist() == list(WINDOWS.values())
    assert ds.impacts.values[0] == 0 and ds.impacts.values[-1] == ds.sizes["sample"]
    # one impact per cycle of each window's orbit: period adding
    impacting = ds.period.values > 1
    np.testing.assert_array_equal(ds.impacts.values[impacting] * ds.period.values[impacting], 120)


def test_windows_agree_with_shooting(window_sweep):
    """Every periodic point of the sweep is a stable orbit found independently by Newton."""
    etas, ds = window_sweep
    for eta, p, samples in zip(etas, ds.period.values, ds.samples.values):
        if p <= 0:
            continue
        orbit = find_orbit(M40.with_params(eta=float(eta)), samples[-1], period=int(p))
        assert orbit.stable and orbit.abs_lambda < 0.75  # well inside the window: |mu| <= 0.70 here
        assert orbit.impacts == (0 if eta < 0.445 else 1)
        assert np.min(np.max(np.abs(samples[-p:] - orbit.state), axis=1)) < 1e-8


def test_impacts_per_period_is_the_orbits_over_a_window_of_no_whole_cycles():
    """100 sampled periods hold no whole number of cycles of the period-3, 6... orbits: the count of impacts
    in them is off by up to one cycle's, and the dataset's impacts per period is still the orbit's, exact
    (it was 0.99 for the period-3 orbit, 1.02 or 0.98 for a period-6 one)."""
    etas = np.array(list(WINDOWS))
    ds = sweep(M40, "eta", etas, fresh=True, workers=1, transient=800, periods=100)
    partial = [p for p in ds.period.values if p > 0 and 100 % p]
    assert sorted(set(partial)) == [3, 6]  # (what the test is about)
    for eta, p, ipp, count, samples in zip(
        etas, ds.period.values, ds.impacts_per_period.values, ds.impacts.values, ds.samples.values
    ):
        if p <= 0:  # (aperiodic: per forcing period, the count's ratio)
            assert ipp == count / 100
            continue
        orbit = find_orbit(M40.with_params(eta=float(eta)), samples[-1], period=int(p))
        assert ipp == orbit.impacts, eta


@given(
    period=st.integers(1, 12),
    pattern=st.lists(st.integers(0, 3), min_size=12, max_size=12),
    offset=st.integers(0, 11),
    periods=st.integers(1, 150),
)
def test_orbit_impacts_of_any_periodic_pattern(period, pattern, offset, periods):
    """A period-p orbit with pattern[j] impacts in its j-th forcing period, seen through a window of
    ``periods`` forcing periods starting anywhere: the orbit's impacts per period, exact where the count
    allows only one whole number, else the count's ratio -- and exact whenever the window holds more
    whole cycles than the orbit has impacts."""
    pattern = pattern[:period]
    k = sum(pattern)
    count = sum(pattern[(offset + i) % period] for i in range(periods))
    got = float(orbit_impacts(np.array([count]), np.array([period]), periods)[0])
    q = periods // period
    assert got == k or got == pytest.approx(count / periods * period)
    if q > k:
        assert got == k


def test_lyapunov_exponents(window_sweep):
    etas, ds = window_sweep
    lyap = ds.lyapunov.values
    # periodic points: ln|mu_max| / (2 pi p) from the Floquet multipliers
    for eta, p, lam, samples in zip(etas, ds.period.values, lyap, ds.samples.values):
        if p <= 0:
            continue
        orbit = find_orbit(M40.with_params(eta=float(eta)), samples[-1], period=int(p))
        expected = math.log(orbit.abs_lambda) / (2 * math.pi * p)
        # a finite-time exponent over whole cycles differs from the Floquet one by O(1) / span (the
        # tangent vector's growth within a cycle with complex multipliers): measured up to 0.7 / span
        assert lam == pytest.approx(expected, abs=2 / (2 * math.pi * 120))
    # the chaotic bands: positive (0.013-0.053 over the variations listed above WINDOWS)
    assert np.all(lyap[ds.period.values == 0] > 5e-3)


def test_chaotic_points_have_positive_exponents_and_no_period():
    """The middle of the chaotic band between the period-3 and period-2 windows (0.4578-0.4636)."""
    ds = sweep(M40, "eta", [0.4595, 0.4600, 0.4605], fresh=True, workers=1, transient=1000, periods=1000)
    assert np.all(ds.period.values == 0)
    assert np.all(ds.lyapunov.values > 0.005)


# --------------------------------------------------------------------------
# Adaptive transients


@pytest.mark.parametrize(
    ("fresh", "lo", "hi"),
    [
        (True, 0.44, 0.49),  # fresh: every point starts from x0; chaos and windows alike
        (False, 0.465, 0.49),  # continuation without chaos (see the note in sweeps.run)
    ],
)
def test_adaptive_transient_gives_the_same_periods(fresh, lo, hi):
    etas = np.linspace(lo, hi, 60)
    kw = dict(fresh=fresh, workers=1, lyapunov=False, chunk_size=20)
    a = sweep(M40, "eta", etas, adaptive=True, **kw)
    b = sweep(M40, "eta", etas, adaptive=False, **kw)
    np.testing.assert_array_equal(a.period.values, b.period.values)
    assert a.transient_used.values.mean() < 0.7 * b.transient_used.values.mean()
    # same orbit at the same point of its cycle
    periodic = a.period.values > 0
    np.testing.assert_allclose(a.samples.values[periodic], b.samples.values[periodic], atol=1e-7)


def test_sweep_direction_and_order():
    etas = np.linspace(0.40, 0.43, 4)
    up = sweep(M40, "eta", etas, direction="up", workers=1, periods=20)
    down = sweep(M40, "eta", etas, direction="down", workers=1, periods=20)
    np.testing.assert_allclose(up.value.values, etas)
    np.testing.assert_allclose(down.value.values, etas)  # results are returned in increasing order
    np.testing.assert_array_equal(up.period.values, down.period.values)
    np.testing.assert_allclose(up.samples.values, down.samples.values, atol=1e-8)  # unique attractor


def test_two_parameter_map_shape():
    ds = parameter_map(M40, "eta", np.linspace(0.40, 0.55, 6), "theta_hat", np.radians([10, 30, 50]),
                       periods=40, workers=1)  # fmt: skip
    assert ds.period.dims == ("theta_hat", "eta")
    assert ds.period.shape == (3, 6)
    assert ds.period.values[2, 0] == 1  # 50 deg, far from resonance: nonimpacting period 1
    assert ds.impacts.values[2, 0] == 0
    # issue 30: the coordinates keep what plots need (a map drawn in radians on a degree axis was blank)
    assert ds.theta_hat.attrs["angle"] == 1 and ds.theta_hat.attrs["symbol"] == "θ̂"
    assert ds.eta.attrs["angle"] == 0 and ds.eta.attrs["symbol"] == "η"
    from matplotlib.figure import Figure

    from grazing.plotting import plot_period_map

    ax = Figure().add_subplot()
    mesh = plot_period_map(ax, ds, colorbar=False)
    ys = mesh.get_coordinates()[:, 0, 1]  # the cell edges along the θ̂ axis
    assert ys.min() < 10 and ys.max() > 50 and ax.get_ylabel() == "θ̂ (degrees)"


# --------------------------------------------------------------------------
# Storage: Zarr, resume after SIGKILL, refusal of other sweeps, NetCDF


def _spec(**kw):
    base = dict(model=M40, params=("eta",), points=tuple((float(v),) for v in np.linspace(0.44, 0.46, 12)),
                x0=(0.0, 0.0), transient=200, periods=30, chunk_size=4)  # fmt: skip
    base.update(kw)
    return SweepSpec(**base)


def test_zarr_store_roundtrip_and_mismatch(tmp_path):
    from grazing.sweeps import run_sweep

    spec = _spec()
    path = tmp_path / "s.zarr"
    ds = run_sweep(spec, store=ZarrStore(path, spec), workers=1)
    ref = run_sweep(spec, workers=1)
    np.testing.assert_array_equal(ds.samples.values, ref.samples.values)
    np.testing.assert_array_equal(ds.period.values, ref.period.values)
    # reopening computes nothing and returns the same
    again = run_sweep(spec, store=ZarrStore(path, spec), workers=1)
    np.testing.assert_array_equal(again.samples.values, ref.samples.values)
    with pytest.raises(StoreMismatchError, match=r"differs in transient \(200 in the store, 300 now\)"):
        ZarrStore(path, _spec(transient=300))


def test_a_store_of_another_layout_is_refused_not_rewritten(tmp_path, monkeypatch):
    """A store written before impacts were counted per stop is another sweep: one line, left as it is."""
    from grazing.sweeps import run_sweep
    from grazing.sweeps import spec as spec_module

    monkeypatch.setattr(spec_module, "STORE_LAYOUT", 1)
    path = tmp_path / "old.zarr"
    run_sweep(_spec(), store=ZarrStore(path, _spec()), workers=1)
    before = sorted((p.relative_to(path), p.stat().st_mtime_ns) for p in path.rglob("*"))
    monkeypatch.setattr(spec_module, "STORE_LAYOUT", 2)
    with pytest.raises(StoreMismatchError, match=r"store_layout \(1 in the store, 2 now\)"):
        ZarrStore(path, _spec())
    assert sorted((p.relative_to(path), p.stat().st_mtime_ns) for p in path.rglob("*")) == before


def _sweep_cmd(out: Path) -> list[str]:
    # enough work per chunk (~0.1 s) that the kill lands mid-sweep
    args = "sweep --param eta --start 0.44 --stop 0.49 --num 60 --chunk-size 5 --workers 1"
    args += " --transient 3000 --periods 50 --no-adaptive --no-lyapunov --out"
    return [sys.executable, "-m", "grazing.cli", *args.split(), str(out)]


def test_resume_after_sigkill_computes_only_missing_chunks(tmp_path):
    import zarr

    out = tmp_path / "killed.zarr"
    proc = subprocess.Popen(_sweep_cmd(out), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 300  # (a loaded machine compiles slowly: the kill must land mid-sweep)
    done = 0
    while time.time() < deadline:
        time.sleep(0.01)
        try:
            done = int(np.sum(zarr.open_array(str(out / "chunk_done"), mode="r")[:]))
        except Exception:
            continue
        if done >= 3:
            break
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    flags = np.asarray(zarr.open_array(str(out / "chunk_done"), mode="r")[:])
    n_done = int(flags.sum())
    assert 3 <= n_done < flags.size, "the kill should land mid-sweep"
    chunk_files = sorted((out / "samples" / "c").rglob("*"))
    before = {p: p.stat().st_mtime_ns for p in chunk_files if p.is_file()}
    # re-run the same command: completes, without touching the finished chunks
    assert subprocess.run(_sweep_cmd(out), capture_output=True).returncode == 0
    for p, mtime in before.items():
        # samples/c/<chunk along the points>/<...>: a chunk that was not finished may be rewritten
        idx = int(p.relative_to(out / "samples" / "c").parts[0])
        if flags[idx]:
            assert p.stat().st_mtime_ns == mtime
    # and gives exactly the uninterrupted result
    ref_out = tmp_path / "ref.zarr"
    assert subprocess.run(_sweep_cmd(ref_out), capture_output=True).returncode == 0
    import xarray as xr

    a = xr.open_zarr(str(out), consolidated=False)
    b = xr.open_zarr(str(ref_out), consolidated=False)
    np.testing.assert_array_equal(a.samples.values, b.samples.values)
    np.testing.assert_array_equal(a.period.values, b.period.values)
    np.testing.assert_array_equal(a.lyapunov.values, b.lyapunov.values)
    assert a.attrs["grazing_version"] == grazing.__version__ if "grazing_version" in a.attrs else True
    assert "sweep --param eta" in a.attrs["command"]


def test_netcdf_export(tmp_path, capsys):
    out = tmp_path / "s.nc"
    argv = ["sweep", "--param", "eta", "--start", "0.40", "--stop", "0.42", "--num", "3", "--periods", "20",
            "--workers", "1", "--out", str(out), "--json"]  # fmt: skip
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    import xarray as xr

    ds = xr.open_dataset(out, engine="h5netcdf")
    assert ds.period.values.tolist() == res["period"] == [1, 1, 1]


# --------------------------------------------------------------------------
# Dask cluster on loopback


def test_dask_cluster_gives_identical_results():
    from grazing.sweeps import run_sweep

    spec = _spec()
    local = run_sweep(spec, workers=2)
    with loopback_client(2) as client:
        remote = run_sweep(spec, client=client)
        args = "sweep --param eta --start 0.44 --stop 0.46 --num 12 --chunk-size 4 --transient 200"
        args += f" --periods 30 --scheduler {client.scheduler.address} --json"
        cli_out = subprocess.run(
            [sys.executable, "-m", "grazing.cli", *args.split()], capture_output=True, text=True
        )
    np.testing.assert_array_equal(local.samples.values, remote.samples.values)
    np.testing.assert_array_equal(local.period.values, remote.period.values)
    assert cli_out.returncode == 0, cli_out.stderr
    res = json.loads(cli_out.stdout)
    assert res["period"] == local.period.values.tolist()
    np.testing.assert_array_equal(np.array(res["samples"]), local.samples.values[..., 0])


def test_chunk_is_a_pure_function():
    spec = _spec()
    a, b = run_chunk(spec, 1), run_chunk(spec, 1)
    np.testing.assert_array_equal(a.samples, b.samples)


# --------------------------------------------------------------------------
# CLI


def test_sweep_json_keys(capsys):
    argv = ["sweep", "--param", "theta-hat", "--start", "38", "--stop", "42", "--num", "3", "--eta", "0.447",
            "--periods", "20", "--workers", "1", "--json"]  # fmt: skip
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    for key in ("param", "values", "period", "impacts_per_period", "lyapunov", "samples"):
        assert key in res
    assert res["param"] == "theta-hat" and res["values"] == [38.0, 40.0, 42.0]
    assert len(res["samples"]) == 3 and len(res["samples"][0]) == 20


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--scheduler", "tcp://127.0.0.1:1"], "cannot connect to the Dask scheduler"),
        (["--out", "x.txt"], "--out must end in .zarr or .nc"),
        (["--r", "2"], "r = 2 is outside"),
        (["--method", "map", "--theta-hat", "70"], "no first grazing"),
    ],
)
def test_sweep_errors(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    base = ["sweep", "--param", "eta", "--start", "0.4", "--stop", "0.41", "--num", "2", "--periods", "5"]
    code = main([*base, *argv])
    err = capsys.readouterr().err
    assert code != 0 and message in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_sweep_chatter_tol_is_a_setting_of_the_spec():
    """issue 29: the sweep driver takes the spec's chatter_tol (it hard-coded the default)."""
    import dataclasses

    from grazing.core.options import CHATTER_TOL
    from grazing.models import bouncing_ball
    from grazing.sweeps.run import batch_key
    from grazing.sweeps.spec import sweep_spec

    settings = grazing.SweepSettings(transient=3, periods=10, lyapunov=False)
    spec = sweep_spec(bouncing_ball(amplitude=1.2), "amplitude", [1.2], settings=settings)
    assert spec.chatter_tol == CHATTER_TOL and "chatter_tol" not in spec.description()  # (stores kept)
    never = dataclasses.replace(spec, chatter_tol=0.0)  # chattering is never summed in closed form
    assert never.description()["chatter_tol"] == 0.0 and never.fingerprint() != spec.fingerprint()
    assert batch_key(never) != batch_key(spec)
    default, unsummed = run_chunk(spec, 0), run_chunk(never, 0)
    assert default.status.tolist() == unsummed.status.tolist() == [0]
    # The ball is thrown off the table and chatters back to rest on it, period after period: summed,
    # a chattering sequence counts as the impacts before its tail; unsummed, every impact of it.
    assert unsummed.impacts[0] > default.impacts[0] > 0


def test_a_memory_store_reads_its_chunks_not_written_as_not_computed():
    """The arrays are filled only when read: a chunk written keeps its values, the others read as before
    computing (NaN, -1, the status not computed), also after a chunk is written once they were read."""
    from grazing.sweeps.run import run_chunk
    from grazing.sweeps.status import NOT_COMPUTED
    from grazing.sweeps.store import MemoryStore

    spec = _spec()
    store = MemoryStore(spec)
    one = run_chunk(spec, 1)
    store.write(one)
    a = store.arrays
    sl, other = spec.chunk(1), spec.chunk(0)
    np.testing.assert_array_equal(a["samples"][sl], one.samples)
    assert np.isnan(a["samples"][other]).all() and np.isnan(a["lyapunov"][other]).all()
    assert (a["period"][other] == -1).all() and (a["impacts_by_stop"][other] == -1).all()
    assert (a["status"][other] == NOT_COMPUTED).all()
    zero = run_chunk(spec, 0)
    store.write(zero)
    np.testing.assert_array_equal(store.arrays["period"][other], zero.period)
    ds = store.dataset()
    assert ds.period.values.tolist() == [*zero.period, *one.period, *[-1] * (spec.n_points - sl.stop)]
