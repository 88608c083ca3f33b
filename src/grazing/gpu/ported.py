"""The CPU driver's model-independent helpers as CUDA device functions, made from their own source.

The step size (:func:`~grazing.engine.stepping.step_size`, with its
``fast_log``/``fast_exp``), the event polynomial and its certificate
(:mod:`grazing.engine.driver.events`), the certified first root
(:mod:`grazing.engine.polyroots`: quadratic bound, Bernstein subdivision,
Newton polishing, the check that the root is the first), the test of a
repeating transient, the start times, the step's cut at the last sample and at
the discontinuity map's phase (``step.cut_step``, ``map_reached``), the map's
kick and its tangent (``tangent.map_kick``, ``kick_tangent``), the Lyapunov
vectors' Gram-Schmidt and (un)packing of the variational matrix, chattering's
time to its accumulation point and the Newton step onto a sticking contact
(:mod:`grazing.engine.driver.impacts`), the cores of a transition
(:mod:`grazing.engine.driver.transitions`: the saltation matrix, the
projection onto a guard, the mode after a switch or sliding, the region
check, the roots an impact's reset leaves known), and the model code's ``sin`` and ``cos``
(:mod:`grazing.engine.sincos`: not the C library's) are compiled for the GPU from the
very text the CPU driver compiles: the decorators dropped, each function
executed in one namespace where every callee is its device copy.  A change in
the CPU's event location is the GPU's at once; nothing is written twice.

Only three names differ: the bits of a double and back (an LLVM intrinsic on
the CPU) and ``np.nextafter`` are :mod:`grazing.gpu.target`'s device forms.
And one table is computed where it is read: a module's array read by a device
function is copied into the device's 64 kB bank of constants once for each
type signature it is compiled for, and ``polyroots._QUOTIENTS`` (34,848 bytes,
``i / j``) twice would not fit (``ptxas``: "too much global constant data"; the
kernel would not load).  Its reads become the division they stand for
(:data:`COMPUTED`): the same double, as a division is correctly rounded on
either processor.  No other array comes with a module (:func:`_constants`).
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
    "grazing.engine.driver.impacts": ("chatter_time_left", "along_contact_dir"),
    "grazing.engine.driver.transitions": (
        "state_scale", "mode_after", "outside_region", "roots_after_reset", "onto_zero_step",
        "saltation_vector", "apply_saltation",
    ),
    "grazing.core.period": ("repeats_with_period",),
    "grazing.core.options": ("step_limit",),
    "grazing.engine.timebase": ("start_times", "map_period"),
    "grazing.engine.driver.step": ("cut_step", "map_reached"),
    "grazing.engine.driver.tangent": ("map_kick", "kick_tangent"),
    "grazing.engine.sincos": ("sincos_fast", "sincos", "sin", "cos"),
}  # fmt: skip
"""The functions made device functions, by module (their module's constants come with them)."""

REPLACED = {"np.nextafter": "nextafter"}
"""Calls rewritten in the ported text (a device cannot call numpy)."""
COMPUTED = {"_QUOTIENTS": ast.Div()}
"""Tables of ``i op j`` whose reads ``T[i, j]`` the ported text computes as ``(i) op (j)`` (the module)."""


class _ComputeTables(ast.NodeTransformer):
    """Rewrites each read ``T[i, j]`` of a table of :data:`COMPUTED` as ``(i) op (j)``."""

    def visit_Subscript(self, node: ast.Subscript) -> ast.AST:
        self.generic_visit(node)
        if isinstance(node.value, ast.Name) and node.value.id in COMPUTED:
            index = node.slice
            if not (isinstance(index, ast.Tuple) and len(index.elts) == 2):  # pragma: no cover
                raise RuntimeError(f"{node.value.id} is read other than as T[i, j]: compute it otherwise")
            return ast.BinOp(index.elts[0], COMPUTED[node.value.id], index.elts[1])
        return node


def _function_text(module: ModuleType, name: str) -> str:
    """The source of ``module.name`` without its decorators."""
    obj = getattr(module, name)
    fn = getattr(obj, "py_func", obj)
    tree = ast.parse(inspect.getsource(fn))
    node = tree.body[0]
    assert isinstance(node, ast.FunctionDef)
    node.decorator_list = []
    text = ast.unparse(ast.fix_missing_locations(_ComputeTables().visit(node)))
    for old, new in REPLACED.items():
        text = text.replace(old, new)
    return text


def _constants(module: ModuleType) -> dict[str, Any]:
    """The module-level numbers of ``module`` (what its functions read as constants; no arrays: a device
    function's array is a copy in the device's small bank of constants per signature, see the module)."""
    return {
        k: v for k, v in vars(module).items() if not k.startswith("__") and isinstance(v, (int, float))
        and not isinstance(v, bool)
    }  # fmt: skip


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
