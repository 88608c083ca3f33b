"""Built-in models, each citing its source."""

from grazing.models.bouncing_ball import bouncing_ball
from grazing.models.impact_oscillator import impact_oscillator
from grazing.models.pendulum import CASES, DEFAULT_CASE, case_values, pendulum

__all__ = ["CASES", "DEFAULT_CASE", "bouncing_ball", "case_values", "impact_oscillator", "pendulum"]
