"""A model's functions as CUDA device functions, from the same generated text as its CPU kernels.

:func:`grazing.engine.codegen.generate_source` writes every function of a
model (Taylor-coefficient kernels, guards, resets ...) as straight-line Python
over ``math`` and array arguments, which :mod:`grazing.engine.llvmgen`
compiles for the CPU.  Here the same text is executed and each function
compiled with ``cuda.jit(device=True)``; a per-stop function is reached, as the
CPU's dispatchers do, by the stop's index, through a generated chain of ``if``
tests.  ``math.sin`` and ``math.cos`` are grazing's own, as in the CPU's
compiled code (:mod:`grazing.engine.llvmgen`): the device copies of
:mod:`grazing.engine.sincos`.
"""

from __future__ import annotations

import ast
import math
from dataclasses import dataclass
from typing import Any

from grazing.engine.codegen import ModelSource, generate_source

MODE_FUNCTIONS = ("tc_free", "tc_var", "rhs")
"""The per-mode functions, reached by the mode's index (``mode_tc_free(x0, s0, pv, X, O, vf)``)."""


@dataclass(frozen=True)
class DeviceModel:
    """The device functions of a model and its sizes.

    Attributes
    ----------
    functions
        Every generated function by name (``tc_free``, ``guard_s0`` ...) and,
        for each per-stop name of ``ModelSource.dispatch``, the dispatcher over
        the stops (``guard(x, s, pv, j)``).
    nx, nstops, nparams, order
        The sizes.
    sticks
        Per stop: it has a sticking mode.
    nmodes, rows, targets, resets, back, slide_entry
        The modes (the generated ``sizes``'; for one mode every stop is a row of its kernels, each
        transition a reset into mode 0): a mode's event rows (its transitions, -1 padding), each
        transition's target mode, whether it resets, its way back (-1 none), its sliding entry (-1 none).
        ``functions`` has ``mode_tc_free``, ``mode_tc_var`` and ``mode_rhs``: the mode's function by its
        index (the last argument), for one mode as for several.
    """

    functions: dict[str, Any]
    nx: int
    nstops: int
    nparams: int
    order: int
    sticks: tuple[bool, ...]
    nmodes: int = 1
    rows: tuple[tuple[int, ...], ...] = ()
    targets: tuple[int, ...] = ()
    resets: tuple[bool, ...] = ()
    back: tuple[int, ...] = ()
    slide_entry: tuple[int, ...] = ()


def dispatcher_text(name: str, choices: list[str], args: str) -> str:
    """The source of ``name(args, j)``, calling ``choices[j](args)`` (the last one for any larger ``j``).

    Examples
    --------
    >>> print(dispatcher_text("guard", ["guard_s0", "guard_s1"], "x, s, pv"))
    def guard(x, s, pv, j):
        if j == 0:
            return guard_s0(x, s, pv)
        return guard_s1(x, s, pv)
    <BLANKLINE>
    """
    lines = [f"def {name}({args}, j):"]
    for j, choice in enumerate(choices[:-1]):
        lines += [f"    if j == {j}:", f"        return {choice}({args})"]
    lines.append(f"    return {choices[-1]}({args})")
    return "\n".join(lines) + "\n"


def _arguments(text: str, name: str) -> str:
    """The argument list of the definition of ``name`` in ``text``."""
    head = f"def {name}("
    start = text.index(head) + len(head)
    return text[start : text.index("):", start)]


def device_model(source: ModelSource) -> DeviceModel:
    """The device functions of the generated ``source``."""
    from grazing.gpu.ported import device_helpers
    from grazing.gpu.target import device_function

    sizes = source.sizes
    nstops = int(sizes["nstops"])
    nmodes = int(sizes.get("nmodes", 1))
    helpers = device_helpers()
    namespace: dict[str, Any] = {"math": math, "_sin": helpers["sin"], "_cos": helpers["cos"]}
    text = source.text.replace("math.sin(", "_sin(").replace("math.cos(", "_cos(")
    exec(compile(text, "<grazing.gpu.model>", "exec"), namespace)
    defined = [node.name for node in ast.parse(text).body if isinstance(node, ast.FunctionDef)]
    functions: dict[str, Any] = {}
    for name in defined:
        functions[name] = device_function(namespace[name])
        namespace[name] = functions[name]
    for name, choices in source.dispatch.items():
        text = dispatcher_text(name, choices, _arguments(source.text, choices[0]))
        exec(compile(text, f"<grazing.gpu.model.{name}>", "exec"), namespace)
        functions[name] = device_function(namespace[name])
    for name in MODE_FUNCTIONS:  # (by the mode's index: the dispatcher, or the one mode's function)
        choices = source.dispatch[name] if nmodes > 1 else [name]
        text = dispatcher_text(f"mode_{name}", choices, _arguments(source.text, choices[0]))
        exec(compile(text, f"<grazing.gpu.model.mode_{name}>", "exec"), namespace)
        functions[f"mode_{name}"] = device_function(namespace[f"mode_{name}"])
    return DeviceModel(
        functions=functions,
        nx=int(sizes["nx"]),
        nstops=int(sizes["nstops"]),
        nparams=int(sizes["nparams"]),
        order=int(sizes["order"]),
        sticks=tuple(bool(s) for s in sizes["sticks"]),
        nmodes=nmodes,
        rows=tuple(tuple(int(r) for r in row) for row in sizes.get("rows", [list(range(nstops))])),
        targets=tuple(int(t) for t in sizes.get("targets", [0] * nstops)),
        resets=tuple(bool(r) for r in sizes.get("resets", [True] * nstops)),
        back=tuple(int(b) for b in sizes.get("back", [-1] * nstops)),
        slide_entry=tuple(int(e) for e in sizes.get("slide_entry", [-1] * nstops)),
    )


_cache: dict[tuple[str, int], DeviceModel] = {}


def model_functions(definition: Any, order: int) -> DeviceModel:
    """The device functions of a model definition (a model's ``_def``) at Taylor ``order``, made once."""
    key = (definition.identity(), int(order))
    found = _cache.get(key)
    if found is None:
        found = device_model(generate_source(definition.system, 0, order))
        _cache[key] = found
    return found
