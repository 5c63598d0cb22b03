"""Reference mesh stiffness from ROSS (``ross-rotordynamics``), for validation only.

ROSS's ``GearElementTVMS`` / ``Mesh`` compute a spur pair's time-varying mesh stiffness by
the potential-energy method (Ma et al. 2014: bending, shear, axial compression over the
involute and the cutter's trochoidal fillet, Sainsot et al. 2004's fillet foundation, a
constant Hertzian term). ROSS takes a ``helix_angle`` but does not use it in the stiffness
(only in the force projection, ROSS 2.3 and 3.1), so a helical pair's reference is built
here from ROSS's stiffness of the **transverse** profile (transverse module and pressure
angle, addendum ``m_n``) averaged over the face with the slices staggered by the overlap
ratio (the slice method: a box filter ``eps_beta`` mesh periods wide on the periodic mesh
stiffness). The helical comparison therefore checks the transverse energy model and our
stagger, not an independent helical model.

Optional dependency: ``pip install gearshot[ross]`` (heavy: it pulls CoolProp, plotly, ...;
ROSS 3.x needs Python >= 3.13, 2.3 works with 3.11 and ``plotly<6``).
"""

from __future__ import annotations

import math

import numpy as np

from .._errors import GearshotError
from .._validation import check_int
from .geometry import GearPair

__all__ = ["ross_mesh_stiffness"]


def _ross():
    try:
        import ross  # type: ignore[import-not-found, import-untyped, unused-ignore]
    except ImportError as exc:
        raise GearshotError(f"ross-rotordynamics is not installed ({exc}); install the "
                            f"optional extra: pip install 'gearshot[ross]'") from None
    return ross


def _spur_transverse(pair: GearPair, n_points: int):
    """ROSS's mesh stiffness of the transverse profile over one mesh period:
    (mesh position 0 ... 1 without the end point, N/m, ROSS's contact ratio)."""
    rs = _ross()
    beta = pair.helix_angle
    mt = pair.transverse_module
    steel = rs.Material(name="gearshot_reference", rho=pair.density, E=pair.youngs_modulus,
                        Poisson=pair.poisson)
    gears = [rs.GearElementTVMS(n=i, material=steel, width=pair.face_width,
                                bore_diameter=2 * pair.bore_radius, module=mt, n_teeth=z,
                                pr_angle=pair.transverse_pressure_angle,
                                addendum_coeff=pair.addendum * math.cos(beta),
                                tip_clearance_coeff=(pair.dedendum - pair.addendum)
                                * math.cos(beta))
             for i, z in enumerate((pair.z_pinion, pair.z_gear))]
    mesh = rs.Mesh(gears[0], gears[1])
    theta = np.asarray(mesh.theta_range, dtype=float)
    k = np.asarray(mesh.stiffness_range, dtype=float)
    pos = theta / (2 * math.pi / pair.z_pinion)
    grid = np.arange(n_points) / n_points
    return grid, np.interp(grid, pos, k, period=1.0), float(mesh.contact_ratio)


def ross_mesh_stiffness(pair: GearPair, n_points: int = 400):
    """ROSS's mesh stiffness of ``pair`` over one mesh period (module docstring).

    Parameters
    ----------
    pair : GearPair
        Spur or helical pair (helical: transverse profile + slice stagger).
    n_points : int
        Samples over the mesh period.

    Returns
    -------
    position : ndarray (n_points,)
        Mesh position in mesh periods, 0 ... 1 (end point excluded); ROSS's origin is a
        pair's entry into contact.
    stiffness : ndarray (n_points,)
        N/m.
    contact_ratio : float
        ROSS's transverse contact ratio.
    """
    n_points = check_int(n_points, "n_points", minimum=16, maximum=100_000)
    grid, k, eps = _spur_transverse(pair, n_points)
    eps_b = pair.overlap_ratio
    if eps_b > 0:
        # box filter eps_beta wide on the periodic curve, by exact Fourier multipliers
        spec = np.fft.rfft(k)
        f = np.arange(spec.size)
        mult = np.ones(spec.size, dtype=complex)
        x = math.pi * f[1:] * eps_b
        mult[1:] = np.sin(x) / x * np.exp(-1j * x)
        k = np.fft.irfft(spec * mult, n=n_points)
    return grid, k, eps
