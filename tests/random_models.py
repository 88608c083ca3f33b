"""Random small impacting models for property tests, with names chosen to collide.

A drawn model is a forced oscillator (one or two degrees of freedom) with a
stop, whose states, time and parameters are named from :data:`NAMES`: names
the code generator or Python uses itself (``v0``/``v1`` for the variational
matrix, ``t_0`` for common subexpressions, ``pi``, ``E``, ``I``, ``lambda``,
numpy and math functions, the generated code's own locals...).  The forcing
frequency sets the period, so every drawn model has a period-setting parameter.
The first (minimal) example is the issue's case: states ``x1, v1``.  A drawn
model may add a term with one of the smooth functions beyond sin and cos
(:mod:`tests.function_models`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import sympy as sp
from hypothesis import strategies as st

from grazing import HybridModel, Parameter
from tests.function_models import SMOOTH_FUNCTIONS, smooth_term

NAMES = (
    "x1", "v1", "t_0", "v0", "pi", "T", "J", "t", "t_", "x2", "v2", "E", "I", "e", "S", "N", "lambda",
    "sin", "cos", "exp", "log", "sqrt", "math", "np", "pv", "s", "x", "out", "h", "k", "c0", "w0", "p0",
    "xs0_0", "X", "O", "tau", "Dummy",
)  # fmt: skip


@dataclass(frozen=True)
class ModelSpec:
    """What defines a drawn model: names, degrees of freedom and parameter values."""

    names: tuple[str, ...]
    dof: int
    damping: float
    stiffness: float
    amplitude: float
    omega: float
    stop_fraction: float
    restitution: float
    coupling: float
    cubic: float
    smooth: str = "none"
    """A term ``-0.3 F(q / (1 + q^2))`` in the acceleration, ``F`` a
    :func:`tests.function_models.smooth_term` (tanh, asin, a power with a variable exponent ...),
    or ``"none"``."""

    @property
    def state_names(self) -> tuple[str, ...]:
        return self.names[: 2 * self.dof]

    @property
    def time_name(self) -> str:
        return self.names[2 * self.dof]

    @property
    def param_names(self) -> tuple[str, ...]:
        """damping, stiffness, amplitude, frequency (sets the period), stop, restitution[, coupling]."""
        return self.names[2 * self.dof + 1 : 2 * self.dof + 1 + (7 if self.dof == 2 else 6)]

    @property
    def stop(self) -> float:
        """A stop inside the linear response amplitude, so the model impacts."""
        k, c, w = self.stiffness, self.damping, self.omega
        reach = self.amplitude / math.sqrt((k - w * w) ** 2 + (c * w) ** 2)
        return self.stop_fraction * min(reach, 2.0)

    def model(self) -> HybridModel:
        states = sp.symbols(self.state_names)
        t = sp.Symbol(self.time_name)
        c, k, a, w, stop, r, *rest = sp.symbols(self.param_names)
        q, p = states[0], states[1]
        force = a * sp.cos(w * t)
        accel = -c * p - k * q - self.cubic * q**3 + force
        if self.smooth != "none":  # (of a bounded argument: a bounded force, no runaway)
            accel -= sp.Rational(3, 10) * smooth_term(self.smooth, q / (1 + q**2))
        params = [
            Parameter(str(c), self.damping, lower=0.0),
            Parameter(str(k), self.stiffness, lower=0.0, lower_open=True),
            Parameter(str(a), self.amplitude),
            Parameter(str(w), self.omega, lower=0.0, lower_open=True),
            Parameter(str(stop), self.stop),
            Parameter(str(r), self.restitution, lower=0.0, upper=1.0),
        ]
        field = [p, accel]
        reset = [q, -r * p]
        contact = [0, 1]
        if self.dof == 2:
            (kc,) = rest
            q2, p2 = states[2], states[3]
            field = [p, accel - kc * (q - q2), p2, -c * p2 - k * q2 - kc * (q2 - q)]
            reset = [q, -r * p, q2, p2]
            contact = [0, 1, 0, 0]
            params.append(Parameter(str(kc), self.coupling, lower=0.0))
        return HybridModel(
            "random-" + "-".join(self.names[:3]), list(states), t, params, vector_field=field,
            guard=stop - q, reset=reset, period=2 * sp.pi / w, contact_direction=contact,
        )  # fmt: skip

    def initial_state(self) -> list[float]:
        """At rest at the origin but moving fast enough to reach the stop in the first swing."""
        x = [0.0] * (2 * self.dof)
        x[1] = 1.6 * math.sqrt(self.stiffness) * self.stop + 0.3
        return x


@st.composite
def model_specs(draw: st.DrawFn) -> ModelSpec:
    """A random :class:`ModelSpec`; the names are a random selection of :data:`NAMES`."""
    names = tuple(draw(st.permutations(NAMES)))
    return ModelSpec(
        names=names,
        dof=draw(st.sampled_from([1, 2])),
        damping=draw(st.floats(0.02, 0.2)),
        stiffness=draw(st.floats(0.5, 2.0)),
        amplitude=draw(st.floats(0.3, 1.0)),
        omega=draw(st.floats(0.6, 3.0)),
        stop_fraction=draw(st.floats(0.3, 0.8)),
        restitution=draw(st.floats(0.5, 0.95)),
        coupling=draw(st.floats(0.1, 1.0)),
        cubic=draw(st.sampled_from([0.0, 0.2])),
        smooth=draw(st.sampled_from(["none", *SMOOTH_FUNCTIONS])),
    )


# ----------------------------------------------------------------------------- models with modes

MODE_NAMES = (
    "free", "contact", "stick", "m0", "m1", "tc_free", "tc_var", "rhs", "dispatch", "sliding", "on_belt",
    "x1", "v1", "t", "pi", "E", "sin", "X", "O", "np", "pv", "j", "vf", "back", "to", "belt", "wall",
    "hit", "touch", "leave", "behind", "ahead", "mode", "Dummy", "lambda_", "t_0",
)  # fmt: skip
"""Names of modes, transitions, stops and surfaces: the engine's and the generated code's own words among
them (a surface ``s`` names its transitions ``s_to_<mode>``, so the pool holds no name of that form)."""

MODE_KINDS = ("soft stop and impact", "three modes, reset", "sliding", "three modes, sliding")
"""The structures of :class:`ModesSpec`: two modes (free flight and a compliant contact, no reset;
an impact stop on the other side); three (a contact on either side, the right one entered with a reset
that scales the speed); two slip modes of a belt with Coulomb friction on either side of a sliding
surface (flat or curved); the belt with a third mode of drag above a higher speed.  Each mode is entered
only where its transitions out have a positive guard (a consistent partition of the state space)."""


@dataclass(frozen=True)
class ModesSpec:
    """A random model with two or three modes (:data:`MODE_KINDS`): names and values.

    Every field is ``q'' = -c q' - k q - cubic q^3 + a cos(w t)`` plus the mode's own force: a contact
    spring-damper ``-kc (q - g + q' / 8)`` past a gap, a friction ``-+ mu`` on either side of the belt speed,
    a drag ``-kc (q' - vf) / 4`` above a speed ``vf``.
    """

    kind: str
    names: tuple[str, ...]  # states, time, parameters (from NAMES)
    labels: tuple[str, ...]  # modes, transitions, stops, surfaces (from MODE_NAMES)
    damping: float
    stiffness: float
    amplitude: float
    omega: float
    gap: float
    contact: float
    restitution: float
    friction: float
    belt: float
    cubic: float
    curved: bool
    sticky: bool = False  # (the impact stop has a contact direction)

    @property
    def param_names(self) -> tuple[str, ...]:
        """damping, stiffness, amplitude, frequency (sets the period), gap, contact stiffness, restitution,
        friction, belt speed."""
        return self.names[3:12]

    def model(self) -> HybridModel:
        from grazing import Mode, Stop, Surface, Transition

        q, p = sp.symbols(self.names[:2])
        t = sp.Symbol(self.names[2])
        c, k, a, w, g, kc, r, mu, vb = sp.symbols(self.param_names)
        values = (
            self.damping, self.stiffness, self.amplitude, self.omega, self.gap, self.contact,
            self.restitution, self.friction, self.belt,
        )  # fmt: skip
        params = [Parameter(str(s), v) for s, v in zip((c, k, a, w, g, kc, r, mu, vb), values)]
        params[3] = Parameter(str(w), self.omega, lower=0.0, lower_open=True)
        accel = -c * p - k * q - self.cubic * q**3 + a * sp.cos(w * t)
        lab = self.labels
        transitions: list = []
        surfaces: list = []
        if self.kind == "soft stop and impact":
            contact = [0, 1] if self.sticky else None  # (with it, chattering on the stop sticks)
            stop = Stop(lab[4], q + 2 * g, [q, -r * p], contact_direction=contact)  # (on the far side)
            modes = [Mode(lab[0], [p, accel], stops=[stop]), Mode(lab[1], [p, accel - kc * (q - g + p / 8)])]
            transitions = [
                Transition(lab[2], lab[0], lab[1], g - q),
                Transition(lab[3], lab[1], lab[0], q - g),
            ]
        elif self.kind == "three modes, reset":
            modes = [
                Mode(lab[0], [p, accel]),
                Mode(lab[1], [p, accel - kc * (q - g + p / 8)]),
                Mode(lab[2], [p, accel - kc * (q + g + p / 8)]),
            ]
            transitions = [
                Transition(lab[3], lab[0], lab[1], g - q, reset=[q, r * p]),  # (enters at speed r p)
                Transition(lab[4], lab[1], lab[0], q - g),
                Transition(lab[5], lab[0], lab[2], q + g),
                Transition(lab[6], lab[2], lab[0], -g - q),
            ]
        else:
            h = p - vb * (1 + sp.sin(q) / 4) if self.curved else p - vb
            modes = [Mode(lab[0], [p, accel + mu]), Mode(lab[1], [p, accel - mu])]  # (behind, ahead)
            surfaces = [Surface(lab[2], h, lab[1], lab[0])]
            if self.kind == "three modes, sliding":  # (air drag above the speed vf = vb + 3 g / 10)
                vf = vb + 3 * g / 10
                modes.append(Mode(lab[3], [p, accel - mu - kc * (p - vf) / 4]))
                transitions = [
                    Transition(lab[4], lab[1], lab[3], vf - p),
                    Transition(lab[5], lab[3], lab[1], p - vf),
                ]
        return HybridModel(
            "random-modes-" + "-".join(self.names[:2]), [q, p], t, params, period=2 * sp.pi / w,
            modes=modes, transitions=transitions, surfaces=surfaces,
        )  # fmt: skip

    def initial_state(self) -> list[float]:
        """At rest at the origin (free flight; behind the belt)."""
        return [0.0, 0.0]


@st.composite
def modes_specs(draw: st.DrawFn, kinds: tuple[str, ...] = MODE_KINDS) -> ModesSpec:
    """A random :class:`ModesSpec` of one of ``kinds``; names a random selection of :data:`NAMES` and
    :data:`MODE_NAMES`."""
    kind = draw(st.sampled_from(kinds))
    sliding = "sliding" in kind
    return ModesSpec(
        kind=kind,
        names=tuple(draw(st.permutations(NAMES))[:12]),
        labels=tuple(draw(st.permutations(MODE_NAMES))[:7]),
        damping=draw(st.floats(0.02, 0.2)),
        stiffness=draw(st.floats(0.5, 2.0)),
        amplitude=draw(st.floats(0.8, 1.5) if sliding else st.floats(0.5, 1.2)),
        omega=draw(st.floats(0.4, 0.9) if sliding else st.floats(0.6, 2.0)),
        gap=draw(st.floats(0.6, 1.2) if sliding else st.floats(0.2, 0.5)),
        contact=draw(st.floats(2.0, 10.0)),
        restitution=draw(st.floats(0.5, 0.95)),
        friction=draw(st.floats(0.2, 0.6)),
        belt=draw(st.floats(0.1, 0.4)),
        cubic=draw(st.sampled_from([0.0, 0.2])),
        curved=draw(st.booleans()),
        sticky=draw(st.booleans()),  # (drawn last: the other values as before)
    )
