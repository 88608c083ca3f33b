"""Code generation: the compiled functions of a hybrid model, assembled, cached and loaded.

For each model (and each number of parameter-sensitivity directions and
Taylor order) the model's functions are generated as straight-line Python:
Taylor-coefficient kernels for free flight, free flight with variational
equations, and sticking; the vector field, guards, resets and their
Jacobians, one per stop, and dispatchers over the stops.
:mod:`grazing.engine.llvmgen` translates them to LLVM IR and compiles them to
an object file (under a second), which is cached on disk by a hash of the
model and of the generator; loading it takes milliseconds.  The integration
driver (:mod:`grazing.engine.driver`) is model-independent: numba compiles it
once per machine and it calls the model's functions through their addresses
(:mod:`grazing.engine.abi`).

The cache directory is ``$GRAZING_CACHE_DIR`` if set, else
``$XDG_CACHE_HOME/grazing`` (``~/.cache/grazing``); it is made if missing
(``GRAZING_CACHE_DIR``'s folder must exist: only the last level is made).  A
``GRAZING_CACHE_DIR`` that cannot be used (not a folder, not writable, in a
missing folder) is an error of one line: you chose it.  Where the default folder cannot be used (a
read-only home), the kernels are cached in a private folder of the system's
temporary folder instead, and one line on stderr says so.  Cache files are
written all at once, after the compilation succeeded: a failed compilation or
a full disk leaves nothing in the cache (a full disk is one
:class:`~grazing.errors.WriteError`).
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import json
import math
import os
import sys
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from grazing.atomic import write_bytes_atomic
from grazing.core.model import set_kernel_loader
from grazing.core.options import MACHINE_EPSILON
from grazing.core.symbolic import SymbolicSystem
from grazing.engine import driver, outputs
from grazing.engine.abi import LANE_SLOTS, SLOTS
from grazing.engine.interrupts import interruptibly
from grazing.errors import WriteError

if TYPE_CHECKING:  # pragma: no cover
    import sympy as sp

# Bump when the generated code changes meaning without its text changing.
_CODEGEN_VERSION = "4"


def taylor_order(tol: float) -> int:
    """Order of the Taylor method for a tolerance (Jorba & Zou): ``ceil(-ln(tol)/2 + 1)``.

    Examples
    --------
    >>> taylor_order(2.220446049250313e-16)
    20
    """
    return int(min(60, max(6, math.ceil(-math.log(tol) / 2 + 1))))


DEFAULT_ORDER = taylor_order(MACHINE_EPSILON)
"""Order of the kernels for the default tolerance (machine epsilon): 20."""


def _scalar_function(
    name: str,
    sys_: SymbolicSystem,
    assigns: Sequence[tuple[str, sp.Expr]],
    returns: sp.Expr | None = None,
    extra_args: str = "",
) -> str:
    """Source of ``name(x, s, pv{extra_args})`` with CSE'd assignments (for :mod:`.llvmgen`)."""
    import sympy as sp

    from grazing.engine.taylor import ScalarPrinter

    names: dict[sp.Symbol, str] = {x: f"x[{i}]" for i, x in enumerate(sys_.states)}
    names[sys_.time] = "s"
    names.update({p: f"pv[{i}]" for i, p in enumerate(sys_.params)})
    exprs = [e for _, e in assigns] + ([returns] if returns is not None else [])
    repl, reduced = sp.cse([sp.sympify(e) for e in exprs], symbols=sp.numbered_symbols("t_"))
    for sym, _ in repl:
        names[sym] = str(sym)
    pr = ScalarPrinter(names)
    lines = [f"def {name}(x, s, pv{extra_args}):"]
    for sym, e in repl:
        lines.append(f"    {sym} = {pr.doprint(e)}")
    for (target, _), e in zip(assigns, reduced):
        lines.append(f"    {target} = {pr.doprint(e)}")
    if returns is not None:
        lines.append(f"    return {pr.doprint(reduced[-1])}")
    elif not assigns:
        lines.append("    return 0.0")
    return "\n".join(lines) + "\n"


def direction_columns(k: int) -> int:
    """Sensitivity columns of the kernel module that serves ``k`` parameter sensitivities.

    Sensitivities are *directions* in parameter space given at run time, so one
    module with two columns serves every request for one or two parameters
    (continuation in any parameter, the grazing curve, the normal form's
    unfolding): no new compilation for a new parameter.

    Examples
    --------
    >>> [direction_columns(k) for k in (0, 1, 2, 5)]
    [0, 2, 2, 5]
    """
    return 0 if k == 0 else max(2, int(k))


def _stop_functions(
    on: SymbolicSystem, ond: SymbolicSystem, j: int, along: Callable[..., Any], directions: int
) -> list[str]:
    """The scalar functions of stop ``j`` (guard, reset, their derivatives, contact), named ``*_s{j}``.

    ``on`` is the system seen from the stop, ``ond`` the same with the
    sensitivity directions among its parameters.
    """
    import sympy as sp

    n = len(on.states)
    gx = on.gradient(on.guard)
    gr = on.gradient(on.normal_rate)
    g = on.reset
    gjac = [(f"Gx[{i}, {k}]", sp.diff(gi, x)) for i, gi in enumerate(g) for k, x in enumerate(on.states)]
    gjac += [(f"Gt[{i}]", sp.diff(gi, on.time)) for i, gi in enumerate(g)]
    gjac += [(f"Gp[{i}, {c}]", along(c, gi)) for i, gi in enumerate(g) for c in range(directions)]
    e = on.contact_direction if on.contact_direction is not None else tuple(sp.Integer(0) for _ in range(n))
    return [
        _scalar_function(f"guard_s{j}", on, [], returns=on.guard),
        _scalar_function(
            f"guard_grad_s{j}",
            on,
            [(f"gx[{i}]", ei) for i, ei in enumerate(gx)],
            returns=sp.diff(on.guard, on.time),
            extra_args=", gx",
        ),
        _scalar_function(
            f"guard_pgrad_s{j}",
            ond,
            [(f"hp[{c}]", along(c, on.guard)) for c in range(directions)],
            extra_args=", hp",
        ),
        _scalar_function(
            f"reset_s{j}", on, list(zip([f"out[{i}]" for i in range(n)], g)), extra_args=", out"
        ),
        _scalar_function(f"reset_jac_s{j}", ond, gjac, extra_args=", Gx, Gt, Gp"),
        _scalar_function(f"normal_rate_s{j}", on, [], returns=on.normal_rate),
        _scalar_function(f"normal_accel_s{j}", on, [], returns=on.normal_accel),
        _scalar_function(
            f"normal_rate_grad_s{j}", on, [(f"gr[{i}]", ei) for i, ei in enumerate(gr)], extra_args=", gr"
        ),
        _scalar_function(
            f"contact_dir_s{j}", on, list(zip([f"e[{i}]" for i in range(n)], e)), extra_args=", e"
        ),
    ]


@dataclass(frozen=True)
class ModelSource:
    """The generated functions of a model, and what their compilation and the driver need to know.

    Attributes
    ----------
    text
        Python definitions of every function (straight-line code).
    columns
        For each function, the number of columns of its 2-D array arguments.
    dispatch
        For each per-stop function of :data:`grazing.engine.abi.SLOTS`, the
        definitions it picks from by the stop index.
    sizes
        ``nx``, ``nsens``, ``nparams``, ``nstops``, ``order`` and ``sticks``
        (per stop: it has a sticking mode); with several modes also ``nmodes``,
        ``rows`` (per mode, the transition of each of its event rows, -1 for
        padding), ``targets``, ``resets`` and ``back`` (per transition: the
        switch back whose guard is 0 right after it, -1 none) and
        ``slide_entry`` (per transition: the virtual transition into a sliding
        pseudo-mode that replaces its crossing where the far side pushes back,
        -1 none); the transitions are the real ones, then four virtual ones per
        sliding pseudo-mode (:meth:`~grazing.core.symbolic.SymbolicSystem.sliding_modes`).
    """

    text: str
    columns: dict[str, dict[str, int]]
    dispatch: dict[str, list[str]]
    sizes: dict[str, Any]


def generate_source(system: SymbolicSystem, directions: int = 0, order: int = DEFAULT_ORDER) -> ModelSource:
    """The functions of ``system`` with Taylor polynomials of degree ``order``.

    ``directions`` extra columns of the variational matrix hold derivatives
    along directions ``D[c]`` in parameter space, read at run time after the
    parameter values: the functions' parameter vector is ``(p, D.ravel())``.
    """
    import dataclasses

    import sympy as sp

    from grazing.engine.taylor import taylor_kernel

    sys_ = system.canonical()
    n = len(sys_.states)
    nstops = len(sys_.stops)
    m = len(sys_.params)
    dsyms = [[sp.Dummy(f"d{c}_{j}") for j in range(m)] for c in range(directions)]
    sysd = dataclasses.replace(sys_, params=tuple(sys_.params) + tuple(d for row in dsyms for d in row))

    def along(c: int, expr: sp.Expr) -> sp.Expr:
        """The derivative of ``expr`` along the direction ``D[c]``."""
        return sp.Add(*[dsyms[c][j] * sp.diff(expr, p) for j, p in enumerate(sys_.params)])

    ncol = n + directions
    vsyms = tuple(sp.Dummy(f"v{i}") for i in range(n * ncol))
    vmat = sp.Matrix(n, ncol, vsyms)

    def flow_kernels(suffix: str, f: Sequence[sp.Expr], guards: Sequence[sp.Expr]) -> list[Any]:
        """Free flight along ``f``, without and with the variational equations, watching ``guards``."""
        free = taylor_kernel(f"tc_free{suffix}", sys_.states, sys_.time, sys_.params, f, guards, order)
        # Variational equations: V' = f_x V (+ f_p D[c] on the direction columns).
        jac = sp.Matrix([[sp.diff(fi, x) for x in sys_.states] for fi in f])
        vrhs = jac * vmat
        for c in range(directions):
            for i in range(n):
                vrhs[i, n + c] += along(c, f[i])
        var = taylor_kernel(
            f"tc_var{suffix}",
            tuple(sys_.states) + tuple(vsyms),
            sys_.time,
            sysd.params,
            tuple(f) + tuple(vrhs),
            guards,
            order,
        )
        return [free, var]

    guards = [stop.guard for stop in sys_.stops]  # the event rows of free flight, one per stop
    nmodes = max(1, len(sys_.modes))
    if nmodes == 1:
        f = sys_.vector_field
        kernels = flow_kernels("", f, guards)
        sticky = [j for j, stop in enumerate(sys_.stops) if stop.contact_direction is not None]
    else:  # per mode: its field, its outgoing transitions' guards padded to as many rows as the most
        rows = [[j for j in range(nstops) if sys_.sources[j] == k] for k in range(nmodes)]
        sliding = sys_.sliding_modes()
        fields = [mode.vector_field for mode in sys_.modes]
        row_exprs = [[guards[j] for j in rows[k]] for k in range(nmodes)]
        for sl in sliding:  # a pseudo-mode: Filippov's field, its exits, then both sides' other transitions
            others = [
                j
                for j in range(nstops)
                if sys_.sources[j] in (sl.positive, sl.negative) and j not in (sl.down, sl.up)
            ]
            rows.append([sl.base, sl.base + 1, *others])
            fields.append(sys_.filippov_field(sl.surface))
            row_exprs.append([*sys_.exit_rows(sl.surface), *(guards[j] for j in others)])
        nmodes += len(sliding)
        width = max(len(r) for r in rows)
        kernels = []
        for k in range(nmodes):
            pad = [sp.Integer(1)] * (width - len(rows[k]))
            kernels += flow_kernels(f"_m{k}", fields[k], row_exprs[k] + pad)
        f = sys_.vector_field
        sticky = [  # a mode's own impact stop (a reset back to its mode) with a contact direction
            j
            for j, stop in enumerate(sys_.stops)
            if stop.contact_direction is not None and sys_.resets[j] and sys_.targets[j] == sys_.sources[j]
        ]
    # Sticking on stop j: the event rows are those of its mode (every stop's guard, for one mode), the
    # contact force in stop j's row (sticking_field and the force are those of j's source mode: at_stop).
    for j in sticky:
        on = sys_.at_stop(j)
        if nmodes == 1:
            stick_rows = [on.normal_accel if i == j else g for i, g in enumerate(guards)]
        else:
            mode_rows = rows[sys_.sources[j]]
            stick_rows = [on.normal_accel if i == j else guards[i] for i in mode_rows]
            stick_rows += [sp.Integer(1)] * (width - len(mode_rows))
        kernels.append(
            taylor_kernel(
                f"tc_stick_s{j}", sys_.states, sys_.time, sys_.params, on.sticking_field(), stick_rows, order
            )
        )
    if not sticky:
        kernels.append(
            taylor_kernel("tc_stick_s0", sys_.states, sys_.time, sys_.params, f, [sp.Integer(1)], order)
        )
    parts = [k.source for k in kernels]
    columns: dict[str, dict[str, int]] = {k.name: {"X": order + 1, "O": order + 1} for k in kernels}
    if nmodes == 1:
        parts.append(
            _scalar_function("rhs", sys_, [(f"out[{i}]", e) for i, e in enumerate(f)], extra_args=", out")
        )
    for k, field in enumerate(fields if nmodes > 1 else ()):
        assigns = [(f"out[{i}]", e) for i, e in enumerate(field)]
        parts.append(_scalar_function(f"rhs_m{k}", sys_, assigns, extra_args=", out"))
    every = list(range(nstops))
    for j in every:
        parts.extend(_stop_functions(sys_.at_stop(j), sysd.at_stop(j), j, along, directions))
        columns[f"reset_jac_s{j}"] = {"Gx": n, "Gp": max(directions, 1)}
    dispatch = {
        name: [f"{name}_s{j}" for j in every]
        for name in (
            "guard", "guard_grad", "guard_pgrad", "reset", "reset_jac", "normal_rate", "normal_accel",
            "normal_rate_grad", "contact_dir",
        )
    }  # fmt: skip
    # (by the stop's index: the switch's cases are the list's positions, its default the last entry)
    dispatch["tc_stick"] = (
        [f"tc_stick_s{j if j in sticky else sticky[0]}" for j in every] if sticky else ["tc_stick_s0"]
    )
    if nmodes > 1:  # the flow's functions by the active mode (the driver's last argument)
        for name in ("tc_free", "tc_var", "rhs"):
            dispatch[name] = [f"{name}_m{k}" for k in range(nmodes)]
    # dT/dp for every parameter: a sample "one period later" moves when the period does.
    period = sp.Integer(0) if sys_.period is None else sys_.period
    parts.append(
        _scalar_function(
            "period_grad", sys_, [(f"tp[{i}]", sp.diff(period, p)) for i, p in enumerate(sys_.params)],
            extra_args=", tp",
        )
    )  # fmt: skip
    sizes = {
        "nx": n, "nsens": directions, "nparams": m, "nstops": nstops, "order": order,
        "sticks": [j in sticky for j in every],
    }  # fmt: skip
    if nmodes > 1:  # (a model of one mode: ModelKernels' defaults)
        back = [_transition_back(sys_, j) for j in every]
        targets, resets, entry = list(sys_.targets), list(sys_.resets), [-1] * nstops
        for sl in sliding:  # its virtual transitions: the exits to either side, the entries from either side
            targets += [sl.positive, sl.negative, sl.mode, sl.mode]
            back += [sl.down, sl.up, -1, -1]
            resets += [False] * 4
            entry[sl.down], entry[sl.up] = sl.base + 2, sl.base + 3
        sizes.update(
            nmodes=nmodes, rows=[r + [-1] * (width - len(r)) for r in rows], targets=targets,
            resets=resets, back=back, slide_entry=entry + [-1] * (4 * len(sliding)),
        )  # fmt: skip
    return ModelSource("\n\n".join(parts), columns, dispatch, sizes)


def _transition_back(system: SymbolicSystem, j: int) -> int:
    """The transition whose guard is 0 right after transition ``j`` (its root at ``u = 0`` is known), or -1.

    A reset within one mode: ``j`` itself (an impact).  Otherwise a transition
    ``i`` leaving ``j``'s target with ``h_i(g_j(x)) = -h_j(x)`` (``g_j`` the
    identity without a reset): a switch's way back, or the rocking block's
    other corner after an impact.
    """
    import sympy as sp

    if system.resets[j] and system.sources[j] == system.targets[j]:
        return j
    guards = [stop.guard for stop in system.stops]
    after = dict(zip(system.states, system.stops[j].reset)) if system.resets[j] else {}
    for i in range(len(guards)):
        if system.sources[i] == system.targets[j] and (system.resets[j] or not system.resets[i]):
            if sp.simplify(guards[i].subs(after, simultaneous=True) + guards[j]) == 0:
                return i
    return -1


CACHE_ENV = "GRAZING_CACHE_DIR"
"""Environment variable naming the folder of the compiled kernels."""


def cache_dir() -> Path:
    """Directory where generated kernel modules (and numba's caches) live, as configured (see
    :func:`usable_cache_dir` for the one used)."""
    env = os.environ.get(CACHE_ENV)
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "grazing"


def _unusable(folder: Path, private: bool = False, parents: bool = True) -> str | None:
    """Why ``folder`` cannot hold the cache (made if missing, with its parents if ``parents``), or None."""
    if not parents and not os.path.lexists(folder) and not folder.parent.is_dir():
        return f"its folder {str(folder.parent)!r} does not exist"
    try:
        folder.mkdir(mode=0o700 if private else 0o777, parents=parents, exist_ok=True)
    except OSError as exc:
        return exc.strerror or str(exc)
    if not folder.is_dir():
        return "not a folder"
    if not os.access(folder, os.W_OK | os.X_OK):
        return "not writable"
    uid = getattr(os, "getuid", None)
    if private and uid is not None and folder.stat().st_uid != uid():
        return "owned by another user"
    return None


_NOTED: set[Path] = set()


def usable_cache_dir() -> Path:
    """The folder the compiled kernels are cached in: :func:`cache_dir`, made if missing.

    Raises
    ------
    WriteError
        If ``GRAZING_CACHE_DIR`` is set and cannot be used, or neither the
        default folder nor the private fallback in the temporary folder can.
    """
    folder = cache_dir()
    chosen = bool(os.environ.get(CACHE_ENV))  # (a folder the user named is made, not its parents: a typo)
    problem = _unusable(folder, parents=not chosen)
    if problem is None:
        return folder
    if chosen:
        raise WriteError(
            f"{CACHE_ENV}={os.environ[CACHE_ENV]} cannot hold the compiled kernels ({problem}): set it to a "
            "writable folder, or unset it"
        )
    uid = getattr(os, "getuid", lambda: "user")()
    fallback = Path(tempfile.gettempdir()) / f"grazing-cache-{uid}"
    second = _unusable(fallback, private=True)
    if second is not None:
        raise WriteError(
            f"no folder can hold the compiled kernels: {folder} ({problem}), {fallback} ({second}); "
            f"set {CACHE_ENV} to a writable folder"
        )
    if folder not in _NOTED:
        _NOTED.add(folder)
        print(
            f"grazing: note: {folder} cannot hold the compiled kernels ({problem}); they are cached in "
            f"{fallback} (set {CACHE_ENV} to choose)",
            file=sys.stderr,
        )
    return fallback


def _key(*parts: Any) -> str:
    return hashlib.sha256(repr(parts).encode()).hexdigest()[:20]


def kernel_key(identity: str, directions: int, order: int = DEFAULT_ORDER) -> str:
    """Cache key of a model's compiled functions: the model's identity and everything the code depends on."""
    import llvmlite

    here = Path(__file__).parent
    deps = "".join(
        (here / f).read_text() for f in ("taylor.py", "codegen.py", "llvmgen.py", "sincos.py", "abi.py")
    )
    from grazing.engine.llvmgen import lane_width

    versions = (_CODEGEN_VERSION, llvmlite.__version__, sys.version)
    return _key(identity, int(directions), order, versions, deps, lane_width())


def _numba_version() -> str:
    """numba's version, without importing numba: its ``_version.py`` as text (else its metadata's).

    (``importlib.metadata`` costs 20-50 ms to import, in every process that runs the driver.)
    """
    spec = importlib.util.find_spec("numba")
    if spec is not None and spec.origin is not None:
        path = Path(spec.origin).parent / "_version.py"
        if path.exists():
            return path.read_text()
    from importlib.metadata import version  # pragma: no cover - a numba without versioneer's file

    return version("numba")  # pragma: no cover


@functools.cache
def driver_key() -> str:
    """Cache key of the compiled driver: its sources and those of everything it inlines.

    numba's on-disk cache does not notice changes in functions imported from
    other modules, so the sources of the helpers are part of the key, and so
    are the values of the constants the driver takes from :mod:`grazing.core`
    (the step limit, the status codes, the tolerance of a state on a guard),
    and the sources of the functions of :mod:`grazing.core` it
    compiles in (the step limit's formula, the test of a repeating transient).
    """
    import inspect

    from grazing.core.model import ON_STOP_TOL
    from grazing.core.options import STEPS_EXTRA, STEPS_PER_PERIOD, step_limit
    from grazing.core.period import repeats_with_period
    from grazing.core.solution import Status

    here = Path(__file__).parent
    helpers = ("polyroots.py", "stepping.py", "records.py", "abi.py", "timebase.py", "lanevec.py")
    files = [here / f for f in helpers]
    deps = "".join(path.read_text() for path in [*files, *driver.template_files()])
    from grazing.engine.llvmgen import lane_width

    constants = (STEPS_PER_PERIOD, STEPS_EXTRA, [(s.name, int(s)) for s in Status], ON_STOP_TOL)  # (core's)
    constants += tuple(inspect.getsource(f) for f in (step_limit, repeats_with_period))
    versions = (_CODEGEN_VERSION, _numba_version(), sys.version)
    return _key(*versions, deps, constants, lane_width())  # (lanevec's vectors are lane_width() wide)


def _init_numba_without_blas_probe() -> None:
    """Initialise numba's array support without importing scipy.linalg.

    The first compiled function numba loads in a process initialises its CPU
    target, which imports ``numba.np.arraymath``; that module probes for BLAS
    by importing ``scipy.linalg.cython_blas``, which costs ~0.2 s (a third of
    this package's start-up) and is only used to pick a BLAS inner product
    for ``np.convolve``/``np.correlate`` in numba code, which no kernel here
    calls.  If scipy.linalg is not imported yet, it is hidden during that one
    import (the probe then reports no BLAS; numba's linear algebra still
    imports scipy when it is used).
    """
    if "numba.np.arraymath" in sys.modules or "scipy.linalg" in sys.modules:
        return
    sys.modules["scipy.linalg"] = None  # type: ignore[assignment]  # import raises ImportError
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        if sys.modules.get("scipy.linalg", 0) is None:
            del sys.modules["scipy.linalg"]


def _write_bytecode(path: Path) -> None:
    """Byte-compile a generated module once, even under ``PYTHONDONTWRITEBYTECODE``.

    Compiling the driver's source on every import would cost time in every
    process.  The ``.pyc`` is checked against the source as usual, so it is
    never stale.
    """
    import py_compile

    pyc = importlib.util.cache_from_source(str(path))
    if os.path.exists(pyc):
        return
    try:
        py_compile.compile(str(path), cfile=pyc, doraise=True)
    except (OSError, py_compile.PyCompileError):  # pragma: no cover - read-only cache: compile on import
        pass


def _cached_file(name: str, make: Callable[[], bytes]) -> Path:
    """The cache file ``name``, written with ``make()`` if it is not there yet.

    ``make()`` runs first and the file is written all at once after it, so a
    failed compilation or a failed write (a full disk: a
    :class:`~grazing.errors.WriteError`) leaves nothing in the cache.
    """
    path = usable_cache_dir() / name
    if not path.exists():
        data = interruptibly(make)  # (a Ctrl-C ends a compile at once)
        write_bytes_atomic(path, data)
    return path


def load_kernels(key: str, source: Callable[[], str]) -> ModuleType:
    """Import the generated numba module ``key``, writing it with ``source()`` if not cached."""
    modname = f"grazing_kernels_{key}"
    if modname in sys.modules:
        return sys.modules[modname]
    _init_numba_without_blas_probe()
    path = _cached_file(f"{modname}.py", lambda: source().encode())
    _write_bytecode(path)
    spec = importlib.util.spec_from_file_location(modname, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[modname] = module
    spec.loader.exec_module(module)
    return module


def load_driver() -> ModuleType:
    """The compiled driver (numba compiles it once per machine and caches it)."""
    return load_kernels(
        driver_key(), lambda: "# Generated by grazing.engine.codegen; do not edit.\n" + driver.template_text()
    )


class ModelKernels:
    """A model's compiled functions, loaded: callable from Python and, through their addresses, the driver.

    Attributes ``NX``, ``NSENS``, ``NPARAMS``, ``NSTOPS``, ``ORDER``,
    ``STICKS`` give the sizes; every name of :data:`grazing.engine.abi.SLOTS`
    is a Python caller (``model.kernels().guard(x, t, pv, j)``); arrays must
    be C-contiguous float64, outputs are written in place.  ``table`` is the
    :class:`~grazing.engine.records.Kernels` record the driver takes
    (:func:`grazing.engine.runner.integrate`).
    """

    def __init__(self, library: Any, sizes: dict[str, Any]) -> None:
        self.library = library
        self.NX = int(sizes["nx"])
        self.NSENS = int(sizes["nsens"])
        self.NPARAMS = int(sizes["nparams"])
        self.NSTOPS = int(sizes["nstops"])
        self.ORDER = int(sizes["order"])
        self.STICKS = tuple(bool(s) for s in sizes["sticks"])
        self.HAS_STICK = any(self.STICKS)
        self.LANES = int(sizes.get("lanes", 0))
        fns = np.array([library.address(name) for name in SLOTS + LANE_SLOTS], dtype=np.int64)
        if not fns[: len(SLOTS)].all() or (self.LANES and not fns[len(SLOTS) :].all()):  # pragma: no cover
            raise OSError("compiled model functions are missing from the kernel cache")  # a damaged file
        sticks = np.array(self.STICKS, dtype=bool)
        self.NMODES = int(sizes.get("nmodes", 1))
        every = list(range(self.NSTOPS))
        self.ROWS = np.array(sizes.get("rows", [every]), dtype=np.int64).reshape(self.NMODES, -1)
        self.TARGETS = np.array(sizes.get("targets", [0] * self.NSTOPS), dtype=np.int64)
        self.RESETS = np.array(sizes.get("resets", [True] * self.NSTOPS), dtype=bool)
        self.BACK = np.array(sizes.get("back", every), dtype=np.int64)
        self.SLIDE_ENTRY = np.array(sizes.get("slide_entry", [-1] * self.NSTOPS), dtype=np.int64)
        self.table = (
            fns, self.NX, self.NSENS, self.NSTOPS, self.ORDER, sticks, self.LANES, self.NMODES, self.ROWS,
            self.TARGETS, self.RESETS, self.BACK, self.SLIDE_ENTRY,
        )  # fmt: skip
        for name in SLOTS:
            setattr(self, name, library.function(name))
        self.impacts_per_period = outputs.IMPACTS_PER_PERIOD  # (the last run's: see runner.integrate)


_loaded: dict[str, ModelKernels] = {}


def compile_model(source: ModelSource, key: str) -> bytes:
    """The cache file of a model: a JSON line of its sizes, then the object file of its functions."""
    from grazing.engine import llvmgen

    prefix = f"grazing_{key}"
    # Lane (SIMD) versions of the Taylor kernels for sweeps, which use no sensitivity directions; with
    # several modes one per mode, behind a dispatcher by the active mode as the scalar kernels'.
    lanes = llvmgen.lane_width() if source.sizes["nsens"] == 0 else 0
    nmodes = int(source.sizes.get("nmodes", 1))
    dispatch, lane_functions = source.dispatch, ("tc_free", "tc_var")
    if nmodes > 1:
        lane_functions = tuple(f"{name}_m{k}" for name in lane_functions for k in range(nmodes))
        if lanes:
            dispatch = {**dispatch}
            for name in ("tc_free", "tc_var"):
                dispatch[f"{name}_lanes"] = [f"{name}_m{k}_lanes" for k in range(nmodes)]
    module = llvmgen.translate(
        source.text, prefix, columns=source.columns, dispatch=dispatch, lanes=lanes,
        lane_functions=lane_functions,
    )  # fmt: skip
    sizes = {**source.sizes, "lanes": lanes}
    return json.dumps(sizes).encode() + b"\n" + llvmgen.compile_object(module)


def load_compiled(key: str, source: Callable[[], ModelSource]) -> ModelKernels:
    """The model functions ``key``, compiled with ``source()`` if not cached, loaded once per process."""
    kernels = _loaded.get(key)
    if kernels is None:
        from grazing.engine import llvmgen

        name = f"grazing_model_{key}.bin"

        def read(path: Path) -> ModelKernels:
            header, obj = path.read_bytes().split(b"\n", 1)
            sizes = json.loads(header)
            return ModelKernels(llvmgen.Library(obj, f"grazing_{key}"), sizes)

        path = _cached_file(name, lambda: compile_model(source(), key))
        try:
            kernels = read(path)
        except (ValueError, RuntimeError, OSError):  # a damaged cache file (ours): compile it again
            path.unlink(missing_ok=True)
            kernels = read(_cached_file(name, lambda: compile_model(source(), key)))
        _loaded[key] = kernels
    return kernels


def load_model_kernels(definition: Any, directions: int, order: int | None) -> ModelKernels:
    """The compiled functions of a model definition (:class:`grazing.core.model` calls this).

    Keyed by the model's identity, the number of sensitivity directions, the
    order and the sources of the generator, so a cached model is found without
    building the model's symbolic form (no sympy import on a cache hit).
    """
    order = DEFAULT_ORDER if order is None else order
    key = kernel_key(definition.identity(), directions, order)
    return load_compiled(key, lambda: generate_source(definition.system, directions, order))


set_kernel_loader(load_model_kernels)
