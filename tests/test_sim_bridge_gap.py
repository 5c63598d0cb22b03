"""The pruned bridge search equals the plain loop over every flank point, bit for bit."""
import numpy as np
import pytest

from gearshot.sim import GearPair
from gearshot.sim import _ftff_batch as fb
from gearshot.sim._bridge_gap import min_gap, min_gap_plain
from gearshot.sim.fault_types import fault_class
from gearshot.sim.geometry import contact_angles


def _search_args(pair, faults):
    s0, s1, arcs = fb._arcs(pair, faults)
    knots = np.linspace(s0, s1, fb._N_KNOTS, axis=-1)
    r, ang = fb._flank_points(pair, s0, s1, arcs)
    phi_p, centre = contact_angles(pair, 1.0 - knots)
    return (np.cos(centre), np.sin(centre), phi_p, r, np.cos(ang), np.sin(ang),
            pair.center_distance, pair.base_radius(pair.z_pinion),
            pair.tip_radius(pair.z_pinion))


@pytest.mark.parametrize("pair", [GearPair.paper(), GearPair.helical(np.radians(20.0)),
                                  GearPair(z_pinion=16, z_gear=48, module=3e-3)],
                         ids=["paper", "helical", "16-48"])
def test_pruned_search_equals_plain_search(pair):
    rng = np.random.default_rng(7)
    cls = fault_class("ftff")
    centre = rng.uniform(0.3, 0.7, 40)
    sizes = np.minimum(np.concatenate([[1.0, 1e-6, 1e-3], rng.uniform(0, 1, 37)]),
                       2 * np.minimum(centre, 1 - centre))
    sizes[0], centre[0] = 1.0, 0.5
    faults = [cls(size=float(y), center=float(c), depth=float(d))
              for y, c, d in zip(sizes, centre, rng.uniform(0.1, 1.0, 40))]
    args = _search_args(pair, faults)
    ret, rad = min_gap(*args)
    ret_p, rad_p = min_gap_plain(*args)
    np.testing.assert_array_equal(ret, ret_p)
    np.testing.assert_array_equal(rad, rad_p)
    assert np.all(np.isfinite(ret)) and np.all(ret >= 0) and np.any(ret > 0)


def test_points_out_of_range_everywhere_give_the_plain_result():
    """No flank point within the pinion's flank: both searches give inf and the first
    point's radius."""
    pair = GearPair.paper()
    faults = [fault_class("ftff")(size=0.4, center=0.5, depth=0.5)]
    cc, sc, phi_p, r, ca, sa, o2x, rb1, ra1 = _search_args(pair, faults)
    far = (cc, sc, phi_p, r, ca, sa, o2x + 10.0, rb1, ra1)
    for got, want in zip(min_gap(*far), min_gap_plain(*far)):
        np.testing.assert_array_equal(got, want)
    assert np.all(np.isinf(min_gap(*far)[0]))
