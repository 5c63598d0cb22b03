"""The fit's fast paths (issue #23 item 4) give what the plain computations give.

* the simulated side built as spectra (steps 4-6 in the frequency domain) against the
  steps one by one in the time domain;
* features from spectra against features from signals, and block-wise features against
  row-by-row ones (bit for bit);
* the k-nearest-neighbour searches by one distance matrix against scikit-learn's tree,
  ties included (bit for bit).
"""

import estimator_data
import numpy as np
import pytest
from estimator_data import MESH, N, synthetic_sa
from numpy.testing import assert_allclose, assert_array_equal

from gearshot import GearshotError
from gearshot.estimator import steps
from gearshot.estimator.knn import _knn_pipeline, _nearest, _validation_neighbours
from gearshot.features import available_features, extract_features, spectrum_features
from gearshot.transfer import one_sided_response, propagate, propagate_spectrum


@pytest.fixture(scope="module")
def paired():
    """Signals of one grade, their healthy twins (the healthy rows' own SA) and sizes."""
    rng = np.random.default_rng(5)
    y = np.r_[np.zeros(12), rng.uniform(0.05, 1, 60)]
    seeds = rng.integers(0, 2**31, y.size)
    sa = np.vstack([synthetic_sa([yi], 6, np.random.default_rng(s))[0]
                    for yi, s in zip(y, seeds)])
    twins = np.vstack([synthetic_sa([0.0], 6, np.random.default_rng(s))[0] for s in seeds])
    return sa, twins, y


def _time_domain_chain(sa, healthy, tf, names, twins=None, noise=None, rms=True):
    """Steps 4-7 one by one in the time domain (what simulated_features stands for)."""
    if twins is None:
        sim = steps.propagate_simulated(sa, tf)
        if rms:
            sim = steps.normalize_rms(sim, sim[healthy])
        sim = steps.suppress_harmonics_simulated(sim, healthy)
    else:
        sim = steps.propagate_simulated(steps.suppress_harmonics_simulated(sa, healthy, twins),
                                        tf)
        if rms:
            sim = steps.normalize_rms(sim, steps.propagate_simulated(sa[healthy], tf))
    if noise is not None:
        sim = sim + noise
    feats, _ = steps.centred_features(sim, mesh_order=MESH, names=names, healthy_mask=healthy)
    return feats


@pytest.mark.parametrize("with_tf", [True, False])
@pytest.mark.parametrize("mode", ["twins+noise", "twins", "first_healthy", "no_rms"])
def test_simulated_features_equal_the_time_domain_steps(paired, with_tf, mode):
    sa, twins, y = paired
    healthy = y == 0
    tf = estimator_data.tf_pair()[0] if with_tf else None
    names = available_features()[:4]
    rng = np.random.default_rng(1)
    power = np.abs(np.fft.rfft(rng.normal(size=N))) ** 2 * 1e-4
    noise = (steps.residue_noise(power, sa.shape[0], N, np.random.default_rng(2))
             if mode == "twins+noise" else None)
    use_twins = twins if mode in ("twins", "twins+noise") else None
    rms = mode != "no_rms"
    want = _time_domain_chain(sa, healthy, tf, names, use_twins, noise, rms)
    got = steps.simulated_features(sa, healthy, tf, mesh_order=MESH, names=names,
                                   twins=use_twins, noise=noise, rms_normalization=rms)
    scale = np.abs(want).max(axis=0)
    assert_allclose(got, want, rtol=0, atol=1e-9 * scale.max())
    if noise is not None:   # the same residue given as its spectrum
        spec = steps.simulated_features(sa, healthy, tf, mesh_order=MESH, names=names,
                                        twins=use_twins, noise_spectrum=np.fft.rfft(noise),
                                        rms_normalization=rms)
        assert_allclose(spec, want, rtol=0, atol=1e-9 * scale.max())
    # a faulty signal's features differ from the healthy mean (the test can fail)
    assert np.all(np.abs(got[y > 0.5]).max(axis=0) > 1e-6 * scale)


def test_simulated_features_refuse_twins_of_another_shape(paired):
    sa, twins, y = paired
    with pytest.raises(GearshotError, match="twins must have the shape"):
        steps.simulated_features(sa, y == 0, None, mesh_order=MESH, names=["rms_diff"],
                                 twins=twins[:-1])


def test_residue_noise_is_the_inverse_fft_of_its_spectrum():
    from gearshot.estimator._simulated import residue_noise_spectrum

    power = np.linspace(1.0, 0.0, N // 2 + 1)
    spec = residue_noise_spectrum(power, 3, N, np.random.default_rng(4))
    noise = steps.residue_noise(power, 3, N, np.random.default_rng(4))
    assert_array_equal(np.fft.irfft(spec, n=N), noise)
    with pytest.raises(GearshotError, match="n_points // 2 \\+ 1 = 1025"):
        residue_noise_spectrum(power[:-1], 3, N, np.random.default_rng(4))


# ------------------------------------------------------------------ features of spectra
def test_spectrum_features_equal_features_of_the_signals(paired):
    sa = paired[0][:9] - paired[1][:9] + paired[0][9]   # differences on a mesh
    names = available_features()
    want = extract_features(sa, MESH, names=names, baseline_variance=0.5)
    got = spectrum_features(np.fft.rfft(sa), N, MESH, names=names, baseline_variance=0.5)
    assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    # leading axes and a single signal keep their shape
    three = spectrum_features(np.fft.rfft(sa).reshape(3, 3, -1), N, [MESH, 17])
    assert_allclose(three.reshape(9, -1), extract_features(sa, [MESH, 17]), rtol=1e-9)
    assert spectrum_features(np.fft.rfft(sa[0]), N, MESH).shape == (4,)


def test_spectrum_features_refuse_bad_spectra():
    good = np.fft.rfft(np.random.default_rng(0).normal(size=(2, 64)))
    with pytest.raises(GearshotError, match="spectrum must be complex"):
        spectrum_features(good.real, 64, 5)
    with pytest.raises(GearshotError, match="n_points // 2 \\+ 1 = 33"):
        spectrum_features(good[:, :-1], 64, 5)
    bad = good.copy()
    bad[1, 3] = np.nan
    with pytest.raises(GearshotError, match="spectrum must be finite"):
        spectrum_features(bad, 64, 5)
    with pytest.raises(GearshotError, match="n_points must be >= 4"):
        spectrum_features(good[:, :2], 2, 1)


def test_features_in_blocks_equal_one_batch(paired, monkeypatch):
    """Batches are computed in blocks of rows: the same numbers as one batch, bit for bit."""
    import gearshot.features as features_module

    rng = np.random.default_rng(3)
    sa = np.vstack([paired[0]] * 3) + rng.normal(size=(3 * paired[0].shape[0], N))
    names = available_features()
    blocks = extract_features(sa, MESH, names=names)
    assert sa.shape[0] * N > features_module._CHUNK_ELEMENTS   # more than one block
    monkeypatch.setattr(features_module, "_CHUNK_ELEMENTS", sa.size)
    assert_array_equal(blocks, extract_features(sa, MESH, names=names))
    assert_allclose(blocks[5], extract_features(sa[5], MESH, names=names), rtol=1e-12)


def test_propagate_is_the_inverse_fft_of_propagate_spectrum(paired):
    tf = estimator_data.tf_pair()[0]
    sa = paired[0]
    assert_array_equal(np.fft.irfft(propagate_spectrum(sa, tf), n=N), propagate(sa, tf))
    assert_array_equal(propagate_spectrum(sa, tf), np.fft.rfft(sa) * one_sided_response(tf))
    with pytest.raises(GearshotError, match="tf has 2047 points"):
        propagate_spectrum(sa, tf[:-1])


# ------------------------------------------------------------------ nearest neighbours
def _probe(X_train, y_train, X_val, k):
    probe = _knn_pipeline(k).fit(X_train, y_train)
    _, idx = probe.named_steps["knn"].kneighbors(
        probe.named_steps["scale"].transform(X_val), n_neighbors=k)
    return idx


@pytest.mark.parametrize("ties", [False, True])
def test_validation_neighbours_equal_the_tree(ties):
    rng = np.random.default_rng(7)
    X = rng.normal(size=(300, 2)) * [1.0, 30.0]
    if ties:   # a coarse grid: many equal distances, which the tree answers
        X = np.round(X, 0)
    y = rng.uniform(size=300)
    train, val = np.arange(210), np.arange(210, 300)
    for k in (1, 7, 100):
        got = _validation_neighbours(X[train], y[train], X[val], k)
        assert_array_equal(got, _probe(X[train], y[train], X[val], k))
    scaled = X[train] / X[train].std(axis=0)
    assert (_nearest(scaled, X[val] / X[train].std(axis=0), 100) is None) == ties


@pytest.mark.parametrize("ties", [False, True])
def test_knn_predict_equals_the_pipeline(ties):
    rng = np.random.default_rng(8)
    X = rng.normal(size=(400, 2))
    if ties:
        X = np.round(X, 1)
    y = np.clip(0.5 + 0.2 * X[:, 0] + 0.05 * rng.normal(size=400), 0, 1)
    model = steps.fit_knn(X, y, random_state=1)
    queries = np.vstack([rng.normal(size=(50, 2)), X[:20]])
    if ties:
        queries = np.round(queries, 1)
    assert_array_equal(model.predict(queries), model.pipeline.predict(queries))
    assert_array_equal(model.predict(queries[:1]), model.pipeline.predict(queries[:1]))


def test_fit_knn_refuses_bad_shapes_and_values():
    X = np.random.default_rng(0).normal(size=(20, 2))
    with pytest.raises(GearshotError, match="y must hold one label per row of X"):
        steps.fit_knn(X, np.ones(19))
    with pytest.raises(GearshotError, match="X must have 2 dimension"):
        steps.fit_knn(X[:, 0], np.ones(20))
    bad = X.copy()
    bad[3, 1] = np.inf
    with pytest.raises(GearshotError, match="X must be finite"):
        steps.fit_knn(bad, np.ones(20))
