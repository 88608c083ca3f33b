"""Beyond impacts: grazing a switching surface without a reset, its 3/2-power map against simulation.

The soft-impact oscillator ``x'' + 2 zeta x' + x = a cos(omega t) - k (x - gap)``
while ``x > gap`` (a spring engages; no reset) is a model with two modes whose
field is continuous across ``x = gap``.  Its free periodic orbit
``x = Re(X exp(i omega t))``, ``X = a / (1 - omega^2 + 2 i zeta omega)``, grazes
the surface when ``|X| = gap``: at ``a* = gap sqrt((1 - omega^2)^2 + (2 zeta omega)^2)``,
which the section locates and checks.  There the map of
:func:`~grazing.normalform.switching_map_at` (``docs/normal-form.md``, section 5)
changes a grazing trajectory by ``-(4/3) sqrt(2 / a) delta^(3/2) (0, k)``,
``a = omega^2 gap``; the section checks it against the flow through the
contact over four decades of the penetration ``delta``
(:func:`~grazing.normalform.switching_check.compare_with_flow`), as
``tests/normalform/test_switching_zdm.py`` does: the difference goes as
``delta^(3/2)``, the map's error as ``delta^(5/2)`` on the grazing orbit's
family and ``delta^2`` off the section, each with one constant.

The model is the built-in ``soft-impact-oscillator`` (parameters ``zeta``, ``a``,
``omega``, ``gap``, ``k``); its grazing is located on the free mode alone with
the surface as a stop (:func:`free_oscillator_with_stop`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from grazing import models
from grazing.core.model import HybridModel, Parameter
from grazing.errors import InvalidParameterError
from grazing.normalform import SwitchingMap, find_grazing_point, switching_map_at
from grazing.normalform.switching_check import FlowCheck, compare_with_flow, loglog_slope, state_at
from grazing.report.base import Comparison, DataFile, FigureResult, Image, Say, new_figure, save_png
from grazing.report.data import write_csv
from grazing.report.rules import criterion_row, numeric_row

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

FIGURE_ID = "switch"
CLOSED_FORM = "closed form"
THEORY = "theory"
FAR = 100.0
"""A gap the motions here never reach: the model then runs its free flow."""
FAMILIES = ("family", "off")
"""The two sets of starts: the grazing orbit's family (``gap* - delta``) and states off the section."""
POWERS = {"family": 2.5, "off": 2.0}
"""The power of the map's error in ``delta`` for each set (the theory of ``docs/normal-form.md`` §5)."""
RELATIVE_POWERS = {"family": 1.0, "off": 0.5}
"""``ε / |Δ| = C delta^p``: ``p`` for each set."""
LABELS = {"family": "grazing orbit's family (gap* − δ)", "off": "off the section (h = δ, L_f h = −√(4aδ))"}

SIZE_SLOPE_TOL = 0.01
"""|Δ|'s slope: the next order (a relative ``C delta^p``) bends the fit by < 0.01 over these decades, and
rounding (~1e-15 against differences >= 1e-11) moves it by < 1e-3."""
ERROR_SLOPE_TOL = 0.05
"""ε's slope: the same next order acts on the error itself (its own relative ``delta^(1/2)`` terms)."""
SAME_CONSTANT = 1.05
"""``max / min`` of ``ε / (|Δ| delta^p)`` over the decades: a coefficient off by a relative ``eps`` adds
``eps`` to ``C delta^p`` at every ``delta`` and breaks this where ``C delta^p < eps / 0.05``."""
COEFFICIENT_TOL = 1e-6
"""Relative: the simulation's coefficient, extrapolated to ``delta -> 0`` from the smallest ``delta``
(rounding of the differences, ~1e-15 against ``k delta^(3/2) >= 4e-9``, limits it to ~1e-7)."""
CLOSED_FORM_TOL = 1e-10
"""The grazing point against its closed form (solved to ~1e-12)."""


@dataclass(frozen=True)
class Settings:
    """The model and the decades of penetration."""

    params: tuple[tuple[str, float], ...] = ()
    """Parameters of the oscillator other than :data:`DEFAULTS` (``a`` is the grazing's)."""
    search: tuple[float, float] = (0.1, 0.5)
    """The interval of ``a`` where the grazing is searched."""
    family: tuple[float, float, int] = (1e-6, 1e-2, 17)
    """``delta`` from, to, number (geometric) on the grazing orbit's family."""
    off: tuple[float, float, int] = (1e-7, 1e-3, 17)
    """The same off the section (the error is larger there: ``delta^2``)."""
    extrapolate: int = 5
    """The smallest ``delta`` of the family from which the simulation's coefficient is extrapolated."""


SETTINGS = Settings()
"""What the report computes (a second or so, once the model's kernels are compiled)."""


DEFAULTS = {"zeta": 0.05, "a": 0.3, "omega": 1.2, "gap": 0.5, "k": 4.0}
"""The oscillator's parameters (the report's: those of ``tests/normalform/test_switching_zdm.py``); ``a``
is replaced by the grazing's."""


def _definition() -> tuple[Any, ...]:
    """The symbols ``x, v, t, gap, k``, the free field and the period."""
    import sympy as sp

    x, v, t, zeta, a, w, gap, k = sp.symbols("x v t zeta a omega gap k")
    return x, v, t, gap, k, [v, -2 * zeta * v - x + a * sp.cos(w * t)], 2 * sp.pi / w


def _parameters(values: dict[str, float]) -> list[Parameter]:
    unknown = set(values) - set(DEFAULTS)
    if unknown:
        raise InvalidParameterError(f"unknown parameters {sorted(unknown)} (known: {', '.join(DEFAULTS)})")
    return [Parameter(name, float(values.get(name, v))) for name, v in DEFAULTS.items()]


def soft_impact_oscillator(**values: float) -> HybridModel:
    """The built-in soft-impact oscillator (:func:`grazing.models.soft_impact_oscillator`: modes ``free``
    and ``contact``, transitions ``touch`` and ``leave`` across ``x = gap`` without a reset) at the
    section's parameters :data:`DEFAULTS`, replaced by ``values``."""
    _parameters(values)  # (the section's parameters only)
    return models.soft_impact_oscillator(**{**DEFAULTS, **values})


def free_oscillator_with_stop(**values: float) -> HybridModel:
    """The free mode alone, the surface a stop: the grazing orbit never enters the contact, so its grazing
    is the free mode's (:func:`~grazing.normalform.find_grazing_point` locates it)."""
    x, v, t, gap, _k, free, period = _definition()
    return HybridModel(
        "free-oscillator-report", [x, v], t, _parameters(values), free, gap - x, [x, -v], period
    )


def grazing_amplitude(p: dict[str, float]) -> float:
    """``a* = gap |1 - omega^2 + 2 i zeta omega|``: the forcing at which the free orbit's amplitude is
    ``gap``."""
    return p["gap"] * math.hypot(1 - p["omega"] ** 2, 2 * p["zeta"] * p["omega"])


def grazing_time(p: dict[str, float]) -> float:
    """``t* = -arg(X) / omega`` modulo the period: when ``x = Re(X exp(i omega t))`` is largest."""
    arg_x = -math.atan2(2 * p["zeta"] * p["omega"], 1 - p["omega"] ** 2)  # X = a / (1 - w^2 + 2 i zeta w)
    return (-arg_x / p["omega"]) % (2 * math.pi / p["omega"])


def free_propagator(p: dict[str, float], span: float) -> np.ndarray:
    """``exp(A span)``, ``A = [[0, 1], [-1, -2 zeta]]``: the free flow's propagator (it is linear)."""
    from scipy.linalg import expm

    return expm(np.array([[0.0, 1.0], [-1.0, -2 * p["zeta"]]]) * span)


@dataclass
class Run:
    """Everything the section shows."""

    zdm: SwitchingMap
    nominal: dict[str, np.ndarray]
    """The penetrations asked for, per set."""
    checks: dict[str, FlowCheck]
    kick: np.ndarray
    """The simulation's velocity change on the section per ``k delta^(3/2)`` on the family (the difference
    carried back by the free propagator), the coefficient it measures at each ``delta``."""
    coefficient: float
    """That coefficient extrapolated to ``delta -> 0`` (a line in ``delta`` through the smallest)."""
    seconds: float

    @property
    def params(self) -> dict[str, float]:
        return dict(self.zdm.model.params)

    def slopes(self, which: str) -> tuple[float, float, float]:
        """Fitted log-log slopes of ``|Δ|``, the prediction's size and ``ε`` against ``delta``."""
        c = self.checks[which]
        return (
            loglog_slope(c.depth, c.size),
            loglog_slope(c.depth, c.predicted_size),
            loglog_slope(c.depth, c.error),
        )

    def constants(self, which: str) -> np.ndarray:
        """``ε / (|Δ| delta^p)`` at every ``delta``: one constant if the map's leading order is right."""
        c = self.checks[which]
        return c.error / c.size / c.depth ** RELATIVE_POWERS[which]


def compute(s: Settings, progress: Say | None = None) -> Run:
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    values = dict(s.params)
    say("switch: the grazing of the soft-impact oscillator's free orbit with x = gap")
    point = find_grazing_point(free_oscillator_with_stop(**values), "a", *s.search)
    model = soft_impact_oscillator(**values, a=point.model.params["a"])
    zdm = switching_map_at(model, "touch", point.contact, point.t_graze)
    p, ts, T = dict(model.params), zdm.t_graze, model.period
    free_model = model.with_params(gap=FAR)
    # the grazing orbit a quarter period before the contact (the free flow from the contact, 3/4 on)
    before = state_at(free_model, zdm.contact, ts, ts + 0.75 * T).x_final
    nominal = {
        "family": np.geomspace(s.family[0], s.family[1], s.family[2]),
        "off": np.geomspace(s.off[0], s.off[1], s.off[2]),
    }
    say(f"switch: the flow through the contact against the map, {s.family[2]} + {s.off[2]} penetrations")
    starts = {
        "family": [(model.with_params(gap=p["gap"] - y), before, ts - T / 4) for y in nominal["family"]],
        "off": [(model, [p["gap"] - y, math.sqrt(4 * zdm.accel * y)], ts) for y in nominal["off"]],
    }
    checks = {which: compare_with_flow(zdm, starts[which], free_model) for which in FAMILIES}
    fam = checks["family"]
    back = np.linalg.solve(free_propagator(p, fam.t_end - ts), fam.actual.T).T
    kick = -back[:, 1] / (p["k"] * nominal["family"] ** 1.5)
    m = s.extrapolate
    coefficient = float(np.polyfit(nominal["family"][:m], kick[:m], 1)[1])
    return Run(zdm, nominal, checks, kick, coefficient, time.perf_counter() - start)


def draw(run: Run, path: Path) -> Figure:
    """The two sets side by side, log-log; returns the figure (saved at ``path``)."""
    fig, axes = new_figure(1, 2, (11.0, 4.8))
    for ax, which in zip(np.ravel(axes), FAMILIES):
        c = run.checks[which]
        s_size, s_pred, s_err = run.slopes(which)
        ax.loglog(
            c.depth,
            c.size,
            "o",
            color="tab:blue",
            ms=5,
            label=f"|Δ|: flow through the contact − free flow (slope {s_size:.4f})",
        )
        ax.loglog(
            c.depth,
            c.predicted_size,
            "-",
            color="tab:orange",
            lw=1.4,
            label=f"the map's prediction (slope {s_pred:.4f})",
        )
        ax.loglog(
            c.depth,
            c.error,
            "s",
            color="tab:red",
            ms=4,
            label=f"ε = |Δ − prediction| (slope {s_err:.3f}; theory {POWERS[which]:g})",
        )
        ax.set_xlabel("penetration δ")
        ax.set_ylabel("size of the difference at t* + T/4")
        ax.set_title(LABELS[which], fontsize=10)
        ax.grid(True, which="major", lw=0.4, color="0.85")
        ax.legend(loc="upper left", fontsize=8)
    p = run.params
    fig.suptitle(
        f"Soft-impact oscillator (ζ = {p['zeta']:g}, ω = {p['omega']:g}, gap = {p['gap']:g}, k = {p['k']:g}) "
        f"at grazing, a* = {p['a']:.10f}: the switching map D(x) = x − (4/3)√(2/a) δ^(3/2) (0, k)",
        fontsize=10,
    )
    save_png(fig, path)
    return fig


def comparisons(run: Run, s: Settings) -> tuple[Comparison, ...]:
    p, zdm = run.params, run.zdm
    rows: list[Comparison] = []
    a_star = grazing_amplitude(p)
    rows.append(
        numeric_row(
            FIGURE_ID,
            "grazing: forcing amplitude a*",
            a_star,
            p["a"],
            kind="self-check",
            reference=CLOSED_FORM,
            tolerance=CLOSED_FORM_TOL,
            why_tolerance=f"{CLOSED_FORM_TOL:g}",
            decimals=12,
            paper_text=f"{a_star:.12f}",
            note="closed form: the free orbit's amplitude a/√((1−ω²)² + (2ζω)²) equals the gap; ours: "
            "find_grazing_point on the free mode with the surface as a stop (the grazing orbit never enters "
            "the "
            "contact)",
        )
    )
    T = 2 * math.pi / p["omega"]
    t_exact = grazing_time(p)
    t_ours = zdm.t_graze % T
    rows.append(
        numeric_row(
            FIGURE_ID,
            "grazing: time t* of the contact (modulo the period)",
            t_exact,
            t_ours,
            kind="self-check",
            reference=CLOSED_FORM,
            tolerance=CLOSED_FORM_TOL,
            why_tolerance=f"{CLOSED_FORM_TOL:g}",
            decimals=12,
            paper_text=f"{t_exact:.12f}",
            note="closed form: x = Re(X exp(iωt)) is largest at ωt = −arg X",
        )
    )
    off = float(np.max(np.abs(zdm.contact - np.array([p["gap"], 0.0]))))
    rows.append(
        criterion_row(
            FIGURE_ID,
            "grazing: the contact state (x, x′)",
            f"({p['gap']:g}, 0)",
            f"({zdm.contact[0]:.12f}, {zdm.contact[1]:.1e})",
            off <= CLOSED_FORM_TOL,
            kind="self-check",
            reference=CLOSED_FORM,
            rule=f"agree when max |ours − (gap, 0)| ≤ {CLOSED_FORM_TOL:g}",
            delta=off,
            delta_text=f"{off:.1e}",
        )
    )
    acc = p["omega"] ** 2 * p["gap"]
    rows.append(
        numeric_row(
            FIGURE_ID,
            "the map: a = L_f² h at the contact",
            acc,
            zdm.accel,
            kind="self-check",
            reference=CLOSED_FORM,
            tolerance=1e-9 * acc,
            why_tolerance=f"1e-9 relative, {1e-9 * acc:.2g}",
            decimals=12,
            paper_text=f"ω² gap = {acc:.12f}",
            note="on the periodic orbit x″ = −ω² x, and h = gap − x",
        )
    )
    jump_off = float(np.max(np.abs(zdm.jump - np.array([0.0, p["k"]]))))
    rows.append(
        criterion_row(
            FIGURE_ID,
            "the map: the jump w of the field per unit guard",
            f"(0, k) = (0, {p['k']:g})",
            f"({zdm.jump[0]:.3g}, {zdm.jump[1]:.12g})",
            jump_off <= 1e-12,
            kind="self-check",
            reference=CLOSED_FORM,
            rule="agree when max |ours − (0, k)| ≤ 1e-12",
            delta=jump_off,
            delta_text=f"{jump_off:.1e}",
            note="f₊ − f₋ = (0, −k (x − gap)) = (0, k) h",
        )
    )
    coef = 4 / 3 * math.sqrt(2) / (p["omega"] * math.sqrt(p["gap"]))
    rows.append(
        numeric_row(
            FIGURE_ID,
            "the map's coefficient (4/3)√(2/a)",
            coef,
            zdm.coefficient,
            kind="self-check",
            reference=CLOSED_FORM,
            tolerance=1e-9 * coef,
            why_tolerance=f"1e-9 relative, {1e-9 * coef:.2g}",
            decimals=12,
            paper_text=f"(4/3)√2 / (ω √gap) = {coef:.12f}",
        )
    )
    m = s.extrapolate
    rows.append(
        numeric_row(
            FIGURE_ID,
            "the simulation's coefficient: −Δv on the section / (k δ^(3/2)), δ → 0",
            coef,
            run.coefficient,
            kind="self-check",
            reference=CLOSED_FORM,
            tolerance=COEFFICIENT_TOL * coef,
            why_tolerance=f"{COEFFICIENT_TOL:g} relative, {COEFFICIENT_TOL * coef:.2g}",
            decimals=10,
            paper_text=f"{coef:.10f}",
            note=f"the family's differences carried back to the section t* by the free flow's propagator "
            f"exp(A (T/4)) (it is linear), the velocity part divided by k δ^(3/2): "
            f"{run.kick[0]:.8f} at δ = {run.nominal['family'][0]:.0e}, {run.kick[-1]:.6f} at "
            f"δ = {run.nominal['family'][-1]:.0e} (the next order, a relative C δ); extrapolated to δ → 0 "
            "by a line "
            f"in δ through the {m} smallest δ",
        )
    )
    depth_off = max(float(np.max(np.abs(run.checks[w].depth / run.nominal[w] - 1))) for w in FAMILIES)
    rows.append(
        criterion_row(
            FIGURE_ID,
            "the starts' penetration δ as the map computes it",
            "the δ asked for",
            f"{depth_off:.1e}",
            depth_off <= 1e-6,
            kind="self-check",
            reference="construction",
            rule="agree when max |δ_map / δ − 1| ≤ 1e-6 over both sets (the family's starts are the grazing "
            "orbit, whose contact section is solved to ~1e-12; the others are set on the section)",
            delta=depth_off,
            delta_text=f"{depth_off:.1e}",
        )
    )
    for which in FAMILIES:
        s_size, _, s_err = run.slopes(which)
        lo, hi = run.nominal[which][0], run.nominal[which][-1]
        span = f"δ from {lo:.0e} to {hi:.0e}"
        rows.append(
            numeric_row(
                FIGURE_ID,
                f"{LABELS[which]}: log-log slope of |Δ|, {span}",
                1.5,
                s_size,
                kind="self-check",
                reference=THEORY,
                tolerance=SIZE_SLOPE_TOL,
                decimals=4,
                paper_text="1.5 (the 3/2 law)",
                why_tolerance=f"{SIZE_SLOPE_TOL:g} (the next order bends the fit by < 0.01 here)",
            )
        )
        p_err = POWERS[which]
        rows.append(
            numeric_row(
                FIGURE_ID,
                f"{LABELS[which]}: log-log slope of the map's error ε, {span}",
                p_err,
                s_err,
                kind="self-check",
                reference=THEORY,
                tolerance=ERROR_SLOPE_TOL,
                decimals=4,
                paper_text=f"{p_err:g}",
                why_tolerance=f"{ERROR_SLOPE_TOL:g}",
                note="the error is O(δ^(5/2)) where the closest approach is on the section (the grazing "
                "orbit's own family: its δ² terms cancel by symmetry), O(δ²) otherwise "
                "(docs/normal-form.md, §5)",
            )
        )
        ratios = run.constants(which)
        spread = float(ratios.max() / ratios.min())
        power = "δ" if RELATIVE_POWERS[which] == 1.0 else "δ^(1/2)"
        sensitive = (SAME_CONSTANT - 1) * ratios[0] * lo ** RELATIVE_POWERS[which]
        rows.append(
            criterion_row(
                FIGURE_ID,
                f"{LABELS[which]}: ε / |Δ| = C {power}, one C over the decades",
                f"≤ {SAME_CONSTANT:g}",
                f"max/min = {spread:.4f} (C from {ratios.min():.3f} to {ratios.max():.3f})",
                spread <= SAME_CONSTANT,
                kind="self-check",
                reference=THEORY,
                rule=f"agree when max/min of ε / (|Δ| {power}) over the decades ≤ {SAME_CONSTANT:g}: a "
                f"leading coefficient off by a relative ε₀ adds ε₀ to ε / |Δ| at every δ, which breaks it "
                f"once ε₀ > {SAME_CONSTANT - 1:g} C {power} at the smallest δ (here {sensitive:.1e})",
                delta=spread,
                delta_text=f"{spread:.4f}",
            )
        )
    return tuple(rows)


def write_data(run: Run, out_dir: Path) -> DataFile:
    rows = []
    for which in FAMILIES:
        c = run.checks[which]
        for i, y in enumerate(run.nominal[which]):
            rows.append(
                (
                    which,
                    y,
                    c.depth[i],
                    *c.actual[i],
                    *c.predicted[i],
                    c.size[i],
                    c.predicted_size[i],
                    c.error[i],
                )
            )
    header = ["set", "delta_asked", "delta", "actual_x", "actual_v", "predicted_x", "predicted_v", "size",
              "predicted_size", "error"]  # fmt: skip
    path = out_dir / "switch_zdm.csv"
    write_csv(path, header, rows)
    return DataFile(
        path.name,
        "per start: the set (family: the grazing orbit at gap* − δ; off: a state off the section), δ asked "
        "for and "
        "δ as the map computes it, the flow through the contact minus the free flow at t* + T/4 (x, x′), the "
        "map's prediction of it, their sizes and the map's error, CSV",
    )


def build(out_dir: Path, progress: Say | None = None, settings: Settings | None = None) -> FigureResult:
    """Compute the section, write its PNG and data into ``out_dir`` and describe it."""
    say = progress or (lambda _msg: None)
    start = time.perf_counter()
    s = settings or SETTINGS
    run = compute(s, say)
    name = "switch_zdm.png"
    draw(run, out_dir / name)
    p = run.params
    image = Image(
        name,
        f"The soft-impact oscillator at grazing (a* = {p['a']:.10f}). Left: the grazing periodic orbit run "
        "from a "
        f"quarter period before its contact with gap* − δ for {s.family[2]} values of δ from "
        f"{s.family[0]:g} to "
        f"{s.family[1]:g}; right: {s.off[2]} states on the section t* at distance δ from the surface moving "
        "towards "
        f"it (δ from {s.off[0]:g} to {s.off[1]:g}). Each run through the contact is compared a quarter "
        "period after "
        "the contact with the free flow of the same state (blue), and with the free flow of the state "
        "mapped by the "
        "switching map (its prediction, orange); red: the map's error. Slopes from least-squares fits.",
        "Log-log plot of the difference the soft contact makes, the map's prediction and its error against "
        "the "
        "penetration",
    )
    summary = (
        "Not in the paper: grazing a switching surface that has no reset (a compliant stop: a spring engages "
        "beyond x = gap) is not an impact, and its discontinuity map is of order 3/2 in the penetration δ, "
        "not "
        "1/2 (docs/normal-form.md, section 5). The soft-impact oscillator's free orbit is known in closed "
        "form, "
        "so the grazing, the contact and the map's coefficient are checked against it, and the map against "
        "the "
        "simulated flow through the contact over four decades of δ."
    )
    notes = (
        "Theory: the difference goes as δ^(3/2) with the coefficient (4/3)√(2/a) k on the velocity; the "
        "map's "
        "error as δ^(5/2) on the grazing orbit's family (the closest approach on the section) and δ² off "
        "it. "
        f"The same check for impacts (a square-root map) is tests/normalform/test_normal_form.py's; the "
        f"simulated contact itself agrees with matrix exponentials to 1e-12 "
        f"(tests/normalform/test_switching_zdm.py). Computed in {run.seconds:.1f} s.",
        "The model is the built-in soft-impact-oscillator (two modes, transitions touch and leave without a "
        "reset); its grazing is located on the free mode with the surface taken as a stop.",
    )
    return FigureResult(
        figure_id=FIGURE_ID,
        title="Extra: grazing a switching surface — the 3/2-power map of a soft stop against simulation",
        images=(image,),
        summary=summary,
        comparisons=comparisons(run, s),
        notes=notes,
        seconds=time.perf_counter() - start,
        data=(write_data(run, out_dir),),
    )
