"""Mesh stiffness against ROSS's energy-method TVMS (optional: ``pip install gearshot[ross]``).

Same geometry (paper pair; helical 20 deg: ROSS's transverse-profile stiffness staggered
by the overlap ratio, see :mod:`gearshot.sim.ross_reference`); ROSS computes the stiffness
by adaptive quadrature, ~10-20 s per pair.
"""
import math

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.sim import GearPair, mesh_stiffness

pytest.importorskip("ross", reason="ross-rotordynamics not installed (optional extra "
                    "'ross': pip install 'gearshot[ross]')")

from gearshot.sim.ross_reference import ross_mesh_stiffness  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore")


def _compare(pair):
    pos, k_ross, eps = ross_mesh_stiffness(pair, 400)
    ours = mesh_stiffness(pair, 2 * math.pi * pos / pair.z_pinion)
    assert eps == pytest.approx(pair.contact_ratio, rel=1e-9)    # same geometry
    return ours, k_ross


@pytest.fixture(scope="module")
def spur():
    return _compare(GearPair.paper())


@pytest.fixture(scope="module")
def helical():
    return _compare(GearPair.helical(math.radians(20)))


def test_spur_shape_matches_ross(spur):
    ours, k_ross = spur
    assert np.corrcoef(ours, k_ross)[0, 1] >= 0.9       # same phase: a pair enters at 0
    assert np.ptp(ours) / ours.mean() == pytest.approx(np.ptp(k_ross) / k_ross.mean(),
                                                        rel=0.1)


@pytest.mark.xfail(strict=True, reason="ours 0.894 x ROSS's mean: our Sainsot fillet "
                   "foundation takes theta_f at the base-circle thickness instead of the "
                   "fillet's junction with the root circle (1.009 x with it). Kept: "
                   "the lab's reference (bgu_mesh_stiffness.csv) is 0.934 x ROSS and ours "
                   "is within 5 % of it; the ROSS theta_f would put us 8.5 % above the "
                   "lab's model; benchmarks/RESULTS.md")
def test_spur_mean_within_10_percent_of_ross(spur):
    ours, k_ross = spur
    assert ours.mean() == pytest.approx(k_ross.mean(), rel=0.10)


def test_helical_matches_ross(helical):
    ours, k_ross = helical
    assert ours.mean() == pytest.approx(k_ross.mean(), rel=0.10)
    assert np.corrcoef(ours, k_ross)[0, 1] >= 0.9


def test_bad_n_points():
    with pytest.raises(GearshotError, match="n_points"):
        ross_mesh_stiffness(GearPair.paper(), 3)
