"""The sweep driver as machine code of its own, loaded without importing numba.

numba compiles the driver (:mod:`grazing.engine.driver`) once per machine and
caches it, but a process that uses it pays about half a second to import
numba and have it load that cache -- in every worker of every sweep, more
than the work of a small sweep.  So the sweep's entry point,
:func:`~grazing.engine.driver.lanes.sweep_lanes`, is compiled by numba once
per machine and its LLVM IR (the function and everything it calls, as numba
optimised it) becomes an object file in the kernel cache, with a small entry
function added that takes the function's arguments from an array of 64-bit
slots.  A sweep loads that file with llvmlite, as it loads a model's
functions (:mod:`grazing.engine.llvmgen`), and calls it through ctypes: the
machine code numba would run, the same numbers bit for bit.

numba's code calls a few C functions of numba's own: its memory allocator
(NRT, for the driver's work arrays) and, on the error path only, its
exception helpers.  They come from numba's extension modules, loaded by path
without importing the numba package (or from numba, if it is imported
already).  Should the code report an error, the call is repeated with numba's
own compiled function, which raises the error as a Python exception.

Examples
--------
>>> sweep = load_sweep_lanes()  # the driver's arguments (records.SWEEP_RECORDS); it writes the results
>>> [label for label, kind, spec in _layout()][:3]
['Kernels.fns', 'Kernels.nx', 'Kernels.nsens']
"""

from __future__ import annotations

import ctypes
import functools
import importlib.machinery
import importlib.util
import json
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Annotated, Any

import numpy as np

_PREFIX = "grazing_native"
_ENTRY = "sweep_lanes"
_RETURNED = (0, -2)
"""numba's status codes of a function that returned (OK, None); the others report an exception."""


def _layout() -> list[tuple[str, str, Any]]:
    """The sweep driver's arguments, field by field: ``(record.field, kind, dtype and dimensions)``.

    Derived from the annotations of :data:`grazing.engine.records.SWEEP_RECORDS`:
    an array field is annotated with its dtype and dimensions, the others are
    ``int``, ``float`` or ``bool``.
    """
    from typing import get_args, get_origin, get_type_hints

    from grazing.engine.records import SWEEP_RECORDS

    fields = []
    for record in SWEEP_RECORDS:
        for name, hint in get_type_hints(record, include_extras=True).items():
            label = f"{record.__name__}.{name}"
            if get_origin(hint) is Annotated:
                fields.append((label, "array", get_args(hint)[1]))
            elif hint in (int, float, bool):
                fields.append((label, hint.__name__, None))
            else:  # pragma: no cover - a record field the driver cannot take
                raise TypeError(f"sweep driver: {label} has a type the machine code cannot take: {hint}")
    return fields


def _signature() -> Any:
    """The numba signature of ``sweep_lanes``: a tuple of its fields' types per record."""
    from numba import types

    from grazing.engine.records import SWEEP_RECORDS

    scalar = {"i8": types.int64, "f8": types.float64, "?": types.boolean}
    kinds = {"int": types.int64, "float": types.float64, "bool": types.boolean}
    of = {
        label: types.Array(scalar[spec[0]], spec[1], "C") if kind == "array" else kinds[kind]
        for label, kind, spec in _layout()
    }
    return tuple(
        types.Tuple([of[f"{record.__name__}.{name}"] for name in record._fields]) for record in SWEEP_RECORDS
    )


def _slot_loads(types_: list[str]) -> tuple[list[str], list[str]]:
    """LLVM IR lines loading one argument of each type in ``types_`` from ``%slots``; and the arguments."""
    lines, args = [], []
    for i, ty in enumerate(types_):
        lines.append(f"  %p{i} = getelementptr inbounds i64, ptr %slots, i64 {i}")
        lines.append(f"  %s{i} = load i64, ptr %p{i}, align 8")
        if ty == "i64":
            args.append(f"i64 %s{i}")
            continue
        cast = {"ptr": "inttoptr", "double": "bitcast", "i8": "trunc", "i32": "trunc", "i1": "trunc"}.get(ty)
        if cast is None:
            raise TypeError(f"an argument of type {ty} cannot come from a 64-bit slot")
        lines.append(f"  %a{i} = {cast} i64 %s{i} to {ty}")
        args.append(f"{ty} %a{i}")
    return lines, args


_REFCOUNTS = {
    "NRT_incref": (
        "  %null = icmp eq ptr %m, null\n  br i1 %null, label %done, label %add\n"
        "add:\n  %c = load i64, ptr %m, align 8\n  %c1 = add i64 %c, 1\n  store i64 %c1, ptr %m, align 8\n"
        "  br label %done\ndone:\n  ret void\n"
    ),
    "NRT_decref": (
        "  %null = icmp eq ptr %m, null\n  br i1 %null, label %done, label %sub\n"
        "sub:\n  %c = load i64, ptr %m, align 8\n  %c1 = sub i64 %c, 1\n  store i64 %c1, ptr %m, align 8\n"
        "  %zero = icmp eq i64 %c1, 0\n  br i1 %zero, label %free, label %done\n"
        "free:\n  call void @NRT_MemInfo_call_dtor(ptr %m)\n  br label %done\ndone:\n  ret void\n"
    ),
}


def plain_reference_counts(text: str) -> str:
    """numba's LLVM IR ``text`` with reference counts kept by plain (not atomic) adds.

    numba counts the references to each array it allocates with atomic
    instructions (an array may be shared between threads), about 20 cycles
    each, and a numba function increments and decrements the count of each
    array it is given: the sweep driver's pieces, given the lanes' arrays,
    spent a fifth of its time on them.  In the driver's machine code no
    count is shared between threads: the arrays it is given come without a
    memory manager (:func:`flatten`: a null pointer, whose count is never
    touched) and those it allocates are its own thread's, so plain adds count
    the same.  They are inlined where they are called (:func:`object_file`
    runs LLVM's always-inliner, which touches nothing else).  The text is
    returned unchanged if numba's definitions are not found (they stay atomic).
    """
    import re

    for name, body in _REFCOUNTS.items():
        pattern = rf"^define linkonce_odr void @{name}\(ptr[^%\n]*%([\w.]+)\)([^{{\n]*)\{{\n.*?^\}}\n"
        found = re.search(pattern, text, flags=re.M | re.S)
        if found is None or "NRT_MemInfo_call_dtor" not in text:
            return text
        head = f"define linkonce_odr void @{name}(ptr %m) alwaysinline nounwind {{\nentry:\n"
        text = text[: found.start()] + head + body + "}\n" + text[found.end() :]
    return text


def object_file(dispatcher: Any, signature: tuple[Any, ...], name: str) -> bytes:
    """The cache file of a numba function compiled for ``signature``: a JSON line, then an object file.

    The object file holds numba's LLVM IR of the function (and of everything it
    calls, as numba optimised it, not optimised again) and an entry function
    ``{_PREFIX}_{name}(int64 *slots) -> int64``: numba's status code, the
    function's flattened arguments read from ``slots``.  ``dispatcher`` must
    not come from numba's on-disk cache (whose IR numba does not keep).  The
    JSON line lists the C symbols the code needs and the arguments' LLVM types.
    """
    import llvmlite.binding as llvm

    dispatcher.compile(signature)
    text = plain_reference_counts(dispatcher.inspect_llvm(signature))
    module = llvm.parse_assembly(text)
    target = module.get_function(dispatcher.overloads[signature].fndesc.llvm_func_name)
    params = [str(a.type) for a in target.arguments][2:]  # (after the return slot and the exception info)
    lines, args = _slot_loads(params)
    entry = "\n".join(
        [
            f"define i64 @{_PREFIX}_{name}(ptr %slots) {{",
            "entry:",
            "  %ret = alloca [8 x i64], align 8",
            "  %exc = alloca ptr, align 8",
            "  store ptr null, ptr %exc, align 8",
            *lines,
            f'  %status = call i32 @"{target.name}"(ptr %ret, ptr %exc, {", ".join(args)})',
            "  %code = sext i32 %status to i64",
            "  ret i64 %code",
            "}",
        ]
    )
    wrapper = llvm.parse_assembly(
        f'target triple = "{module.triple}"\ntarget datalayout = "{module.data_layout}"\n'
        f'declare i32 @"{target.name}"(ptr, ptr, {", ".join(params)})\n{entry}\n'
    )
    module.link_in(wrapper)
    passes = llvm.create_new_module_pass_manager()
    passes.add_always_inliner_pass()  # (only the counts above: numba's own code is not optimised again)
    tuning = llvm.create_pipeline_tuning_options(0)
    passes.run(module, llvm.create_pass_builder(_jit_target_machine(), tuning))
    needs = sorted(
        {f.name for f in module.functions if f.is_declaration and not f.name.startswith("llvm.")}
        | {g.name for g in module.global_variables if g.is_declaration}
    )
    header = json.dumps({"symbols": needs, "params": params}).encode()
    return header + b"\n" + _jit_target_machine().emit_object(module)


def _jit_target_machine() -> Any:
    """A target machine with the options numba's JIT uses (static relocations, the JIT's code model)."""
    import llvmlite.binding as llvm

    from grazing.engine.llvmgen import _target_machine

    _target_machine()  # (initialises LLVM's native target)
    return llvm.Target.from_default_triple().create_target_machine(
        cpu=llvm.get_host_cpu_name(), features=llvm.get_host_cpu_features().flatten(), opt=3,
        reloc="static", codemodel="jitdefault", jit=True,
    )  # fmt: skip


def build() -> bytes:
    """The cache file of the sweep driver (numba compiles ``sweep_lanes``, which it does not cache)."""
    from grazing.engine.codegen import load_driver

    return object_file(load_driver().sweep_lanes, _signature(), _ENTRY)


def cache_key() -> str:
    """Key of the entry point's cache file: the driver's key, this module, llvmlite's version and this CPU."""
    import llvmlite
    import llvmlite.binding as llvm

    from grazing.engine.codegen import _key, driver_key
    from grazing.engine.llvmgen import _target_machine

    _target_machine()  # (initialises LLVM's native target)
    cpu = (llvm.get_host_cpu_name(), llvm.get_host_cpu_features().flatten())
    return _key(driver_key(), Path(__file__).read_text(), llvmlite.__version__, cpu)


def _numba_extension(name: str) -> ModuleType:
    """numba's extension module ``name`` (e.g. ``numba._helperlib``), without importing numba.

    A module loaded here is registered under its own name, so that numba, if
    imported later, uses it rather than initialising it a second time.
    """
    module = sys.modules.get(name)
    if module is not None:
        return module
    spec = importlib.util.find_spec("numba")
    if spec is None or spec.origin is None:  # pragma: no cover - numba is a dependency
        raise ImportError("numba is not installed")
    *parts, last = name.split(".")[1:]
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = Path(spec.origin).parent.joinpath(*parts, last + suffix)
        if path.exists():
            break
    else:  # pragma: no cover
        raise ImportError(f"numba's extension module {name} is missing")
    loader = importlib.machinery.ExtensionFileLoader(name, str(path))
    module_spec = importlib.util.spec_from_file_location(name, path, loader=loader)
    assert module_spec is not None
    module = importlib.util.module_from_spec(module_spec)
    loader.exec_module(module)
    sys.modules[name] = module
    return module


@functools.cache
def _register_numba_runtime() -> None:
    """Give LLVM the addresses of numba's C helpers, under the names numba's code calls them by."""
    import builtins

    import llvmlite.binding as llvm

    helpers = _numba_extension("numba._helperlib")
    nrt = _numba_extension("numba.core.runtime._nrt_python")
    if "numba.core.runtime.nrt" not in sys.modules:
        nrt.memsys_use_cpython_allocator()  # (what numba does when it sets up its runtime)
    for name, address in helpers.c_helpers.items():
        llvm.add_symbol("numba_" + name, address)
    for name, address in nrt.c_helpers.items():
        llvm.add_symbol(name if name.startswith("_") else "NRT_" + name, address)
    llvm.add_symbol("_Py_NoneStruct", id(None))
    for obj in vars(builtins).values():
        if isinstance(obj, type) and issubclass(obj, BaseException):
            llvm.add_symbol("PyExc_" + obj.__name__, id(obj))


def _resolvable(name: str) -> bool:
    """Whether machine code loaded now finds the C symbol ``name``."""
    import llvmlite.binding as llvm

    if llvm.address_of_symbol(name):
        return True
    try:
        getattr(ctypes.CDLL(None), name)  # (in this process: Python's C API, the C library)
    except AttributeError:
        return False
    return True


def _shapes(values: dict[str, Any]) -> dict[str, tuple[int, ...]]:
    """The shape each array field must have, from the sizes the others give (the driver does not check)."""
    nx, nstops = values["Kernels.nx"], values["Kernels.nstops"]
    npts, njobs = values["LanePoints.pvs"].shape[0], values["LaneJobs.jobs"].shape[0]
    per_point = ("LanePoints.Ts", "LanePoints.sphase", "LanePoints.tcarry", "LanePoints.zdms")
    per_point += ("LaneResults.lyap", "LaneResults.used", "LaneResults.t", "LaneResults.status")
    return {
        **{name: (npts,) for name in per_point}, "Kernels.fns": values["Kernels.fns"].shape,
        "Kernels.sticks": (nstops,), "LaneJobs.jobs": (njobs, 2), "LaneJobs.control": (3,),
        "LaneJobs.x0": (njobs, nx), "LaneJobs.firsts": (njobs, nx + 1),
        "LanePoints.pvs": values["LanePoints.pvs"].shape,
        "LaneSettings.zdm_e": (nx,), "LaneResults.samples": (npts, values["LaneSettings.periods"], nx),
        "LaneResults.by_stop": (npts, nstops), "LaneResults.x": (npts, nx),
    }  # fmt: skip


def flatten(arguments: tuple[Any, ...]) -> tuple[np.ndarray, list[str]]:
    """``sweep_lanes``'s arguments as numba passes them: 64-bit slots and their LLVM types.

    The arguments are the records of :data:`grazing.engine.records.SWEEP_RECORDS`
    (or plain tuples of their fields), each passed field by field: an array as
    its memory manager (none), parent (none), size, item size, data pointer,
    shape and strides; a boolean as a byte.  Arrays of another dtype,
    dimension, shape or layout than the driver takes are refused
    (``TypeError``).
    """
    from grazing.engine.records import SWEEP_RECORDS

    if len(arguments) != len(SWEEP_RECORDS):
        raise TypeError(f"sweep driver: {len(SWEEP_RECORDS)} arguments expected, got {len(arguments)}")
    values: dict[str, Any] = {}
    for record, value in zip(SWEEP_RECORDS, arguments, strict=True):
        if not isinstance(value, tuple) or len(value) != len(record._fields):
            raise TypeError(f"sweep driver: a {record.__name__} ({len(record._fields)} fields) expected")
        values.update((f"{record.__name__}.{name}", v) for name, v in zip(record._fields, value, strict=True))
    shapes = _shapes(values)
    slots: list[int] = []
    kinds: list[str] = []
    for label, kind, spec in _layout():
        value = values[label]
        if kind == "array":
            dtype, ndim = spec
            a = value
            ok = isinstance(a, np.ndarray) and a.dtype == np.dtype(dtype) and a.ndim == ndim
            if not (ok and a.flags.c_contiguous and a.shape == shapes[label]):
                want = f"a C-contiguous {np.dtype(dtype)} array of shape {shapes[label]}"
                raise TypeError(f"sweep driver: {label} must be {want}")
            if label.startswith("LaneResults.") and not a.flags.writeable:
                raise TypeError(f"sweep driver: {label} must be writeable")
            slots += [0, 0, a.size, a.itemsize, a.ctypes.data, *a.shape, *a.strides]
            kinds += ["ptr", "ptr", "i64", "i64", "ptr", *["i64"] * (2 * ndim)]
        elif kind == "bool":
            slots.append(1 if value else 0)
            kinds.append("i8")
        elif kind == "float":
            slots.append(int(np.float64(value).view(np.int64)))
            kinds.append("double")
        else:
            slots.append(int(value))
            kinds.append("i64")
    return np.array(slots, dtype=np.int64), kinds


def _caller(address: int, params: list[str], keep: Any) -> Callable[..., None]:
    """A Python function with the arguments of ``driver.lanes.sweep_lanes``, calling its machine code."""
    entry = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_void_p)(address)

    def sweep_lanes(*arguments: Any) -> None:
        slots, kinds = flatten(arguments)
        if kinds != params:  # pragma: no cover - a driver whose arguments changed without its cache key
            raise TypeError("sweep driver: the compiled code takes other arguments; clear the kernel cache")
        if entry(slots.ctypes.data) not in _RETURNED:  # pragma: no cover - the driver raised
            from grazing.engine.codegen import load_driver

            m, cfg, work, points, out = arguments
            work[1][1] = 1  # (the other threads of the call stop: LaneJobs.control)
            again = (work[0], np.zeros(3, dtype=np.int64), *work[2:])  # every job again, in this thread:
            load_driver().sweep_lanes(m, cfg, again, points, out)  # numba's function raises the error
            raise RuntimeError("the compiled sweep driver failed where numba's function did not")

    sweep_lanes.library = keep  # type: ignore[attr-defined]  # (the machine code lives as long as this)
    return sweep_lanes


@functools.cache
def load_sweep_lanes() -> Callable[..., None]:
    """The sweep driver's entry point, loaded from the kernel cache (compiled by numba the first time).

    The returned function takes the arguments of
    :func:`grazing.engine.driver.lanes.sweep_lanes` (the records of
    :data:`grazing.engine.records.SWEEP_RECORDS`).  If numba's runtime
    cannot be given to the machine code (a numba that no longer provides a
    C helper), numba's own compiled function is returned instead.
    """
    from grazing.engine.codegen import _cached_file, load_driver

    name = f"grazing_native_{cache_key()}.bin"
    path = _cached_file(name, build)
    try:
        loaded = load_object(path.read_bytes(), _ENTRY)
    except (ValueError, KeyError, OSError, RuntimeError):  # a damaged cache file (ours): build it again
        path.unlink(missing_ok=True)
        loaded = load_object(_cached_file(name, build).read_bytes(), _ENTRY)
    if loaded is None:  # pragma: no cover - a numba whose C helpers we do not know
        return load_driver().sweep_lanes
    return _caller(*loaded)


def load_object(data: bytes, name: str) -> tuple[int, list[str], Any] | None:
    """Load a cache file of :func:`object_file`: its entry point's address, argument types and owner.

    ``None`` if a C function the code calls cannot be found.
    """
    import llvmlite.binding as llvm

    from grazing.engine.llvmgen import Library

    header, obj = data.split(b"\n", 1)
    meta = json.loads(header)
    symbols, params = list(meta["symbols"]), list(meta["params"])
    _register_numba_runtime()
    helpers = _numba_extension("numba._helperlib").c_helpers
    for symbol in symbols:
        if symbol in helpers:  # a C math function: bound to the C library's, as numba binds it
            llvm.add_symbol(symbol, helpers[symbol])
    if not all(_resolvable(symbol) for symbol in symbols):
        return None
    library = Library(obj, _PREFIX)
    address = library.address(name)
    if not address:
        raise OSError(f"no function {name} in the object file")
    return address, params, library
