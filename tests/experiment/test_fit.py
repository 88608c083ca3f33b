"""The paper's fit of (r, beta): equal damping plus the observed primary grazing."""

from __future__ import annotations

import math

import pytest

from grazing.errors import InvalidParameterError
from grazing.experiment import fit_parameters, grazing_eta, model_damping
from tests.free_orbit import grazing_degrees


def test_grazing_eta_depends_on_beta_not_on_r():
    import grazing
    from grazing.orbits import find_grazings

    eta_g = grazing_eta(40.0, 0.048)
    # independently, by simulation: the free orbit's largest angle there is the stop angle
    assert grazing_degrees(eta=eta_g) == pytest.approx(40.0, abs=1e-7)
    # r plays no part: the orbit does not touch the stop before it grazes
    for r in (0.3, 1.0):
        m = grazing.models.pendulum("B", r=r, theta_hat=math.radians(40))
        pts, _ = find_grazings(m, "eta", 0.2, 0.5)
        assert pts[0].model.params["eta"] == pytest.approx(eta_g, abs=1e-9)
    # more damping: a smaller swing reaches the stop closer to resonance
    assert grazing_eta(40.0, 0.03) < grazing_eta(40.0, 0.048) < grazing_eta(40.0, 0.06)
    assert grazing_eta(40.0, 0.2) is None  # too damped to reach 40 degrees


def test_fit_recovers_case_b_from_its_own_grazing():
    d_b = model_damping(0.7675, 0.048).damping
    eta_b = grazing_eta(40.0, 0.048)
    fit = fit_parameters(40.0, eta_b, d_b)
    assert fit.beta == pytest.approx(0.048, abs=1e-7)
    assert fit.r == pytest.approx(0.7675, abs=1e-6)
    assert fit.eta_graze == pytest.approx(eta_b, abs=1e-8)
    assert fit.evaluations <= 20


def test_fit_with_the_papers_relation_reproduces_point_b():
    fit = fit_parameters(40.0, 0.445, 0.07, relation="protocol")
    assert fit.beta == pytest.approx(0.048, abs=5e-4)
    assert fit.r == pytest.approx(0.7675, abs=3e-3)


def test_fit_rejects_unreachable_grazing():
    with pytest.raises(InvalidParameterError, match="even with beta = 0"):
        fit_parameters(40.0, 0.40, 0.07)
    with pytest.raises(InvalidParameterError, match="r > 1"):
        fit_parameters(40.0, 0.49, 0.07)
    with pytest.raises(InvalidParameterError, match=r"grazing disappears at beta = 0\.043"):
        fit_parameters(60.0, 0.5, 0.07)  # past 56 deg the swing stops reaching the stop as beta grows
    with pytest.raises(InvalidParameterError, match="outside the search range"):
        fit_parameters(40.0, 0.1, 0.07)
    with pytest.raises(InvalidParameterError, match="damping D"):
        fit_parameters(40.0, 0.445, -0.07)
