"""A forced linear oscillator whose damping may take any sign: real, complex, stable and unstable multipliers.

::

    y'' + 2 c y' + y = cos(k s)        (a stop at y = 100, far away: followed as a virtual branch)

Its periodic orbit's multipliers are ``exp(T (-c +- sqrt(c^2 - 1)))``, ``T = 2 pi / k``: real and
inside the unit circle for ``c > 1`` (overdamped), a complex pair inside for ``0 < c < 1``, on the
unit circle at ``c = 0`` (a Neimark-Sacker point of the map) and outside for ``c < 0``.
"""

from __future__ import annotations

import sympy as sp

from grazing import HybridModel, Parameter


def any_damping(**values: float) -> HybridModel:
    """The model, with parameter overrides (also the ``--model FILE.py:any_damping`` object)."""
    y, dy, s = sp.symbols("y dy s")
    c, k = sp.symbols("c k")
    model = HybridModel(
        "any-damping", [y, dy], s,
        [Parameter("c", 1.2, lower=-2.0, upper=2.0), Parameter("k", 1.3, lower=0.0, lower_open=True)],
        vector_field=[dy, -2 * c * dy - y + sp.cos(k * s)], guard=100 - y, reset=[y, -dy],
        period=2 * sp.pi / k,
    )  # fmt: skip
    return model.with_params(**values) if values else model
