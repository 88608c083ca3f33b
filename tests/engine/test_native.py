"""The driver's machine code loaded without numba (:mod:`grazing.engine.native`).

Both entry points, the sweep's ``sweep_lanes`` and the scalar ``integrate``:
the sweeps of tests/engine/test_lanes.py run through the first and equal an
oracle over the second; here: each is numba's function bit for bit (slow:
numba compiles them anew, they are not in numba's cache), a sweep and a
simulation in a new process do not import numba, wrong arrays are refused
before any machine code runs, an error inside the code is reported, a
damaged cache file is built again, and a run whose tables were too short is
run again, the same.
"""

from __future__ import annotations

import ctypes
import math
import subprocess
import sys

import numpy as np
import pytest

from grazing.core.options import SweepSettings
from grazing.engine import codegen, interrupts, native, outputs
from grazing.engine.codegen import load_driver, taylor_order
from grazing.engine.records import Config, LaneJobs, LanePoints, LaneResults, LaneSettings
from grazing.models import bouncing_ball, impact_oscillator, pendulum
from grazing.sweeps import run
from grazing.sweeps.spec import sweep_spec

FIELDS = (
    "samples", "period", "impacts", "lyapunov", "transient_used", "x_final", "impacts_by_stop", "status",
)  # fmt: skip


@pytest.mark.slow
@pytest.mark.parametrize(
    ("make", "param", "values", "fresh"),
    [
        (lambda: pendulum("B", theta_hat=math.radians(40)), "eta", np.linspace(0.44, 0.47, 24), False),
        (lambda: bouncing_ball(amplitude=1.2), "amplitude", np.linspace(1.0, 1.6, 12), True),
    ],
    ids=["pendulum-continuation", "bouncing-ball-fresh"],
)
def test_native_entry_equals_numbas_function(make, param, values, fresh, monkeypatch) -> None:
    settings = SweepSettings(transient=60, periods=12, chunk_size=3, fresh=fresh)
    spec = sweep_spec(make(), param, values, settings=settings)
    chunks = list(range(spec.n_chunks))
    ours = run.run_chunks(spec, chunks)
    monkeypatch.setattr(run, "load_sweep_lanes", lambda: load_driver().sweep_lanes)
    numbas = run.run_chunks(spec, chunks)
    for a, b in zip(ours, numbas, strict=True):
        for field in FIELDS:
            assert np.array_equal(getattr(a, field), getattr(b, field), equal_nan=True), field
    assert np.isfinite(np.concatenate([r.samples for r in ours])).all()


NEW_PROCESS = {
    "sweep": (
        "import sys, numpy as np, grazing\n"
        "from grazing.sweeps.spec import sweep_spec\n"
        "from grazing.core.options import SweepSettings\n"
        "from grazing.sweeps.run import run_chunks\n"
        "spec = sweep_spec(grazing.models.pendulum('B'), 'eta', np.linspace(0.44, 0.45, 4),\n"
        "                  settings=SweepSettings(transient=20, periods=4, chunk_size=2))\n"
        "res = run_chunks(spec, [0, 1])\n"
        "assert np.isfinite(res[0].samples).all()\n"
    ),
    "simulation": (
        "import sys, math, grazing\n"
        "from grazing.models import pendulum\n"
        "sol = grazing.simulate(pendulum('B', theta_hat=math.radians(40)), periods=20)\n"
        "assert len(sol.samples) == 20\n"
    ),
}


@pytest.mark.parametrize("what", list(NEW_PROCESS))
def test_a_run_in_a_new_process_does_not_import_numba(what) -> None:
    native.load_sweep_lanes(), native.load_integrate()  # (the cache files exist)
    code = NEW_PROCESS[what] + "print('numba' in sys.modules)\n"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"


def sweep_arguments() -> list:
    """The arguments of ``sweep_lanes`` for one bouncing-ball point: its records, as lists."""
    model = bouncing_ball()
    kern = model.kernels(0, taylor_order(1e-10))
    n, periods = model.n_states, 3
    settings = LaneSettings(
        lanes=1, fresh=False, periodic=bool(model.periodic), transient=4, periods=periods, adaptive=False,
        adaptive_tol=1e-9, lyapunov=False, safety=1.5, chatter_tol=1e-9, zdm=False, zdm_a=1.0,
        zdm_e=np.zeros(n), zdm_window=0.0, stop=0,
    )  # fmt: skip
    work = LaneJobs(
        jobs=np.array([[0, 1]], dtype=np.int64), control=np.zeros(3, dtype=np.int64),
        x0=np.array([[0.5, 0.0]]), firsts=np.array([[0.0, 0.5, 0.0]]), first_vf=np.zeros(1, dtype=np.int64),
        x0_vf=np.zeros(1, dtype=np.int64),
    )  # fmt: skip
    points = LanePoints(
        pvs=model.param_vector.reshape(1, -1).copy(), Ts=np.array([float(model.period)]), sphase=np.zeros(1),
        tcarry=np.zeros(1), zdms=np.zeros(1),
    )  # fmt: skip
    out = LaneResults(
        samples=np.full((1, periods, n), np.nan), by_stop=np.zeros((1, model.n_stops), dtype=np.int64),
        lyap=np.zeros(1), used=np.zeros(1, dtype=np.int64), x=np.zeros((1, n)), t=np.zeros(1),
        status=np.full(1, -1, dtype=np.int64), vf=np.zeros(1, dtype=np.int64),
    )  # fmt: skip
    return [list(kern.table), list(settings), list(work), list(points), list(out)]


def call(sweep, args: list) -> None:
    sweep(*(tuple(record) for record in args))


def test_the_entry_point_computes_and_refuses_wrong_arrays() -> None:
    sweep = native.load_sweep_lanes()
    args = sweep_arguments()
    call(sweep, args)
    samples, status = args[4][0], args[4][6]
    assert np.isfinite(samples).all() and status[0] == 0
    samples_at, x0_at = (4, 0), (2, 2)
    wrong_arrays = (
        (samples_at, np.zeros((1, 2, 2))),  # shape
        (samples_at, np.zeros((1, 3, 2), dtype=np.float32)),  # dtype
        (samples_at, np.zeros((1, 3, 4))[:, :, ::2]),  # not contiguous
        (x0_at, np.zeros((1, 3))),  # x0 of the wrong size
        (x0_at, np.zeros((2, 2))),  # x0 not one per job
        ((2, 3), np.zeros((1, 2))),  # firsts without the time
        ((1, 12), np.zeros(3)),  # the discontinuity map's direction of the wrong size
    )
    for (record, field), bad in wrong_arrays:
        wrong = [list(r) for r in args]
        wrong[record][field] = bad
        with pytest.raises(TypeError, match="must be a C-contiguous"):
            call(sweep, wrong)
    read_only = [list(r) for r in args]
    read_only[4][2] = np.zeros(1)
    read_only[4][2].flags.writeable = False
    with pytest.raises(TypeError, match=r"LaneResults\.lyap must be writeable"):
        call(sweep, read_only)


def test_an_exception_in_the_machine_code_is_reported() -> None:
    from numba import njit, types

    loaded = native.load_object(native.object_file(njit(lambda n: 10 // n), (types.int64,), "toy"), "toy")
    assert loaded is not None
    address, params, _library = loaded
    assert params == ["i64"]
    entry = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_void_p)(address)
    assert entry(np.array([3], dtype=np.int64).ctypes.data) in native._RETURNED
    assert entry(np.array([0], dtype=np.int64).ctypes.data) not in native._RETURNED  # ZeroDivisionError


def test_a_damaged_cache_file_is_built_again(tmp_path, monkeypatch) -> None:
    native.load_sweep_lanes()  # (the cache file exists)
    key = native.cache_key()
    source = (codegen.cache_dir() / f"grazing_native_{key}.bin").read_bytes()
    built = []

    def build(entry=None) -> bytes:
        built.append(1)
        return source

    monkeypatch.setattr(native, "build", build)
    monkeypatch.setenv("GRAZING_CACHE_DIR", str(tmp_path))
    path = tmp_path / f"grazing_native_{key}.bin"
    path.write_bytes(b"not a header\n\x00\x01")
    native.load_sweep_lanes.cache_clear()
    try:
        sweep = native.load_sweep_lanes()
        args = sweep_arguments()
        call(sweep, args)
        assert np.isfinite(args[4][0]).all() and built == [1]
        assert path.read_bytes() == source
    finally:
        native.load_sweep_lanes.cache_clear()


def test_the_entry_point_takes_the_drivers_records() -> None:
    """The argument layout comes from the records: their fields, in order, are what the driver reads."""
    import inspect

    from grazing.engine.records import SWEEP_RECORDS

    assert len(inspect.signature(load_driver().sweep_lanes.py_func).parameters) == len(SWEEP_RECORDS)
    labels = [label for label, _kind, _spec in native._layout()]
    assert labels == [f"{r.__name__}.{name}" for r in SWEEP_RECORDS for name in r._fields]
    with pytest.raises(TypeError, match=f"{len(SWEEP_RECORDS)} arguments expected"):
        native.load_sweep_lanes()(1, 2)
    args = sweep_arguments()
    with pytest.raises(TypeError, match="a LaneSettings"):
        native.load_sweep_lanes()(tuple(args[0]), tuple(args[1][:-1]), *(tuple(r) for r in args[2:]))


def test_reference_counts_are_plain_adds_and_every_array_is_freed() -> None:
    """The machine code counts references without atomic instructions (native.plain_reference_counts),
    and still frees each array it allocates, once, when its count drops to zero."""
    from numba import njit, types
    from numba.core.runtime import _nrt_python, rtsys

    @njit
    def total(x, n):  # (not inlined: it is given its arrays, whose counts go up and down)
        s = 0.0
        for i in range(n):
            s += x[i]
        return s

    def toy(n):
        a = np.arange(n) * 1.0
        b = np.ones(n)
        parts = (a, b, a[1:])
        s = 0.0
        for k in range(3):
            s += total(parts[k], parts[k].size)
        return int(s)

    dispatcher = njit(toy)
    dispatcher.compile((types.int64,))
    ir = native.plain_reference_counts(dispatcher.inspect_llvm((types.int64,)))
    for name in ("NRT_incref", "NRT_decref"):
        body = ir[ir.index(f"define linkonce_odr void @{name}") :]
        body = body[: body.index("\n}\n")]
        assert "atomic" not in body and "call void @NRT_MemInfo_call_dtor" in ir
    assert native.plain_reference_counts("no such definitions") == "no such definitions"

    loaded = native.load_object(native.object_file(njit(toy), (types.int64,), "toy"), "toy")
    assert loaded is not None
    address, _params, _library = loaded
    entry = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_void_p)(address)
    enabled = _nrt_python.memsys_stats_enabled()
    _nrt_python.memsys_enable_stats()
    try:
        before = rtsys.get_allocation_stats()
        for _ in range(100):
            assert entry(np.array([10], dtype=np.int64).ctypes.data) in native._RETURNED
        after = rtsys.get_allocation_stats()
    finally:
        if not enabled:
            _nrt_python.memsys_disable_stats()
    allocated, freed = after.alloc - before.alloc, after.free - before.free
    assert allocated >= 200 and freed == allocated  # (two arrays per call, every one freed)


# -- the scalar integrator's entry point (integrate)


def run_arguments(model, x0, periods=3, keep=3, variational=False, impacts="all", trajectory=0) -> list:
    """The arguments of ``integrate`` for a run of ``model`` from ``x0`` (by a Runner), its output last."""
    from grazing.engine.runner import RECORD_IMPACTS, Runner

    r = Runner(model, np.asarray(x0, dtype=float), variational=variational)
    call = dict(
        max_steps=100_000, n_samples=periods, ks=r.ks, ss=float(r.ss), n_keep=keep, lyapunov=variational,
        traj_dt=r.T / trajectory if trajectory else 0.0, track_min=True,
        record_impacts=RECORD_IMPACTS[impacts], touch_start=False, touch_end=False,
    )  # fmt: skip
    seen = int(interrupts.SIGINTS[0])  # (SIGINTs counted by earlier tests in this process)
    cfg = Config(*(call[name] for name in Config._fields[: len(call)]), *r._static, interrupts.SIGINTS, seen)
    rows = outputs.TableRows.guess(cfg)
    out = outputs.allocate(model.n_states, r.V.shape[1], model.n_stops, keep, rows)
    return [(r.x, r.V, r.k, r.s, r.mode, r.vf), r.pv, cfg, r.kern.table, out]


RUNS = [
    pytest.param(
        lambda: bouncing_ball(amplitude=1.2),
        {"x0": [0.5, 0.0], "trajectory": 40},
        id="bouncing-ball-trajectory",
    ),
    pytest.param(
        lambda: pendulum("B", theta_hat=math.radians(40)),
        {"x0": [0.1, 0.0], "periods": 30, "variational": True},
        id="pendulum-jacobian",
    ),
    pytest.param(
        lambda: impact_oscillator(),
        {"x0": [0.0, 0.0], "periods": 20, "keep": 5, "impacts": "sampled"},
        id="oscillator",
    ),
]


@pytest.mark.slow
@pytest.mark.parametrize(("make", "options"), RUNS)
def test_native_integrate_equals_numbas_function(make, options) -> None:
    ours = run_arguments(make(), **options)
    native.load_integrate()(*ours)
    theirs = run_arguments(make(), **options)
    load_driver().integrate(*theirs)
    a, b = (outputs.result(out, outputs.Totals.of(out)) for out in (ours[4], theirs[4]))
    for field, x, y in zip(a._fields, a, b, strict=True):
        assert np.asarray(x).tobytes() == np.asarray(y).tobytes(), field  # (what the run wrote, bit for bit)


@pytest.mark.parametrize(("make", "options"), RUNS)
def test_a_run_whose_tables_were_too_short_runs_again_the_same(make, options) -> None:
    """Tables of one row: the run counts the rows it needs, runs again with them, and equals a roomy run."""
    arguments = run_arguments(make(), **options)
    cfg = arguments[2]
    integrate = native.load_integrate()

    def call(out):
        integrate(*arguments[:4], out)

    n, ncol, nstops = arguments[0][0].size, arguments[0][1].shape[1], arguments[3][3]
    short, need = outputs.run(call, n, ncol, nstops, cfg, outputs.TableRows(1, 1, 1))
    roomy, need_roomy = outputs.run(call, n, ncol, nstops, cfg, outputs.TableRows(10_000, 10_000, 10_000))
    assert need == need_roomy and short.status == 0
    assert max(need) > 1  # (the case needs a second run)
    for field, a, b in zip(short._fields, short, roomy, strict=True):
        assert np.asarray(a).tobytes() == np.asarray(b).tobytes(), field
    assert short.impacts.shape[0] == need.impacts and short.trajectory.shape[0] == need.trajectory


def test_the_integrate_entry_refuses_wrong_arrays() -> None:
    arguments = run_arguments(bouncing_ball(), [0.5, 0.0])
    native.load_integrate()(*arguments)
    assert outputs.Totals.of(arguments[4]).status == 0
    start_x, out_V, out_samples, impacts = (0, 0), (4, 2), (4, 3), (4, 4)
    wrong_arrays = (
        (start_x, np.zeros(3)),  # the state of the wrong size
        (start_x, np.zeros((2, 1))),  # dimensions
        (out_V, np.zeros((2, 2), dtype=np.float32)),  # dtype
        (out_samples, np.zeros((3, 4))[:, ::2]),  # not contiguous
        (impacts, np.zeros((4, 2))),  # a row of impacts without its time and speed
        ((4, 0), np.zeros(1)),  # the totals as plain numbers
    )
    for (record, field), bad in wrong_arrays:
        wrong = [list(r) if isinstance(r, tuple) else r for r in arguments]
        wrong[record][field] = bad
        with pytest.raises(TypeError, match="must be a C-contiguous"):
            native.load_integrate()(*(tuple(r) if isinstance(r, list) else r for r in wrong))
    read_only = [list(r) if isinstance(r, tuple) else r for r in arguments]
    read_only[4][1] = np.zeros(2)
    read_only[4][1].flags.writeable = False
    with pytest.raises(TypeError, match=r"RunOutput\.x must be writeable"):
        native.load_integrate()(*(tuple(r) if isinstance(r, list) else r for r in read_only))
    with pytest.raises(TypeError, match="5 arguments expected"):
        native.load_integrate()(*arguments[:4])
    with pytest.raises(TypeError, match=rf"a Config \({len(Config._fields)} fields\) expected"):
        native.load_integrate()(arguments[0], arguments[1], tuple(arguments[2])[:-1], *arguments[3:])


def test_numpys_array_objects_hold_their_fields_where_the_entry_reads_them() -> None:
    assert native.numpy_layout_holds()
