"""Periodic orbits: shooting, Floquet multipliers, continuation, grazing, sliding and bifurcation curves."""

from grazing.maps import flow_map
from grazing.orbits.contact import GrazingPoint, refine_grazing
from grazing.orbits.continuation import Branch, ContinuationSettings, SpecialPoint, continue_orbit
from grazing.orbits.curve_data import BifurcationCurve, CurvePoint, CurveSpecial
from grazing.orbits.curves import follow_curve
from grazing.orbits.grazing import GrazingCurve, find_grazings, grazing_curve
from grazing.orbits.palc import PalcSettings
from grazing.orbits.shooting import PeriodicOrbit, find_orbit
from grazing.orbits.sliding_curves import SlidingCurve, sliding_curve

__all__ = [
    "BifurcationCurve",
    "Branch",
    "ContinuationSettings",
    "CurvePoint",
    "CurveSpecial",
    "GrazingCurve",
    "GrazingPoint",
    "PalcSettings",
    "PeriodicOrbit",
    "SlidingCurve",
    "SpecialPoint",
    "continue_orbit",
    "find_grazings",
    "find_orbit",
    "flow_map",
    "follow_curve",
    "grazing_curve",
    "refine_grazing",
    "sliding_curve",
]
