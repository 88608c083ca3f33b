"""Filtering, noise, stroboscopic sampling, embedding and period detection on noisy synthetic records."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grazing.experiment import (
    analyze_recording,
    delay_embedding,
    detect_period_noisy,
    estimate_noise,
    from_arrays,
    lowpass,
)
from grazing.experiment.signal import noise_gain
from grazing.experiment.synthetic import synthetic_recording
from tests.recordings import FAST_RATE


def test_lowpass_is_zero_phase_and_removes_noise():
    fs = 1000.0
    t = np.arange(0, 20, 1 / fs)
    clean = np.sin(2 * math.pi * 0.46 * t) + 0.3 * np.sin(2 * math.pi * 1.38 * t)
    noisy = clean + 0.01 * np.random.default_rng(1).standard_normal(t.size)
    y = lowpass(noisy, fs, 9.2)
    inner = slice(2000, -2000)
    assert np.max(np.abs(y - clean)[inner]) < 5 * 0.01 * noise_gain(fs, 9.2)  # no lag, noise reduced
    assert np.std((y - clean)[inner]) == pytest.approx(0.01 * noise_gain(fs, 9.2), rel=0.1)


def test_noise_estimate_with_quantisation():
    rng = np.random.default_rng(2)
    t = np.arange(0, 30, 1e-3)
    x = 0.6 * np.sin(2 * math.pi * 0.46 * t)
    for sigma, q in ((0.002, 0.0), (0.001, 2 * math.pi / 4096), (0.0005, 0.0)):
        y = x + sigma * rng.standard_normal(t.size)
        if q:
            y = np.round(y / q) * q
        expected = math.hypot(sigma, q / math.sqrt(12))
        assert estimate_noise(y, 1000.0) == pytest.approx(expected, rel=0.08)


def test_delay_embedding_of_a_sine_is_a_circle():
    t = np.arange(0, 10, 0.01)  # period 2 s: a quarter period is 50 samples
    emb = delay_embedding(np.sin(math.pi * t), 50)
    assert emb.shape == (t.size - 50, 2)
    np.testing.assert_allclose(emb[:, 0] ** 2 + emb[:, 1] ** 2, 1.0, atol=1e-9)


def test_detect_period_noisy_known_sequences():
    rng = np.random.default_rng(3)
    for p in (1, 2, 3, 5, 7, 13):
        base = rng.uniform(-1, 1, p)
        s = np.tile(base, 120 // p + 1)[:120] + 0.002 * rng.standard_normal(120)
        assert detect_period_noisy(s, 0.002).period == p
    # a slow drift does not break the clusters' differences
    s = np.tile([0.1, -0.3, 0.2], 40) + np.linspace(0, 0.05, 120) + 0.001 * rng.standard_normal(120)
    assert detect_period_noisy(s, 0.001).period == 3
    # banded chaos: two bands wider than the noise -> no period
    band = np.where(np.arange(120) % 2, 0.5, -0.5) + 0.05 * rng.uniform(-1, 1, 120)
    assert detect_period_noisy(band, 0.002).period == 0
    assert detect_period_noisy(band, 0.05).period == 2  # ... but at a coarser noise level they are clusters
    # a period above max_period is not detected
    s = np.tile(rng.uniform(-1, 1, 40), 4)
    assert detect_period_noisy(s, 1e-3, max_period=32).period == 0


def test_period_five_on_noisy_synthetic_record(period5_recording):
    """Paper fig 3 (c, d), fig 9 (b): period 5 at theta_hat = 40 deg, eta = 0.446 (case B), 1 kHz."""
    res = analyze_recording(period5_recording)
    assert res.period == 5
    assert res.from_trigger and res.eta == pytest.approx(0.446, abs=2e-5)
    assert res.noise == pytest.approx(math.hypot(1e-3, 2 * math.pi / 4096 / math.sqrt(12)), rel=0.15)
    # the stroboscopic samples are the model's (phase 0) to the drift and noise
    model = np.asarray(period5_recording.metadata["model_samples"])
    k = np.round(res.sample_times * res.forcing_hz).astype(int)
    assert np.max(np.abs(res.samples - model[k])) < 3e-3
    # five tight clusters
    clusters = np.sort(np.unique(np.round(model[k] / 1e-3)))
    assert clusters.size == 5


def test_chaos_gives_period_zero(chaos_recording):
    res = analyze_recording(chaos_recording)
    assert res.period == 0
    assert np.nanstd(res.samples) > 100 * res.sample_noise


@pytest.mark.parametrize(("eta", "period"), [(0.43, 1), (0.452, 3), (0.47, 2)])
def test_other_known_periods(eta, period):
    rec = synthetic_recording(eta, 40.0, periods=36, transient=600, sample_rate=FAST_RATE, noise=3e-3, seed=5)
    assert analyze_recording(rec).period == period


def test_trigger_and_forcing_hz_sampling_agree(period5_recording):
    rec = period5_recording
    with_trigger = analyze_recording(rec)
    without = analyze_recording(from_arrays(rec.time, rec.angle), rec.metadata["forcing_hz"])
    assert not without.from_trigger and without.period == 5
    n = min(with_trigger.samples.size, without.samples.size)
    np.testing.assert_allclose(with_trigger.samples[:n], without.samples[:n], atol=2e-4)
    # a phase shift of a quarter cycle gives the embedding's second coordinate
    shifted = analyze_recording(rec, phase=math.pi / 2)
    T = 1.0 / with_trigger.forcing_hz
    common, i, j = np.intersect1d(
        np.round(shifted.sample_times, 9), np.round(with_trigger.sample_times + T / 4, 9), return_indices=True
    )
    assert common.size >= 30
    np.testing.assert_allclose(shifted.samples[i], with_trigger.quarter[j], atol=1e-9)


def test_gaps_drop_samples_but_keep_the_period(period5_recording):
    rec = period5_recording
    x = rec.angle.copy()
    x[20000:21500] = np.nan
    res = analyze_recording(from_arrays(rec.time, x, None), rec.metadata["forcing_hz"])
    assert len(res.gaps) == 1
    assert np.isnan(res.samples).sum() >= 1
    assert res.period == 5


def test_embedding_lag_is_a_quarter_period(period5_recording):
    res = analyze_recording(period5_recording)
    fs = period5_recording.sample_rate
    assert res.lag == round(fs / res.forcing_hz / 4)
    emb = res.embedding()
    assert emb.shape[1] == 2 and emb.shape[0] == res.filtered.size - res.lag
