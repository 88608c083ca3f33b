"""Results of a simulation: the :class:`Solution`, its :class:`Impacts`, and the :class:`Status` of a run."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum
from typing import TYPE_CHECKING, Any

import numpy as np

from grazing.core.options import STEPS_PER_PERIOD
from grazing.core.period import DEFAULT_MAX_PERIOD, DEFAULT_PERIOD_TOL, detect_period

if TYPE_CHECKING:  # pragma: no cover
    from grazing.core.model import HybridModel


class Status(IntEnum):
    """How a run of the compiled driver ended; the codes are the driver's.

    Examples
    --------
    >>> Status(1).message(t=12.5, max_steps=1000)
    'step limit of 1000 steps reached at t = 12.5'
    """

    OK = 0
    STEP_LIMIT = 1
    NONFINITE = 2
    ZENO = 3
    """Impacts accumulate and the model has no sticking rule (or a zero-time event loop)."""
    INTERRUPTED = 4
    """Ctrl-C (SIGINT) during the run: the caller raises :class:`KeyboardInterrupt`."""
    OUTSIDE_MODE = 5
    """A transition entered a mode at a state outside its region (a guard of the mode's own transitions
    already negative there): the modes' regions do not fit together; on a model of one mode, an impact's
    reset put the state beyond a stop."""

    def message(
        self, t: float, max_steps: int, model: HybridModel | None = None, x: Any = None, mode: int = -1
    ) -> str:
        """The user-facing sentence for this status at time ``t`` (the run ended in state ``x`` of ``model``,
        in its mode number ``mode``).

        For :attr:`ZENO` the model and the state say why: see :func:`accumulation_message`; for
        :attr:`OUTSIDE_MODE` the mode too: see :func:`outside_mode_message`.
        """
        if self is Status.STEP_LIMIT:
            return f"step limit of {max_steps} steps reached at t = {t:.6g}"
        if self is Status.NONFINITE:
            return f"the state became non-finite at t = {t:.6g}"
        if self is Status.ZENO:
            if model is None or x is None:
                return f"impacts accumulate at t = {t:.6g} and cannot be continued"
            return accumulation_message(model, x, t)
        if self is Status.INTERRUPTED:
            return f"interrupted at t = {t:.6g}"
        if self is Status.OUTSIDE_MODE:
            if model is None or x is None or mode < 0:
                return f"a transition entered a mode outside its region at t = {t:.6g}"
            return outside_mode_message(model, x, t, mode)
        return "ok"

    @property
    def reason(self) -> str:
        """A few words for the outcome, as sweeps report each point's: ``'ok'``, ``'step limit'`` ...

        Examples
        --------
        >>> [s.reason for s in Status]
        ['ok', 'step limit', 'non-finite state', 'accumulating impacts', 'interrupted', 'outside its mode']
        """
        return _REASONS[self][0]

    @property
    def explanation(self) -> str:
        """What the outcome means and what to do about it (one sentence, for documentation)."""
        return _REASONS[self][1]


_REASONS = {
    Status.OK: ("ok", "computed"),
    Status.STEP_LIMIT: (
        "step limit",
        f"the integrator reached its step limit ({STEPS_PER_PERIOD} steps per forcing period): the forcing "
        "period is very long for the motion, the motion very fast, or the tolerance very small",
    ),
    Status.NONFINITE: (
        "non-finite state",
        "the state overflowed to infinity or NaN: a parameter too large, or a motion that escapes",
    ),
    Status.ZENO: (
        "accumulating impacts",
        "impacts accumulate (complete chattering) on a stop without a contact_direction for sticking, "
        "in a corner where two stops are hit at once, or events repeat at one instant (a guard the reset "
        "does not move away from)",
    ),
    Status.INTERRUPTED: ("interrupted", "Ctrl-C stopped the run (raised as KeyboardInterrupt)"),
    Status.OUTSIDE_MODE: (
        "outside its mode",
        "a transition entered a mode at a state where a guard of that mode's own transitions is already "
        "negative (outside the mode's region): the model's modes and guards do not fit together there; "
        "on a model of one mode, an impact's reset put the state beyond a stop",
    ),
}


def accumulation_message(model: HybridModel, x: Any, t: float) -> str:
    """Why impacts accumulate at ``(x, t)`` and cannot be continued (the driver's :attr:`Status.ZENO`).

    The driver stops after a few events in a row at zero time.  With the state
    on one stop, that stop has no contact direction (complete chattering is
    continued as sticking only with one); on two stops at once (a corner where
    both are active: the reset of each leaves the state on the other) it is a
    contact with two stops, which the engine does not continue.

    Examples
    --------
    >>> import sympy as sp
    >>> import grazing
    >>> x, v, t = sp.symbols("x v t")
    >>> m = grazing.HybridModel("ball", [x, v], t, [grazing.Parameter("r", 0.5, lower=0, upper=1)],
    ...     vector_field=[v, -1], guard=x, reset=[x, -sp.Symbol("r") * v], period=1, periodic=False)
    >>> print(accumulation_message(m, [0.0, -1e-9], 2.0))  # doctest: +NORMALIZE_WHITESPACE
    impacts accumulate at t = 2 on the stop and cannot be continued
    (the model defines no contact_direction for sticking)
    """
    from grazing.core.model import ON_STOP_TOL

    state = np.asarray(x, dtype=float).reshape(-1)
    tol = ON_STOP_TOL * max(1.0, float(np.max(np.abs(state), initial=0.0)))
    on = [j for j, h in enumerate(model.guards(state, t)) if abs(h) <= tol]
    names = [repr(model.stop_names[j]) for j in on]
    switching = [j for j in on if model.transition_source[j] != model.transition_target[j]]
    if model.has_modes and switching and all(model.symbolic.resets[j] for j in switching):
        return (  # landings from one mode onto another that accumulate (a rocking block coming to rest)
            f"impacts from mode to mode accumulate at t = {t:.6g} (transitions "
            f"{', '.join(repr(model.stop_names[j]) for j in switching)}): the motion comes to rest on "
            "their guard, and a model with modes cannot continue that yet"
        )
    if model.has_modes and switching:  # two modes whose fields push into each other
        modes = sorted(
            {m for j in switching for m in (model.transition_source[j], model.transition_target[j])}
        )
        return (
            f"modes {', '.join(map(repr, modes))} switch back and forth at zero time at t = {t:.6g} (their "
            "fields push into each other): declare their boundary as a Surface with sliding=True to slide "
            "on it"
        )
    sticks = model.kernels().STICKS
    if len(on) >= 2:
        return (
            f"impacts accumulate at t = {t:.6g} in the corner where stops {', '.join(names[:-1])} and "
            f"{names[-1]} meet (the state is on both): sticking is continued on one stop at a time, "
            "not on two at once"
        )
    if len(on) == 1:
        (j,) = on
        where = "the stop" if model.stop_names == ("stop",) else f"stop {names[0]}"
        if not sticks[j]:
            why = (
                "the model defines no contact_direction for sticking"
                if model.n_stops == 1
                else f"stop {names[0]} has no contact_direction for sticking"
            )
            return f"impacts accumulate at t = {t:.6g} on {where} and cannot be continued ({why})"
        return (
            f"impacts accumulate at t = {t:.6g} on {where} and cannot be continued as sticking "
            "(events repeat at zero time: the contact neither holds nor releases)"
        )
    return f"events repeat at zero time at t = {t:.6g}: the run cannot be continued"


def outside_mode_message(model: HybridModel, x: Any, t: float, mode: int) -> str:
    """Why a run ended in mode number ``mode`` at ``(x, t)`` (the driver's :attr:`Status.OUTSIDE_MODE`).

    A transition entered the mode where a guard of the mode's own transitions is already negative
    (beyond :data:`~grazing.core.model.ON_STOP_TOL`): the state is outside the mode's region, and
    the run would have jumped at once onto that guard's surface.  The message names the mode and that
    guard (the most negative, if several); on a model of one mode, where only an impact's reset can
    put the state there, the stop it is beyond.

    Examples
    --------
    >>> import grazing
    >>> m = grazing.models.soft_impact_oscillator(gap=0.5)
    >>> contact = m.mode_index("contact")
    >>> print(outside_mode_message(m, [0.0, 0.0], 2.0, contact))  # doctest: +NORMALIZE_WHITESPACE
    a transition entered mode 'contact' at t = 2 outside its region: there the guard of its transition
    'leave' is already h = -0.5 < 0 (the guards of the model's modes do not fit together there)
    """
    from grazing.core.model import ON_STOP_TOL

    state = np.asarray(x, dtype=float).reshape(-1)
    name = model.mode_names[mode]
    tol = ON_STOP_TOL * max(1.0, float(np.max(np.abs(state), initial=0.0)))
    guards = model.guards(state, t)
    own = [j for j in range(model.n_stops) if model.transition_source[j] == name and guards[j] < -tol]
    if not own:
        return f"a transition entered mode {name!r} at t = {t:.6g} outside its region"
    j = min(own, key=lambda i: guards[i])
    if not model.has_modes:  # (one mode: an impact's reset beyond a stop)
        return (
            f"an impact's reset at t = {t:.6g} put the state beyond stop {model.stop_names[j]!r}: its guard "
            f"is h = {guards[j]:.3g} < 0 there (a reset must leave the state where every guard is >= 0)"
        )
    return (
        f"a transition entered mode {name!r} at t = {t:.6g} outside its region: there the guard of its "
        f"transition {model.stop_names[j]!r} is already h = {guards[j]:.3g} < 0 (the guards of the model's "
        "modes do not fit together there)"
    )


@dataclass(frozen=True)
class Impacts:
    """Impact-map samples: one row per impact.

    Attributes
    ----------
    t
        Impact times.
    phase
        Forcing phase ``2 pi (t mod T) / T`` in [0, 2 pi).
    speed
        Approach speed ``-dh/dt`` just before the impact (for the pendulum,
        the angular velocity ``theta'`` hitting the stop).
    state
        State just before the impact, shape ``(n_impacts, n_states)``.
    stop
        Index of the stop each impact is on (into ``stop_names``).
    stop_names
        The model's stop names.

    Examples
    --------
    >>> import numpy as np
    >>> imp = Impacts(np.array([1.0, 2.0, 3.0]), np.zeros(3), np.ones(3), np.zeros((3, 2)),
    ...               stop=np.array([0, 1, 1]), stop_names=("right", "left"))
    >>> imp.per_stop(), imp.stop_name(2)
    ({'right': 1, 'left': 2}, 'left')
    """

    t: np.ndarray
    phase: np.ndarray
    speed: np.ndarray
    state: np.ndarray
    stop: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    stop_names: tuple[str, ...] = ("stop",)

    def __post_init__(self) -> None:
        if self.stop.shape != self.t.shape:  # impacts of a one-stop model given without their stops
            object.__setattr__(self, "stop", np.zeros(self.t.shape, dtype=int))

    def __len__(self) -> int:
        return int(self.t.size)

    def stop_name(self, i: int) -> str:
        """The name of the stop impact ``i`` is on."""
        return self.stop_names[int(self.stop[i])]

    def per_stop(self) -> dict[str, int]:
        """The number of impacts on each stop, by name (every stop listed)."""
        counts = np.bincount(self.stop.astype(int), minlength=len(self.stop_names))
        return {name: int(c) for name, c in zip(self.stop_names, counts)}


@dataclass(frozen=True)
class Switches:
    """Changes of mode (a model with modes): one row per switch.

    A transition with a reset that changes the mode (the rocking block's
    impact from one corner onto the other) is both an impact (in
    :attr:`Solution.impacts`, with the state before it) and a switch (here,
    with the state after the reset).

    Attributes
    ----------
    t
        Switch times.
    transition
        Index of each switch's transition (into ``transition_names``).
    state
        The state at the switch (after the reset, if any), shape ``(n_switches, n_states)``.
    transition_names
        The model's transitions (:attr:`~grazing.core.model.HybridModel.stop_names`), then its
        sliding pseudo-modes' exits and entries
        (:attr:`~grazing.core.model.HybridModel.switch_names`: ``belt_slide_from_slip_ahead`` enters
        ``"sliding on 'belt'"``, ``belt_exit_to_slip_behind`` leaves it).
    sources, targets
        Per transition, the mode it leaves and the mode it enters.

    Examples
    --------
    >>> import numpy as np
    >>> sw = Switches(np.array([1.0, 2.0]), np.array([0, 1]), np.zeros((2, 2)), ("touch", "leave"),
    ...               ("free", "contact"), ("contact", "free"))
    >>> len(sw), sw.source(1), sw.target(1), sw.name(0)
    (2, 'contact', 'free', 'touch')
    """

    t: np.ndarray
    transition: np.ndarray
    state: np.ndarray
    transition_names: tuple[str, ...] = ()
    sources: tuple[str, ...] = ()
    targets: tuple[str, ...] = ()

    def __len__(self) -> int:
        return int(self.t.size)

    def name(self, i: int) -> str:
        """The transition of switch ``i``."""
        return self.transition_names[int(self.transition[i])]

    def source(self, i: int) -> str:
        """The mode switch ``i`` leaves."""
        return self.sources[int(self.transition[i])]

    def target(self, i: int) -> str:
        """The mode switch ``i`` enters."""
        return self.targets[int(self.transition[i])]


@dataclass(frozen=True)
class Solution:
    """The outcome of :func:`grazing.simulate`.

    Attributes
    ----------
    model
        The model (with its parameter values) that was simulated.
    t, samples
        Stroboscopic sample times and states, one per sampled forcing period
        (transient periods discarded).
    impacts
        Impacts during the sampled span (see :class:`Impacts`).
    n_impacts
        Number of impacts over the whole run, transient included.
    sticking
        Sticking intervals ``[t_start, t_end]`` during the sampled span.
    trajectory_t, trajectory
        Dense trajectory over the sampled span (with both states at every
        impact), if requested.
    t_final, x_final
        Time and state at the end of the run (the last sample).
    jacobian
        Derivative of ``x_final`` with respect to ``x0`` (and to the requested
        parameters, as extra columns), if requested.
    jacobian_valid
        False when the run stuck to the stop (the Jacobian across sticking is
        not computed) or met it at exactly zero normal speed (where the
        saltation matrix is unbounded).
    lyapunov
        Lyapunov exponents per unit time over the sampled span, if requested.
    guard_min
        ``(h_min, t, x)``: the smallest value of the guard over the sampled
        span, if requested (for a stop at ``x = c``, ``c - max x``).
    approach_min
        ``(h, t, x)``: the closest approach to the stop in free flight (the
        smallest local minimum of the guard, away from impacts and sticking),
        if requested and there is one.  For an impacting orbit it says how
        near the orbit is to gaining an impact.  Both refer to the stop named
        by ``stop_name`` (the first by default).
    guard_min_by_stop, approach_by_stop
        The same for every stop of the model, in the order of
        :attr:`~grazing.HybridModel.stop_names` (``approach_by_stop[j]`` is
        None when stop ``j`` has no closest approach in free flight).
    n_steps
        Number of Taylor steps taken.
    info
        How the run was made: ``"order"`` (the Taylor order the tolerance
        chose), ``"tol"`` (the local error tolerance), ``"transient"`` (forcing
        periods run before the samples), ``"phase"`` (the stroboscopic phase
        of the samples, radians) and ``"period_gradient"`` (for each parameter
        of ``Tangent.sensitivities``, the derivative of the forcing period with
        respect to it: 0 for a parameter that does not set the period).
    switches
        A model with modes: its changes of mode, with or without a reset
        (:class:`Switches`, recorded as the impacts are); None for a model of one mode.
    mode_final
        A model with modes: the mode at the end; None for a model of one mode.
    modes
        A model with modes: the mode of every sample (an index into
        :attr:`mode_names`, the mode after any switch at the sample's time);
        None for a model of one mode.
    sliding
        A model with modes: its sliding intervals during the sampled span, rows
        ``[t_start, t_end, surface]`` (``surface`` an index into
        :attr:`~grazing.HybridModel.surface_names`; the motion on a surface with
        ``sliding=True``, in its pseudo-mode ``"sliding on 'name'"``, entered and
        left by the switches in :attr:`switches`); None for a model of one mode
        or a run that records no impacts (``SaveAt(impacts="none")``: no switches either).

    Examples
    --------
    The paper's period-5 orbit at θ̂ = 40°, η = 0.446 (its fig. 7): ten
    samples after a transient of 400 periods, two impacts among them (none on
    the back face of the stop):

    >>> import math, grazing
    >>> model = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> sol = grazing.simulate(model, [0.0, 0.0], transient=400, periods=10)
    >>> sol.samples.shape, sol.period(), len(sol.impacts), sol.impacts.per_stop()
    ((10, 2), 5, 2, {'stop': 2, 'back': 0})
    >>> sorted(sol.info), sol.info["order"], sol.info["transient"]
    (['order', 'period_gradient', 'phase', 'tol', 'transient'], 20, 400)
    >>> bool(abs(sol.t[1] - sol.t[0] - model.period) < 1e-12), sol.x_final.shape  # one sample a period
    (True, (2,))
    """

    model: HybridModel
    t: np.ndarray
    samples: np.ndarray
    impacts: Impacts
    n_impacts: int
    sticking: np.ndarray
    t_final: float
    x_final: np.ndarray
    n_steps: int
    trajectory_t: np.ndarray | None = None
    trajectory: np.ndarray | None = None
    jacobian: np.ndarray | None = None
    jacobian_valid: bool = True
    lyapunov: np.ndarray | None = None
    guard_min: tuple[float, float, np.ndarray] | None = None
    approach_min: tuple[float, float, np.ndarray] | None = None
    guard_min_by_stop: tuple[tuple[float, float, np.ndarray], ...] | None = None
    approach_by_stop: tuple[tuple[float, float, np.ndarray] | None, ...] | None = None
    info: dict[str, Any] = field(default_factory=dict)
    switches: Switches | None = None
    mode_final: str | None = None
    modes: np.ndarray | None = None
    sliding: np.ndarray | None = None

    @property
    def mode_names(self) -> tuple[str, ...]:
        """The model's modes (:attr:`modes` indexes them); ``("free",)`` for a model of one mode."""
        return self.model.mode_names

    def mode_spans(self) -> list[tuple[float, float, int]]:
        """The modes over the recorded span: ``(start, end, mode index)``, one per stay.

        The span is the dense trajectory's when there is one, else the sampled
        periods' (from one period before the first sample) to :attr:`t_final`.
        Read from the switches (so it needs them recorded: ``impacts="sampled"``,
        the default, or ``"all"``) and the mode of the first sample; empty for
        a model of one mode or without samples.

        Examples
        --------
        >>> import grazing
        >>> sol = grazing.simulate(grazing.models.soft_impact_oscillator(), [0.0, 0.0], periods=2)
        >>> [sol.mode_names[k] for _, _, k in sol.mode_spans()]
        ['free', 'contact', 'free', 'contact', 'free']
        """
        if self.modes is None or self.switches is None or not len(self.modes):
            return []
        if self.trajectory_t is not None and self.trajectory_t.size:
            start = float(self.trajectory_t[0])
        else:
            start = float(self.t[0]) - self.model.period
        after = np.flatnonzero(self.switches.t > start)
        index = {name: k for k, name in enumerate(self.mode_names)}
        mode = index[self.switches.source(int(after[0]))] if after.size else int(self.modes[0])
        spans = []
        for i in after:
            t = float(self.switches.t[i])
            spans.append((start, t, mode))
            start, mode = t, index[self.switches.target(int(i))]
        spans.append((start, float(self.t_final), mode))
        return spans

    def period(self, tol: float = DEFAULT_PERIOD_TOL, max_period: int = DEFAULT_MAX_PERIOD) -> int:
        """Smallest period of the sampled sequence (0 if none); see :func:`detect_period`."""
        return detect_period(self.samples, tol=tol, max_period=max_period)
