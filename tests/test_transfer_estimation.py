"""TF estimation, resampling, propagation and RMS normalization."""

import numpy as np
import pytest
import scipy.signal
from numpy.testing import assert_allclose

from gearshot import transfer

N = 2048


def test_propagate_identity_and_delay():
    rng = np.random.default_rng(0)
    x = rng.normal(size=(3, N))
    assert_allclose(transfer.propagate(x, np.ones(N)), x, atol=1e-12)
    k = np.fft.fftfreq(N, 1 / N)
    delay = np.exp(-2j * np.pi * k * 5 / N)  # 5-sample circular delay
    assert_allclose(transfer.propagate(x, delay), np.roll(x, 5, axis=-1), atol=1e-10)


def test_resample_is_hermitian_and_interpolates_a_smooth_response():
    freqs = np.linspace(0, 1, 513)
    tf = 1.0 / (1 + 2j * freqs)  # smooth first-order response, one-sided
    out = transfer.resample_transfer_function(tf, N)
    assert out.shape == (N,)
    assert_allclose(out[1:N // 2], np.conj(out[N // 2 + 1:][::-1]), atol=1e-14)
    # the mirrored response spans [0, 1]: output bin k sits at one-sided fraction 2k/(N-1)
    # (away from Nyquist, where the mirrored phase jumps and the spline rings)
    u = 2 * np.arange(N // 2 - 40) / (N - 1)
    assert_allclose(out[: N // 2 - 40], 1.0 / (1 + 2j * u), atol=1e-6)
    odd = transfer.resample_transfer_function(tf, 101)
    assert odd.shape == (101,)
    assert_allclose(odd[1:51], np.conj(odd[51:][::-1]), atol=1e-14)


def test_estimate_recovers_a_minimum_phase_path():
    # white noise through a minimum-phase resonant filter; the estimate is that filter
    rng = np.random.default_rng(1)
    b, a = [1.0, 0.4], np.poly([0.9 * np.exp(0.6j), 0.9 * np.exp(-0.6j)]).real
    x = scipy.signal.lfilter(b, a, rng.normal(size=40 * 2 ** 15))
    est = transfer.estimate_transfer_function(x, N)
    _, h = scipy.signal.freqz(b, a, worN=N, whole=True)
    lag_mag = np.corrcoef(np.log(np.abs(est[: N // 2])), np.log(np.abs(h[: N // 2])))[0, 1]
    assert lag_mag > 0.99
    assert_allclose(np.abs(est[: N // 2]), np.abs(h[: N // 2]), rtol=0.15)
    phase_err = np.angle(est[: N // 2] / h[: N // 2])
    assert np.median(np.abs(phase_err)) < 0.1


def test_rms_normalize_scales_by_mean_reference_rms():
    ref = np.stack([np.full(16, 2.0), np.full(16, 4.0)])  # RMS 2 and 4 → scale 3
    assert_allclose(transfer.rms_normalize(np.full(16, 6.0), ref), 2.0)
    assert transfer.rms(np.full((2, 8), 3.0)).shape == (2,)
    with pytest.raises(ValueError):
        transfer.rms_normalize(np.ones(4), np.zeros((2, 4)))
