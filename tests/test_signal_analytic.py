"""Analytic checks of gearshot.signal: known inputs with known answers."""

import numpy as np
import pytest
import scipy.signal
from numpy.testing import assert_allclose

from gearshot import signal

N = 2048
MESH = 38


def order_amplitude_phase(x, order):
    spec = np.fft.rfft(x, axis=-1)
    return 2 * np.abs(spec[..., order]) / x.shape[-1], np.angle(spec[..., order])


def test_tone_at_integer_order_keeps_amplitude_and_phase():
    rng = np.random.default_rng(1)
    theta = np.arange(40 * N) / N  # 40 cycles, revolutions
    for order in (1, 7, 38, 300):
        amp, phase = rng.uniform(0.5, 3), rng.uniform(-np.pi, np.pi)
        noise = rng.normal(scale=0.5, size=theta.size)  # not synchronous: averages down
        x = amp * np.cos(2 * np.pi * order * theta + phase) + noise
        sa = signal.synchronous_average(x, N)
        a, p = order_amplitude_phase(sa, order)
        assert a == pytest.approx(amp, rel=0.03)
        assert np.angle(np.exp(1j * (p - phase))) == pytest.approx(0, abs=0.03)
    # a non-integer order averages away
    x = np.cos(2 * np.pi * 12.5 * theta)
    assert np.max(np.abs(signal.synchronous_average(x, N))) < 1e-10


def test_synchronous_average_uses_requested_cycles():
    x = np.repeat(np.arange(5.0), 8)  # cycle i is constant i
    assert_allclose(signal.synchronous_average(x, 8, n_cycles=3), np.full(8, 1.0))
    assert_allclose(signal.synchronous_average(x, 8), np.full(8, 2.0))
    batch = np.stack([x, 2 * x])
    assert signal.synchronous_average(batch, 8).shape == (2, 8)


def test_difference_signal_removes_mesh_bands_and_keeps_the_rest_exactly():
    rng = np.random.default_rng(2)
    sa = rng.normal(size=(3, N))
    diff = signal.difference_signal(sa, MESH, n_sidebands=2)
    harm = signal.harmonic_signal(sa, MESH, n_sidebands=2)
    assert_allclose(diff + harm, sa, atol=1e-12)
    spec_in, spec_out = np.fft.rfft(sa), np.fft.rfft(diff)
    bands = np.zeros(N // 2 + 1, bool)
    for k in range(1, (N // 2) // MESH + 1):
        bands[k * MESH - 2: k * MESH + 3] = True
    assert np.max(np.abs(spec_out[:, bands])) < 1e-9
    assert_allclose(spec_out[:, ~bands], spec_in[:, ~bands], rtol=1e-10, atol=1e-9)
    assert bands.sum() == 26 * 5  # 26 harmonics below Nyquist, 5 orders each
    assert np.isrealobj(diff)


def test_difference_signal_sideband_count():
    rng = np.random.default_rng(3)
    sa = rng.normal(size=N)
    d0 = np.fft.rfft(signal.difference_signal(sa, MESH, n_sidebands=0))
    assert abs(d0[MESH]) < 1e-9 and abs(d0[MESH + 1]) > 1e-3


def test_envelope_of_am_tone():
    t = np.arange(N) / N
    mod = 1 + 0.5 * np.cos(2 * np.pi * 3 * t)
    x = mod * np.cos(2 * np.pi * 200 * t)
    assert_allclose(signal.envelope(x), mod, atol=1e-9)


def test_amplitude_spectrum_parseval_and_white_noise_level():
    rng = np.random.default_rng(4)
    x = rng.normal(scale=2.0, size=8 * 4096)
    spec = signal.amplitude_spectrum(x, nfft=4096)
    # mean square of the amplitude spectrum equals the signal's power (Parseval)
    assert np.mean(spec ** 2) == pytest.approx(np.mean(x ** 2), rel=1e-12)
    assert np.median(spec) == pytest.approx(2.0, rel=0.05)


def test_acs_background_finds_noise_floor_under_strong_tones():
    rng = np.random.default_rng(5)
    nfft = 2 ** 15
    n = 12 * nfft
    t = np.arange(n)
    x = rng.normal(scale=1.0, size=n)
    for k in range(1, 60):  # 59 strong tones spread over the band
        x += 30.0 * np.cos(2 * np.pi * (k * 271) * t / nfft + k)
    spec = signal.amplitude_spectrum(x, nfft=nfft)
    assert spec.max() > 100  # the tones stand far above the floor
    background = signal.acs_background(spec)
    assert_allclose(background, 1.0, rtol=0.10)
    assert_allclose(background[1:], background[1:][::-1])  # symmetric


def test_minimum_phase_recovers_a_minimum_phase_filter():
    # zeros at 0.5, -0.3±0.4j and poles at 0.8, 0.6j: all inside the unit circle
    b = np.poly([0.5, -0.3 + 0.4j, -0.3 - 0.4j]).real
    a = np.poly([0.8, 0.6j, -0.6j]).real
    _, h = scipy.signal.freqz(b, a, worN=4096, whole=True)
    h_mp = signal.minimum_phase(np.abs(h))
    assert_allclose(h_mp, h, rtol=1e-8, atol=1e-8 * np.abs(h).max())


def test_minimum_phase_of_a_maximum_phase_filter_flips_its_zero():
    _, h_max = scipy.signal.freqz([0.5, 1.0], worN=4096, whole=True)  # zero at -2
    _, h_min = scipy.signal.freqz([1.0, 0.5], worN=4096, whole=True)  # zero at -0.5
    assert_allclose(signal.minimum_phase(np.abs(h_max)), h_min, atol=1e-9)


def test_fractional_shift_and_alignment_recover_a_known_delay():
    rng = np.random.default_rng(6)
    spec = np.zeros(N // 2 + 1, complex)
    spec[1:400] = rng.normal(size=399) + 1j * rng.normal(size=399)
    ref = np.fft.irfft(spec, n=N)
    delayed = signal.fractional_shift(ref, 17.37)
    assert_allclose(signal.fractional_shift(delayed, -17.37), ref, atol=1e-12)
    other = signal.fractional_shift(rng.permutation(ref), 3.0)
    residual, idx, delay = signal.subtract_healthy(delayed, np.stack([other, ref]),
                                                   return_details=True)
    assert idx == 1
    assert delay == pytest.approx(17.37, abs=0.006)
    assert np.max(np.abs(residual)) < 1e-3 * np.max(np.abs(ref))


def _tacho_and_vibration(fs, duration, speed_of_t, order, amp, rng):
    t = np.arange(int(duration * fs)) / fs
    speed = speed_of_t(t)  # rev/s
    theta = np.cumsum(speed) / fs  # revolutions
    tacho = (np.mod(theta, 1.0) < 0.2).astype(float) * 5.0  # TTL, rising at integer revs
    x = amp * np.cos(2 * np.pi * order * theta) + 0.1 * rng.normal(size=t.size)
    return t, theta, tacho, x


def test_pulse_times_are_subsample_accurate():
    fs = 10_000.0
    t = np.arange(int(fs)) / fs
    tacho = np.sin(2 * np.pi * 7.3 * t)  # analog tacho, rising zero crossings
    pulses = signal.pulse_times(tacho, fs, threshold=0.0)
    expected = np.arange(1, 8) / 7.3
    assert_allclose(pulses, expected, atol=2e-6)


def test_angular_resampling_recovers_order_under_wandering_speed():
    rng = np.random.default_rng(7)
    fs, duration, f0, order, amp = 50_000.0, 20.0, 15.0, 38, 1.0
    speed = lambda t: f0 * (1 + 0.05 * np.sin(2 * np.pi * t / 7.0))  # noqa: E731, ±5 %
    _, _, tacho, x = _tacho_and_vibration(fs, duration, speed, order, amp, rng)
    pulses = signal.pulse_times(tacho, fs)
    spr = 256
    angle_signal = signal.angular_resample(x, fs, pulses, samples_per_rev=spr)
    assert angle_signal.size == (pulses.size - 1) * spr
    a_ok, _ = order_amplitude_phase(signal.synchronous_average(angle_signal, spr), order)
    assert a_ok == pytest.approx(amp, rel=0.01)
    # constant-speed assumption: equally spaced pulses at the mean speed
    naive = np.linspace(pulses[0], pulses[-1], pulses.size)
    naive_signal = signal.angular_resample(x, fs, naive, samples_per_rev=spr)
    a_bad, _ = order_amplitude_phase(signal.synchronous_average(naive_signal, spr), order)
    assert a_bad < 0.5 * amp
    assert abs(a_ok - amp) < 0.1 * abs(a_bad - amp)


def test_lag_search_equals_the_full_interpolated_correlation():
    """The coarse-to-fine delay search finds the first maximum of the ×100 interpolation."""
    from gearshot.signal.alignment import _LagSearch

    rng = np.random.default_rng(8)
    n, up = 512, 100
    theta = np.arange(n) / n
    base = np.cos(2 * np.pi * 19 * theta) + 0.3 * np.cos(2 * np.pi * 38 * theta + 1)
    x = base + 0.2 * rng.normal(size=(40, n))
    ref = np.roll(base, 7) + 0.2 * rng.normal(size=n)
    cross = np.fft.fft(x) * np.conj(np.fft.fft(ref))
    fine = np.zeros((40, n * up // 2 + 1), complex)
    fine[:, : n // 2] = cross[:, : n // 2]
    fine[:, n // 2] = cross[:, n // 2] / 4
    brute = np.argmax(np.fft.irfft(fine, n=n * up), axis=-1)
    np.testing.assert_array_equal(_LagSearch(n, up).best(cross), brute)


@pytest.mark.parametrize("n", [2, 3])
def test_lag_search_on_signals_shorter_than_its_candidate_count(n):
    """Regression (found by Hypothesis): 2- and 3-sample signals align to themselves."""
    x = np.arange(1.0, n + 1)
    residual = signal.subtract_healthy(x, x, upsample=1)
    np.testing.assert_allclose(residual, 0.0, atol=1e-12)


def test_pulse_times_with_no_rearmed_crossing_is_empty():
    """Regression (found by Hypothesis): an up-crossing never preceded by a re-arm is no pulse."""
    x = np.array([0.0] + [1.7e16] * 8 + [-1.3e16])
    assert signal.pulse_times(x, 1000.0).size == 0
