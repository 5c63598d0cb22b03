"""Helical pairs: geometry, slice-method mesh stiffness, dynamics (issue #13)."""
import math

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.signal import difference_signal
from gearshot.sim import Fault, GearPair, contact_ratio, mesh_stiffness, simulate_sa
from gearshot.sim.stiffness import _pair_table

PAIR = GearPair.paper()
THETA = np.linspace(0, 2 * np.pi * 38 / 17, 6000, endpoint=False)


def _rms(x):
    return np.sqrt(np.mean(x ** 2, axis=-1))


def test_helix_zero_is_spur_exactly():
    h = GearPair.paper(helix_angle=0.0)
    assert h == PAIR and not h.is_helical
    fault = Fault.ftff(0.4)
    np.testing.assert_array_equal(mesh_stiffness(h, THETA, fault=fault),
                                  mesh_stiffness(PAIR, THETA, fault=fault))
    kw = dict(speed=15, load=10, grade=7, fault_sizes=[0.0, 0.5], rng=[1, 2])
    np.testing.assert_array_equal(simulate_sa(h, **kw), simulate_sa(PAIR, **kw))
    assert contact_ratio(h) == PAIR.contact_ratio and h.overlap_ratio == 0.0


@pytest.mark.parametrize("deg", [8.0, 15.0, 25.0])
def test_contact_ratios(deg):
    h = GearPair.helical(math.radians(deg))
    b = math.radians(deg)
    assert h.overlap_ratio == pytest.approx(15e-3 * math.sin(b) / (math.pi * 3e-3))
    assert contact_ratio(h) == pytest.approx(
        contact_ratio(h, kind="transverse") + contact_ratio(h, kind="overlap"), rel=1e-14)
    assert h.total_contact_ratio == contact_ratio(h)
    assert h.transverse_module == pytest.approx(3e-3 / math.cos(b))
    # transverse contact ratio from the transverse section's own formula
    a_t = math.atan(math.tan(math.radians(20)) / math.cos(b))
    mt = 3e-3 / math.cos(b)
    rb = [0.5 * mt * z * math.cos(a_t) for z in (17, 38)]
    ra = [0.5 * mt * z + 3e-3 for z in (17, 38)]
    path = (sum(math.sqrt(r_a ** 2 - r_b ** 2) for r_a, r_b in zip(ra, rb))
            - 0.5 * mt * 55 * math.sin(a_t))
    assert h.contact_ratio == pytest.approx(path / (math.pi * mt * math.cos(a_t)), rel=1e-12)
    with pytest.raises(GearshotError, match="kind"):
        contact_ratio(h, kind="axial")


def test_helix_angle_validated():
    with pytest.raises(GearshotError, match="helix_angle"):
        GearPair.paper(helix_angle=math.radians(60))
    with pytest.raises(GearshotError, match="helix_angle"):
        GearPair.paper(helix_angle=-0.1)


def test_slice_method_against_explicit_slices():
    """The face average equals a sum over many thin, staggered spur slices."""
    h = GearPair.helical(math.radians(20))
    k = mesh_stiffness(h, THETA)
    tab = _pair_table(h, None)
    ug = np.linspace(0, 1, tab.size)
    ea, eb = h.contact_ratio, h.overlap_ratio
    tm = THETA * 17 / (2 * np.pi)
    n_slices = 300
    ref = np.zeros_like(tm)
    for j in range(n_slices):
        d = eb * (j + 0.5) / n_slices
        for n in range(-2, 40):
            u = (tm - d - n) / ea
            m = (u >= 0) & (u < 1)
            ref[m] += np.interp(u[m], ug, tab) / n_slices
    assert np.mean(np.abs(k - ref)) < 2e-3 * ref.mean()
    # mean mesh stiffness = mean single-pair stiffness x transverse contact ratio
    assert k.mean() == pytest.approx(tab.mean() * ea, rel=5e-3)


def test_fluctuation_falls_with_overlap_and_vanishes_at_integers():
    def fluct(eb, width):
        beta = math.asin(eb * math.pi * 3e-3 / width)
        h = GearPair.paper(helix_angle=beta, face_width=width)
        k = mesh_stiffness(h, THETA[:2000])
        return k.std() / k.mean()

    f = [fluct(eb, 15e-3) for eb in (0.0, 0.25, 0.5, 0.75)]
    assert all(a > b for a, b in zip(f, f[1:]))
    assert fluct(1.0, 15e-3) < 0.02 * f[0]
    assert fluct(2.0, 30e-3) < 0.02 * f[0]
    assert fluct(1.5, 30e-3) > 5 * fluct(2.0, 30e-3)


def test_helical_fault_dip_spread_over_more_mesh_periods():
    h = GearPair.helical(math.radians(20))
    loss_s = mesh_stiffness(PAIR, THETA) - mesh_stiffness(PAIR, THETA, fault=Fault.ftff(0.5))
    loss_h = mesh_stiffness(h, THETA) - mesh_stiffness(h, THETA, fault=Fault.ftff(0.5))
    assert loss_h.max() > 0 and loss_h.sum() > 0
    width = [np.ptp(THETA[x > 0.05 * x.max()]) for x in (loss_s, loss_h)]
    assert width[1] > width[0]


def test_helical_sa_smoother_and_fault_grows():
    h = GearPair.helical(math.radians(20))
    sizes = np.linspace(0.0, 0.9, 7)
    sa_h = simulate_sa(h, speed=15, load=10, grade=7, fault_sizes=sizes, same_gear=True,
                       rng=3)
    sa_s = simulate_sa(PAIR, speed=15, load=10, grade=7, fault_sizes=[0.0], rng=3)
    assert sa_h.shape == (7, 2048) and np.all(np.isfinite(sa_h))
    assert _rms(sa_h[0]) < _rms(sa_s[0])        # overlap smooths the mesh excitation
    r = _rms(difference_signal(sa_h, 38, n_sidebands=2))
    assert np.all(np.diff(r) >= -0.02 * r[0]) and r[-1] > 1.5 * r[0]


def test_helical_time_simulation_runs_and_matches_sa_level():
    h = GearPair.helical(math.radians(15))
    res = __import__("gearshot.sim", fromlist=["simulate"]).simulate(
        h, speed=15, load=10, grade=7, fault_sizes=[0.3], fs=20000, duration=0.2, rng=0)
    assert res.acceleration.shape == (1, 4000) and np.all(np.isfinite(res.acceleration))
