"""Parity with the original MATLAB implementation (../shared/reference/matlab_dsp_vectors.npz).

Reference arrays hold signals in columns; gearshot holds them along the last axis.
"""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from gearshot import features, signal, transfer
from gearshot.estimator import steps

RTOL = 1e-8
MESH = 38


def assert_parity(actual, expected):
    """Relative error ≤ 1e-8 against the reference's largest magnitude."""
    expected = np.asarray(expected)
    scale = np.max(np.abs(expected))
    assert_allclose(actual, expected, rtol=0, atol=RTOL * scale)


def test_amplitude_spectrum(matlab_ref):
    assert_parity(signal.amplitude_spectrum(matlab_ref["in_x_long"]), matlab_ref["out_psd"])


def test_acs_background(matlab_ref):
    assert_parity(signal.acs_background(matlab_ref["out_psd"]), matlab_ref["out_bg"])


def test_minimum_phase(matlab_ref):
    assert_parity(signal.minimum_phase(matlab_ref["out_bg"]), matlab_ref["out_tf_mp"])


def test_estimate_transfer_function(matlab_ref):
    est = transfer.estimate_transfer_function(matlab_ref["in_x_long"], 2048)
    assert_parity(est, matlab_ref["out_tf_est_2048"])


@pytest.mark.parametrize("n", [2048, 4096])
def test_resample_transfer_function(matlab_ref, n):
    out = transfer.resample_transfer_function(matlab_ref["in_H"], n)
    assert_parity(out, matlab_ref[f"out_tf_interp_{n}"])


def test_synchronous_average(matlab_ref):
    sa = signal.synchronous_average(matlab_ref["in_x_long"], 2048, n_cycles=50)
    assert_parity(sa, matlab_ref["out_sa50"])


def test_features_with_reference_centring(matlab_ref):
    train = matlab_ref["in_sa_train"].T
    healthy = matlab_ref["in_sa_healthy"].T
    test = matlab_ref["in_sa_test"].T
    names = features.PAPER_FEATURES
    first_healthy = np.arange(len(train)) == 0  # the reference's training set: one healthy SA
    x_train, _ = steps.centred_features(train, mesh_order=MESH, names=names,
                                        healthy_mask=first_healthy)
    x_healthy, healthy_mean = steps.centred_features(
        healthy, mesh_order=MESH, names=names, healthy_mask=np.ones(len(healthy), bool))
    x_test, _ = steps.centred_features(test, healthy_mean, mesh_order=MESH, names=names)
    # each feature row has its own scale: compare row by row
    for row, ref in zip(np.concatenate([x_train, x_healthy]).T, matlab_ref["out_x_training"]):
        assert_parity(row, ref)
    for row, ref in zip(x_test.T, matlab_ref["out_x_test"]):
        assert_parity(row, ref)
    assert_parity(np.r_[matlab_ref["in_y_train"], np.zeros(10)], matlab_ref["out_y_training"])


def test_subtract_healthy(matlab_ref):
    healthy = matlab_ref["in_sa_healthy"].T
    refs = healthy[8:10]
    assert_parity(signal.subtract_healthy(matlab_ref["in_sa_test"].T, refs).T,
                  matlab_ref["out_sub_test"])
    assert_parity(signal.subtract_healthy(healthy[:8], refs).T, matlab_ref["out_sub_healthy"])


def test_subtract_simulated_healthy(matlab_ref):
    train = matlab_ref["in_sa_train"].T
    healthy_mask = np.arange(len(train)) == 0
    assert_parity(steps.suppress_harmonics_simulated(train, healthy_mask).T,
                  matlab_ref["out_sub_train"])


def test_rms_normalize(matlab_ref):
    healthy = matlab_ref["in_sa_healthy"].T
    train = matlab_ref["in_sa_train"].T
    assert_parity(transfer.rms_normalize(matlab_ref["in_sa_test"].T, healthy).T,
                  matlab_ref["out_rmsn_test"])
    assert_parity(transfer.rms_normalize(healthy, healthy).T, matlab_ref["out_rmsn_healthy"])
    assert_parity(transfer.rms_normalize(train, train[0]).T, matlab_ref["out_rmsn_train"])
