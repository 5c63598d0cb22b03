"""FTFF geometry: the bridging retreat against an analytic small-cut limit."""
import dataclasses
import math

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.sim import Fault, FullToothFaceFault, GearPair, ToothFault

PAIR = GearPair.paper()


def _curvature_estimate(pair, fault):
    """Two convex involutes touching at mid-cut, bridged over the cut's chord c:
    the mating flank advances by c^2/8 (1/rho_p + 1/rho_g)."""
    (xa, ha), (xb, hb) = fault._edges(pair)
    c = math.hypot(xb - xa, hb - ha)
    _, (l_lo, l_hi) = pair.roll_limits
    rho_g = l_lo + fault.center * (l_hi - l_lo)
    rho_p = pair.center_distance * math.sin(pair.pressure_angle) - rho_g
    return c ** 2 / 8 * (1 / rho_p + 1 / rho_g)


@pytest.mark.parametrize("y", [0.05, 0.1, 0.15])
def test_small_cut_retreat_matches_curvature_limit(y):
    f = Fault.ftff(y)
    assert f.deviation_depth(PAIR) == pytest.approx(_curvature_estimate(PAIR, f), rel=0.08)


def test_healthy_profile_is_conjugate():
    # a cut of size 0 leaves the flank intact: no displacement anywhere
    s = np.linspace(0, 1, 101)
    assert np.all(Fault.ftff(0.0).displacement(PAIR, s) == 0)
    assert np.all(ToothFault().displacement(PAIR, s) == 0)


def test_displacement_only_inside_cut_and_grows_with_size():
    s = np.linspace(0, 1, 2001)
    peaks = []
    for y in (0.2, 0.4, 0.6, 0.8):
        f = Fault.ftff(y)
        e = f.displacement(PAIR, s)
        lo, hi = f.window
        assert np.all(e[(s <= lo) | (s >= hi)] == 0)
        assert np.all(e <= 0) and e.min() < 0
        peaks.append(-e.min())
    assert np.all(np.diff(peaks) > 0)


def test_shallow_cut_limits_retreat():
    deep = Fault.ftff(0.6, depth=0.5).deviation_depth(PAIR)
    shallow = Fault.ftff(0.6, depth=0.02).deviation_depth(PAIR)
    assert shallow < deep


def test_section_loss_inside_cut_only():
    f = Fault.ftff(0.5)
    (xa, _), (xb, _) = f._edges(PAIR)
    x = np.linspace(xa - 1e-3, xb + 1e-3, 501)
    loss = f.section_loss(PAIR, x)
    assert np.all(loss[(x < xa) | (x > xb)] == 0)
    assert loss.max() > 0


def test_fault_is_hashable_and_frozen():
    f = Fault.ftff(0.3)
    assert hash(f) == hash(FullToothFaceFault(size=0.3))
    with pytest.raises(dataclasses.FrozenInstanceError):
        f.size = 0.5


@pytest.mark.parametrize("kwargs, name", [(dict(depth=0.0), "depth"), (dict(depth=1.5), "depth"),
                                          (dict(center=-0.1), "center"),
                                          (dict(tooth=-1), "tooth")])
def test_bad_fault_parameters(kwargs, name):
    with pytest.raises(GearshotError, match=name):
        Fault.ftff(0.2, **kwargs)
