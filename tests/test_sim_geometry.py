"""GearPair: geometry, defaults and validation."""
import dataclasses
import math

import pytest

from gearshot import GearshotError
from gearshot.sim import GearPair


def test_paper_pair():
    p = GearPair.paper()
    assert (p.z_pinion, p.z_gear) == (17, 38)
    assert p.masses == (0.8, 3.2)
    assert p.damping_ratio == 0.05
    assert p.center_distance == pytest.approx(0.0825)
    assert p.base_radius(17) == pytest.approx(0.0255 * math.cos(math.radians(20)))
    assert p.base_pitch == pytest.approx(math.pi * 3e-3 * math.cos(math.radians(20)))
    assert p.contact_ratio == pytest.approx(1.609, abs=2e-3)


def test_defaults_from_geometry_and_shafts():
    p = GearPair()
    m1, m2 = p.masses
    assert m1 == pytest.approx(7850 * math.pi * 0.0255 ** 2 * 0.015)
    assert m2 == pytest.approx(7850 * math.pi * 0.057 ** 2 * 0.015)
    j1, _ = p.inertias
    assert j1 == pytest.approx(0.5 * m1 * 0.0255 ** 2)
    kt_in, kt_out = p.shaft_torsional_stiffness
    g = 210e9 / 2.6
    assert kt_in == pytest.approx(math.pi * 0.01 ** 4 * g / (2 * 0.2))
    assert kt_out == pytest.approx(kt_in / 3)


def test_replace_validates_and_is_frozen():
    p = GearPair.paper()
    assert p.replace(face_width=0.02).face_width == 0.02
    with pytest.raises(GearshotError, match="face_width"):
        p.replace(face_width=-1.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.module = 1.0
    assert hash(p) == hash(GearPair.paper())


@pytest.mark.parametrize("kwargs, name", [
    (dict(z_pinion=11), "z_pinion"), (dict(z_gear=8), "z_gear"),
    (dict(module=-1.0), "module"), (dict(face_width=float("nan")), "face_width"),
    (dict(poisson=0.7), "poisson")])
def test_bad_pair(kwargs, name):
    with pytest.raises(GearshotError, match=name):
        GearPair.paper(**kwargs)


def test_interference_is_refused():
    with pytest.raises(GearshotError, match="interference"):
        GearPair(z_pinion=12, z_gear=60)

