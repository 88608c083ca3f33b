"""The commands on models with modes: orbit, continue, curve, graze, sweep, map, normal-form and simulate's
sliding give the library's numbers (and the soft-impact oscillator's closed forms); ``--mode`` is checked in
one line; the JSON of a model of one mode keeps its keys; what the library does not run is refused in one
line."""

from __future__ import annotations

import math

import numpy as np
import pytest

import grazing
from tests.cli.test_cli_models import TWO, run, run_json

SOFT = ["--model", "soft-impact-oscillator"]

ORBIT_KEYS = [
    "params", "period", "impacts", "state", "multipliers", "abs_multipliers", "stable", "isolated",
    "residual", "newton_iterations", "min_impact_speed", "impacts_per_stop",
]  # fmt: skip
"""The keys of ``orbit --json`` for a model of one mode (not the pendulum), as before modes."""


def soft() -> grazing.HybridModel:
    return grazing.models.soft_impact_oscillator()


def grazing_amplitude(p: dict) -> float:
    """The forcing amplitude at which the free (linear) response's amplitude is the gap: it grazes."""
    w = p["omega"]
    return p["gap"] * abs(1 - w * w + 2j * p["zeta"] * w)


def test_orbit_json_is_find_orbits_with_its_mode_and_switches(capsys):
    from grazing.orbits import find_orbit

    out = run_json(["orbit", *SOFT], capsys)
    assert list(out) == [*ORBIT_KEYS, "mode", "switches"]
    orb = find_orbit(soft())
    assert out["state"] == orb.state.tolist() and out["mode"] == orb.mode
    assert out["multipliers"] == [[z.real, z.imag] for z in orb.multipliers]
    assert [s["t"] for s in out["switches"]] == orb.switch_times.tolist()
    # the orbit leaves and re-enters the contact once a period: contact on the section iff x > gap
    assert sorted(s["transition"] for s in out["switches"]) == ["leave", "touch"]
    assert (out["mode"] == "contact") == (out["state"][0] > soft().params["gap"])
    for s in out["switches"]:
        assert (s["from"], s["to"]) == {"touch": ("free", "contact"), "leave": ("contact", "free")}[
            s["transition"]
        ]
    # --mode with --initial: the library's orbit from that guess in that mode
    guess = ",".join(f"{v:.3f}" for v in orb.state)
    again = run_json(["orbit", *SOFT, "--initial", guess, "--mode", orb.mode], capsys)
    assert again["mode"] == orb.mode
    assert np.abs(np.array(again["state"]) - orb.state).max() < 1e-9
    code, text, _ = run(["orbit", *SOFT], capsys)
    assert code == 0 and f"mode {orb.mode} on the section; 2 switches per period" in text


@pytest.mark.parametrize(
    "command",
    [
        ["orbit"],
        ["continue", "--param", "a", "--start", "1", "--stop", "2"],
        ["curve", "--kind", "grazing", "--param", "a", "--start", "0.1", "--stop", "0.5", "--param2",
         "omega", "--range", "1.1,1.3"],
        ["simulate"],
    ],
)  # fmt: skip
@pytest.mark.parametrize("mode, msg", [("stuck", "unknown mode 'stuck'"), ("sliding on 'x'", "unknown mode")])
def test_a_bad_mode_is_one_line_and_exit_2(command, mode, msg, capsys):
    code, out, err = run([*command, *SOFT, "--mode", mode], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1 and f"--mode: {msg}" in err, err


def test_orbit_json_of_a_model_of_one_mode_is_unchanged(capsys):
    from grazing.orbits import find_orbit

    out = run_json(["orbit", *TWO], capsys)
    assert list(out) == ORBIT_KEYS
    again = run_json(["orbit", *TWO, "--mode", "free"], capsys)
    assert again == out
    assert out["state"] == find_orbit(grazing.models.two_sided_oscillator()).state.tolist()


def test_continue_json_is_continue_orbits_with_each_points_mode(capsys):
    from grazing.core.options import MAX_STEP
    from grazing.orbits import PalcSettings, continue_orbit

    out = run_json(["continue", *SOFT, "--param", "a", "--start", "1", "--stop", "1.5"], capsys)
    branch = continue_orbit(
        soft(), "a", 1.0, 1.5, settings=PalcSettings(ds=min(0.01, MAX_STEP), ds_max=MAX_STEP)
    )
    assert out["values"] == list(branch.values) and out["states"] == np.asarray(branch.states).tolist()
    assert list(out)[-2:] == ["modes", "switches"]
    assert out["modes"] == [o.mode for o in branch.orbits]
    assert all(sorted(s) == ["leave", "touch"] for s in out["switches"])
    code, text, _ = run(["continue", *SOFT, "--param", "a", "--start", "1", "--stop", "1.5"], capsys)
    first = f"first point: mode {out['modes'][0]}, switches per period: {', '.join(out['switches'][0])}"
    assert code == 0 and first in text
    # --mode with --initial: the branch starts from that guess in that mode (here the orbit's own state)
    x0 = ",".join(repr(v) for v in out["states"][0])
    argv = ["continue", *SOFT, "--param", "a", "--start", "1", "--stop", "1.1", "--initial", x0]
    started = run_json([*argv, "--mode", out["modes"][0]], capsys)
    assert started["modes"][0] == out["modes"][0] == "contact"
    assert np.abs(np.array(started["states"][0]) - out["states"][0]).max() < 1e-9
    # the free response grazes the contact at a = gap |1 - w^2 + 2 i zeta w|: below it, no switch
    p = soft().params
    a = grazing_amplitude(p)
    below = run_json(
        ["continue", *SOFT, "--param", "a", "--start", f"{0.8 * a}", "--stop", f"{0.9 * a}"], capsys
    )
    assert set(below["modes"]) == {"free"} and all(s == [] for s in below["switches"])


def test_continue_json_of_a_model_of_one_mode_has_no_modes(capsys):
    argv = ["continue", *TWO, "--param", "amp", "--start", "0.2", "--stop", "0.3"]
    out = run_json(argv, capsys)
    assert "modes" not in out and "switches" not in out and "mode" not in out
    assert run_json([*argv, "--mode", "free"], capsys)["states"] == out["states"]


def test_graze_and_its_curve_meet_the_closed_form(capsys):
    from grazing.orbits import find_grazings

    p = soft().params
    out = run_json(["graze", *SOFT, "--param", "a", "--range", "0.1,0.5"], capsys)
    (g,) = out["grazings"]
    assert abs(g["value"] - grazing_amplitude(p)) < 1e-8 and (g["stop"], g["mode"]) == ("touch", "free")
    points, _ = find_grazings(soft(), "a", 0.1, 0.5, stop_name=0)
    assert g["value"] == points[0].model.params["a"]
    assert abs(g["accel"] - p["omega"] ** 2 * p["gap"]) < 1e-8  # (x'' = -w^2 x at the top of a sine)
    argv = ["--param", "a", "--start", "0.1", "--stop", "0.5", "--param2", "omega", "--range", "1.1,1.3"]
    curve = run_json(["curve", *SOFT, "--kind", "grazing", *argv], capsys)
    assert len(curve["points"]) >= 5
    for pt in curve["points"]:
        assert abs(pt["a"] - grazing_amplitude({**p, "omega": pt["omega"]})) < 1e-7
        assert pt["mode"] == "free" and pt["switches"] == []
    code, text, _ = run(["curve", *SOFT, "--kind", "grazing", *argv], capsys)
    assert code == 0 and "at the start: mode free, switches per period: none" in text


def test_normal_form_of_the_switching_surface_is_the_switch_map(capsys):
    p = soft().params
    out = run_json(["normal-form", *SOFT, "--param", "a", "--range", "0.1,0.5"], capsys)
    m = out["switching_map"]
    a = p["omega"] ** 2 * p["gap"]
    assert abs(m["accel"] - a) < 1e-8 and np.abs(np.array(m["jump"]) - [0.0, p["k"]]).max() < 1e-10
    assert abs(m["coefficient"] - 4 / 3 * math.sqrt(2 / a)) < 1e-8
    assert (
        out["stop"] == "touch" and out["mode"] == "free" and abs(out["value"] - grazing_amplitude(p)) < 1e-8
    )
    code, text, err = run(["normal-form", *SOFT, "--param", "a", "--range", "0.1,0.5", "--check"], capsys)
    assert code == 2 and text == "" and err.count("\n") == 1 and "not predicted yet" in err, err


def test_sweep_and_map_are_the_librarys(capsys):
    from grazing.sweeps import sweep

    base = ["--transient", "30", "--periods", "3", "--workers", "1"]
    out = run_json(
        ["sweep", *SOFT, "--param", "a", "--start", "0.1", "--stop", "1", "--num", "3", *base], capsys
    )
    ds = sweep(soft(), "a", np.linspace(0.1, 1.0, 3), transient=30, periods=3)
    assert np.array_equal(np.array(out["samples"], dtype=float), ds.samples.values[..., 0])
    argv = ["map", *SOFT, "--param1", "a", "--start1", "0.1", "--stop1", "1", "--num1", "2", "--param2",
            "omega", "--start2", "1.1", "--stop2", "1.2", "--num2", "2", *base]  # fmt: skip
    code, _, err = run(argv, capsys)
    assert code == 0, err


def test_simulate_shows_the_friction_oscillators_sliding(capsys):
    argv = ["simulate", "--model", "friction-oscillator", "--transient", "20", "--periods", "3"]
    out = run_json(argv, capsys)
    sol = grazing.simulate(grazing.models.friction_oscillator(), [0.0, 0.0], transient=20, periods=3)
    assert sol.sliding is not None and len(sol.sliding) >= 2
    assert [[s["t_start"], s["t_end"]] for s in out["sliding_intervals"]] == sol.sliding[:, :2].tolist()
    assert {s["surface"] for s in out["sliding_intervals"]} == {"belt"}
    # each interval is entered and left by the pseudo-mode's switches
    into = [s["t"] for s in out["switches"] if s["to"] == "sliding on 'belt'"]
    assert into == [s["t_start"] for s in out["sliding_intervals"]]
    code, text, _ = run(argv, capsys)
    assert code == 0 and f"sliding intervals: {len(sol.sliding)}" in text and "sliding on 'belt': " in text
    assert "switches per transition: belt_slide_from_slip_" in text


def test_simulate_of_a_model_of_one_mode_shows_no_sliding(capsys):
    code, text, _ = run(["simulate", *TWO, "--transient", "5", "--periods", "3"], capsys)
    assert code == 0 and "sliding" not in text and "switches per transition" not in text
    assert "sliding_intervals" not in run_json(
        ["simulate", *TWO, "--transient", "5", "--periods", "3"], capsys
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--mode", "stuck"], "--mode: unknown mode 'stuck'"),
        (["--mode", "sliding on 'belt'"], "--mode: unknown mode"),
        (["--set", "k=-1"], "k = -1 is outside"),
    ],
)
def test_explore_s_bad_modes_are_one_line_before_it_serves(args, message, capsys):
    """``explore`` takes models with modes (tests/explore/test_explore_modes.py); its ``--mode`` is checked
    as ``simulate``'s, before the page is served."""
    code, out, err = run(["explore", *SOFT, "--param", "omega", "--range", "0.8,1.6", *args], capsys)
    assert code != 0 and out == "" and err.count("\n") == 1, err
    assert message in err


def test_explore_draws_a_model_with_modes_that_sticks(tmp_path):
    """Sticking to a stop in a model with modes: its diagram (a sweep) is drawn as any other (sweeps stick
    through modes, tests/engine/test_sticking_modes.py), not refused."""
    from grazing.cli.common import load_model
    from grazing.explore import View

    path = tmp_path / "belt.py"
    path.write_text(
        "import sympy as sp\n"
        "from grazing import HybridModel, Mode, Parameter, Stop, Surface\n"
        "x, v, t, r = sp.symbols('x v t r')\n"
        "table = Stop('table', x, [x, -r * v], contact_direction=[0, 1])\n"
        "BELT = HybridModel('belt', [x, v], t, [Parameter('r', 0.5)], period=2 * sp.pi,\n"
        "    modes=[Mode('slip_right', [v, -x - 1], stops=[table]), Mode('slip_left', [v, -x + 1])],\n"
        "    surfaces=[Surface('belt', v, 'slip_right', 'slip_left', sliding=True)])\n"
    )
    view = View.of(load_model(f"{path}:BELT"), {"r": (0.4, 0.6)}, num=2)
    assert view.names == ("r",)


# Below the fold of its resonance the soft-impact oscillator has a small free orbit and a large one in
# contact each period (tests/attractors/test_basins_modes.py); the grid reaches into the contact region.
COEXISTING = [*SOFT, "--set", "a=0.15", "--x-range=-1.5,1.5", "--y-range=-1.5,1.5"]


def test_basins_of_a_model_with_modes_and_their_store(tmp_path, capsys, monkeypatch):
    store = tmp_path / "b.zarr"
    res = run_json(["basins", *COEXISTING, "--num", "8,8", "--out", str(store), "--chunk-size", "16"], capsys)
    assert [a["kind"] for a in res["attractors"]] == ["periodic", "periodic"]
    labels = np.array(res["labels"])
    assert labels.min() >= 1 and set(labels.ravel()) == {1, 2}  # (no state invalid: each in its mode)
    import grazing.sweeps.executor as executor

    monkeypatch.setattr(
        executor, "chunk_results", lambda *a, **k: (_ for _ in ()).throw(AssertionError("again"))
    )
    again = run_json(
        ["basins", *COEXISTING, "--num", "8,8", "--out", str(store), "--chunk-size", "16"], capsys
    )
    assert again["labels"] == res["labels"]


def test_attractors_of_a_model_with_modes_are_followed(capsys):
    argv = ["attractors", *SOFT, "--x-range=-1.5,1.5", "--y-range=-1.5,1.5", "--param", "a",
            "--start", "0.15", "--stop", "0.2", "--num", "2", "--num-grid", "6,6"]  # fmt: skip
    code, text, err = run(argv, capsys)
    assert code == 0 and err == "" and "2 attractors and outcomes followed" in text, (text, err)
    assert text.count("periodic; a in [0.15, 0.2] (2 values)") == 2, text  # (both at both values)


def test_graze_json_of_a_model_of_one_mode_has_no_mode(capsys):
    out = run_json(["graze", *TWO, "--param", "amp", "--range", "0.1,2"], capsys)
    assert out["grazings"] and all("mode" not in g for g in out["grazings"])


def test_graze_curve_meets_the_closed_form(capsys):
    p = soft().params
    argv = ["graze-curve", *SOFT, "--params", "omega,a", "--range", "1.0,1.5", "--start-value", "0.2"]
    out = run_json(argv, capsys)
    assert len(out["curve"]) >= 5 and out["stop"] == "touch"
    for g in out["curve"]:
        assert abs(g["a"] - grazing_amplitude({**p, "omega": g["omega"]})) < 1e-7
        assert g["mode"] == "free" and abs(g["accel"] - g["omega"] ** 2 * p["gap"]) < 1e-7
