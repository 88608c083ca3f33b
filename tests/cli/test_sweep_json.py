"""A sweep's --json samples encoded chunk by chunk (grazing.cli.sweep_json): the text of the whole array."""

from __future__ import annotations

import json

import numpy as np
import orjson
from hypothesis import given, settings
from hypothesis import strategies as st

from grazing.cli import main
from grazing.cli.common import JsonText, json_text
from grazing.cli.sweep_json import SampleRows
from grazing.core.options import SweepSettings
from grazing.models import pendulum
from grazing.sweeps import sweep
from grazing.sweeps.spec import sweep_spec

MODEL = pendulum("B")


def _sorted_rows(spec, samples: np.ndarray, segment: int) -> bytes:
    """The JSON text of a chain's first-state samples, its points sorted by value (as --json sorts them)."""
    n = spec.segment_points
    part = slice(segment * n, (segment + 1) * n)
    by_value = np.argsort(np.asarray(spec.points, dtype=float)[part, 0], kind="stable")
    return json_text(samples[part][by_value][..., 0].tolist()).encode()


@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_chunks_in_any_order_give_the_text_of_the_sorted_array(data):
    """Chunks written in any order, some twice (the last one counts, as a chain's chunk run again), give
    the text of the sorted array (distinct values: always; else the command encodes the array at the end);
    a chain with a chunk missing gives None."""
    direction = data.draw(st.sampled_from(["up", "down", "both"]))
    n = data.draw(st.integers(1, 30))
    values = data.draw(st.lists(st.sampled_from([0.41, 0.42, 0.43, 0.44, 0.45]), min_size=n, max_size=n))
    chunk = data.draw(st.integers(0, 8))
    fresh = direction != "both" and data.draw(st.booleans())
    spec = sweep_spec(
        MODEL,
        "eta",
        values,
        direction=direction,
        settings=SweepSettings(chunk_size=chunk, periods=3, fresh=fresh),
    )
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    final = rng.normal(size=(spec.n_points, 3, 2)) * 10.0 ** rng.integers(
        -300, 300, size=(spec.n_points, 3, 2)
    )
    special = np.array([np.nan, np.inf, -np.inf, 0.0, -0.0, 1e-7, 5e-324])
    final.flat[rng.integers(0, final.size, size=4)] = rng.choice(special, size=4)
    rows = SampleRows(spec)
    order = data.draw(st.permutations(range(spec.n_chunks)))
    again = data.draw(st.lists(st.sampled_from(order), max_size=3))
    for i in order:
        rows.add(i, final[spec.chunk(i)])
    for i in again:  # (written again with other numbers, then with its own: the last counts)
        rows.add(i, final[spec.chunk(i)] + 1.0)
    for i in again:
        rows.add(i, final[spec.chunk(i)])
    for segment in range(spec.segments):
        got = rows.text(segment)
        if got is None:  # (only where a chunk's points are no run of the sorted points: equal values)
            assert len(set(values)) < len(values)
            continue
        assert b"".join(got.pieces) == _sorted_rows(spec, final, segment)
    missing = data.draw(st.sampled_from(order))
    rows._runs.pop(missing, None)
    assert rows.text(missing // spec.chunks_per_segment) is None


def test_sweep_json_samples_are_the_datasets(capsys):
    """The command's samples (encoded as the chunks arrived) are the dataset's, both directions."""
    argv = ["sweep", "--param", "eta", "--start", "0.44", "--stop", "0.47", "--num", "9", "--direction",
            "both", "--chunk-size", "2", "--transient", "30", "--periods", "5", "--workers", "2",
            "--json"]  # fmt: skip
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    values = np.linspace(0.44, 0.47, 9)
    ds = sweep(MODEL, "eta", values, direction="both", transient=30, periods=5, chunk_size=2, workers=2)
    for k, way in enumerate(["up", "down"]):
        assert res["samples"][way] == ds.samples.values[k, :, :, 0].tolist()


def test_json_text_places_encoded_text_also_through_the_json_module():
    """A JsonText is placed as it is by orjson and, where orjson cannot encode the rest, by json."""
    text = orjson.dumps(np.array([[1.5, np.nan]]), option=orjson.OPT_SERIALIZE_NUMPY)
    rows = JsonText((text[:5], text[5:]))
    assert json_text({"a": {"rows": rows}}) == '{"a":{"rows":[[1.5,null]]}}'
    assert json.loads(json_text({"n": 2**70, "rows": rows})) == {"n": 2**70, "rows": [[1.5, None]]}
