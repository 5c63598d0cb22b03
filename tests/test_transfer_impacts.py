"""Tests of gearshot.transfer.impacts (H1/H2 from impact-hammer records)."""

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.signal import find_peaks, lfilter

from gearshot import GearshotError
from gearshot.transfer import frf_from_impacts, impact_arrays, read_uff_records

SHARED = Path(__file__).resolve().parents[1].parent / "shared"
IMPACT_FILE = SHARED / "data" / "impact" / "hammer_impacts.uff"

FS = 4096.0
N = 4096


def _synthetic_impacts(n_impacts=4, noise=0.0, seed=0):
    """Half-sine hammer pulses through a known IIR system (single mode, fully decayed)."""
    rng = np.random.default_rng(seed)
    # resonator: poles at 300 Hz, r = 0.99 -> decays to 1e-17 over N samples
    w0, r = 2 * np.pi * 300 / FS, 0.99
    b, a = [0.5, 0.0, -0.5], [1, -2 * r * np.cos(w0), r**2]
    force = np.zeros((n_impacts, N))
    for i in range(n_impacts):
        start = 40 + 7 * i
        width = 6 + i
        pulse = np.sin(np.pi * np.arange(width) / width)
        force[i, start:start + width] = rng.uniform(50, 100) * pulse
    resp = lfilter(b, a, force, axis=-1)
    resp_noisy = resp + noise * rng.standard_normal(resp.shape)
    z = np.exp(-2j * np.pi * np.fft.rfftfreq(N, 1 / FS) / FS)
    h_true = (b[0] + b[1] * z + b[2] * z**2) / (a[0] + a[1] * z + a[2] * z**2)
    return force, resp_noisy, h_true


def test_h1_h2_exact_on_noise_free_linear_system():
    force, resp, h_true = _synthetic_impacts()
    for est in ("H1", "H2"):
        tf, coh = frf_from_impacts(force, resp, FS, estimator=est, force_window=None)
        assert_allclose(tf.freqs, np.fft.rfftfreq(N, 1 / FS))
        band = (tf.freqs > 5) & (tf.freqs < 1500)   # where the pulses carry force
        assert_allclose(tf.values[band], h_true[band], rtol=1e-8)
        assert_allclose(coh[band], 1.0, atol=1e-9)
        assert tf.metadata["estimator"] == est and tf.metadata["n_impacts"] == 4


def test_h1_below_h2_with_response_noise_and_coherence_drops():
    force, resp, h_true = _synthetic_impacts(n_impacts=8, noise=0.05, seed=3)
    h1, coh = frf_from_impacts(force, resp, FS, estimator="H1")
    h2, _ = frf_from_impacts(force, resp, FS, estimator="H2")
    band = (h1.freqs > 5) & (h1.freqs < 1500)
    # |H1| <= |H2| always (their ratio is the coherence)
    assert np.all(np.abs(h1.values) <= np.abs(h2.values) * (1 + 1e-12))
    assert_allclose(np.abs(h1.values) / np.abs(h2.values), coh, rtol=1e-9)
    # noise lowers coherence away from the resonance, not at it
    k_res = np.argmin(np.abs(h1.freqs - 300))
    assert coh[k_res] > 0.99
    assert coh[band].min() < 0.9
    # H1 is unbiased by response noise: errors small at the resonance
    assert abs(h1.values[k_res] / h_true[k_res] - 1) < 0.02


def test_force_window_removes_force_noise_after_pulse():
    force, resp, h_true = _synthetic_impacts(n_impacts=4, seed=5)
    rng = np.random.default_rng(9)
    noisy_force = force + 0.5 * rng.standard_normal(force.shape)
    plain, _ = frf_from_impacts(noisy_force, resp, FS, force_window=None)
    windowed, _ = frf_from_impacts(noisy_force, resp, FS, force_window=0.01)
    band = (plain.freqs > 50) & (plain.freqs < 1200)
    err_plain = np.median(np.abs(plain.values[band] / h_true[band] - 1))
    err_win = np.median(np.abs(windowed.values[band] / h_true[band] - 1))
    assert err_win < 0.3 * err_plain


def test_single_impact_and_exponential_window():
    force, resp, _ = _synthetic_impacts(n_impacts=1)
    tf, coh = frf_from_impacts(force[0], resp[0], FS, exp_window=0.01)
    assert_allclose(coh, 1.0, atol=1e-12)
    # exponential window adds damping: the peak gets lower and wider, stays at 300 Hz
    tf0, _ = frf_from_impacts(force[0], resp[0], FS)
    k = np.argmax(np.abs(tf.values))
    assert abs(tf.freqs[k] - 300) <= 1
    assert np.abs(tf.values).max() < np.abs(tf0.values).max()


@pytest.mark.parametrize("kwargs, match", [
    ({"estimator": "H3"}, "estimator"),
    ({"force_window": -1.0}, "force_window"),
    ({"exp_window": 0.0}, "exp_window"),
    ({"exp_window": 1.5}, "exp_window"),
])
def test_bad_options(kwargs, match):
    force, resp, _ = _synthetic_impacts(n_impacts=2)
    with pytest.raises(GearshotError, match=match):
        frf_from_impacts(force, resp, FS, **kwargs)


def test_bad_inputs():
    force, resp, _ = _synthetic_impacts(n_impacts=2)
    with pytest.raises(GearshotError, match="shape"):
        frf_from_impacts(force, resp[:, :-1], FS)
    with pytest.raises(GearshotError, match="fs"):
        frf_from_impacts(force, resp, 0.0)
    with pytest.raises(GearshotError, match="no energy"):
        frf_from_impacts(np.zeros_like(force), resp, FS, force_window=None)
    bad = resp.copy()
    bad[0, 3] = np.nan
    with pytest.raises(GearshotError, match="response must be finite"):
        frf_from_impacts(force, bad, FS)


@pytest.fixture(scope="module")
def hammer():
    if not IMPACT_FILE.exists():
        pytest.skip(f"impact records not found at {IMPACT_FILE}")
    force, resp, fs = impact_arrays(read_uff_records(IMPACT_FILE))
    return force, resp, fs


def _main_resonances(tf, n=8, fmax=6500.0):
    """The n highest peaks of |H| below fmax (where the hammer still excites well)."""
    mag = np.abs(tf.values)
    pk, prop = find_peaks(mag, prominence=0.05 * mag.max())
    pk = pk[tf.freqs[pk] < fmax]
    return np.sort(pk[np.argsort(mag[pk])[::-1][:n]])


def test_real_hammer_h1_coherence_at_main_resonances(hammer):
    force, resp, fs = hammer
    assert force.shape == (5, 25600) and fs == 25600.0
    tf, coh = frf_from_impacts(force, resp, fs, estimator="H1")
    assert tf.df == 1.0
    peaks = _main_resonances(tf)
    assert len(peaks) == 8
    # resonances of this structure (900 Hz … 6.1 kHz)
    assert tf.freqs[peaks[0]] == pytest.approx(900, abs=2)
    for k in peaks:
        assert coh[k - 3:k + 4].min() > 0.9, f"coherence near {tf.freqs[k]} Hz"
    # and over the whole well-excited band the coherence stays high on average
    band = (tf.freqs > 500) & (tf.freqs < 6500)
    assert np.median(coh[band]) > 0.9


def test_real_hammer_single_impacts_agree_within_one_line(hammer):
    force, resp, fs = hammer
    avg, _ = frf_from_impacts(force, resp, fs)
    ref = avg.freqs[_main_resonances(avg)]
    for i in range(force.shape[0]):
        single, coh = frf_from_impacts(force[i], resp[i], fs)
        assert_allclose(coh, 1.0, atol=1e-9)
        mag = np.abs(single.values)
        for f0 in ref:
            win = np.abs(single.freqs - f0) <= 3
            f_single = single.freqs[win][np.argmax(mag[win])]
            assert abs(f_single - f0) <= single.df, (i, f0, f_single)


def test_real_hammer_h1_repeatable_across_impact_subsets(hammer):
    """H1 from impacts 1, 3, 5 and from impacts 2, 4 agree at the main resonances."""
    force, resp, fs = hammer
    odd, _ = frf_from_impacts(force[0::2], resp[0::2], fs)
    even, _ = frf_from_impacts(force[1::2], resp[1::2], fs)
    for k in _main_resonances(odd):
        assert abs(abs(even.values[k]) / abs(odd.values[k]) - 1) < 0.1, odd.freqs[k]
    h2, _ = frf_from_impacts(force, resp, fs, estimator="H2")
    h1, coh = frf_from_impacts(force, resp, fs)
    assert_allclose(np.abs(h1.values) / np.abs(h2.values), coh, rtol=1e-9)


def test_impact_arrays_pairing_errors(hammer):
    recs = read_uff_records(IMPACT_FILE)
    with pytest.raises(GearshotError, match="pair force and response"):
        impact_arrays(recs[:-1])
    with pytest.raises(GearshotError, match="non-empty"):
        impact_arrays([])
    f, r, fs = impact_arrays(recs, response_quantity="acceleration")
    assert f.shape == r.shape == (5, 25600)
