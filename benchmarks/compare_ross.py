"""Mesh stiffness against ROSS's energy-method TVMS and ISO 6336-1's c_gamma_alpha (#13).

    PYTHONPATH=src python benchmarks/compare_ross.py        # needs gearshot[ross]

Per pair (paper spur; helical 20 and 30 deg): mean stiffness of ours / ROSS's (over one mesh
period, 400 points), the shape correlation, the relative fluctuation, and ISO 6336-1's
mesh stiffness c_gamma_alpha b (method B: c'_th = 1 / q', q' = 0.04723 + 0.15551 / z_n1
+ 0.25791 / z_n2 for x = 0, c' = c'_th C_M C_R C_B cos(beta) with C_M = 0.8, C_R = C_B = 1,
c_gamma_alpha = c' (0.75 eps_alpha + 0.25), N / (mm um) per mm of face width;
``bench_helical.iso_c_gamma_alpha``). Then the spur tooth compliance by term (bending,
shear, axial, fillet foundation) at three contact points, ours against ROSS's.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from bench_helical import iso_c_gamma_alpha

from gearshot.sim import GearPair, mesh_stiffness
from gearshot.sim.ross_reference import _ross, ross_mesh_stiffness


def main():
    warnings.filterwarnings("ignore")
    print("pair            ours/ROSS mean  corr  fluct ours/ROSS   ours / ROSS / ISO c_ga b "
          "(N/m)")
    for name, pair in (("spur", GearPair.paper()),
                       ("helical 20 deg", GearPair.helical(math.radians(20))),
                       ("helical 30 deg", GearPair.helical(math.radians(30)))):
        pos, k_ross, _ = ross_mesh_stiffness(pair, 400)
        ours = mesh_stiffness(pair, 2 * math.pi * pos / pair.z_pinion)
        iso = iso_c_gamma_alpha(pair)
        print(f"{name:15s} {ours.mean() / k_ross.mean():6.3f}        "
              f"{np.corrcoef(ours, k_ross)[0, 1]:.4f} {np.ptp(ours) / ours.mean():.3f}/"
              f"{np.ptp(k_ross) / k_ross.mean():.3f}   {ours.mean():.4g} / {k_ross.mean():.4g}"
              f" / {iso:.4g} (ours/ISO {ours.mean() / iso:.2f}, ROSS/ISO "
              f"{k_ross.mean() / iso:.2f})")
    components()


def components():
    """Compliance terms of one tooth, ours vs ROSS's, spur paper pair."""
    from gearshot.sim import _compliance as st

    rs = _ross()
    p = GearPair.paper()
    steel = rs.Material(name="gearshot_reference", rho=p.density, E=p.youngs_modulus,
                        Poisson=p.poisson)
    print("\ncompliance of one tooth (1e-10 m/N), bending+shear+axial and fillet foundation, "
          "ours | ROSS")
    for z in (p.z_pinion, p.z_gear):
        g = rs.GearElementTVMS(n=0, material=steel, width=p.face_width,
                               bore_diameter=2 * p.bore_radius, module=p.module, n_teeth=z,
                               pr_angle=p.pressure_angle)
        print(f"  z={z}: Sainsot theta_f ours {_theta_f(p, z):.4f} rad (half base-circle "
              f"thickness), ROSS {g.tooth_dict['root_angle']:.4f} rad (fillet / root circle)")
        for deg in (12.0, 20.0, 28.0):
            a = math.radians(deg)
            b = g._to_tau(a)
            ross = [g._inv_kb(b), g._inv_ks(b), g._inv_ka(b), g._inv_kf(b)]
            roll = np.array([p.base_radius(z) * math.tan(a)])
            total = float(st._tooth_compliance(p, z, roll)[0])
            found = _foundation(p, z, roll)
            print(f"    pressure angle {deg:4.1f} deg: {1e10 * (total - found):6.3f}, "
                  f"{1e10 * found:6.3f} | {1e10 * sum(ross[:3]):6.3f}, {1e10 * ross[3]:6.3f}")


def _theta_f(p, z):
    from gearshot.sim import _compliance as st

    rb, rf = p.base_radius(z), p.root_radius(z)
    psi_b = float(st.involute_half_angle(z, p.transverse_pressure_angle, np.array(rb), rb))
    return math.asin(min(rb * math.sin(psi_b) / rf, 1.0))


def _foundation(p, z, roll):
    """Our fillet-foundation compliance (Sainsot 2004), as in ``_tooth_compliance``."""
    from gearshot.sim import _compliance as st

    rb, rf = p.base_radius(z), p.root_radius(z)
    theta_f = _theta_f(p, z)
    s_f = 2 * rf * theta_f
    h_fi = rf / p.bore_radius
    basis = np.array([1 / theta_f ** 2, h_fi ** 2, h_fi / theta_f, 1 / theta_f, h_fi, 1.0])
    ls, ms, ps, qs = st._SAINSOT @ basis
    rc = np.hypot(rb, roll)
    psi_c = st.involute_half_angle(z, p.transverse_pressure_angle, rc, rb)
    xc, hc = rc * np.cos(psi_c), rc * np.sin(psi_c)
    beta = np.arccos(rb / rc) - psi_c
    u_f = xc - hc * np.tan(beta) - rf
    inv_kf = np.cos(beta) ** 2 / (p.youngs_modulus * p.face_width) * (
        ls * (u_f / s_f) ** 2 + ms * (u_f / s_f) + ps * (1 + qs * np.tan(beta) ** 2))
    return float(inv_kf[0])


if __name__ == "__main__":
    main()
