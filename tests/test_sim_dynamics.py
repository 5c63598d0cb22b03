"""Batched dynamics: fault signature, grade effect, dt convergence, SA shortcut, inputs."""
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import spearmanr

from gearshot import GearshotError
from gearshot.signal import difference_signal
from gearshot.sim import GearPair, simulate, simulate_sa

SHARED = Path(__file__).resolve().parents[1].parent / "shared"


def _diff(sa):
    """Difference signal (mesh order 38, two sidebands), as in the reference."""
    return difference_signal(sa, 38, n_sidebands=2)


def _rms(x):
    return np.sqrt(np.mean(x ** 2, axis=-1))


PAIR = GearPair.paper()


def test_signature_rises_with_size():
    sizes = np.linspace(0.05, 0.95, 20)
    sa = simulate_sa(PAIR, speed=15, load=10, grade=7, fault_sizes=sizes, same_gear=True,
                     rng=11)
    assert spearmanr(sizes, _rms(_diff(sa))).statistic >= 0.95


def test_fault_to_profile_ratio_matches_reference():
    ref = SHARED / "reference" / "bgu_sa.npz"
    if not ref.exists():
        pytest.skip(f"{ref} not found")
    d = np.load(ref)
    ref_ratio = _rms(_diff(d["y070_din7"])) / _rms(_diff(d["y000_din7"]))
    sa = simulate_sa(PAIR, speed=15, load=10, grade=7,
                     fault_sizes=np.repeat([0.0, 0.7], 8), rng=2)
    r = _rms(_diff(sa))
    ratio = r[8:].mean() / r[:8].mean()
    assert ref_ratio / 2 <= ratio <= ref_ratio * 2
    # levels: healthy diff-RMS within a factor 2 of the lab model's
    assert 0.5 < r[:8].mean() / _rms(_diff(d["y000_din7"])) < 2


def test_coarser_grade_raises_profile_energy():
    ratios = []
    for grade in (3, 11):
        sa = simulate_sa(PAIR, speed=15, load=10, grade=grade,
                         fault_sizes=np.repeat([0.0, 0.5], 6), rng=4)
        r = _rms(_diff(sa))
        ratios.append(r[:6].mean() / r[6:].mean())   # profile energy / fault energy
    assert ratios[1] > 2 * ratios[0]


def test_dt_convergence():
    kw = dict(speed=15, load=10, grade=7, fault_sizes=[0.0, 0.4, 0.8], same_gear=True)
    a = _rms(_diff(simulate_sa(PAIR, rng=3, min_fs=100e3, **kw)))
    b = _rms(_diff(simulate_sa(PAIR, rng=3, min_fs=200e3, **kw)))
    assert np.all(np.abs(a / b - 1) < 0.02)


def test_same_seed_same_signal_and_per_signal_streams():
    a = simulate_sa(PAIR, speed=20, load=5, grade=5, fault_sizes=[0.2, 0.6], rng=[7, 8])
    b = simulate_sa(PAIR, speed=20, load=5, grade=5, fault_sizes=[0.6], rng=[8])
    np.testing.assert_allclose(a[1], b[0], rtol=1e-12, atol=1e-12)


def test_sa_shortcut_equals_long_average():
    """simulate_sa's one-revolution steady state with the mean pinion tooth equals the
    synchronous average of a full hunting period of the time simulation."""
    speed = 15.0
    t_rev = 38 / (17 * speed)
    fs = 2048 * 16 / t_rev
    res = simulate(PAIR, speed=speed, load=10, grade=7, fault_sizes=[0.5], fs=fs,
                   duration=17 * t_rev, rng=5, min_fs=fs)
    x = res.acceleration[0].reshape(17, -1).mean(axis=0)
    X = np.fft.rfft(x)[:1025]
    X[1024] = X[1024].real            # ideal resampling to 2048 points (as simulate_sa)
    sa_long = np.fft.irfft(X, n=2048) * 2048 / x.size
    sa = simulate_sa(PAIR, speed=speed, load=10, grade=7, fault_sizes=[0.5], rng=5,
                     min_fs=fs)[0]
    assert np.sqrt(np.mean((sa - sa_long) ** 2)) < 1e-3 * _rms(sa)


def test_time_varying_speed_and_load():
    res = simulate(PAIR, speed=lambda t: 15 + 2 * t, load=lambda t: 10 + np.sin(40 * t),
                   grade=7, fault_sizes=[0.0], fs=25_600, duration=0.2, rng=0)
    assert res.acceleration.shape == (1, 5120)
    assert np.all(np.isfinite(res.acceleration))
    expected = 2 * np.pi * (15 * 0.2 + 0.2 ** 2)
    assert res.pinion_angle[-1] == pytest.approx(expected, rel=1e-3)
    arr = simulate(PAIR, speed=np.full(5120, 15.0), load=10, grade=7, fault_sizes=[0.0],
                   fs=25_600, duration=0.2, rng=0)
    const = simulate(PAIR, speed=15.0, load=10, grade=7, fault_sizes=[0.0], fs=25_600,
                     duration=0.2, rng=0)
    np.testing.assert_allclose(arr.acceleration, const.acceleration, atol=1e-9)


def test_physics_sanity():
    """A smoother gear (finer grade) vibrates less; more load raises mesh harmonics."""
    a = simulate_sa(PAIR, speed=15, load=10, grade=2, fault_sizes=[0.0] * 4, rng=1)
    b = simulate_sa(PAIR, speed=15, load=10, grade=10, fault_sizes=[0.0] * 4, rng=1)
    assert _rms(_diff(a)).mean() < _rms(_diff(b)).mean()


@pytest.mark.parametrize("kwargs, name", [
    (dict(speed=0.0), "speed"), (dict(speed=-3.0), "speed"), (dict(load=0), "load"),
    (dict(load=float("nan")), "load"), (dict(grade=0), "grade"), (dict(grade=13), "grade"),
    (dict(fault_sizes=[0.2, 1.5]), "fault_sizes"), (dict(fault_sizes=[np.nan]), "fault_sizes"),
    (dict(speed=float("inf")), "speed")])
def test_bad_input(kwargs, name):
    kw = dict(speed=15, load=10, grade=7, fault_sizes=[0.0])
    kw.update(kwargs)
    with pytest.raises(GearshotError, match=name):
        simulate_sa(PAIR, **kw)


def test_simulate_decimation_is_anti_aliased_and_chunk_consistent():
    """Output at fs equals the fine simulation decimated by a Kaiser FIR (resample_poly),
    and long signals are integrated in chunks without seams."""
    from scipy.signal import resample_poly

    fs, up = 25_600, 4
    kw = dict(speed=15, load=10, grade=7, fault_sizes=[0.0, 0.6], rng=3, min_fs=fs * up)
    a = simulate(PAIR, fs=fs, duration=3.0, **kw)
    b = simulate(PAIR, fs=fs * up, duration=3.0, **kw)
    ref = resample_poly(b.acceleration, 1, up, axis=-1)
    inner = slice(200, -200)
    np.testing.assert_allclose(a.acceleration[:, inner], ref[:, inner],
                               atol=1e-9 * np.abs(ref).max())


def test_simulate_bad_profiles():
    with pytest.raises(GearshotError, match="speed"):
        simulate(PAIR, speed=lambda t: 15 - 20 * t, load=10, grade=7, fault_sizes=[0.0],
                 fs=25_600, duration=1.0)
    with pytest.raises(GearshotError, match="load"):
        simulate(PAIR, speed=15, load=np.full(10, 5.0), grade=7, fault_sizes=[0.0],
                 fs=25_600, duration=1.0)
    with pytest.raises(GearshotError, match="duration"):
        simulate(PAIR, speed=15, load=5, grade=7, fault_sizes=[0.0], fs=25_600)


def test_custom_fault_type_plugs_in():
    """A new fault type only implements the ToothFault hooks."""
    from dataclasses import dataclass

    from gearshot.sim import ToothFault

    @dataclass(frozen=True)
    class Dent(ToothFault):
        depth_m: float = 5e-6

        @property
        def is_healthy(self):
            return False

        def displacement(self, pair, s):
            s = np.asarray(s, dtype=float)
            return np.where((s > 0.4) & (s < 0.6), -self.depth_m, 0.0)

    kw = dict(speed=15, load=10, grade=5, same_gear=True, rng=1)
    sa = simulate_sa(PAIR, faults=[None, Dent(), Dent(depth_m=20e-6)], **kw)
    r = _rms(_diff(sa))
    assert r[0] < r[1] < r[2]
    with pytest.raises(GearshotError, match="faults"):
        simulate_sa(PAIR, faults=[0.3], **kw)
    with pytest.raises(GearshotError, match="not both"):
        simulate_sa(PAIR, faults=[Dent()], fault_sizes=[0.2], **kw)
    with pytest.raises(GearshotError, match="fault_sizes"):
        simulate_sa(PAIR, fault_sizes=["a"], **kw)


def test_pair_must_be_gearpair():
    with pytest.raises(GearshotError, match="pair"):
        simulate_sa("paper", speed=15, load=10, grade=7, fault_sizes=[0.0])
