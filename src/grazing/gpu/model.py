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
    """

    functions: dict[str, Any]
    nx: int
    nstops: int
    nparams: int
    order: int
    sticks: tuple[bool, ...]


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
    """The device functions of the generated ``source`` (one mode: ``ValueError`` for a model with modes)."""
    from grazing.gpu.ported import device_helpers
    from grazing.gpu.target import device_function

    sizes = source.sizes
    if int(sizes.get("nmodes", 1)) > 1:
        raise ValueError("models with several modes are not on the GPU yet")
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
    return DeviceModel(
        functions=functions,
        nx=int(sizes["nx"]),
        nstops=int(sizes["nstops"]),
        nparams=int(sizes["nparams"]),
        order=int(sizes["order"]),
        sticks=tuple(bool(s) for s in sizes["sticks"]),
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
