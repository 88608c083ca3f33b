"""Built-in models, each citing its source."""

from grazing.models.bouncing_ball import bouncing_ball
from grazing.models.friction_oscillator import friction_oscillator
from grazing.models.impact_damper import impact_damper
from grazing.models.impact_oscillator import impact_oscillator
from grazing.models.pendulum import CASES, DEFAULT_CASE, case_values, pendulum
from grazing.models.rocking_block import rocking_block
from grazing.models.soft_impact_oscillator import soft_impact_oscillator
from grazing.models.two_sided_oscillator import two_sided_oscillator

BUILT_IN = {
    "pendulum": pendulum,
    "two-sided-oscillator": two_sided_oscillator,
    "impact-oscillator": impact_oscillator,
    "bouncing-ball": bouncing_ball,
    "impact-damper": impact_damper,
    "soft-impact-oscillator": soft_impact_oscillator,
    "rocking-block": rocking_block,
    "friction-oscillator": friction_oscillator,
}
"""The built-in models by their command-line names (each a function of parameter overrides)."""

__all__ = [
    "BUILT_IN",
    "CASES",
    "DEFAULT_CASE",
    "bouncing_ball",
    "case_values",
    "friction_oscillator",
    "impact_damper",
    "impact_oscillator",
    "pendulum",
    "rocking_block",
    "soft_impact_oscillator",
    "two_sided_oscillator",
]
