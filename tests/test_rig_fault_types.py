"""The virtual rig grows every fault type, each irregular in its hidden reality (#13)."""

from __future__ import annotations

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.rig import (
    IrregularBreakage,
    IrregularDestruction,
    IrregularFaceFault,
    IrregularPartialFace,
    VirtualRig,
)
from gearshot.rig.irregular import physical_fault_of_type
from gearshot.signal import difference_signal
from gearshot.sim import (
    GearPair,
    PartialFaceFault,
    ToothBreakage,
    ToothDestruction,
    fault_of_type,
    mesh_stiffness,
)

PAIR = GearPair.paper()
THETA = np.linspace(0, 2 * np.pi * 38 / 17, 4000, endpoint=False)
TYPES = ["partial_face", "breakage", "destruction"]
ZG, ZP = 38, 17


def _diff_rms(rec):
    sa = rec.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)
    return float(np.sqrt(np.mean(difference_signal(sa, ZG) ** 2)))


def test_zero_roughness_is_the_nominal_shape():
    """The irregular classes with no roughness are the nominal faults, bit for bit."""
    pairs = [(IrregularPartialFace(size=0.4, roughness=()), PartialFaceFault(size=0.4)),
             (IrregularBreakage(size=0.7, roughness=(0.0,)), ToothBreakage(size=0.7)),
             (IrregularDestruction(size=0.5, roughness=()), ToothDestruction(size=0.5))]
    for rough, nominal in pairs:
        np.testing.assert_array_equal(mesh_stiffness(PAIR, THETA, fault=rough),
                                      mesh_stiffness(PAIR, THETA, fault=nominal))


def test_irregular_shapes_are_not_scaled_nominal_ones():
    r = (0.3, -0.2, 0.1)
    # partial face: the band's transverse cut is an irregular FTFF
    pf = IrregularPartialFace(size=0.5, roughness=r)
    assert isinstance(pf.transverse, IrregularFaceFault) and pf.transverse.roughness == r
    # breakage: the break line's height varies across the broken face share
    z = np.linspace(0.0, 0.5, 51)
    hb = IrregularBreakage(size=0.5, roughness=r, corner=0.0).lost_height(PAIR, z)
    hn = ToothBreakage(size=0.5, corner=0.0).lost_height(PAIR, z)
    ratio = hb / hn
    assert ratio.min() < 0.85 and ratio.max() > 1.15
    assert np.all(IrregularBreakage(size=0.5, roughness=r).lost_height(PAIR, [0.6, 1.0]) == 0)
    # the missing tooth stays missing where the factor exceeds 1
    assert IrregularBreakage(size=1.0, roughness=r).lost_height(PAIR, [0.0])[0] == \
        pytest.approx(ToothBreakage.active_height(PAIR))
    # destruction: the pits' depth varies along the band
    s = np.linspace(0.0, 1.0, 2001)
    (_, _, bi), = IrregularDestruction(size=0.6, roughness=r).face_bands(PAIR)
    (_, _, bn), = ToothDestruction(size=0.6).face_bands(PAIR)
    di, dn = bi.displacement(PAIR, s), bn.displacement(PAIR, s)
    deep = dn < -0.5 * (-dn.min())
    q = di[deep] / dn[deep]
    assert q.min() < 0.85 and q.max() > 1.15
    assert np.all(di[dn == 0] == 0)
    with pytest.raises(GearshotError, match="roughness"):
        IrregularBreakage(size=0.5, roughness=(0.6, 0.6))
    with pytest.raises(GearshotError, match="roughness"):
        IrregularDestruction(size=0.5, roughness="ab")


@pytest.mark.parametrize("name", TYPES)
def test_physical_fault_differs_from_the_label(name):
    reality = VirtualRig(seed=0).reveal()
    assert any(reality.fault_roughness)
    real = physical_fault_of_type(name, 0.6, reality)
    nominal = fault_of_type(name, 0.6)
    assert type(real).__name__.startswith("Irregular")
    k0 = mesh_stiffness(PAIR, THETA)
    loss_real = k0 - mesh_stiffness(PAIR, THETA, fault=real)
    loss_nom = k0 - mesh_stiffness(PAIR, THETA, fault=nominal)
    assert not np.allclose(loss_real, loss_nom, rtol=0.02, atol=1e-3 * k0.mean())
    assert physical_fault_of_type(name, 0.0, reality).is_healthy
    assert physical_fault_of_type(name, 0.6, None) == nominal
    with pytest.raises(GearshotError, match="ftff"):
        physical_fault_of_type("ftff", 0.6, reality)


def test_ftff_default_and_healthy_runs_unchanged():
    kw = dict(speed=15.0, load=10.0, duration=0.3)
    a = VirtualRig(seed=2).record(fault_size=0.5, **kw)
    b = VirtualRig(seed=2, fault_type="ftff").record(fault_size=0.5, **kw)
    np.testing.assert_array_equal(a.acceleration, b.acceleration)
    h = VirtualRig(seed=2).record(**kw)
    for name in TYPES:
        rig = VirtualRig(seed=2, fault_type=name)
        assert rig.reveal() == VirtualRig(seed=2).reveal()     # same hidden reality
        rec = rig.record(**kw)
        np.testing.assert_array_equal(rec.acceleration, h.acceleration)
        assert rec.extras["fault_type"] == name


@pytest.mark.parametrize("name", TYPES)
def test_rig_grows_each_fault_type_visibly(name):
    rig = VirtualRig(seed=0, fault_type=name).with_reality(snr_db=40.0)
    assert rig.fault_type == name                               # kept by with_reality
    kw = dict(speed=15.0, load=10.0, duration=8.0)
    healthy = _diff_rms(rig.record(fault_size=0.0, **kw))
    large = _diff_rms(rig.record(fault_size=1.0 if name == "breakage" else 0.8, **kw))
    assert large > 1.3 * healthy, (name, healthy, large)


def test_bad_fault_type_and_engines():
    with pytest.raises(GearshotError, match="fault_type must be one of"):
        VirtualRig(seed=0, fault_type="rust").reveal()
    with pytest.raises(GearshotError, match="surrogate engine models the FTFF only"):
        VirtualRig(seed=0, engine="surrogate", fault_type="breakage").record(
            speed=15.0, load=10.0, duration=0.2)
    seen = {}

    def engine(*, motor_revs, load_torque, fs, fault_size, reality, rng, fault_type):
        seen["fault_type"] = fault_type
        return np.sin(2 * np.pi * ZP * np.asarray(motor_revs))

    rec = VirtualRig(seed=0, engine=engine, fault_type="destruction").record(
        speed=15.0, load=10.0, fault_size=0.5, duration=0.2)
    assert seen == {"fault_type": "destruction"} and rec.extras["engine"] == "function"
