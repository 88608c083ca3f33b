"""A model file with three modes: a forced oscillator between two soft (spring) stops.

::

    x'' + 2 zeta x' + x = a cos(omega t) + F(x)
    F = -k_left (x + gap)    while x < -gap   (mode "left")
    F = 0                    while |x| < gap  (mode "free")
    F = -k_right (x - gap)   while x > gap    (mode "right")

Run it with ``grazing simulate --model docs/examples/soft_stops.py:soft_stops``
(docs/user-models.md).
"""

import sympy as sp

from grazing import HybridModel, Mode, Parameter, Transition

x, v, t = sp.symbols("x v t")
zeta, a, w, gap, k_left, k_right = sp.symbols("zeta a omega gap k_left k_right")
forced = -2 * zeta * v - x + a * sp.cos(w * t)

soft_stops = HybridModel(
    "soft-stops", [x, v], t,
    [Parameter("zeta", 0.05, lower=0), Parameter("a", 1.0), Parameter("omega", 1.1, lower=0, lower_open=True),
     Parameter("gap", 0.6, lower=0), Parameter("k_left", 3.0, lower=0), Parameter("k_right", 10.0, lower=0)],
    modes=[Mode("free", [v, forced]),
           Mode("left", [v, forced - k_left * (x + gap)]),
           Mode("right", [v, forced - k_right * (x - gap)])],
    transitions=[Transition("touch_left", "free", "left", x + gap),     # guards: positive in the source mode
                 Transition("touch_right", "free", "right", gap - x),
                 Transition("leave_left", "left", "free", -gap - x),
                 Transition("leave_right", "right", "free", x - gap)],
    period=2 * sp.pi / w,
)  # fmt: skip
