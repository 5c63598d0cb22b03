"""Step 6's reference blend (gearshot.signal.reference_blend and the estimator's
``reference_blend``): a healthy pattern that moves with the speed through a sharp
resonance is followed by a blend of references where no single reference matches it, a
fault component is left nearly whole, and the estimator records what it blends."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from gearshot import GearshotError
from gearshot.signal import fractional_shift, subtract_blend, subtract_healthy
from gearshot.signal.alignment import _subtract

N = 512


def _resonant_runs(speeds, *, seed=0, fault=0.0):
    """SAs of one rough gear (every order excited, fixed amplitudes and phases) through a
    lightly damped mode (damping ratio 0.3 %) at order 150 of the nominal speed: order k
    sits at frequency k × speed, so a 0.5 % change of speed moves the response near the
    mode by tens of percent and turns its phase. ``fault``: a local impulse of that
    height added (a tooth's signature, a shape no healthy SA has)."""
    rng = np.random.default_rng(seed)
    k = np.arange(N // 2 + 1)
    excitation = rng.normal(size=k.size) * np.exp(2j * np.pi * rng.uniform(size=k.size))
    excitation[0] = 0.0
    theta = np.arange(N) / N
    out = []
    for s in speeds:
        r = k * s / 150.0
        h = 1.0 / (1 - r ** 2 + 2j * 0.003 * r)
        sa = np.fft.irfft(excitation * h, n=N)
        out.append(sa + fault * np.exp(-0.5 * ((theta - 0.3) / 0.004) ** 2))
    return np.array(out)


def test_one_reference_is_subtract_healthy_bit_for_bit():
    rng = np.random.default_rng(1)
    refs = rng.normal(size=(5, 128)).cumsum(axis=1)
    signals = refs[[0, 2, 4]] + 0.1 * rng.normal(size=(3, 128))
    blended, lags = subtract_blend(signals, refs, n_blend=1)
    assert_array_equal(blended, subtract_healthy(signals, refs))
    assert lags.shape == (3, 5)
    # leading axes are batch axes, as everywhere in gearshot.signal
    batch, batch_lags = subtract_blend(np.stack([signals, signals[::-1]]), refs)
    assert batch.shape == (2, 3, 128) and batch_lags.shape == (2, 3, 5)
    assert_array_equal(batch[0], subtract_blend(signals, refs)[0])


def test_a_speed_dependent_pattern_is_followed_by_the_blend_and_the_fault_kept():
    rng = np.random.default_rng(2)
    refs = _resonant_runs(1 + 0.005 * rng.uniform(-1, 1, 12))
    new = _resonant_runs(1 + 0.005 * rng.uniform(-1, 1, 6))
    single = subtract_healthy(new, refs)
    blended, _ = subtract_blend(new, refs, n_blend=3)
    # the healthy residue: far less energy left by the blend than by the best reference
    assert (blended ** 2).sum() < 0.1 * (single ** 2).sum()
    # a fault component passes: the faulty SAs' residual keeps most of the impulse
    faulty = _resonant_runs(1 + 0.005 * rng.uniform(-1, 1, 6), fault=3.0)
    impulse = _resonant_runs([1.0], fault=3.0)[0] - _resonant_runs([1.0])[0]
    kept, _ = subtract_blend(faulty, refs, n_blend=3)
    along = kept @ impulse / (impulse @ impulse)
    assert np.all(np.abs(along - 1) < 0.05)


def test_the_step_6_function_blends_when_asked_and_is_the_papers_otherwise():
    from gearshot.estimator.steps import suppress_harmonics_target

    rng = np.random.default_rng(5)
    refs = _resonant_runs(1 + 0.005 * rng.uniform(-1, 1, 8))
    new = _resonant_runs(1 + 0.005 * rng.uniform(-1, 1, 3))
    assert_array_equal(suppress_harmonics_target(new, refs), subtract_healthy(new, refs))
    blended = suppress_harmonics_target(new, refs, blend=3)
    assert_array_equal(blended, subtract_blend(new, refs, n_blend=3)[0])
    assert (blended ** 2).sum() < (subtract_healthy(new, refs) ** 2).sum()


def test_the_pruned_lag_search_keeps_every_reference_the_blend_picks():
    rng = np.random.default_rng(3)
    theta = np.arange(256) / 256
    base = np.cos(2 * np.pi * 19 * theta) + 0.4 * np.cos(2 * np.pi * 38 * theta + 1)
    refs = np.vstack([fractional_shift(base * rng.uniform(0.7, 1.3), rng.uniform(0, 5))
                      + 0.05 * rng.normal(size=256) for _ in range(8)])
    signals = np.vstack([fractional_shift(refs[i % 8], rng.uniform(-3, 3))
                         + 0.05 * rng.normal(size=256) for i in range(20)])
    full = _subtract(signals, refs, 100)[3]
    pruned = _subtract(signals, refs, 100, prune=3)[3]
    energy = np.array([[np.sum((s - fractional_shift(r, lag / 100)) ** 2)
                        for r, lag in zip(refs, row)] for s, row in zip(signals, full)])
    best3 = np.argsort(energy, axis=1)[:, :3]
    assert (np.take_along_axis(pruned, best3, axis=1) >= 0).all()
    assert (pruned < 0).any()            # and the bound does drop some
    # lags found once serve again: the same residual
    residual, lags = subtract_blend(signals, refs, n_blend=3)
    again, _ = subtract_blend(signals, refs, n_blend=3, lags=lags)
    assert_array_equal(residual, again)


def test_silent_references_leave_the_signal_whole():
    signals = np.random.default_rng(5).normal(size=(2, 64))
    residual, _ = subtract_blend(signals, np.zeros((4, 64)))
    np.testing.assert_allclose(residual, signals, atol=1e-12)


@pytest.mark.parametrize("kwargs, match", [
    ({"n_blend": 0}, "n_blend"),
    ({"n_blend": 2.5}, "n_blend"),
    ({"lags": np.zeros((2, 2), int)}, "lags must be integers of shape"),
    ({"lags": np.zeros((3, 4))}, "lags must be integers of shape"),
])
def test_bad_arguments_are_refused_by_name(kwargs, match):
    refs = np.random.default_rng(4).normal(size=(4, 64))
    with pytest.raises(GearshotError, match=match):
        subtract_blend(refs[:3], refs, **kwargs)


@pytest.mark.slow
def test_a_rough_gear_through_a_measured_beam_path_leaves_less_residue_blended(shared_dir):
    """Virtual rig 102 of the family (grade 11 through the measured beam_h3 path, 30 rps,
    its speed drifting and rippling as recorded): the healthy residue of one run against
    five others sits at the beam's modes, and the blend of 3 references takes at least a
    quarter of it off (40-60 % per band of orders: benchmarks/residue_by_segment.py)."""
    from gearshot.experiments import family_rigs as fr
    from gearshot.paper import GEAR_TEETH, PINION_TEETH, SAMPLES_PER_CYCLE
    from gearshot.signal import mesh_band_orders

    rig, vr = fr.family_rig(102, shared_dir / "data" / "frf")
    assert (rig.grade, rig.path) == (11, "beam_h3")
    duration = fr.campaign_duration({"segments": 4}, rig.speed)
    runs = [vr.record(speed=rig.speed, load=rig.load, duration=duration, repetition=r)
            .to_sa_segments(gear_teeth=GEAR_TEETH, pinion_teeth=PINION_TEETH)
            for r in range(6)]
    refs = np.vstack(runs[1:])
    keep = np.ones(SAMPLES_PER_CYCLE // 2 + 1, bool)
    keep[mesh_band_orders(SAMPLES_PER_CYCLE, GEAR_TEETH, 2)] = False
    keep[0] = False

    def energy(x):
        return float((np.abs(np.fft.rfft(x, axis=-1)) ** 2 * keep).sum())

    single = subtract_healthy(runs[0], refs)
    blended, _ = subtract_blend(runs[0], refs, n_blend=3)
    assert energy(blended) < 0.75 * energy(single)
    # the residue is the beam's: much of it within a few orders of its modes near 2.8
    # and 7.7 kHz (orders 200-219 and 560-579: 40 of the 1024 orders)
    power = (np.abs(np.fft.rfft(single, axis=-1)) ** 2 * keep).mean(axis=0)
    assert power[200:220].sum() + power[560:580].sum() > 0.4 * power.sum()
