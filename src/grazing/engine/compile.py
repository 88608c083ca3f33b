"""Assemble, cache and load the compiled kernels of a hybrid model.

For each model (and each set of parameters to differentiate with respect to)
one Python module is generated: Taylor-coefficient kernels for free flight,
free flight with variational equations, and sticking; scalar functions for the
vector field, guard, reset and their Jacobians; and the integration driver
(``_driver_template.py``).  The module is written to a cache directory named
by a hash of its source and imported; numba then caches the machine code next
to it, so a model is compiled once per machine, not once per process.

The cache directory is ``$GRAZING_CACHE_DIR`` if set, else
``$XDG_CACHE_HOME/grazing`` (``~/.cache/grazing``).
"""

from __future__ import annotations

import hashlib
import importlib.util
import math
import os
import sys
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

from grazing.engine.polyroots import work_shape

if TYPE_CHECKING:  # pragma: no cover
    import sympy as sp

_TEMPLATE = Path(__file__).with_name("_driver_template.py")
# Bump when the generated code changes meaning without its text changing.
_CODEGEN_VERSION = "3"


def taylor_order(tol: float) -> int:
    """Order of the Taylor method for a tolerance (Jorba & Zou): ``ceil(-ln(tol)/2 + 1)``.

    Examples
    --------
    >>> taylor_order(2.220446049250313e-16)
    20
    """
    return int(min(60, max(6, math.ceil(-math.log(tol) / 2 + 1))))


DEFAULT_ORDER = taylor_order(2.220446049250313e-16)
"""Order of the kernels for the default tolerance (machine epsilon): 20."""


@dataclass(frozen=True)
class SymbolicSystem:
    """The symbolic pieces of a hybrid model that the code generator needs.

    Attributes
    ----------
    states, time, params
        Symbols of the state vector, time and parameters (in the order of the
        parameter vector).
    vector_field
        ``f(x, t)``, one expression per state.
    guard
        ``h(x, t)``; the allowed region is ``h > 0``, impacts happen when ``h``
        reaches 0.
    reset
        ``g(x, t)``, the state just after an impact.
    contact_direction
        Direction ``e(x, t)`` along which the reset changes the state (the
        velocity direction of a mechanical impact), used to constrain the flow
        to the stop during sticking; ``None`` disables sticking.
    """

    states: tuple[sp.Symbol, ...]
    time: sp.Symbol
    params: tuple[sp.Symbol, ...]
    vector_field: tuple[sp.Expr, ...]
    guard: sp.Expr
    reset: tuple[sp.Expr, ...]
    contact_direction: tuple[sp.Expr, ...] | None = None
    period: sp.Expr | None = None

    def canonical(self) -> SymbolicSystem:
        """The same system with every user symbol replaced by a fresh :class:`sympy.Dummy`.

        The code generator creates symbols of its own (the variational matrix,
        common subexpressions); working on the canonical system guarantees that
        no name a user chooses for a state, parameter or time (``v1``, ``t_0``,
        ``pi``, ``sin`` ...) can be the same sympy object as one of those.
        """
        import sympy as sp

        sub = {x: sp.Dummy(f"x{i}") for i, x in enumerate(self.states)}
        sub[self.time] = sp.Dummy("t")
        sub.update({p: sp.Dummy(f"p{i}") for i, p in enumerate(self.params)})

        def tr(e: sp.Expr) -> sp.Expr:
            return sp.sympify(e).xreplace(sub)

        return SymbolicSystem(
            states=tuple(sub[x] for x in self.states),
            time=sub[self.time],
            params=tuple(sub[p] for p in self.params),
            vector_field=tuple(tr(e) for e in self.vector_field),
            guard=tr(self.guard),
            reset=tuple(tr(e) for e in self.reset),
            contact_direction=(
                None if self.contact_direction is None else tuple(map(tr, self.contact_direction))
            ),
            period=None if self.period is None else tr(self.period),
        )

    def gradient(self, expr: sp.Expr) -> list[sp.Expr]:
        import sympy as sp

        return [sp.diff(expr, x) for x in self.states]

    def lie(self, expr: sp.Expr) -> sp.Expr:
        """Derivative of ``expr`` along the flow: grad(expr) . f + d(expr)/dt."""
        import sympy as sp

        return sp.Add(*[g * f for g, f in zip(self.gradient(expr), self.vector_field)]) + sp.diff(
            expr, self.time
        )

    @property
    def normal_rate(self) -> sp.Expr:
        """``L_f h``: rate of change of the guard (negative when approaching)."""
        return self.lie(self.guard)

    @property
    def normal_accel(self) -> sp.Expr:
        """``L_f^2 h``: the guard's acceleration (negative when pushed into the stop)."""
        return self.lie(self.normal_rate)

    def sticking_field(self) -> tuple[sp.Expr, ...]:
        """Vector field constrained to ``h = 0, L_f h = 0`` along the contact direction."""
        import sympy as sp

        if self.contact_direction is None:
            raise ValueError("model has no contact direction")
        e = self.contact_direction
        gr = self.gradient(self.normal_rate)
        den = sp.Add(*[g * ei for g, ei in zip(gr, e)])
        lam = self.normal_accel / den
        return tuple(f - lam * ei for f, ei in zip(self.vector_field, e))


def _scalar_function(
    name: str,
    sys_: SymbolicSystem,
    assigns: Sequence[tuple[str, sp.Expr]],
    returns: sp.Expr | None = None,
    extra_args: str = "",
) -> str:
    """Numba source of ``name(x, s, pv{extra_args})`` with CSE'd assignments."""
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
    lines = ["@njit(cache=True)", f"def {name}(x, s, pv{extra_args}):"]
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


def generate_source(system: SymbolicSystem, directions: int = 0, order: int = DEFAULT_ORDER) -> str:
    """Full source of the kernel module for ``system`` with Taylor polynomials of degree ``order``.

    ``directions`` extra columns of the variational matrix hold derivatives
    along directions ``D[c]`` in parameter space, read at run time after the
    parameter values: the kernels' parameter vector is ``(p, D.ravel())``.
    """
    import dataclasses

    import sympy as sp

    from grazing.engine.taylor import taylor_kernel

    sys_ = system.canonical()
    n = len(sys_.states)
    m = len(sys_.params)
    dsyms = [[sp.Dummy(f"d{c}_{j}") for j in range(m)] for c in range(directions)]
    sysd = dataclasses.replace(sys_, params=tuple(sys_.params) + tuple(d for row in dsyms for d in row))

    def along(c: int, expr: sp.Expr) -> sp.Expr:
        """The derivative of ``expr`` along the direction ``D[c]``."""
        return sp.Add(*[dsyms[c][j] * sp.diff(expr, p) for j, p in enumerate(sys_.params)])

    ncol = n + directions
    f = sys_.vector_field
    parts = [
        "# Generated by grazing.engine.compile; do not edit.",
        "import math",
        "import numpy as np",
        "from numba import njit",
        "from grazing.engine.polyroots import horner, isolate_first_root, quadratic_bound",
        "from grazing.engine.stepping import (append_pair, append_record, append_row,"
        " divide_double_root_at_one, eval_rows, new_table, orthonormalize, pack_var, poly_derivative,"
        " set_row, set_slice, step_factor, step_size, table_rows, unpack_var)",
        f"NX = {n}",
        f"NSENS = {directions}",
        f"NPARAMS = {m}",
        f"ORDER = {order}",
        f"ROOT_WORK_ROWS, ROOT_WORK_MIN_COLS = {work_shape(0)}",
    ]
    free = taylor_kernel("tc_free", sys_.states, sys_.time, sys_.params, f, [sys_.guard], order)
    # Variational equations: V' = f_x V (+ f_p D[c] on the direction columns).
    vsyms = tuple(sp.Dummy(f"v{i}") for i in range(n * ncol))
    vmat = sp.Matrix(n, ncol, vsyms)
    jac = sp.Matrix([[sp.diff(fi, x) for x in sys_.states] for fi in f])
    vrhs = jac * vmat
    for c in range(directions):
        for i in range(n):
            vrhs[i, n + c] += along(c, f[i])
    var = taylor_kernel(
        "tc_var",
        tuple(sys_.states) + tuple(vsyms),
        sys_.time,
        sysd.params,
        tuple(f) + tuple(vrhs),
        [sys_.guard],
        order,
    )
    has_stick = sys_.contact_direction is not None
    if has_stick:
        stick = taylor_kernel(
            "tc_stick",
            sys_.states,
            sys_.time,
            sys_.params,
            sys_.sticking_field(),
            [sys_.normal_accel],
            order,
        )
    else:
        stick = taylor_kernel("tc_stick", sys_.states, sys_.time, sys_.params, f, [sp.Integer(1)], order)
    parts.append(f"HAS_STICK = {has_stick}")
    for k in (free, var, stick):
        parts.append("@njit(cache=True)\n" + k.source)

    gx = sys_.gradient(sys_.guard)
    parts.append(
        _scalar_function("rhs", sys_, [(f"out[{i}]", e) for i, e in enumerate(f)], extra_args=", out")
    )
    parts.append(_scalar_function("guard", sys_, [], returns=sys_.guard))
    parts.append(
        _scalar_function(
            "guard_grad",
            sys_,
            [(f"gx[{i}]", e) for i, e in enumerate(gx)],
            returns=sp.diff(sys_.guard, sys_.time),
            extra_args=", gx",
        )
    )
    parts.append(
        _scalar_function(
            "guard_pgrad",
            sysd,
            [(f"hp[{c}]", along(c, sys_.guard)) for c in range(directions)],
            extra_args=", hp",
        )
    )
    g = sys_.reset
    gjac = [(f"Gx[{i}, {j}]", sp.diff(gi, x)) for i, gi in enumerate(g) for j, x in enumerate(sys_.states)]
    gjac += [(f"Gt[{i}]", sp.diff(gi, sys_.time)) for i, gi in enumerate(g)]
    gjac += [(f"Gp[{i}, {c}]", along(c, gi)) for i, gi in enumerate(g) for c in range(directions)]
    parts.append(
        _scalar_function("reset", sys_, [(f"out[{i}]", e) for i, e in enumerate(g)], extra_args=", out")
    )
    parts.append(_scalar_function("reset_jac", sysd, gjac, extra_args=", Gx, Gt, Gp"))
    parts.append(_scalar_function("normal_rate", sys_, [], returns=sys_.normal_rate))
    parts.append(_scalar_function("normal_accel", sys_, [], returns=sys_.normal_accel))
    parts.append(
        _scalar_function(
            "normal_rate_grad",
            sys_,
            [(f"gr[{i}]", e) for i, e in enumerate(sys_.gradient(sys_.normal_rate))],
            extra_args=", gr",
        )
    )
    e = sys_.contact_direction if has_stick else tuple(sp.Integer(0) for _ in range(n))
    parts.append(
        _scalar_function("contact_dir", sys_, [(f"e[{i}]", ei) for i, ei in enumerate(e)], extra_args=", e")
    )
    # dT/dp for every parameter: a sample "one period later" moves when the period does.
    period = sp.Integer(0) if sys_.period is None else sys_.period
    parts.append(
        _scalar_function(
            "period_grad", sys_, [(f"tp[{i}]", sp.diff(period, p)) for i, p in enumerate(sys_.params)],
            extra_args=", tp",
        )
    )  # fmt: skip
    parts.append(_TEMPLATE.read_text())
    return "\n\n".join(parts)


def cache_dir() -> Path:
    """Directory where generated kernel modules (and numba's caches) live."""
    env = os.environ.get("GRAZING_CACHE_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "grazing"


def kernel_key(identity: str, directions: int, order: int = DEFAULT_ORDER) -> str:
    """Cache key of a kernel module: the model's identity and everything the code depends on.

    numba's on-disk cache does not notice changes in functions imported from
    other modules, so the sources of the driver template, the root finder and
    the code generator are part of the key.
    """
    import numba

    here = Path(__file__).parent
    files = ("_driver_template.py", "polyroots.py", "stepping.py", "taylor.py", "compile.py")
    deps = "".join((here / f).read_text() for f in files)
    versions = (_CODEGEN_VERSION, numba.__version__, sys.version)
    text = repr((identity, int(directions), order, versions, deps))
    return hashlib.sha256(text.encode()).hexdigest()[:20]


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

    A kernel module is thousands of lines; compiling its source on every import
    costs ~80 ms per process.  The ``.pyc`` is checked against the source as
    usual, so it is never stale.
    """
    import py_compile

    pyc = importlib.util.cache_from_source(str(path))
    if os.path.exists(pyc):
        return
    try:
        py_compile.compile(str(path), cfile=pyc, doraise=True)
    except (OSError, py_compile.PyCompileError):  # pragma: no cover - read-only cache: compile on import
        pass


def load_kernels(key: str, source: Callable[[], str]) -> ModuleType:
    """Import the kernel module ``key``, generating it with ``source()`` if not cached."""
    modname = f"grazing_kernels_{key}"
    if modname in sys.modules:
        return sys.modules[modname]
    _init_numba_without_blas_probe()
    path: Path | None = None
    for d in (cache_dir(), Path(tempfile.gettempdir()) / "grazing-cache"):
        try:
            d.mkdir(parents=True, exist_ok=True)
            candidate = d / f"{modname}.py"
            if not candidate.exists():
                fd, tmp = tempfile.mkstemp(dir=d, suffix=".tmp")
                with os.fdopen(fd, "w") as fh:
                    fh.write(source())
                os.replace(tmp, candidate)
            path = candidate
            break
        except OSError:
            continue
    if path is None:  # pragma: no cover - no writable directory at all
        raise OSError("no writable cache directory for compiled kernels")
    _write_bytecode(path)
    spec = importlib.util.spec_from_file_location(modname, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[modname] = module
    spec.loader.exec_module(module)
    return module


def load_source(source: str) -> ModuleType:
    """Import generated ``source`` as a cached kernel module (keyed by its text)."""
    return load_kernels(kernel_key(source, 0), lambda: source)
