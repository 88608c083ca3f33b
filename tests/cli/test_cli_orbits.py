"""CLI: orbit, graze, graze-curve, continue."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from grazing.cli import main


def run_json(argv, capsys):
    code = main([*argv, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_orbit_json(capsys):
    res = run_json(["orbit", "--theta-hat", "40", "--eta", "0.446"], capsys)
    assert res["period"] == 5 and res["impacts"] == 1 and res["stable"] is True
    assert len(res["state"]) == 2
    assert len(res["multipliers"]) == 2 and len(res["multipliers"][0]) == 2
    assert res["max_theta_deg"] == pytest.approx(40.0, abs=1e-9)  # it impacts: max angle is the stop


def test_orbit_nonimpacting_max_theta(capsys):
    res = run_json(["orbit", "--theta-hat", "40", "--eta", "0.40", "--period", "1"], capsys)
    assert res["impacts"] == 0 and res["period"] == 1
    assert 20 < res["max_theta_deg"] < 40


def test_graze_json(capsys):
    res = run_json(["graze", "--theta-hat", "40"], capsys)
    etas = [g["eta"] for g in res["grazings"]]
    assert etas == pytest.approx([0.4451, 0.5473], abs=2e-4)
    for g in res["grazings"]:
        assert set(g) >= {"eta", "multipliers", "abs_lambda", "t_graze"}
        assert 0 <= g["t_graze"] < 6.2832


def test_graze_curve_json(capsys, tmp_path):
    out = tmp_path / "curve.nc"
    res = run_json(["graze-curve", "--out", str(out)], capsys)
    assert 54 < res["theta_max_deg"] < 57
    assert 0.45 < res["eta_at_theta_max"] < 0.50
    assert len(res["curve"]) > 20
    assert out.exists()


def test_continue_json_and_netcdf(capsys, tmp_path):
    out = tmp_path / "branch.nc"
    argv = ["continue", "--param", "eta", "--start", "0.40", "--stop", "0.60", "--out", str(out)]
    res = run_json(argv, capsys)
    kinds = [s["kind"] for s in res["special"]]
    assert kinds == ["grazing", "grazing"]
    assert res["values"][0] == 0.40 and res["values"][-1] == pytest.approx(0.60)
    assert out.exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["orbit", "--r", "3"], "r = 3 is outside"),
        (["graze", "--eta-min", "0.5", "--eta-max", "0.4"], "need 0 < --eta-min < --eta-max"),
        (["continue", "--param", "eta", "--start", "0.4", "--stop", "0.4"], "must be finite and differ"),
        (["continue", "--param", "gamma", "--start", "0", "--stop", "1"], "unknown parameter 'gamma'"),
        (["continue", "--param", "eta", "--start", "0.4", "--stop", "0.5", "--out", "x.txt"],
         "--out must name a .nc file"),
        (["graze-curve", "--out", "/nonexistent/c.nc"], "does not exist"),
    ],
)  # fmt: skip
def test_errors_are_one_line(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = main(argv)
    _out, err = capsys.readouterr()
    assert code != 0
    assert message in err
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_newton_failure_is_reported(capsys):
    argv = ["orbit", "--eta", "0.4458", "--period", "2", "--initial", "0.6,0.6"]
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 1 and out == ""
    assert err.startswith("grazing: error: Newton did not converge to a period-2 orbit: residual")
    assert "after 30 iterations; try another initial guess" in err
    assert len(err.strip().splitlines()) == 1


# --------------------------------------------------------------------------
# issue 26: an unstable orbit from --initial; parameters in their display unit; --switch


NEG = [
    "--model",
    f"{Path(__file__).resolve().parents[1] / 'orbits' / 'negative_damping.py'}:negative_damping",
]


def run_text(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


def test_the_unstable_orbit_s_grazings_from_initial(capsys):
    """Every grazing command finds the unstable nonimpacting orbit from --initial (Newton's method on
    the flow through the stops) and its grazings where the closed form has them."""
    from tests.orbits.negative_damping import UPPER, ClosedForm

    cf = ClosedForm()
    first, second = cf.grazing_frequencies(UPPER)
    orbit = run_json(["orbit", *NEG, "--set", "w=0.7", "--initial", "0,0", "--period", "1"], capsys)
    assert orbit["state"] == pytest.approx(list(cf.state(0.7)), abs=1e-12)
    assert orbit["impacts"] == 0 and orbit["stable"] is False
    search = ["--param", "w", "--range", "0.5,1.5", "--initial", "0,0"]
    res = run_json(["graze", *NEG, *search], capsys)
    assert [g["value"] for g in res["grazings"]] == pytest.approx([first, second], rel=1e-10)
    assert all(g["abs_lambda"] > 1 and g["stop"] == "ceiling" for g in res["grazings"])
    res = run_json(["normal-form", *NEG, *search, "--which", "second"], capsys)
    assert res["value"] == pytest.approx(second, rel=1e-10) and res["abs_lambda"] > 1
    assert res["coefficients"]["accel"] == pytest.approx(UPPER * second**2, rel=1e-9)
    res = run_json(["continue", *NEG, "--param", "w", "--start", "0.5", "--stop", "1.5", "--virtual",
                    "--initial", "0,0"], capsys)  # fmt: skip
    graze = [(s["stop"], s["value"]) for s in res["special"] if s["kind"] == "grazing"]
    assert graze[0] == ("ceiling", pytest.approx(first, rel=1e-10))
    assert graze[-1] == ("ceiling", pytest.approx(second, rel=1e-10))
    assert not any(res["stable"])
    res = run_json(["graze-curve", *NEG, "--params", "w,upper", "--range", "0.5,1.5", "--start-value", "2",
                    "--initial", "0,0"], capsys)  # fmt: skip
    fold_w, fold_a = cf.fold()
    assert res["fold"] == {"w": pytest.approx(fold_w, rel=1e-8), "upper": pytest.approx(fold_a, rel=1e-12)}


def test_the_pendulum_s_unstable_orbit_from_initial(capsys):
    """α = 0.6, η = 0.4148: a saddle nonimpacting orbit between two stable ones.  Its grazing in θ̂
    (degrees) is where the stop meets its largest angle, which `orbit` reports from shooting alone;
    without --initial the search finds a stable orbit's grazing instead."""
    base = ["--alpha", "0.6", "--eta", "0.4148"]
    orbit = run_json(
        ["orbit", *base, "--theta-hat", "170", "--period", "1", "--initial", "-1.39,0.73"], capsys
    )
    assert orbit["impacts"] == 0 and not orbit["stable"]
    search = ["--param", "theta_hat", "--range", "60,120", *base]
    (g,) = run_json(["graze", *search, "--initial", "-1.39,0.73"], capsys)["grazings"]
    assert g["value"] == pytest.approx(orbit["max_theta_deg"], abs=1e-8)
    assert g["abs_lambda"] == pytest.approx(max(orbit["abs_multipliers"]), rel=1e-7)
    (stable,) = run_json(["graze", *search], capsys)["grazings"]
    assert stable["abs_lambda"] < 1 and abs(stable["value"] - g["value"]) > 10
    res = run_json(["normal-form", *search, "--initial", "-1.39,0.73"], capsys)
    assert res["value"] == pytest.approx(g["value"], abs=1e-8)


def test_continue_shows_the_parameter_in_its_display_unit_on_every_line(capsys):
    """θ̂ in degrees on the status line and on the special points' lines (it was radians on the
    first), the same number as the JSON, which keeps degrees; a parameter with a unit shows it."""
    argv = ["continue", "--param", "theta-hat", "--start", "30", "--stop", "50", "--eta", "0.44"]
    res = run_json(argv, capsys)
    (graze,) = [s for s in res["special"] if s["kind"] == "grazing"]
    # The period-2 orbit loses its impact where the period-1 nonimpacting orbit grazes (graze, JSON).
    (g,) = run_json(["graze", "--param", "theta_hat", "--range", "30,50", "--set", "eta=0.44"], capsys)[
        "grazings"
    ]
    assert graze["value"] == pytest.approx(g["value"], abs=1e-8) and 36 < g["value"] < 37
    assert res["values"][0] == pytest.approx(30.0)
    out = run_text(argv, capsys)
    assert f"ended at a grazing at theta_hat = {graze['value']:.10g} deg" in out
    assert f"  grazing          theta_hat = {graze['value']:.8g} deg   multipliers" in out
    assert "(stop stop)" not in out and "= 0.6" not in out
    out = run_text(
        ["continue", "--param", "theta_hat", "--start", "30", "--stop", "50", "--eta", "0.3"], capsys
    )
    assert "reached the bound theta_hat = 50 deg" in out
    out = run_text(["continue", *NEG, "--set", "w=0.7", "--param", "upper", "--start", "1", "--stop", "3",
                    "--virtual", "--initial", "0,0"], capsys)  # fmt: skip
    assert "reached the bound upper = 3 m" in out and "  grazing          upper = 1.7187815 m" in out


@pytest.mark.parametrize(
    "argv",
    [
        ["continue", "--param", "eta", "--start", "0.40", "--stop", "0.47"],
        ["continue", "--model", "impact-oscillator", "--param", "omega", "--start", "4", "--stop", "3"],
    ],
    ids=["pendulum", "impact-oscillator"],
)
def test_switch_from_a_nonimpacting_orbit_follows_it_physically(argv, capsys):
    """--switch is used: the nonimpacting orbit is followed with the stops (physical) up to its grazing,
    where the branch switches or says why not; without it the branch ignores the stops."""
    plain = run_json(argv, capsys)
    switched = run_json([*argv, "--switch"], capsys)
    assert plain["virtual"] is True and switched["virtual"] is False and switched["switch"] is True
    first = next(s["value"] for s in plain["special"] if s["kind"] == "grazing")
    assert switched["special"][-1]["value"] == pytest.approx(first, abs=1e-9)
    assert "switch" in switched["status"] and "can be followed with switch" not in switched["status"]


def test_a_parameter_named_like_an_option_leaves_the_option_alone(capsys, tmp_path, monkeypatch):
    """A model's parameters called ``out`` and ``period``: continuing in them still takes --out and
    --period (only the pendulum's options set parameters); --set of them is refused."""
    (tmp_path / "named.py").write_text(
        "import sympy as sp\n"
        "from grazing import HybridModel, Parameter\n"
        "x, v, t, out, period, wall = sp.symbols('x v t out period wall')\n"
        "MODEL = HybridModel('named', [x, v], t, [Parameter('out', 0.05, lower=0),\n"
        "    Parameter('period', 2.8, lower=0, lower_open=True), Parameter('wall', 1.0)],\n"
        "    vector_field=[v, -2 * out * v - x + sp.cos(period * t)], guard=wall - x, reset=[x, -0.8 * v],\n"
        "    period=2 * sp.pi / period, contact_direction=[0, 1])\n"
    )
    monkeypatch.chdir(tmp_path)
    model = ["continue", "--model", "named.py:MODEL"]
    res = run_json([*model, "--param", "out", "--start", "0.05", "--stop", "0.1", "--out", "b.nc"], capsys)
    assert res["out"] == "b.nc" and (tmp_path / "b.nc").exists()
    res = run_json([*model, "--param", "period", "--start", "2.8", "--stop", "3.2", "--period", "1"], capsys)
    assert res["period"] == 1 and res["values"][-1] == pytest.approx(3.2)
    code = main([*model, "--param", "period", "--start", "2.8", "--stop", "3.2", "--set", "period=3"])
    assert code == 2 and "--set period=3 is not used with --param period" in capsys.readouterr().err


# --------------------------------------------------------------------------
# issue 27: branch points, unlocated stability changes, switching at period-doublings and branch points

WALLED = [
    "--model",
    f"{Path(__file__).resolve().parents[1] / 'orbits' / 'symmetric_models.py'}:walled_pendulum",
]
SYMMETRIC = [*WALLED, "--set", "A=0.3", "--param", "Om", "--start", "1.2", "--stop", "0.6"]
BALL = (
    "--model bouncing-ball --param amplitude --start 1.3 --stop 1.6 --period 1 --initial 2.56,-2.51".split()
)
OLD_KEYS = {"params", "param", "period", "virtual", "values", "states", "multipliers", "stable", "impacts",
            "segments", "section_times", "switch", "special", "status", "out"}  # fmt: skip


def test_continue_tells_a_branch_point_from_a_fold_and_reaches_the_grazing(capsys):
    """A model file with a symmetric orbit: its symmetry-breaking branch point (it was reported as a
    fold) and, on the unstable branch, its grazing (it ended with "step size fell below 1e-06")."""
    res = run_json(["continue", *SYMMETRIC], capsys)
    assert set(res) >= OLD_KEYS | {"periods", "segment_status"}
    assert [s["kind"] for s in res["special"]] == ["branch point", "grazing"]
    bp, graze = res["special"]
    assert min(abs(complex(*z) - 1) for z in bp["multipliers"]) < 1e-9 and bp["switched"] is False
    # (the orbit is symmetric: both walls graze at the same value; which is located first is rounding's)
    ended = f"ended at a grazing at Om = {graze['value']:.10g} with stop "
    assert res["status"].startswith((ended + "'west'", ended + "'east'"))
    assert res["periods"] == [1] * len(res["values"]) and set(res["segments"]) == {0}
    out = run_text(["continue", *SYMMETRIC], capsys)
    assert f"  branch point     Om = {bp['value']:.8g}   multipliers +1.0000+0.0000i" in out
    assert "fold" not in out and "step size" not in out


def test_continue_switch_at_a_period_doubling(capsys):
    """The bouncing ball (r = 0.5, g = omega = 1): the period-1 orbit period-doubles at the closed form's
    amplitude; with --switch the branch goes on along the period-2 orbit, a second segment."""
    import math

    a_pd = math.sqrt((math.pi / 3) ** 2 + (2 * 1.25 / 2.25) ** 2)
    plain = run_json(["continue", *BALL], capsys)
    res = run_json(["continue", *BALL, "--switch"], capsys)
    assert set(plain["periods"]) == {1} and [s["kind"] for s in plain["special"]] == ["period-doubling"]
    pd = res["special"][0]
    assert pd["kind"] == "period-doubling" and pd["switched"] is True
    assert pd["value"] == pytest.approx(a_pd, abs=1e-8) == plain["special"][0]["value"]
    k = res["segments"].index(1)
    assert res["periods"][:k] == [1] * k and res["periods"][k:] == [2] * (len(res["periods"]) - k)
    assert res["segment_status"] == [
        f"switched at the period-doubling at amplitude = {pd['value']:.10g} to the period-2 orbit born there",
        "reached the bound amplitude = 1.6",
    ]
    assert res["status"] == "reached the bound amplitude = 1.6" and res["values"][-1] == 1.6
    out = run_text(["continue", *BALL, "--switch"], capsys)
    assert "points of the period-1 orbit in 2 segments (switched at: period-doubling; periods 1, 2)" in out
    assert (
        "  segment 1, period 2 (from the period-doubling at amplitude = 1.5268237): reached the bound" in out
    )


def test_continue_switch_at_a_branch_point_follows_both_directions(capsys):
    res = run_json(["continue", *SYMMETRIC, "--switch"], capsys)
    assert res["segment_status"][0].startswith("switched at the branch point at Om = ")
    assert res["segment_status"][0].endswith("to the other branch through it (both directions)")
    halves = [s for s in res["special"] if s["kind"] == "grazing" and s["switched"]][:2]
    # the two asymmetric orbits lose their weaker impact at the same value, one on each wall
    assert halves[0]["value"] == pytest.approx(halves[1]["value"], abs=1e-10)
    assert {halves[0]["stop"], halves[1]["stop"]} == {"east", "west"}


def test_continue_reports_an_unlocated_stability_change(capsys, monkeypatch):
    """Steps too coarse to locate it (the command's --max-step always refines where stability changes;
    here the library is made to step from c = 1.2 to c = -0.5 at once): one line says so."""
    import grazing.orbits
    from grazing.orbits import PalcSettings

    real = grazing.orbits.continue_orbit

    def coarse(*args, **kwargs):
        return real(*args, **{**kwargs, "settings": PalcSettings(ds=2.0, ds_max=2.0, ds_refine=2.0)})

    monkeypatch.setattr(grazing.orbits, "continue_orbit", coarse)
    model = f"{Path(__file__).resolve().parents[1] / 'orbits' / 'any_damping.py'}:any_damping"
    argv = ["continue", "--model", model, "--param", "c", "--start", "1.2", "--stop", "-0.5", "--virtual",
            "--period", "1", "--initial", "0,0"]  # fmt: skip
    (unlocated,) = run_json(argv, capsys)["special"]
    assert unlocated["kind"] == "unlocated" and unlocated["between"] == [1.2, -0.5]
    assert unlocated["value"] == pytest.approx(0.35)
    assert unlocated["note"].startswith(
        "unlocated stability change between c = 1.2 and c = -0.5: stable -> 2"
    )
    out = run_text(argv, capsys)
    assert f"  unlocated        {unlocated['note']}\n" in out
