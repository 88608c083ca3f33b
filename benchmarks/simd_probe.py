"""Can the Taylor recurrences run on SIMD lanes (one parameter value per lane)?  A measured probe.

Issue 15 asks for several sweep points integrated in lockstep lanes.  This
script takes the pendulum's generated free-flight kernel (``tc_free``: the
Taylor coefficients of the solution and of the guards, straight-line code)
and times three ways of computing it for ``L`` states at once, per lane:

1. ``numba scalar``: the kernel's text compiled by numba (the engine's kernels before
   issue 15) called once per lane (the reference); and the engine's own scalar kernel
   (compiled from the same text through LLVM IR by :mod:`grazing.engine.llvmgen`), called
   from numba through its address;
2. ``numba lanes``: the same straight-line body inside ``for l in range(L)``
   with lane-contiguous arrays (``X[i, k, l]``) -- what an attempt in numba
   looks like.  The assembly shows whether LLVM vectorised it (packed
   ``vmulpd`` on ymm/zmm registers) or not (scalar ``vmulsd``);
3. ``llvmlite vectors``: the same operations emitted directly as LLVM IR on
   ``<L x double>`` values (``noalias`` pointers, ``llvm.sin``/``llvm.cos``
   on vectors), compiled by llvmlite's JIT -- heyoka's approach -- and called
   from numba through its address.

It checks that the lane results are bit-identical to the scalar kernel and
prints times, the packed/scalar instruction counts and the compile time.

Run::

    python benchmarks/simd_probe.py          # L = 4 and 8

Findings on the 2-core AVX-512 machine of benchmarks/README.md (order 20): the engine's
scalar kernel is bit-identical to numba's and 1.1-1.25x faster;
numba does not vectorise the lane loop -- no packed multiply for L = 4 or 8,
0.43-1.1x per lane (the earlier attempt's 0.6-0.9x), 1.2x with ``fastmath``
only by contracting to scalar FMAs, which changes the results.  The llvmlite
kernel is vectorised (ymm for L = 4, zmm for L = 8), bit-identical to the
scalar kernel, 3.1-3.7x faster per lane, and compiles in 0.12-0.16 s (numba:
about 3 s for this one function).
"""

from __future__ import annotations

import ast
import ctypes
import math
import re
import sys
import time
from types import SimpleNamespace

import llvmlite.binding as llvm
import llvmlite.ir as ir
import numpy as np
from numba import njit

import grazing
from grazing.engine.abi import call_model
from grazing.engine.codegen import generate_source

ORDER = 20


def kernel_body(model: grazing.HybridModel) -> tuple[str, list[str]]:
    """The generated ``tc_free`` of ``model``: its source, and its body's statements."""
    src = generate_source(model._def.system, 0, ORDER).text
    start = src.index("def tc_free")
    end = src.index("\ndef ", start + 1)
    text = src[start:end]
    body = [s.strip() for s in text.splitlines()[1:] if s.strip() and s.strip() != "return"]
    return text, body


def numba_lanes(body: list[str], L: int, fastmath: bool):
    """The straight-line body inside a loop over lanes, compiled by numba."""
    lines = [
        "def tc_lanes(x0, s0, pv, X, O):",
        f"    for l in range({L}):",
    ]
    for s in body:
        s = re.sub(r"x0\[(\d+)\]", r"x0[\1, l]", s)
        s = re.sub(r"\bs0\b", "s0[l]", s)
        s = re.sub(r"^([XO])\[(\d+), (\d+)\] =", r"\1[\2, \3, l] =", s)
        lines.append("        " + s)
    ns: dict = {"math": math}
    exec("\n".join(lines), ns)  # our own generated code
    return njit(fastmath=fastmath, boundscheck=False, error_model="numpy")(ns["tc_lanes"])


def llvm_lanes(body: list[str], L: int, n_rows: int, n_guards: int) -> SimpleNamespace:
    """The body emitted as LLVM IR on ``<L x double>`` values and compiled by llvmlite."""
    dbl = ir.DoubleType()
    vec = ir.VectorType(dbl, L)
    ptr = dbl.as_pointer()
    i64 = ir.IntType(64)
    mod = ir.Module(name="tc_lanes")
    mod.triple = llvm.get_process_triple()
    fn = ir.Function(mod, ir.FunctionType(ir.VoidType(), [ptr, ptr, ptr, ptr, ptr]), name="tc_lanes")
    for arg in fn.args:
        arg.add_attribute("noalias")
    x0, s0, pv, X, O = fn.args
    b = ir.IRBuilder(fn.append_basic_block())
    intrinsics = {
        f: ir.Function(mod, ir.FunctionType(vec, [vec]), name=f"llvm.{f}.v{L}f64") for f in ("sin", "cos")
    }
    k1 = ORDER + 1

    def at(p, off):
        return b.bitcast(b.gep(p, [ir.Constant(i64, off)]), vec.as_pointer())

    def splat(v):
        out = ir.Constant(vec, ir.Undefined)
        for i in range(L):
            out = b.insert_element(out, v, ir.Constant(ir.IntType(32), i))
        return out

    env: dict[str, tuple[str, ir.Value]] = {}

    def ev(node) -> tuple[str, ir.Value]:  # ("s", scalar) or ("v", vector)
        if isinstance(node, ast.Constant):
            return "s", ir.Constant(dbl, float(node.value))
        if isinstance(node, ast.Name):
            if node.id == "s0":
                return "v", b.load(at(s0, 0), align=8)
            return env[node.id]
        if isinstance(node, ast.Attribute) and node.attr == "pi":
            return "s", ir.Constant(dbl, math.pi)
        if isinstance(node, ast.Subscript):
            i = node.slice.value
            if node.value.id == "pv":
                return "s", b.load(b.gep(pv, [ir.Constant(i64, i)]))
            return "v", b.load(at(x0, i * L), align=8)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            k, v = ev(node.operand)
            return k, b.fneg(v)
        if isinstance(node, ast.Call):
            k, v = ev(node.args[0])
            return "v", b.call(intrinsics[node.func.attr], [splat(v) if k == "s" else v])
        if isinstance(node, ast.BinOp):
            (ka, a), (kc, c) = ev(node.left), ev(node.right)
            if ka != kc:
                a, c = (splat(a), c) if ka == "s" else (a, splat(c))
            op = {ast.Add: b.fadd, ast.Sub: b.fsub, ast.Mult: b.fmul, ast.Div: b.fdiv}[type(node.op)]
            return ("s" if ka == kc == "s" else "v"), op(a, c)
        raise ValueError(f"unexpected generated code: {ast.dump(node)}")

    for s in body:
        stmt = ast.parse(s).body[0]
        target = stmt.targets[0]
        if isinstance(target, ast.Subscript):
            i, k = (e.value for e in target.slice.elts)
            kind, v = ev(stmt.value)
            b.store(splat(v) if kind == "s" else v, at(X if target.value.id == "X" else O, (i * k1 + k) * L),
                    align=8)  # fmt: skip
        else:
            env[target.id] = ev(stmt.value)
    b.ret_void()
    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    t = time.perf_counter()
    parsed = llvm.parse_assembly(str(mod))
    parsed.verify()
    tm = llvm.Target.from_default_triple().create_target_machine(
        cpu=llvm.get_host_cpu_name(), features=llvm.get_host_cpu_features().flatten(), opt=3
    )
    pb = llvm.create_pass_builder(tm, llvm.create_pipeline_tuning_options(3))
    pb.getModulePassManager().run(parsed, pb)
    engine = llvm.create_mcjit_compiler(parsed, tm)
    engine.finalize_object()
    seconds = time.perf_counter() - t
    addr = engine.get_function_address("tc_lanes")
    vp = ctypes.c_void_p
    return SimpleNamespace(
        fn=ctypes.CFUNCTYPE(None, vp, vp, vp, vp, vp)(addr), engine=engine, asm=tm.emit_assembly(parsed),
        seconds=seconds,
    )  # fmt: skip


def counts(asm: str) -> str:
    return (
        f"packed vmulpd {asm.count('vmulpd')}, scalar vmulsd {asm.count('vmulsd')}, "
        f"zmm {asm.count('zmm')}, ymm {asm.count('ymm')}"
    )


def best_of(f, repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def time_numba_lanes(body, L, fastmath, x0, s0, pv, ref, reps) -> tuple[float, float, bool, str]:
    """Seconds for ``reps`` calls of the numba lane loop, its compile time, bit-identity, assembly."""
    lanes = numba_lanes(body, L, fastmath)
    X, O = np.zeros((x0.shape[0], ORDER + 1, L)), np.zeros((ref[0][1].shape[0], ORDER + 1, L))

    @njit
    def run_lanes(reps, x0, s0, pv, X, O):
        for _ in range(reps):
            lanes(x0, s0, pv, X, O)

    t = time.perf_counter()
    run_lanes(1, x0, s0, pv, X, O)
    compile_s = time.perf_counter() - t
    same = all(np.array_equal(X[:, :, i], ref[i][0]) for i in range(L))
    seconds = best_of(lambda: run_lanes(reps, x0, s0, pv, X, O))
    return seconds, compile_s, same, lanes.inspect_asm(lanes.signatures[0])


def probe(L: int) -> None:
    model = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    text, body = kernel_body(model)
    ns: dict = {"math": math}
    exec(text, ns)  # our own generated code
    tc = njit(ns["tc_free"])  # numba compiling the kernel's text (the engine's kernels before issue 15)
    engine_addr = model.kernels(0, ORDER).library.address("tc_free")  # the engine's kernel (llvmlite)
    n, n_guards, k1 = model.n_states, model.n_stops, ORDER + 1
    rng = np.random.default_rng(1)
    pv = model.param_vector.copy()
    x0 = np.ascontiguousarray(rng.uniform(-0.5, 0.5, (n, L)))
    s0 = rng.uniform(0, 2 * math.pi, L)
    Xs, Os = np.zeros((n, k1)), np.zeros((n_guards, k1))
    ref = []
    for lane in range(L):
        tc(x0[:, lane].copy(), s0[lane], pv, Xs, Os)
        ref.append((Xs.copy(), Os.copy()))

    @njit
    def run_scalar(reps, x0, s0, pv, Xs, Os):
        xl = np.empty(x0.shape[0])
        for _ in range(reps):
            for lane in range(x0.shape[1]):
                for i in range(x0.shape[0]):
                    xl[i] = x0[i, lane]
                tc(xl, s0[lane], pv, Xs, Os)

    @njit
    def run_engine(reps, addr, x0, s0, pv, Xs, Os):
        xl = np.empty(x0.shape[0])
        for _ in range(reps):
            for lane in range(x0.shape[1]):
                for i in range(x0.shape[0]):
                    xl[i] = x0[i, lane]
                call_model(addr, xl, s0[lane], pv, Xs, Os, None, 0)

    reps = 200_000 // L
    run_scalar(1, x0, s0, pv, Xs, Os)
    t_scalar = best_of(lambda: run_scalar(reps, x0, s0, pv, Xs, Os))
    print(f"L = {L}: numba scalar kernel, once per lane: {t_scalar / (reps * L) * 1e9:6.1f} ns per lane")
    Xe, Oe = np.zeros_like(Xs), np.zeros_like(Os)
    run_engine(1, engine_addr, x0[:, -1:].copy(), s0[-1:], pv, Xe, Oe)
    same = np.array_equal(Xe, ref[-1][0]) and np.array_equal(Oe, ref[-1][1])
    t_engine = best_of(lambda: run_engine(reps, engine_addr, x0, s0, pv, Xs, Os))
    print(f"       engine's scalar kernel (llvmlite): {t_engine / (reps * L) * 1e9:6.1f} ns per lane, "
          f"{t_scalar / t_engine:.2f}x; bit-identical {same}")  # fmt: skip

    for fastmath in (False, True):
        t_l, compile_s, same, asm = time_numba_lanes(body, L, fastmath, x0, s0, pv, ref, reps)
        print(f"       numba lanes (fastmath={fastmath!s:5}): {t_l / (reps * L) * 1e9:6.1f} ns per lane, "
              f"{t_scalar / t_l:.2f}x; compiled in {compile_s:.1f} s; bit-identical {same};\n"
              f"           {counts(asm)}")  # fmt: skip

    k = llvm_lanes(body, L, n, n_guards)
    X, O = np.zeros((n, k1, L)), np.zeros((n_guards, k1, L))
    fn = k.fn

    @njit
    def run_llvm(reps, x0, s0, pv, X, O):
        for _ in range(reps):
            fn(x0.ctypes.data, s0.ctypes.data, pv.ctypes.data, X.ctypes.data, O.ctypes.data)

    run_llvm(1, x0, s0, pv, X, O)
    same = all(
        np.array_equal(X[:, :, i], ref[i][0]) and np.array_equal(O[:, :, i], ref[i][1]) for i in range(L)
    )
    t_v = best_of(lambda: run_llvm(reps, x0, s0, pv, X, O))
    print(f"       llvmlite vectors:            {t_v / (reps * L) * 1e9:6.1f} ns per lane, "
          f"{t_scalar / t_v:.2f}x; compiled in {k.seconds:.2f} s; bit-identical {same};\n"
          f"           {counts(k.asm)}")  # fmt: skip


if __name__ == "__main__":
    for lanes in [int(a) for a in sys.argv[1:]] or [4, 8]:
        probe(lanes)
