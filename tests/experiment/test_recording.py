"""Loading recordings: every malformed case is rejected with one clear line; resampling; gaps; timing."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grazing.experiment import RecordingError, forcing_clock, from_arrays, load_recording
from grazing.experiment.recording import frequency_from_name


def _csv(tmp_path, text, name="rec.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def _rows(t, x, trig=None):
    if trig is None:
        return "".join(f"{a:.17g},{b:.17g}\n" for a, b in zip(t, x))
    return "".join(f"{a:.17g},{b:.17g},{int(g)}\n" for a, b, g in zip(t, x, trig))


GOOD_T = np.arange(0.0, 20.0, 0.01)
GOOD_X = 0.3 * np.sin(2 * math.pi * 0.5 * GOOD_T)

_MISSING40 = "".join(f"{t:.17g},\n" for t in GOOD_T[:40])
MALFORMED = {
    "missing angle column": ("time,theta\n" + _rows(GOOD_T[:50], GOOD_X[:50]), r"missing column 'angle'"),
    "missing both columns": ("t,x\n0,1\n", r"missing columns 'time' and 'angle' \(found: t, x\)"),
    "empty file": ("", "empty file"),
    "header only": ("time,angle\n", "no data rows"),
    "non-numeric angle": (
        "time,angle\n" + _rows(GOOD_T[:30], GOOD_X[:30]) + "0.30,abc\n",
        r"line 32: angle 'abc'",
    ),
    "non-numeric time": (
        "time,angle\n0.0,0.1\nnow,0.2\n" + _rows(GOOD_T[3:40], GOOD_X[3:40]),
        r"line 3: time 'now'",
    ),
    "short row": ("time,angle\n" + _rows(GOOD_T[:20], GOOD_X[:20]) + "0.2\n", r"line 22: expected 2 fields"),
    "unsorted times": (
        "time,angle\n" + _rows([0, 0.01, 0.03, 0.02, *GOOD_T[4:40]], GOOD_X[:40]),
        r"not sorted: 0\.02 s after 0\.03 s",
    ),
    "duplicated time": (
        "time,angle\n" + _rows([0, 0.01, 0.01, *GOOD_T[3:40]], GOOD_X[:40]),
        r"time 0\.01 s appears twice",
    ),
    "too few samples": ("time,angle\n" + _rows(GOOD_T[:5], GOOD_X[:5]), "only 5 samples"),
    "infinite time": ("time,angle\n" + _rows(GOOD_T[:30], GOOD_X[:30]) + "inf,0.1\n", "line 32: time 'inf'"),
    "bad trigger value": (
        "time,angle,trigger\n" + _rows(GOOD_T[:40], GOOD_X[:40], [0] * 39 + [2]),
        "trigger must be 0 or 1, got 2",
    ),
    "mostly missing": (
        "time,angle\n" + _MISSING40 + _rows(GOOD_T[40:60], GOOD_X[40:60]),
        "40 of 60 angle values are missing",
    ),
}


@pytest.mark.parametrize("case", list(MALFORMED))
def test_malformed_files_are_rejected_in_one_line(tmp_path, case):
    text, message = MALFORMED[case]
    p = _csv(tmp_path, text)
    with pytest.raises(RecordingError, match=message) as info:
        load_recording(p)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith("rec.csv")


def test_missing_file_and_folder(tmp_path):
    with pytest.raises(RecordingError, match="no such file"):
        load_recording(tmp_path / "nope.csv")
    with pytest.raises(RecordingError, match="is a folder"):
        load_recording(tmp_path)


def test_binary_file(tmp_path):
    p = tmp_path / "rec.csv"
    p.write_bytes(b"\xff\xfe\x00\x81binary")
    with pytest.raises(RecordingError, match="not a text"):
        load_recording(p)


def test_well_formed_file_with_extra_columns_and_degrees(tmp_path):
    body = "".join(f"{t:.17g},{math.degrees(x):.17g},ok\n" for t, x in zip(GOOD_T, GOOD_X))
    text = "Time, Angle ,comment\n" + body
    rec = load_recording(_csv(tmp_path, text), degrees=True)
    assert rec.sample_rate == pytest.approx(100.0)
    assert not rec.resampled and rec.gaps == () and rec.trigger_times is None
    np.testing.assert_allclose(rec.angle, GOOD_X, atol=1e-12)


def test_non_uniform_sampling_is_resampled():
    rng = np.random.default_rng(4)
    t = np.cumsum(rng.uniform(0.008, 0.012, 2000))
    x = np.sin(2 * math.pi * 0.5 * t)
    rec = from_arrays(t, x)
    assert rec.resampled
    assert np.allclose(np.diff(rec.time), np.diff(rec.time)[0], rtol=1e-9)
    assert rec.sample_rate == pytest.approx(100.0, rel=0.01)
    np.testing.assert_allclose(rec.angle, np.sin(2 * math.pi * 0.5 * rec.time), atol=2e-3)


def test_gaps_are_reported(tmp_path):
    x = GOOD_X.copy()
    x[500:520] = np.nan  # missing values
    fields = ("" if np.isnan(v) else f"{v:.17g}" for v in x)
    text = "time,angle\n" + "".join(f"{t:.17g},{f}\n" for t, f in zip(GOOD_T, fields))
    rec = load_recording(_csv(tmp_path, text))
    assert rec.gaps == ((pytest.approx(4.99), pytest.approx(5.2)),)
    assert np.isnan(rec.angle[505]) and np.isfinite(rec.filled_angle()).all()
    # a jump in time is a gap too (and makes the sampling non-uniform)
    keep = np.r_[0:800, 900:2000]
    rec = from_arrays(GOOD_T[keep], GOOD_X[keep])
    assert rec.resampled and rec.gaps == ((pytest.approx(7.99), pytest.approx(9.0)),)
    assert np.isnan(rec.angle[850]) and rec.in_gap(np.array([8.5, 3.0])).tolist() == [True, False]


def test_forcing_clock_from_trigger_and_frequency():
    t = np.arange(0.0, 30.0, 1e-3)
    f = 0.4592
    marks = np.round(np.arange(0, 14) / f * 1000).astype(int)
    trig = np.zeros(t.size)
    trig[marks[marks < t.size]] = 1
    trig[marks[5]] = 0  # a missed pulse
    rec = from_arrays(t, np.sin(2 * math.pi * f * t), trig)
    clock = forcing_clock(rec)
    assert clock.from_trigger and clock.forcing_hz == pytest.approx(f, rel=1e-5)
    np.testing.assert_allclose(clock.reference_times[:3], np.arange(3) / f, atol=5e-4)
    assert clock.reference_times.size == 14  # the missed pulse is restored
    plain = forcing_clock(from_arrays(t, np.sin(t)), f)
    assert not plain.from_trigger
    np.testing.assert_allclose(plain.sample_times(math.pi), (np.arange(plain.reference_times.size) + 0.5) / f)
    with pytest.raises(RecordingError, match=r"trigger pulses give 0\.4592"):
        forcing_clock(rec, 0.5)
    with pytest.raises(RecordingError, match="no trigger column"):
        forcing_clock(from_arrays(t, np.sin(t)))
    with pytest.raises(RecordingError, match="spans 3 forcing periods"):
        forcing_clock(from_arrays(t, np.sin(t)), 0.1)
    with pytest.raises(RecordingError, match="must be positive"):
        forcing_clock(from_arrays(t, np.sin(t)), -1.0)


def test_trigger_needs_two_pulses():
    t = np.arange(0.0, 1.0, 0.01)
    trig = np.zeros(t.size)
    trig[3] = 1
    with pytest.raises(RecordingError, match="1 pulse"):
        from_arrays(t, np.sin(t), trig)


def test_frequency_in_file_names():
    assert frequency_from_name("a/theta40_0.459234Hz.csv") == pytest.approx(0.459234)
    assert frequency_from_name("run_0p45HZ.csv") == 0.45
    assert frequency_from_name("run_12.csv") is None
