"""The hybrid model type: parameters, Jacobians, saltation, user models."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import grazing
from grazing import HybridModel, InvalidParameterError, InvalidStateError, Parameter
from grazing.models import CASES, bouncing_ball, impact_oscillator, pendulum


def _fd_jacobian(fun, x, eps=1e-6):
    x = np.asarray(x, dtype=float)
    cols = []
    for j in range(x.size):
        dx = np.zeros_like(x)
        dx[j] = eps
        cols.append((np.atleast_1d(fun(x + dx)) - np.atleast_1d(fun(x - dx))) / (2 * eps))
    return np.array(cols).T


@pytest.mark.parametrize("case", list(CASES))
def test_cases_by_name(case):
    m = pendulum(case)
    for k, v in CASES[case].items():
        assert m.params[k] == v
    assert pendulum(case.lower()).params == m.params


def test_case_a_reduced_and_errata():
    assert pendulum("A-reduced").params["alpha"] == pytest.approx(0.71 * 0.2254)
    assert pendulum("D").params["beta"] == 0.068  # the paper's "0.68" is a typo


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"r": 1.5}, r"r = 1.5 is outside \[0, 1\]"),
        ({"r": -0.1}, "r = -0.1 is outside"),
        ({"eta": 0.0}, r"eta = 0 is outside \(0, inf\)"),
        ({"beta": -1.0}, "beta = -1 is outside"),
        ({"theta_hat": math.pi}, "theta_hat"),
        ({"alpha": float("nan")}, "alpha must be finite"),
        ({"alpha": "abc"}, "alpha must be a number"),
        ({"gamma": 1.0}, "unknown parameter 'gamma'"),
    ],
)
def test_bad_parameters_are_rejected(changes, message):
    with pytest.raises(InvalidParameterError, match=message):
        pendulum("B", **changes)


def test_unknown_case():
    with pytest.raises(InvalidParameterError, match="unknown case 'Z'"):
        pendulum("Z")


def test_with_params_shares_kernels_and_keeps_values():
    a = pendulum("B", eta=0.4)
    b = a.with_params(eta=0.5)
    assert a.params["eta"] == 0.4 and b.params["eta"] == 0.5
    assert a.kernels() is b.kernels()


MODELS = {
    "pendulum": pendulum("B", eta=0.45, theta_hat=0.7),
    "oscillator": impact_oscillator(sigma=0.2, omega=2.5),
    "ball": bouncing_ball(amplitude=0.3, omega=1.3),
}


@pytest.mark.parametrize("name", list(MODELS))
@settings(max_examples=20, deadline=None)
@given(x=st.tuples(st.floats(-1, 1), st.floats(-1, 1)), t=st.floats(0, 10))
def test_jacobians_match_finite_differences(name, x, t):
    m = MODELS[name]
    fx, hx, gx = m.jacobians(x, t)
    np.testing.assert_allclose(fx, _fd_jacobian(lambda z: m.vector_field(z, t), x), atol=1e-7)
    np.testing.assert_allclose(hx, _fd_jacobian(lambda z: m.guard(z, t), x)[0], atol=1e-7)
    np.testing.assert_allclose(gx, _fd_jacobian(lambda z: m.reset(z, t), x), atol=1e-7)


@settings(max_examples=30, deadline=None)
@given(
    r=st.floats(0.05, 1.0),
    v=st.floats(0.01, 2.0),
    tau=st.floats(0, 2 * math.pi),
    theta_hat=st.floats(-1.5, 1.5),
)
def test_pendulum_saltation_determinant_is_r_squared(r, v, tau, theta_hat):
    """det S = r^2 for every impact (what makes det(monodromy) = r^(2k) e^(...))."""
    m = pendulum("B", r=r, theta_hat=theta_hat)
    S = m.saltation([theta_hat, v], tau)
    assert np.linalg.det(S) == pytest.approx(r**2, rel=1e-10)


def test_saltation_maps_flow_direction_to_flow_direction():
    """S f(x-) = f(g(x-)): a perturbation along the flow stays along the flow."""
    m = pendulum("B", eta=0.45, theta_hat=0.5)
    x_im, t_im = np.array([0.5, 0.3]), 1.1
    S = m.saltation(x_im, t_im)
    f_minus = m.vector_field(x_im, t_im)
    f_plus = m.vector_field(m.reset(x_im, t_im), t_im)
    np.testing.assert_allclose(S @ f_minus, f_plus, rtol=1e-12)


def test_initial_state_beyond_stop():
    m = pendulum("B", theta_hat=0.5)
    with pytest.raises(InvalidStateError, match="beyond the stop"):
        m.check_state([0.6, 0.0])
    with pytest.raises(InvalidStateError, match="2 components"):
        m.check_state([0.1])


def test_user_defined_model_runs():
    x, v, t = sp.symbols("x v t")
    k, r, a, w = sp.symbols("k r a w")
    model = HybridModel(
        "cubic",
        [x, v],
        t,
        [
            Parameter("k", 1.0),
            Parameter("r", 0.8, lower=0, upper=1),
            Parameter("a", 0.5),
            Parameter("w", 1.2),
        ],
        vector_field=[v, -0.1 * v - k * x - x**3 + a * sp.cos(w * t)],
        guard=0.3 - x,
        reset=[x, -r * v],
        period=2 * sp.pi / w,
        contact_direction=[0, 1],
    )
    sol = grazing.simulate(model, [0.0, 0.0], transient=50, periods=20)
    assert sol.samples.shape == (20, 2)
    assert np.all(sol.samples[:, 0] <= 0.3)
    assert sol.n_impacts > 0


def test_model_rejects_unknown_symbols():
    x, v, t, q = sp.symbols("x v t q")
    with pytest.raises(ValueError, match="unknown symbols"):
        HybridModel("bad", [x, v], t, [], [v, q], -x, [x, -v], 1)


# ----------------------------------------------------------------------------
# issue 26: functions the kernels cannot expand are refused when the model is built


def _oscillator(*, field=None, guard=None, reset=None, contact=(0, 1), period=None, stops=None):
    """A forced oscillator with one term of each piece replaceable (states x, v; parameters w, r)."""
    x, v, t, w, r = sp.symbols("x v t w r")
    kw: dict = {"period": 2 * sp.pi / w if period is None else period}
    if stops is None:
        kw.update(guard=1 - x if guard is None else guard, reset=[x, -r * v] if reset is None else reset,
                  contact_direction=contact)  # fmt: skip
    else:
        kw["stops"] = stops
    params = [Parameter("w", 1.2, lower=0, lower_open=True), Parameter("r", 0.8, lower=0, upper=1)]
    return HybridModel(
        "probe", [x, v], t, params,
        vector_field=[v, -0.1 * v - x + sp.cos(w * t) + (0 if field is None else field)], **kw,
    )  # fmt: skip


X, V, T, W = sp.symbols("x v t w")
NON_SMOOTH = [
    sp.Abs(X), sp.sign(V), sp.Heaviside(X), sp.Max(X, 0), sp.Min(X, V), sp.floor(X), sp.ceiling(V),
    sp.Piecewise((X, X > 0), (0, True)), sp.Mod(X, 1), sp.re(X), sp.frac(X), sp.DiracDelta(X),
]  # fmt: skip


@pytest.mark.parametrize("term", NON_SMOOTH, ids=lambda e: type(e).__name__)
def test_non_smooth_functions_are_refused_naming_the_function_and_a_stop(term):
    name = type(term).__name__
    with pytest.raises(grazing.UnsupportedExpressionError) as err:
        _oscillator(field=term)
    msg = str(err.value)
    assert msg.startswith(f"{name} is not smooth (") and "in the vector field (v')" in msg
    assert msg.endswith("model it as a stop (a guard and a reset), see docs/user-models.md")
    assert "\n" not in msg
    assert isinstance(err.value, grazing.GrazingError)  # (the CLI prints it as one line)


@pytest.mark.parametrize(
    "pieces, where",
    [
        (dict(guard=1 - sp.Abs(X)), "in the guard)"),
        (dict(reset=[X, -sp.Symbol("r") * sp.Abs(V)]), "in the reset)"),
        (dict(contact=(0, sp.sign(V))), "in the contact direction)"),
        (dict(period=2 * sp.pi / sp.Abs(W)), "in the period)"),
        (
            dict(stops=[grazing.Stop("left", X + 1, [X, -V], [0, 1]),
                        grazing.Stop("right", 1 - X, [X, -sp.Max(V, 0)], [0, 1])]),
            "in the reset of stop 'right')",
        ),
    ],
)  # fmt: skip
def test_every_piece_of_a_model_is_checked(pieces, where):
    with pytest.raises(grazing.UnsupportedExpressionError, match="is not smooth") as err:
        _oscillator(**pieces)
    assert where in str(err.value)


@pytest.mark.parametrize(
    "term, start",
    [
        (
            sp.besselj(0, X),
            "besselj is not supported by the Taylor kernels (besselj(0, x) in the vector field",
        ),
        (sp.gamma(X), "gamma is not supported by the Taylor kernels"),
        (sp.atan2(V, X), "atan2 is not supported by the Taylor kernels"),
        (sp.Function("f")(X), "f(x) in the vector field (v') is an undefined function"),
        (sp.I * X, "the imaginary unit I in the vector field"),
        (sp.oo * X, "oo in the vector field (v') is not a finite real number"),
    ],
)
def test_unknown_functions_are_refused_naming_them(term, start):
    with pytest.raises(grazing.UnsupportedExpressionError) as err:
        _oscillator(field=term)
    assert str(err.value).startswith(start)
    assert "docs/user-models.md" in str(err.value) or "real" in str(err.value)


def test_smooth_functions_are_accepted_without_compiling():
    """Building a model compiles nothing; every supported function passes the check."""
    from tests.function_models import SMOOTH_FUNCTIONS

    for name, f in SMOOTH_FUNCTIONS.items():
        model = _oscillator(field=f(X) / 10 + sp.acosh(2 + V**2) / 10)
        assert model.symbolic.vector_field[1].has(sp.acosh), name
    assert _oscillator(field=sp.E**X * sp.EulerGamma).n_states == 2


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(default=1.5, lower=0, upper=1), "default of parameter r is invalid: r = 1.5 is outside [0, 1]"),
        (dict(default=0.0, lower=0.0, lower_open=True), "r = 0 is outside (0, inf)"),
        (dict(default=math.nan), "the default of parameter r is invalid: r must be finite, got nan"),
        (dict(default="x"), "r must be a number, got 'x'"),
        (dict(default=0.5, lower=1.0, upper=0.0), "parameter r: lower=1, upper=0 is not an interval"),
    ],
)  # fmt: skip
def test_parameter_defaults_are_checked_against_their_bounds(kwargs, message):
    with pytest.raises(InvalidParameterError) as err:
        Parameter("r", **kwargs)
    assert message in str(err.value)


def test_states_that_are_views_of_other_arrays_are_accepted():
    """A column of a 2-D array (not C-contiguous) gives what its copy gives, in every compiled call."""
    m = impact_oscillator(sigma=0.1)
    table = np.array([[0.3, 9.0], [-0.7, 9.0]])
    view, copy = table[:, 0], table[:, 0].copy()
    assert not view.flags.c_contiguous
    assert m.guard(view) == m.guard(copy) and m.normal_accel(view) == m.normal_accel(copy)
    assert np.array_equal(m.vector_field(view), m.vector_field(copy))
    assert np.array_equal(m.reset(view), m.reset(copy))


def _tables_by_model(model, names, points):
    """What ``parameter_table`` must give: a model per point (the first of equal points', as sweeps had)."""
    vectors, periods, seen = [], [], {}
    for pt in points:
        m = seen.setdefault(tuple(pt), model.with_params(**dict(zip(names, pt))))
        vectors.append(m.param_vector)
        periods.append(m.period)
    return np.array(vectors), np.array(periods)


def _raised(call):
    try:
        call()
    except Exception as exc:  # (compared by type and text)
        return type(exc), str(exc)
    return None


@pytest.mark.parametrize("name", ["pendulum", "oscillator", "ball"])
@settings(max_examples=40, deadline=None)
@given(data=st.data())
def test_parameter_table_is_a_model_per_point(name, data):
    """Every point's parameter vector and period are those of its own model, bit for bit; a point
    with_params refuses raises with_params' error (the first such point's)."""
    model = MODELS[name]
    names = data.draw(st.lists(st.sampled_from(list(model.params)), min_size=0, max_size=2, unique=True))
    value = st.one_of(
        st.sampled_from([0.0, -0.0, 0.3, 0.3, 1.0, 2.5, -1.0, math.inf, math.nan]),
        st.floats(-3, 3, allow_nan=False),
    )
    points = data.draw(st.lists(st.tuples(*[value] * len(names)), min_size=1, max_size=12))
    expected = _raised(lambda: _tables_by_model(model, names, points))
    got = _raised(lambda: model.parameter_table(names, points))
    assert got == expected
    if expected is None:
        vectors, periods = _tables_by_model(model, names, points)
        table = model.parameter_table(names, points)
        assert table.vectors.tobytes() == vectors.tobytes() and table.periods.tobytes() == periods.tobytes()


def test_parameter_table_refuses_a_period_not_positive_between_good_points():
    """A user model whose period is negative for a parameter value between two good ones."""
    x, v, t, w = sp.symbols("x v t w")
    model = HybridModel(
        "shifted", [x, v], t, [Parameter("w", 2.0, lower=0.0, lower_open=True)], vector_field=[v, -x],
        guard=1 - x, reset=[x, -v], period=2 * sp.pi / (w - 1),
    )  # fmt: skip
    assert model.parameter_table(["w"], [[2.0], [3.0]]).periods.tolist() == [2 * math.pi, math.pi]
    with pytest.raises(InvalidParameterError, match="the forcing period must be positive"):
        model.parameter_table(["w"], [[2.0], [0.5], [3.0]])
    with pytest.raises(ZeroDivisionError):  # (as with_params: the period's own error)
        model.parameter_table(["w"], [[2.0], [1.0]])
