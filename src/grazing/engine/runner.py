"""A trajectory advanced in whole forcing periods: the engine's low-level interface.

:class:`Runner` holds the state of one trajectory (state, variational matrix,
time split as ``k T + s``, contact mode) and the compiled kernels, and
advances it by a number of stroboscopic periods per call, returning the raw
outputs of the compiled driver.  :func:`grazing.simulate` and the sweeps are
built on it; it does no input validation.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.options import CHATTER_TOL, MACHINE_EPSILON, step_limit
from grazing.core.solution import Status
from grazing.engine import interrupts, outputs
from grazing.engine.codegen import ModelKernels, direction_columns, taylor_order
from grazing.engine.native import load_integrate
from grazing.engine.records import CALL, STATIC, Config, Result, RunOutput
from grazing.engine.timebase import start_times
from grazing.errors import InvalidParameterError, SimulationError

RECORD_IMPACTS = {"none": 0, "sampled": 1, "all": 2}


def integrate(kern: ModelKernels, start: tuple[Any, ...], pv: np.ndarray, cfg: tuple[Any, ...]) -> Result:
    """Run the driver on the model of ``kern`` (see :mod:`grazing.engine.driver.loop`).

    ``start`` holds the fields of :class:`~grazing.engine.records.Start`, ``cfg``
    those of :class:`~grazing.engine.records.Config` but the last ones
    (:data:`~grazing.engine.records.INTERRUPT`), added here: a Ctrl-C during
    the run stops the driver at its next step and raises
    :class:`KeyboardInterrupt` (:mod:`grazing.engine.interrupts`).  The
    driver's machine code is loaded without numba
    (:func:`grazing.engine.native.load_integrate`); it writes into arrays
    allocated here, with tables for as many impacts per period as the last
    run of these kernels made (:mod:`grazing.engine.outputs`).
    """
    driver = load_integrate()

    def call(out: RunOutput) -> None:
        with interrupts.counting_sigint() as seen:
            driver(start, pv, (*cfg, interrupts.SIGINTS, seen), kern.table, out)
        interrupts.raise_if_interrupted(seen)

    config = Config(*cfg, interrupts.SIGINTS, 0)  # (its settings by name, here)
    rows = outputs.TableRows.guess(config, kern.impacts_per_period)
    result, need = outputs.run(call, kern.NX, start[1].shape[1], kern.NSTOPS, config, rows)
    kern.impacts_per_period = outputs.impacts_per_period(need, config)
    return result


@dataclass(frozen=True)
class DiscontinuityMap:
    """Nordmark's zero-time discontinuity map, applied once per period at ``phase``.

    The flow then ignores the stop; at local time ``phase`` (the grazing
    time, in ``[0, T)``) the state is corrected by ``x <- x - e sqrt(2 a delta)``
    where ``delta = (L_f h)^2 / (2 a) - h`` is how far the local parabola would
    reach past the stop (only when ``delta > 0`` and ``|L_f h| / a < window``).

    Attributes
    ----------
    phase
        Local time of the grazing contact in ``[0, T)``.
    accel
        ``a = L_f^2 h`` at the grazing point (positive).
    direction
        ``e = (g_x - I) c / (grad(L_f h) . c)`` at the grazing point (``c`` the
        contact direction); ``(0, 1 + r)`` for the pendulum.
    window
        Largest ``|L_f h| / a`` (time to the parabola's extremum) for which the
        map is applied.
    stop
        Index of the stop it stands for; impacts on the model's other stops
        are applied as usual.  On a model with modes, a stop of one mode
        (:func:`check_map_stop`): the map is applied only while the run is in
        that mode.
    """

    phase: float
    accel: float
    direction: tuple[float, ...]
    window: float = math.inf
    stop: int = 0


def check_map_stop(model: HybridModel, stop: int) -> None:
    """One line (:class:`~grazing.errors.InvalidParameterError`) unless the discontinuity map can stand for
    ``model``'s stop ``stop``: a stop of the model, and on a model with modes a transition with a reset
    back into the mode it leaves (a mode's own stop: the map kicks the state and keeps the mode; it is
    applied only while the run is in that mode).

    Examples
    --------
    >>> import grazing
    >>> check_map_stop(grazing.models.pendulum(), 1)
    >>> check_map_stop(grazing.models.pendulum(), 2)
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: the discontinuity map's stop 2 is not a stop of 'pendulum' (0..1)
    """
    if not 0 <= stop < model.n_stops:
        raise InvalidParameterError(
            f"the discontinuity map's stop {stop} is not a stop of {model.name!r} (0..{model.n_stops - 1})"
        )
    if not model.has_modes:
        return
    name, source, target = (
        model.stop_names[stop],
        model.transition_source[stop],
        model.transition_target[stop],
    )
    if not model.transition_resets[stop]:
        raise InvalidParameterError(
            f"the discontinuity map stands for an impact: transition {name!r} has no reset (a switch of "
            "vector field: its map is the switching surface's, grazing normal-form)"
        )
    if source != target:
        raise InvalidParameterError(
            f"the discontinuity map keeps the mode: it cannot stand for transition {name!r}, whose reset "
            f"goes from mode {source!r} to {target!r} (only a stop of a mode, a reset back into it)"
        )


def map_stops(model: HybridModel) -> list[int]:
    """The stops the discontinuity map can stand for (:func:`check_map_stop`): every stop of a model of one
    mode; with modes, the transitions with a reset back into the mode they leave.

    Examples
    --------
    >>> import grazing
    >>> map_stops(grazing.models.pendulum())
    [0, 1]
    """
    if not model.has_modes:
        return list(range(model.n_stops))
    return [
        j
        for j in range(model.n_stops)
        if model.transition_resets[j] and model.transition_source[j] == model.transition_target[j]
    ]


@dataclass(frozen=True)
class Segment:
    """Raw outputs of one :meth:`Runner.advance` call (see the driver for details)."""

    samples: np.ndarray
    impacts: np.ndarray  # rows [t, speed, state..., stop index]
    n_impacts: int
    sticking: np.ndarray
    trajectory: np.ndarray  # rows [t, state...]
    log_sums: np.ndarray
    lyap_span: float
    guard_min: np.ndarray  # rows per stop: [h_min, t, state...]
    approach_min: np.ndarray  # rows per stop: [h, t, state...] at the closest approach away from contacts
    jacobian_valid: bool
    steps: int
    switches: np.ndarray  # rows [t, transition index, state...] (models with modes)
    sample_modes: np.ndarray  # the mode of each sample (as samples)
    vf_span: int = 0  # the active mode when the recorded span started


def step_safety(tol: float, order: int) -> float:
    """The exponent ``c`` of the step ``h = rho * exp(-c - 0.7/(order - 1))``: ``-ln(tol)/(order + 1)``.

    With ``h = rho e^-c`` the truncation error of a step of a Taylor method of
    degree ``order`` is about ``e^(-c (order + 1))``, which this choice makes
    equal to ``tol``.  Jorba & Zou (and heyoka) use ``c = 2``, i.e. an error
    about ``e^-6`` below ``tol`` at their order: at the default tolerance the
    steps here are 1.35 times longer, and the samples of a 100,000-period run
    deviate 5.2e-15 from a long-double reference instead of 1.7e-15
    (benchmarks/README.md).

    Examples
    --------
    >>> round(step_safety(2.220446049250313e-16, 20), 3)
    1.716
    """
    return -math.log(tol) / (order + 1)


class Runner:
    """One trajectory of ``model``, advanced period by period.

    Parameters
    ----------
    model
        Model with parameter values.
    x
        State at time ``t0`` (not validated).
    t0
        Initial time.
    phase
        Stroboscopic phase in radians: samples at ``t = (phase/2pi + k) T``.
    tol
        Local error tolerance: it sets the Taylor order (Jorba & Zou,
        ``ceil(-ln(tol)/2 + 1)``, as heyoka) and the step, chosen so that the
        estimated truncation error of a step, ``(h/rho)^(order + 1)`` with
        ``rho`` the estimated radius of convergence, equals ``tol``
        (:func:`step_safety`).
    variational
        Integrate the variational equations (Jacobian or Lyapunov exponents).
    sensitivities
        Parameters whose derivatives are appended to the Jacobian.
    events
        Apply impacts (False: the flow passes through the stop).
    chatter_tol
        Chattering summation threshold, as a fraction of the period.
    zdm
        Apply a discontinuity map once per period instead of the impacts on
        its stop (the other stops' impacts are applied).
    touching
        The trajectory starts at a grazing contact with the stop (a grazing
        orbit from its contact point): that tangential contact is not an
        impact.  Set :attr:`touch_end` before the call of :meth:`advance` that
        ends at a contact.
    stop
        Index of the stop a grazing analysis looks at: its guard's minimum is
        tracked (``guard_min``), the contacts of ``touching`` are on it, and
        ``zdm`` stands for its impacts.
    mode
        The index of the mode a model with modes starts in.
    """

    def __init__(
        self,
        model: HybridModel,
        x: np.ndarray,
        *,
        t0: float = 0.0,
        phase: float = 0.0,
        tol: float = MACHINE_EPSILON,
        variational: bool = False,
        sensitivities: Sequence[str] = (),
        events: bool = True,
        chatter_tol: float = CHATTER_TOL,
        zdm: DiscontinuityMap | None = None,
        touching: bool = False,
        stop: int = 0,
        mode: int = 0,
    ):
        self.model = model
        self.zdm = zdm
        self.stop = int(zdm.stop if zdm is not None else stop)
        self.touch_start = touching
        self.touch_end = False  # set by the caller for the call that ends at a contact
        n = model.n_states
        self.x = np.array(x, dtype=float)
        self.V = np.zeros((n, n + direction_columns(len(sensitivities) if variational else 0)))
        self.V[:, :n] = np.eye(n)
        self.variational = variational
        self.events = events
        self.T = model.period
        self.order = taylor_order(tol)
        self.safety = step_safety(tol, self.order)
        self.sensitivities = tuple(sensitivities) if variational else ()
        self.directions = direction_columns(len(self.sensitivities))
        self.kern = model.kernels(self.directions, self.order)
        self.chatter_time = chatter_tol * self.T
        self.set_params(model)
        T = self.T
        s_phase = (phase % (2 * math.pi)) / (2 * math.pi) * T
        self.mode = 0
        self.vf = int(mode)  # the active mode (vector field) of a model with modes
        self.k, self.s, self.ks, self.ss = start_times(float(t0), T, s_phase, bool(model.periodic))
        self.k_start = self.k

    @property
    def t(self) -> float:
        """Current time."""
        return self.k * self.T + self.s

    @property
    def next_sample_time(self) -> float:
        return self.ks * self.T + self.ss if self.model.periodic else self.ss

    def set_params(self, model: HybridModel) -> None:
        """Continue with other parameter values of the same model (same period)."""
        self.model = model
        names = [p.name for p in model.parameters]
        D = np.zeros((self.directions, len(names)))  # unit directions; unused columns stay zero
        for c, name in enumerate(self.sensitivities):
            D[c, names.index(name)] = 1.0
        self.pv = np.concatenate([model.param_vector, D.ravel()])
        self.Tp = D @ self.period_gradient()
        self._static = self._static_config()

    def _static_config(self) -> tuple[Any, ...]:
        """The fields of the driver's config that stay the same for this trajectory (``records.STATIC``)."""
        T = float(self.model.period)
        z = self.zdm
        n = self.model.n_states
        fields = dict(
            T=T, wrap=bool(self.model.periodic), max_step=T, safety=float(self.safety),
            use_var=bool(self.variational), events=bool(self.events), chatter_time=float(self.chatter_time),
            zdm=z is not None, zdm_s=float(z.phase) % T if z is not None else 0.0,
            zdm_a=float(z.accel) if z is not None else 1.0,
            zdm_e=np.asarray(z.direction if z is not None else np.zeros(n), dtype=float),
            zdm_window=float(z.window) if z is not None else 0.0, Tp=np.asarray(self.Tp, dtype=float),
            stop=self.stop,
        )  # fmt: skip
        return tuple(fields[name] for name in STATIC)

    def vector_field(self, x: np.ndarray, s: float, mode: int | None = None) -> np.ndarray:
        """``f(x, s)`` of ``mode`` (by default the current one), by the kernels this runner loaded."""
        out = np.empty(self.model.n_states)
        self.kern.rhs(np.asarray(x, dtype=float), float(s), self.pv, out, self.vf if mode is None else mode)
        return out

    def period_gradient(self) -> np.ndarray:
        """``dT/dp`` for every parameter (zero for parameters that do not set the period)."""
        full = np.zeros(len(self.model.parameters))
        self.kern.period_grad(self.x, 0.0, self.model.param_vector, full)
        return full

    def reset_variational(self) -> None:
        n = self.model.n_states
        self.V[:] = 0.0
        self.V[:, :n] = np.eye(n)

    def advance(
        self,
        periods: int,
        keep: int,
        *,
        lyapunov: bool = False,
        guard_min: bool = False,
        impacts: str = "none",
        trajectory: int = 0,
        max_steps: int | None = None,
    ) -> Segment:
        """Advance by ``periods`` samples, keeping (recording) the last ``keep``."""
        T = self.T
        if max_steps is None:
            max_steps = step_limit(periods)
        start = (self.x, self.V, self.k, self.s, self.mode, self.vf)  # a records.Start, as a plain tuple
        call = dict(
            max_steps=int(max_steps), n_samples=periods, ks=self.ks, ss=float(self.ss), n_keep=keep,
            lyapunov=bool(lyapunov), traj_dt=T / trajectory if trajectory else 0.0, track_min=bool(guard_min),
            record_impacts=RECORD_IMPACTS[impacts], touch_start=self.touch_start, touch_end=self.touch_end,
        )  # fmt: skip
        # A records.Config but its INTERRUPT fields, as a plain tuple (see the driver's integrate).
        cfg = (*(call[name] for name in CALL), *self._static)
        out = integrate(self.kern, start, self.pv, cfg)
        if out.status != Status.OK:
            raise SimulationError(
                Status(int(out.status)).message(out.k * T + out.s, max_steps, self.model, out.x, int(out.vf))
            )
        self.x, self.V, self.k, self.s, self.mode, self.vf = out.x, out.V, out.k, out.s, out.mode, out.vf
        self.touch_start = False  # only the first call starts at the contact
        if self.model.periodic:
            self.ks += periods
        else:
            self.ss += periods * T
        n = self.model.n_states
        gm = out.guard_min
        return Segment(
            out.samples, out.impacts, out.n_impacts, out.sticking, out.trajectory, out.log_sums,
            out.lyap_span, gm[:, : 2 + n], gm[:, 2 + n :], out.jacobian_valid, out.steps, out.switches,
            out.sample_modes,
            out.vf_span,
        )  # fmt: skip
