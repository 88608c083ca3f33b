"""Property tests over random models with two and three modes (:class:`tests.random_models.ModesSpec`).

Soft contacts (switches of vector field without a reset, a contact damper making the field jump), an
impact stop (with or without a contact direction for sticking), a reset that changes the mode, a
sliding surface (flat or curved) of a belt with Coulomb friction, with modes, transitions, parameters,
states and time named like the engine's and the generated code's own words.  For each drawn model:

1. A sweep over the forcing frequency on SIMD lanes equals the independent Runner oracle of
   ``tests/engine/test_lanes.py`` bit for bit (samples, impacts by transition, Lyapunov exponent,
   transient used, final state and mode of every point): the lanes run the modes, switches, resets and
   sliding as the scalar driver does.
2. :func:`grazing.simulate`'s Jacobian ``d x_final / d x0`` (saltation matrices of switches and resets,
   the sliding entry's, the sliding field's variational equations) equals central differences of the
   flow, where the perturbed runs take the same transitions and no event lies near either end.  The
   tolerance: the engine locates events to ~1e-12 and keeps local errors near its tolerance 1e-12, so two
   runs 2h = 2e-6 apart differ by ~1e-12 more than their true difference; the quotient by 2h is off by
   ~1e-6, and its truncation error h^2 |x'''| ~ 1e-12 is below that.  2e-5 times the Jacobian's scale
   leaves a margin of twenty (as tests/core/test_random_models.py).

Each model compiles its kernels and lane functions (a few seconds): the default suite draws one model
of each structure (derandomized on CI: tests/conftest.py), the slow suite many.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import grazing
from grazing.core.options import SweepSettings
from grazing.engine.codegen import taylor_order
from grazing.errors import SimulationError
from grazing.sweeps.spec import sweep_spec
from tests.engine.test_lanes import assert_lanes_equal_the_oracle
from tests.random_models import MODE_KINDS, ModesSpec, modes_specs

PERIODS = 3
T0 = 0.3  # (periods: the start of the Jacobian's run)
FD_STEP = 1e-6
FD_TOL = 2e-5
END_MARGIN = 1e-3  # (periods: no event this close to either end of the Jacobian's run)
MAX_SCALE = 1e3  # (a Jacobian this large amplifies the engine's errors past FD_TOL: not compared)


def check_lanes(spec: ModesSpec, fresh: bool, lyapunov: bool, scalar_lanes: bool) -> None:
    """1: a sweep over the frequency on lanes against the Runner oracle (and lane by lane)."""
    model = spec.model()
    w = spec.param_names[3]
    values = model.params[w] * np.linspace(0.95, 1.05, 8)
    settings_ = SweepSettings(transient=20, periods=8, chunk_size=2, fresh=fresh, lyapunov=lyapunov)
    sw = dataclasses.replace(sweep_spec(model, w, values, settings=settings_), polish=False)
    kern = model.kernels(0, taylor_order(sw.tol))
    assert kern.NMODES == len(model.mode_names) >= 2
    assert_lanes_equal_the_oracle(sw, f"{spec.kind}, ", scalar=scalar_lanes, regroup=False)


def _events(sol: grazing.Solution) -> tuple[np.ndarray, list[int]]:
    """The times of a run's switches and impacts, and its transitions in order."""
    times = np.concatenate([sol.switches.t, sol.impacts.t])
    seq = sorted(zip(sol.switches.t.tolist(), sol.switches.transition.tolist()))
    seq += sorted(zip(sol.impacts.t.tolist(), ["impact"] * len(sol.impacts.t)))
    return times, [j for _, j in sorted(seq, key=lambda e: e[0])]


def check_jacobian(spec: ModesSpec) -> None:
    """2: simulate's Jacobian against central differences of the flow (see the module)."""
    model = spec.model()
    T = float(model.period)
    x0 = np.array(spec.initial_state())
    kw = dict(t0=T0 * T, periods=PERIODS, impacts="all")
    try:
        sol = grazing.simulate(model, x0, jacobian=True, **kw)
    except SimulationError:  # (impacts that accumulate on the stop, which has no sticking: one line)
        assume(False)
    times, seq = _events(sol)
    assume(len(seq) > 0 and sol.jacobian_valid)
    assume(
        np.all(np.abs(times - T0 * T) > END_MARGIN * T)
        and np.all(np.abs(times - sol.t_final) > END_MARGIN * T)
    )
    n = model.n_states
    J = sol.jacobian[:, :n]
    fd = np.empty_like(J)
    for j in range(n):
        up, down = x0.copy(), x0.copy()
        up[j] += FD_STEP
        down[j] -= FD_STEP
        try:
            a, b = grazing.simulate(model, up, **kw), grazing.simulate(model, down, **kw)
        except SimulationError:
            assume(False)
        assume(_events(a)[1] == seq == _events(b)[1])  # (the same transitions, in the same order)
        assume(a.mode_final == b.mode_final == sol.mode_final)
        fd[:, j] = (a.x_final - b.x_final) / (2 * FD_STEP)
    scale = max(1.0, float(np.max(np.abs(fd))))
    assume(scale <= MAX_SCALE)
    np.testing.assert_allclose(J, fd, rtol=0, atol=FD_TOL * scale, err_msg=f"{spec}")


@pytest.mark.parametrize("kind", MODE_KINDS)
@settings(max_examples=1, suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(data=st.data())
def test_random_models_with_modes(kind: str, data: st.DataObject) -> None:
    spec = data.draw(modes_specs((kind,)))
    check_lanes(spec, fresh=data.draw(st.booleans()), lyapunov=data.draw(st.booleans()), scalar_lanes=False)
    check_jacobian(spec)


@pytest.mark.slow
@settings(max_examples=24, suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(spec=modes_specs(), fresh=st.booleans(), lyapunov=st.booleans())
def test_random_models_with_modes_many(spec: ModesSpec, fresh: bool, lyapunov: bool) -> None:
    check_lanes(spec, fresh, lyapunov, scalar_lanes=True)
    check_jacobian(spec)
