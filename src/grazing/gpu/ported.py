"""The CPU driver's model-independent helpers as CUDA device functions, made from their own source.

The step size (:func:`~grazing.engine.stepping.step_size`, with its
``fast_log``/``fast_exp``), the event polynomial and its certificate
(:mod:`grazing.engine.driver.events`), the certified first root
(:mod:`grazing.engine.polyroots`: quadratic bound, Bernstein subdivision,
Newton polishing, the check that the root is the first), the test of a
repeating transient, the start times, the Lyapunov vectors' Gram-Schmidt and
(un)packing of the variational matrix, the cores of a transition
(:mod:`grazing.engine.driver.transitions`: the saltation matrix, the
projection onto a guard, the mode after a switch or sliding, the region
check), and the model code's ``sin`` and ``cos``
(:mod:`grazing.engine.sincos`: not the C library's) are compiled for the GPU from the
very text the CPU driver compiles: the decorators dropped, each function
executed in one namespace where every callee is its device copy.  A change in
the CPU's event location is the GPU's at once; nothing is written twice.

Only three names differ: the bits of a double and back (an LLVM intrinsic on
the CPU) and ``np.nextafter`` are :mod:`grazing.gpu.target`'s device forms.
"""

from __future__ import annotations

import ast
import functools
import inspect
import math
from types import ModuleType
from typing import Any

PORTED: dict[str, tuple[str, ...]] = {
    "grazing.engine.polyroots": (
        "horner", "horner_with_derivative", "to_bernstein", "split_half", "_polish", "quadratic_bound",
        "quadratic_lower_bound", "_most_sign_changes", "isolate_first_root", "confirm_first_root",
    ),
    "grazing.engine.stepping": (
        "fast_log", "fast_exp", "step_size", "step_from_norms", "eval_rows", "divide_double_root_at_one",
        "orthonormalize", "unpack_var", "pack_var",
    ),
    "grazing.engine.driver.events": ("event_polynomial", "event_certificate"),
    "grazing.engine.driver.transitions": (
        "mode_after", "outside_region", "onto_zero_step", "saltation_vector", "apply_saltation",
    ),
    "grazing.core.period": ("repeats_with_period",),
    "grazing.core.options": ("step_limit",),
    "grazing.engine.timebase": ("start_times",),
    "grazing.engine.sincos": ("sincos_fast", "sincos", "sin", "cos"),
}  # fmt: skip
"""The functions made device functions, by module (their module's constants come with them)."""

REPLACED = {"np.nextafter": "nextafter"}
"""Calls rewritten in the ported text (a device cannot call numpy)."""


def _function_text(module: ModuleType, name: str) -> str:
    """The source of ``module.name`` without its decorators."""
    obj = getattr(module, name)
    fn = getattr(obj, "py_func", obj)
    tree = ast.parse(inspect.getsource(fn))
    node = tree.body[0]
    assert isinstance(node, ast.FunctionDef)
    node.decorator_list = []
    text = ast.unparse(node)
    for old, new in REPLACED.items():
        text = text.replace(old, new)
    return text


def _constants(module: ModuleType) -> dict[str, Any]:
    """The module-level numbers and arrays of ``module`` (what its functions read as constants)."""
    import numpy as np

    return {
        k: v
        for k, v in vars(module).items()
        if not k.startswith("__") and isinstance(v, (int, float, np.ndarray)) and not isinstance(v, bool)
    }


@functools.cache
def device_helpers() -> dict[str, Any]:
    """Every function of :data:`PORTED` as a device function, by name (made once per process)."""
    import importlib

    from grazing.gpu.target import bit_casts, device_function, nextafter_function

    namespace: dict[str, Any] = {"math": math}
    texts = []
    for modname, names in PORTED.items():
        module = importlib.import_module(modname)
        for key, value in _constants(module).items():
            if key in namespace and namespace[key] is not value:
                raise RuntimeError(f"two ported modules define {key}: rename one")  # pragma: no cover
            namespace[key] = value
        texts += [_function_text(module, name) for name in names]
    bits_of, double_of = bit_casts()
    namespace.update(_bits_of=bits_of, _double_of=double_of, nextafter=nextafter_function())
    exec(compile("\n\n".join(texts), "<grazing.gpu.ported>", "exec"), namespace)
    helpers: dict[str, Any] = {}
    for names in PORTED.values():
        for name in names:
            helpers[name] = device_function(namespace[name])
            namespace[name] = helpers[name]  # (the callers find the device copy when they are compiled)
    helpers["namespace"] = namespace
    return helpers
