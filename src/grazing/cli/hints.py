"""The library's messages with its arguments named as the command line's options.

A message of the library names what to give as a Python user gives it, an argument with an equals
sign (``give an initial guess (x0=)``, ``can be followed with switch (switch=True)``); the command
line says the same with its options (``give an initial guess (--initial)``).  The translation is
here, in one table, so that no library module names an option (``tests/test_layers.py``).
"""

from __future__ import annotations

import re

__all__ = ["FLAGS", "flag_hints"]

FLAGS: dict[str, str] = {
    "x0=": "--initial",
    "period=": "--period",
    "transient=": "--transient",
    "switch=True": "--switch",
    "forcing_hz=": "--forcing-hz",
    "wait=True": "--wait",
    "store=": "--out",
    "client=": "--scheduler",
    "timeout=": "--timeout",
    "port=": "--port",
    "overwrite=True": "--overwrite",
    "fresh=True": "--fresh",
    "chunk_size=": "--chunk-size",
    "lyapunov=False": "--no-lyapunov",
    "device=": "--device",
}
"""Each argument as the library's messages name it, and the option that gives it on the command line."""

_NAMES = "|".join(re.escape(k) for k in sorted(FLAGS, key=len, reverse=True))
_ARGUMENT = re.compile(rf"(?<![\w.=])({_NAMES})(?=[\s),;:]|$)")
"""An argument of :data:`FLAGS` named alone: not part of a longer name, not followed by a value."""


def flag_hints(message: str) -> str:
    """``message`` with every argument of :data:`FLAGS` it names replaced by its option.

    Examples
    --------
    >>> flag_hints("give the period (period=) or an initial guess (x0=)")
    'give the period (--period) or an initial guess (--initial)'
    >>> flag_hints("can be followed with switch (switch=True)")
    'can be followed with switch (--switch)'
    >>> flag_hints("period=3 is not a period")  # (a value given, not an argument to give: left as it is)
    'period=3 is not a period'
    """
    return _ARGUMENT.sub(lambda m: FLAGS[m.group(1)], message)
