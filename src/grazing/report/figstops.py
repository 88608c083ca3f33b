"""Beyond the pendulum: the oscillator between two stops, against its closed forms (not in the paper).

The model ``x'' + 2 zeta x' + x = amp cos(omega t)`` with stops at
``x = gap_right`` and ``x = -gap_left`` (:mod:`grazing.models.two_sided_oscillator`)
is swept in the forcing frequency ``omega`` with the impacts counted per stop;
its nonimpacting orbit's grazings with each stop are located by continuation
and marked.  Below grazing the motion is linear, so the amplitude, the Floquet
multipliers and the grazing frequencies have closed forms, which every row
checks; an orbit hitting both stops checks the determinant of its monodromy
matrix, ``r^4 exp(-2 zeta T)``.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from grazing.errors import GrazingWarning
from grazing.models import two_sided_oscillator
from grazing.orbits import find_grazings, find_orbit
from grazing.plotting import plot_bifurcation
from grazing.report.base import Comparison, DataFile, FigureResult, Image, Say, new_figure, save_png
from grazing.report.data import write_dataset
from grazing.report.rules import criterion_row, numeric_row
from grazing.sweeps import sweep

FIGURE_ID = "stops"
STOPS = ("right", "left")
CLOSED_FORM = "closed form"
"""What the reference column holds for the rows checked against the linear oscillator's exact solution."""
COLORS = {"right": "tab:red", "left": "tab:blue"}


@dataclass(frozen=True)
class Settings:
    """Resolution and cost of the section."""

    values: tuple[float, float, int] = (0.5, 1.6, 221)
    """ω range and number of sweep points."""
    transient: int = 300
    periods: int = 32
    params: tuple[tuple[str, float], ...] = (("amp", 0.5), ("gap_right", 1.0), ("gap_left", 1.5))
    """The model's parameters (the others keep their defaults: ζ = 0.05, r = 0.8)."""
    workers: int | None = None


SETTINGS = Settings()
"""Resolution used by the report (tests pass a smaller one to :func:`build`)."""


def linear_amplitude(model: Any, omega: float | None = None) -> float:
    """``amp / |1 - w^2 + 2 i zeta w|``: the amplitude of the linear (nonimpacting) response."""
    p = model.params
    w = p["omega"] if omega is None else omega
    return p["amp"] / math.hypot(1 - w * w, 2 * p["zeta"] * w)


def grazing_frequencies(model: Any, gap: float) -> list[float]:
    """The ω where the linear amplitude is ``gap``: ``(1 - u)^2 + 4 zeta^2 u = (amp/gap)^2``, ``u = ω^2``."""
    z, a = model.params["zeta"], model.params["amp"]
    b = 2 - 4 * z * z
    disc = b * b - 4 * (1 - (a / gap) ** 2)
    if disc < 0:
        return []
    roots = [(b - math.sqrt(disc)) / 2, (b + math.sqrt(disc)) / 2]
    return [math.sqrt(u) for u in roots if u > 0]


@dataclass
class Run:
    model: Any
    ds: Any
    grazings: dict[str, list[Any]]
    seconds: float


def compute(s: Settings, progress: Say | None = None) -> Run:
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    model = two_sided_oscillator(**dict(s.params))
    lo, hi, num = s.values
    say(f"two stops: sweep in ω, {num} points, {s.transient} + {s.periods} periods each")
    ds = sweep(
        model, "omega", np.linspace(lo, hi, num), transient=s.transient, periods=s.periods, workers=s.workers
    )
    say("two stops: grazings of the nonimpacting orbit with each stop")
    with warnings.catch_warnings():  # (a grazing that passes through the other stop is drawn as such)
        warnings.simplefilter("ignore", GrazingWarning)
        grazings = {name: find_grazings(model, "omega", lo, hi, stop_name=name)[0] for name in STOPS}
    return Run(model, ds, grazings, time.perf_counter() - start)


def draw(run: Run, path: Path) -> None:
    fig, axes = new_figure(2, 1, (8.0, 6.4))
    ax1, ax2 = np.ravel(axes)
    plot_bifurcation(ax1, run.ds, windows=False, nonimpacting=False)
    ax1.set_title("stroboscopic x against ω; dashed: grazings of the nonimpacting orbit\n(dotted: it passes "
                  "through the other stop)")  # fmt: skip
    omega = run.ds["value"].values
    for name in STOPS:
        ipp = run.ds.impacts_per_period_by_stop.sel(stop=name).values
        ax2.plot(omega, ipp, ".", ms=3, color=COLORS[name], label=f"stop {name}")
        for g in run.grazings[name]:
            for ax in (ax1, ax2):  # dotted: that orbit passes through the other stop (not a motion)
                ax.axvline(g.model.params["omega"], color=COLORS[name], ls=":" if g.crossed else "--", lw=0.8)
    gaps = {"right": run.model.params["gap_right"], "left": -run.model.params["gap_left"]}
    for name, level in gaps.items():
        ax1.axhline(level, color=COLORS[name], lw=0.8)
    ax1.set_ylim(1.1 * gaps["left"], 1.1 * gaps["right"])
    ax2.set_xlim(ax1.get_xlim())
    ax2.set_xlabel("ω")
    ax2.set_ylabel("impacts per period of the orbit")
    ax2.legend(loc="upper right")
    save_png(fig, path)


def comparisons(run: Run) -> tuple[Comparison, ...]:
    m = run.model
    rows: list[Comparison] = []
    note = "closed form of the linear response (the motion below grazing touches no stop)"
    w0 = 0.5
    below = m.with_params(omega=w0)
    orbit = find_orbit(below, period=1, tol=1e-13)
    x, v = orbit.state
    rows.append(
        numeric_row(
            FIGURE_ID,
            f"ω = {w0}: amplitude of the nonimpacting orbit",
            linear_amplitude(below),
            math.hypot(x, v / w0),
            kind="self-check",
            reference=CLOSED_FORM,
            tolerance=1e-10,
            decimals=12,
            note=note,
            paper_text=f"{linear_amplitude(below):.12f}",
            why_tolerance="1e-10",
        )
    )
    T, z = below.period, m.params["zeta"]
    exact = complex(
        math.exp(-z * T) * math.cos(T * math.sqrt(1 - z * z)),
        abs(math.exp(-z * T) * math.sin(T * math.sqrt(1 - z * z))),
    )
    ours = max(orbit.multipliers, key=lambda c: c.imag)
    d = abs(complex(ours.real, abs(ours.imag)) - exact)
    rows.append(
        criterion_row(
            FIGURE_ID,
            f"ω = {w0}: Floquet multipliers",
            f"{exact.real:.10f} ± {exact.imag:.10f}i",
            f"{ours.real:.10f} ± {abs(ours.imag):.10f}i",
            d <= 1e-10,
            kind="self-check",
            reference=CLOSED_FORM,
            rule="agree when |ours − exp(T(−ζ ± i√(1−ζ²)))| ≤ 1e-10",
            delta=d,
            delta_text=f"|Δ| = {d:.1e}",
            note=note,
        )
    )
    for name, gap in (("right", m.params["gap_right"]), ("left", m.params["gap_left"])):
        exact_w = [w for w in grazing_frequencies(m, gap) if run.ds["value"].values.min() <= w]
        found = sorted(run.grazings[name], key=lambda g: g.model.params["omega"])
        for i, w in enumerate(exact_w):
            g = min(found, key=lambda g: abs(g.model.params["omega"] - w)) if found else None
            near = g.model.params["omega"] if g is not None else math.nan
            crossed = (
                f"; that orbit passes through stop {', '.join(g.crossed)} (hit first), so this grazing "
                "of the linear response is not a motion of the system (dotted in the figure)"
                if g is not None and g.crossed
                else ""
            )
            rows.append(
                numeric_row(
                    FIGURE_ID,
                    f"grazing {i + 1} with stop {name} (gap {gap:g}): ω",
                    w,
                    near,
                    kind="self-check",
                    reference=CLOSED_FORM,
                    tolerance=1e-8,
                    decimals=10,
                    why_tolerance="1e-8",
                    paper_text=f"{w:.10f}",
                    note="closed form: the linear amplitude equals the gap; ours: continuation of the "
                    "nonimpacting orbit watching that stop, then Newton on the grazing equations" + crossed,
                )
            )
    both = m.with_params(amp=1.0, omega=0.8, gap_left=1.0)
    orb2 = find_orbit(both, period=1)
    r = m.params["r"]
    det_exact = r**4 * math.exp(-2 * z * both.period)
    det = float(np.linalg.det(orb2.monodromy))
    per_stop = sorted(orb2.impact_stops.tolist())
    rows.append(
        numeric_row(
            FIGURE_ID,
            "ω = 0.8, amp = 1, both gaps 1: det(monodromy) of the period-1 orbit hitting both stops",
            det_exact,
            det,
            kind="self-check",
            reference=CLOSED_FORM,
            tolerance=1e-9 * det_exact,
            decimals=12,
            why_tolerance="1e-9 relative",
            paper_text=f"{det_exact:.12f}",
            note=f"r^(2k) exp(−2ζT) with k = 2 impacts per period (stops {per_stop})",
        )
    )
    first = min(g.model.params["omega"] for name in STOPS for g in run.grazings[name])
    omega = run.ds["value"].values
    ipp = run.ds.impacts_per_period.values
    quiet = ipp[omega < first - 1e-3]
    rows.append(
        criterion_row(
            FIGURE_ID,
            "sweep: no impacts below the first grazing",
            "0 impacts",
            f"max {np.nanmax(quiet):g} impacts per period",
            bool(np.nanmax(quiet) == 0),
            kind="self-check",
            reference="below the first grazing",
            rule=f"agree when every sweep point with ω < {first:.4f} − 0.001 has no impact",
        )
    )
    return tuple(rows)


def write_data(run: Run, out_dir: Path) -> DataFile:
    ds = run.ds[["period", "impacts_per_period", "impacts_per_period_by_stop"]].copy()
    ds.attrs = {k: v for k, v in run.ds.attrs.items() if isinstance(v, (str, int, float))}
    path = write_dataset(out_dir / "stops_sweep.nc", ds)
    return DataFile(path.name, "the sweep's detected period and impacts per period on each stop, NetCDF")


def build(out_dir: Path, progress: Say | None = None, settings: Settings | None = None) -> FigureResult:
    """Compute the section, write its PNG and data into ``out_dir`` and describe it."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    s = settings or SETTINGS
    run = compute(s, say)
    name = "stops_sweep.png"
    draw(run, out_dir / name)
    p = run.model.params
    image = Image(
        name,
        f"The oscillator between two stops (ζ = {p['zeta']:g}, amp = {p['amp']:g}, "
        f"gap right {p['gap_right']:g}, gap left {p['gap_left']:g}, r = {p['r']:g}): {s.values[2]} values "
        "of ω "
        f"swept upwards, each from the previous one's final state, {s.transient} transient and {s.periods} "
        "sampled periods. Top: the samples "
        "(the stops as horizontal lines); bottom: impacts on each stop per period of the detected orbit (per "
        "forcing period where none is detected). Dashed: the "
        "grazings of the nonimpacting orbit with each stop, from continuation; dotted where that orbit "
        "already passes through the other stop (the system hits that stop first: not a motion of the "
        "system).",
        "Bifurcation diagram of the two-sided oscillator in omega with impacts per stop",
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="Extra: any impacting system — the oscillator between two stops",
        images=(image,),
        summary=(
            "Not in the paper: the same tools on another model, with a stop on each side. Below its first "
            "grazing the motion is linear, so every number here has a closed form to check against."
        ),
        comparisons=comparisons(run),
        seconds=time.perf_counter() - start,
        data=(write_data(run, out_dir),),
    )
