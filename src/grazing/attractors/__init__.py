"""Coexisting attractors: found from many initial states, their basins, and followed along a parameter.

:func:`find_attractors` runs initial states (a grid, a random sample) on the
sweep engine's SIMD lanes and recognises the attractor each ends on
(:mod:`~grazing.attractors.classify`: periodic, sticking, chaotic,
quasi-periodic, aperiodic, escaping, failed; ``invalid`` beyond a stop);
:func:`basins` does it on a grid in two state components
(:mod:`~grazing.attractors.grid`) and returns an xarray Dataset;
:func:`continue_attractors` follows the attractors and their basin fractions
along a parameter (global continuation, as Attractors.jl's).
"""

from grazing.attractors.basins import AttractorSet, basins, find_attractors, to_dataset
from grazing.attractors.classify import KINDS, Attractor
from grazing.attractors.continuation import continue_attractors
from grazing.attractors.grid import StateGrid, state_grid
from grazing.attractors.kinds import AttractorKind

__all__ = [
    "KINDS",
    "Attractor",
    "AttractorKind",
    "AttractorSet",
    "StateGrid",
    "basins",
    "continue_attractors",
    "find_attractors",
    "state_grid",
    "to_dataset",
]
