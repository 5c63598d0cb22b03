"""Tests of gearshot.transfer.filtering (physical-time filtering through a TF)."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from gearshot import GearshotError
from gearshot.transfer import (
    Mode,
    TransferFunction,
    filter_signal,
    fir_from_transfer_function,
    modal_frf,
)

FS = 2000.0


def _tf():
    f = np.arange(0, 1000.0 + 1e-9, 0.5)          # 0.5 Hz lines -> 4000-tap FIR at 2 kHz
    modes = [Mode(60.0, 0.03, 1.0), Mode(210.0, 0.02, 0.6), Mode(530.0, 0.04, -0.8)]
    return modal_frf(f, modes, rigid_body=0.3)


def test_fir_frequency_response_matches_tf():
    tf = _tf()
    h = fir_from_transfer_function(tf, FS)
    assert h.size == 4000
    grid = np.fft.rfftfreq(4000, 1 / FS)
    want = tf.at(grid)
    want[-1] = want[-1].real                      # Nyquist line of a real FIR
    assert_allclose(np.fft.rfft(h), want, rtol=1e-9, atol=1e-12 * np.abs(tf.values).max())


def _linear_fir(h, n_acausal):
    return np.roll(h, n_acausal)                  # index j <-> time (j - n_acausal) / fs


@pytest.mark.parametrize("acausal_fraction", [0.0, 0.125])
def test_impulse_train_has_no_wrap_around(acausal_fraction):
    tf = _tf()
    h = fir_from_transfer_function(tf, FS)
    na = int(round(acausal_fraction * h.size))
    hl = _linear_fir(h, na)
    n, period = 30000, 6000                       # impulses farther apart than the FIR
    x = np.zeros(n)
    starts = np.arange(1000, n, period)
    x[starts] = 1.0
    x[-1] = 5.0                                   # an impulse at the very end of the record
    y = filter_signal(x, FS, tf, acausal_fraction=acausal_fraction)
    assert y.shape == x.shape
    expected = np.zeros(n + 2 * h.size)
    for s, amp in [*((s, 1.0) for s in starts), (n - 1, 5.0)]:
        expected[h.size + s - na: h.size + s - na + h.size] += amp * hl
    expected = expected[h.size: h.size + n]
    tol = 1e-12 * np.abs(h).max()
    assert_allclose(y, expected, rtol=0, atol=tol)
    # nothing before the first impulse's response: the end impulse does not wrap around
    assert np.max(np.abs(y[:1000 - na])) < tol
    # the circular alternative would wrap: show the test can tell
    circ = np.fft.irfft(np.fft.rfft(x) * np.fft.rfft(np.pad(h, (0, n - h.size))), n)
    assert np.max(np.abs(circ[:1000 - na])) > 1e-3 * np.abs(h).max()


def test_sine_steady_state_gain_and_phase():
    tf = _tf()
    f0 = 123.25
    t = np.arange(40000) / FS
    y = filter_signal(np.cos(2 * np.pi * f0 * t), FS, tf)
    tail = slice(20000, 39000)                    # after the FIR's 2 s start-up, before
    #                                               the end (where the acausal part sees zeros)
    h0 = tf.at(np.array([f0]))[0]
    expected = np.abs(h0) * np.cos(2 * np.pi * f0 * t[tail] + np.angle(h0))
    assert_allclose(y[tail], expected, atol=1e-4 * np.abs(h0))


def test_batched_signals_and_band_handling():
    tf = _tf()
    rng = np.random.default_rng(0)
    x = rng.standard_normal((2, 3, 5000))
    y = filter_signal(x, FS, tf)
    assert y.shape == x.shape
    assert_allclose(y[1, 2], filter_signal(x[1, 2], FS, tf), rtol=1e-10, atol=1e-12)
    with pytest.raises(GearshotError, match="outside the band"):
        filter_signal(x[0, 0], 4 * FS, tf)        # fs/2 = 4 kHz beyond the 1 kHz FRF
    y_zero = filter_signal(x[0, 0], 4 * FS, tf, outside="zero", n_taps=8000)
    assert y_zero.shape == (5000,)


def test_bad_arguments():
    tf = _tf()
    with pytest.raises(GearshotError, match="acausal_fraction"):
        filter_signal(np.ones(10), FS, tf, acausal_fraction=0.7)
    with pytest.raises(GearshotError, match="n_taps must be even"):
        filter_signal(np.ones(10), FS, tf, n_taps=101)
    with pytest.raises(GearshotError, match="fs"):
        filter_signal(np.ones(10), -1.0, tf)
    with pytest.raises(GearshotError, match="TransferFunction"):
        filter_signal(np.ones(10), FS, np.ones(5))
    with pytest.raises(GearshotError, match="x must be finite"):
        filter_signal(np.array([1.0, np.nan]), FS, tf)
    # a TF that starts one line above DC still filters (clamped at 0 Hz)
    off = TransferFunction(tf.freqs[1:], tf.values[1:])
    assert np.isfinite(filter_signal(np.ones(100), FS, off)).all()
