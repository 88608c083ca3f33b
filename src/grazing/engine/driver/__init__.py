"""The compiled integration driver, in small pieces, compiled once per machine for every model.

The driver reaches a model through a :class:`~grazing.engine.records.Kernels`
record: the addresses of the model's compiled functions (``tc_free``,
``tc_var``, ``tc_stick``, ``rhs``, ``guard``, ``reset``, ``reset_jac`` ...;
machine code from :mod:`grazing.engine.llvmgen`) and its sizes, given at run
time.  So the driver does not depend on the model and numba compiles it once
per machine, not once per model, sensitivity set and Taylor order.

Each file here is valid Python that imports on its own.  For numba they are
concatenated into one generated module (:func:`template_text`, imports
between the pieces dropped), keyed by a hash of their sources and of the
helpers they call (:mod:`grazing.engine.stepping`,
:mod:`grazing.engine.polyroots`): numba's own cache would not notice a change
in a piece that another one inlines.

The pieces, in the order a step uses them:

* :mod:`.state` -- the state of a run (one per lane), a named record;
* :mod:`.calls` -- the model's functions through the address table;

* :mod:`.events` -- the step (Taylor coefficients and step size) and event
  location (the guard's polynomial over the step, known roots divided out,
  its first root);
* :mod:`.recording` -- stroboscopic samples, trajectory points, the guard's
  minimum and closest approach;
* :mod:`.tangent` -- the variational equations at period boundaries, Lyapunov
  orthonormalisation, the discontinuity map;
* :mod:`.transitions` -- the record-free cores of a transition (saltation
  matrix, projection onto a guard, the mode after it, the region check),
  which the GPU kernel compiles too;
* :mod:`.impacts` -- reset and saltation matrix, chattering summed to sticking,
  release, switches of mode and sliding;
* :mod:`.step` -- the parts of a step that the loop and the lanes share:
  where it ends, and its end (time, Lyapunov vectors, the map, the event);
* :mod:`.loop` -- ``integrate(start, config) -> result`` over the records of
  :mod:`grazing.engine.records`;
* :mod:`.lanes` -- the points of a sweep on SIMD lanes, the loop's step per
  lane around the model's lane functions.
"""

from __future__ import annotations

from pathlib import Path

PIECES = (
    "atomics.py", "state.py", "calls.py", "events.py", "recording.py", "tangent.py", "transitions.py",
    "impacts.py", "step.py", "loop.py", "lanes.py",
)  # fmt: skip
"""The template files, in the order they are appended."""


def template_files() -> list[Path]:
    """The paths of the driver's template files."""
    here = Path(__file__).parent
    return [here / name for name in PIECES]


def _without_driver_imports(text: str) -> str:
    """``text`` without its ``from grazing.engine.driver... import`` statements."""
    import ast

    lines = text.splitlines()
    for node in ast.parse(text).body:
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("grazing.engine.driver"):
            assert node.end_lineno is not None
            for i in range(node.lineno - 1, node.end_lineno):
                lines[i] = ""
    return "\n".join(lines) + "\n"


def template_text() -> str:
    """The driver's source: the pieces in order, as one module."""
    return "\n\n".join(_without_driver_imports(path.read_text()) for path in template_files())
