"""The rocking block lying on its side (mode ``overturned``, field 0, no transition out) is an attractor
reached in finite time, not a neutral family: every block that overturns to one side lands on exactly
``(+-pi/2, 0)`` (the overturning resets the state to it: its saltation matrix is 0), so its multipliers
as the motion reaches it are 0 and its Lyapunov exponent ``-inf``.  Within the mode every state is at
rest (the map is the identity): a state started there by hand, off that point, stays where it is, and
that one is ``neutral`` (a family of motions).

Before: the overturned attractor was ``neutral`` with ``lyapunov +0`` (the identity map of the mode).
"""

from __future__ import annotations

import math

import numpy as np

import grazing
from grazing.attractors import find_attractors
from grazing.attractors.kinds import AttractorKind
from tests.cli.test_cli_models import run_json

SIDE = math.pi / 2


def block() -> grazing.HybridModel:
    return grazing.models.rocking_block(a=0.15)


def test_the_overturning_erases_every_perturbation():
    """The independent reason: the saltation matrix of the overturning is 0 (a constant reset into a zero
    field), so the linearised motion after it is 0, whatever came before."""
    m = block()
    for name, x in (("overturn_right", [SIDE, 0.3]), ("overturn_left", [-SIDE, -0.3])):
        assert np.array_equal(m.saltation(x, 0.7, name), np.zeros((2, 2)))


def test_the_overturned_block_is_an_attractor_reached_in_finite_time():
    m = block()
    grid = np.array([[th, om] for th in np.linspace(-0.3, 0.3, 5) for om in (-0.6, 0.6)])
    beyond = np.array([[2.0, 0.0], [-2.0, 0.5]])  # (in no corner's region: they start overturned, at rest)
    found = find_attractors(m, np.vstack([grid, beyond]), workers=1)
    side = [
        a for a in found.attractors if a.mode == "overturned" and np.allclose(np.abs(a.points[0]), [SIDE, 0])
    ]
    assert sorted(np.sign(a.points[0, 0]) for a in side) == [-1.0, 1.0]
    for a in side:
        assert a.kind is AttractorKind.PERIODIC and a.period == 1 and a.lyapunov == -math.inf, a
        assert a.count >= 2 and a.to_json()["lyapunov"] is None
    rest = [a for a in found.attractors if len(a.points) and np.abs(a.points[0, 0]) == 2.0]
    assert len(rest) == 2  # (each stays where it started: a family of rests, one per state)
    for a in rest:
        assert a.kind is AttractorKind.NEUTRAL and a.lyapunov == 0.0 and a.mode == "overturned", a


def test_the_command_line_says_so(capsys):
    argv = ["basins", "--model", "rocking-block", "--set", "a=0.15", "--x-range=-0.3,0.3",
            "--y-range=-0.6,0.6", "--num", "4,2", "--workers", "1"]  # fmt: skip
    out = run_json(argv, capsys)
    side = [a for a in out["attractors"] if a["modes"] == ["overturned"]]
    assert side and all(a["kind"] == "periodic" and a["lyapunov"] is None for a in side)
