"""The sweep driver as machine code of its own, loaded without importing numba.

numba compiles the driver (:mod:`grazing.engine.driver`) once per machine and
caches it, but a process that uses it pays about half a second to import
numba and have it load that cache -- in every worker of every sweep, more
than the work of a small sweep.  So the sweep's entry point,
:func:`~grazing.engine.driver.lanes.sweep_lanes`, is also compiled once per
machine as a plain C function over pointers (a ``numba.cfunc``), and its
LLVM IR (the function and everything it calls) is turned into an object file
in the kernel cache.  A sweep loads that file with llvmlite, as it loads a
model's functions (:mod:`grazing.engine.llvmgen`), and calls it through
ctypes: the same machine code as numba's, the same numbers bit for bit.

numba's code calls a few C functions of numba's own: its memory allocator
(NRT, for the driver's work arrays) and, on the error path only, its
exception helpers.  They come from numba's extension modules, loaded by path
without importing the numba package (or from numba, if it is imported
already).

Examples
--------
>>> sweep = load_sweep_lanes()  # the driver's arguments; it writes the out_* arrays
>>> DRIVER_ARGUMENTS[:3], DRIVER_ARGUMENTS[-1]
(('m', 'lanes', 'jobs'), 'out_ok')
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
from typing import Any

import numpy as np

# The entry point's C arguments, in order: (name, kind).  Arrays are passed as pointers and
# their shapes as the integer arguments around them; ``m`` (the Kernels record) is spread out.
ARGUMENTS = (
    ("fns", "i64*"), ("nfns", "i64"), ("nx", "i64"), ("nsens", "i64"), ("nstops", "i64"),
    ("order", "i64"), ("sticks", "bool*"), ("mlanes", "i64"),
    ("lanes", "i64"), ("jobs", "i64*"), ("njobs", "i64"), ("fresh", "u8"), ("periodic", "u8"),
    ("x0", "f64*"), ("npts", "i64"), ("npv", "i64"), ("pvs", "f64*"), ("Ts", "f64*"),
    ("sphase", "f64*"), ("tcarry", "f64*"), ("zdms", "f64*"), ("transient", "i64"),
    ("periods", "i64"), ("adaptive", "u8"), ("lyapunov", "u8"), ("safety", "f64"),
    ("chatter_tol", "f64"), ("zdm_on", "u8"), ("zdm_a", "f64"), ("zdm_e", "f64*"),
    ("zdm_window", "f64"), ("watch", "i64"), ("out_samples", "f64*"), ("out_by_stop", "i64*"),
    ("out_lyap", "f64*"), ("out_used", "i64*"), ("out_x", "f64*"), ("out_t", "f64*"),
    ("out_ok", "i64*"),
)  # fmt: skip
DRIVER_ARGUMENTS = (
    "m", "lanes", "jobs", "fresh", "periodic", "x0", "pvs", "Ts", "sphase", "tcarry", "zdms", "transient",
    "periods", "adaptive", "lyapunov", "safety", "chatter_tol", "zdm_on", "zdm_a", "zdm_e", "zdm_window",
    "watch", "out_samples", "out_by_stop", "out_lyap", "out_used", "out_x", "out_t", "out_ok",
)  # fmt: skip
"""The arguments of :func:`grazing.engine.driver.lanes.sweep_lanes`; the loaded entry point takes them too."""
_CTYPES = {"i64": ctypes.c_int64, "u8": ctypes.c_uint8, "f64": ctypes.c_double}
_DTYPES = {"i64*": np.dtype(np.int64), "f64*": np.dtype(np.float64), "bool*": np.dtype(np.bool_)}
_PREFIX = "grazing_native"
_ENTRY = "sweep_lanes"
_DONE = 1
"""What the entry point returns when the sweep ran (numba's wrapper returns 0 after an exception)."""


def _entry_function(sweep: Callable[..., None]) -> Callable[..., int]:
    """The C entry point's Python source, for ``numba.cfunc``: pointers to arrays, then ``sweep``."""
    from numba import carray

    def entry(
        fns, nfns, nx, nsens, nstops, order, sticks, mlanes, lanes, jobs, njobs, fresh, periodic, x0,
        npts, npv, pvs, Ts, sphase, tcarry, zdms, transient, periods, adaptive, lyapunov, safety,
        chatter_tol, zdm_on, zdm_a, zdm_e, zdm_window, watch, out_samples, out_by_stop, out_lyap,
        out_used, out_x, out_t, out_ok,
    ):  # fmt: skip
        m = (carray(fns, (nfns,)), nx, nsens, nstops, order, carray(sticks, (nstops,)), mlanes)
        sweep(
            m, lanes, carray(jobs, (njobs, 2)), fresh != 0, periodic != 0, carray(x0, (nx,)),
            carray(pvs, (npts, npv)), carray(Ts, (npts,)), carray(sphase, (npts,)), carray(tcarry, (npts,)),
            carray(zdms, (npts,)), transient, periods, adaptive != 0, lyapunov != 0, safety, chatter_tol,
            zdm_on != 0, zdm_a, carray(zdm_e, (nx,)), zdm_window, watch,
            carray(out_samples, (npts, periods, nx)), carray(out_by_stop, (npts, nstops)),
            carray(out_lyap, (npts,)), carray(out_used, (npts,)), carray(out_x, (npts, nx)),
            carray(out_t, (npts,)), carray(out_ok, (npts,)),
        )  # fmt: skip
        return _DONE

    return entry


def _numba_signature() -> Any:
    from numba import types

    kinds = {
        "i64": types.int64, "u8": types.uint8, "f64": types.float64, "i64*": types.CPointer(types.int64),
        "f64*": types.CPointer(types.float64), "bool*": types.CPointer(types.boolean),
    }  # fmt: skip
    return types.int64(*(kinds[kind] for _, kind in ARGUMENTS))


def object_file(compiled: Any, name: str) -> bytes:
    """The cache file of the ``numba.cfunc`` ``compiled``: a JSON line (the C symbols it needs), its object.

    The entry point is named ``{_PREFIX}_{name}`` in the object file.
    """
    import llvmlite.binding as llvm

    module = llvm.parse_assembly(compiled.inspect_llvm())
    module.get_function(compiled.native_name).name = f"{_PREFIX}_{name}"
    needs = sorted(
        {f.name for f in module.functions if f.is_declaration and not f.name.startswith("llvm.")}
        | {g.name for g in module.global_variables if g.is_declaration}
    )
    return json.dumps({"symbols": needs}).encode() + b"\n" + _jit_target_machine().emit_object(module)


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
    """The cache file of the sweep driver's entry point (numba compiles the driver or loads its cache)."""
    from numba import cfunc

    from grazing.engine.codegen import load_driver

    return object_file(cfunc(_numba_signature())(_entry_function(load_driver().sweep_lanes)), _ENTRY)


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


def _resolvable(name: str, math_helpers: dict[str, int]) -> bool:
    import llvmlite.binding as llvm

    if name in math_helpers:  # (bound to the C library's function, as numba binds them)
        llvm.add_symbol(name, math_helpers[name])
    if llvm.address_of_symbol(name):
        return True
    try:
        getattr(ctypes.CDLL(None), name)  # (in this process: Python's C API, the C library)
    except AttributeError:
        return False
    return True


def _caller(address: int, keep: Any) -> Callable[..., None]:
    """A Python function with the arguments of ``driver.lanes.sweep_lanes``, calling the entry point."""
    cfunc = ctypes.CFUNCTYPE(ctypes.c_int64, *(_CTYPES.get(kind, ctypes.c_void_p) for _, kind in ARGUMENTS))(
        address
    )

    def sweep_lanes(*arguments: Any) -> None:
        if len(arguments) != len(DRIVER_ARGUMENTS):
            raise TypeError(f"sweep driver: {len(DRIVER_ARGUMENTS)} arguments expected, got {len(arguments)}")
        values = dict(zip(DRIVER_ARGUMENTS, arguments, strict=True))
        fns, nx, nsens, nstops, order, sticks, mlanes = values.pop("m")
        npts, npv = values["pvs"].shape
        periods = values["periods"]
        values.update(
            fns=fns, nfns=fns.shape[0], nx=nx, nsens=nsens, nstops=nstops, order=order, sticks=sticks,
            mlanes=mlanes, njobs=values["jobs"].shape[0], npts=npts, npv=npv,
        )  # fmt: skip
        shapes = {
            "fns": (values["nfns"],), "sticks": (nstops,), "jobs": (values["njobs"], 2), "x0": (nx,),
            "pvs": (npts, npv), "Ts": (npts,), "sphase": (npts,), "tcarry": (npts,), "zdms": (npts,),
            "zdm_e": (nx,), "out_samples": (npts, periods, nx), "out_by_stop": (npts, nstops),
            "out_lyap": (npts,), "out_used": (npts,), "out_x": (npts, nx), "out_t": (npts,),
            "out_ok": (npts,),
        }  # fmt: skip
        args = []
        for name, kind in ARGUMENTS:
            value = values[name]
            if kind in _DTYPES:
                a = value
                if a.dtype != _DTYPES[kind] or not a.flags.c_contiguous or a.shape != shapes[name]:
                    want = f"a C-contiguous {_DTYPES[kind]} array of shape {shapes[name]}"
                    raise TypeError(f"sweep driver: {name} must be {want}")
                if name.startswith("out_") and not a.flags.writeable:
                    raise TypeError(f"sweep driver: {name} must be writeable")
                args.append(a.ctypes.data)
            else:
                args.append(value)
        if cfunc(*args) != _DONE:
            raise RuntimeError("the compiled sweep driver raised an error (its message is above)")

    sweep_lanes.library = keep  # type: ignore[attr-defined]  # (the machine code lives as long as this)
    return sweep_lanes


@functools.cache
def load_sweep_lanes() -> Callable[..., None]:
    """The sweep driver's entry point, loaded from the kernel cache (compiled by numba the first time).

    The returned function takes the arguments of
    :func:`grazing.engine.driver.lanes.sweep_lanes`.  If numba's runtime
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


def load_object(data: bytes, name: str) -> tuple[int, Any] | None:
    """Load a cache file of :func:`object_file`: the address of its entry point ``name`` and the code's owner.

    ``None`` if a C function the code calls cannot be found.
    """
    from grazing.engine.llvmgen import Library

    header, obj = data.split(b"\n", 1)
    symbols = list(json.loads(header)["symbols"])
    _register_numba_runtime()
    math_helpers = dict(_numba_extension("numba._helperlib").c_helpers)
    if not all(_resolvable(s, math_helpers) for s in symbols):
        return None
    library = Library(obj, _PREFIX)
    address = library.address(name)
    if not address:
        raise OSError(f"no function {name} in the object file")
    return address, library
