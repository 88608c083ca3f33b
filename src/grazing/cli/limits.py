"""The memory a run will need, estimated before any work, and the bound it must stay under.

Every command that can be asked for an arbitrarily large result (a trajectory,
a sweep, a curve, a synthetic recording) estimates the memory it will hold
from its options and refuses, with one line saying how to split the work or
stream it to a file, when the estimate exceeds the bound.  The bound is half
of the machine's physical memory, or the size in the environment variable
``GRAZING_MAX_MEMORY`` (``8G``, ``512M``, ``2.5e9``).

The estimates are upper bounds of what the commands keep in memory at once,
measured on the commands themselves (the constants below); they do not count
the ~250 MB of the interpreter and the compiled kernels.

>>> format_bytes(2.4e12), format_bytes(512 * 2**20)
('2.4 TB', '537 MB')
>>> parse_size("8G"), parse_size("512M"), parse_size("2.5e9")
(8000000000, 512000000, 2500000000)
>>> parse_size("1e400")
Traceback (most recent call last):
...
grazing.errors.GrazingError: GRAZING_MAX_MEMORY='1e400' is not a size such as 8G or 512M
"""

from __future__ import annotations

import math
import os
import re

from grazing.errors import GrazingError

MEMORY_ENV = "GRAZING_MAX_MEMORY"
"""Environment variable that sets the memory bound (a size: ``8G``, ``512M``, bytes)."""

DEFAULT_FRACTION = 0.5
"""Share of the physical memory a run may use when ``GRAZING_MAX_MEMORY`` is not set."""

FALLBACK_LIMIT = 8e9
"""The bound where the physical memory cannot be read."""

# Measured costs (bytes), with a margin: see the module docstring.
VALUE = 8
"""One float64."""
SAMPLE_COPIES = 4
"""Copies of the sampled values a command holds at its peak (result, dataset, sorted view, output)."""
JSON_COPIES = 8
"""The same with ``--json`` (a Python float and its text per value)."""
POINT_OVERHEAD = 600
"""Per sweep point besides its samples: the point's parameter tuple, flags, coordinates."""
TRAJECTORY_COPIES = 3
"""Copies of a dense trajectory (engine buffer, its growth, the stacked array written out)."""
CURVE_POINT = 400
"""Per point of an equal-damping curve (arrays, the printed or JSON line)."""
RECORDING_SAMPLE = 120
"""Per sample of a synthetic recording (time, true and measured angle, noise, trigger, columns)."""
RECORDING_PERIOD = 400 * 3 * VALUE * TRAJECTORY_COPIES
"""Per forcing period of a synthetic recording (its dense trajectory, 400 points a period)."""

_SIZE = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([kKmMgGtT]?)i?[bB]?\s*$")
_UNITS = {"": 1, "k": 1e3, "m": 1e6, "g": 1e9, "t": 1e12}


class MemoryLimitError(GrazingError):
    """A run would need more memory than the bound (the message says how to split or stream it)."""


def parse_size(text: str) -> int:
    """Bytes in a size such as ``8G``, ``512M``, ``2.5e9`` (decimal units).

    Raises
    ------
    GrazingError
        If ``text`` is not such a size.
    """
    m = _SIZE.match(text)
    size = float(m.group(1)) * _UNITS[m.group(2).lower()] if m else math.nan
    if not math.isfinite(size):  # (1e400 is a float overflow)
        raise GrazingError(f"{MEMORY_ENV}={text!r} is not a size such as 8G or 512M")
    return int(size)


def physical_memory() -> int | None:
    """Bytes of physical memory, or None where it cannot be read."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return None


def memory_limit() -> tuple[float, str]:
    """The bound in bytes and where it comes from (for the message)."""
    env = os.environ.get(MEMORY_ENV, "").strip()
    if env:
        return float(parse_size(env)), f"set by {MEMORY_ENV}"
    phys = physical_memory()
    if phys is None:
        return FALLBACK_LIMIT, f"the default; set {MEMORY_ENV} to change it"
    return DEFAULT_FRACTION * phys, f"half of this machine's memory; set {MEMORY_ENV} to change it"


def format_bytes(n: float) -> str:
    """A byte count with three significant digits and a decimal unit."""
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n:.0f} B"


def check_memory(need: float, what: str, advice: str) -> None:
    """Refuse a run whose estimated memory ``need`` (bytes) exceeds the bound.

    Parameters
    ----------
    need
        Estimated bytes.
    what
        What needs it, as the start of the message (``"a sweep of 1e9 points"``).
    advice
        How to split the work or stream it to a file.

    Raises
    ------
    MemoryLimitError
        One line: the estimate, the bound, where the bound comes from, the advice.
    """
    limit, source = memory_limit()
    if not need <= limit:  # also refuses a non-finite estimate
        raise MemoryLimitError(
            f"{what} needs about {format_bytes(need)} of memory, more than the limit of "
            f"{format_bytes(limit)} ({source}); {advice}"
        )


def simulate_bytes(periods: int, n_states: int, trajectory_points: int = 0, as_json: bool = False) -> float:
    """Memory of ``simulate``: the stroboscopic samples and, if asked, the dense trajectory."""
    copies = JSON_COPIES if as_json else SAMPLE_COPIES
    samples = float(periods) * (n_states + 1) * VALUE * copies
    return samples + float(trajectory_points) * (n_states + 1) * VALUE * TRAJECTORY_COPIES


def sweep_bytes(
    n_points: int,
    periods: int,
    n_states: int,
    *,
    streamed: bool,
    as_json: bool,
    chunk_points: int,
    workers: int,
) -> float:
    """Memory of a sweep or map.

    ``streamed``: the results go to a Zarr store and are not read back at the
    end (only the detected periods are), so only the chunks in flight hold samples.
    """
    per_sample = float(periods) * n_states * VALUE
    held = chunk_points * (2 * workers + 2) if streamed else n_points
    copies = JSON_COPIES if as_json else SAMPLE_COPIES
    return float(n_points) * POINT_OVERHEAD + min(held, n_points) * per_sample * copies


def curve_bytes(num: int) -> float:
    """Memory of an equal-damping curve of ``num`` points."""
    return float(num) * CURVE_POINT


def recording_bytes(n_samples: float, periods: int) -> float:
    """Memory of one synthetic recording of ``n_samples`` samples spanning ``periods`` forcing periods."""
    return float(n_samples) * RECORDING_SAMPLE + float(periods) * RECORDING_PERIOD


def count_text(n: float) -> str:
    """A count for messages: ``1000000000`` -> ``1e+09``, small counts as they are.

    >>> count_text(1000000000), count_text(1234)
    ('1e+09', '1234')
    """
    return f"{n:.3g}" if n >= 1e6 or not math.isfinite(n) else f"{int(n)}"


DECAY_CYCLE = 200 * 3 * VALUE * (TRAJECTORY_COPIES + 1)
"""Per cycle of a simulated free decay (200 trajectory points a cycle, rescaled copies)."""


def decay_bytes(cycles: int) -> float:
    """Memory of a free decay simulated over ``cycles`` cycles."""
    return float(cycles) * DECAY_CYCLE


BASIN_POINT = 160
"""Per initial state of a basin besides its state: labels, flags, the sweep point, a deferred end state."""
BASIN_JSON = 48
"""Per initial state with ``--json`` (its label as a Python int and as text)."""


def basin_bytes(
    n_points: float,
    periods: int,
    n_states: int,
    *,
    chunk_points: int,
    workers: int,
    as_json: bool,
    values: int = 1,
) -> float:
    """Memory of ``basins`` and ``attractors``: per initial state (state, labels), and the chunks in flight.

    The end states are classified chunk by chunk, so only the chunks in flight hold samples; the
    labels of every parameter value (``values``) are kept, and each value's own row
    (:data:`POINT_OVERHEAD`: the value, its attractors' rows, its JSON).
    """
    per_point = BASIN_POINT + 3 * n_states * VALUE + (BASIN_JSON if as_json else 0)
    flight = float(chunk_points) * (2 * workers + 2) * periods * n_states * VALUE * 2
    return (
        float(n_points) * (per_point + 4 * (values - 1))
        + min(flight, float(n_points) * periods * n_states * 16)
        + (float(values) * POINT_OVERHEAD if values > 1 else 0.0)
    )
