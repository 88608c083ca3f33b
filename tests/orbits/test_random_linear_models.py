"""Random two- and three-body impacting models (4 and 6 states, two stops) against their exact maps.

Between impacts the flow is linear, so the stroboscopic map is exact in closed form
(:mod:`tests.linear_exact`: matrix exponentials, impacts by bracketing); grazing's
map (its Taylor integration, event location, resets and the saltation matrices of
its Jacobian, the parameter sensitivity of the period-setting frequency) must agree
with it for any drawn parameters and state.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from grazing.maps import flow_map
from tests.linear_exact import chain_matrices, chain_model


@lru_cache(maxsize=2)
def _model(bodies: int):
    return chain_model(bodies)  # (compiled once: each example only sets its parameters)


@st.composite
def chains(draw):
    bodies = draw(st.sampled_from([2, 3]))
    values = {
        "kP": draw(st.floats(0.5, 2.0)), "cP": draw(st.floats(0.02, 0.3)), "F0": draw(st.floats(0.3, 1.5)),
        "wf": draw(st.floats(0.6, 2.5)), "kQ": draw(st.sampled_from([0.0, 0.3, 1.0])),
        "cQ": draw(st.floats(0.0, 0.1)), "gap": draw(st.floats(0.2, 1.0)), "m": draw(st.floats(0.05, 1.0)),
        "e": draw(st.floats(0.3, 1.0)),
    }  # fmt: skip
    if bodies == 3:
        values.update(kA=draw(st.floats(0.2, 3.0)), cA=draw(st.floats(0.0, 0.2)))
    model = _model(bodies).with_params(**values)
    gap = values["gap"]
    x = np.array([draw(st.floats(-1.0, 1.0)) for _ in range(model.n_states)])
    x[2] = x[0] + draw(st.floats(-0.9, 0.9)) * gap  # (the rattling mass inside its cavity)
    t0 = draw(st.floats(0.0, 2 * np.pi / values["wf"]))
    return model, x, t0


@settings(max_examples=30, deadline=None)
@given(chains())
def test_the_stroboscopic_map_and_its_jacobian_are_the_exact_ones(case):
    model, x, t0 = case
    ref = chain_matrices(model)
    image, jacobian, impacts = ref.flow_map(x, t0, 1)
    # (a grazing contact within the reference's sampling is where the two may count differently)
    speeds = (
        [abs(float(ref.stops[j].c @ ref.f(ref.flow(x, t0, t), t))) for t, j in impacts] if impacts else []
    )
    assume(not speeds or min(speeds) > 1e-3)
    fm = flow_map(model, x, t0=t0, periods=1, sensitivities=("wf",))
    # (chattering that grazing sums and continues as sticking: the reference, impact by impact, has no
    # such thing)
    assume(not len(fm.solution.sticking) and fm.solution.jacobian_valid)
    assert fm.impacts == len(impacts)
    assert [int(j) for j in fm.solution.impacts.stop] == [j for _, j in impacts]
    scale = 1.0 + np.max(np.abs(image))
    np.testing.assert_allclose(fm.image, image, atol=1e-10 * scale)
    jscale = 1.0 + np.max(np.abs(jacobian))
    np.testing.assert_allclose(fm.jacobian, jacobian, atol=1e-8 * jscale)
    # The period-setting frequency's sensitivity, against central differences of the exact map (the
    # end of the map moves with the period: t0 + T(wf)).
    w = model.params["wf"]
    h = 1e-6 * w
    plus = chain_matrices(model.with_params(wf=w + h)).flow_map(x, t0, 1)
    minus = chain_matrices(model.with_params(wf=w - h)).flow_map(x, t0, 1)
    assume(len(plus[2]) == len(minus[2]) == len(impacts))
    numeric = (plus[0] - minus[0]) / (2 * h)
    np.testing.assert_allclose(fm.sensitivity[:, 0], numeric, atol=1e-5 * (1.0 + np.max(np.abs(numeric))))
