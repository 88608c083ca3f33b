"""Orbits that are not isolated: a double multiplier 1, from a Jordan block or an eigenspace.

The impact damper with its particle at rest and clear of the walls has a
non-impacting orbit whose monodromy holds ``[[1, T], [0, 1]]`` for the particle
(a free mass: every position is periodic, a small velocity drifts): one kept
direction, so counting kept directions (the test before issue 42) called it an
isolated, stable orbit.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import grazing
from grazing.cli import main
from grazing.core.options import NOT_ISOLATED_TOL
from grazing.orbits import continue_orbit, find_orbit
from grazing.orbits.shooting import is_isolated, kept_directions, multiplier_one_multiplicity
from tests.linear_exact import six_state_model

EPS = np.finfo(float).eps


def _jordan(T: float, others: np.ndarray) -> np.ndarray:
    n = 2 + others.size
    M = np.zeros((n, n))
    M[:2, :2] = [[1.0, T], [0.0, 1.0]]
    M[2:, 2:] = np.diag(others)
    V = np.random.default_rng(0).normal(size=(n, n)) + 3 * np.eye(n)
    return V @ M @ np.linalg.inv(V)


@pytest.mark.parametrize("T", [0.5, 5.2])
def test_a_jordan_block_rounded_as_a_monodromy_is_rounded_is_still_double(T):
    M = _jordan(T, np.array([0.3, -0.5]))
    rng = np.random.default_rng(1)
    for _ in range(20):  # (8 eps |M| per entry, in a basis of condition number 10: the rounding of the
        # variational equations over a period, where a decoupled free mass makes the block; a longer T
        # splits the multipliers by more than NON_ISOLATED_TOL: sqrt(T eps |M| cond), 1.5e-6 for T = 20)
        noisy = M + 8 * EPS * np.linalg.norm(M, 2) * rng.uniform(-1, 1, M.shape)
        assert multiplier_one_multiplicity(noisy) == 2 and not is_isolated(noisy)
    assert kept_directions(M) == 1  # (what the old test counted: a Jordan block keeps one direction)


def test_a_fold_far_from_normal_is_isolated():
    # Near a grazing the monodromy is far from normal (|M| = 5e5 from a saltation matrix's 1 / v): the
    # singular values of (M - I)^2 fall far below |M|^2 eps there, which made such a fold "not isolated"
    # (the test before); its multipliers are 1, 0.888 and -0.41.
    M = np.array([[1.0, 4e5, 3e5], [0.0, 0.888, 2e5], [0.0, 0.0, -0.41]])
    a = M - np.eye(3)
    assert np.sort(np.linalg.svd(a @ a, compute_uv=False))[1] < 1e-11 * (1 + np.linalg.norm(M, 2)) ** 2
    assert multiplier_one_multiplicity(M) == 1 and is_isolated(M)


def test_a_fold_and_two_multipliers_near_one_are_isolated():
    fold = np.diag([1.0, 0.5, 0.2])
    assert multiplier_one_multiplicity(fold) == 1 and is_isolated(fold)
    near = np.diag([1.0 + 1e-4, 1.0 - 1e-4, 0.2])
    assert multiplier_one_multiplicity(near) == 0 and is_isolated(near)
    assert not is_isolated(np.diag([1.0, 1.0, 0.2]))  # (an eigenspace)


@pytest.mark.parametrize(
    ("make", "param"),
    [
        (lambda: grazing.models.impact_damper(gap=8.0, omega=1.2), "omega"),
        (lambda: six_state_model(d=20.0, Om=1.2), "Om"),
    ],
    ids=["impact-damper", "six-states"],
)
def test_the_particle_at_rest_is_a_non_isolated_orbit_never_stable(make, param):
    model = make()
    orbit = find_orbit(model)  # (from rest: the particle stays where it is)
    assert orbit.impacts == 0
    mu = np.sort_complex(orbit.multipliers)
    assert np.sum(np.abs(mu - 1.0) < 1e-6) == 2  # the double multiplier 1
    assert np.all(np.abs(orbit.multipliers[np.abs(orbit.multipliers - 1.0) > 1e-6]) < 1.0)
    assert orbit.isolated is False and orbit.stable is False
    with pytest.raises(grazing.ConvergenceError, match=r"not isolated .*Jordan block"):
        continue_orbit(model, param, 1.2, 1.3, orbit=orbit)


def test_the_cli_names_a_non_isolated_orbit_and_refuses_to_continue_it(capsys):
    argv = ["--model", "impact-damper", "--set", "gap=8"]
    assert main(["orbit", *argv, "--set", "omega=1.2", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["isolated"] is False and res["stable"] is False
    assert main(["orbit", *argv, "--set", "omega=1.2"]) == 0
    out = capsys.readouterr().out
    assert "not isolated" in out.splitlines()[0]
    notes = [line for line in out.splitlines() if "note:" in line]
    assert len(notes) == 1 and "Jordan block" in notes[0]
    code = main(["continue", *argv, "--param", "omega", "--start", "1.2", "--stop", "1.3"])
    captured = capsys.readouterr()
    assert code != 0
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and "not isolated" in err[0] and "Jordan block" in err[0], captured.err


def test_an_isolated_orbit_stays_isolated_and_stable():
    orbit = find_orbit(grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40)))
    assert orbit.isolated and orbit.stable


@pytest.mark.parametrize("largest", [0.5, 100.0])
def test_kept_directions_are_counted_relative_to_one_plus_the_norm(largest):
    """Two directions kept within ``NOT_ISOLATED_TOL (1 + |M|)`` of the identity, and not beyond it,
    whatever the size of the rest of ``M`` (a norm of 1, or 100)."""
    scale = NOT_ISOLATED_TOL * (1.0 + max(largest, 1.0))

    def matrix(offset: float) -> np.ndarray:
        m = np.diag([1.0 + offset, 1.0 + offset, largest])
        # (an orthogonal change of basis: the same singular values)
        basis = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))[0]
        return basis @ m @ basis.T

    assert kept_directions(matrix(0.9 * scale)) == 2
    assert kept_directions(matrix(1.1 * scale)) == 0
