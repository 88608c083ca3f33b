"""A run's output arrays: allocated by the caller, written by the driver, read as a :class:`Result`.

The compiled integrator (:func:`grazing.engine.driver.loop.integrate`) writes
into a :class:`~grazing.engine.records.RunOutput` whose arrays the caller
allocates (:func:`allocate`).  Its tables (impacts, sticking intervals,
trajectory points) have as many rows as the caller guesses
(:class:`TableRows`, from the rows per period seen before); a run that
needs more counts them all the same, and :func:`run` runs it again with
exactly that many rows (the run is the same, bit for bit).

Examples
--------
>>> from grazing.engine.records import Config
>>> settings = Config(*[0] * len(Config._fields))._replace(n_samples=10, n_keep=10, record_impacts=1)
>>> rows = TableRows.guess(settings)
>>> rows.impacts, rows.sticking, rows.trajectory
(56, 14, 0)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from grazing.core.solution import Status
from grazing.engine.records import RUN_TOTALS, Config, Result, RunOutput

IMPACTS_PER_PERIOD = 4.0
"""The impacts per recorded period a first run makes room for (then: what the runs before needed)."""

MAX_GUESSED_ROWS = 1 << 22
"""At most this many rows of guessed impacts or sticking intervals per table (an array not written is
not in memory: numpy's ``empty`` leaves its pages to the first write)."""


def _recorded_periods(cfg: Config) -> int:
    """The periods whose impacts a run with settings ``cfg`` records (none, the kept ones, all)."""
    return (0, cfg.n_keep, cfg.n_samples)[cfg.record_impacts]


class TableRows(NamedTuple):
    """Rows of the tables of a :class:`~grazing.engine.records.RunOutput`."""

    impacts: int
    sticking: int
    trajectory: int
    switches: int = 0  # (switches of a model with modes: as many as impacts are guessed)

    @classmethod
    def guess(cls, cfg: Config, impacts_per_period: float = IMPACTS_PER_PERIOD) -> TableRows:
        """Rows for a run with settings ``cfg``, at ``impacts_per_period`` impacts per recorded period."""
        span = _recorded_periods(cfg)
        impacts = min(16 + math.ceil(impacts_per_period * span), MAX_GUESSED_ROWS) if span else 0
        sticking = min(4 + math.ceil(impacts_per_period * cfg.n_keep / 4), MAX_GUESSED_ROWS)
        trajectory = 0
        if cfg.traj_dt > 0.0:  # a point per traj_dt (known), two per impact and one per end of sticking
            around = min(math.ceil(impacts_per_period * cfg.n_keep * 2) + sticking, MAX_GUESSED_ROWS)
            trajectory = 8 + math.ceil(cfg.n_keep * cfg.T / cfg.traj_dt) + around
        return cls(impacts, sticking, trajectory, impacts)

    def fit(self, needed: TableRows) -> bool:
        """Whether tables of these rows hold ``needed`` rows."""
        return (
            self.impacts >= needed.impacts
            and self.sticking >= needed.sticking
            and self.trajectory >= needed.trajectory
            and self.switches >= needed.switches
        )


def allocate(nx: int, ncol: int, nstops: int, n_keep: int, rows: TableRows) -> RunOutput:
    """A run's output arrays: ``nx`` states, ``ncol`` columns of V, ``n_keep`` samples, ``rows``."""
    return RunOutput(
        totals=np.zeros(1, dtype=RUN_TOTALS), x=np.empty(nx), V=np.empty((nx, ncol)),
        samples=np.empty((n_keep, nx)),
        impacts=np.empty((rows.impacts, 3 + nx)), sticking=np.empty((rows.sticking, 2)),
        trajectory=np.empty((rows.trajectory, 1 + nx)), log_sums=np.empty(nx),
        guard_min=np.empty((nstops, 2 * (2 + nx))), switches=np.empty((rows.switches, 2 + nx)),
        sample_modes=np.empty(n_keep, dtype=np.int64),
    )  # fmt: skip


class Totals(NamedTuple):
    """The single values of a run (:data:`~grazing.engine.records.RUN_TOTALS`), read as Python values."""

    status: int
    k: int
    s: float
    mode: int
    vf: int
    steps: int
    n_impacts: int
    samples_kept: int
    impact_rows: int
    sticking_rows: int
    trajectory_rows: int
    lyap_span: float
    jacobian_valid: bool
    switch_rows: int
    vf_span: int

    @classmethod
    def of(cls, out: RunOutput) -> Totals:
        """The totals ``out`` holds."""
        return cls._make(out.totals[0].item())

    @property
    def rows(self) -> TableRows:
        """The rows the run needed in each table."""
        return TableRows(self.impact_rows, self.sticking_rows, self.trajectory_rows, self.switch_rows)


def _rows(table: np.ndarray, count: int) -> np.ndarray:
    """The first ``count`` rows of ``table``: the array itself if that is all of it, else a copy."""
    return table if count == table.shape[0] else table[:count].copy()


def result(out: RunOutput, t: Totals) -> Result:
    """The :class:`~grazing.engine.records.Result` of a run written into ``out`` (whose tables hold it)."""
    return Result(
        status=t.status, x=out.x, V=out.V, k=t.k, s=t.s, mode=t.mode, vf=t.vf, steps=t.steps,
        n_impacts=t.n_impacts,
        samples=_rows(out.samples, t.samples_kept), impacts=_rows(out.impacts, t.impact_rows),
        sticking=_rows(out.sticking, t.sticking_rows), trajectory=_rows(out.trajectory, t.trajectory_rows),
        log_sums=out.log_sums, lyap_span=t.lyap_span, guard_min=out.guard_min,
        jacobian_valid=t.jacobian_valid, switches=_rows(out.switches, t.switch_rows), vf_span=t.vf_span,
        sample_modes=_rows(out.sample_modes, t.samples_kept),
    )  # fmt: skip


def run(
    call: Callable[[RunOutput], None], nx: int, ncol: int, nstops: int, cfg: Config, rows: TableRows
) -> tuple[Result, TableRows]:
    """``call(out)`` with outputs of ``rows`` (a run with settings ``cfg``); again if it needs more rows.

    Returns the run's result and the rows it needed.  A run that failed
    (its status is not OK) is not run again: its tables hold the rows that fit.
    """
    out = allocate(nx, ncol, nstops, cfg.n_keep, rows)
    call(out)
    totals = Totals.of(out)
    if totals.status == Status.OK and not rows.fit(totals.rows):
        out = allocate(nx, ncol, nstops, cfg.n_keep, totals.rows)
        call(out)
        totals = Totals.of(out)
    return result(out, totals), totals.rows


def impacts_per_period(need: TableRows, cfg: Config) -> float:
    """The impacts per recorded period of a run with settings ``cfg`` that needed ``need`` rows.

    At least :data:`IMPACTS_PER_PERIOD`; sticking intervals count as a quarter of that.
    """
    span = _recorded_periods(cfg)
    return max(
        IMPACTS_PER_PERIOD,
        max(need.impacts, need.switches) / span if span else 0.0,
        need.sticking * 4 / max(cfg.n_keep, 1),
    )
