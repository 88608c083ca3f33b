"""Machine code for a model's generated functions, through LLVM IR (llvmlite), as heyoka does.

:mod:`grazing.engine.codegen` writes a model's functions (the Taylor kernels,
the vector field, the guards, resets and their derivatives) as straight-line
Python: assignments of arithmetic expressions, ``math`` functions and array
elements.  This module translates that text into LLVM IR, one function per
definition with the common C signature of :mod:`grazing.engine.abi`, and has
LLVM compile it to an object file.  Compared with numba compiling the same
text (about 3 s per Taylor kernel, 40 s per model with the driver), the IR
is compiled in a fraction of a second: numba's front end (typing, reference
counting, exception paths for every division) is what cost the time.

The translation keeps the arithmetic exactly: the same operations in the same
order, no fast-math flags (so no fused multiply-adds), and for ``math.exp``,
``**`` and the other functions the same LLVM intrinsics or C library functions
that numba calls, so the results are bit-identical to numba's compiling the
same text, with two exceptions.  ``math.sin`` and ``math.cos``, in every
generated function, are grazing's own (:mod:`grazing.engine.sincos`: within
one ulp, not always the C library's bits): straight-line arithmetic
translated in place, the same operations on a scalar and on SIMD lanes, so
that a lane function gives its scalar twin's bits while its vectors stay
vectors (the C library's ``sin`` would take one call per lane).  Using them
in every function (the vector field, guards, resets), not only in the Taylor
kernels and their lane twins, keeps one definition of ``sin`` and ``cos`` for
the whole model.  And a division by zero gives an infinity or a NaN
(IEEE) where numba raised ``ZeroDivisionError``.  The reference for the
compiled code is CPython running the same text with
:func:`grazing.engine.sincos.sin` and :func:`~grazing.engine.sincos.cos` as
``math.sin`` and ``math.cos`` (``tests/engine/test_llvmgen.py``).

Examples
--------
>>> src = "def f(x, s, pv, out):\\n    out[0] = pv[0] * math.sin(s) + x[0]\\n    return x[0] ** 2.5\\n"
>>> lib = compile_library(src, "doc_example")
>>> import numpy as np
>>> out = np.zeros(1)
>>> float(lib.function("f")(np.array([4.0]), 0.0, np.array([2.0]), out)), float(out[0])
(32.0, 4.0)
"""

from __future__ import annotations

import ast
import ctypes
import functools
import inspect
import math
import os
import textwrap
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import llvmlite.binding as llvm
import llvmlite.ir as ir
import numpy as np

from grazing.engine import sincos
from grazing.engine.abi import ARITY, C_SIGNATURE

_DOUBLE = ir.DoubleType()
_PTR = _DOUBLE.as_pointer()
_I64 = ir.IntType(64)
_I1 = ir.IntType(1)
_FNTY = ir.FunctionType(_DOUBLE, [_PTR, _DOUBLE, _PTR, _PTR, _PTR, _PTR, _I64])
"""The common signature (:mod:`grazing.engine.abi`)."""

# math functions as numba lowers them: LLVM intrinsics for these ...
_INTRINSICS = {"exp", "log", "log10", "log2", "fabs", "exp2", "copysign", "pow"}
# ... and C library calls for the rest.
_EXTERNS = {
    "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan", "atan2": "atan2", "sinh": "sinh",
    "cosh": "cosh", "tanh": "tanh", "asinh": "asinh", "acosh": "acosh", "atanh": "atanh",
    "expm1": "expm1", "log1p": "log1p", "erf": "erf", "erfc": "erfc", "sqrt": "sqrt",
    "hypot": "hypot", "lgamma": "lgamma", "gamma": "tgamma", "cbrt": "cbrt", "floor": "floor",
    "ceil": "ceil", "trunc": "trunc",
}  # fmt: skip
_CONSTANTS = {"pi": math.pi, "e": math.e, "inf": math.inf, "nan": math.nan}


def _sincos_body() -> tuple[list[ast.stmt], tuple[str, str]]:
    """The statements of :func:`grazing.engine.sincos.sincos_fast` and the names it returns."""
    fdef = ast.parse(textwrap.dedent(inspect.getsource(sincos.sincos_fast))).body[0]
    assert isinstance(fdef, ast.FunctionDef)
    *body, ret = fdef.body
    assert isinstance(ret, ast.Return) and isinstance(ret.value, ast.Tuple)
    names = [e.id for e in ret.value.elts if isinstance(e, ast.Name)]
    return body, (names[0], names[1])


_SINCOS_BODY, _SINCOS_RESULTS = _sincos_body()


class UntranslatableCodeError(ValueError):
    """Generated code uses a construct the IR translator does not know (an internal error)."""


@dataclass
class _Function:
    """The translation of one ``def`` into the common signature."""

    module: ir.Module
    fn: ir.Function
    builder: ir.IRBuilder
    args: dict[str, tuple[str, Any]]  # Python name -> ("ptr", value, columns) or ("val", value)
    columns: Mapping[str, int]
    lanes: int = 0  # 0: scalars; L: every value a vector of L lanes (see translate)
    env: dict[str, ir.Value] = field(default_factory=dict)
    trig: dict[int, tuple[ir.Value, ir.Value, ir.Value]] = field(default_factory=dict)
    # id of an argument -> (the argument, its sin, its cos): sin and cos of one value computed once

    def _declare(self, name: str, nargs: int, intrinsic: bool) -> ir.Function:
        ty = ir.VectorType(_DOUBLE, self.lanes) if self.lanes and intrinsic else _DOUBLE
        full = (f"llvm.{name}.v{self.lanes}f64" if self.lanes else f"llvm.{name}.f64") if intrinsic else name
        existing = self.module.globals.get(full)
        if existing is not None:
            return existing
        return ir.Function(self.module, ir.FunctionType(ty, [ty] * nargs), name=full)

    def _constant(self, ty: ir.Type, v: Any) -> ir.Constant:
        """A constant, as a vector of equal lanes in lane functions."""
        if self.lanes:
            return ir.Constant(ir.VectorType(ty, self.lanes), [v] * self.lanes)
        return ir.Constant(ty, v)

    def _scalarised(self, callee: ir.Function, args: list[ir.Value]) -> ir.Value:
        """``callee`` (a C function of doubles) applied lane by lane."""
        b = self.builder
        out = self._constant(_DOUBLE, 0.0)
        for lane in range(self.lanes):
            i = ir.Constant(ir.IntType(32), lane)
            out = b.insert_element(out, b.call(callee, [b.extract_element(a, i) for a in args]), i)
        return out

    def _sincos(self, x: ir.Value) -> tuple[ir.Value, ir.Value]:
        """``sin x`` and ``cos x`` by :func:`grazing.engine.sincos.sincos` (scalar or lanes alike).

        The fast path is the text of :func:`~grazing.engine.sincos.sincos_fast`
        translated in place; if a lane is beyond :data:`~grazing.engine.sincos.LIMIT`
        (or NaN, infinite), a branch computes the C library's ``sin`` and
        ``cos`` of every lane and keeps them for those lanes.
        """
        known = self.trig.get(id(x))
        if known is not None:
            return known[1], known[2]
        b = self.builder
        env = {"x": x, **{k: self._constant(_DOUBLE, v) for k, v in sincos.CONSTANTS.items()}}
        fast = _Function(self.module, self.fn, b, {}, {}, self.lanes, env)
        for stmt in _SINCOS_BODY:
            fast.statement(stmt)
        s_fast, c_fast = (fast.env[name] for name in _SINCOS_RESULTS)
        inside = b.fcmp_ordered(
            "<", b.call(self._declare("fabs", 1, True), [x]), self._constant(_DOUBLE, sincos.LIMIT)
        )
        every = inside
        if self.lanes:  # every lane inside: the L bits of the mask all set
            mask = ir.IntType(self.lanes)
            every = b.icmp_unsigned("==", b.bitcast(inside, mask), ir.Constant(mask, -1))
        entry = b.block
        slow, done = self.fn.append_basic_block("sincos_slow"), self.fn.append_basic_block("sincos_done")
        b.cbranch(every, done, slow).set_weights([1000, 1])
        b.position_at_end(slow)
        libm = [self._declare(name, 1, False) for name in ("sin", "cos")]
        if self.lanes:
            s_slow, c_slow = (
                b.select(inside, v, self._scalarised(f, [x])) for v, f in zip((s_fast, c_fast), libm)
            )
        else:
            s_slow, c_slow = (b.call(f, [x]) for f in libm)
        b.branch(done)
        b.position_at_end(done)
        out = []
        for v_fast, v_slow in ((s_fast, s_slow), (c_fast, c_slow)):
            phi = b.phi(x.type)
            phi.add_incoming(v_fast, entry)
            phi.add_incoming(v_slow, slow)
            out.append(phi)
        self.trig[id(x)] = (x, out[0], out[1])
        return out[0], out[1]

    def _element(self, node: ast.Subscript) -> ir.Value:
        """Pointer to ``arr[i]`` or ``arr[i, k]`` (C order; the columns of 2-D arrays are known)."""
        if not isinstance(node.value, ast.Name) or node.value.id not in self.args:
            raise UntranslatableCodeError(f"subscript of an unknown array: {ast.unparse(node)}")
        name = node.value.id
        kind, ptr = self.args[name][:2]
        if kind != "ptr":
            raise UntranslatableCodeError(f"{name} is not an array")
        idx = node.slice
        if isinstance(idx, ast.Tuple):
            i, k = (_int(e) for e in idx.elts)
            offset = i * self.columns[name] + k
        else:
            offset = _int(idx)
        if self.lanes:  # lane l of element e is at e * L + l
            vec = ir.VectorType(_DOUBLE, self.lanes).as_pointer()
            return self.builder.bitcast(self.builder.gep(ptr, [ir.Constant(_I64, offset * self.lanes)]), vec)
        return self.builder.gep(ptr, [ir.Constant(_I64, offset)])

    def value(self, node: ast.expr) -> ir.Value:
        """The IR value of a Python expression of the generated code."""
        b = self.builder
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool):
                return self._constant(_I1, int(node.value))
            if isinstance(node.value, int | float):
                return self._constant(_DOUBLE, float(node.value))
        elif isinstance(node, ast.Name):
            if node.id in self.env:
                return self.env[node.id]
            if node.id in self.args and self.args[node.id][0] == "val":
                return self.args[node.id][1]
        elif isinstance(node, ast.Attribute):
            if isinstance(node.value, ast.Name) and node.value.id == "math" and node.attr in _CONSTANTS:
                return self._constant(_DOUBLE, _CONSTANTS[node.attr])
        elif isinstance(node, ast.Subscript):
            return b.load(self._element(node), align=8)
        elif isinstance(node, ast.UnaryOp):
            v = self.value(node.operand)
            if isinstance(node.op, ast.USub):
                return b.fneg(v)
            if isinstance(node.op, ast.UAdd):
                return v
            if isinstance(node.op, ast.Not):
                return b.not_(v)
        elif isinstance(node, ast.BinOp):
            lhs, rhs = self.value(node.left), self.value(node.right)
            ops = {ast.Add: b.fadd, ast.Sub: b.fsub, ast.Mult: b.fmul, ast.Div: b.fdiv}
            if type(node.op) in ops:
                return ops[type(node.op)](lhs, rhs)
            if isinstance(node.op, ast.Pow):
                return b.call(self._declare("pow", 2, True), [lhs, rhs])
        elif isinstance(node, ast.Call):
            return self._call(node)
        elif isinstance(node, ast.Compare) and len(node.ops) == 1:
            cmp = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==", ast.NotEq: "!="}
            op = cmp.get(type(node.ops[0]))
            if op is not None:
                lhs, rhs = self.value(node.left), self.value(node.comparators[0])
                # Python's comparisons: ordered, except != (true when either is NaN).
                return b.fcmp_unordered(op, lhs, rhs) if op == "!=" else b.fcmp_ordered(op, lhs, rhs)
        elif isinstance(node, ast.BoolOp):
            vals = [self.value(v) for v in node.values]
            out = vals[0]
            for v in vals[1:]:
                out = b.and_(out, v) if isinstance(node.op, ast.And) else b.or_(out, v)
            return out
        elif isinstance(node, ast.IfExp):
            return b.select(self.value(node.test), self.value(node.body), self.value(node.orelse))
        raise UntranslatableCodeError(f"cannot translate {ast.unparse(node)!r} to LLVM IR")

    def _call(self, node: ast.Call) -> ir.Value:
        b = self.builder
        args = [self.value(a) for a in node.args]
        f = node.func
        if isinstance(f, ast.Name) and f.id in ("abs", "min", "max", "float"):
            if f.id == "abs" and len(args) == 1:
                return b.call(self._declare("fabs", 1, True), args)
            if f.id == "float" and len(args) == 1:
                return args[0]
            if f.id in ("min", "max") and len(args) == 2:  # Python: the first unless the second is beyond
                beyond = b.fcmp_ordered("<" if f.id == "min" else ">", args[1], args[0])
                return b.select(beyond, args[1], args[0])
        if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) and f.value.id == "math":
            name = f.attr
            if name in ("sin", "cos") and len(args) == 1:
                return self._sincos(args[0])[name == "cos"]
            if name in _INTRINSICS:
                return b.call(self._declare(name, len(args), True), args)
            if name in _EXTERNS:
                callee = self._declare(_EXTERNS[name], len(args), False)
                return self._scalarised(callee, args) if self.lanes else b.call(callee, args)
        raise UntranslatableCodeError(f"cannot translate the call {ast.unparse(node)!r} to LLVM IR")

    def statement(self, stmt: ast.stmt) -> bool:
        """Translate one statement; True once the function has returned."""
        b = self.builder
        if isinstance(stmt, ast.Assign) and len(stmt.targets) == 1:
            target = stmt.targets[0]
            v = self.value(stmt.value)
            if isinstance(target, ast.Name):
                self.env[target.id] = v
                return False
            if isinstance(target, ast.Subscript):
                b.store(v, self._element(target), align=8)
                return False
        elif isinstance(stmt, ast.Return):
            if self.lanes and stmt.value is not None:
                raise UntranslatableCodeError("a lane function returns nothing")
            b.ret(ir.Constant(_DOUBLE, 0.0) if stmt.value is None else self.value(stmt.value))
            return True
        elif isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant):  # a docstring
            return False
        raise UntranslatableCodeError(f"cannot translate the statement {ast.unparse(stmt)!r} to LLVM IR")


def _int(node: ast.expr) -> int:
    if isinstance(node, ast.Constant) and isinstance(node.value, int):
        return node.value
    raise UntranslatableCodeError(f"array index {ast.unparse(node)!r} is not a constant")


def _define(
    module: ir.Module, fdef: ast.FunctionDef, symbol: str, columns: Mapping[str, int], lanes: int = 0
) -> None:
    """Define ``symbol`` in ``module`` from the Python function ``fdef`` (see :func:`translate`)."""
    fn = ir.Function(module, _FNTY, name=symbol)
    params = [a.arg for a in fdef.args.args]
    if not 3 <= len(params) <= (5 if lanes else 6):
        raise UntranslatableCodeError(f"{fdef.name} has {len(params)} arguments (3 to 6 expected)")
    x, s, pv, a, bb, c, _j = fn.args
    builder = ir.IRBuilder(fn.append_basic_block("entry"))
    if lanes:  # the lanes' times come in c, as L doubles
        for arg in (x, pv, a, bb, c):
            arg.add_attribute("noalias")
        svec = builder.load(builder.bitcast(c, ir.VectorType(_DOUBLE, lanes).as_pointer()), align=8)
        slots = [("ptr", x), ("val", svec), ("ptr", pv), ("ptr", a), ("ptr", bb)]
    else:
        slots = [("ptr", x), ("val", s), ("ptr", pv), ("ptr", a), ("ptr", bb), ("ptr", c)]
    f = _Function(module, fn, builder, dict(zip(params, slots)), columns, lanes)
    for stmt in fdef.body:
        if f.statement(stmt):
            return
    builder.ret(ir.Constant(_DOUBLE, 0.0))


def translate(source: str, prefix: str, columns: Mapping[str, Mapping[str, int]] | None = None,
              dispatch: Mapping[str, list[str]] | None = None, lanes: int = 0,
              lane_functions: tuple[str, ...] = ()) -> ir.Module:  # fmt: skip
    """The LLVM module of every ``def`` in ``source``, each named ``{prefix}_{name}``.

    A function ``def f(x, s, pv[, a[, b[, c]]])`` becomes ``double
    {prefix}_f(x, s, pv, a, b, c, j)`` (:data:`grazing.engine.abi.C_SIGNATURE`):
    its arguments by position, arrays as pointers to C-ordered doubles.
    ``columns[f][name]`` gives the number of columns of each 2-D array
    argument of ``f``.  ``dispatch[name]`` lists functions (one per stop)
    that ``{prefix}_{name}`` calls according to its last argument ``j``
    (any other ``j``: the last of them).

    With ``lanes = L``, each function ``f`` named in ``lane_functions`` (a
    function of ``x, s, pv`` and at most two output arrays) also becomes
    ``{prefix}_{f}_lanes``, which computes ``f`` for ``L`` points at once on
    vectors of ``L`` doubles (SIMD): every array element holds ``L`` lanes
    (lane ``l`` of element ``e`` at ``e * L + l``), and the lanes' times come
    in the argument ``c`` (``L`` doubles; ``s`` is unused).  Each lane's
    result is the same operations on the same values as ``f``'s: the same
    numbers, bit for bit.
    """
    module = ir.Module(name=prefix)
    module.triple = llvm.get_process_triple()
    tree = ast.parse(source)
    columns = columns or {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            _define(module, node, f"{prefix}_{node.name}", columns.get(node.name, {}))
            if lanes and node.name in lane_functions:
                _define(module, node, f"{prefix}_{node.name}_lanes", columns.get(node.name, {}), lanes)
    for name, targets in (dispatch or {}).items():
        fn = ir.Function(module, _FNTY, name=f"{prefix}_{name}")
        b = ir.IRBuilder(fn.append_basic_block("entry"))
        callees = [module.get_global(f"{prefix}_{t}") for t in targets]
        blocks = [fn.append_basic_block(f"stop{j}") for j in range(len(targets))]
        sw = b.switch(fn.args[6], blocks[-1])
        for j, (block, callee) in enumerate(zip(blocks, callees)):
            if j < len(targets) - 1:
                sw.add_case(ir.Constant(_I64, j), block)
            b.position_at_end(block)
            b.ret(b.call(callee, list(fn.args)))
    return module


_lock = threading.Lock()
_initialised: list[bool] = []


def _target_machine() -> Any:
    """A new target machine for this host (an execution engine owns and frees its own)."""
    with _lock:
        if not _initialised:
            try:
                llvm.initialize()
            except RuntimeError:  # llvmlite >= 0.45 initialises itself
                pass
            llvm.initialize_native_target()
            llvm.initialize_native_asmprinter()
            _initialised.append(True)
    target = llvm.Target.from_default_triple()
    features = llvm.get_host_cpu_features().flatten()
    return target.create_target_machine(
        cpu=llvm.get_host_cpu_name(), features=features, opt=3, reloc="pic", codemodel="default"
    )


LANE_WIDTH_ENV = "GRAZING_LANE_WIDTH"
"""An environment variable that narrows the lanes (2 or 4 doubles where the processor has more): the
vector code a processor with narrower registers runs, tested on this one."""


@functools.cache
def lane_width() -> int:
    """Doubles in this CPU's widest vector registers: 8 with AVX-512, 4 with AVX, else 2.

    ``GRAZING_LANE_WIDTH`` (:data:`LANE_WIDTH_ENV`) asks for fewer: 2, 4 or 8, at most the
    processor's; any other value is refused (a :class:`~grazing.errors.GrazingError`).

    Examples
    --------
    >>> lane_width() in (2, 4, 8)
    True
    """
    _target_machine()  # (initialises LLVM)
    features = llvm.get_host_cpu_features()
    widest = 8 if features.get("avx512f") else 4 if features.get("avx") else 2
    asked = os.environ.get(LANE_WIDTH_ENV, "").strip()
    if not asked:
        return widest
    allowed = [w for w in (2, 4, 8) if w <= widest]
    if asked not in [str(w) for w in allowed]:
        from grazing.errors import GrazingError

        lanes = " or ".join(map(str, allowed))
        raise GrazingError(f"{LANE_WIDTH_ENV}={asked!r}: this processor's lanes are {lanes} doubles wide")
    return int(asked)


def compile_object(module: ir.Module) -> bytes:
    """Optimise ``module`` (LLVM's O3 pipeline, no fast-math) and return its object file."""
    tm = _target_machine()
    module.data_layout = str(tm.target_data)
    parsed = llvm.parse_assembly(str(module))
    parsed.verify()
    pb = llvm.create_pass_builder(tm, llvm.create_pipeline_tuning_options(3))
    pb.getModulePassManager().run(parsed, pb)
    return tm.emit_object(parsed)


_CFUNC = ctypes.CFUNCTYPE(ctypes.c_double, *C_SIGNATURE)


class Library:
    """Machine code loaded into this process: the addresses of its functions and Python callers.

    The engine that holds the code lives as long as this object; the Python
    callers keep it alive.
    """

    def __init__(self, obj: bytes, prefix: str) -> None:
        tm = _target_machine()
        self.prefix = prefix
        self._engine = llvm.create_mcjit_compiler(llvm.parse_assembly(""), tm)
        self._engine.add_object_file(llvm.ObjectFileRef.from_data(obj))
        self._engine.finalize_object()
        self._callers: dict[str, Callable[..., float]] = {}

    def address(self, name: str) -> int:
        """Address of the function ``name`` (without the prefix); 0 if there is none."""
        return int(self._engine.get_function_address(f"{self.prefix}_{name}"))

    def function(self, name: str) -> Callable[..., float]:
        """A Python caller of ``name``: ``f(x, s, pv, *arrays[, j])``, arrays of C-ordered float64.

        Each array is passed as a pointer and must be C-contiguous float64
        (outputs are written in place); ``j`` (an int after the arrays) picks
        the stop of a per-stop function.
        """
        caller = self._callers.get(name)
        if caller is None:
            addr = self.address(name)
            if not addr:
                raise AttributeError(f"no compiled function {name!r}")
            cfunc = _CFUNC(addr)

            def caller(x: np.ndarray, s: float, pv: np.ndarray, *rest: Any) -> float:
                ptrs = [_pointer(x), float(s), _pointer(pv)]
                arrays = [r for r in rest if isinstance(r, np.ndarray)]
                j = [r for r in rest if not isinstance(r, np.ndarray)]
                ptrs += [_pointer(a) for a in arrays] + [None] * (ARITY - len(arrays))
                return cfunc(*ptrs, int(j[0]) if j else 0)

            caller.__name__ = name
            caller.library = self  # type: ignore[attr-defined]  # the code lives as long as its callers
            self._callers[name] = caller
        return caller


def _pointer(a: np.ndarray) -> int:
    if a.dtype != np.float64 or not a.flags.c_contiguous:
        raise TypeError("compiled model functions take C-contiguous float64 arrays")
    return a.ctypes.data


def compile_library(source: str, prefix: str, **kwargs: Any) -> Library:
    """Translate, compile and load ``source`` (see :func:`translate`) in one go."""
    return Library(compile_object(translate(source, prefix, **kwargs)), prefix)
