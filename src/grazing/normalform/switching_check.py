"""The switching surface's discontinuity map against simulation: the flow through the contact, run by run.

A :class:`~grazing.normalform.switching.SwitchingMap` claims that a trajectory
grazing a switching surface without a reset is changed, on the section
``t = t*``, by ``D(x) - x = -(4/3) sqrt(2 / a) delta^(3/2) w``.  The check
(``docs/normal-form.md``, section 5) runs each start through the contact and
compares it, some time after the contact, with the free flow (the source
mode's, the surface out of reach) of the same state: that difference ``Δ`` is
what the map must predict, as the free flow of ``D(x)`` minus the free flow of
``x``, ``x`` the free flow's state on the section.  Over decades of the
penetration ``delta``, ``|Δ|`` goes as ``delta^(3/2)`` and the map's error as a
higher power (``delta^2`` in general, ``delta^(5/2)`` on a grazing orbit's
family unfolded by the guard): :func:`loglog_slope` fits them.

Used by ``tests/normalform/test_switching_zdm.py`` and the report's section on
the switching surface (:mod:`grazing.report.figswitch`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.solution import Solution
from grazing.engine.simulate import simulate
from grazing.errors import InvalidParameterError, InvalidStateError
from grazing.normalform.switching import SwitchingMap, _way_back

TIME_TOL = 1e-9
"""How close (relative to the period) a run's last sample must be to the time asked for."""

Start = tuple[HybridModel, Sequence[float] | np.ndarray, float]
"""``(model, x0, t0)``: a state ``x0`` at time ``t0 <= t*`` of ``model`` (the map's model, or the same
model at other parameter values: an unfolding), whose run is to cross the surface once and come back."""


@dataclass(frozen=True)
class FlowCheck:
    """The map's prediction against the flow through the contact, one row per start.

    Attributes
    ----------
    depth
        The penetration ``delta`` of each start as the map computes it (on the section ``t*``, in the
        start's model).
    actual
        The flow through the contact minus the free flow, at :attr:`t_end` (``n`` by ``n_states``).
    predicted
        The free flow of ``D(x)`` minus that of ``x`` at :attr:`t_end`: the map's prediction of
        :attr:`actual`.
    on_section
        The free flow's state ``x`` of each start on the section ``t*``.
    t_end
        When the runs are compared.
    """

    depth: np.ndarray
    actual: np.ndarray
    predicted: np.ndarray
    on_section: np.ndarray
    t_end: float

    @property
    def size(self) -> np.ndarray:
        """``|Δ|``: the size of the difference the contact makes."""
        return np.linalg.norm(self.actual, axis=1)

    @property
    def predicted_size(self) -> np.ndarray:
        """The size of the map's prediction of it."""
        return np.linalg.norm(self.predicted, axis=1)

    @property
    def error(self) -> np.ndarray:
        """``ε = |Δ - prediction|``: the map's error."""
        return np.linalg.norm(self.actual - self.predicted, axis=1)


def loglog_slope(xs: Sequence[float] | np.ndarray, ys: Sequence[float] | np.ndarray) -> float:
    """The slope of the least-squares line through ``(log x, log y)``: the power of ``y ~ C x^p``.

    Examples
    --------
    >>> round(loglog_slope([1e-4, 1e-3, 1e-2], [2e-6, 2 * 10**-4.5, 2e-3]), 12)
    1.5
    """
    return float(np.polyfit(np.log(np.asarray(xs, dtype=float)), np.log(np.asarray(ys, dtype=float)), 1)[0])


def state_at(model: HybridModel, x0: Sequence[float] | np.ndarray, t0: float, t1: float) -> Solution:
    """The run of ``model`` from ``x0`` at ``t0`` to ``t1`` (``t0 < t1 < t0 + period``), every switch
    recorded: a :class:`~grazing.Solution` whose ``x_final`` is the state at ``t1``.

    Raises
    ------
    InvalidParameterError
        One line: ``t1`` is not within a period after ``t0``.
    """
    T = model.period
    if not 0 < t1 - t0 < T:
        raise InvalidParameterError(f"t1 = {t1:.10g} must be within a period ({T:.6g}) after t0 = {t0:.10g}")
    sol = simulate(model, x0, t0=t0, periods=1, phase=2 * math.pi * (t1 / T % 1), impacts="all")
    if abs(sol.t_final - t1) > TIME_TOL * T:  # (the sample of that phase is the next one after t0)
        raise InvalidStateError(f"the run ended at t = {sol.t_final:.12g}, not at t1 = {t1:.12g}")
    return sol


def compare_with_flow(
    zdm: SwitchingMap, starts: Sequence[Start], free_model: HybridModel, t_end: float | None = None
) -> FlowCheck:
    """Run each start through the contact and compare it with the map's prediction at ``t_end``.

    Parameters
    ----------
    zdm
        The map (:func:`~grazing.normalform.switching_map_at`).
    starts
        ``(model, x0, t0)`` with ``t0 <= t*`` (:data:`Start`): each run must switch across the map's
        transition once and come back, before ``t_end``.
    free_model
        The map's model with the surface out of reach (its parameters moved so that the runs never
        switch): its runs are the source mode's free flow.
    t_end
        When to compare (default: a quarter period after the contact, ``t* + T/4``); after every run
        has left the target mode, within a period of every ``t0``.

    Returns
    -------
    FlowCheck
        The differences and the predictions, row by row.

    Raises
    ------
    InvalidStateError
        One line: a run does not switch across the surface and back exactly once, or a free run
        switches.

    Examples
    --------
    The soft stop of :class:`~grazing.normalform.SwitchingMap`'s example (``a = 1/2``), from states on
    the section ``t* = 0`` short of the surface moving towards it, ``h = y``, ``L_f h = -sqrt(4 a y)``
    (so ``delta = y``): the difference goes as ``y^(3/2)`` and the map's error as ``y^2``.

    >>> import sympy as sp, numpy as np, grazing
    >>> from grazing.normalform import switching_map_at
    >>> x, v, t, k, s = sp.symbols("x v t k s")
    >>> free, contact = [v, -x + sp.cos(t) / 2], [v, -x + sp.cos(t) / 2 - k * (x - s)]
    >>> m = grazing.HybridModel("soft-stop", [x, v], t, [grazing.Parameter("k", 4.0),
    ...     grazing.Parameter("s", 1.0)], period=2 * sp.pi,
    ...     modes=[grazing.Mode("free", free), grazing.Mode("contact", contact)],
    ...     surfaces=[grazing.Surface("wall", s - x, "free", "contact", sliding=False)])
    >>> zdm = switching_map_at(m, "wall_to_contact", [1.0, 0.0], 0.0)
    >>> ys = [1e-6, 1e-5, 1e-4]
    >>> starts = [(m, [1 - y, np.sqrt(2 * y)], 0.0) for y in ys]
    >>> check = compare_with_flow(zdm, starts, m.with_params(s=100.0))
    >>> round(loglog_slope(check.depth, check.size), 2), round(loglog_slope(check.depth, check.error), 1)
    (1.5, 2.0)
    """
    ts = zdm.t_graze
    t1 = ts + zdm.model.period / 4 if t_end is None else float(t_end)
    way_back = _way_back(zdm.model, zdm.transition)
    expected = [zdm.transition, way_back]
    depth, actual, predicted, section = [], [], [], []
    for model, x0, t0 in starts:
        x0 = np.asarray(x0, dtype=float)
        through = state_at(model, x0, t0, t1)
        crossed = [int(i) for i in through.switches.transition]
        if crossed != expected:
            names = [through.switches.name(i) for i in range(len(through.switches))]
            raise InvalidStateError(
                f"the run from {x0.tolist()} at t = {t0:.10g} must switch across {zdm.transition_name!r} "
                f"and back once before t = {t1:.10g}; its switches: {names}"
            )
        on_section = x0 if t0 == ts else _free(free_model, x0, t0, ts)
        free = _free(free_model, on_section, ts, t1)
        mapped = _free(free_model, zdm.zdm(on_section, model=model), ts, t1)
        depth.append(zdm.penetration(on_section, model=model))
        actual.append(through.x_final - free)
        predicted.append(mapped - free)
        section.append(on_section)
    return FlowCheck(np.array(depth), np.array(actual), np.array(predicted), np.array(section), t1)


def _free(free_model: HybridModel, x0: np.ndarray, t0: float, t1: float) -> np.ndarray:
    """The free flow's state at ``t1`` from ``x0`` at ``t0`` (a run of ``free_model``: no switch)."""
    sol = state_at(free_model, x0, t0, t1)
    if sol.switches is not None and len(sol.switches):
        raise InvalidStateError(
            f"the free model switched (at t = {float(sol.switches.t[0]):.10g}): its surface must be out "
            "of the runs' reach"
        )
    return sol.x_final
