"""The driver as machine code of its own, loaded without importing numba: the one compile pipeline.

numba compiles the driver (:mod:`grazing.engine.driver`), but a process that
uses numba's compiled functions pays about half a second to import numba and
have it load its cache -- in every command, and in every worker of every
sweep.  So each entry point of the driver (:data:`ENTRIES`: the sweep's
:func:`~grazing.engine.driver.lanes.sweep_lanes` and the scalar integrator
:func:`~grazing.engine.driver.loop.integrate`) is compiled by numba once per
machine and its LLVM IR (the function and everything it calls, as numba
optimised it) becomes an object file in the kernel cache, with a small entry
function added that takes the function's arguments from an array of 64-bit
slots, one per field of its records (an array's slot holds numpy's array
object, whose data pointer, shape and strides the entry function reads).  A
run loads that file with llvmlite, as it loads a model's functions
(:mod:`grazing.engine.llvmgen`), and calls it through ctypes: the machine
code numba would run, the same numbers bit for bit.  The argument layout
comes from the records' annotations (:mod:`grazing.engine.records`), and the
arguments are checked (dtype, dimensions, shape, layout) before any machine
code runs.

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
>>> [label for label, kind, spec in _layout(ENTRIES["integrate"])][:3]
['Start.x', 'Start.V', 'Start.k']
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
from typing import Annotated, Any, NamedTuple, NoReturn

import numpy as np

_PREFIX = "grazing_native"
_RETURNED = (0, -2)
"""numba's status codes of a function that returned (OK, None); the others report an exception."""


class Entry(NamedTuple):
    """A driver function compiled into an object file of its own, and the shapes of its arrays.

    The shapes are Python expressions over the arguments' fields, each named
    ``Record_field`` (``Kernels_nx``; an array of its own by its name) and
    over the sizes, which are such expressions themselves, in order.
    """

    name: str  # the function, in grazing.engine.driver
    arguments: tuple[Any, ...]  # its arguments: records (passed as plain tuples) or (name, annotated array)
    sizes: tuple[tuple[str, str], ...]  # (size, expression), e.g. ("nx", "Kernels_nx")
    shapes: tuple[tuple[str, str], ...]  # (array field, its shape), e.g. ("Start.x", "(nx,)"); unlisted: any


def _parts(argument: Any) -> tuple[str, list[tuple[str, Any]]]:
    """An argument's name and its fields' ``(label, type hint)``: a record's fields, or the array itself."""
    from typing import get_type_hints

    if isinstance(argument, tuple):
        name, hint = argument
        return name, [(name, hint)]
    hints = get_type_hints(argument, include_extras=True)
    return argument.__name__, [(f"{argument.__name__}.{field}", hints[field]) for field in argument._fields]


def _layout(entry: Entry | None = None) -> list[tuple[str, str, Any]]:
    """A driver function's arguments, field by field: ``(record.field, kind, dtype and dimensions)``.

    Derived from the annotations of its records (:data:`ENTRIES`; the sweep
    driver's by default): an array field is annotated with its dtype and
    dimensions, the others are ``int``, ``float`` or ``bool``.
    """
    from typing import get_args, get_origin

    fields = []
    for argument in (entry or ENTRIES["sweep_lanes"]).arguments:
        for label, hint in _parts(argument)[1]:
            if get_origin(hint) is Annotated:
                fields.append((label, "array", get_args(hint)[1]))
            elif hint in (int, float, bool):
                fields.append((label, hint.__name__, None))
            else:  # pragma: no cover - a record field the driver cannot take
                raise TypeError(f"driver: {label} has a type the machine code cannot take: {hint}")
    return fields


def _signature(entry: Entry) -> Any:
    """The numba signature of a driver function: a tuple of its fields' types per record, or an array."""
    from numba import types
    from numba.np.numpy_support import from_dtype

    kinds = {"int": types.int64, "float": types.float64, "bool": types.boolean}
    of = {
        label: types.Array(from_dtype(np.dtype(spec[0])), spec[1], "C") if kind == "array" else kinds[kind]
        for label, kind, spec in _layout(entry)
    }
    signature = []
    for argument in entry.arguments:
        labels = [label for label, _hint in _parts(argument)[1]]
        signature.append(
            of[labels[0]] if isinstance(argument, tuple) else types.Tuple([of[x] for x in labels])
        )
    return tuple(signature)


def _slot_load(i: int, ty: str) -> tuple[list[str], str]:
    """LLVM IR lines loading an argument of type ``ty`` from slot ``i`` of ``%slots``; and the argument."""
    lines = [f"  %p{i} = getelementptr inbounds i64, ptr %slots, i64 {i}"]
    lines.append(f"  %s{i} = load i64, ptr %p{i}, align 8")
    if ty == "i64":
        return lines, f"i64 %s{i}"
    cast = {"ptr": "inttoptr", "double": "bitcast", "i8": "trunc", "i32": "trunc", "i1": "trunc"}.get(ty)
    if cast is None:
        raise TypeError(f"an argument of type {ty} cannot come from a 64-bit slot")
    return [*lines, f"  %a{i} = {cast} i64 %s{i} to {ty}"], f"{ty} %a{i}"


def _slot_loads(types_: list[str]) -> tuple[list[str], list[str]]:
    """LLVM IR lines loading one argument of each type in ``types_`` from ``%slots``; and the arguments."""
    lines, args = [], []
    for i, ty in enumerate(types_):
        more, arg = _slot_load(i, ty)
        lines += more
        args.append(arg)
    return lines, args


NUMPY_ARRAY_FIELDS = {"data": 16, "nd": 24, "dimensions": 32, "strides": 40}
"""Byte offsets in numpy's array object (``PyArrayObject_fields``, the same in numpy 1 and 2) of the
fields the entry functions read; :func:`numpy_layout_holds` checks them in the running numpy."""


def _array_loads(i: int, ndim: int, itemsize: int) -> tuple[list[str], list[str]]:
    """LLVM IR lines reading the numpy array object in slot ``i`` as numba's array arguments; and those.

    numba passes an array as its memory manager (none here), parent (none),
    size, item size, data pointer, shape and strides; here the data pointer,
    shape and strides are read from the array object (:data:`NUMPY_ARRAY_FIELDS`),
    the size is the product of the shape, the item size is ``itemsize``.
    """
    f = NUMPY_ARRAY_FIELDS
    lines = [
        f"  %p{i} = getelementptr inbounds i64, ptr %slots, i64 {i}",
        f"  %o{i} = load ptr, ptr %p{i}, align 8",
        f"  %dp{i} = getelementptr inbounds i8, ptr %o{i}, i64 {f['data']}",
        f"  %data{i} = load ptr, ptr %dp{i}, align 8",
        f"  %shp{i} = getelementptr inbounds i8, ptr %o{i}, i64 {f['dimensions']}",
        f"  %sh{i} = load ptr, ptr %shp{i}, align 8",
        f"  %stp{i} = getelementptr inbounds i8, ptr %o{i}, i64 {f['strides']}",
        f"  %st{i} = load ptr, ptr %stp{i}, align 8",
    ]
    size = "1"
    for d in range(ndim):
        lines += [
            f"  %shq{i}.{d} = getelementptr inbounds i64, ptr %sh{i}, i64 {d}",
            f"  %dim{i}.{d} = load i64, ptr %shq{i}.{d}, align 8",
            f"  %stq{i}.{d} = getelementptr inbounds i64, ptr %st{i}, i64 {d}",
            f"  %str{i}.{d} = load i64, ptr %stq{i}.{d}, align 8",
            f"  %size{i}.{d} = mul i64 {size}, %dim{i}.{d}",
        ]
        size = f"%size{i}.{d}"
    dims = [f"i64 %dim{i}.{d}" for d in range(ndim)] + [f"i64 %str{i}.{d}" for d in range(ndim)]
    return lines, ["ptr null", "ptr null", f"i64 {size}", f"i64 {itemsize}", f"ptr %data{i}", *dims]


def _field_loads(
    params: list[str], fields: list[tuple[int, int] | None]
) -> tuple[list[str], list[str], list[str]]:
    """The entry's loads when each of ``fields`` (``(ndim, itemsize)`` of an array, or None) takes one slot.

    Returns the IR lines, the call's arguments and the slots' kinds (an
    array's ``"array<ndim>"``, else its LLVM type).
    """
    lines, args, kinds = [], [], []
    at = 0
    for i, field in enumerate(fields):
        if field is None:
            more, arg = _slot_load(i, params[at])
            lines += more
            args.append(arg)
            kinds.append(params[at])
            at += 1
            continue
        ndim, itemsize = field
        expected = ["ptr", "ptr", "i64", "i64", "ptr", *["i64"] * (2 * ndim)]
        if params[at : at + len(expected)] != expected:  # pragma: no cover - numba passes arrays otherwise
            raise TypeError(f"argument {i}: numba's array arguments are {params[at : at + len(expected)]}")
        more, array_args = _array_loads(i, ndim, itemsize)
        lines += more
        args += array_args
        kinds.append(f"array{ndim}")
        at += len(expected)
    if at != len(params):  # pragma: no cover
        raise TypeError(f"{len(params)} arguments, {at} described")
    return lines, args, kinds


def numpy_layout_holds() -> bool:
    """Whether numpy's array objects have their fields where :data:`NUMPY_ARRAY_FIELDS` says."""
    a = np.empty((3, 4))[:, ::2]
    at = id(a)

    def word(offset: int) -> int:
        return ctypes.c_void_p.from_address(at + offset).value or 0

    shape = (ctypes.c_int64 * 2).from_address(word(NUMPY_ARRAY_FIELDS["dimensions"]))
    strides = (ctypes.c_int64 * 2).from_address(word(NUMPY_ARRAY_FIELDS["strides"]))
    nd = ctypes.c_int.from_address(at + NUMPY_ARRAY_FIELDS["nd"]).value
    found = (word(NUMPY_ARRAY_FIELDS["data"]), nd, tuple(shape), tuple(strides))
    return found == (a.ctypes.data, a.ndim, a.shape, a.strides)


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
    memory manager (:func:`_array_loads`: a null pointer, whose count is never
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


def object_file(
    dispatcher: Any, signature: tuple[Any, ...], name: str, fields: list[tuple[int, int] | None] | None = None
) -> bytes:
    """The cache file of a numba function compiled for ``signature``: a JSON line, then an object file.

    The object file holds numba's LLVM IR of the function (and of everything it
    calls, as numba optimised it, not optimised again) and an entry function
    ``{_PREFIX}_{name}(int64 *slots) -> int64``: numba's status code, the
    function's flattened arguments read from ``slots``: one slot per LLVM
    argument, or, with ``fields`` (per field of the arguments, in order, an
    array's ``(ndim, itemsize)`` or None), one per field, an array's slot
    holding numpy's array object (:func:`_array_loads`).  ``dispatcher`` must
    not come from numba's on-disk cache (whose IR numba does not keep).  The
    JSON line lists the C symbols the code needs and the slots' kinds.
    """
    import llvmlite.binding as llvm

    dispatcher.compile(signature)
    text = plain_reference_counts(dispatcher.inspect_llvm(signature))
    module = llvm.parse_assembly(text)
    target = module.get_function(dispatcher.overloads[signature].fndesc.llvm_func_name)
    params = [str(a.type) for a in target.arguments][2:]  # (after the return slot and the exception info)
    if fields is None:
        lines, args = _slot_loads(params)
        kinds = params
    else:
        lines, args, kinds = _field_loads(params, fields)
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
    header = json.dumps({"symbols": needs, "params": kinds}).encode()
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


def build(entry: Entry | None = None) -> bytes:
    """The cache file of a driver function (the sweep's by default; numba compiles it, uncached)."""
    from grazing.engine.codegen import load_driver

    entry = entry or ENTRIES["sweep_lanes"]
    layout = _plan(entry).layout
    fields = [None if kind != "array" else (spec[1], spec[0].itemsize) for _label, kind, spec in layout]
    return object_file(getattr(load_driver(), entry.name), _signature(entry), entry.name, fields)


def cache_key(entry: Entry | None = None) -> str:
    """Key of an entry point's cache file: the function, the driver, this module, llvmlite, the CPU."""
    import llvmlite
    import llvmlite.binding as llvm

    from grazing.engine.codegen import _key, driver_key
    from grazing.engine.llvmgen import _target_machine

    _target_machine()  # (initialises LLVM's native target)
    cpu = (llvm.get_host_cpu_name(), llvm.get_host_cpu_features().flatten())
    name = (entry or ENTRIES["sweep_lanes"]).name
    return _key(name, driver_key(), Path(__file__).read_text(), llvmlite.__version__, cpu)


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


_PER_POINT = ("LanePoints.Ts", "LanePoints.sphase", "LanePoints.tcarry", "LanePoints.zdms")
_PER_POINT += ("LaneResults.lyap", "LaneResults.used", "LaneResults.t", "LaneResults.status")

SWEEP_LANES = (
    (("nx", "Kernels_nx"), ("nstops", "Kernels_nstops"), ("points", "LanePoints_pvs.shape[0]"),
     ("jobs", "LaneJobs_jobs.shape[0]"), ("periods", "LaneSettings_periods")),
    (*((name, "(points,)") for name in _PER_POINT), ("Kernels.sticks", "(nstops,)"),
     ("LaneJobs.jobs", "(jobs, 2)"), ("LaneJobs.control", "(3,)"), ("LaneJobs.x0", "(jobs, nx)"),
     ("LaneJobs.firsts", "(jobs, nx + 1)"), ("LaneSettings.zdm_e", "(nx,)"),
     ("LaneResults.samples", "(points, periods, nx)"), ("LaneResults.by_stop", "(points, nstops)"),
     ("LaneResults.x", "(points, nx)")),
)  # fmt: skip
"""The sizes and shapes of the arrays of ``sweep_lanes`` (it checks none)."""

INTEGRATE = (
    (("nx", "Kernels_nx"), ("nstops", "Kernels_nstops"), ("ncol", "Kernels_nx + Kernels_nsens"),
     ("keep", "Config_n_keep")),
    (("Start.x", "(nx,)"), ("Start.V", "(nx, ncol)"), ("Config.zdm_e", "(nx,)"),
     ("Config.Tp", "(ncol - nx,)"), ("Config.sigints", "(1,)"), ("Kernels.sticks", "(nstops,)"),
     ("RunOutput.totals", "(1,)"),
     ("RunOutput.x", "(nx,)"), ("RunOutput.V", "(nx, ncol)"), ("RunOutput.samples", "(keep, nx)"),
     ("RunOutput.impacts", "(RunOutput_impacts.shape[0], 3 + nx)"),
     ("RunOutput.sticking", "(RunOutput_sticking.shape[0], 2)"),
     ("RunOutput.trajectory", "(RunOutput_trajectory.shape[0], 1 + nx)"), ("RunOutput.log_sums", "(nx,)"),
     ("RunOutput.guard_min", "(nstops, 2 * (2 + nx))"), ("RunOutput.sample_modes", "(keep,)")),
)  # fmt: skip
"""The sizes and shapes of the arrays of ``integrate`` (its tables' rows are the caller's to choose)."""


def _entries() -> dict[str, Entry]:
    from grazing.engine.records import INTEGRATE_ARGUMENTS, SWEEP_RECORDS

    return {
        "sweep_lanes": Entry("sweep_lanes", SWEEP_RECORDS, *SWEEP_LANES),
        "integrate": Entry("integrate", INTEGRATE_ARGUMENTS, *INTEGRATE),
    }


ENTRIES = _entries()
"""The driver's functions that run as machine code of their own: the sweep's and the scalar integrator."""


class _Plan(NamedTuple):
    """How :func:`_flattener`'s function reads a driver function's arguments."""

    arguments: list[tuple[str, list[str] | None]]  # name and its fields' labels (None: an array of its own)
    layout: list[tuple[str, str, Any]]  # (label, kind, (numpy dtype, dimensions) of an array)
    written: str  # the prefix of the labels of the arrays the function writes (its last argument's)
    kinds: list[str]  # the slots' kinds: an array's "array<ndim>", else its LLVM type
    format: str  # the slots' struct format (64-bit integers, doubles)


_SLOT_TYPES = {"int": ("i64", "q"), "float": ("double", "d"), "bool": ("i8", "q")}


@functools.cache
def _plan(entry: Entry) -> _Plan:
    """The :class:`_Plan` of ``entry``."""
    arguments = []
    for argument in entry.arguments:
        name, fields = _parts(argument)
        arguments.append((name, None if isinstance(argument, tuple) else [label for label, _hint in fields]))
    layout, kinds, format_ = [], [], "="
    for label, kind, spec in _layout(entry):
        if kind == "array":  # (one slot: numpy's array object, read by the entry function)
            layout.append((label, kind, (np.dtype(spec[0]), spec[1])))
            kinds.append(f"array{spec[1]}")
            format_ += "q"
        else:
            layout.append((label, kind, None))
            kinds.append(_SLOT_TYPES[kind][0])
            format_ += _SLOT_TYPES[kind][1]
    return _Plan(arguments, layout, _parts(entry.arguments[-1])[0] + ".", kinds, format_)


def _name(label: str) -> str:
    """The Python name of a field in the expressions of an :class:`Entry` (``Kernels.nx``: ``Kernels_nx``)."""
    return label.replace(".", "_")


def _refuse(entry: Entry, fields: dict[str, Any]) -> NoReturn:
    """Raise the ``TypeError`` saying which array of ``fields`` (by :func:`_name`) the driver cannot take."""
    plan = _plan(entry)
    arrays = [(label, spec) for label, kind, spec in plan.layout if kind == "array"]
    for label, (dtype, ndim) in arrays:
        a = fields[_name(label)]
        if not (isinstance(a, np.ndarray) and a.dtype == dtype and a.ndim == ndim and a.flags.c_contiguous):
            raise TypeError(
                f"{entry.name}: {label} must be a C-contiguous {dtype} array of {ndim} dimension(s)"
            )
    values = dict(fields)
    for size, expression in entry.sizes:
        values[size] = eval(expression, {}, values)  # (the entry's own expressions)
    for label, (dtype, _ndim) in arrays:
        a = fields[_name(label)]
        want = eval(dict(entry.shapes).get(label, "None"), {}, values)
        if want is not None and a.shape != want:
            raise TypeError(f"{entry.name}: {label} must be a C-contiguous {dtype} array of shape {want}")
        if label.startswith(plan.written) and not a.flags.writeable:
            raise TypeError(f"{entry.name}: {label} must be writeable")
    raise TypeError(f"{entry.name}: arguments the driver cannot take")  # pragma: no cover - a size not an int


@functools.cache
def _flattener(entry: Entry) -> Callable[[tuple[Any, ...]], bytes]:
    """A function from the arguments of ``entry`` to the 64-bit slots its entry function reads (as bytes).

    The arguments are its records (or plain tuples of their fields) and its
    arrays; a slot per field, an array's holding the address of its numpy
    object (which must live as long as the slots are used; the entry function
    reads its data pointer, shape and strides, :func:`_array_loads`), a
    boolean's 0 or 1.  Arrays of another dtype, dimension, shape or layout
    than the driver takes are refused (``TypeError``), and so are read-only
    arrays the driver writes.  Python code with a line per field (no loop over the layout, no table of
    values): the driver's arguments are flattened on every call of the scalar
    integrator, about as often as numba's dispatcher would take them.  Should
    any check fail, :func:`_refuse` finds which.
    """
    import struct

    plan = _plan(entry)
    lines = [
        "def flatten(arguments):",
        f"    if len(arguments) != {len(plan.arguments)}:",
        f"        raise TypeError(f'{entry.name}: {len(plan.arguments)} arguments expected, "
        "got {len(arguments)}')",
        f"    {', '.join(f'a{i}' for i in range(len(plan.arguments)))}, = arguments",
    ]
    for i, (name, labels) in enumerate(plan.arguments):
        if labels is None:
            lines.append(f"    {_name(name)} = a{i}")
            continue
        lines += [
            f"    if not (isinstance(a{i}, tuple) and len(a{i}) == {len(labels)}):",
            f"        raise TypeError('{entry.name}: a {name} ({len(labels)} fields) expected')",
            f"    {', '.join(_name(label) for label in labels)}, = a{i}",
        ]
    lines.append("    try:")
    lines += [f"        {size} = {expression}" for size, expression in entry.sizes]
    shapes = dict(entry.shapes)
    items = []
    dtypes = {}
    for label, kind, spec in plan.layout:
        v = _name(label)
        if kind != "array":
            items.append({"bool": f"1 if {v} else 0", "float": f"float({v})", "int": f"int({v})"}[kind])
            continue
        dtypes[f"D_{v}"] = spec[0]
        shape = f"{v}.shape == {shapes[label]}" if label in shapes else f"{v}.ndim == {spec[1]}"
        written = f" and {v}.flags.writeable" if label.startswith(plan.written) else ""
        lines += [
            f"        if not (isinstance({v}, ndarray) and {v}.dtype == D_{v} and {v}.flags.c_contiguous"
            f"{written} and {shape}):",
            "            raise RefusedError",
        ]
        items.append(f"id({v})")
    lines += [
        "    except Exception:",
        "        refuse(entry, locals())",
        f"    return pack({plan.format!r}, {', '.join(items)})",
    ]
    scope = {
        "ndarray": np.ndarray, "pack": struct.pack, "refuse": _refuse, "entry": entry,
        "RefusedError": _RefusedError, **dtypes,
    }  # fmt: skip
    exec(compile("\n".join(lines) + "\n", f"<grazing.engine.native: flatten {entry.name}>", "exec"), scope)
    return scope["flatten"]


class _RefusedError(Exception):
    """An argument a driver function cannot take (the generated checks' signal to :func:`_refuse`)."""


def _raise_numbas_error(entry: Entry, arguments: tuple[Any, ...]) -> None:
    """Call numba's function of ``entry`` with ``arguments``, after its machine code reported an exception.

    numba's function raises the exception.  The sweep driver's other threads
    are stopped first, and its jobs run again in this thread.
    """
    from grazing.engine.codegen import load_driver

    function = getattr(load_driver(), entry.name)
    if entry.name == "sweep_lanes":
        m, cfg, work, points, out = arguments
        work[1][1] = 1  # (the other threads of the call stop: LaneJobs.control)
        again = (work[0], np.zeros(3, dtype=np.int64), *work[2:])  # every job again, in this thread:
        arguments = (m, cfg, again, points, out)
    function(*arguments)


def _caller(entry: Entry, address: int, params: list[str], keep: Any) -> Callable[..., None]:
    """A Python function with the arguments of the driver's function ``entry``, calling its machine code."""
    if _plan(entry).kinds != params:  # pragma: no cover - arguments changed without the cache key
        raise TypeError(f"{entry.name}: the compiled code takes other arguments; clear the kernel cache")
    call = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_char_p)(address)
    flatten_ = _flattener(entry)

    def driver_function(*arguments: Any) -> None:
        if call(flatten_(arguments)) not in _RETURNED:  # pragma: no cover - the driver raised
            _raise_numbas_error(entry, arguments)
            raise RuntimeError(f"the compiled {entry.name} failed where numba's function did not")

    driver_function.__name__ = entry.name
    driver_function.library = keep  # type: ignore[attr-defined]  # (the machine code lives as long as this)
    return driver_function


def _load(entry: Entry) -> Callable[..., None]:
    """A driver function's entry point, loaded from the kernel cache (compiled by numba the first time).

    If numba's runtime cannot be given to the machine code (a numba that no
    longer provides a C helper), numba's own compiled function is returned.
    """
    from grazing.engine.codegen import _cached_file, load_driver

    name = f"grazing_native_{cache_key(entry)}.bin"
    path = _cached_file(name, lambda: build(entry))
    try:
        loaded = load_object(path.read_bytes(), entry.name)
    except (ValueError, KeyError, OSError, RuntimeError):  # a damaged cache file (ours): build it again
        path.unlink(missing_ok=True)
        loaded = load_object(_cached_file(name, lambda: build(entry)).read_bytes(), entry.name)
    if loaded is None or not numpy_layout_holds():  # pragma: no cover - a numba or numpy we do not know
        return getattr(load_driver(), entry.name)
    return _caller(entry, *loaded)


@functools.cache
def load_sweep_lanes() -> Callable[..., None]:
    """The sweep driver's entry point: the arguments of :func:`grazing.engine.driver.lanes.sweep_lanes`.

    They are the records of :data:`grazing.engine.records.SWEEP_RECORDS`; it
    writes the results into the last.
    """
    return _load(ENTRIES["sweep_lanes"])


@functools.cache
def load_integrate() -> Callable[..., None]:
    """The scalar integrator's entry point: the arguments of :func:`grazing.engine.driver.loop.integrate`.

    They are :data:`grazing.engine.records.INTEGRATE_ARGUMENTS`; it writes the
    run into the last, a :class:`~grazing.engine.records.RunOutput`.
    """
    return _load(ENTRIES["integrate"])


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
