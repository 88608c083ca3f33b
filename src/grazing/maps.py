"""Poincare maps of a hybrid model as discrete systems: the stroboscopic map and the impact map.

As in DynamicalSystems.jl, a map derived from the flow is a system of its own:
:class:`StroboscopicMap` (``P^n``, the state from the section ``t = t0 (mod T)``
to itself ``n`` periods later) and :class:`ImpactMap` (the state on the stop
from one impact to the next) can be iterated, and the stroboscopic map
linearised (:func:`flow_map`: its Jacobian with saltation matrices at the
impacts, and its parameter derivatives), which is what shooting, continuation
and the normal form are built on.

Examples
--------
>>> import math, grazing
>>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
>>> P = StroboscopicMap(m, periods=5)
>>> x = P.iterate([0.0, 0.0], 120)[-1]
>>> bool(abs(P(x) - x).max() < 1e-9)
True
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.solution import Impacts, Solution
from grazing.engine.simulate import simulate
from grazing.errors import InvalidParameterError


@dataclass(frozen=True)
class FlowMap:
    """``P^n`` at a point: the image, its Jacobians and what happened on the way (:func:`flow_map`).

    Parameters
    ----------
    image
        ``P^n(x)``: the state ``n`` forcing periods later.
    jacobian
        ``d P^n / d x``, with the saltation matrices of the impacts on the way.
    sensitivity
        ``d P^n / d p``, one column per parameter asked for.
    solution
        The simulation that computed them (its impacts, guard minimum, switches ...).
    mode
        A model with modes: the mode ``x`` is taken in (the map's image is in
        :attr:`mode_final`); None for a model without modes.

    Examples
    --------
    >>> import math, grazing
    >>> from grazing.maps import flow_map
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> fm = flow_map(m, [0.0, 0.0], sensitivities=("eta",))
    >>> fm.image.shape, fm.jacobian.shape, fm.sensitivity.shape, fm.impacts
    ((2,), (2, 2), (2, 1), 0)
    """

    image: np.ndarray
    jacobian: np.ndarray  # d P^n / d x
    sensitivity: np.ndarray  # d P^n / d p for the requested parameters (columns)
    solution: Solution
    mode: str | None = None

    @property
    def impacts(self) -> int:
        return self.solution.n_impacts

    @property
    def mode_final(self) -> str | None:
        """A model with modes: the mode of the image (None without modes)."""
        return self.solution.mode_final


def flow_map(
    model: HybridModel,
    x: np.ndarray,
    *,
    t0: float = 0.0,
    periods: int = 1,
    sensitivities: Sequence[str] = (),
    virtual: bool = False,
    touching: bool = False,
    stop_name: int | str | None = None,
    mode: str | None = None,
) -> FlowMap:
    """Apply the stroboscopic map ``periods`` times from ``x`` at time ``t0``.

    The map goes from the section ``t = t0 (mod T)`` to itself, ending at
    ``t0 + periods T``.  With ``virtual`` the stop is ignored (the flow passes
    through it).  The parameter derivatives hold ``t0`` fixed and let the end
    ``t0 + periods T(p)`` move with a parameter that sets the period ``T``.
    With ``touching`` the map starts and ends at a grazing contact with the
    stop (``x`` on the stop with zero normal velocity), which is not an impact.
    ``stop_name`` names the stop that the contact and the solution's ``guard_min``
    refer to (the first by default).

    On a model with modes the map goes from ``x`` in ``mode`` to the image in
    the mode the flow is in then (:attr:`FlowMap.mode_final`), its Jacobian
    carried across the switches by their saltation matrices; the guard
    minimum is not computed there, and a ``virtual`` map ignores only the
    transitions with a reset (it still switches and slides).

    Parameters
    ----------
    model
        The model with its parameter values.
    x
        The state at ``t0``.
    t0
        Time of the section.
    periods
        ``n``: forcing periods the map spans.
    sensitivities
        Parameter names whose derivatives are wanted (:attr:`FlowMap.sensitivity`).
    virtual
        Ignore the stop (the flow passes through it).
    touching
        ``x`` is a grazing contact with the stop, not an impact.
    stop_name
        The stop the contact and the guard minimum refer to (name or index).
    mode
        A model with modes: the mode ``x`` is in (its initial mode by default).

    Returns
    -------
    FlowMap
        The image, its Jacobians and the simulation.

    Examples
    --------
    On the period-5 orbit at θ̂ = 40°, η = 0.446 the map of five periods
    fixes the point, and its Jacobian's eigenvalues are the orbit's Floquet
    multipliers (both inside the unit circle: a stable orbit):

    >>> import math, numpy as np, grazing
    >>> from grazing.maps import StroboscopicMap
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> x = StroboscopicMap(m, periods=5).iterate([0.0, 0.0], 120)[-1]
    >>> fm = flow_map(m, x, periods=5)
    >>> bool(np.abs(fm.image - x).max() < 1e-9), fm.impacts
    (True, 1)
    >>> np.sort(np.abs(np.linalg.eigvals(fm.jacobian))).round(4).tolist()
    [0.002, 0.3464]

    With the stop ignored, the same orbit would pass it (a negative guard minimum):

    >>> fm = flow_map(m, x, periods=5, virtual=True)
    >>> fm.impacts, bool(fm.solution.guard_min[0] < 0)
    (0, True)
    """
    sol = simulate(
        model,
        x,
        t0=t0,
        periods=periods,
        phase=2 * math.pi * (t0 / model.period % 1.0),  # the section through t0
        jacobian=True,
        sensitivities=tuple(sensitivities),
        guard_min=True,
        events=not virtual,
        touching=touching,
        stop_name=stop_name,
        mode=mode,
    )
    n = model.n_states
    sens = sol.jacobian[:, n:]
    tp = np.array([sol.info["period_gradient"][p] for p in sensitivities])
    if np.any(tp) and model.periodic:
        # simulate's derivative keeps the end at the forcing phase of t0, i.e. at
        # (t0/T + periods) T(p); the map's end is t0 + periods T(p).
        f_end = model.vector_field(sol.x_final, sol.t_final, sol.mode_final)
        sens = sens - np.outer(f_end * (t0 / model.period), tp)
    start = model.mode_names[model.mode_index(mode)] if model.has_modes else None
    return FlowMap(sol.x_final, sol.jacobian[:, :n], sens, sol, start)


@dataclass(frozen=True)
class StroboscopicMap:
    """``P^n``: the state at ``t0 (mod T)`` to the state ``periods`` forcing periods later.

    Attributes
    ----------
    model
        The model with its parameter values.
    t0
        Time of the section.
    periods
        ``n``: forcing periods per application.
    virtual
        Ignore the stop (the flow passes through it).
    mode
        A model with modes: the mode the first state is in (its initial mode by default).

    Examples
    --------
    The map is a discrete system: call it, iterate it, linearise it.

    >>> import math, numpy as np, grazing
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> P = StroboscopicMap(m)
    >>> xs = P.iterate([0.0, 0.0], 400)
    >>> xs.shape, grazing.detect_period(xs[-50:])
    ((400, 2), 5)
    >>> bool(np.allclose(P(xs[-2]), xs[-1], atol=1e-9))  # one more application: the next iterate
    True
    >>> P.linearize(xs[-1]).jacobian.shape
    (2, 2)
    """

    model: HybridModel
    t0: float = 0.0
    periods: int = 1
    virtual: bool = False
    mode: str | None = None

    def __call__(self, x: Sequence[float] | np.ndarray) -> np.ndarray:
        """The image of ``x``."""
        return self._run(x, 1).x_final

    def iterate(self, x: Sequence[float] | np.ndarray, n: int) -> np.ndarray:
        """The ``n`` iterates ``P(x), P^2(x), ...`` (rows), from one continuous run."""
        if n < 1:
            raise InvalidParameterError(f"n must be >= 1, got {n}")
        samples = self._run(x, n).samples
        return samples[self.periods - 1 :: self.periods] if self.periods > 1 else samples

    def linearize(self, x: Sequence[float] | np.ndarray, sensitivities: Sequence[str] = ()) -> FlowMap:
        """The image of ``x`` with its Jacobian and parameter derivatives (see :func:`flow_map`)."""
        return flow_map(
            self.model, np.asarray(x, dtype=float), t0=self.t0, periods=self.periods,
            sensitivities=sensitivities, virtual=self.virtual, mode=self.mode,
        )  # fmt: skip

    def _run(self, x: Sequence[float] | np.ndarray, n: int) -> Solution:
        return simulate(
            self.model, x, t0=self.t0, periods=n * self.periods,
            phase=2 * math.pi * (self.t0 / self.model.period % 1.0), impacts="none", events=not self.virtual,
            mode=self.mode,
        )  # fmt: skip


@dataclass(frozen=True)
class ImpactMap:
    """The impact map: the state on the stop at one impact to the state at the next.

    Attributes
    ----------
    model
        The model with its parameter values.
    max_periods
        Give up looking for the next impacts after this many forcing periods.

    Examples
    --------
    The period-5 orbit at θ̂ = 40°, η = 0.446 hits the stop once every five
    forcing periods (5 × 2π apart), always at the same speed:

    >>> import math, numpy as np, grazing
    >>> from grazing.maps import StroboscopicMap
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> x = StroboscopicMap(m, periods=5).iterate([0.0, 0.0], 120)[-1]
    >>> imp = ImpactMap(m).iterate(x, 0.0, 4)
    >>> np.diff(imp.t).round(6).tolist() == [round(10 * math.pi, 6)] * 3, imp.speed.round(5).tolist()
    (True, [0.08977, 0.08977, 0.08977, 0.08977])
    """

    model: HybridModel
    max_periods: int = 10_000

    def iterate(self, x: Sequence[float] | np.ndarray, t: float, n: int) -> Impacts:
        """The next ``n`` impacts after the state ``x`` at time ``t`` (times, phases, speeds, states).

        ``x`` may be an impact state itself (on the stop, after its reset):
        the impacts returned are the ones that follow it.  Fewer than ``n``
        are returned if the motion stops impacting (or sticks to the stop)
        within :attr:`max_periods`.
        """
        if n < 1:
            raise InvalidParameterError(f"n must be >= 1, got {n}")
        T = self.model.period
        t_start = float(t)
        found: list[tuple[np.ndarray, ...]] = []
        count, done, block = 0, 0, 8
        while count < n and done < self.max_periods:
            sol = simulate(
                self.model, x, t0=t, periods=block, phase=2 * math.pi * (t / T % 1.0), impacts="all"
            )
            imp = sol.impacts
            after = imp.t > t_start  # an impact state given as x is not its own successor
            found.append(
                (imp.t[after], imp.phase[after], imp.speed[after], imp.state[after], imp.stop[after])
            )
            count += int(after.sum())
            done += block
            if len(sol.sticking):
                break
            x, t = sol.x_final, sol.t_final
            block = min(2 * block, 1024)
        t_all, phase, speed, state, stop = (np.concatenate(parts) for parts in zip(*found))
        state = state[:n].reshape(-1, self.model.n_states)
        return Impacts(
            t=t_all[:n],
            phase=phase[:n],
            speed=speed[:n],
            state=state,
            stop=stop[:n].astype(int),
            stop_names=self.model.stop_names,
        )
