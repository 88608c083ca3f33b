"""Copy as code: the Python and the command lines the explorer gives reproduce what it shows, when run."""

from __future__ import annotations

import json
import math
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import grazing
from grazing.cli import main
from grazing.explore import ModelSource, View, compute_diagram, continue_click, inspect_click, view_code
from grazing.explore.basins import basins_at
from grazing.explore.branch import follow_click_curves, grazings_in_view

SYMMETRIC = Path(__file__).resolve().parents[1] / "orbits" / "symmetric_models.py"


def run_python(code: str, cwd: Path) -> str:
    path = cwd / "view.py"
    path.write_text(code)
    done = subprocess.run([sys.executable, str(path)], cwd=cwd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return done.stdout


def run_cli(line: str, capsys) -> dict:
    argv = shlex.split(line)
    assert argv[0] == "grazing"
    capsys.readouterr()
    assert main([*argv[1:], "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.fixture(scope="module")
def pendulum_view():
    model = grazing.models.pendulum("B", theta_hat=math.radians(40))
    view = View.of(model, {"eta": (0.44, 0.49)}, num=21)
    diagram = compute_diagram(view)
    point = inspect_click(diagram, [0.446])
    return view, diagram, point, continue_click(view, point)


def test_the_python_code_prints_what_the_page_shows(pendulum_view, tmp_path):
    view, _diagram, point, continued = pendulum_view
    out = run_python(view_code(view, point, continued=True).python, tmp_path).splitlines()
    assert out[0] == f"period {point.period} impacts {float(point.impacts_per_period)}"
    assert out[1].startswith(f"orbit {point.orbit.period} {point.orbit.impacts} [")
    # the branch, both ways: its special points where the page has them
    expected = [[(s.kind, round(s.param, 8)) for s in piece.branch.special] for piece in continued.pieces]
    got = [re.match(r"branch (\d+) (.*)$", line) for line in out[2:]]
    assert [eval(g.group(2)) for g in got] == expected  # (a list of (kind, value) tuples)
    assert [int(g.group(1)) for g in got] == [len(p.branch) for p in continued.pieces]


def test_the_command_lines_compute_the_same_diagram_point_orbit_and_branch(pendulum_view, capsys):
    view, diagram, point, continued = pendulum_view
    lines = view_code(view, point, continued=True).cli.strip().splitlines()
    assert [shlex.split(line)[1] for line in lines] == ["sweep", "simulate", "orbit", "continue", "continue"]
    sweep = run_cli(lines[0], capsys)
    assert sweep["period"] == diagram.period.tolist()
    assert sweep["values"] == pytest.approx(diagram.values[0].tolist(), rel=1e-12)
    sim = run_cli(lines[1], capsys)
    assert sim["period"] == point.period
    assert sim["impacts_sampled"] / sim["periods"] * point.period == pytest.approx(
        point.impacts_per_period, abs=point.period / 128
    )
    orbit = run_cli(lines[2], capsys)
    assert (orbit["period"], orbit["impacts"]) == (point.orbit.period, point.orbit.impacts)
    expected = np.array([[z.real, z.imag] for z in point.orbit.multipliers])
    assert np.array(orbit["multipliers"]) == pytest.approx(expected, abs=1e-8)
    for line, piece in zip(lines[3:], continued.pieces):
        branch = run_cli(line, capsys)
        assert [s["kind"] for s in branch["special"]] == [s.kind for s in piece.branch.special]
        assert [s["value"] for s in branch["special"]] == pytest.approx(
            [s.param for s in piece.branch.special], abs=1e-9
        )


@pytest.fixture(scope="module")
def basins_and_grazings(pendulum_view):
    view, _diagram, point, _continued = pendulum_view
    return basins_at(point, num=(12, 10)), grazings_in_view(view)


def test_the_basins_and_grazings_code_prints_what_the_page_shows(
    pendulum_view, basins_and_grazings, tmp_path
):
    view, _diagram, point, _continued = pendulum_view
    found, grazings = basins_and_grazings
    assert grazings.marks and len(found.kinds) >= 1  # (what the test is about)
    code = view_code(view, point, continued=True, basins=found, grazings=grazings)
    out = run_python(code.python, tmp_path).splitlines()
    shown = [line.split() for line in out if line.startswith("attractor ")]
    assert [(k, int(p)) for _, k, p, _ in shown] == list(zip(found.kinds, found.periods))
    fractions = [np.mean(found.label == k) for k in found.ids]
    assert [float(f) for *_, f in shown] == pytest.approx(fractions, abs=1e-6)
    (line,) = [line for line in out if line.startswith("grazings ")]
    assert eval(line[len("grazings ") :]) == pytest.approx([m.value for m in grazings.marks], abs=1e-8)


def test_the_basins_and_graze_command_lines_compute_the_same(pendulum_view, basins_and_grazings, capsys):
    view, _diagram, point, _continued = pendulum_view
    found, grazings = basins_and_grazings
    lines = view_code(view, point, basins=found, grazings=grazings).cli.strip().splitlines()
    # (the command looks at one stop: a line for each of the pendulum's, "stop" and "back")
    commands = [shlex.split(line)[1] for line in lines]
    assert commands == ["sweep", "simulate", "orbit", "basins", "graze", "graze"]
    res = run_cli(lines[3], capsys)
    labels = np.array(res["labels"])
    assert found.label.tolist() in (labels.tolist(), labels.T.tolist())
    got = [g["value"] for line in lines[4:] for g in run_cli(line, capsys)["grazings"]]
    assert sorted(got) == pytest.approx(sorted(m.value for m in grazings.marks), abs=1e-9)


def test_a_map_s_grazings_are_sought_along_its_clicked_row(capsys, tmp_path):
    model = grazing.models.pendulum("B")
    view = View.of(model, {"eta": (0.44, 0.45), "theta_hat": (39.0, 40.0)}, num=3)
    row = math.radians(39.5)
    grazings = grazings_in_view(view, {"theta_hat": row})
    assert len(grazings.marks) == 1
    code = view_code(view, grazings=grazings)
    assert f"model.with_params(theta_hat={row!r})" in code.python
    (line,) = [line for line in run_python(code.python, tmp_path).splitlines() if line.startswith("grazings")]
    assert eval(line[len("grazings ") :]) == pytest.approx([grazings.marks[0].value], abs=1e-8)
    grazes = [line for line in code.cli.strip().splitlines() if shlex.split(line)[1] == "graze"]
    assert all("theta_hat=39.5" in line or "--theta-hat 39.5" in line for line in grazes)
    got = [g["value"] for line in grazes for g in run_cli(line, capsys)["grazings"]]
    assert got == pytest.approx([grazings.marks[0].value], abs=1e-9)


def test_the_curves_of_a_map_s_clicked_orbit_are_followed_the_same_in_both(tmp_path, capsys):
    """The period-5 window's special points followed in (eta, theta_hat), as on the page
    (tests/explore/test_explore_app.py): the same curves, point for point, in Python and on the command
    line."""
    model = grazing.models.pendulum("B")
    view = View.of(model, {"eta": (0.43, 0.46), "theta_hat": (35.0, 45.0)}, num=4)
    point = inspect_click(compute_diagram(view), [0.446, math.radians(40)])
    found = follow_click_curves(view, point, continue_click(view, point))
    assert {c.kind for c in found.curves} >= {"period-doubling", "grazing"}  # (what the test is about)
    code = view_code(view, point, continued=True, curves=found)
    printed = run_python(code.python, tmp_path).splitlines()
    out = [line.split(" ", 3) for line in printed if line.startswith("curve ")]
    assert [(k, int(n)) for _, k, n, _ in out] == [(c.kind, c.first.size) for c in found.curves]
    lines = [line for line in code.cli.strip().splitlines() if shlex.split(line)[1] == "curve"]
    assert len(lines) == len(found.curves)
    for line, c in zip(lines, found.curves):
        res = run_cli(line, capsys)
        assert res["kind"] == c.kind and len(res["points"]) == c.first.size
        got = np.array([[p["eta"], p["theta_hat"]] for p in res["points"]])  # (theta_hat in degrees)
        assert got[:, 0] == pytest.approx(c.first, abs=1e-8)
        assert np.radians(got[:, 1]) == pytest.approx(c.second, abs=1e-8)


def test_a_model_file_is_loaded_by_its_path_in_both(tmp_path, capsys):
    """The pendulum between two walls, a model file with parameters A, Om and stops east, west."""
    from tests.orbits.symmetric_models import walled_pendulum

    model = walled_pendulum(A=0.3)
    source = ModelSource.of(model, f"{SYMMETRIC}:walled_pendulum")
    view = View.of(model, {"Om": (1.0, 1.2)}, num=4, source=source)
    point = inspect_click(compute_diagram(view), [1.1])
    code = view_code(view, point)
    assert "runpy.run_path(" in code.python
    out = run_python(code.python, tmp_path).splitlines()
    assert out[0] == "period 1 impacts 2.0"
    lines = code.cli.strip().splitlines()
    assert f"--model {SYMMETRIC}:walled_pendulum" in lines[0] and "--set A=0.3" in lines[0]
    orbit = run_cli(lines[2], capsys)
    assert (orbit["period"], orbit["impacts"]) == (1, 2)
    assert orbit["impacts_per_stop"] == {"east": 1, "west": 1}


def test_a_map_s_code_is_grazing_map(capsys):
    model = grazing.models.pendulum("B")
    view = View.of(model, {"eta": (0.44, 0.45), "theta_hat": (39.0, 40.0)}, num=3)
    d = compute_diagram(view)
    code = view_code(view)
    assert "parameter_map(model, 'eta'" in code.python
    res = run_cli(code.cli.strip(), capsys)
    assert np.array(res["period"]).tolist() == d.period.tolist()
    assert res["values2"] == pytest.approx([39.0, 39.5, 40.0])


def test_a_model_object_without_a_file_says_so():
    from tests.orbits.symmetric_models import walled_pendulum

    view = View.of(walled_pendulum(), {"Om": (1.0, 1.2)}, num=3)
    assert view.source.spec is None
    code = view_code(view)
    lines = code.python.splitlines()
    assert "# model: the HybridModel given to the explorer (a variable of your own)" in lines
    assert code.cli.startswith("# a model given as a Python object has no --model")
