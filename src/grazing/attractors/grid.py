"""Grids of initial states: a 2-D slice of state space at a forcing phase, the other states fixed.

:func:`state_grid` checks what a user asks for (the two states varied, their
ranges and counts, the values of the other states) and returns a
:class:`StateGrid`; :meth:`StateGrid.states_array` lists its initial states
row by row (along ``y``), and :func:`beyond_stops` tells which of them lie
beyond a stop (labelled ``invalid``, never run).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from grazing.core.cells import box_cell
from grazing.core.model import ON_STOP_TOL, HybridModel
from grazing.errors import InvalidParameterError


@dataclass(frozen=True)
class StateGrid:
    """Initial states on a grid in two state components, the others fixed, at a forcing phase.

    Attributes
    ----------
    states
        The indices of the two state components varied (``x`` along the first, ``y`` the second).
    x, y
        Their values (``num[0]`` and ``num[1]`` of them).
    base
        The full initial state the grid varies (the fixed values of the other components).
    phase
        The forcing phase of the initial states, in radians: they are states at
        time ``phase / 2 pi`` forcing periods, where they are also sampled.

    Examples
    --------
    >>> import grazing
    >>> g = state_grid(grazing.models.bouncing_ball(), (0.0, 1.0), (-1.0, 1.0), (3, 2))
    >>> g.shape, g.states_array()[:4].tolist()
    ((2, 3), [[0.0, -1.0], [0.5, -1.0], [1.0, -1.0], [0.0, 1.0]])
    """

    states: tuple[int, int]
    x: np.ndarray
    y: np.ndarray
    base: tuple[float, ...]
    phase: float = 0.0

    @property
    def shape(self) -> tuple[int, int]:
        """``(len(y), len(x))``: the labels' shape, rows along ``y``."""
        return (self.y.size, self.x.size)

    @property
    def size(self) -> int:
        return self.x.size * self.y.size

    def states_array(self) -> np.ndarray:
        """The initial states, one row each, ``x`` fastest (row ``j * len(x) + i`` is ``(x[i], y[j])``)."""
        out = np.tile(np.asarray(self.base, dtype=float), (self.size, 1))
        xi, yi = np.meshgrid(self.x, self.y)
        out[:, self.states[0]] = xi.ravel()
        out[:, self.states[1]] = yi.ravel()
        return out


def state_index(model: HybridModel, name: str | int, what: str = "state") -> int:
    """The index of a state given by its index or name; one clear error for any other.

    Examples
    --------
    >>> import grazing
    >>> m = grazing.models.impact_damper()
    >>> state_index(m, "x2"), state_index(m, 1), state_index(m, "3")
    (2, 1, 3)
    """
    n = model.n_states
    names = model.state_names
    text = str(name).strip()
    if text in names:
        return names.index(text)
    try:
        k = int(text)
    except ValueError:
        raise InvalidParameterError(
            f"unknown {what} {name!r} for model {model.name!r} (states: {', '.join(names)}, or 0..{n - 1})"
        ) from None
    if not 0 <= k < n:
        raise InvalidParameterError(
            f"{what} index {k} is out of range: model {model.name!r} has {n} states "
            f"({', '.join(f'{i} {s}' for i, s in enumerate(names))})"
        )
    return k


def state_grid(
    model: HybridModel,
    x_range: Sequence[float],
    y_range: Sequence[float],
    num: Sequence[int],
    *,
    states: Sequence[str | int] = (0, 1),
    fixed: Mapping[str | int, float] | None = None,
    phase: float = 0.0,
) -> StateGrid:
    """The grid of initial states ``num[0] x num[1]`` over ``x_range`` x ``y_range`` in ``states``.

    Parameters
    ----------
    model
        The model (its states give the names and the count).
    x_range, y_range
        ``(lo, hi)`` of the two states varied (``lo <= hi``; equal only with one value).
    num
        Values along each (at least one each).
    states
        The two state components varied, by index or name (distinct).
    fixed
        Values of other state components (by index or name); the rest are 0.
    phase
        Forcing phase of the initial states (radians).

    Returns
    -------
    StateGrid
        The grid: its values along each state varied, and every initial
        state (:meth:`StateGrid.states_array`, row by row, ``x`` fastest).

    Raises
    ------
    InvalidParameterError
        An empty grid, a state index out of range or unknown, a fixed value of
        a varied or unknown state, a range that is not finite or is reversed.

    Examples
    --------
    >>> import grazing
    >>> grid = state_grid(grazing.models.bouncing_ball(), (-1.0, 6.0), (-4.0, 4.0), (3, 2))
    >>> grid.x.tolist(), grid.y.tolist()
    ([-1.0, 2.5, 6.0], [-4.0, 4.0])
    >>> grid.states_array().tolist()
    [[-1.0, -4.0], [2.5, -4.0], [6.0, -4.0], [-1.0, 4.0], [2.5, 4.0], [6.0, 4.0]]
    """
    if model.n_states < 2:
        raise InvalidParameterError(f"model {model.name!r} has one state: a grid needs two")
    if len(states) != 2:
        raise InvalidParameterError(f"states must name two state components, got {len(states)}")
    i, j = (state_index(model, s) for s in states)
    if i == j:
        raise InvalidParameterError(
            f"the two states of the grid must differ, got {model.state_names[i]} twice"
        )
    if len(num) != 2:
        raise InvalidParameterError(f"num must be two counts, got {len(num)}")
    counts = []
    for k in num:
        if isinstance(k, bool) or int(k) != k or int(k) < 1:
            raise InvalidParameterError(
                f"the grid needs at least one value along each state, got {tuple(num)}"
            )
        counts.append(int(k))
    axes = []
    for rng, n, name in (
        (x_range, counts[0], model.state_names[i]),
        (y_range, counts[1], model.state_names[j]),
    ):
        lo, hi = (float(v) for v in rng)
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise InvalidParameterError(f"the range of {name} must be finite, got {lo:g}, {hi:g}")
        if hi < lo or (hi == lo and n > 1):
            raise InvalidParameterError(
                f"the range of {name} must have LO < HI (LO = HI with one value), got {lo:g}, {hi:g}"
            )
        axes.append(np.linspace(lo, hi, n))
    base = np.zeros(model.n_states)
    for key, value in (fixed or {}).items():
        c = state_index(model, key, "fixed state")
        if c in (i, j):
            raise InvalidParameterError(
                f"state {model.state_names[c]} is varied by the grid: it cannot be fixed"
            )
        v = float(value)
        if not math.isfinite(v):
            raise InvalidParameterError(
                f"the fixed value of {model.state_names[c]} must be finite, got {value!r}"
            )
        base[c] = v
    ph = float(phase)
    if not math.isfinite(ph):
        raise InvalidParameterError(f"phase must be finite, got {phase!r}")
    return StateGrid((i, j), axes[0], axes[1], tuple(float(v) for v in base), ph)


def start_time(model: HybridModel, phase: float) -> float:
    """The time of initial states at forcing phase ``phase`` (as the sweeps' start of a point there)."""
    return (phase / (2 * math.pi)) % 1.0 * float(model.period)


def beyond_stops(model: HybridModel, states: np.ndarray, t: float) -> np.ndarray:
    """Which rows of ``states`` lie beyond a stop at time ``t`` (as :meth:`HybridModel.check_state` decides).

    A state on a stop to rounding (its guard above ``-ON_STOP_TOL * max(1, |x|)``) is allowed.

    Examples
    --------
    >>> import grazing
    >>> ball = grazing.models.bouncing_ball(amplitude=0.0)
    >>> beyond_stops(ball, np.array([[1.0, 0.0], [-0.5, 0.0], [0.0, -1.0]]), 0.0).tolist()
    [False, True, False]
    """
    x = np.asarray(states, dtype=float)
    out = np.zeros(x.shape[0], dtype=bool)
    if x.size == 0:
        return out
    params = list(model.param_vector)
    scale = np.maximum(1.0, np.max(np.abs(x), axis=1))
    columns = [x[:, c] for c in range(x.shape[1])]
    for stop in range(model.n_stops):
        h = np.broadcast_to(
            np.asarray(model.numeric("h", stop)(columns, float(t), params), dtype=float), out.shape
        )
        out |= h < -ON_STOP_TOL * scale
    return out


def default_cell(states: np.ndarray) -> np.ndarray:
    """The cell size per state component for initial states ``states``: the extent of their box over
    :data:`~grazing.core.options.CELLS` (where the box is flat, the largest of the others).

    Examples
    --------
    >>> default_cell(np.array([[0.0, -1.0, 5.0], [1.0, 1.0, 5.0]])) * 64
    array([1., 2., 2.])
    """
    from grazing.core.options import CELLS

    return box_cell(states, CELLS)


def as_states(model: HybridModel, states: Any) -> np.ndarray:
    """An array of initial states, one row each, with the model's number of components (finite)."""
    x = np.asarray(states, dtype=float)
    if x.ndim != 2 or x.shape[1] != model.n_states:
        raise InvalidParameterError(
            f"initial states must be an array of rows of {model.n_states} numbers, got shape {x.shape}"
        )
    if x.shape[0] == 0:
        raise InvalidParameterError("no initial states: the grid is empty")
    if not np.all(np.isfinite(x)):
        raise InvalidParameterError("initial states must be finite numbers")
    return x
