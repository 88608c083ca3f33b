"""Attractors of a model with modes are told apart by the mode at each sample, not by the samples alone.

The model: a resonantly forced oscillator ``q'' + mu q' + q = kappa cos t`` whose periodic orbit is the
circle ``q = R sin t, w = R cos t`` of radius ``R = kappa / mu`` (at resonance the response is a quarter
period behind the forcing).  Four modes ``ann -> bo -> cy -> dee -> ann`` switch without a reset when
``q`` rises through ``ell`` (ann, cy) or falls through ``-ell`` (bo, dee); each adds its own damping
``k nu (q^2 + w^2 - R^2) w`` (k = 0, 1, 2, 3), which is zero on the circle: the circle is an orbit of
every mode, and its sample at phase 0 is ``(0, R)`` in each.

- ``R = 0.5 < ell``: the orbit never switches: four attractors with the same samples, one per mode (a
  state of the band ``|q| < ell`` belongs to two modes: the switch is hysteretic).
- ``R = 2 > ell``: each period ``q`` rises through ``ell`` and then falls through ``-ell``: ann -> bo ->
  cy, then cy -> dee -> ann.  The samples repeat every period, the modes every second period: one
  attractor of period 2, its modes alternating ``ann, cy``.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp

import grazing
from grazing import HybridModel, Mode, Parameter, Transition
from grazing.attractors import basins, continue_attractors, find_attractors
from grazing.attractors.basins import start_modes

q, w, t = sp.symbols("q w t")
mu, kappa, nu, ell = sp.symbols("mu kappa nu ell")


def _field(k: int) -> list:
    return [w, -q - mu * w + kappa * sp.cos(t) - k * nu * (q**2 + w**2 - (kappa / mu) ** 2) * w]


QUAD = HybridModel(
    "quadcount",
    [q, w],
    t,
    [
        Parameter("mu", 0.1, lower=0),
        Parameter("kappa", 0.05),
        Parameter("nu", 0.3, lower=0),
        Parameter("ell", 1.0, lower=0, lower_open=True),
    ],
    modes=[Mode("ann", _field(0)), Mode("bo", _field(1)), Mode("cy", _field(2)), Mode("dee", _field(3))],
    transitions=[
        Transition("rise", "ann", "bo", ell - q),
        Transition("fall", "bo", "cy", q + ell),
        Transition("climb", "cy", "dee", ell - q),
        Transition("drop", "dee", "ann", q + ell),
    ],
    period=2 * sp.pi,
)
NAMES = ("ann", "bo", "cy", "dee")
SMALL, LARGE = QUAD, QUAD.with_params(kappa=0.2)  # (R = 0.5 and R = 2)


def test_one_state_in_four_modes_is_on_four_attractors():
    """The circle's sample started in each mode stays in it: four attractors, the same points."""
    found = find_attractors(SMALL, [[0.0, 0.5]] * 4, modes=list(NAMES), workers=1)
    assert found.labels.tolist() == [1, 2, 3, 4]
    for a, name in zip(found.attractors, NAMES):
        assert (a.kind, a.period, a.modes) == ("periodic", 1, (name,))
        np.testing.assert_allclose(a.points, [[0.0, 0.5]], atol=1e-6)
    assert json.loads(json.dumps(found.attractors[0].to_json()))["modes"] == ["ann"]


def test_a_grid_is_split_by_the_mode_each_state_ends_in():
    """Each initial state's label is the mode its own run (simulate, from the mode it lies in) ends in."""
    grid = grazing.attractors.state_grid(SMALL, (-3.0, 3.0), (-3.0, 3.0), (7, 7))
    x = grid.states_array()
    ds = basins(SMALL, (-3.0, 3.0), (-3.0, 3.0), (7, 7), workers=1)
    ended = []
    for x0, k in zip(x, start_modes(SMALL, x, 0.0)):
        sol = grazing.simulate(SMALL, x0, transient=300, periods=2, mode=NAMES[k])
        assert np.allclose(sol.samples[-1], [0.0, 0.5], atol=1e-6)  # (all on the circle)
        ended.append(NAMES[int(sol.modes[-1])])
    assert len(set(ended)) >= 2  # (the grid reaches several modes: else nothing would be merged)
    labels = ds.label.values.ravel().tolist()
    assert {(k, m) for k, m in zip(labels, ended)} == {(labels[ended.index(m)], m) for m in set(ended)}
    assert len(set(labels)) == len(set(ended))  # (one attractor per mode ended in, not one for all)
    kinds = dict(zip(ds.attractor.values.tolist(), ds.kind.values.tolist()))
    modes = dict(zip(ds.attractor.values.tolist(), ds.modes.values[:, 0].tolist()))
    assert {kinds[k] for k in labels} == {"periodic"}
    assert [modes[k] for k in labels] == ended


def test_a_store_read_back_keeps_each_end_states_mode(tmp_path):
    """Run again on its Zarr store (every chunk read back, none computed), the grid is split as before: the
    store keeps the mode of each point's last sample, not only of each chunk's last point."""
    args = (SMALL, (-3.0, 3.0), (-3.0, 3.0), (7, 7))
    fresh = basins(*args, workers=1)
    path = tmp_path / "quad.zarr"
    first = basins(*args, workers=1, store=path, chunk_size=10)
    again = basins(*args, workers=1, store=path, chunk_size=10)
    assert len(set(fresh.label.values.ravel().tolist())) >= 2
    for ds in (first, again):
        assert ds.label.values.tolist() == fresh.label.values.tolist()
        assert ds.modes.values.tolist() == fresh.modes.values.tolist()


def test_an_orbit_whose_modes_repeat_every_second_period_is_one_attractor_of_period_2():
    """Two runs of the large circle a period apart (the same state, in ann and in cy) end on one
    attractor, whose period is that of its states and modes together."""
    found = find_attractors(LARGE, [[0.0, 2.0], [0.0, 2.0]], modes=["ann", "cy"], workers=1)
    assert found.labels.tolist() == [1, 1]
    (a,) = found.attractors
    assert (a.kind, a.period, sorted(a.modes)) == ("periodic", 2, ["ann", "cy"])
    np.testing.assert_allclose(a.points, [[0.0, 2.0], [0.0, 2.0]], atol=1e-6)
    sol = grazing.simulate(LARGE, [0.0, 2.0], transient=0, periods=4, mode="ann")
    assert [NAMES[k] for k in sol.modes] == ["cy", "ann", "cy", "ann"]  # (the dynamics, independently)


def test_continuation_follows_each_mode_as_itself():
    """Along kappa (the circle grows), each mode's orbit is followed as itself: its seeds start in its
    mode, and it is matched to the orbit of the same mode (the same points in another mode are far)."""
    ds = continue_attractors(SMALL, "kappa", [0.05, 0.055], (-3.0, 3.0), (-3.0, 3.0), (7, 7), workers=1)
    assert len(set(ds.modes.values[:, :, 0][ds.present.values].tolist()) - {""}) >= 2
    for j in range(ds.attractor.size):
        here = ds.present.values[:, j]
        assert here.all()  # (each found at both values: no orbit lost, none counted twice)
        assert len(set(ds.modes.values[here, j, 0].tolist())) == 1
        np.testing.assert_allclose(ds.points.values[:, j, 0, 1], [0.5, 0.55], atol=1e-6)  # (w = R)


def test_bad_modes():
    with pytest.raises(grazing.errors.InvalidParameterError, match="unknown mode 'eve'"):
        find_attractors(SMALL, [[0.0, 0.5]], modes=["eve"], workers=1)
    with pytest.raises(grazing.errors.InvalidParameterError, match="one mode per initial state"):
        find_attractors(SMALL, [[0.0, 0.5]], modes=["ann", "bo"], workers=1)
    with pytest.raises(grazing.errors.InvalidParameterError, match="start modes need a model with modes"):
        find_attractors(grazing.models.bouncing_ball(), [[1.0, 0.0]], modes=["free"], workers=1)
    found = find_attractors(SMALL, [[2.0, 0.0], [2.0, 0.0]], modes=["ann", "bo"], workers=1)
    assert found.labels.tolist()[0] == 0  # (q = 2 is beyond ann's switch at q = 1: invalid, not run)
    assert found.labels.tolist()[1] != 0


def test_matching_and_seeding_go_by_mode():
    """Two orbits with the same points in two modes are matched each to its own mode, whatever their
    order (nearest first would pair them as listed), and seeds start in the mode of their point."""
    from grazing.attractors.classify import Attractor
    from grazing.attractors.continuation import _start_modes, match

    def orbit(i, mode):
        return Attractor(id=i, kind="periodic", period=1, impacts_per_period=0.0, lyapunov=-0.1,
                         points=np.array([[0.0, 0.5]]), modes=(mode,))  # fmt: skip

    assert match([orbit(1, "ann"), orbit(2, "bo")], [orbit(1, "bo"), orbit(2, "ann")], np.ones(2)) == {
        1: 2,
        2: 1,
    }
    states = np.array([[0.0, 0.5]] * 3)  # (in the band: ann's and bo's regions; the grid's start in ann)
    assert _start_modes(SMALL, states, ["bo", ""], 0.0) == [0, 1, 0]
    assert _start_modes(grazing.models.bouncing_ball(), states, ["free"] * 3, 0.0) is None
    rubbing = grazing.models.friction_oscillator()  # (no run starts sliding: the seed starts where it lies)
    there = _start_modes(rubbing, np.zeros((2, 2)), [], 0.0)
    assert _start_modes(rubbing, np.zeros((2, 2)), ["sliding on 'belt'", "slip_ahead"], 0.0) == [there[0], 1]
