"""The built-in rocking block (Housner) against closed forms.

Free rocking (no base motion): between impacts ``E = theta'^2 / 2 + p^2 cos(alpha - |theta|)`` is
conserved, so from an amplitude ``theta_m`` the block reaches ``theta = 0`` after the quadrature
``int_0^theta_m dtheta / sqrt(2 p^2 (cos(alpha - theta_m) - cos(alpha - theta)))`` (computed here with
the substitution ``theta = theta_m - u^2``, smooth, to ~1e-14), and each impact multiplies the angular
velocity by Housner's ``1 - 3/2 sin^2 alpha`` (or ``r``): impact times, the energy of every sample and
the restitution at each impact.  Small angles: the block is the piecewise-linear
``theta'' = p^2 (theta -+ alpha) - p^2 a cos(omega t)`` (tests/piecewise_exact.py with the linear reset);
the neglected terms are cubic in the angles (``sin y = y - y^3/6``, ``cos y = 1 - y^2/2``), so with
``alpha``, ``theta`` and ``a`` scaled by ``s`` the difference scaled by ``s`` is of order ``s^2``: it must
fall by 4 when ``s`` halves.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

import grazing
from grazing.models import rocking_block
from grazing.models.rocking_block import housner_restitution
from tests.piecewise_exact import LinearMode, PiecewiseLinearModel


def fall_time(theta_m, p, alpha):
    """Time from rest at ``theta_m`` (0 < theta_m < alpha) to ``theta = 0``, free rocking."""

    def integrand(u):  # theta = theta_m - u^2; cos(alpha - theta_m) - cos(alpha - theta) without cancellation
        if u == 0.0:
            return 2.0 / math.sqrt(2 * p**2 * math.sin(alpha - theta_m))
        return 2 * u / math.sqrt(4 * p**2 * math.sin(alpha - theta_m + u * u / 2) * math.sin(u * u / 2))

    return quad(integrand, 0.0, math.sqrt(theta_m), epsabs=0.0, epsrel=1e-13, limit=200)[0]


def free_rocking(theta0, p, alpha, rho, impacts):
    """Impact times, speeds before each impact and the amplitude of each half-cycle (from rest at theta0)."""
    t, amp, times, speeds, amps = 0.0, theta0, [], [], [theta0]
    for i in range(impacts):
        t += fall_time(amp, p, alpha) * (1 if i == 0 else 2)
        speed = math.sqrt(2 * p**2 * (math.cos(alpha - amp) - math.cos(alpha)))
        times.append(t)
        speeds.append(speed)
        amp = alpha - math.acos(math.cos(alpha) + (rho * speed) ** 2 / (2 * p**2))  # the next amplitude
        amps.append(amp)
    return np.array(times), np.array(speeds), amps


FREE = [{"p": 1.3, "alpha": 0.25}, {"p": 2.0, "alpha": 0.4, "housner": 0.0, "r": 0.7}]


@pytest.mark.parametrize("values", FREE)
def test_free_rocking_against_its_quadrature(values):
    m = rocking_block(a=0.0, **values)
    p, alpha = m.params["p"], m.params["alpha"]
    rho = housner_restitution(alpha) if m.params["housner"] == 1.0 else m.params["r"]
    theta0 = 0.8 * alpha
    times, speeds, amps = free_rocking(theta0, p, alpha, rho, 7)
    T = (times[5] + times[6]) / 2 / 40  # 40 samples, the last between the 6th and 7th impacts
    sol = grazing.simulate(m.with_params(omega=2 * math.pi / T), [theta0, 0.0], periods=40, impacts="all")
    assert len(sol.impacts) == len(sol.switches) == 6
    assert np.abs(sol.impacts.t - times[:6]).max() < 1e-11
    assert np.abs(np.abs(sol.impacts.state[:, 1]) - speeds[:6]).max() < 1e-11
    assert np.abs(sol.impacts.state[:, 0]).max() < 1e-12
    # the restitution at each impact, exactly; the corners alternate
    assert np.allclose(sol.switches.state[:, 1] / sol.impacts.state[:, 1], rho, rtol=1e-14, atol=0)
    assert [sol.switches.target(i) for i in range(6)] == ["left_corner", "right_corner"] * 3
    # energy of every sample: that of its half-cycle
    energy = sol.samples[:, 1] ** 2 / 2 + p**2 * np.cos(alpha - np.abs(sol.samples[:, 0]))
    half = np.searchsorted(times, sol.t)
    assert np.abs(energy - p**2 * np.cos(alpha - np.array(amps)[half])).max() < 1e-11
    # the mode of every sample is the side of theta = 0 it is on
    assert sol.modes.tolist() == (sol.samples[:, 0] < 0).astype(int).tolist()
    assert sol.mode_final == ("right_corner", "left_corner")[half[-1] % 2]


def test_forced_restitution_at_each_impact():
    for values, rho in (({}, housner_restitution(0.2)), ({"housner": 0.0, "r": 0.85}, 0.85)):
        m = rocking_block(**values)
        sol = grazing.simulate(m, [0.1, 0.0], periods=10, impacts="all", trajectory=50)
        assert len(sol.impacts) >= 15
        assert np.abs(sol.impacts.state[:, 0]).max() < 1e-12
        assert np.allclose(sol.switches.state[:, 1] / sol.impacts.state[:, 1], rho, rtol=1e-14, atol=0)
        for start, end, k in sol.mode_spans():  # the trajectory stays on the side of its mode
            inside = (sol.trajectory_t > start + 1e-9) & (sol.trajectory_t < end - 1e-9)
            assert np.all((sol.trajectory[inside, 0] < 0) == (k == 1))


def linearised(q):
    """The small-angle block as a piecewise-linear model with the linear reset ``diag(1, r)``."""
    A = np.array([[0.0, 1.0], [q["p"] ** 2, 0.0]])
    b = np.array([0.0, -(q["p"] ** 2) * q["a"]])
    R = np.diag([1.0, q["r"]])
    d = np.array([0.0, q["p"] ** 2 * q["alpha"]])
    right = LinearMode(A, b, -d, ((np.array([1.0, 0.0]), 0.0, 1, R),))
    left = LinearMode(A, b, d, ((np.array([-1.0, 0.0]), 0.0, 0, R),))
    return PiecewiseLinearModel([right, left], q["omega"])


def scaled_difference(s):
    """max |nonlinear - linearised| / s over 3 periods, with alpha, theta0 and a scaled by s."""
    m = rocking_block(alpha=0.2 * s, a=0.3 * s, housner=0.0, r=0.9)
    x0 = [0.1 * s, 0.0]
    sol = grazing.simulate(m, x0, periods=3, impacts="all")
    ref = linearised(dict(m.params))
    x, mode, t_prev, diffs, events = np.array(x0), 0, 0.0, [], 0
    for ts, xs in zip(sol.t, sol.samples):
        x, mode, _, ev = ref.run(x, mode, t_prev, ts)
        t_prev, events = ts, events + len(ev)
        diffs.append(np.abs(xs - x).max() / s)
    assert events == len(sol.impacts) >= 4  # the same impacts, so the samples compare
    return max(diffs)


def test_small_angles_tend_to_the_linearised_block():
    e1, e2, e3 = (scaled_difference(s) for s in (0.2, 0.1, 0.05))
    assert e1 < 1e-3
    assert 3.8 < e1 / e2 < 4.2 and 3.8 < e2 / e3 < 4.2, (e1, e2, e3)


def test_forced_rocking_against_scipy():
    """The forced nonlinear equations (Makris & Konstantinidis 2003, eq. 1), written here from the
    source, integrated by scipy (DOP853 at rtol 1e-13) from impact to impact: samples to 1e-9."""
    from scipy.integrate import solve_ivp

    m = rocking_block(a=0.35, omega=3.5, alpha=0.3, p=1.5)
    q = dict(m.params)
    rho = housner_restitution(q["alpha"])

    def field(t, y):
        sgn = 1.0 if y[0] > 0 or (y[0] == 0 and y[1] > 0) else -1.0
        phi = q["alpha"] * sgn - y[0]
        return [y[1], -(q["p"] ** 2) * (math.sin(phi) + q["a"] * math.cos(q["omega"] * t) * math.cos(phi))]

    def landing(t, y):
        return y[0]

    landing.terminal = True
    sol = grazing.simulate(m, [0.1, 0.0], periods=6, impacts="all")
    assert np.abs(sol.samples[:, 0]).max() < q["alpha"]  # (rocking, not overturning)
    y, t, times = [0.1, 0.0], 0.0, []
    for ts, xs in zip(sol.t, sol.samples):
        while True:
            run = solve_ivp(field, (t, ts), y, method="DOP853", rtol=1e-13, atol=1e-15, events=landing)
            if run.status == 1 and run.t_events[0][0] < ts:
                t = float(run.t_events[0][0])
                speed = rho * run.y_events[0][0][1]
                y = [math.copysign(1e-300, speed), speed]  # theta = 0 on the new corner's side
                times.append(t)
                continue
            y, t = list(run.y[:, -1]), ts
            break
        assert np.abs(np.array(y) - xs).max() < 1e-9, (ts, y, xs)
    assert len(times) == len(sol.impacts) >= 4
    assert np.abs(np.array(times) - sol.impacts.t).max() < 1e-9


def test_free_rocking_comes_to_rest_in_one_line():
    """Unforced, the impacts accumulate (their intervals fall geometrically) at the sum of the half-cycles
    of the quadrature: a one-line error there, not a hang."""
    import re

    p, alpha, rho, amp = 1.0, 0.2, housner_restitution(0.2), 0.1
    t_rest = fall_time(amp, p, alpha)
    while amp > 1e-12:
        speed = math.sqrt(2 * p**2 * (math.cos(alpha - amp) - math.cos(alpha)))
        amp = alpha - math.acos(math.cos(alpha) + (rho * speed) ** 2 / (2 * p**2))
        t_rest += 2 * fall_time(amp, p, alpha)
    with pytest.raises(grazing.SimulationError, match=r"^impacts from mode to mode accumulate") as info:
        grazing.simulate(rocking_block(a=0.0, p=p, alpha=alpha), [0.1, 0.0], periods=20)
    assert "\n" not in str(info.value) and "'onto_left', 'onto_right'" in str(info.value)
    t = float(re.search(r"at t = (\S+) ", str(info.value)).group(1))
    assert abs(t - t_rest) < 1e-4 * t_rest, (t, t_rest)


def overturn_time(theta0, p, alpha):
    """Time from rest at ``theta0`` (alpha < theta0 < pi/2) to ``theta = pi/2``, free: the quadrature of
    ``theta'^2 / 2 = p^2 (cos(alpha - theta0) - cos(alpha - theta))``, with ``theta = theta0 + u^2``."""

    def integrand(u):  # cos(alpha - theta0) - cos(alpha - theta) = 2 sin(theta0 + u^2/2 - alpha) sin(u^2/2)
        if u == 0.0:
            return 2.0 / math.sqrt(2 * p**2 * math.sin(theta0 - alpha))
        return 2 * u / math.sqrt(4 * p**2 * math.sin(theta0 + u * u / 2 - alpha) * math.sin(u * u / 2))

    return quad(integrand, 0.0, math.sqrt(math.pi / 2 - theta0), epsabs=0.0, epsrel=1e-13, limit=200)[0]


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_free_overturning_against_its_quadrature(side):
    """Released past its slenderness, the unforced block falls onto its side at ``|theta| = pi/2`` at the
    time of the energy quadrature, with the energy's speed there, and lies there: ``(+-pi/2, 0)`` in the
    mode ``overturned`` at every later sample."""
    p, alpha, theta0 = 1.3, 0.25, 0.3
    m = rocking_block(a=0.0, p=p, alpha=alpha)
    t_side = overturn_time(theta0, p, alpha)
    speed = math.sqrt(2 * p**2 * (math.cos(alpha - theta0) - math.sin(alpha)))
    start = "right_corner" if side > 0 else "left_corner"
    sol = grazing.simulate(m, [side * theta0, 0.0], periods=10, impacts="all", mode=start)
    assert t_side < sol.t[3]  # (several samples lie after it)
    name = "overturn_right" if side > 0 else "overturn_left"
    assert [sol.switches.name(i) for i in range(len(sol.switches))] == [name]
    assert [m.stop_names[j] for j in sol.impacts.stop] == [name]
    assert abs(sol.impacts.t[0] - t_side) < 1e-11 and abs(sol.switches.t[0] - t_side) < 1e-11
    assert np.abs(sol.impacts.state[0] - [side * math.pi / 2, side * speed]).max() < 1e-11
    assert sol.switches.state[0].tolist() == [side * math.pi / 2, 0.0]
    after = sol.t > t_side
    assert np.all(sol.samples[after] == [side * math.pi / 2, 0.0])
    assert {sol.mode_names[k] for k in sol.modes[after]} == {"overturned"} and sol.mode_final == "overturned"
    assert np.all(np.abs(sol.samples[~after, 0]) < math.pi / 2)


def test_forced_overturning_against_scipy():
    """Forced hard (a = 0.5, beyond tan(alpha) = 0.31), the block rocks on both corners, then overturns: the
    landings and the overturning (``|theta| = pi/2``, a terminal event of the scipy reference of
    :func:`test_forced_rocking_against_scipy`'s equations) to 1e-9, the samples before it to 1e-9 and
    ``(+-pi/2, 0)`` after it."""
    from scipy.integrate import solve_ivp

    m = rocking_block(a=0.5, omega=3.0, alpha=0.3, p=1.5)
    q = dict(m.params)
    rho = housner_restitution(q["alpha"])

    def field(t, y):
        sgn = 1.0 if y[0] > 0 or (y[0] == 0 and y[1] > 0) else -1.0
        phi = q["alpha"] * sgn - y[0]
        return [y[1], -(q["p"] ** 2) * (math.sin(phi) + q["a"] * math.cos(q["omega"] * t) * math.cos(phi))]

    def landing(t, y):
        return y[0]

    def side(t, y):
        return math.pi / 2 - abs(y[0])

    landing.terminal = side.terminal = True
    sol = grazing.simulate(m, [0.1, 0.0], periods=8, impacts="all")
    y, t, times, over = [0.1, 0.0], 0.0, [], None
    for ts, xs in zip(sol.t, sol.samples):
        while over is None:
            run = solve_ivp(
                field, (t, ts), y, method="DOP853", rtol=1e-13, atol=1e-15, events=(landing, side)
            )
            if run.status == 1 and len(run.t_events[1]):
                over = float(run.t_events[1][0])
                y = [math.copysign(math.pi / 2, run.y_events[1][0][0]), 0.0]
                break
            if run.status == 1:
                t = float(run.t_events[0][0])
                speed = rho * run.y_events[0][0][1]
                y = [math.copysign(1e-300, speed), speed]
                times.append(t)
                continue
            y, t = list(run.y[:, -1]), ts
            break
        assert np.abs(np.array(y) - xs).max() < 1e-9, (ts, y, xs)
    assert over is not None and len(times) >= 4  # (it rocked on both corners first)
    assert np.abs(np.array([*times, over]) - sol.impacts.t).max() < 1e-9
    assert sol.switches.name(len(sol.switches) - 1).startswith("overturn_") and sol.mode_final == "overturned"
    assert sol.t[-1] > over + 2 * m.period  # (samples after it, all on the side)


def test_basins_name_the_overturned_block_once_a_side():
    """On a grid of initial states the overturned blocks end on two attractors, the block on either side
    (``(+-pi/2, 0)``, period 1), not on as many one-cell "chaotic" sets as there are spinning blocks
    (before the mode ``overturned``: 20 attractors on this grid, their samples at ``|theta|`` in the
    thousands)."""
    from grazing.attractors import basins

    ds = basins(rocking_block(a=0.15), (-0.3, 0.3), (-0.6, 0.6), (8, 8), workers=1)
    points = ds.points.values[:, 0, :]
    side = np.isclose(np.abs(points[:, 0]), math.pi / 2, rtol=0, atol=1e-12) & (points[:, 1] == 0)
    assert sorted(np.sign(points[side, 0]).tolist()) == [-1.0, 1.0]
    assert (ds.period.values[side] == 1).all() and ds["count"].values[side].sum() >= 32  # (half the grid)
    assert not np.any(np.abs(ds.points.values[..., 0]) > math.pi / 2 + 1e-12)  # (nothing spins on)
    assert ds.sizes["attractor"] <= 4, ds.kind.values
    assert set(ds["modes"].values[side, 0].tolist()) == {"overturned"}  # (named by the mode they are in)
    rocking = ~side & (ds.period.values == 1)  # (the rocking orbit: on the side of its corner)
    assert rocking.sum() == 1
    assert ds["modes"].values[rocking, 0].tolist() == [
        "right_corner" if points[rocking, 0][0] > 0 else "left_corner"
    ]
