"""Condition indicators: analytic values and physical sanity."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from gearshot import GearshotError, features, signal

N = 2048
MESH = 38


def gear_sa(fault=0.0, *, rng, n=1):
    """Mesh tones + small random profile noise + a local impact of height ``fault``."""
    theta = np.arange(N) / N
    sa = (np.cos(2 * np.pi * MESH * theta) + 0.3 * np.cos(2 * np.pi * 2 * MESH * theta + 1))
    out = np.tile(sa, (n, 1)) + 0.02 * rng.normal(size=(n, N))
    pulse = np.exp(-0.5 * ((np.arange(N) - 700) / 3.0) ** 2)
    return out + fault * pulse


def test_default_is_the_papers_four():
    assert features.PAPER_FEATURES == ("rms_diff", "kurtosis_diff", "rms_env_diff",
                                       "skewness_env_diff")
    rng = np.random.default_rng(0)
    out = features.extract_features(gear_sa(rng=rng, n=5), MESH)
    assert out.shape == (5, 4)
    everything = features.extract_features(gear_sa(rng=rng, n=3), MESH,
                                           names=features.available_features())
    assert everything.shape == (3, 18)   # 10 indicators + 8 band RMS (issue #30)
    assert set(features.available_features()) >= {"fm0", "fm4", "m6a", "m8a", "na4", "er"}


def test_gaussian_difference_signal_moments():
    rng = np.random.default_rng(1)
    x = rng.normal(size=(200, N))
    f = features.extract_features(x, MESH, names=["kurtosis_diff", "fm4", "m6a", "m8a",
                                                  "na4"])
    assert_allclose(f.mean(0), [3, 3, 15, 105, 3], rtol=0.1)  # Gaussian moments


def test_rms_diff_matches_direct_computation():
    rng = np.random.default_rng(2)
    x = rng.normal(size=(4, N))
    d = signal.difference_signal(x, MESH)
    assert_allclose(features.extract_features(x, MESH, names="rms_diff")[:, 0],
                    np.sqrt(np.mean(d ** 2, axis=1)))


def test_pure_mesh_signal_has_no_difference_energy():
    theta = np.arange(N) / N
    sa = np.cos(2 * np.pi * MESH * theta) + 0.5 * np.sin(2 * np.pi * (MESH + 2) * theta)
    f = features.extract_features(sa[None], MESH)
    assert_allclose(f, 0.0, atol=1e-9)  # moment ratios are 0 below the RMS floor


def test_fm0_of_a_pure_mesh_tone():
    theta = np.arange(N) / N
    sa = 2.0 * np.cos(2 * np.pi * MESH * theta)
    # peak-to-peak 4 over a harmonic amplitude of 2
    assert features.extract_features(sa, MESH, names="fm0")[0] == pytest.approx(2.0)


def test_fault_indicators_grow_with_fault_size():
    rng = np.random.default_rng(3)
    names = ["rms_diff", "kurtosis_diff", "rms_env_diff", "fm4", "na4", "er", "m6a"]
    values = [features.extract_features(gear_sa(a, rng=rng), MESH, names=names)[0]
              for a in (0.0, 0.2, 0.5, 1.0)]
    values = np.array(values)
    assert np.all(np.diff(values, axis=0) > 0), values


def test_na4_baseline_variance_normalizes_trend():
    rng = np.random.default_rng(4)
    healthy = gear_sa(rng=rng, n=20)
    var = features.na4_baseline_variance(healthy, MESH)
    own = features.extract_features(healthy, MESH, names="na4")[:, 0]
    based = features.extract_features(healthy, MESH, names="na4", baseline_variance=var)
    assert_allclose(based[:, 0], own, rtol=0.2)
    # a noisier (worn) signal: own-variance NA4 stays ~3, baseline NA4 rises
    worn = healthy + 0.05 * rng.normal(size=healthy.shape)
    assert np.mean(features.extract_features(worn, MESH, names="na4",
                                             baseline_variance=var)) > 3 * np.mean(own)


def test_unknown_name_lists_valid_ones():
    with pytest.raises(GearshotError, match="valid names are .*skewness_env_diff"):
        features.extract_features(np.zeros((1, N)), MESH, names=["nope"])
    with pytest.raises(GearshotError, match="baseline_variance"):
        features.extract_features(np.zeros((1, N)), MESH, names="na4", baseline_variance=-1.0)


def test_band_rms_splits_the_difference_signal_by_order():
    """Issue #30's band features: a tone at order k lands in band 1 + 8 (k - 1) // 1024
    with its RMS a / sqrt(2); with the mean, the bands' squares sum to rms_diff²."""
    n = 2048
    theta = np.arange(n) / n
    names = [f"band_rms_{k}" for k in range(1, 9)]
    for order, band in ((5, 1), (300, 3), (1000, 8)):
        tone = 2.0 * np.cos(2 * np.pi * order * theta)
        f = features.extract_features(tone, 38, names=names)
        expected = np.zeros(8)
        expected[band - 1] = 2.0 / np.sqrt(2)
        np.testing.assert_allclose(f, expected, atol=1e-12)
    x = np.random.default_rng(0).normal(size=(4, n))
    f = features.extract_features(x, 38, names=["rms_diff", *names])
    np.testing.assert_allclose(np.sum(f[:, 1:] ** 2, axis=1) + x.mean(axis=1) ** 2,
                               f[:, 0] ** 2, rtol=1e-10)
