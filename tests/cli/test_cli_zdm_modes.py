"""``grazing sweep --method map`` on a model with modes: the map at the grazing of a stop of one mode.

The bumper oscillator (``tests/engine/zdm_modes_model.py``, a user model file): its first transitions are
switches (``grip_Q``), so the map is built at the grazing of its first stop of a mode, ``Bumper_9``; a
model with no such stop (the soft-impact oscillator's transitions are switches) is refused in one line.
"""

from __future__ import annotations

from pathlib import Path

from grazing.normalform import find_grazing_point
from tests.cli.test_cli_models import run, run_json
from tests.engine.zdm_modes_model import bumper_oscillator

MODEL = ["--model", f"{Path(__file__).parents[1] / 'engine' / 'zdm_modes_model.py'}:bumper_oscillator"]


def test_the_map_of_a_sweep_is_built_at_the_bumpers_grazing(capsys) -> None:
    argv = ["sweep", *MODEL, "--param", "F_0", "--start", "0.4992", "--stop", "0.505", "--num", "4",
            "--method", "map", "--transient", "50", "--periods", "10"]  # fmt: skip
    res = run_json(argv, capsys)
    point = find_grazing_point(bumper_oscillator(), "F_0", 0.2, 1.5, "first", "Bumper_9")
    assert res["method"] == "map" and res["grazing"]["stop"] == "Bumper_9"
    assert abs(res["grazing"]["value"] - point.model.params["F_0"]) < 1e-9
    assert res["grazing"]["direction"] == [0.0, 1.8]  # (-0.0 == 0.0)
    by_stop = res["impacts_per_period_by_stop"]
    assert by_stop["grip_Q"] == by_stop["slip_Q"] == [0.0] * 4  # (switches: never the map's)
    assert all(v > 0 for v in by_stop["Bumper_9"]), by_stop  # (from rest: the kicks of a large orbit)
    assert res["status"] == ["ok"] * 4


def test_a_model_without_a_stop_of_a_mode_is_refused_in_one_line(capsys) -> None:
    argv = ["sweep", "--model", "soft-impact-oscillator", "--param", "a", "--start", "0.5", "--stop", "0.6",
            "--num", "2", "--method", "map"]  # fmt: skip
    code, out, err = run(argv, capsys)
    assert code != 0 and out == ""
    assert err.strip().count("\n") == 0 and "has no stop of a mode" in err, err
