"""Neimark-Sacker points of models of any dimension, against an exact linear reference.

The test function is the bialternate product's (``det(P_x (.) P_x - I)``, as
``sign * min |mu_i mu_j - 1| / (1 + |mu_i mu_j|)``), which for two states is
``det(P_x) - 1`` and for more states is not: on the impact damper (4 states)
``det(P_x) - 1`` is about -0.9 on both sides of its Neimark-Sacker point
(issue 42).  The references are built from matrix exponentials
(:mod:`tests.linear_exact`), not from grazing's engine.
"""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from grazing.cli import main
from grazing.models import impact_damper
from grazing.orbits import continue_orbit, follow_curve
from grazing.orbits.bifurcations import (
    neimark_sacker_angle,
    neimark_sacker_test,
    neutral_saddle,
    orbit_test,
    verified,
)
from grazing.orbits.bordered import bialternate
from grazing.orbits.crossings import limit_condition, reduced_limit
from tests.linear_exact import (
    damper,
    damper_matrices,
    neimark_sacker_parameter,
    pair_closest_to_circle,
    six_state_matrices,
    six_state_model,
)


def _only_neimark_sacker(branch):
    kinds = [sp.kind for sp in branch.special]
    assert kinds == ["neimark-sacker"], (kinds, [sp.note for sp in branch.special])
    return branch.special[0]


@pytest.mark.parametrize(
    ("states", "make", "reference", "param"),
    [
        (4, lambda: damper(omega=1.2), lambda m: damper_matrices(m.params["omega"]), "omega"),
        (6, lambda: six_state_model(Om=1.2), six_state_matrices, "Om"),
    ],
    ids=["impact-damper", "six-states"],
)
def test_the_neimark_sacker_point_is_located_on_models_of_more_states(states, make, reference, param):
    model = make()
    assert model.n_states == states
    branch = continue_orbit(model, param, 1.2, 1.45)
    ns = _only_neimark_sacker(branch)  # (no "unlocated stability change": issue 42's report)
    orbit = ns.orbit
    # The orbit there is the exact one: the reference's fixed point and monodromy at the same parameter.
    ref = reference(orbit.model)
    x, J = ref.periodic_orbit(orbit.state, orbit.t0)
    np.testing.assert_allclose(orbit.state, x, atol=1e-12)
    np.testing.assert_allclose(orbit.monodromy, J, atol=1e-11)
    # det(P_x) - 1, the old test function, is far from zero and does not change sign there.
    assert abs(np.linalg.det(orbit.monodromy) - 1.0) > 0.5
    # Located to Newton tolerance: the parameter where the exact map's pair is on the circle.
    p_ref, mu_ref = neimark_sacker_parameter(
        lambda p: reference(orbit.model.with_params(**{param: p})), ns.param - 1e-3, ns.param + 1e-3,
        orbit.state, orbit.t0,
    )  # fmt: skip
    assert ns.param == pytest.approx(p_ref, abs=1e-9)
    assert ns.angle == pytest.approx(abs(np.angle(mu_ref)), abs=1e-9)
    # Its precision and interval say how well it is located (as BifurcationKit's special points do).
    lo, hi = ns.interval
    assert lo <= p_ref <= hi and lo <= ns.param <= hi
    assert abs(ns.param - p_ref) <= 2 * ns.precision + 1e-13
    pair = orbit.multipliers[np.argmin(np.abs(np.abs(orbit.multipliers) - 1.0))]
    assert abs(abs(pair) - 1.0) < 1e-8
    # Stable before it, two multipliers outside the circle after it.
    assert branch.orbits[ns.index].unstable_count == 0 and branch.orbits[-1].unstable_count == 2


def test_the_neimark_sacker_curve_of_a_four_state_model_keeps_its_pair_on_the_circle():
    model = damper(omega=1.2)
    curve = follow_curve(model, "neimark-sacker", "omega", 1.2, 1.45, "r", (0.7, 0.9))
    assert len(curve.points) >= 5
    for point in curve.points:
        mu = np.asarray(point.multipliers)
        assert np.min(np.abs(np.abs(mu) - 1.0)) < 1e-8
    # Each point is a Neimark-Sacker point of the exact map too: the reference's pair on the circle.
    for point in curve.points[:: max(1, len(curve.points) // 4)]:
        omega, r = point.values
        ref = damper_matrices(omega, r=r)
        _, J = ref.periodic_orbit(np.asarray(point.state), point.section_time)
        mu = np.linalg.eigvals(J)
        assert np.min(np.abs(np.abs(mu) - 1.0)) < 1e-8


def test_the_neimark_sacker_curve_of_a_six_state_model_is_the_exact_maps():
    model = six_state_model(Om=1.2)
    curve = follow_curve(model, "neimark-sacker", "Om", 1.2, 1.45, "rr", (0.75, 0.85))
    assert len(curve.points) >= 3
    for point in curve.points[:: max(1, len(curve.points) // 3)]:
        om, rr = point.values
        ref = six_state_matrices(model.with_params(Om=om, rr=rr))
        _, J = ref.periodic_orbit(np.asarray(point.state), point.section_time)
        pair = pair_closest_to_circle(J)
        assert abs(abs(pair) - 1.0) < 1e-8
        assert np.min(np.abs(np.abs(np.asarray(point.multipliers)) - 1.0)) < 1e-8


def test_grazing_continue_and_curve_report_the_neimark_sacker_point_with_its_angle(capsys):
    argv = ["--model", "impact-damper", "--set", "mu=0.3", "--set", "r=0.8", "--param", "omega"]
    code = main(["continue", *argv, "--start", "1.2", "--stop", "1.45", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    special = json.loads(out)["special"]
    assert [sp["kind"] for sp in special] == ["neimark-sacker"]
    assert special[0]["value"] == pytest.approx(1.40918347113, abs=1e-9)  # (the exact reference's)
    assert special[0]["angle"] == pytest.approx(2.7714078182, abs=1e-9)
    code = main(["continue", *argv, "--start", "1.2", "--stop", "1.45"])
    out, err = capsys.readouterr()
    assert code == 0 and "unlocated" not in out and "angle 2.77141 rad" in out, out
    code = main(
        ["curve", *argv, "--kind", "neimark-sacker", "--start", "1.2", "--stop", "1.45",
         "--param2", "r", "--range", "0.75,0.85", "--json"]
    )  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    points = json.loads(out)["points"]
    assert len(points) >= 3 and {p["r"] for p in points} >= {0.75, 0.85}


# ----------------------------------------------------------------------------
# The test function itself


@st.composite
def spectra(draw):
    """Real matrices of 2 to 6 states with chosen multipliers: complex pairs and real ones."""
    n = draw(st.integers(2, 6))
    blocks, mus = [], []
    while sum(b.shape[0] for b in blocks) < n:
        if n - sum(b.shape[0] for b in blocks) >= 2 and draw(st.booleans()):
            rho, th = draw(st.floats(0.2, 1.8)), draw(st.floats(0.1, 3.0))
            a, b = rho * math.cos(th), rho * math.sin(th)
            blocks.append(np.array([[a, -b], [b, a]]))
            mus += [complex(a, b), complex(a, -b)]
        else:
            mu = draw(st.floats(0.1, 2.5)) * draw(st.sampled_from([1.0, -1.0]))
            blocks.append(np.array([[mu]]))
            mus.append(complex(mu))
    D = np.zeros((n, n))
    k = 0
    for b in blocks:
        D[k : k + b.shape[0], k : k + b.shape[0]] = b
        k += b.shape[0]
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    V = rng.normal(size=(n, n)) + 3 * np.eye(n)
    return V @ D @ np.linalg.inv(V), np.array(mus)


@settings(max_examples=200, deadline=None)
@given(spectra())
def test_the_test_function_has_the_sign_of_the_bialternate_determinant(case):
    M, mu = case
    n = M.shape[0]
    det = np.linalg.det(bialternate(M, M) - np.eye(n * (n - 1) // 2))
    prods = [mu[i] * mu[j] for i in range(n) for j in range(i + 1, n)]
    if min(abs(p - 1.0) for p in prods) < 1e-3:  # (the sign there is rounding's)
        return
    value = neimark_sacker_test(np.linalg.eigvals(M))
    assert np.sign(value) == np.sign(det)
    assert abs(value) == pytest.approx(min(abs(p - 1.0) / (1 + abs(p)) for p in prods), rel=1e-6)


def test_a_neutral_saddle_is_neither_a_neimark_sacker_point_nor_missed():
    # Two real multipliers mu, 1/mu: the test function vanishes, no multiplier is on the circle.
    saddle = SimpleNamespace(multipliers=np.array([3.0, 1 / 3.0, 0.2 + 0.1j, 0.2 - 0.1j]))
    assert abs(neimark_sacker_test(saddle.multipliers)) < 1e-15
    assert neutral_saddle(saddle) and not verified("neimark-sacker", saddle)
    assert math.isnan(neimark_sacker_angle(saddle.multipliers))
    torus = SimpleNamespace(multipliers=np.array([np.exp(0.9j), np.exp(-0.9j), 3.0, 0.2]))
    assert verified("neimark-sacker", torus) and not neutral_saddle(torus)
    assert neimark_sacker_angle(torus.multipliers) == pytest.approx(0.9, abs=1e-15)


@pytest.fixture(scope="module")
def damper_grazing():
    """The grazing that ends the damper's branch below omega = 1.2 (mu = 0.3, r = 0.8): 4 states."""
    branch = continue_orbit(impact_damper(mu=0.3, r=0.8), "omega", 1.2, 0.6)
    (graze,) = [s for s in branch.special if s.kind == "grazing"]
    return graze.grazing


def test_the_neimark_sacker_limit_at_a_lost_impact_is_that_of_the_bounded_multipliers(damper_grazing):
    # With an impact of speed nu at the contact the monodromy is g_x J + N (h_x J) / nu: one multiplier grows
    # as 1 / nu, the other three tend to those of the reduced matrix, whose pairs' products minus one are the
    # limit condition of a Neimark-Sacker curve of 4 states (nan before).
    point = damper_grazing
    m, y, t, j = point.model, point.contact, point.t_graze, point.stop
    _, h_x, g_x = m.jacobians(y, t, j)
    g_t = np.asarray(m._call("g_t", y, t, j), dtype=float).reshape(-1)
    N = m.vector_field(m.reset(y, t, j), t) - g_x @ m.vector_field(y, t) - g_t
    M0, c = g_x @ point.monodromy, h_x @ point.monodromy
    nu = 1e-7
    mu = np.linalg.eigvals(M0 + np.outer(N, c) / nu)
    mu = mu[np.argsort(np.abs(mu))][:-1]  # (the three bounded ones)
    assert np.allclose(np.sort_complex(mu), np.sort_complex(np.linalg.eigvals(reduced_limit(M0, N, c))),
                       rtol=0, atol=1e-5)  # fmt: skip
    pairs = np.prod([mu[a] * mu[b] - 1 for a in range(3) for b in range(a + 1, 3)])
    value = limit_condition("neimark-sacker", point, loses=True)
    assert math.isfinite(value) and value == pytest.approx(pairs.real, rel=1e-4)


def test_a_multiplier_within_the_monodromys_rounding_changes_no_sign_of_the_test():
    # An orbit near a grazing with a saddle flow: multipliers mu and det / mu, det = 0.25 (their product,
    # below 1 all along), |mu| from 1e6 to 1e10, the monodromy rounded as one is (eps |M| per entry).  The
    # small multiplier then comes out as rounding's (1e-7 for 2e-10): its product with the large one, which
    # the Neimark-Sacker test takes, was 175 at some of them, a sign change where nothing happens.
    rng = np.random.default_rng(7)
    eps = np.finfo(float).eps
    signs = set()
    for large in np.geomspace(1e6, 1e10, 40):
        V = np.array([[1.0, 0.3], [-0.2, 1.0]]) + 0.1 * rng.normal(size=(2, 2))
        M = V @ np.diag([large, 0.25 / large]) @ np.linalg.inv(V)
        M = M + eps * np.linalg.norm(M, 2) * rng.uniform(-1, 1, M.shape)
        orbit = SimpleNamespace(monodromy=M, multipliers=np.linalg.eigvals(M))
        signs.add(math.copysign(1.0, orbit_test("neimark-sacker", orbit)))
    assert signs == {-1.0}
