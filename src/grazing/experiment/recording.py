"""Recorded angle time series: loading, validation, resampling, and the forcing's timing.

A recording is a CSV file with a header row and the columns

``time``
    seconds, strictly increasing;
``angle``
    radians (degrees with ``degrees=True``); an empty field or ``nan`` is a
    gap (a missing sample), which is reported and bridged;
``trigger`` (optional)
    1 on the sample where the forcing passes its reference phase (the sample
    nearest to that instant), 0 elsewhere.

Other columns are ignored; column names are case-insensitive.  Lines that
start with ``#`` are comments, before the header or among the rows (grazing
ends each CSV file it writes with one: :mod:`grazing.outputs`).  A sidecar
``NAME.json`` next to ``NAME.csv`` may give ``forcing_hz``, ``theta_hat_deg``
and anything else (the synthetic recordings write one).

Every defect is reported as a :class:`RecordingError` with one line naming the
file, the line and the problem: a missing column, a non-numeric field, times
that are unsorted or repeated, too short a record.  Non-uniform sampling is
resampled on a uniform grid; a jump in time longer than
:data:`GAP_FACTOR` sampling intervals becomes a gap.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from grazing.errors import GrazingError

MIN_SAMPLES = 16
"""Fewest samples a recording may have."""

MIN_PERIODS = 8
"""Fewest forcing periods a recording must span to be analysed."""

GAP_FACTOR = 5.0
"""A time step longer than this many median steps is a gap, not slow sampling."""

UNIFORM_TOL = 1e-3
"""Relative deviation of a time step from the median beyond which the record is resampled."""

MAX_MISSING = 0.5
"""Largest fraction of missing angle samples accepted."""

_MISSING = {"", "nan", "NaN", "NAN", "na", "NA", "null"}
_HZ_IN_NAME = re.compile(r"(\d+(?:[.p]\d+)?)\s*hz", re.IGNORECASE)


class RecordingError(GrazingError, ValueError):
    """A recording cannot be used as it is (a one-line message names the file and the problem).

    Examples
    --------
    >>> import numpy as np
    >>> from_arrays(np.array([0.0, 1.0, 0.5]), np.zeros(3))
    Traceback (most recent call last):
    ...
    grazing.experiment.recording.RecordingError: <memory>: only 3 samples; a recording needs at least 16
    """


@dataclass(frozen=True)
class Recording:
    """A uniformly sampled angle record.

    Attributes
    ----------
    time
        Sample times in seconds, uniform.
    angle
        Angle in radians; NaN inside gaps.
    trigger_times
        Times (s) of the trigger pulses (the forcing at its reference phase),
        or None without a trigger column.
    source
        Where the data came from (file name).
    resampled
        True when the recorded times were not uniform and the angle was
        interpolated on a uniform grid.
    gaps
        ``(t_start, t_end)`` of every run of missing samples.
    metadata
        The sidecar JSON (empty if none).

    Examples
    --------
    >>> from grazing.experiment.synthetic import synthetic_recording
    >>> rec = synthetic_recording(0.446, 40.0, periods=40, sample_rate=250.0, seed=2)
    >>> round(rec.sample_rate, 6), rec.time.size, rec.trigger_times is not None, rec.resampled, rec.gaps
    (250.0, 21776, True, False, ())
    >>> rec.metadata["synthetic"], rec.metadata["eta"]
    (True, 0.446)
    """

    time: np.ndarray
    angle: np.ndarray
    trigger_times: np.ndarray | None = None
    source: str = "<memory>"
    resampled: bool = False
    gaps: tuple[tuple[float, float], ...] = ()
    metadata: dict[str, Any] = field(default_factory=dict)

    @property
    def sample_rate(self) -> float:
        """Samples per second."""
        return float((self.time.size - 1) / (self.time[-1] - self.time[0]))

    @property
    def duration(self) -> float:
        """Length of the record in seconds."""
        return float(self.time[-1] - self.time[0])

    def filled_angle(self) -> np.ndarray:
        """The angle with gaps bridged by linear interpolation (for filtering)."""
        x = self.angle
        bad = ~np.isfinite(x)
        if not bad.any():
            return x.copy()
        return np.interp(self.time, self.time[~bad], x[~bad])

    def in_gap(self, t: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """Whether each time in ``t`` lies within ``margin`` s of a gap."""
        t = np.asarray(t, dtype=float)
        out = np.zeros(t.shape, dtype=bool)
        for a, b in self.gaps:
            out |= (t >= a - margin) & (t <= b + margin)
        return out


def from_arrays(
    time: np.ndarray,
    angle: np.ndarray,
    trigger: np.ndarray | None = None,
    *,
    source: str = "<memory>",
    metadata: dict[str, Any] | None = None,
) -> Recording:
    """Validate and, if needed, resample arrays into a :class:`Recording`.

    Parameters
    ----------
    time, angle
        Sample times (s) and angles (rad; NaN for missing samples).
    trigger
        Optional 0/1 trigger column, one value per sample.
    source, metadata
        Name used in messages, and extra information to keep.

    Returns
    -------
    Recording
        The record, uniform in time.

    Examples
    --------
    >>> t = np.array([0.0, 0.1, 0.25, 0.3] + [0.4 + 0.1 * k for k in range(20)])
    >>> rec = from_arrays(t, np.sin(t))
    >>> rec.resampled, round(rec.sample_rate, 6)
    (True, 10.0)
    """
    t = np.asarray(time, dtype=float).ravel()
    x = np.asarray(angle, dtype=float).ravel()
    if t.size != x.size:
        raise RecordingError(f"{source}: time and angle differ in length ({t.size} and {x.size})")
    if t.size < MIN_SAMPLES:
        raise RecordingError(f"{source}: only {t.size} samples; a recording needs at least {MIN_SAMPLES}")
    if not np.all(np.isfinite(t)):
        raise RecordingError(f"{source}: sample {int(np.argmin(np.isfinite(t)))} has a non-finite time")
    dt = np.diff(t)
    if np.any(dt == 0):
        i = int(np.argmax(dt == 0))
        raise RecordingError(f"{source}: time {t[i]:g} s appears twice (samples {i} and {i + 1})")
    if np.any(dt < 0):
        i = int(np.argmax(dt < 0))
        raise RecordingError(
            f"{source}: times are not sorted: {t[i + 1]:g} s after {t[i]:g} s (sample {i + 1})"
        )
    finite = np.isfinite(x)
    if np.any(np.isinf(x)):
        raise RecordingError(f"{source}: sample {int(np.argmax(np.isinf(x)))} has an infinite angle")
    if finite.sum() < MIN_SAMPLES or (1.0 - finite.mean()) > MAX_MISSING:
        raise RecordingError(
            f"{source}: {int((~finite).sum())} of {x.size} angle values are missing (at most "
            f"{MAX_MISSING:.0%} may be)"
        )
    trig_times = None
    if trigger is not None:
        g = np.asarray(trigger, dtype=float).ravel()
        if g.size != t.size:
            raise RecordingError(f"{source}: trigger column differs in length from time")
        bad = ~np.isin(g, (0.0, 1.0))
        if bad.any():
            i = int(np.argmax(bad))
            raise RecordingError(f"{source}: trigger must be 0 or 1, got {g[i]:g} at sample {i}")
        trig_times = t[g == 1.0]
        if trig_times.size < 2:
            raise RecordingError(
                f"{source}: the trigger column has {trig_times.size} pulse(s); need at least 2"
            )
    step = float(np.median(dt))
    resampled = bool(np.any(np.abs(dt - step) > UNIFORM_TOL * step))
    gaps_t: list[tuple[float, float]] = []
    if resampled:
        n = math.floor((t[-1] - t[0]) / step + 1e-9) + 1
        tg = t[0] + step * np.arange(n)
        xg = np.interp(tg, t[finite], x[finite])
        # long time jumps and runs of missing values become NaN on the grid
        for i in np.nonzero(dt > GAP_FACTOR * step)[0]:
            gaps_t.append((float(t[i]), float(t[i + 1])))
        for a, b in _nan_runs(t, finite):
            gaps_t.append((a, b))
        for a, b in gaps_t:
            xg[(tg > a) & (tg < b)] = np.nan
        t, x = tg, xg
    else:
        gaps_t = _nan_runs(t, finite)
    gaps = tuple(sorted(gaps_t))
    return Recording(
        time=t,
        angle=x,
        trigger_times=trig_times,
        source=source,
        resampled=resampled,
        gaps=gaps,
        metadata=dict(metadata or {}),
    )


def _nan_runs(t: np.ndarray, finite: np.ndarray) -> list[tuple[float, float]]:
    """``(last good time, next good time)`` around every run of missing samples."""
    runs = []
    bad = ~finite
    if not bad.any():
        return runs
    edges = np.diff(np.concatenate([[0], bad.astype(np.int8), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    for s, e in zip(starts, ends):
        a = t[s - 1] if s > 0 else t[s]
        b = t[e] if e < t.size else t[e - 1]
        runs.append((float(a), float(b)))
    return runs


def read_sidecar(path: str | Path) -> dict[str, Any]:
    """The JSON sidecar of a recording (``NAME.json`` beside ``NAME.csv``), or ``{}``."""
    side = Path(path).with_suffix(".json")
    if not side.is_file():
        return {}
    try:
        data = json.loads(side.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise RecordingError(f"{side.name}: not valid JSON ({exc})") from None
    if not isinstance(data, dict):
        raise RecordingError(f"{side.name}: expected a JSON object")
    return data


def frequency_from_name(path: str | Path) -> float | None:
    """A forcing frequency written in a file name as ``<number>Hz`` (``0.4592Hz``, ``0p4592hz``).

    Examples
    --------
    >>> frequency_from_name("theta40_0.4592Hz.csv"), frequency_from_name("run_0p45hz.csv")
    (0.4592, 0.45)
    >>> frequency_from_name("run3.csv") is None
    True
    """
    m = _HZ_IN_NAME.search(Path(path).stem)
    return float(m.group(1).replace("p", ".")) if m else None


def load_recording(path: str | Path, *, degrees: bool = False) -> Recording:
    """Read and validate a recording CSV (see the module docstring for the format).

    Parameters
    ----------
    path
        The CSV file.  A sidecar ``.json`` beside it becomes :attr:`Recording.metadata`.
    degrees
        The angle column is in degrees (converted to radians).

    Returns
    -------
    Recording
        The record, with its sidecar's metadata.

    Raises
    ------
    RecordingError
        With one line naming the file, the line and the problem.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "rec.csv"
    >>> _ = p.write_text("time,angle\\n" + "".join(f"{k / 10},0.1\\n" for k in range(20)))
    >>> rec = load_recording(p)
    >>> rec.time.size, rec.sample_rate
    (20, 10.0)
    >>> _ = p.write_text("time,angel\\n0,1\\n")
    >>> load_recording(p)
    Traceback (most recent call last):
    ...
    grazing.experiment.recording.RecordingError: rec.csv: missing column 'angle' (found: time, angel)
    """
    path = Path(path)
    name = path.name
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise RecordingError(f"{path}: no such file") from None
    except UnicodeDecodeError:
        raise RecordingError(f"{name}: not a text (CSV) file") from None
    except IsADirectoryError:
        raise RecordingError(f"{path}: is a folder, not a CSV file") from None
    lines = text.splitlines()
    first = next((i for i, line in enumerate(lines) if not _is_comment(line)), len(lines))
    if first == len(lines) or not lines[first].strip():
        raise RecordingError(f"{name}: empty file (expected a header row with time,angle)")
    header = [
        h.strip().lower() for h in next(_csv_rows(lines[first : first + 1], name, first + 1), (1, []))[1]
    ]
    missing = [c for c in ("time", "angle") if c not in header]
    if missing:
        found = ", ".join(h for h in header if h) or "nothing"
        cols = " and ".join(repr(c) for c in missing)
        raise RecordingError(
            f"{name}: missing column{'s' if len(missing) > 1 else ''} {cols} (found: {found})"
        )
    cols = {c: header.index(c) for c in ("time", "angle", "trigger") if c in header}
    data = _parse_rows(lines, header, cols, name, first)
    x = data["angle"]
    if degrees:
        x = np.radians(x)
    return from_arrays(data["time"], x, data.get("trigger"), source=name, metadata=read_sidecar(path))


def _csv_rows(lines: list[str], name: str, first: int = 1) -> Iterator[tuple[int, list[str]]]:
    """``(line number, fields)`` of CSV lines; a malformed line (a field over the csv module's
    limit of 128 kB, a NUL byte...) is a :class:`RecordingError` naming the file and the line."""
    reader = csv.reader(lines)
    while True:
        try:
            row = next(reader)
        except StopIteration:
            return
        except csv.Error as exc:
            raise RecordingError(
                f"{name}: line {first + reader.line_num - 1}: not a valid CSV row ({exc})"
            ) from None
        yield first + reader.line_num - 1, row


def _is_comment(line: str) -> bool:
    return line.lstrip().startswith("#")


def _parse_rows(
    lines: list[str], header: list[str], cols: dict[str, int], name: str, head: int = 0
) -> dict[str, np.ndarray]:
    """Parse the numeric columns (the header is ``lines[head]``); fast path through numpy (which skips
    ``#`` comments), exact error messages from a row loop."""
    body = "\n".join(lines[head + 1 :])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "input contained no data": reported below
            arr = np.loadtxt(io.StringIO(body), delimiter=",", usecols=list(cols.values()), ndmin=2)
        if arr.shape[0] and arr.shape[1] == len(cols) and np.isfinite(arr[:, 0]).all():
            return {c: arr[:, j] for j, c in enumerate(cols)}
    except ValueError:
        pass
    out: dict[str, list[float]] = {c: [] for c in cols}
    width = len(header)
    for lineno, row in _csv_rows(lines[head + 1 :], name, first=head + 2):
        if not row or all(not f.strip() for f in row) or _is_comment(row[0]):
            continue
        if len(row) < width:
            raise RecordingError(f"{name}: line {lineno}: expected {width} fields, got {len(row)}")
        for c, j in cols.items():
            field_ = row[j].strip()
            if c == "angle" and field_ in _MISSING:
                out[c].append(math.nan)
                continue
            try:
                v = float(field_)
            except ValueError:
                raise RecordingError(f"{name}: line {lineno}: {c} {field_!r} is not a number") from None
            if not math.isfinite(v):
                raise RecordingError(f"{name}: line {lineno}: {c} {field_!r} is not a finite number")
            out[c].append(v)
    if not out["time"]:
        raise RecordingError(f"{name}: no data rows after the header")
    return {c: np.array(v, dtype=float) for c, v in out.items()}


# ----------------------------------------------------------------------------
# Forcing timing


@dataclass(frozen=True)
class ForcingClock:
    """When the forcing passes its reference phase.

    Attributes
    ----------
    forcing_hz
        Forcing frequency in Hz.
    reference_times
        Times (s) of the reference phase within the record.
    from_trigger
        True when measured from the trigger column.

    Examples
    --------
    A synthetic recording of the rig at η = 0.446 (0.4592 Hz), with its trigger column:

    >>> from grazing.experiment.synthetic import synthetic_recording
    >>> rec = synthetic_recording(0.446, 40.0, periods=40, sample_rate=250.0, seed=2)
    >>> clock = forcing_clock(rec)
    >>> round(clock.forcing_hz, 4), clock.from_trigger, clock.reference_times[:2].round(4).tolist()
    (0.4592, True, [0.0, 2.1776])
    """

    forcing_hz: float
    reference_times: np.ndarray
    from_trigger: bool

    @property
    def period(self) -> float:
        """Forcing period in seconds."""
        return 1.0 / self.forcing_hz

    def sample_times(self, phase: float = 0.0) -> np.ndarray:
        """Times at forcing phase ``phase`` (radians after the reference)."""
        return self.reference_times + (float(phase) / (2.0 * math.pi)) * self.period


def forcing_clock(
    rec: Recording, forcing_hz: float | None = None, *, min_periods: int = MIN_PERIODS
) -> ForcingClock:
    """The forcing's timing: from the trigger pulses, or from ``forcing_hz`` with phase 0 at t = 0.

    Trigger pulses are quantised to the sampling interval; the reference times
    are the least-squares uniform grid through them (which takes out that
    jitter), unless the pulses are irregular (a drifting frequency), in which
    case they are used as they are.  Missing pulses are allowed.

    Parameters
    ----------
    rec
        The recording.
    forcing_hz
        Forcing frequency in Hz; required without a trigger column.  With a
        trigger column, it must agree with the pulses to 2 %.
    min_periods
        The record must span at least this many forcing periods.

    Returns
    -------
    ForcingClock
        The forcing frequency and the times of its reference phase.

    Examples
    --------
    >>> t = np.arange(0, 20, 0.01)
    >>> trig = (np.arange(t.size) % 200 == 3).astype(float)
    >>> clock = forcing_clock(from_arrays(t, np.sin(t), trig))
    >>> round(clock.forcing_hz, 9), clock.reference_times[:2].round(9).tolist()
    (0.5, [0.03, 2.03])
    """
    src = rec.source
    if forcing_hz is not None and not (math.isfinite(forcing_hz) and forcing_hz > 0):
        raise RecordingError(f"the forcing frequency must be positive, got {forcing_hz:g} Hz")
    if rec.trigger_times is not None:
        tt = rec.trigger_times
        steps = np.diff(tt)
        T0 = float(np.median(steps))
        k = np.round((tt - tt[0]) / T0)
        if np.any(np.diff(k) < 1):
            raise RecordingError(f"{src}: trigger pulses closer together than half a forcing period")
        slope, icpt = np.polyfit(k, tt, 1)
        resid = tt - (icpt + slope * k)
        dt = 1.0 / rec.sample_rate
        if np.max(np.abs(resid)) <= max(1.5 * dt, 1e-3 * slope):
            period = float(slope)
            kk = np.arange(0, int(k[-1]) + 1)
            refs = icpt + period * kk
        else:
            period = float(np.median(steps))
            refs = tt
        hz = 1.0 / period
        if forcing_hz is not None and abs(hz - forcing_hz) > 0.02 * forcing_hz:
            raise RecordingError(
                f"{src}: the trigger pulses give {hz:.6g} Hz "
                f"but the forcing frequency given is {forcing_hz:.6g} Hz"
            )
        clock = ForcingClock(hz, np.asarray(refs, dtype=float), True)
    else:
        if forcing_hz is None:
            raise RecordingError(f"{src}: no trigger column; give the forcing frequency (forcing_hz=)")
        T = 1.0 / forcing_hz
        k0 = math.ceil(rec.time[0] / T - 1e-9)
        k1 = math.floor(rec.time[-1] / T + 1e-9)
        clock = ForcingClock(float(forcing_hz), T * np.arange(k0, k1 + 1), False)
    n_periods = rec.duration * clock.forcing_hz
    if n_periods < min_periods:
        raise RecordingError(
            f"{src}: the record spans {n_periods:.3g} forcing periods ({rec.duration:.4g} s at "
            f"{clock.forcing_hz:.5g} Hz); at least {min_periods} are needed"
        )
    return clock
