"""Failed sweep points: each says why, in the Dataset, the stores, NetCDF, the JSON and the summaries.

The failures are chosen so that their reasons follow from the equations:

* the pendulum with forcing amplitude alpha = 1e300: its acceleration alpha cos(theta) sin(tau)
  is ~1e300, and the velocity overflows within a few steps ("non-finite state");
* the pendulum at eta = 1e-6: its natural frequency 1/(2 eta) = 5e5 per unit tau is 5e5 turns
  per forcing period 2 pi, far more than the 20000 steps per period the driver allows
  ("step limit");
* a clock model (below) whose guard c + cos(w t) depends on time only: for |c| < 1 it reaches
  zero and its reset does not move it away, so events repeat at one instant ("accumulating
  impacts"); for c > 1 it never reaches zero.
"""

from __future__ import annotations

import functools
import json
import math
import runpy
from pathlib import Path

import numpy as np
import pytest

from grazing.cli import main
from grazing.cli.common import json_text
from grazing.core.options import SweepSettings
from grazing.core.solution import Status
from grazing.models import pendulum
from grazing.sweeps import parameter_map, run_sweep, sweep
from grazing.sweeps.run import run_chunk
from grazing.sweeps.spec import sweep_spec
from grazing.sweeps.status import failure_text
from grazing.sweeps.store import ZarrStore
from tests.sweeps.dask_cluster import loopback_client

OK, STEPS, NONFINITE, ZENO = (int(s) for s in (Status.OK, Status.STEP_LIMIT, Status.NONFINITE, Status.ZENO))
QUICK = {"transient": 20, "periods": 10, "workers": 1}
SMALL = functools.partial(SweepSettings, transient=20, periods=10)
WORDS = {STEPS: "step_limit", NONFINITE: "non_finite_state", ZENO: "accumulating_impacts"}

CLOCK = """
import sympy as sp
from grazing import HybridModel, Parameter

q_1, P, tau, omega_f, c_0 = sp.symbols("q_1 P tau omega_f c_0")
model = HybridModel(
    "clock-stop",
    states=[q_1, P],
    time=tau,
    parameters=[Parameter("omega_f", 1.0, lower=0, lower_open=True), Parameter("c_0", 1.5)],
    vector_field=[P, -q_1],
    guard=c_0 + sp.cos(omega_f * tau),
    reset=[q_1, -P],
    period=2 * sp.pi / omega_f,
)
"""
"""A linear oscillator q'' = -q with a stop that is a clock.  Unstopped (c_0 > 1) its period 2 pi
equals the sampling period 2 pi / omega_f at omega_f = 1: every point has period 1."""


def strict_json(text: str) -> dict:
    """``text`` parsed as strict JSON: NaN, Infinity and -Infinity are refused."""

    def refuse(constant: str) -> None:
        raise ValueError(f"not strict JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


@pytest.fixture(scope="module")
def clock_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("models") / "clock_model.py"
    path.write_text(CLOCK)
    return path


@pytest.fixture(scope="module")
def clock(clock_file):
    return runpy.run_path(str(clock_file))["model"]


CASES = {
    "huge forcing": (lambda clock: pendulum("B"), "alpha", [0.2254, 1e300], [OK, NONFINITE]),
    "tiny eta": (lambda clock: pendulum("B"), "eta", [1e-6, 0.44], [STEPS, OK]),
    "guard of time only": (lambda clock: clock, "c_0", [0.5, 1.5], [ZENO, OK]),
}


@pytest.mark.parametrize("case", list(CASES))
def test_each_failed_point_says_why_and_looks_like_no_result(case, clock):
    make, param, values, expected = CASES[case]
    ds = sweep(make(clock), param, values, **QUICK)
    assert ds.status.values.tolist() == expected
    failed = ds.status.values != OK
    assert (ds.period.values[failed] == -1).all() and (ds.period.values[~failed] >= 0).all()
    assert np.isnan(ds.samples.values[failed]).all() and np.isfinite(ds.samples.values[~failed]).all()
    assert np.isnan(ds.x_final.values[failed]).all() and np.isnan(ds.lyapunov.values[failed]).all()
    assert np.isnan(ds.impacts_per_period.values[failed]).all()
    for name in ("impacts", "transient_used"):
        assert (ds[name].values[failed] == -1).all(), name
    meanings = dict(zip(ds.status.attrs["flag_values"].tolist(), ds.status.attrs["flag_meanings"].split()))
    failure = next(code for code in expected if code != OK)
    assert meanings[failure] == WORDS[failure] and meanings[OK] == "ok"


def test_the_unstopped_clock_is_period_one(clock):
    """The successful points are results: the free oscillator at omega_f = 1 repeats every period."""
    ds = sweep(clock, "c_0", [1.5, 2.0, 3.0], **QUICK)
    assert ds.status.values.tolist() == [OK] * 3 and ds.period.values.tolist() == [1] * 3
    assert (ds.impacts.values == 0).all()


def test_a_map_gives_the_same_status():
    ds = parameter_map(pendulum("B"), "eta", [0.44, 0.45], "alpha", [0.2254, 1e300], **QUICK)
    assert ds.status.dims == ("alpha", "eta")
    assert ds.status.values.tolist() == [[OK, OK], [NONFINITE, NONFINITE]]
    assert (ds.period.values[1] == -1).all()


def test_the_status_survives_the_zarr_store_and_its_resume(tmp_path):
    import xarray as xr

    spec = sweep_spec(pendulum("B"), "alpha", [0.2, 0.2254, 1e299, 1e300], settings=SMALL(chunk_size=1))
    path = tmp_path / "s.zarr"
    with ZarrStore(path, spec) as store:  # a first run that stopped after chunks 0 and 2
        for i in (0, 2):
            store.write(run_chunk(spec, i))
    raw = xr.open_zarr(str(path), consolidated=False)
    assert raw.status.values.tolist() == [OK, -1, NONFINITE, -1]  # -1: not computed yet
    assert "not_computed" in raw.status.attrs["flag_meanings"]
    seen = []
    ds = run_sweep(spec, store=path, workers=1, progress=lambda done, total: seen.append((done, total)))
    assert seen[0] == (2, 4)  # the resumed run computes the two missing chunks only
    assert ds.status.values.tolist() == [OK, OK, NONFINITE, NONFINITE]
    assert ds.period.values.tolist()[2:] == [-1, -1]
    assert ds.status.values.tolist() == run_sweep(spec, workers=1).status.values.tolist()
    assert ds.status.attrs["flag_meanings"] == raw.status.attrs["flag_meanings"]


def run_cli(argv: list[str], capsys) -> str:
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


FAILING_SWEEP = ["sweep", "--param", "alpha", "--start", "0.2254", "--stop", "1e300", "--num", "2",
                 "--eta", "0.4", "--transient", "200", "--periods", "10", "--workers", "1"]  # fmt: skip
"""At eta = 0.4 (below the grazing at 0.445) the first point is the nonimpacting period-1 orbit."""
FAILING_MAP = ["map", "--param1", "eta", "--start1", "0.4", "--stop1", "0.42", "--num1", "2",
               "--param2", "alpha", "--start2", "0.2254", "--stop2", "1e300", "--num2", "2",
               "--transient", "200", "--periods", "10", "--workers", "1"]  # fmt: skip


def test_netcdf_keeps_the_status(tmp_path, capsys):
    import xarray as xr

    out = tmp_path / "s.nc"
    run_cli([*FAILING_SWEEP, "--out", str(out)], capsys)
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.status.values.tolist() == [OK, NONFINITE]
        meanings = dict(
            zip(ds.status.attrs["flag_values"].tolist(), ds.status.attrs["flag_meanings"].split())
        )
        assert meanings[NONFINITE] == "non_finite_state" and meanings[OK] == "ok"


def test_sweep_json_is_strict_with_a_status_per_point(capsys, clock_file):
    res = strict_json(run_cli([*FAILING_SWEEP, "--json"], capsys))
    assert res["status"] == ["ok", "non-finite state"]
    assert res["period"][1] == -1 and res["period"][0] >= 1
    assert res["samples"][1] == [None] * 10 and None not in res["samples"][0]
    assert res["lyapunov"][1] is None and res["impacts_per_period"][1] is None
    keys = [
        "param",
        "values",
        "impacts_per_period",
        "lyapunov",
        "transient_used",
        "impacts_per_period_by_stop",
    ]
    keys += [
        "direction",
        "fresh",
        "transient",
        "periods",
        "chunk_size",
        "elapsed_s",
        "out",
        "method",
        "grazing",
    ]
    for key in [*keys, "params"]:
        assert key in res, key
    argv = ["sweep", "--model", f"{clock_file}:model", "--param", "c_0", "--start", "-0.5", "--stop", "2",
            "--num", "6", "--transient", "20", "--periods", "10", "--workers", "1", "--json"]  # fmt: skip
    res = strict_json(run_cli(argv, capsys))  # (c_0 = -0.5, 0, 0.5, 1, 1.5, 2: |c_0| <= 1 reaches the stop)
    assert res["status"] == ["accumulating impacts"] * 4 + ["ok"] * 2
    assert res["period"] == [-1] * 4 + [1, 1]


def test_map_json_is_strict_with_a_status_per_cell(capsys):
    res = strict_json(run_cli([*FAILING_MAP, "--json"], capsys))
    assert res["status"] == [["ok", "ok"], ["non-finite state", "non-finite state"]]
    assert res["period"][1] == [-1, -1] and res["lyapunov"][1] == [None, None]
    for key in ("param1", "values1", "param2", "values2", "period", "impacts_per_period", "elapsed_s", "out"):
        assert key in res, key


def test_summaries_count_failed_points_by_reason(capsys, clock_file):
    out = run_cli(FAILING_SWEEP, capsys)
    assert "periodic points: 1, no period <= 64: 0, failed: 1 (non-finite state: 1)" in out
    assert "  failed, non-finite state: 1 points, alpha in [1e+300, 1e+300]" in out
    out = run_cli(FAILING_MAP, capsys)
    assert "periodic cells 2, none 0, failed: 2 (non-finite state: 2)" in out
    assert "  failed, non-finite state: 2 cells, eta in [0.4, 0.42], alpha in [1e+300, 1e+300]" in out
    argv = ["sweep", "--param", "eta", "--start", "1e-6", "--stop", "0.44", "--num", "2", "--transient", "20",
            "--periods", "10", "--workers", "1"]  # fmt: skip
    assert "no period <= 64: 0, failed: 1 (step limit: 1)" in run_cli(argv, capsys)
    argv = ["sweep", "--model", f"{clock_file}:model", "--param", "c_0", "--start", "-0.5", "--stop", "2",
            "--num", "6", "--transient", "20", "--periods", "10", "--workers", "1"]  # fmt: skip
    out = run_cli(argv, capsys)
    assert "periodic points: 2, no period <= 64: 0, failed: 4 (accumulating impacts: 4)" in out
    assert "  failed, accumulating impacts: 4 points, c_0 in [-0.5, 1]" in out


def test_a_summary_without_failures_says_so(capsys):
    argv = ["sweep", "--param", "eta", "--start", "0.40", "--stop", "0.42", "--num", "3", "--periods", "20",
            "--workers", "1"]  # fmt: skip
    assert "periodic points: 3, no period <= 64: 0, failed: 0\n" in run_cli(argv, capsys)


def test_failure_text_counts_most_frequent_first():
    status = np.array([OK, STEPS, NONFINITE, NONFINITE, ZENO, OK, NONFINITE])
    assert failure_text(status) == "failed: 5 (non-finite state: 3, step limit: 1, accumulating impacts: 1)"


def test_the_dask_path_gives_the_same_status():
    spec = sweep_spec(pendulum("B"), "alpha", [0.2, 1e300, 0.2254, 1e299], settings=SMALL(chunk_size=2))
    local = run_sweep(spec, workers=1)
    with loopback_client(1) as client:
        remote = run_sweep(spec, client=client)
    assert local.status.values.tolist() == [OK, OK, NONFINITE, NONFINITE]
    assert remote.status.values.tolist() == local.status.values.tolist()
    np.testing.assert_array_equal(remote.samples.values, local.samples.values)


# --------------------------------------------------------------------------
# The JSON writer every command's --json goes through


def test_json_text_writes_null_for_every_non_finite_number():
    nan, inf = float("nan"), float("inf")
    obj = {
        "float": nan, "nested": {"list": [1.5, inf, (-inf, 2)]},
        "array": np.array([[0.0, np.nan], [np.inf, 1.0]]),
        "ints": np.array([1, 2]), "scalar": np.float64(-np.inf), "float32": np.float32(np.nan),
        "zero-d": np.array(np.nan), "objects": np.array([1.0, None, nan], dtype=object), "text": "NaN",
    }  # fmt: skip
    back = strict_json(json_text(obj))
    assert back == {
        "float": None, "nested": {"list": [1.5, None, [None, 2]]}, "array": [[0.0, None], [None, 1.0]],
        "ints": [1, 2], "scalar": None, "float32": None, "zero-d": None, "objects": [1.0, None, None],
        "text": "NaN",
    }  # fmt: skip
    finite = {"a": np.linspace(0, 1, 3), "b": [math.pi], "c": np.int64(3)}
    text = json_text(finite)
    assert strict_json(text) == {"a": [0.0, 0.5, 1.0], "b": [math.pi], "c": 3}  # (every float exactly)
    assert text == json.dumps({"a": [0.0, 0.5, 1.0], "b": [math.pi], "c": 3}, separators=(",", ":"))
    huge = {"n": 2**70, "x": [float("nan")]}  # (beyond orjson's integers: through json, still strict)
    assert strict_json(json_text(huge)) == {"n": 2**70, "x": [None]}
