"""Checks irpol's rotation of Mueller matrices from SCATMECH's xyxy basis into psps.

irpol reads tables written in the sample frame's xyxy basis (NIST's goniometer data) through a
layout with `mueller_convention = "xyxy"` (docs/design.md §2.8) and converts each row with
(src/measure/layout/basis.rs)

    M_psps = L(alpha_r) M_xyxy L(alpha_i),   alpha_r = phi_r,  alpha_i = phi_i + 180 deg,

L the Stokes rotation of docs/design.md §1.3 and (phi_i, phi_r) irpol's azimuths (specular at
phi_r = phi_i + 180 deg). This script checks two things:

1. against NIST SCATMECH itself: `MuellerBRDF(..., 'xyxy')` converted with the formula equals
   `MuellerBRDF(..., 'psps')` for a facet model and a Rayleigh-Rice microroughness model at random
   out-of-plane geometries. SCATMECH's source lies at azimuth 180 deg (phi_i = 180 deg, alpha_i = 0)
   and its viewer azimuth phi_s is irpol's phi_r. The opposite sign of the rotation is evaluated
   too, to show the check can fail.
2. the geometry behind both signs, for any incidence azimuth: the basis the formula implies for
   each direction, e1 = cos(psi) s + sin(psi) p (psi = -alpha_r for the scattered light, +alpha_i for
   the incident light, from S_xyxy = L(psi) S_psps), tends to the sample's y axis near the normal
   on both sides; and L(psi) is the Stokes change of basis for random Jones vectors.

Run (in a venv with `pip install -r scripts/requirements.txt`):

    .venv/bin/python scripts/check_xyxy_basis.py [--samples 400] [--seed 1]

Exit status 0 when every residual is below 1e-12 (relative to m00), 1 otherwise.
"""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np
from pySCATMECH.brdf import BRDF_Model

TOLERANCE = 1e-12


def stokes_rotation(eta_deg: float) -> np.ndarray:
    """L(eta) of docs/design.md §1.3."""
    c, s = math.cos(math.radians(2 * eta_deg)), math.sin(math.radians(2 * eta_deg))
    return np.array([[1, 0, 0, 0], [0, c, s, 0], [0, -s, c, 0], [0, 0, 0, 1.0]])


def xyxy_to_psps(m: np.ndarray, phi_i_deg: float, phi_r_deg: float, sign: float = 1.0) -> np.ndarray:
    """irpol's conversion; sign = -1 is the opposite rotation, which must fail the check."""
    return stokes_rotation(sign * phi_r_deg) @ m @ stokes_rotation(sign * (phi_i_deg + 180.0))


def facet_model() -> BRDF_Model:
    model = BRDF_Model("Shadowed_Facet_BRDF_Model")
    model.setParameters({"lambda": "10", "substrate": "(1.5,0.1)", "type": "0"})
    model.setParameter("sdf", "Gaussian_Slope_Distribution_Function")
    model.setParameter("sdf.s", "0.3")
    model.setParameter("shadow", "Torrance_Sparrow_Shadow_Function")
    return model


def microroughness_model() -> BRDF_Model:
    model = BRDF_Model("Microroughness_BRDF_Model")
    model.setParameters({"lambda": "0.633", "substrate": "(0.2,3.5)", "type": "0"})
    return model


def check_against_scatmech(name: str, model: BRDF_Model, rng: np.random.Generator, samples: int):
    worst, worst_flipped, largest_change = 0.0, 0.0, 0.0
    for _ in range(samples):
        thetai = rng.uniform(0.0, math.radians(80.0))
        thetas = rng.uniform(0.0, math.radians(80.0))
        phis = rng.uniform(-math.pi, math.pi)
        psps = np.array(model.MuellerBRDF(thetai, thetas, phis, 0.0, "psps"), dtype=float)
        xyxy = np.array(model.MuellerBRDF(thetai, thetas, phis, 0.0, "xyxy"), dtype=float)
        m00 = abs(psps[0, 0])
        if not m00 > 0.0:
            continue
        phi_r = math.degrees(phis)
        worst = max(worst, np.max(np.abs(xyxy_to_psps(xyxy, 180.0, phi_r) - psps)) / m00)
        flipped = xyxy_to_psps(xyxy, 180.0, phi_r, sign=-1.0)
        worst_flipped = max(worst_flipped, np.max(np.abs(flipped - psps)) / m00)
        largest_change = max(largest_change, np.max(np.abs(xyxy - psps)) / m00)
    print(
        f"{name}: {samples} geometries, max |L(phi_r) M_xyxy L(phi_i+180) - M_psps| / m00 = "
        f"{worst:.3e}; the opposite rotation: {worst_flipped:.3e}; "
        f"max |M_xyxy - M_psps| / m00 = {largest_change:.3e}"
    )
    return worst <= TOLERANCE and worst_flipped > 1e-3 and largest_change > 1e-3


def psps_basis(k: np.ndarray):
    s = np.cross([0.0, 0.0, 1.0], k)
    s /= np.linalg.norm(s)
    return s, np.cross(k, s)


def direction(theta_deg: float, phi_deg: float) -> np.ndarray:
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


def check_geometry(rng: np.random.Generator, samples: int) -> bool:
    worst_axis, worst_stokes = 0.0, 0.0
    y_axis = np.array([0.0, 1.0, 0.0])
    for _ in range(samples):
        phi_i, phi_r = rng.uniform(-180.0, 180.0, size=2)
        theta = 1e-7  # degrees: the limit at the normal
        # Scattered light travels along the viewer direction; incident light toward the surface.
        k_out = direction(theta, phi_r)
        k_in = -direction(theta, phi_i)
        for k, psi in ((k_out, -phi_r), (k_in, phi_i + 180.0)):
            s, p = psps_basis(k)
            e1 = math.cos(math.radians(psi)) * s + math.sin(math.radians(psi)) * p
            worst_axis = max(worst_axis, np.linalg.norm(e1 - y_axis))
            # L(psi) is the change of Stokes basis from (s, p) to (e1, k x e1).
            e2 = np.cross(k, e1)
            field = rng.normal(size=3) + 1j * rng.normal(size=3)
            stokes = lambda a, b: np.array(
                [abs(a) ** 2 + abs(b) ** 2, abs(a) ** 2 - abs(b) ** 2,
                 2 * (np.conj(a) * b).real, 2 * (np.conj(a) * b).imag]
            )
            in_psps = stokes(field @ s, field @ p)
            in_e = stokes(field @ e1, field @ e2)
            worst_stokes = max(worst_stokes, np.max(np.abs(stokes_rotation(psi) @ in_psps - in_e)))
    print(
        f"geometry: {samples} azimuth pairs, max |e1 - y| at the normal = {worst_axis:.3e}; "
        f"max Stokes change-of-basis error = {worst_stokes:.3e}"
    )
    return worst_axis <= 1e-6 and worst_stokes <= 1e-12


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=400)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    ok = check_against_scatmech("Shadowed_Facet_BRDF_Model", facet_model(), rng, args.samples)
    ok &= check_against_scatmech("Microroughness_BRDF_Model", microroughness_model(), rng, args.samples)
    ok &= check_geometry(rng, args.samples)
    print("OK" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
