"""A forced, damped linear oscillator with a stop no orbit reaches, at a distance of the test's choosing.

::

    swing'' + 0.2 swing' + swing = force cos(t / 2)      stop "far" at swing = distance

Its periodic orbit (period ``4 pi``) is known in closed form, ``swing = Re(force e^(i t/2) / (3/4 + i/10))``
(:func:`orbit_state`), and attracts with multipliers of modulus ``exp(-0.1 * 4 pi)``: a stop far away must
change neither (a guard offset by ``1e12`` once set the integration's scale, and its steps).
"""

from __future__ import annotations

import sympy as sp

import grazing

RESPONSE = 1.0 / complex(0.75, 0.1)
"""The orbit's complex amplitude per unit force at the forcing frequency 1/2."""


def far_stop_swing(force: float = 1.0, distance: float = 1e12) -> grazing.HybridModel:
    """The model (states ``swing``, ``swing_rate``; time ``t``) with its stop at ``swing = distance``."""
    q, v, t = sp.symbols("swing swing_rate t")
    f, d = sp.symbols("force distance")
    model = grazing.HybridModel(
        "far-stop-swing",
        states=[q, v],
        time=t,
        parameters=[
            grazing.Parameter("force", 1.0, description="forcing amplitude"),
            grazing.Parameter("distance", 1e12, description="where the stop is"),
        ],
        vector_field=[v, -sp.Rational(1, 5) * v - q + f * sp.cos(t / 2)],
        period=4 * sp.pi,
        stops=[grazing.Stop("far", d - q, [q, -v / 2])],
    )
    return model.with_params(force=force, distance=distance)


def orbit_state(force: float) -> tuple[float, float]:
    """``(swing, swing_rate)`` of the periodic orbit at the times ``4 pi k``."""
    z = force * RESPONSE
    return z.real, (0.5j * z).real
