"""subtract_healthy's reference pruning: references the energy bound drops before their
fine delay search could not have been chosen (the results are the unpruned ones, bit for
bit), and the bound does drop some."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from gearshot.signal import fractional_shift, subtract_healthy
from gearshot.signal.alignment import _subtract, subtract_with_lags


def _gear_like(n, n_signals, n_refs, seed):
    """Mesh-harmonic signals with random delays, amplitudes and noise; references alike."""
    rng = np.random.default_rng(seed)
    theta = np.arange(n) / n
    base = (np.cos(2 * np.pi * 19 * theta) + 0.4 * np.cos(2 * np.pi * 38 * theta + 1)
            + 0.1 * np.cos(2 * np.pi * 57 * theta + 2))
    refs = np.vstack([fractional_shift(base * rng.uniform(0.7, 1.3), rng.uniform(0, 5))
                      + 0.05 * rng.normal(size=n) for _ in range(n_refs)])
    signals = np.vstack([fractional_shift(refs[rng.integers(n_refs)], rng.uniform(-3, 3))
                         * rng.uniform(0.9, 1.1) + 0.05 * rng.normal(size=n)
                         for _ in range(n_signals)])
    return signals, refs


@pytest.mark.parametrize("n, upsample, drops", [(256, 100, True), (255, 100, True),
                                               (128, 12, True), (128, 10, False),
                                               (97, 7, False), (64, 1, False)])
def test_pruned_search_gives_the_full_search_results(n, upsample, drops):
    """``drops``: on the ×4 coarse grid (upsample a multiple of 4) the bound is tight enough
    to drop references of these signals; on coarser grids it may keep them all."""
    signals, refs = _gear_like(n, 40, 6, seed=n + upsample)
    full = _subtract(signals, refs, upsample)
    pruned = _subtract(signals, refs, upsample, prune=True)
    for a, b in zip(full[:3], pruned[:3]):   # residual, chosen reference, delay
        assert_array_equal(a, b)
    lags = pruned[3]
    searched = lags >= 0
    assert searched[np.arange(len(signals)), pruned[1]].all()
    assert_array_equal(lags[searched], full[3][searched])   # the searched lags are the same
    if drops:   # the bound drops references (else this test proves nothing)
        assert not searched.all()


def test_subtract_healthy_prunes_and_subtract_with_lags_does_not():
    signals, refs = _gear_like(256, 20, 5, seed=3)
    residual, index, delay = subtract_healthy(signals, refs, return_details=True)
    full = _subtract(signals, refs, 100)
    assert_array_equal(residual, full[0])
    assert_array_equal(index, full[1])
    assert_array_equal(delay, full[2])
    _, lags = subtract_with_lags(signals, refs)
    assert_array_equal(lags, full[3])   # every reference's lag, as documented
    assert (lags >= 0).all()


def test_a_single_reference_is_searched_as_before():
    signals, refs = _gear_like(128, 10, 1, seed=4)
    full = _subtract(signals, refs, 100)
    pruned = _subtract(signals, refs, 100, prune=True)
    for a, b in zip(full, pruned):
        assert_array_equal(a, b)
