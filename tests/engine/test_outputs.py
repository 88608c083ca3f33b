"""A run's output arrays (:mod:`grazing.engine.outputs`): room guessed, a run made again only when short."""

from __future__ import annotations

import math

import numpy as np

import grazing
from grazing.engine import interrupts, native, outputs
from grazing.engine.records import Config

BLANK = Config(*[0] * len(Config._fields))


def test_a_trajectory_has_room_for_all_its_regular_points() -> None:
    """The points every traj_dt are known in advance, however many: only the ones at impacts are guessed."""
    cfg = BLANK._replace(n_samples=100, n_keep=100, T=2.0, traj_dt=2.0 / 50_000)
    rows = outputs.TableRows.guess(cfg)
    assert rows.trajectory >= 100 * 50_000 + 1 > outputs.MAX_GUESSED_ROWS
    assert rows.impacts == 0  # (none recorded)


def test_the_guess_follows_the_impacts_a_run_needed() -> None:
    cfg = BLANK._replace(n_samples=1000, n_keep=1000, record_impacts=2)
    need = outputs.TableRows(impacts=50_000, sticking=10, trajectory=0)
    rate = outputs.impacts_per_period(need, cfg)
    assert rate == 50.0
    assert outputs.TableRows.guess(cfg, rate).fit(need)
    assert outputs.impacts_per_period(outputs.TableRows(0, 0, 0), cfg) == outputs.IMPACTS_PER_PERIOD


def test_a_run_is_made_again_only_when_its_tables_were_short() -> None:
    """The ball from rest, every impact recorded: tables of one row need a second run, with exactly
    the rows the first one counted; then tables of that size need none."""
    from grazing.engine.runner import Runner

    model = grazing.models.bouncing_ball(amplitude=1.2)
    r = Runner(model, np.array([0.5, 0.0]))
    cfg = Config(
        100_000, 30, r.ks, float(r.ss), 30, False, r.T / 10, False, 2, False, False, *r._static,
        interrupts.SIGINTS, int(interrupts.SIGINTS[0]),  # (the count so far: earlier tests send SIGINTs)
    )  # fmt: skip
    made = []

    def call(out):
        made.append(outputs.TableRows(*(len(t) for t in (out.impacts, out.sticking, out.trajectory))))
        native.load_integrate()((r.x, r.V, r.k, r.s, r.mode, r.vf), r.pv, cfg, r.kern.table, out)

    result, need = outputs.run(call, 2, 2, model.n_stops, cfg, outputs.TableRows(1, 1, 1))
    assert made == [outputs.TableRows(1, 1, 1), need] and need.impacts > 1 and need.trajectory > 1
    assert len(result.impacts) == need.impacts and len(result.trajectory) == need.trajectory
    made.clear()
    again, need_again = outputs.run(call, 2, 2, model.n_stops, cfg, need)
    assert made == [need] and need_again == need
    assert all(np.array_equal(a, b) for a, b in zip(result, again, strict=True) if isinstance(a, np.ndarray))
    assert math.isclose(result.s, again.s)


def test_the_totals_are_read_by_the_names_the_driver_writes() -> None:
    from grazing.engine.records import RUN_TOTALS

    assert outputs.Totals._fields == RUN_TOTALS.names
