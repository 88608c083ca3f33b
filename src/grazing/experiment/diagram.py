"""Experimental bifurcation diagrams (fig 2 style) from a folder of recordings.

One recording per forcing frequency; each is run through
:func:`~grazing.experiment.analyze_recording` and contributes its
stroboscopic samples at its ``eta`` (frequency converted with the apparatus).
The forcing frequency of a file comes from, in this order: its sidecar JSON
(``forcing_hz``), its name (``...0.4592Hz.csv``), its trigger column.  The stop
angle comes from the sidecars (``theta_hat_deg``) or is given.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from grazing.experiment.apparatus import PAPER_RIG, Apparatus
from grazing.experiment.recording import RecordingError, frequency_from_name, load_recording
from grazing.experiment.signal import DEFAULT_CUTOFF_MULTIPLE, DEFAULT_MAX_PERIOD, Analysis, analyze_recording

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes


@dataclass(frozen=True)
class ExperimentDiagram:
    """A bifurcation diagram from recordings, ordered by forcing frequency.

    Attributes
    ----------
    theta_hat_deg
        Stop angle (degrees) from the sidecars or the caller, or None.
    analyses
        One :class:`~grazing.experiment.Analysis` per recording.
    files
        The recordings' file names.
    synthetic
        True when every sidecar says the recording is synthetic.

    Examples
    --------
    Two synthetic recordings at θ̂ = 40° analysed as the rig's would be
    (:func:`load_diagram`): period 1 before the grazing, period 5 after, each file
    named by its forcing frequency in Hz on the paper's rig:

    >>> import tempfile
    >>> from grazing.experiment import load_diagram
    >>> from grazing.experiment.synthetic import synthetic_sweep
    >>> folder = tempfile.mkdtemp()
    >>> _ = synthetic_sweep(folder, 40.0, [0.43, 0.446], periods=30, sample_rate=250.0)
    >>> d = load_diagram(folder)
    >>> d.synthetic, len(d.analyses), d.files
    (True, 2, ('theta40_0.442759Hz.csv', 'theta40_0.459234Hz.csv'))
    """

    theta_hat_deg: float | None
    analyses: tuple[Analysis, ...]
    files: tuple[str, ...]
    synthetic: bool = False

    @property
    def forcing_hz(self) -> np.ndarray:
        return np.array([a.forcing_hz for a in self.analyses])

    @property
    def eta(self) -> np.ndarray:
        return np.array([a.eta for a in self.analyses])

    @property
    def period(self) -> np.ndarray:
        return np.array([a.period for a in self.analyses], dtype=int)

    @property
    def noise(self) -> np.ndarray:
        return np.array([a.noise for a in self.analyses])

    def samples(self) -> list[np.ndarray]:
        """Stroboscopic angles (rad) of every recording (NaN-free)."""
        return [a.samples[np.isfinite(a.samples)] for a in self.analyses]


def _file_frequency(path: Path, meta: dict[str, Any], has_trigger: bool) -> float | None:
    if "forcing_hz" in meta:
        f = meta["forcing_hz"]
        if not isinstance(f, (int, float)) or isinstance(f, bool) or not (math.isfinite(f) and f > 0):
            raise RecordingError(f"{path.with_suffix('.json').name}: forcing_hz must be a positive number")
        return float(f)
    f = frequency_from_name(path)
    if f is not None:
        return f
    if has_trigger:
        return None  # measured from the pulses
    raise RecordingError(
        f"{path.name}: no forcing frequency: give forcing_hz in {path.with_suffix('.json').name}, "
        "write it in the file name (e.g. run_0.4592Hz.csv), or record a trigger column"
    )


def _sidecar_theta(path: Path, value: Any) -> float:
    """A sidecar's ``theta_hat_deg``: a number in (-180, 180), or a one-line :class:`RecordingError`."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    if not (ok and math.isfinite(value) and -180.0 < value < 180.0):
        raise RecordingError(
            f"{path.with_suffix('.json').name}: theta_hat_deg must be a number of degrees in (-180, 180), "
            f"got {json.dumps(value)}"
        )
    return float(value)


def load_diagram(
    folder: str | Path,
    *,
    theta_hat_deg: float | None = None,
    degrees: bool = False,
    phase: float = 0.0,
    cutoff_multiple: float = DEFAULT_CUTOFF_MULTIPLE,
    max_period: int = DEFAULT_MAX_PERIOD,
    apparatus: Apparatus = PAPER_RIG,
    progress: Callable[[int, int], None] | None = None,
) -> ExperimentDiagram:
    """Analyse every ``*.csv`` recording in a folder into a bifurcation diagram.

    Parameters
    ----------
    folder
        Folder with one recording per forcing frequency (and optional sidecars).
    theta_hat_deg
        Stop angle in degrees; default from the sidecars, which must agree.
    degrees, phase, cutoff_multiple, max_period
        As in :func:`~grazing.experiment.load_recording` and
        :func:`~grazing.experiment.analyze_recording`.
    apparatus
        Rig for converting the frequencies to ``eta``.
    progress
        Called as ``progress(done, total)``.

    Returns
    -------
    ExperimentDiagram
        One analysis per recording, in increasing forcing frequency.

    Examples
    --------
    >>> import tempfile
    >>> from grazing.experiment.synthetic import synthetic_sweep
    >>> folder = tempfile.mkdtemp()
    >>> _ = synthetic_sweep(folder, 40.0, [0.43, 0.446], periods=30, sample_rate=250.0)
    >>> d = load_diagram(folder)
    >>> d.theta_hat_deg, d.eta.round(4).tolist(), d.period.tolist()
    (40.0, [0.43, 0.446], [1, 5])
    """
    root = Path(folder)
    if not root.is_dir():
        raise RecordingError(f"{root}: no such folder")
    paths = sorted(p for p in root.iterdir() if p.suffix.lower() == ".csv" and not p.name.startswith("."))
    if not paths:
        raise RecordingError(f"{root}: no .csv recordings in the folder")
    analyses: list[tuple[float, str, Analysis]] = []
    thetas: set[float] = set()
    synthetic = True
    for j, path in enumerate(paths):
        rec = load_recording(path, degrees=degrees)
        hz = _file_frequency(path, rec.metadata, rec.trigger_times is not None)
        res = analyze_recording(
            rec, hz, phase=phase, cutoff_multiple=cutoff_multiple, max_period=max_period, apparatus=apparatus
        )
        synthetic = synthetic and bool(rec.metadata.get("synthetic", False))
        if "theta_hat_deg" in rec.metadata:
            thetas.add(_sidecar_theta(path, rec.metadata["theta_hat_deg"]))
        analyses.append((res.forcing_hz, path.name, res))
        if progress is not None:
            progress(j + 1, len(paths))
    if theta_hat_deg is None and len(thetas) > 1:
        raise RecordingError(
            f"{root}: the sidecars give different stop angles {sorted(thetas)}; one folder is one diagram"
        )
    theta = theta_hat_deg if theta_hat_deg is not None else (thetas.pop() if thetas else None)
    analyses.sort(key=lambda a: a[0])
    return ExperimentDiagram(
        theta_hat_deg=theta,
        analyses=tuple(a[2] for a in analyses),
        files=tuple(a[1] for a in analyses),
        synthetic=synthetic,
    )


def model_sweep(
    theta_hat_deg: float,
    etas: Sequence[float],
    *,
    case: str | None = "B",
    periods: int = 60,
    transient: int = 300,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    **params: float,
) -> Any:
    """The model's brute-force diagram over ``etas`` at the same stop angle (an :class:`xarray.Dataset`).

    A thin wrapper of :func:`grazing.sweeps.sweep` (increasing ``eta``,
    continuation from point to point, as the rig is swept).

    Parameters
    ----------
    theta_hat_deg
        Stop angle in degrees.
    etas
        The forcing frequencies.
    case
        The pendulum's parameter case (``None``: the model's defaults).
    periods, transient
        Forcing periods sampled, and run before, at each ``eta``.
    workers
        Local threads (default: all cores).
    progress
        Called as ``progress(done, total)``.
    **params
        Other parameter values of the pendulum (``alpha``, ``beta``, ``r``).

    Returns
    -------
    xarray.Dataset
        As :func:`grazing.sweeps.sweep` returns.

    Examples
    --------
    >>> ds = model_sweep(40.0, [0.43, 0.446], periods=20, workers=1)
    >>> ds.period.values.tolist()
    [1, 5]
    """
    from grazing.models.pendulum import pendulum
    from grazing.sweeps import sweep

    model = pendulum(case, theta_hat=math.radians(theta_hat_deg), **params)
    return sweep(
        model, "eta", np.asarray(etas, dtype=float), periods=periods, transient=transient,
        workers=workers, lyapunov=False, progress=progress,
    )  # fmt: skip


def plot_diagram(
    ax: Axes,
    diagram: ExperimentDiagram,
    model: Any = None,
    *,
    degrees: bool = True,
    label: str = "recordings",
) -> None:
    """Draw a fig 2-style diagram: stroboscopic angles against ``eta``, the model's sweep behind.

    Parameters
    ----------
    ax
        Axes to draw on.
    diagram
        The recordings' diagram.
    model
        Optional :func:`model_sweep` result, drawn in grey behind.
    degrees
        Angles in degrees (else radians).
    label
        Legend label of the recordings (say "synthetic recordings" for synthetic data).
    """
    k = 180.0 / math.pi if degrees else 1.0
    if model is not None:
        v = model["value"].values
        s = model.samples.values[..., 0]
        xs = np.repeat(v, s.shape[1])
        ax.plot(xs, s.ravel() * k, ".", color="tab:orange", ms=1.0, alpha=0.6)
        ax.plot([], [], "s", color="tab:orange", ms=3, label="model sweep")  # legend proxy
    for a in diagram.analyses:
        s = a.samples[np.isfinite(a.samples)]
        ax.plot(np.full(s.size, a.eta), s * k, ".", color="k", ms=2.0)
    ax.plot([], [], ".", color="k", ms=4, label=label)
    ax.legend(loc="best", fontsize="small")
    ax.set_xlabel("η")
    ax.set_ylabel("θ at the sampling phase" + (" (degrees)" if degrees else " (rad)"))
    if diagram.theta_hat_deg is not None:
        ax.set_title(f"θ̂ = {diagram.theta_hat_deg:g}°")
