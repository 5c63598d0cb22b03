"""Mesh stiffness (potential-energy method) against the lab model's reference curve."""
from pathlib import Path

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.sim import Fault, GearPair, mesh_stiffness, pair_stiffness

SHARED = Path(__file__).resolve().parents[1].parent / "shared"
REF = SHARED / "reference" / "bgu_mesh_stiffness.csv"


@pytest.fixture(scope="module")
def ref():
    if not REF.exists():
        pytest.skip(f"reference data {REF} not found")
    data = np.loadtxt(REF, delimiter=",", skiprows=1)
    return data[:, 0] * 2 * np.pi, data[:, 1], data[:, 2]


def _best_shift(a, b, n_mesh=38):
    """Circular shift of b (samples) best aligning it with a, reduced to within half a
    mesh period (the healthy curve is mesh-periodic, so only that part is determined)."""
    xc = np.fft.irfft(np.fft.rfft(a - a.mean()) * np.conj(np.fft.rfft(b - b.mean())), n=a.size)
    per = a.size / n_mesh
    frac = int(np.argmax(xc)) / per
    return int(round((frac - round(frac)) * per))


def _dip(loss, theta, z1):
    """Centre and width (mesh periods) of the region where the loss exceeds half its max."""
    idx = np.flatnonzero(loss > 0.5 * loss.max())
    t = theta[idx] * z1 / (2 * np.pi)
    return 0.5 * (t.min() + t.max()), t.max() - t.min(), loss.max()


def test_healthy_matches_reference(ref):
    theta, k_ref, _ = ref
    k = mesh_stiffness(GearPair.paper(), theta)
    k = np.roll(k, _best_shift(k_ref, k))
    assert abs(k.mean() / k_ref.mean() - 1) < 0.05
    assert np.sqrt(np.mean((k - k_ref) ** 2)) < 0.10 * k_ref.mean()
    assert 1.2e8 < k.min() and k.max() < 2.8e8


def test_ftff_dip_matches_reference(ref):
    theta, k_ref, kf_ref = ref
    pair = GearPair.paper()
    fault = Fault.ftff(0.5, center=0.5, depth=0.5)
    k = mesh_stiffness(pair, theta)
    kf = mesh_stiffness(pair, theta, fault=fault)
    shift = _best_shift(k_ref, k)
    loss = np.roll(k - kf, shift)
    loss_ref = k_ref - kf_ref
    c, w, d = _dip(loss, theta, 17)
    c_ref, w_ref, d_ref = _dip(loss_ref, theta, 17)
    assert abs(c - c_ref) < 0.25                # quarter of a mesh period
    assert abs(w / w_ref - 1) < 0.30
    assert abs(d / d_ref - 1) < 0.30
    # outside the faulty tooth's contact the fault changes nothing
    assert np.all(loss[(theta * 17 / (2 * np.pi) > 3) & (theta * 17 / (2 * np.pi) < 30)] == 0)


def test_contact_ratio_and_pair_count():
    pair = GearPair.paper()
    assert pair.contact_ratio == pytest.approx(1.609, abs=2e-3)
    theta = np.linspace(0, 2 * np.pi / 17, 2001, endpoint=False)
    k = mesh_stiffness(pair, theta)
    double = np.mean(k > 0.5 * (k.max() + k.min()))
    assert double == pytest.approx(pair.contact_ratio - 1, abs=0.01)


def test_stiffness_scales_with_face_width_and_modulus():
    u = np.linspace(0.05, 0.95, 7)
    base = pair_stiffness(GearPair.paper(), u)
    assert np.allclose(pair_stiffness(GearPair.paper(face_width=30e-3), u), 2 * base)
    assert np.allclose(pair_stiffness(GearPair.paper(youngs_modulus=105e9), u), base / 2)


def test_other_pairs_work():
    pair = GearPair(z_pinion=23, z_gear=31, module=2e-3, face_width=20e-3)
    k = mesh_stiffness(pair, np.linspace(0, 2 * np.pi, 5000))
    assert np.all(k > 5e7) and np.all(k < 1e9)


def test_fault_monotone_in_size():
    pair = GearPair.paper()
    theta = np.linspace(0, 2 * 2 * np.pi / 17, 4000)
    base = mesh_stiffness(pair, theta)
    # the largest stiffness change (loss at the tip-side edge, gain at the root-side edge)
    changes = [np.abs(base - mesh_stiffness(pair, theta, fault=Fault.ftff(y))).max()
               for y in (0.1, 0.3, 0.5, 0.7, 0.9)]
    assert np.all(np.diff(changes) > 0)


@pytest.mark.parametrize("args, name", [((1.2,), "size"), ((-0.1,), "size"),
                                        ((float("nan"),), "size")])
def test_bad_fault(args, name):
    with pytest.raises(GearshotError, match=name):
        Fault.ftff(*args)


def test_fault_leaving_profile():
    with pytest.raises(GearshotError, match="center"):
        Fault.ftff(0.8, center=0.2)


def test_nonfinite_angle():
    with pytest.raises(GearshotError, match="pinion_angle"):
        mesh_stiffness(GearPair.paper(), [0.0, np.inf])


def test_faulty_table_matches_direct_evaluation():
    from gearshot.sim.stiffness import _N_TABLE, _pair_table
    pair = GearPair.paper()
    u = np.linspace(0, 1, _N_TABLE)
    for y in (0.1, 0.6):
        fault = Fault.ftff(y)
        fast = _pair_table(pair, fault)
        exact = pair_stiffness(pair, u, fault=fault)
        rel = np.abs(fast - exact) / exact
        assert np.sum(rel > 5e-3) <= 1          # only the one grid point on the jump

