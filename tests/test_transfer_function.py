"""Tests of gearshot.transfer.function.TransferFunction."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from gearshot import GearshotError
from gearshot.transfer import TransferFunction, resample_transfer_function

SHARED = Path(__file__).resolve().parents[1].parent / "shared"


def _tf(n=11, df=10.0):
    f = np.arange(n) * df
    return TransferFunction(freqs=f, values=(1 + 0.1 * f) * np.exp(-2j * np.pi * f * 1e-3),
                            name="ramp")


def test_arrays_are_read_only_copies():
    f = np.arange(5.0)
    v = np.ones(5, complex)
    tf = TransferFunction(f, v)
    f[0] = 99
    assert tf.freqs[0] == 0
    with pytest.raises(ValueError):
        tf.values[0] = 2
    assert tf.n_lines == 5 and tf.band == (0.0, 4.0) and tf.df == 1.0


@pytest.mark.parametrize("freqs, values, match", [
    ([0, 1, 1], [1, 1, 1], "strictly increasing"),
    ([0, 2, 1], [1, 1, 1], "strictly increasing"),
    ([-1, 0, 1], [1, 1, 1], ">= 0"),
    ([0, 1, 2], [1, np.nan, 1], "finite"),
    ([0, 1, 2], [1, 1], "shape"),
    ([0], [1], "at least 2"),
])
def test_invalid_construction(freqs, values, match):
    with pytest.raises(GearshotError, match=match):
        TransferFunction(freqs, values)


def test_equality_ignores_metadata_only():
    a = _tf()
    assert a == replace(a, metadata={"source": "x"})
    assert a != replace(a, values=a.values * 2)
    assert a != replace(a, name="other")


def test_at_is_exact_on_lines_and_linear_between():
    tf = _tf()
    assert_allclose(tf.at(tf.freqs), tf.values, rtol=1e-14)
    assert tf.at(15.0).shape == ()                     # scalar in, scalar out
    mid = tf.at(np.array([15.0]))[0]
    assert_allclose(mid, 0.5 * (tf.values[1] + tf.values[2]), rtol=1e-14)
    # magphase keeps |H| linear between lines
    mp = tf.at(np.array([15.0]), method="magphase")[0]
    assert_allclose(abs(mp), 0.5 * (abs(tf.values[1]) + abs(tf.values[2])), rtol=1e-12)


def test_at_outside_band():
    tf = _tf()
    # within one line of the ends: clamped
    assert_allclose(tf.at(np.array([105.0])), tf.values[-1:])
    with pytest.raises(GearshotError, match="outside the band"):
        tf.at(np.array([200.0]))
    assert tf.at(np.array([200.0]), outside="zero")[0] == 0
    assert tf.at(np.array([200.0]), outside="edge")[0] == tf.values[-1]
    with pytest.raises(GearshotError, match="outside must be"):
        tf.at(np.array([1.0]), outside="wrap")


def test_normalized_has_unit_rms_and_same_phase():
    tf = _tf()
    nt = tf.normalized()
    assert_allclose(np.sqrt(np.mean(np.abs(nt.values) ** 2)), 1.0, rtol=1e-14)
    assert_allclose(np.angle(nt.values), np.angle(tf.values), atol=1e-14)
    with pytest.raises(GearshotError, match="zero"):
        TransferFunction([0, 1], [0, 0]).normalized()


def test_normalized_preserves_white_noise_rms_through_signal_grid():
    tf = _tf(n=201, df=5.0)
    grid = tf.normalized().to_signal_grid(4096)
    # RMS gain of the grid TF for white noise = sqrt(mean |H|^2) over all bins ~ 1
    assert_allclose(np.sqrt(np.mean(np.abs(grid) ** 2)), 1.0, rtol=0.02)


def test_to_signal_grid_equals_resample_transfer_function():
    tf = _tf()
    for n in (64, 2048, 2049):
        assert_allclose(tf.to_signal_grid(n), resample_transfer_function(tf.values, n),
                        rtol=0, atol=0)
        g = tf.to_signal_grid(n)
        k = np.arange(1, (n + 1) // 2)  # Hermitian pairs (the even-n Nyquist bin, like the
        assert_allclose(g[k], np.conj(g[n - k]), rtol=1e-12)  # reference's, is left complex)


def test_to_signal_grid_matches_matlab_reference():
    path = SHARED / "reference" / "matlab_dsp_vectors.npz"
    if not path.exists():
        pytest.skip(f"reference vectors not found at {path}")
    ref = np.load(path)
    h = ref["in_H"]
    tf = TransferFunction(np.arange(h.size, dtype=float), h)
    assert_allclose(tf.to_signal_grid(2048), ref["out_tf_interp_2048"], rtol=1e-8, atol=1e-12)
    assert_allclose(tf.to_signal_grid(4096), ref["out_tf_interp_4096"], rtol=1e-8, atol=1e-12)
