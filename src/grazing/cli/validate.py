"""Validation of command-line input, in one place for every command.

- Option *types* check single values when the command line is parsed, the
  same way wherever an option appears: finite numbers and their ranges
  (:class:`Number` and the instances below: tolerances, angles, rates...),
  bounded counts, seeds and periods, non-empty paths.
- An option given more than once takes its last value, as in most command
  lines (so a wrapper script can append overrides).
- :func:`refuse_unused` refuses an option that the other options make
  meaningless (``--which`` without ``--method map``...): no run ends with
  exit status 0 having ignored something the user asked for.
- The values a model parameter takes (both ends of a sweep or continuation)
  are checked by the model itself, before any work, in the commands.

Every failure is an :class:`InputError`: one line, exit status 2.  This module
imports only click (no other part of grazing), so every command module can
use it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import click
from click.core import ParameterSource

MAX_COUNT = 10**12
"""Largest value of a count option (periods, points...): beyond it the int64 kernels overflow."""

MAX_ORBIT_PERIOD = 64
"""Longest period (in forcing periods) of an orbit sought by shooting.

It is also the longest period that simulations detect.  Over longer spans the
monodromy matrix of a damped orbit underflows (its determinant is
``exp(-4 pi beta n / eta)``), so the multipliers, and the orbit, mean nothing.
"""

MAX_WORKERS = 1024
"""Most local workers (threads of a sweep, processes elsewhere)."""

MAX_SAMPLE_RATE = 1e6
"""Highest sample rate (Hz) of a written recording: times are written to the microsecond."""


class InputError(click.ClickException):
    """Bad command-line input, reported as one line (exit status 2)."""

    exit_code = 2


def option_label(param: click.Parameter | None) -> str:
    """How the user wrote an option (``--tol``; ``--virtual/--physical`` for a flag pair)."""
    if param is None:
        return "value"
    if isinstance(param, click.Option):
        longest = max(param.opts, key=len)
        if param.secondary_opts:
            return f"{longest}/{max(param.secondary_opts, key=len)}"
        return longest
    return param.metavar or (param.name or "value").upper()


def _fmt(v: float) -> str:
    return f"{v:g}"


class Number(click.ParamType):
    """A finite float, optionally in an interval.

    Parameters
    ----------
    low, high
        Bounds (None: unbounded).
    low_open, high_open
        Whether the bound itself is excluded.
    unit
        Appended to the interval in messages (``" degrees"``).

    Examples
    --------
    >>> Number(0, 1e-2).describe()
    'in (0, 0.01)'
    >>> Number(0).describe(), Number(0, low_open=False).describe(), Number().describe()
    ('positive', '>= 0', 'a finite number')
    """

    name = "number"

    def __init__(
        self,
        low: float | None = None,
        high: float | None = None,
        *,
        low_open: bool = True,
        high_open: bool = True,
        unit: str = "",
    ):
        self.low, self.high = low, high
        self.low_open, self.high_open = low_open, high_open
        self.unit = unit

    def describe(self) -> str:
        """The allowed values, as in a message (``in (0, 0.01)``, ``positive``...)."""
        lo, hi = self.low, self.high
        if lo is None and hi is None:
            return "a finite number"
        if hi is None:
            assert lo is not None
            if lo == 0:
                return ("positive" if self.low_open else ">= 0") + self.unit
            return f"{'>' if self.low_open else '>='} {_fmt(lo)}{self.unit}"
        if lo is None:
            return f"{'<' if self.high_open else '<='} {_fmt(hi)}{self.unit}"
        left, right = "(" if self.low_open else "[", ")" if self.high_open else "]"
        return f"in {left}{_fmt(lo)}, {_fmt(hi)}{right}{self.unit}"

    def accepts(self, v: float) -> bool:
        """Whether ``v`` is allowed."""
        if not math.isfinite(v):
            return False
        if self.low is not None and (v < self.low or (self.low_open and v == self.low)):
            return False
        return not (self.high is not None and (v > self.high or (self.high_open and v == self.high)))

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> float:
        v = value if isinstance(value, float) else click.FLOAT.convert(value, param, ctx)
        if not self.accepts(v):
            raise InputError(f"{option_label(param)} must be {self.describe()}, got {_fmt(v)}")
        return v

    def __repr__(self) -> str:
        return f"Number({self.describe()})"


FINITE = Number()
POSITIVE = Number(0.0)
NON_NEGATIVE = Number(0.0, low_open=False)
ANGLE_DEG = Number(-180.0, 180.0, unit=" degrees")
"""An angle in degrees, strictly between -180 and 180 (the stop angle)."""
AMPLITUDE_DEG = Number(0.0, 180.0, unit=" degrees")
"""A release angle below the stop, in degrees."""
TOLERANCE = Number(0.0, 1e-2)
"""An integrator's local error tolerance."""
SAMPLE_RATE = Number(0.0, MAX_SAMPLE_RATE, high_open=False, unit=" Hz")


def count(low: int) -> click.IntRange:
    """An integer count ``>= low`` (and at most :data:`MAX_COUNT`)."""
    return click.IntRange(min=low, max=MAX_COUNT)


class Count(click.IntRange):
    """An integer in a range (click's message), with the reason for the range appended.

    >>> Count(1, 64, why="longer orbits are not resolved").why
    'longer orbits are not resolved'
    """

    def __init__(self, low: int | None = None, high: int | None = None, *, why: str = ""):
        super().__init__(min=low, max=high)
        self.why = why

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        try:
            return super().convert(value, param, ctx)
        except click.BadParameter as exc:
            if self.why:
                exc.message = f"{exc.message.rstrip('.')} ({self.why})"
            raise


SEED = click.IntRange(min=0)
"""A random seed (numpy's generators take non-negative integers)."""
ORBIT_PERIOD = Count(
    1, MAX_ORBIT_PERIOD, why="longer orbits are not resolved: their Floquet multipliers underflow"
)
WORKERS = click.IntRange(min=1, max=MAX_WORKERS)


class NonEmptyPath(click.Path):
    """A :class:`click.Path` that refuses the empty string (an unset shell variable: ``--out "$DIR"``),
    which would otherwise mean the current folder."""

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if isinstance(value, str) and not value.strip():
            raise InputError(f"{option_label(param)} must name a file or folder, got an empty string")
        return super().convert(value, param, ctx)


def path_type(**kwargs: Any) -> NonEmptyPath:
    """A non-empty path option returning :class:`pathlib.Path` (``click.Path`` keywords)."""
    return NonEmptyPath(path_type=Path, **kwargs)


def given(ctx: click.Context, name: str) -> bool:
    """Whether the user gave the option ``name`` (on the command line or in the environment)."""
    return ctx.get_parameter_source(name) in (ParameterSource.COMMANDLINE, ParameterSource.ENVIRONMENT)


def _param(ctx: click.Context, name: str) -> click.Parameter | None:
    return next((p for p in ctx.command.params if p.name == name), None)


def refuse_unused(names: Iterable[str], unused: bool, why: str, ctx: click.Context | None = None) -> None:
    """Refuse any of the options ``names`` that the user gave when ``unused`` holds.

    ``why`` completes the message: ``--which is not used {why}``.

    Examples
    --------
    ``refuse_unused(["which"], method != "map", "without --method map")``
    gives ``--which is not used without --method map``.
    """
    if not unused:
        return
    ctx = ctx or click.get_current_context()
    for name in names:
        if given(ctx, name):
            raise InputError(f"{option_label(_param(ctx, name))} is not used {why}")


def refuse_set(names: Iterable[str], why: str, ctx: click.Context | None = None) -> None:
    """Refuse ``--set NAME=VALUE`` for any model parameter in ``names`` (the command sets them itself).

    ``why`` completes the message: ``--set eta=0.4 is not used {why}``.  The
    command's ``--set`` values are read from the click context.
    """
    ctx = ctx or click.get_current_context()
    wanted = set(names)
    for item in ctx.params.get("sets") or ():
        if item.partition("=")[0].strip().replace("-", "_") in wanted:
            raise InputError(f"--set {item} is not used {why}")
