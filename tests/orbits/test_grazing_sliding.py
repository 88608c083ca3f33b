"""A grazing-sliding on a real branch: the friction oscillator's pure slip behind a moving belt, against its
closed form.

Slipping behind the belt all the time (x' < v_b), the mass feels the constant friction +mu and the motion is
linear: the periodic orbit is x = mu + A cos(w t), A = a / (1 - w^2) (w < 1), so x' = -A w sin(w t) reaches
its largest value A w at w t = -pi/2 (mod 2 pi).  It touches the belt's speed there, tangentially, when
A w = v_b:

    a* = v_b (1 - w^2) / w,

where the force a cos(w t) - x = -mu exactly (x'' = 0), the edge of the sliding region |a cos(w t) - x| < mu
where the field behind the belt is tangent to it.  Past a*, a short stick appears inside the slip (an entry
from behind and an exit back behind): a grazing-sliding.  Undamped, the pure slip orbit's multipliers lie on
the unit circle, exp(+-2 pi i / w); w = 0.7 keeps them away from 1 (and from -1).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from grazing.models import friction_oscillator
from grazing.orbits import continue_orbit, sliding_curve
from grazing.orbits.kinds import SpecialKind
from tests.cli.test_cli_models import run_json
from tests.orbits.test_sliding_orbits import exact_orbit

VALUES = {"a": 0.05, "omega": 0.7, "mu": 0.5, "v_belt": 0.2}
STICK = ("belt_slide_from_slip_behind", "belt_exit_to_slip_behind")


def grazing_amplitude(omega: float, v_belt: float) -> float:
    """The closed form a* of the module's docstring (w < 1)."""
    return v_belt * (1.0 - omega * omega) / omega


def pure_slip(p: dict) -> np.ndarray:
    """The pure slip orbit's state at t = 0: (mu + A, 0)."""
    return np.array([p["mu"] + p["a"] / (1.0 - p["omega"] ** 2), 0.0])


@pytest.fixture(scope="module")
def branch():
    m = friction_oscillator(**VALUES)
    return continue_orbit(m, "a", 0.05, 0.3, x0=pure_slip(VALUES), period=1, t0=0.0, mode="slip_behind")


def test_the_pure_slip_orbit_grazes_the_belt_at_the_closed_form(branch):
    exact = grazing_amplitude(VALUES["omega"], VALUES["v_belt"])
    [sp] = branch.special
    assert sp.kind is SpecialKind.GRAZING_SLIDING and sp.kind == "grazing-sliding"
    assert "ended at a grazing-sliding bifurcation" in branch.status and "\n" not in branch.status
    lo, hi = sp.interval
    assert hi - lo <= 2.1e-10 and lo <= exact <= hi, (lo, exact, hi)
    assert abs(sp.param - exact) < 1e-10 and sp.precision <= 1.1e-10
    # every orbit before it is the exact pure slip, without a switch
    for o in branch.orbits:
        p = dict(o.model.params)
        A, w = p["a"] / (1.0 - p["omega"] ** 2), p["omega"]
        t = o.t0
        assert o.switch_signature == ((),) and o.mode == "slip_behind"
        assert np.abs(o.state - [p["mu"] + A * math.cos(w * t), -A * w * math.sin(w * t)]).max() < 1e-10
        assert p["a"] <= hi
    assert len(branch) >= 3


def test_switched_past_the_grazing_sliding_onto_one_stick_a_period():
    """Past it the orbit sticks once a period (entered from behind, left back behind), for a time that grows
    from zero."""
    m = friction_oscillator(**VALUES)
    exact = grazing_amplitude(VALUES["omega"], VALUES["v_belt"])
    start = {"x0": pure_slip(VALUES), "period": 1, "t0": 0.0, "mode": "slip_behind"}
    br = continue_orbit(m, "a", 0.05, exact + 0.02, **start, switch=True)
    assert br.special[0].kind is SpecialKind.GRAZING_SLIDING and br.special[0].switched
    after = [o for o, s in zip(br.orbits, br.segments) if s == 1]
    assert len(after) >= 3
    sticks = []
    for o in after:
        assert o.switch_signature == (STICK,) and o.model.params["a"] > exact
        te, tx = o.switch_times
        sticks.append(tx - te)
    assert all(d > 0 for d in sticks) and sticks == sorted(sticks)  # (longer as a grows)
    # each the exact stick-slip orbit (the first, with its stick of ~1e-4, too short for the reference's
    # sampled search of the return to the belt)
    for o in after[1:][:: max(1, len(after) // 3)]:
        q = dict(o.model.params)
        x, J, events, res = exact_orbit(q, o.state, m.mode_names.index(o.mode), o.t0)
        assert res < 1e-13 and np.abs(o.state - x).max() < 1e-10
        assert np.abs(o.monodromy - J).max() < 1e-8 * max(1.0, np.abs(J).max())
        assert [k for _, k in events] == ["stick", "slip"]
        # (the entry is slow near the grazing, x'' ~ 0.1 there: a time is a state's error over that)
        assert np.abs(o.switch_times - [t for t, _ in events]).max() < 1e-8


def test_the_grazing_sliding_curve_in_a_and_omega_is_the_closed_form(branch):
    curve = sliding_curve(branch, "omega", 0.6, steps=4)
    assert curve.kind is SpecialKind.GRAZING_SLIDING and curve.status == "reached omega = 0.6"
    assert [w for _, w in curve.values] == pytest.approx([0.7, 0.675, 0.65, 0.625, 0.6])
    for (a, w), (lo, hi) in zip(curve.values, curve.intervals):
        exact = grazing_amplitude(w, VALUES["v_belt"])
        assert abs(a - exact) < 1e-10 and lo <= exact + 1e-10 and exact - 1e-10 <= hi, (w, a - exact)
    assert curve.values[-1][0] - curve.values[0][0] > 0.05  # (it moves: not the start repeated)


def test_continue_on_the_command_line_reports_the_grazing_sliding(capsys):
    set_ = [f"--set={k}={v}" for k, v in VALUES.items() if k != "a"]
    x0 = ",".join(f"{v:.6f}" for v in pure_slip(VALUES))
    argv = ["continue", "--model", "friction-oscillator", *set_, "--param", "a", "--start", "0.05",
            "--stop", "0.3", "--period", "1", "--initial", x0, "--mode", "slip_behind"]  # fmt: skip
    out = run_json(argv, capsys)
    [special] = out["special"]
    assert special["kind"] == "grazing-sliding"
    assert abs(special["value"] - grazing_amplitude(VALUES["omega"], VALUES["v_belt"])) < 1e-10


@pytest.mark.parametrize(
    ("omega", "v_belt", "kind"),
    [(0.45, 0.0, SpecialKind.GRAZING_SLIDING), (2.0, 0.2, SpecialKind.CROSSING_SLIDING)],
)
def test_where_the_non_stop_orbit_first_sticks_is_named_as_the_stick_margin_says(omega, v_belt, kind):
    """Up in mu from weak friction the non-stop orbit first sticks by a grazing-sliding at low omega (a
    slip touches the belt's speed inside it) and by a crossing-sliding at high omega: the name and the
    place as :mod:`grazing.report.den_hartog` finds them from the orbits alone, without switches (the
    stick margin's change of sign by Brent's method, and whether that margin passes through zero or
    jumps)."""
    from grazing.report import den_hartog as dh

    br = continue_orbit(friction_oscillator(omega=omega, mu=0.05, v_belt=v_belt), "mu", 0.05, 0.95)
    sp = br.special[0]
    exact = dh.computed_boundary(omega, v_belt=v_belt)
    assert sp.kind is kind and str(kind) == dh.transition_kind(omega, exact, v_belt)
    assert abs(sp.param - exact) < 1e-10, sp.param - exact
    assert sorted(sp.orbit.switch_signature[0]) == ["belt_to_slip_ahead", "belt_to_slip_behind"]


def test_the_grazing_sliding_curve_with_the_belt_at_rest_is_on_the_stick_margins_boundary():
    """Both slips of the symmetric non-stop orbit graze at once; the curve is bracketed again from a guess
    already past the change (its first step, without a slope yet), and reaches omega = 0.4 on the
    boundary that the stick margin gives."""
    from grazing.report import den_hartog as dh

    br = continue_orbit(friction_oscillator(omega=0.45, mu=0.05, v_belt=0.0), "mu", 0.05, 0.95)
    curve = sliding_curve(br, "omega", 0.4, steps=2)
    assert curve.kind is SpecialKind.GRAZING_SLIDING and curve.status == "reached omega = 0.4"
    mu, w = curve.values[-1]
    assert w == 0.4 and abs(mu - dh.computed_boundary(0.4)) < 1e-10
    assert curve.values[0][0] - mu > 0.05
