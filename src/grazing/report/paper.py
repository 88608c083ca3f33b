"""Every number of the paper that the report compares with, in one place, as the paper prints it.

Piiroinen, Virgin & Champneys, J. Nonlinear Sci. 14 (2004) 383–404.  Each value
is a :class:`Printed` number (its text as printed, hence its precision, and
where it is printed) or a quotation.  The figure modules import from here and
nowhere else; the experiment tools keep their own defaults
(:mod:`grazing.experiment.damping`), which a test checks against these.

Examples
--------
>>> FIG6_INSETS["b"].eta.value, FIG6_INSETS["b"].eta.half_unit
(0.445, 5e-05)
>>> EXPERIMENT["40"].eta_c.text
'0.446'
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

CITATION = (
    "P. T. Piiroinen, L. N. Virgin, A. R. Champneys, “Chaos and period-adding: experimental and numerical "
    "verification of the grazing bifurcation”, J. Nonlinear Sci. 14 (2004) 383–404"
)
DOI = "10.1007/s00332-004-0616-y"
"""The paper's DOI (linked from the report as ``https://doi.org/`` + DOI)."""


@dataclass(frozen=True)
class Printed:
    """A number as the paper prints it.

    Attributes
    ----------
    text
        The digits as printed (``"0.4450"``): they fix the precision.
    source
        Where it is printed (section, figure, caption).
    approximate
        True where the paper writes "≈", "about" or "close to".

    Examples
    --------
    >>> p = Printed("0.4450", "fig 6 caption")
    >>> p.value, p.unit, p.half_unit
    (0.445, 0.0001, 5e-05)
    >>> Printed("41", "§6.1").half_unit
    0.5
    """

    text: str
    source: str
    approximate: bool = False

    @property
    def value(self) -> float:
        return float(self.text)

    @property
    def decimals(self) -> int:
        """Digits printed after the decimal point."""
        return len(self.text.split(".")[1]) if "." in self.text else 0

    @property
    def unit(self) -> float:
        """One unit of the last printed digit."""
        return float(f"1e-{self.decimals}")

    @property
    def half_unit(self) -> float:
        """Half a unit of the last printed digit: how far the true value can lie from a rounded one."""
        return float(f"5e-{self.decimals + 1}")

    @property
    def tolerance(self) -> float:
        """The report's default tolerance for this number.

        Half a unit of the last printed digit (the rounding of an exact
        number); one unit where the paper itself says "≈", "about" or
        "close to".
        """
        return self.unit if self.approximate else self.half_unit


@dataclass(frozen=True)
class PrintedComplex:
    """A complex Floquet multiplier printed as ``re ± im i`` (both parts to the same digits)."""

    real: Printed
    imag: Printed

    @property
    def value(self) -> complex:
        return complex(self.real.value, self.imag.value)

    @property
    def text(self) -> str:
        return f"{self.real.text} ± {self.imag.text}i"

    @property
    def tolerance(self) -> float:
        """Half a unit of the last digit in both parts: ``half_unit * sqrt(2)`` in the complex plane."""
        return self.real.half_unit * 2**0.5


def _cx(re: str, im: str, source: str) -> PrintedComplex:
    return PrintedComplex(Printed(re, source), Printed(im, source))


# ---------------------------------------------------------------------------- the model and its cases

ALPHA_TABLE = Printed("0.2254", "fig 7 caption (and the captions of figs 8, 12)")
"""α of the numerics as the captions print it."""
ALPHA_PRINTED = Printed("0.2258", "§3: “In the experimental data the amplitude was set at α = 0.2258”")
"""α as §3 prints it."""
A_MM = Printed("50.8", "§2.1: forcing amplitude A = 50.8 mm")
L_MM = Printed("225", "§2.1: effective length L = 225 mm")
ALPHA_APPARATUS = A_MM.value / L_MM.value
"""α = A/L (eq. 3) with the apparatus of §2.1, unrounded: 0.225778."""
G_E_OVER_G = Printed("0.24", "§2.1: g_e = 0.24 g")
REDUCED_FORCING = Printed("0.71", "§6.2, fig 12 caption: forcing amplitude 0.71 α")

CASES: MappingProxyType[str, MappingProxyType[str, str]] = MappingProxyType(
    {
        "A": MappingProxyType({"r": "0.4707", "beta": "0.010", "alpha": "0.2254", "used": "fig 8(b)"}),
        "B": MappingProxyType(
            {"r": "0.7675", "beta": "0.048", "alpha": "0.2254", "used": "figs 6, 7, 8(a), 9, 10, 11"}
        ),
        "C": MappingProxyType(
            {"r": "0.8778", "beta": "0.058", "alpha": "0.2254", "used": "figs 4(b), 6 (left)"}
        ),
        "D": MappingProxyType(
            {"r": "1", "beta": "0.068", "alpha": "0.2254", "used": "figs 4(b), 6 (left); printed “β = 0.68”"}
        ),
        "A-reduced": MappingProxyType(
            {"r": "0.4707", "beta": "0.010", "alpha": "0.71 × 0.2254", "used": "fig 12"}
        ),
    }
)
"""The paper's parameter cases as printed (fig 4(b) caption, §3, §6.2)."""

# ---------------------------------------------------------------------------- §2, §3: damping, fig 4

DAMPING = Printed("0.07", "§2.1: “it was estimated that D = 0.07, i.e., 7% of critical damping”")
FIG4A = (Printed("0.7148", "fig 4(a) caption"), Printed("0.0426", "fig 4(a) caption"))
"""``(r, β)`` of the free decay of fig 4(a)."""
KAPPA_FIG4A = Printed("1.1", "§3: “β = 0.0426 (κ = 1.1)”")
KAPPA_B = Printed("1.238", "§3: “β = 0.048 (corresponding to κ ≈ 1.238)”", approximate=True)
CASES_BETA_B = Printed("0.048", "§3: “r = 0.7675 and β = 0.048”")
FIG4B_POINTS = MappingProxyType(
    {
        "A": (Printed("0.4707", "fig 4 caption"), Printed("0.010", "fig 4 caption")),
        "B": (Printed("0.7675", "fig 4 caption"), Printed("0.048", "fig 4 caption")),
        "C": (Printed("0.8778", "fig 4 caption"), Printed("0.058", "fig 4 caption")),
        "D": (Printed("1", "fig 4 caption"), Printed("0.068", "§3: “when β ≈ 0.068, then r = 1”")),
    }
)
"""The points A–D of fig 4(b) (D's β as §3 gives it; the caption prints 0.68)."""
D_BETA_CAPTION = Printed("0.68", "fig 4 caption: “(r = 1, β = 0.68)”")
CURVE_R_AT_BETA0 = Printed(
    "0.42", "§3: “if no linear damping is assumed (β = 0), then ... r is close to 0.42”", approximate=True
)
CURVE_BETA_AT_R1 = Printed("0.068", "§3: “when β ≈ 0.068, then r = 1”", approximate=True)
_REALISTIC = "§3: “r ... between 0.5 and 0.8 ..., which corresponds to ... β between 0.015 and 0.05”"
REALISTIC_RANGE = ((0.5, Printed("0.015", _REALISTIC)), (0.8, Printed("0.05", _REALISTIC)))
"""§3: the realistic range of r for steel on steel and the β the curve of equal damping gives at its ends."""

# ---------------------------------------------------------------------------- §2.2: the experiment


@dataclass(frozen=True)
class ExperimentPanel:
    """What §2.2 says about one stop angle of the experiment (fig 2)."""

    theta_hat_deg: float
    eta_c: Printed
    """The measured first grazing."""
    period: int
    """Period of the first significant window."""
    window: tuple[float, float | None]
    """Its η interval as printed (``(0.45, None)``: "starting around η = 0.45")."""
    window_text: str
    summary: str


EXPERIMENT = MappingProxyType(
    {
        "10": ExperimentPanel(
            10.0,
            Printed("0.343", "§2.2", approximate=True),
            2,
            (0.35, 0.36),
            "0.35 < η < 0.36",
            "a sudden jump to chaos at η_c ≈ 0.343; a significant period-2 window "
            "(0.35 < η < 0.36) ending in a reverse period-doubling to impacting period 1",
        ),
        "20": ExperimentPanel(
            20.0,
            Printed("0.405", "§2.2", approximate=True),
            3,
            (0.406, 0.42),
            "0.406 < η < 0.42",
            "brief chaos, a significant period-3 window (0.406 < η < 0.42), a long "
            "interval of chaos, a period-2 window, a jump to nonimpacting period 1",
        ),
        "30": ExperimentPanel(
            30.0,
            Printed("0.435", "§2.2", approximate=True),
            4,
            (0.44, 0.45),
            "0.44 < η < 0.45",
            "brief chaos, a significant period-4 window (0.44 < η < 0.45), a long "
            "interval of chaos, a period-2 window, a jump to nonimpacting period 1",
        ),
        "40": ExperimentPanel(
            40.0,
            Printed("0.446", "§2.2", approximate=True),
            5,
            (0.45, None),
            "starting around η = 0.45",
            "a first significant window of period 5 (starting around η = 0.45), chaos, "
            "a period-2 window, a jump to nonimpacting period 1",
        ),
    }
)
"""§2.2 on figs 2(a)–(d): η_c, the first significant window and the sequence, by stop angle."""

ETA_C_FIT = Printed(
    "0.445",
    "§3: the fit of case B puts the grazing at 40° at “the observed value of η (≈ 0.445)”",
    approximate=True,
)
WINDOW_START_40 = Printed("0.45", "§2.2: “starting around η = 0.45”", approximate=True)
FIG3_POINTS = ((10.0, 0.35, "chaotic"), (40.0, 0.45, "period-5"))
"""Fig 3: (θ̂ in degrees, η, what the measured series shows)."""
END_OF_IMPACTING = (
    "the period-two window “dies in a sudden abrupt jump (possibly through a small interval of chaos) to "
    "period-one nonimpacting motion”"
)
"""§2.2, on the end of the impacting region at 20°–40°."""

# ---------------------------------------------------------------------------- §6.1: figs 6–11

FIG6_THETA_MAX = Printed("55", "§6.1: “about 55° for case B”", approximate=True)
CASE_A_OVERESTIMATES = (
    "case A “greatly overestimates the value of θ̂_max observed experimentally (recall that no impacting "
    "behaviour was observed for θ̂ = 50°)”"
)
"""§6.2, on case A against case B."""
NO_IMPACTS_AT_DEG = 50.0
"""§6.2 (and §2.2): the stop angle at which the experiment showed no impacting behaviour."""


@dataclass(frozen=True)
class Inset:
    """One multiplier inset of fig 6 (right)."""

    key: str
    theta_hat_deg: float
    eta: Printed
    multiplier: PrintedComplex
    which: int
    """Which grazing at this θ̂ (0: the first in η)."""


FIG6_INSETS = MappingProxyType(
    {
        "a": Inset(
            "a", 10.0, Printed("0.3229", "fig 6 caption"), _cx("0.4040", "0.0114", "fig 6 caption"), 0
        ),
        "b": Inset(
            "b", 40.0, Printed("0.4450", "fig 6 caption"), _cx("0.4606", "0.2137", "fig 6 caption"), 0
        ),
        "c": Inset(
            "c", 40.0, Printed("0.5475", "fig 6 caption"), _cx("0.2534", "0.5178", "fig 6 caption"), 1
        ),
    }
)
"""Fig 6 caption: the three multiplier insets (the trivial multiplier 1 left out)."""
ABS_LAMBDA_FIRST = Printed("0.5114", "§6.1: “|λ| = 0.5114 (see inset (b) of Figure 6)”")
ABS_LAMBDA_SECOND = Printed("0.5765", "§6.1: “|λ| = 0.5765 (see inset (c) of Figure 6)”")
EQ21 = (0.25, 2 / 3)
"""Eq. 21: period adding is predicted for 1/4 < |λ| < 2/3."""

FIRST_WINDOW = MappingProxyType({10.0: 1, 20.0: 2, 30.0: 3, 40.0: 4})
"""§6.1: “the period of the first appreciable periodic window ... period-one for 10°, two for 20°, three
for 30°, and four (actually, briefly, five) for 40°”."""
FIRST_WINDOW_QUOTE = (
    "“the period of the first appreciable periodic window is ... one for 10°, two for 20°, three for 30°, "
    "and four (actually, briefly, five) for 40°”"
)
JUMP_TO_CHAOS = (
    "“For each θ̂ there is a first grazing bifurcation that leads to a rapid change in the dynamics, from "
    "nonimpacting period-one periodic motion to impacting chaotic motion containing windows of stable "
    "periodic orbits in a period-adding cascade”"
)
REVERSE_ADDING = "“The period is decreased by one for each periodic window as η is increased”"
SECOND_GRAZING = (
    "“for all cases with θ̂ > 10° the region of impacting behaviour ends with another grazing bifurcation, "
    "which results in the destruction of a period-two orbit”"
)
NO_SECOND_GRAZING_10 = (
    "“for θ̂ = 10° there is no second grazing bifurcation to restore period-one nonimpacting motion”"
)

FIG8_ETA = Printed("0.447", "fig 8 caption")
FIG8_GRAZING = Printed("41", "§6.1: “a grazing bifurcation at θ̂ = 41°”")

FIG9 = (
    (10.0, Printed("0.33294", "fig 9 caption"), "chaotic"),
    (40.0, Printed("0.446", "fig 9 caption"), "period-5"),
)
"""Fig 9: (θ̂ in degrees, η, what the numerical series shows)."""
FIG7D_CHAOTIC = Printed("0.45", "§6.1: the numerics are chaotic at η = 0.45 (fig 3(d) against fig 7(d))")

FIG10_QUOTE = (
    "the period-adding cascades are “captured and clearly visible in Figures 10(c) and (d), but the "
    "intervals in which they appear are somewhat shortened”"
)
FIG11_ETA = Printed("0.4458", "§6.1, fig 11 caption")
FIG11_THETA_HAT_DEG = 40.0

# ---------------------------------------------------------------------------- §6.2: fig 12

UNCANNY = ("a", "c", "d")
"""§6.2: with the reduced forcing, panels (a), (c), (d) are “uncannily similar” to the experiment."""
FIG12_PATTERN = (
    "“we can clearly see one large periodic window surrounded by chaotic regions, culminating in a "
    "period-two window”"
)

# ---------------------------------------------------------------------------- equations

EQ3_BETA = "β = κ/(2ω0), ω0 = 2√(g_e/L) (eq. 3)"
EQ19 = "b(x_im, 0) = −√(2a(x_im)) (0, −(1+r), 0)ᵀ with a = 𝓛²_f h (eq. 19)"

# ---------------------------------------------------------------------------- issue 28: attractors

SUDDEN_RETURN = (
    "at the reverse grazing (η = 0.5475, θ̂ = 40°) “the transition back to nonimpacting behaviour is much "
    "more sudden and does not appear to involve any appreciable chaotic behaviour”"
)
"""§6.1, on the second grazing at 40°."""
