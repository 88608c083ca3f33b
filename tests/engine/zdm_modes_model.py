"""A forced oscillator with a soft spring beyond a gap and a rigid bumper inside it, for the discontinuity
map on a model with modes (``tests/engine/test_zdm_modes.py``, ``tests/gpu/cases_zdm_modes.py``).

Mode ``Slack_1``: ``q'' + 2 zeta q' + q = F cos(Om t)``; beyond ``q = d_gap`` mode ``Taut_2`` adds the
spring ``k_soft (q - d_gap)`` (switches ``grip_Q`` and ``slip_Q``, no reset); at ``q = w_all`` a rigid
bumper ``Bumper_9`` reverses the velocity (``p <- -r_e p``), a stop of mode ``Taut_2`` (or, with
``bumper_mode="Slack_1"``, of the slack mode, where the orbit never reaches it).
"""

from __future__ import annotations

import sympy as sp

from grazing import HybridModel, Mode, Parameter, Stop, Transition

q, p, t = sp.symbols("q_Z p_Z t")
zeta, F, Om, d, k, w, r = sp.symbols("zeta_k F_0 Om d_gap k_soft w_all r_e")
VALUES = {"zeta_k": 0.05, "F_0": 1.0, "Om": 1.2, "d_gap": 0.5, "k_soft": 4.0, "w_all": 1.5, "r_e": 0.8}


def bumper_oscillator(
    bumper_mode: str = "Taut_2", initial_mode: str = "Slack_1", **values: float
) -> HybridModel:
    """The model (see the module), starting in ``initial_mode``, its parameters ``VALUES`` changed by
    ``values``."""
    slack = [p, -2 * zeta * p - q + F * sp.cos(Om * t)]
    taut = [p, -2 * zeta * p - q + F * sp.cos(Om * t) - k * (q - d)]
    bumper = [Stop("Bumper_9", w - q, [q, -r * p], [0, 1])]
    modes = [
        Mode("Slack_1", slack, stops=bumper if bumper_mode == "Slack_1" else []),
        Mode("Taut_2", taut, stops=bumper if bumper_mode == "Taut_2" else []),
    ]
    model = HybridModel(
        "bumper oscillator", [q, p], t, [Parameter(name, value) for name, value in VALUES.items()],
        modes=modes,
        transitions=[Transition("grip_Q", "Slack_1", "Taut_2", d - q),
                     Transition("slip_Q", "Taut_2", "Slack_1", q - d)],
        period=2 * sp.pi / Om, initial_mode=initial_mode,
    )  # fmt: skip
    return model.with_params(**values)
