"""The grazing of a switching surface where a branch followed by multiple shooting on its switches ends.

The model has unusual names (states ``lurch``/``sway``, time ``tick``, modes ``calm``/``fore``/``aft``)
and two soft stops at different distances (``lip`` ahead, ``rim`` behind) around an inverted (saddle)
middle: its period-1 orbit through both stops is strongly unstable (a multiplier ~1e7 to 1e9), so
single shooting stalls and the continuation in ``lip`` goes on by multiple shooting, cut at the
switches (:mod:`grazing.orbits.segments`).  As ``lip`` grows the orbit's excursion into ``fore`` shrinks
to nothing: it grazes the surface ``lurch = lip``.  There the segmented equations are singular (the
excursion's two switches meet) and the branch must end at the grazing, located.

The reference uses nothing of grazing's engine.  The grazing orbit never enters ``fore``, whose field
holds ``lip``: it is the orbit through ``calm`` and ``aft`` alone (independent of ``lip``), and the
grazing value of ``lip`` is that orbit's largest ``lurch`` (where ``sway = 0`` on its ``calm``
stretch).  That orbit is solved as a boundary-value problem in its switch times and states with each
mode's exact flow (matrix exponentials, tests/piecewise_exact.py) by ``fsolve``, its switch times
checked by Brent's method, the contact by Brent's method on ``sway``, its monodromy from the contact the
product of the exponentials and the saltation matrices.
"""

from __future__ import annotations

import json

import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq, fsolve

import grazing
from grazing.cli import main
from grazing.orbits import continue_orbit, find_orbit
from grazing.orbits.continuation import BranchEnd
from grazing.orbits.kinds import SpecialKind
from grazing.orbits.segmented_grazing import excursions, extrapolated_grazing
from tests.orbits.test_segments_at_switches import GUESS, VALUES, exact_orbit, two_soft_stops
from tests.piecewise_exact import LinearMode, PiecewiseLinearModel

SOURCE = """\
import sympy as sp
from grazing import HybridModel, Mode, Parameter, Transition

lurch, sway, tick = sp.symbols("lurch sway tick")
visc, gust, beat, lip, rim, give, ooze = sp.symbols("visc gust beat lip rim give ooze")
base = -2 * visc * sway + lurch + gust * sp.cos(beat * tick)
LOPSIDED = HybridModel(
    "lopsided", [lurch, sway], tick,
    [Parameter(str(p), v) for p, v in zip((visc, gust, beat, lip, rim, give, ooze),
                                          (0.02, 1.0, 0.27, 0.4, 0.4, 0.5, 0.1))],
    modes=[Mode("calm", [sway, base]),
           Mode("fore", [sway, base - give * (lurch - lip) - ooze * sway]),
           Mode("aft", [sway, base - give * (lurch + rim) - ooze * sway])],
    transitions=[Transition("hit_fore", "calm", "fore", lip - lurch),
                 Transition("off_fore", "fore", "calm", lurch - lip),
                 Transition("hit_aft", "calm", "aft", lurch + rim),
                 Transition("off_aft", "aft", "calm", -rim - lurch)],
    period=2 * sp.pi / beat,
)
"""
"""The model, as a file the CLI loads (``--model PATH:LOPSIDED``) and the tests execute."""

P = {"visc": 0.02, "gust": 1.0, "beat": 0.27, "lip": 0.4, "rim": 0.4, "give": 0.5, "ooze": 0.1}
CALM, AFT = 0, 1  # (the reference's modes: fore is never entered by the grazing orbit)
X1 = np.array([1.0, 0.0])


def lopsided():
    namespace: dict = {}
    exec(SOURCE, namespace)
    return namespace["LOPSIDED"]


def reference() -> PiecewiseLinearModel:
    calm = np.array([[0.0, 1.0], [1.0, -2 * P["visc"]]])
    aft = np.array([[0.0, 1.0], [1.0 - P["give"], -2 * P["visc"] - P["ooze"]]])
    b, r = np.array([0.0, P["gust"]]), P["rim"]
    return PiecewiseLinearModel(
        [
            LinearMode(calm, b, np.zeros(2), ((X1, r, AFT),)),
            LinearMode(aft, b, np.array([0.0, -P["give"] * r]), ((-X1, -r, CALM),)),
        ],
        P["beat"],
    )


GRAZING_GUESS = [-0.0030278, 0.2642879, 18.656802, -0.4, -0.3293725, 27.64371, -0.4, 0.2889759]
"""``(x0, t1, s1, t2, s2)`` of the grazing orbit from the section ``t = T / 4`` in ``calm`` (``t1``, ``s1``:
time and state of ``hit_aft``; ``t2``, ``s2``: of ``off_aft``), roughly: ``fsolve``'s start."""


def exact_grazing() -> dict:
    """The orbit through ``calm`` and ``aft`` alone from the section ``t0 = T / 4`` in ``calm``, and its
    highest ``lurch``: the grazing value of ``lip``, with the contact's time and state, ``L_f^2 h``
    there and the monodromy from it."""
    ref = reference()
    T, r = ref.period, P["rim"]
    t0 = T / 4

    def equations(u):  # u = (x0, t1, s1, t2, s2)
        y1 = ref.flow(CALM, u[:2], t0, u[2])
        y2 = ref.flow(AFT, u[3:5], u[2], u[5])
        back = ref.flow(CALM, u[6:8], u[5], t0 + T)
        return [y1[0] + r, *(u[3:5] - y1), -r - y2[0], *(u[6:8] - y2), *(back - u[:2])]

    u = np.array(GRAZING_GUESS)
    u, _, _, msg = fsolve(equations, u, xtol=1e-15, full_output=True)
    assert np.abs(equations(u)).max() < 1e-11, msg  # (a segment's rounding: exp(13) eps, the saddle's)
    t1, t2 = u[2], u[5]
    # each switch again by Brent's method on its own segment, and no other switch
    assert abs(ref.first_exit(CALM, u[:2], t0, t0 + 1.2 * (t1 - t0))[0] - t1) < 1e-11
    assert abs(ref.first_exit(AFT, u[3:5], t1, t1 + 1.2 * (t2 - t1))[0] - t2) < 1e-11
    assert ref.first_exit(CALM, u[6:8], t2, t0 + T) is None
    # the highest lurch on the calm stretch from off_aft round to hit_aft: where sway = 0 (Brent)
    ts = np.linspace(t2, t1 + T, 801)
    lurch = np.array([ref.flow(CALM, u[6:8], t2, t)[0] for t in ts])
    k = int(np.argmax(lurch))
    tc = brentq(
        lambda t: ref.flow(CALM, u[6:8], t2, t)[1],
        ts[k - 1],
        ts[k + 1],
        xtol=1e-15,
        rtol=4 * np.finfo(float).eps,
    )
    xc = ref.flow(CALM, u[6:8], t2, tc)
    assert lurch.max() <= xc[0] + 1e-12  # (the orbit touches lurch = lip there alone)

    def saltation(k_from, k_to, y, t):
        fm, fp = ref.f(k_from, y, t), ref.f(k_to, y, t)
        return np.eye(2) + np.outer(fp - fm, X1) / (X1 @ fm)

    Ac, Aa = ref.modes[CALM].A, ref.modes[AFT].A
    y1, y2 = u[3:5], u[6:8]
    M = (
        expm(Ac * (tc - t2)) @ saltation(AFT, CALM, y2, t2) @ expm(Aa * (t2 - t1))
        @ saltation(CALM, AFT, y1, t1) @ expm(Ac * (t1 + T - tc))
    )  # fmt: skip
    accel = -ref.f(CALM, xc, tc)[1]  # (h = lip - lurch: L_f h = -sway, L_f^2 h = -sway')
    return {"lip": xc[0], "t": tc, "state": xc, "monodromy": M, "accel": accel, "period": T}


def start_orbit():
    m = lopsided()
    x, _, _ = exact_orbit(dict(VALUES), GUESS[0.27])  # (lip = rim = edge: the symmetric model's orbit)
    return m, find_orbit(m, x, period=1, t0=m.period / 4, mode="calm")


def test_a_switch_cut_branch_ends_at_its_switching_surface_grazing_located():
    m, orbit = start_orbit()
    assert np.abs(orbit.multipliers).max() > 1e7
    branch = continue_orbit(m, "lip", 0.4, 3.0, orbit=orbit)
    assert "by multiple shooting from lip = " in branch.status, branch.status  # (single shooting stalled)
    assert branch.outcome is BranchEnd.GRAZING, branch.status
    assert (
        branch.status.startswith("ended at a grazing at lip = 0.93187948") and "'hit_fore'" in branch.status
    )
    (sp_,) = branch.special
    g = sp_.grazing
    assert sp_.kind == "grazing" and g is not None and m.stop_names[sp_.stop] == "hit_fore" == g.stop_name
    ref = exact_grazing()
    assert abs(sp_.param - ref["lip"]) < 1e-11, sp_.param - ref["lip"]  # (3.5e-13 measured)
    assert sp_.precision < 1e-10 and g.model.params["lip"] == sp_.param
    assert np.abs(g.contact - ref["state"]).max() < 1e-10, g.contact - ref["state"]
    lag = (g.t_graze - ref["t"]) / ref["period"]
    assert abs(lag - round(lag)) * ref["period"] < 1e-9
    assert g.mode == "calm" and g.switches == 2 and g.impacts == 0
    assert g.accel > 0 and abs(g.accel - ref["accel"]) < 1e-10
    M = ref["monodromy"]
    assert np.abs(M).max() > 1e8  # (strongly unstable at the grazing too)
    assert np.abs(g.monodromy - M).max() < 1e-9 * np.abs(M).max(), g.monodromy - M
    mu = max(np.linalg.eigvals(M), key=abs)
    assert abs(g.multipliers[0] - mu) < 1e-9 * abs(mu)


def test_the_cli_continue_reports_the_grazing(tmp_path, capsys):
    path = tmp_path / "lopsided.py"
    path.write_text(SOURCE)
    m, orbit = start_orbit()
    # (the CLI's section is t = 0, where the orbit is in aft)
    x0 = grazing.simulate(m, orbit.state, t0=orbit.t0, periods=1, phase=0.0, mode="calm").x_final
    argv = ["continue", "--model", f"{path}:LOPSIDED", "--param", "lip", "--start", "0.4", "--stop", "3",
            "--initial", ",".join(repr(float(v)) for v in x0), "--mode", "aft"]  # fmt: skip
    code = main([*argv, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    res = json.loads(out)
    ref = exact_grazing()
    (sp_,) = res["special"]
    assert sp_["kind"] == "grazing" and sp_["stop"] == "hit_fore"
    assert abs(sp_["value"] - ref["lip"]) < 1e-11 and sp_["precision"] < 1e-10
    assert res["status"].startswith("ended at a grazing at lip = 0.93187948")
    assert main([*argv, "--switch"]) == 0  # (on past it: the orbit without the excursion, by segments too)
    out = capsys.readouterr().out
    line = next(s for s in out.splitlines() if s.strip().startswith("grazing"))
    assert "lip = 0.93187949" in line and "(stop hit_fore)" in line and "(switched here)" in line, out
    assert "segment 0, period 1: ended at a grazing at lip = 0.93187948" in out
    assert "switched to the orbit with the new switches of mode" in out
    assert "last point: mode aft, switches per period: off_aft, hit_aft" in out


def test_a_symmetric_orbit_grazing_both_soft_stops_at_once_is_a_located_double_grazing():
    """The symmetric model of test_segments_at_switches (one ``edge`` for both stops): as ``edge`` grows
    both excursions shrink together, and the orbit grazes both surfaces at once (codimension two, but for
    the symmetry).  The grazing orbit is then the free saddle's forced response alone, ``Re(X exp(i w t))``
    with ``X = (i w I - A)^-1 b``, and ``edge = |X_1|`` there.  One contact cannot be solved for with the
    other excursion shrunk to nothing as well; each excursion's time ``s`` is extrapolated to zero
    (``edge = edge* + k s^2 + ...``) and the two agree: a double grazing, located."""
    m = two_soft_stops(freq=0.27)
    x, _, _ = exact_orbit(dict(m.params), GUESS[0.27])
    orbit = find_orbit(m, x, period=1, t0=m.period / 4, mode="middle")
    branch = continue_orbit(m, "edge", 0.4, 3.0, orbit=orbit)
    A = np.array([[0.0, 1.0], [1.0, -2 * m.params["damp"]]])
    X = np.linalg.solve(1j * m.params["freq"] * np.eye(2) - A, np.array([0.0, m.params["amp"]]))
    edge = abs(X[0])
    assert branch.outcome is BranchEnd.DOUBLE_GRAZING, branch.status
    assert branch.status.startswith("ended at a double grazing at edge = 0.93200609"), branch.status
    (sp_,) = branch.special
    assert sp_.kind == "double grazing" and sp_.kind is SpecialKind.DOUBLE_GRAZING
    assert sp_.precision < 1e-10 and "'into_port'" in sp_.note and "'into_stbd'" in sp_.note
    assert abs(sp_.param - edge) < 1e-10, sp_.param - edge
    # the extrapolation itself, from points short of the stall (the last of them off by more than
    # 1e-10): its stated precision bounds its error (which points these are depends on the rounding of
    # the branch: 1e-11 or 9e-9 off under different OpenBLAS kernels, each within its stated precision)
    early, values = branch.orbits[:-6], branch.values[:-6]
    assert abs(values[-1] - edge) > 1e-10
    i = min(excursions(early[-1]), key=lambda e: e[1])[0]
    found = extrapolated_grazing(early, values, i)
    assert found is not None and found[1] < 1e-8, (found, edge)
    assert abs(found[0] - edge) <= max(found[1], 1e-10), (found, edge)
