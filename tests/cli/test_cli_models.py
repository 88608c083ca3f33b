"""Every analysis command takes any model: --model (built-in or FILE.py:OBJECT), --set, --param, --stop-name.

Smoke runs of every command on every built-in model with a second stop or more
states, the JSON keys scripts rely on (``impacts_per_stop``, ``impact_stops``,
``impacts_per_period_by_stop``, a grazing's ``stop`` and ``value``), and bad
model input: one line on stderr, a non-zero exit.
"""

from __future__ import annotations

import json
import math

import pytest

from grazing.cli import main
from tests.free_orbit import grazing_degrees


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def run_json(argv, capsys):
    code, out, err = run([*argv, "--json"], capsys)
    assert code == 0, err
    return json.loads(out)


TWO = ["--model", "two-sided-oscillator"]


def test_simulate_two_stops_json(capsys):
    res = run_json(["simulate", *TWO, "--set", "omega=0.8", "--transient", "50", "--periods", "4"], capsys)
    assert res["impacts_per_stop"] == {"right": 4, "left": 4}
    assert res["impact_stops"] == ["right", "left"] * 4 or res["impact_stops"] == ["left", "right"] * 4
    assert set(res["params"]) == {"zeta", "amp", "omega", "gap_left", "gap_right", "r"}


def test_simulate_pendulum_json_lists_both_faces(capsys):
    res = run_json(["simulate", "--transient", "100", "--periods", "5"], capsys)
    assert res["impacts_per_stop"] == {"stop": 1, "back": 0}
    assert res["params"]["case"] == "B" and "theta_hat_deg" in res["params"]


# What `orbit --period 1` must give from each model's default start: an orbit, or the one line why not.
ORBITS = {
    "two-sided-oscillator": {"impacts": 2},  # period 1, one impact on each stop, stable
    "impact-damper": {"impacts": 2},  # the secondary mass hits each wall once per period
    # chaotic at its default parameters (tests/engine/test_reference.py): no period-1 orbit near (how
    # Newton's method fails from a chaotic motion's state, leaving the region, not converging or
    # sticking, is a matter of rounding)
    "impact-oscillator": "period-1",
    # the ball rides on the table (amplitude 0.1 < gravity)
    "bouncing-ball": "the default initial guess sticks",
}


@pytest.mark.parametrize(
    "model, initial",
    [
        ("two-sided-oscillator", "0,0"),
        ("impact-damper", "0,0,0,0"),
        pytest.param("impact-oscillator", "0,0", marks=pytest.mark.slow),
        pytest.param("bouncing-ball", "0.5,0", marks=pytest.mark.slow),
    ],
)
def test_simulate_and_orbit_every_built_in_model(model, initial, capsys):
    res = run_json(
        ["simulate", "--model", model, "--initial", initial, "--transient", "50", "--periods", "3"], capsys
    )
    assert len(res["samples"]) == 3 and len(res["x_final"]) == len(initial.split(","))
    code, out, err = run(["orbit", "--model", model, "--period", "1", "--transient", "300", "--json"], capsys)
    expected = ORBITS[model]
    if isinstance(expected, str):
        assert code == 1 and not out and err.startswith("grazing: error:") and err.count("\n") == 1, err
        assert expected in err
    else:
        assert code == 0, err
        orbit = json.loads(out)
        assert orbit["period"] == 1 and orbit["impacts"] == expected["impacts"] and orbit["stable"]
        assert max(abs(complex(*m)) for m in orbit["multipliers"]) < 1


def test_graze_sweep_continue_on_the_two_sided_oscillator(capsys):
    base = [*TWO, "--set", "amp=0.5", "--set", "gap_left=1.5"]
    res = run_json(["graze", *base, "--param", "omega", "--range", "0.5,0.9", "--stop-name", "left"], capsys)
    (g,) = res["grazings"]
    assert g["stop"] == "left" and 0.8 < g["value"] < 0.85 and "eta" not in g
    assert g["crossed"] == ["right"]  # that orbit passes through the right stop (gap 1 < 1.5)
    res = run_json(["sweep", *TWO, "--param", "omega", "--start", "0.7", "--stop", "0.9", "--num", "3",
                    "--transient", "50", "--periods", "8", "--workers", "1"], capsys)  # fmt: skip
    by_stop = res["impacts_per_period_by_stop"]
    assert set(by_stop) == {"right", "left"} and len(by_stop["right"]) == 3
    assert by_stop["right"][1] == pytest.approx(1.0) and by_stop["left"][1] == pytest.approx(1.0)
    res = run_json(["continue", *base, "--param", "omega", "--start", "0.5", "--stop", "0.9", "--stop-name",
                    "right"], capsys)  # fmt: skip
    assert [(s["kind"], s["stop"]) for s in res["special"]] == [("grazing", "right"), ("grazing", "left")]
    res = run_json(["map", *TWO, "--param1", "omega", "--start1", "0.7", "--stop1", "0.9", "--num1", "2",
                    "--param2", "r", "--start2", "0.5", "--stop2", "0.8", "--num2", "2", "--transient", "30",
                    "--periods", "8", "--workers", "1"], capsys)  # fmt: skip
    assert len(res["period"]) == 2


def test_normal_form_and_graze_curve_on_another_model(capsys):
    base = [*TWO, "--set", "amp=0.5", "--set", "gap_left=1.5"]
    res = run_json(
        ["normal-form", *base, "--param", "omega", "--range", "0.5,0.9", "--stop-name", "right"], capsys
    )
    # the linear amplitude amp / |1 - w^2 + 2 i zeta w| reaches gap_right = 1 (the root below resonance)
    z, a = res["params"]["zeta"], 0.5
    b = 2 - 4 * z * z
    omega_g = math.sqrt((b - math.sqrt(b * b - 4 * (1 - a * a))) / 2)
    assert res["stop"] == "right" and res["value"] == pytest.approx(omega_g, abs=1e-8)
    res = run_json(["graze-curve", *base, "--params", "omega,gap_right", "--range", "0.5,0.75",
                    "--start-value", "1.0", "--stop-name", "right", "--max-step", "0.1"], capsys)  # fmt: skip
    assert res["curve_params"] == ["omega", "gap_right"] and len(res["curve"]) > 2


def test_pendulum_options_unchanged(capsys):
    res = run_json(["graze", "--theta-hat", "40", "--eta-min", "0.4", "--eta-max", "0.6"], capsys)
    assert [round(g["eta"], 4) for g in res["grazings"]] == [0.4451, 0.5473]  # the README's example
    for g in res["grazings"]:  # checked by simulating the free orbit: it reaches the stop at 40°
        assert grazing_degrees(eta=g["eta"]) == pytest.approx(40.0, abs=1e-6)
    assert all(g["stop"] == "stop" and g["value"] == g["eta"] for g in res["grazings"])
    res = run_json(["simulate", "--set", "theta_hat=30", "--transient", "10", "--periods", "2"], capsys)
    assert res["params"]["theta_hat"] == pytest.approx(math.radians(30))


def test_a_model_from_a_file(tmp_path, capsys):
    path = tmp_path / "mine.py"
    path.write_text(
        "import sympy as sp\n"
        "from grazing import HybridModel, Parameter, Stop\n"
        "def build():\n"
        "    x, v, t, w = sp.symbols('x v t w')\n"
        "    return HybridModel('mine', [x, v], t, [Parameter('w', 1.3, lower=0, lower_open=True)],\n"
        "        vector_field=[v, -0.1 * v - x + sp.cos(w * t)], period=2 * sp.pi / w,\n"
        "        stops=[Stop('top', 1 - x, [x, -0.8 * v]), Stop('bottom', x + 1, [x, -0.8 * v])])\n"
        "MODEL = build()\n"
        "NOT_A_MODEL = 3\n"
    )
    res = run_json(["simulate", "--model", f"{path}:build", "--set", "w=1.1", "--periods", "3"], capsys)
    assert set(res["impacts_per_stop"]) == {"top", "bottom"} and res["params"] == {"w": 1.1}
    res = run_json(["simulate", "--model", f"{path}:MODEL", "--periods", "2"], capsys)
    assert res["params"] == {"w": 1.3}
    for bad, msg in [
        (f"{path}:NOPE", "defines no 'NOPE'"),
        (f"{path}:NOT_A_MODEL", "is not a grazing.HybridModel"),
        (f"{tmp_path / 'missing.py'}:M", "no such file"),
    ]:
        code, _, err = run(["simulate", "--model", bad], capsys)
        assert code != 0 and msg in err and err.count("\n") == 1


def test_a_model_with_modes_is_simulated_and_refused_elsewhere_in_one_line(tmp_path, capsys):
    path = tmp_path / "soft.py"
    path.write_text(
        "import sympy as sp\n"
        "from grazing import HybridModel, Mode, Parameter, Transition\n"
        "x, v, t, w = sp.symbols('x v t w')\n"
        "SOFT = HybridModel('soft', [x, v], t, [Parameter('w', 1.3, lower=0, lower_open=True)],\n"
        "    modes=[Mode('free', [v, -x + sp.cos(w * t)]), Mode('contact', [v, -5 * x + 2])],\n"
        "    transitions=[Transition('touch', 'free', 'contact', 0.5 - x),\n"
        "                 Transition('leave', 'contact', 'free', x - 0.5)], period=2 * sp.pi / w)\n"
    )
    out = run_json(["simulate", "--model", f"{path}:SOFT", "--periods", "3"], capsys)
    assert set(out["modes"]) <= {"free", "contact"} and len(out["modes"]) == 3
    for model in (f"{path}:SOFT", "soft-impact-oscillator"):  # (explore takes it: the ranges are asked for)
        code, out, err = run(["explore", "--model", model], capsys)
        assert code != 0 and out == "" and err.count("\n") == 1, err
        assert "explore needs --param NAME --range LO,HI" in err and "has modes" not in err
    # (the basins start each state in its mode: the grid reaches into the contact region, x > 0.5)
    basins = run_json(["basins", "--model", f"{path}:SOFT", "--x-range", "0,1", "--y-range", "0,1", "--num",
                       "3,2"], capsys)  # fmt: skip
    assert 0 not in [label for row in basins["labels"] for label in row]


ONE_MODE_KEYS = [
    "params", "initial", "transient", "periods", "phase", "samples", "impacts", "impacts_sampled",
    "impact_map", "impact_stops", "impacts_per_stop", "sticking_intervals", "period", "t_final", "x_final",
    "steps", "elapsed_s", "trajectory_file", "version",
]  # fmt: skip
"""The keys of ``simulate --json`` for a model of one mode, in order (what they were before modes)."""


def test_simulate_json_of_a_model_with_modes_against_the_api(capsys):
    import numpy as np

    import grazing

    argv = [
        "simulate",
        "--model",
        "soft-impact-oscillator",
        "--set",
        "k=20",
        "--transient",
        "7",
        "--periods",
        "5",
    ]
    out = run_json(argv, capsys)
    assert list(out)[: len(ONE_MODE_KEYS)] == ONE_MODE_KEYS
    assert list(out)[len(ONE_MODE_KEYS) :] == ["modes", "switches", "mode_final", "sliding_intervals"]
    assert out["sliding_intervals"] == []  # (no surface to slide on: its stops are transitions)
    sol = grazing.simulate(grazing.models.soft_impact_oscillator(k=20.0), [0.0, 0.0], transient=7, periods=5)
    assert out["modes"] == [sol.mode_names[k] for k in sol.modes] and out["mode_final"] == sol.mode_final
    assert len(out["switches"]) == len(sol.switches) >= 8
    assert [s["t"] for s in out["switches"]] == sol.switches.t.tolist()
    first = out["switches"][0]
    assert (first["transition"], first["from"], first["to"]) == (
        sol.switches.name(0), sol.switches.source(0), sol.switches.target(0)
    )  # fmt: skip
    assert np.array_equal(first["state"], sol.switches.state[0])
    # --mode: start in contact (x = 1 > gap is not in the initial mode, free)
    argv = ["simulate", "--model", "soft-impact-oscillator", "--initial", "1,0", "--transient", "0"]
    started = run_json([*argv, "--periods", "1", "--mode", "contact"], capsys)
    assert started["switches"][0]["from"] == "contact"
    code, out, err = run([*argv, "--mode", "stuck"], capsys)
    assert code != 0 and out == "" and err.count("\n") == 1 and "--mode: unknown mode 'stuck'" in err, err
    code, out, err = run([*argv, "--mode", "free"], capsys)
    assert code != 0 and out == "" and err.count("\n") == 1 and "is not in mode 'free'" in err, err
    # without --mode it starts in the mode it lies in (contact): the same run
    auto = run_json([*argv, "--periods", "1"], capsys)
    assert auto["switches"] == started["switches"] and auto["x_final"] == started["x_final"]


def test_simulate_json_of_a_model_of_one_mode_is_unchanged(capsys):
    """No key added for one mode, and the values those of the API (``--mode free`` changes nothing)."""
    import grazing

    argv = ["simulate", *TWO, "--transient", "20", "--periods", "4"]
    out = run_json(argv, capsys)
    assert list(out) == ONE_MODE_KEYS
    again = run_json([*argv, "--mode", "free"], capsys)
    assert {**again, "elapsed_s": 0} == {**out, "elapsed_s": 0}
    sol = grazing.simulate(grazing.models.two_sided_oscillator(), [0.0, 0.0], transient=20, periods=4)
    assert out["samples"] == sol.samples.tolist() and out["steps"] == sol.n_steps


@pytest.mark.parametrize(
    "argv, msg",
    [
        (["simulate", "--model", "nope"], "unknown model 'nope'"),
        (["simulate", *TWO, "--set", "zeta"], "expected NAME=VALUE"),
        (["simulate", *TWO, "--set", "eta=1"], "unknown parameter 'eta'"),
        (["simulate", *TWO, "--set", "r=2"], "r = 2 is outside [0, 1]"),
        (["simulate", *TWO, "--set", "r=abc"], "is not a number"),
        (
            ["simulate", *TWO, "--initial", "1,2,3"],
            "--initial must be X,V, got '1,2,3' (model two-sided-oscillator has 2 states)",
        ),
        (["simulate", *TWO, "--initial", "5,0"], "beyond stop 'right'"),
        (["simulate", *TWO, "--eta", "0.5"], "--eta is not used with a model other than the pendulum"),
        (
            ["graze", *TWO, "--param", "omega", "--range", "0.5,0.9", "--stop-name", "middle"],
            "unknown stop 'middle'",
        ),
        (["graze", *TWO, "--param", "nope", "--range", "0.5,0.9"], "unknown parameter 'nope'"),
        (["graze", *TWO], "graze needs --param NAME and --range LO,HI"),
        (
            ["sweep", *TWO, "--param", "nope", "--start", "0", "--stop", "1", "--num", "2"],
            "unknown parameter",
        ),
    ],
)
def test_bad_model_input_is_one_line(argv, msg, capsys):
    code, _, err = run(argv, capsys)
    assert code != 0 and msg in err and err.count("\n") == 1, err


# Every command on every built-in model (slow but for the impact damper: each model compiles its
# tangent kernels).  Each must give a result, except where the model has none to give.
MODEL_ARGS = {
    "two-sided-oscillator": (["--set", "amp=0.5"], "omega", "0.5,0.9", "r", "0.4,0.9"),
    "impact-oscillator": (["--set", "sigma=0.5"], "omega", "1.5,2.5", "r", "0.5,0.9"),
    "bouncing-ball": (["--set", "amplitude=1.3"], "omega", "0.9,1.1", "r", "0.3,0.6"),
    "impact-damper": (
        ["--set", "omega2=0.8", "--set", "amp=0.3", "--set", "omega=0.6"],
        "gap",
        "0.3,5",
        "r",
        "0.3,0.7",
    ),
}
NO_RESULT = {
    # the ball chatters onto the table and sticks within the period from rest: no Newton across sticking
    ("bouncing-ball", "continue"): "sticks to the stop",
    # a ball in free flight has no periodic orbit to graze: the search for one fails
    ("bouncing-ball", "graze"): "Newton did not converge to a period-1 orbit",
    ("bouncing-ball", "normal-form"): "Newton did not converge to a period-1 orbit",
    ("bouncing-ball", "graze-curve"): "Newton did not converge to a period-1 orbit",
}


def _every(model: str, command: str):
    return pytest.param(model, command, marks=() if model == "impact-damper" else pytest.mark.slow)


@pytest.mark.parametrize(
    "model, command",
    [
        _every(model, command)
        for model in sorted(MODEL_ARGS)
        for command in ("sweep", "map", "continue", "graze", "normal-form", "graze-curve")
    ],
)
def test_every_command_on_every_model(model, command, capsys):
    sets, p1, r1, p2, r2 = MODEL_ARGS[model]
    lo1, hi1 = r1.split(",")
    lo2, hi2 = r2.split(",")
    base = [command, "--model", model, *sets]
    argv = {
        "sweep": [*base, "--param", p1, "--start", lo1, "--stop", hi1, "--num", "4", "--transient", "50",
                  "--periods", "8", "--workers", "1"],
        "map": [*base, "--param1", p1, "--start1", lo1, "--stop1", hi1, "--num1", "2", "--param2", p2,
                "--start2", lo2, "--stop2", hi2, "--num2", "2", "--transient", "30", "--periods", "8",
                "--workers", "1"],
        "continue": [*base, "--param", p1, "--start", lo1, "--stop", hi1],
        "graze": [*base, "--param", p1, "--range", r1],
        "normal-form": [*base, "--param", p1, "--range", r1],
        "graze-curve": [*base, "--params", f"{p1},{p2}", "--range", r1, "--start-value", lo2],
    }[command]  # fmt: skip
    code, out, err = run([*argv, "--json"], capsys)
    if (model, command) in NO_RESULT:
        assert code == 1 and not out and err.startswith("grazing: error:") and err.count("\n") == 1, err
        assert NO_RESULT[model, command] in err
        return
    assert code == 0, err
    res = json.loads(out)
    lo, hi = float(lo1), float(hi1)
    if command == "sweep":
        assert len(res["period"]) == 4 and min(res["period"]) >= 0  # no failed point
    elif command == "map":
        assert [len(row) for row in res["period"]] == [2, 2] and min(map(min, res["period"])) >= 0
    elif command == "continue":
        assert len(res["values"]) > 2 and res["values"][0] == pytest.approx(lo) and res["status"]
        assert all(lo - 1e-9 <= v <= hi + 1e-9 for v in res["values"])
    elif command in ("graze", "normal-form"):
        values = [g["value"] for g in res["grazings"]] if command == "graze" else [res["value"]]
        assert values and all(lo <= v <= hi for v in values)
    else:  # graze-curve in (p1, r): r does not change the free orbit, so p1 stays at its grazing value
        curve = [point[p1] for point in res["curve"]]
        assert len(curve) > 2 and max(curve) - min(curve) < 1e-8 and lo <= curve[0] <= hi
