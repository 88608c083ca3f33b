"""The compiled integration driver, in small pieces appended to every generated kernel module.

The pieces call the model's own compiled functions (``tc_free``, ``tc_var``,
``tc_stick``, ``rhs``, ``guard``, ``reset``, ``reset_jac`` ...) and constants
(``NX``, ``NSENS``, ``ORDER``, ``HAS_STICK``, the ``STATUS_*`` codes of
:class:`grazing.core.solution.Status`), which :mod:`grazing.engine.codegen`
defines in each model's module; keeping them in that module lets numba resolve
them as globals and cache the compiled result on disk.  Each file here is
valid Python that imports on its own (the model's names are only looked up
when a piece is compiled).  What does not depend on the model is in
:mod:`grazing.engine.stepping` and :mod:`grazing.engine.polyroots`, compiled
once per machine.

The pieces, in the order a step uses them:

* :mod:`.events` -- the step (Taylor coefficients and step size) and event
  location (the guard's polynomial over the step, known roots divided out,
  its first root);
* :mod:`.recording` -- stroboscopic samples, trajectory points, the guard's
  minimum and closest approach;
* :mod:`.tangent` -- the variational equations at period boundaries, Lyapunov
  orthonormalisation, the discontinuity map;
* :mod:`.impacts` -- reset and saltation matrix, chattering summed to sticking,
  release;
* :mod:`.loop` -- ``integrate(start, config) -> result`` over the records of
  :mod:`grazing.engine.records`.
"""

from __future__ import annotations

from pathlib import Path

PIECES = ("events.py", "recording.py", "tangent.py", "impacts.py", "loop.py")
"""The template files, in the order they are appended."""


def template_files() -> list[Path]:
    """The paths of the driver's template files."""
    here = Path(__file__).parent
    return [here / name for name in PIECES]


def template_text() -> str:
    """The driver's source, as appended to a generated kernel module."""
    return "\n\n".join(path.read_text() for path in template_files())
