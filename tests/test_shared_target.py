"""The target-side work shared by the variants of one dataset (issue #23, the paper sweep):
same numbers as the plain path, bit for bit, and no alignment done twice on the same inputs."""

import numpy as np
import pytest
from estimator_data import N, synthetic_sa

import gearshot.estimator._target as target_module
import gearshot.estimator.steps as steps
from gearshot import GearshotError
from gearshot.estimator import OneFaultShotEstimator
from gearshot.estimator._shared_work import shared_target_work, sharing
from gearshot.estimator._target import suppressed_target
from gearshot.experiments import evaluate_variants, simulated_dataset, variant_params
from gearshot.signal.alignment import subtract_healthy, subtract_with_lags


@pytest.fixture(scope="module")
def dataset():
    rng = np.random.default_rng(3)
    y = np.r_[np.zeros(40), rng.uniform(0, 1, 160)]
    return simulated_dataset(synthetic_sa(y, 4, rng), y, np.ones(N), random_state=2)


@pytest.fixture
def count_alignments(monkeypatch):
    """Record step 6 on the target side: (rows, whether their lags were searched) per call,
    shared (subtract_with_lags) or plain (subtract_healthy, always a search)."""
    calls = []
    plain, with_lags = steps.subtract_healthy, target_module.subtract_with_lags

    def counted_plain(signals, refs, **kw):
        calls.append((np.atleast_2d(signals).shape[0], True))
        return plain(signals, refs, **kw)

    def counted(signals, refs, *, lags=None, **kw):
        calls.append((np.atleast_2d(signals).shape[0], lags is None))
        return with_lags(signals, refs, lags=lags, **kw)

    monkeypatch.setattr(steps, "subtract_healthy", counted_plain)
    monkeypatch.setattr(target_module, "subtract_with_lags", counted)
    return calls


def _plain_rows(ds, variants):
    """evaluate_variants' numbers, each variant fitted and scored on its own (no sharing)."""
    out = []
    for name in variants:
        est = OneFaultShotEstimator(random_state=0, **variant_params(name))
        est.fit(*ds.fit_args(), selection_tf=np.ones(N))
        low, high = est.predict_interval(ds.test_sa)
        out.append((est.predict(ds.test_sa), low, high, est.grade_, est.selected_features_))
    return out


def test_shared_variants_give_the_plain_numbers_bit_for_bit(dataset):
    variants = ("before_da", "rms_only", "full")
    rows = evaluate_variants(dataset.fit_args(), dataset.test_sa, dataset.test_size,
                             variants=variants, selection_tf=np.ones(N), random_state=0)
    assert not sharing()                                  # nothing kept after the block
    for row, (pred, low, high, grade, selected) in zip(rows, _plain_rows(dataset, variants)):
        np.testing.assert_array_equal(row["prediction"], pred)
        assert row["mae"] == float(np.mean(np.abs(pred - dataset.test_size)))
        assert row["width"] == float(np.mean(high - low))
        assert (row["grade"], row["selected"]) == (grade, ",".join(selected))


def test_variants_of_one_dataset_do_not_realign(dataset, count_alignments):
    def aligned(variants):
        """(rows aligned, rows whose lags were searched) by evaluate_variants."""
        count_alignments.clear()
        evaluate_variants(dataset.fit_args(), dataset.test_sa, dataset.test_size,
                          variants=variants, selection_tf=np.ones(N), random_state=0)
        return (sum(r for r, _ in count_alignments),
                sum(r for r, searched in count_alignments if searched))

    rms_only = aligned(["rms_only"])
    # the test set once (predict and predict_interval share it) + the target healthy
    assert rms_only[0] == rms_only[1]
    assert rms_only[0] <= len(dataset.test_sa) + len(dataset.target_healthy) + 1
    # "full" sees the same RMS-normalized target arrays as "rms_only": nothing new
    assert aligned(["rms_only", "full"]) == rms_only
    # "before_da" sees the raw arrays: their residuals once more, with the lags found on
    # the normalized ones (no new lag search), in either order
    assert aligned(["before_da"]) == rms_only
    assert aligned(["before_da", "rms_only", "full"]) == (2 * rms_only[0], rms_only[1])
    assert aligned(["rms_only", "before_da"]) == (2 * rms_only[0], rms_only[1])


def test_shared_features_equal_plain_ones_and_are_copies(dataset):
    est = OneFaultShotEstimator(random_state=0).fit(*dataset.fit_args(),
                                                    selection_tf=np.ones(N))
    plain = est.features_of(dataset.test_sa)
    with shared_target_work():
        first = est.features_of(dataset.test_sa)
        first[:] = np.nan                                 # the caller's copy, not the store's
        with shared_target_work():                        # nested: the same store
            second = est.features_of(dataset.test_sa)
    np.testing.assert_array_equal(second, plain)


def test_shared_alignment_tells_inputs_apart(dataset, count_alignments):
    x, refs = dataset.test_sa[:6], dataset.target_healthy[-2:]
    with shared_target_work():
        a = suppressed_target(x, refs, 100)
        b = suppressed_target(x * 1.5, refs, 100)         # other signals
        c = suppressed_target(x, refs[::-1], 100)         # other references
        d = suppressed_target(x, refs, 10)                # another resolution
        again = suppressed_target(x.copy(), refs.copy(), 100)   # equal bytes: kept
        # the same arrays scaled by 1/3: the residual anew, the lags of the unscaled ones
        scaled = suppressed_target(x / 3, refs / 3, 100, unscaled=(x, refs))
    assert count_alignments == [(6, True)] * 4 + [(6, False)]
    outside = suppressed_target(x, refs, 100)             # no block: computed again
    assert count_alignments[-1] == (6, True)
    np.testing.assert_array_equal(outside, a)
    np.testing.assert_array_equal(again, a)
    np.testing.assert_array_equal(b, steps.suppress_harmonics_target(x * 1.5, refs))
    np.testing.assert_array_equal(c, steps.suppress_harmonics_target(x, refs[::-1]))
    np.testing.assert_array_equal(d, steps.suppress_harmonics_target(x, refs, upsample=10))
    np.testing.assert_array_equal(scaled, steps.suppress_harmonics_target(x / 3, refs / 3))


def test_subtract_with_lags_is_subtract_healthy_bit_for_bit():
    rng = np.random.default_rng(5)
    for n, rows, n_refs in ((2048, 300, 2), (512, 40, 3), (65, 7, 1)):
        x = rng.standard_normal((rows, n))
        refs = rng.standard_normal((n_refs, n)) + x[:n_refs]
        residual, lags = subtract_with_lags(x, refs)
        np.testing.assert_array_equal(residual, subtract_healthy(x, refs))
        assert lags.shape == (rows, n_refs) and lags.dtype.kind == "i"
        # lags do not depend on a common scale; given, they give the scaled residual
        scaled, lags_scaled = subtract_with_lags(x / 7.3, refs / 7.3)
        np.testing.assert_array_equal(lags_scaled, lags)
        np.testing.assert_array_equal(subtract_with_lags(x / 7.3, refs / 7.3, lags=lags)[0],
                                      scaled)
    with pytest.raises(GearshotError, match="lags"):
        subtract_with_lags(x, refs, lags=lags[:3])
    with pytest.raises(GearshotError, match="lags"):
        subtract_with_lags(x, refs, lags=lags.astype(float))


def test_reading_a_database_involves_no_dask_scheduler(tmp_path):
    """A block is decoded straight into numpy: under the distributed scheduler a lazy Zarr
    read inside a task (a sweep condition, a family rig) would go to the scheduler as a
    graph (the 24 MB "large graph" warnings of the paired paper sweep) and back."""
    import dask

    from gearshot.sim import build_database, load_database

    def no_scheduler(*args, **kwargs):
        raise AssertionError("a dask scheduler was asked to compute")

    store = tmp_path / "db"
    build_database(store, speeds=[15], loads=[10], grades=[5, 7], n_healthy=2, n_faulty=3,
                   seed=4, client=False, progress=False, paired=True)
    with dask.config.set(scheduler=no_scheduler):
        db = load_database(store, speed=15, load=10)
    assert all(isinstance(db[name].variable._data, np.ndarray) for name in ("sa", "sa_twin"))
    assert db.sa.shape == (10, 2048) and np.isfinite(db.sa_twin.values).all()
