"""Models with modes: Mode, Transition, Surface, their symbolic checks and fields."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import grazing
from grazing import (
    HybridModel,
    InvalidParameterError,
    InvalidStateError,
    Mode,
    Parameter,
    Stop,
    Surface,
    Transition,
)

x, v, t = sp.symbols("x v t")
zeta, a, w, gap, k, c = sp.symbols("zeta a omega gap k c")
PARAMS = [
    Parameter("zeta", 0.05), Parameter("a", 1.0), Parameter("omega", 1.2, lower=0, lower_open=True),
    Parameter("gap", 0.5), Parameter("k", 4.0), Parameter("c", 0.3),
]  # fmt: skip
FREE = [v, -2 * zeta * v - x + a * sp.cos(w * t)]
CONTACT = [v, -2 * zeta * v - x + a * sp.cos(w * t) - k * (x - gap) - c * v]


def soft(**kw):
    """The soft-impact oscillator with a contact damper (two modes, two transitions)."""
    args = dict(
        modes=[Mode("free", FREE), Mode("contact", CONTACT)],
        transitions=[
            Transition("touch", "free", "contact", gap - x),
            Transition("leave", "contact", "free", x - gap),
        ],
        period=2 * sp.pi / w,
    )
    args.update(kw)
    return HybridModel("soft", [x, v], t, PARAMS, **args)


def test_layout_names_and_sources():
    m = soft()
    assert m.mode_names == ("free", "contact") and m.n_modes == 2 and m.has_modes
    assert m.stop_names == ("touch", "leave")
    assert m.transition_source == ("free", "contact") and m.transition_target == ("contact", "free")
    assert m.initial_mode == "free" and m.mode_index("contact") == 1
    s = m.symbolic
    assert s.sources == (0, 1) and s.targets == (1, 0) and s.resets == (False, False)
    assert s.stops[0].reset == (x, v)  # no reset: the identity
    # at_stop sees the source mode's field: L_f h of 'leave' in contact is v, its L_f^2 h the contact force
    assert sp.simplify(s.at_stop(1).normal_accel - CONTACT[1]) == 0
    assert sp.simplify(s.at_stop(0).normal_accel + FREE[1]) == 0


def test_order_stops_then_transitions_then_surfaces():
    m = HybridModel(
        "m", [x, v], t, PARAMS, period=2 * sp.pi / w,
        modes=[Mode("contact", CONTACT), Mode("free", FREE, stops=[Stop("wall", x + 1, [x, -v])])],
        transitions=[Transition("touch", "free", "contact", gap - x)],
        surfaces=[Surface("s", x - gap, "contact", "free", sliding=False)], initial_mode="free",
    )  # fmt: skip
    assert m.stop_names == ("wall", "touch", "s_to_free", "s_to_contact")
    assert m.transition_source == ("free", "free", "contact", "free")
    assert m.transition_target == ("free", "contact", "free", "contact")
    assert m.symbolic.resets == (True, False, False, False)
    assert m.symbolic.stops[3].guard == gap - x  # the surface's second side: -h
    assert m.initial_mode == "free" and m.symbolic.vector_field == tuple(FREE)


def test_one_mode_models_keep_their_symbolic_form():
    m = grazing.models.impact_oscillator()
    s = m.symbolic
    assert (s.modes, s.sources, s.targets, s.resets, s.surfaces) == ((), (), (), (), ())
    assert s.at_mode(0) is s and m.mode_names == ("free",) and not m.has_modes
    assert m.transition_source == ("free",)
    user = HybridModel("u", [x, v], t, PARAMS, FREE, gap - x, [x, -v], period=2 * sp.pi / w)
    assert set(user._def._symbolic) == {
        "states",
        "time",
        "vector_field",
        "guard",
        "reset",
        "contact_direction",
    }
    assert user.symbolic.at_stop(0).vector_field == tuple(FREE)


ERRORS = [
    (dict(vector_field=FREE), r"^give either vector_field= \(one mode\) or modes=\[\.\.\.\], not both$"),
    (dict(modes=[Mode("free", FREE), Mode("free", CONTACT)]), r"^mode names must be distinct identifiers"),
    (
        dict(modes=[Mode("free", FREE), Mode("in contact", CONTACT)]),
        r"^mode names must be distinct identifiers",
    ),
    (
        dict(
            transitions=[
                Transition("touch", "free", "contct", gap - x),
                Transition("leave", "contact", "free", x),
            ]
        ),
        r"^transition 'touch' goes to unknown mode 'contct' \(modes: free, contact\)$",
    ),
    (
        dict(
            transitions=[
                Transition("touch", "fre", "contact", gap - x),
                Transition("leave", "contact", "free", x),
            ]
        ),
        r"^transition 'touch' leaves unknown mode 'fre' \(modes: free, contact\)$",
    ),
    (
        dict(
            transitions=[
                Transition("touch", "free", "contact", gap),
                Transition("leave", "contact", "free", x),
            ]
        ),
        r"^the guard of transition 'touch' depends on neither the state nor time: it can never be crossed$",
    ),
    (
        dict(
            modes=[Mode("free", [0, -x]), Mode("contact", CONTACT)],
            transitions=[
                Transition("touch", "free", "contact", gap - x),
                Transition("leave", "contact", "free", x),
            ],
        ),
        r"^the guard of transition 'touch' is constant along mode 'free''s flow \(L_f h = 0\): it can never",
    ),
    (
        dict(transitions=[Transition("leave", "contact", "free", x - gap)]),
        r"^mode 'contact' is never entered \(no transition leads to it and it is not the initial mode\)$",
    ),
    (
        dict(transitions=[], surfaces=[Surface("s", x - gap, "free", "free")]),
        r"^surface 's' needs two different modes, got 'free' twice$",
    ),
    (
        dict(transitions=[], surfaces=[Surface("s", x - gap, "free", "contact")]),
        r"^surface 's' has no sliding region: modes 'free' and 'contact' cross it alike \(L\+h - L-h = 0\); "
        r"give sliding=False$",
    ),
    (
        dict(transitions=[], surfaces=[Surface("s", x - gap, "free", "cont")]),
        r"^surface 's' has unknown mode 'cont'",
    ),
    (dict(initial_mode="stuck"), r"^unknown initial mode 'stuck' \(modes: free, contact\)$"),
    (dict(guard=x), r"^with modes=\[\.\.\.\], give each mode's stops in its Mode"),
    (
        dict(
            transitions=[
                Transition("touch", "free", "contact", gap - x),
                Transition("touch", "contact", "free", x),
            ]
        ),
        r"^stop and transition names must be distinct identifiers",
    ),
    (
        dict(
            transitions=[
                Transition("touch", "free", "contact", gap - x, reset=[x]),
                Transition("l", "contact", "free", x),
            ]
        ),
        r"^the reset of transition 'touch' needs one expression per state$",
    ),
    (
        dict(modes=[Mode("free", [v]), Mode("contact", CONTACT)]),
        r"^the vector field of mode 'free' needs one expression",
    ),
    (
        dict(
            transitions=[
                Transition("touch", "free", "contact", gap - x * sp.Symbol("q")),
                Transition("l", "contact", "free", x),
            ]
        ),
        r"^unknown symbols \['q'\]",
    ),
]


@pytest.mark.parametrize(("kw", "message"), ERRORS)
def test_one_line_errors(kw, message):
    with pytest.raises(ValueError, match=message) as info:
        soft(**kw)
    assert "\n" not in str(info.value)


def test_no_modes_arguments_without_modes():
    with pytest.raises(
        ValueError, match=r"^transitions=, surfaces= and initial_mode= need modes=\[\.\.\.\]$"
    ):
        HybridModel("u", [x, v], t, PARAMS, FREE, gap - x, [x, -v], period=1, initial_mode="free")
    with pytest.raises(ValueError, match=r"^a model needs vector_field= \(one mode\) or modes=\[\.\.\.\]$"):
        HybridModel("u", [x, v], t, PARAMS, guard=gap - x, reset=[x, -v], period=1)


def test_a_surface_with_a_sliding_region_is_accepted():
    # Coulomb friction on a belt at speed 1: v' = -x -/+ mu on either side of v = 1
    mu = sp.Symbol("k")
    m = HybridModel(
        "belt", [x, v], t, PARAMS, period=2 * sp.pi / w,
        modes=[Mode("back", [v, -x - mu]), Mode("forward", [v, -x + mu])],
        surfaces=[Surface("belt", v - 1, "back", "forward")],
    )  # fmt: skip
    assert m.stop_names == ("belt_to_forward", "belt_to_back")


def test_filippov_field_stays_on_a_moving_surface():
    # a time-dependent surface h = v - a cos(w t) and two nonlinear fields: L_{f_s} h = 0 identically
    mu = sp.Symbol("k")
    m = HybridModel(
        "belt", [x, v], t, PARAMS, period=2 * sp.pi / w,
        modes=[Mode("back", [v, -x**3 - mu * (1 + x**2)]), Mode("forward", [v, -sp.sin(x) + mu])],
        surfaces=[Surface("belt", v - a * sp.cos(w * t), "back", "forward")],
    )  # fmt: skip
    s = m.symbolic
    fs = s.filippov_field(0)
    h = s.surfaces[0].h
    along = sum(sp.diff(h, xi) * fi for xi, fi in zip(s.states, fs)) + sp.diff(h, t)
    assert sp.simplify(along) == 0
    # the exit rows: -L+h and L-h, and f_s is f+ where L+h = 0 and f- where L-h = 0
    out_pos, _ = s.exit_rows(0)
    lp = sum(sp.diff(h, xi) * fi for xi, fi in zip(s.states, s.modes[0].vector_field)) + sp.diff(h, t)
    assert sp.simplify(out_pos + lp) == 0
    point = {x: 0.3, v: 0.2, t: 0.1, a: 1.0, w: 1.2}
    mu_on_exit = sp.solve(out_pos.subs(point), mu)[0]  # where the side h > 0 stops pushing in
    at = {**point, mu: mu_on_exit}
    assert [float(e.subs(at)) for e in fs] == pytest.approx(
        [float(e.subs(at)) for e in s.modes[0].vector_field]
    )


def test_sticking_field_is_the_equivalent_control_on_the_contact_manifold():
    s = grazing.models.bouncing_ball().symbolic
    sigma = s.normal_rate  # sticking: sigma = L_f h = 0 held along e
    e = s.contact_direction
    grad = [sp.diff(sigma, xi) for xi in s.states]
    lie_sigma = sum(g * fi for g, fi in zip(grad, s.vector_field)) + sp.diff(sigma, s.time)
    lam = lie_sigma / sum(g * ei for g, ei in zip(grad, e))
    expected = [fi - lam * ei for fi, ei in zip(s.vector_field, e)]
    assert all(sp.simplify(a_ - b_) == 0 for a_, b_ in zip(s.sticking_field(), expected))


def test_vector_field_per_mode_and_the_saltation_of_a_switch():
    m = soft()
    p = dict(m.params)
    xs, ts = np.array([p["gap"], 0.7]), 0.3
    forcing = p["a"] * np.cos(p["omega"] * ts)
    f_free = np.array([0.7, -2 * p["zeta"] * 0.7 - p["gap"] + forcing])
    f_contact = f_free - np.array([0.0, p["c"] * 0.7])  # (k (x - gap) = 0 on the surface)
    assert np.allclose(m.vector_field(xs, ts), f_free, rtol=0, atol=1e-15)
    assert np.allclose(m.vector_field(xs, ts, mode="contact"), f_contact, rtol=0, atol=1e-15)
    hx = np.array([-1.0, 0.0])  # touch: h = gap - x
    expected = np.eye(2) + np.outer(f_contact - f_free, hx) / (hx @ f_free)
    assert np.allclose(m.saltation(xs, ts, "touch"), expected, rtol=0, atol=1e-14)
    assert abs(expected[1, 0]) > 0.1  # (the damper's jump: S is not I)
    back = np.array([p["gap"], -0.7])  # leave: h = x - gap, from contact to free
    f_c, f_f = m.vector_field(back, ts, "contact"), m.vector_field(back, ts, "free")
    expected = np.eye(2) + np.outer(f_f - f_c, -hx) / (-hx @ f_c)
    assert np.allclose(m.saltation(back, ts, "leave"), expected, rtol=0, atol=1e-14)
    with pytest.raises(InvalidParameterError, match="unknown mode 'stuck'"):
        m.vector_field(xs, ts, mode="stuck")


def test_check_state_per_mode():
    m = soft()
    assert m.check_state([0.0, 1.0]).tolist() == [0.0, 1.0]
    message = (
        r"^initial state \[1\.0, 0\.0\] is not in mode 'free' \(guard of transition 'touch' h = -0\.5 < 0\)$"
    )
    with pytest.raises(InvalidStateError, match=message):
        m.check_state([1.0, 0.0])
    assert m.check_state([1.0, 0.0], mode="contact").tolist() == [1.0, 0.0]
    with pytest.raises(InvalidStateError, match="is not in mode 'contact'"):
        m.check_state([0.0, 0.0], mode="contact")
    with pytest.raises(
        InvalidParameterError, match=r"^unknown mode 'stuck' for model 'soft' \(modes: free, contact\)$"
    ):
        m.check_state([0.0, 0.0], mode="stuck")


def test_features_not_yet_on_modes_are_refused_in_one_line():

    m = soft()
    # (virtual orbits go through modes: tests/orbits/test_virtual_through_modes.py)
    # (the map stands for a stop of one mode: tests/engine/test_zdm_modes.py; not for a switch)
    from grazing.engine.runner import DiscontinuityMap

    with pytest.raises(InvalidParameterError, match=r"^the discontinuity map stands for an impact"):
        grazing.simulate(m, [0.0, 0.0], periods=1, zdm=DiscontinuityMap(0.0, 1.0, (0.0, 1.0), stop=0))
    # (the grazing analysis and the grazing curve go through modes: tests/orbits/test_curves_through_modes.py)
    # (the attractors and basins go through modes: tests/attractors/test_basins_modes.py)
    from grazing.maps import flow_map

    # a run without events ignores the resets only: this model has none, so it is the run with events
    free, physical = flow_map(m, [0.0, 0.0], periods=3, virtual=True), flow_map(m, [0.0, 0.0], periods=3)
    assert len(physical.solution.switches) >= 2
    assert np.array_equal(free.image, physical.image) and np.array_equal(free.jacobian, physical.jacobian)
