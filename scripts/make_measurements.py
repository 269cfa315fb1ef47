"""Synthetic Mueller-matrix BRDF "measurements" (DESIGN §2.1) generated with NIST SCATMECH plus seeded noise.

    python scripts/make_measurements.py [--out measurements] [--seed 20240611]

Each material's noise-free Mueller BRDF is SCATMECH's `Shadowed_Facet_BRDF_Model` (see
scatmech_backend.py for the mapping of DESIGN §1.3 onto it) plus SCATMECH's `Lambertian_BRDF_Model`
with reflectance rho_d (rho_d/pi on m00 only).  Not the numpy port: the files must not share code
with any model that is later fitted to them.

Goniometer-like geometry, phi_i = 0:
* theta_i in {20, 30, 40, 50, 60, 70};
* in-plane sweep of the signed detector angle -85..85 every 5 deg (positive: phi_r = 180, the
  specular side; negative: phi_r = 0, the retro side), plus 1-deg steps within +-4 deg of specular
  (+-10 deg for glossy samples);
* out-of-plane rings theta_r = theta_i and theta_r = 30 deg (60 deg for theta_i = 30), phi_r every 15 deg;
* for the glossy sample a raster around specular (theta_r = theta_i + {-6,-3,0,3,6}, phi_r = 180 +- 10
  every 2.5 deg).
Points are dropped when the detector would shadow the source (within 3 deg of retro-reflection),
when theta_r >= 88 deg, or when the noise-free m00 < 1e-4 sr^-1 (noise floor).

Noise (seeded): m00 * (1 + 0.03 N(0,1)) (gaussian, multiplicative); other elements + 0.01 m00 N(0,1)
(gaussian, additive, scaled by the noise-free m00).  The u_ columns are exactly these standard
deviations (0.03 m00 and 0.01 m00 of the noise-free m00), so a weighted fit of the true model
gives reduced chi^2 ~ 1.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from dataclasses import dataclass

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scatmech_backend as sb  # noqa: E402
from pySCATMECH.brdf import BRDF_Model  # noqa: E402

LINEAR_ELEMENTS = ["m00", "m01", "m02", "m10", "m11", "m12", "m20", "m21", "m22"]
CIRCULAR_ELEMENTS = ["m03", "m13", "m23", "m30", "m31", "m32", "m33"]
THETA_I_DEG = [20, 30, 40, 50, 60, 70]
M00_FLOOR = 1e-4
THETA_R_MAX_DEG = 88.0
RETRO_EXCLUSION_DEG = 3.0
REL_NOISE_M00 = 0.03
REL_NOISE_OTHERS = 0.01


@dataclass(frozen=True)
class Material:
    name: str
    surface: sb.SurfaceParams
    rho_d: float
    full_mueller: bool  # also the circular row/column (m03, m13, m23, m30, m31, m32, m33)
    fine_halfwidth_deg: int  # 1-deg steps within this many degrees of specular
    specular_raster: bool  # a 2-D raster around specular, as one would measure a glossy sample
    note: str


MATERIALS = [
    Material("paper_paint", sb.SurfaceParams("cauchy", 0.1, 1.8, 1.2, 0.2, "smith", 9.925), 0.0, True, 4, False,
             "the paper's paint (Ma et al. 2009, Figs. 2-3 parameters)"),
    Material("rough_paint", sb.SurfaceParams("cauchy", 0.3, 2.5, 1.55, 0.05, "smith", 9.925), 0.03, True, 4, False,
             "matte paint with a volume (diffuse) part; small k, so the circular elements carry it"),
    Material("smooth_glass", sb.SurfaceParams("cauchy", 0.03, 3.0, 2.2, 0.1, "smith", 10.6), 0.0, False, 10, True,
             "polished silicate glass near 10.6 um (n ~ 2.2, k ~ 0.1)"),
    Material("anodized_panel", sb.SurfaceParams("gaussian", 0.15, 0.0, 3.0, 1.0, "smith", 9.925), 0.01, False, 4, False,
             "bead-blasted anodized aluminium panel; its true slope distribution is Gaussian"),
]


def goniometer_geometry(fine_halfwidth_deg: int, specular_raster: bool) -> np.ndarray:
    """(N, 4) rows theta_i, phi_i, theta_r, phi_r in degrees (phi_i = 0)."""
    rows = set()
    for ti in THETA_I_DEG:
        signed = set(range(-85, 86, 5))
        signed |= {ti + d for d in range(-fine_halfwidth_deg, fine_halfwidth_deg + 1)}
        for s in sorted(signed):
            if abs(s) >= THETA_R_MAX_DEG:
                continue
            rows.add((ti, 0, abs(s), 180 if s >= 0 else 0))
        for tr in (ti, 60 if ti == 30 else 30):
            for pr in range(0, 360, 15):
                if pr in (0, 180):
                    continue  # in-plane, already swept
                rows.add((ti, 0, tr, pr))
        if specular_raster:
            for dt in (-6, -3, 0, 3, 6):
                for dp in np.arange(-10.0, 10.01, 2.5):
                    rows.add((ti, 0, ti + dt, 180 + float(dp)))
    g = np.array(sorted(rows), dtype=float)
    # the detector arm shadows the source near retro-reflection
    ti, pi_, tr, pr = np.radians(g.T)
    cos_sep = np.cos(ti) * np.cos(tr) + np.sin(ti) * np.sin(tr) * np.cos(pr - pi_)
    sep = np.degrees(np.arccos(np.clip(cos_sep, -1.0, 1.0)))
    return g[sep >= RETRO_EXCLUSION_DEG]


def lambertian(rho_d: float, wavelength_um: float) -> BRDF_Model:
    m = BRDF_Model("Lambertian_BRDF_Model")
    m.setParameters({"lambda": sb.fmt(wavelength_um)})
    m.setParameter("reflectance.table", sb.fmt(rho_d))
    return m


def noise_free_mueller(mat: Material, g: np.ndarray) -> np.ndarray:
    surf = sb.ScatmechSurface(mat.surface)
    m = surf.mueller(g[:, 0], g[:, 1], g[:, 2], g[:, 3])
    if mat.rho_d > 0:
        lam = lambertian(mat.rho_d, mat.surface.wavelength_um)
        for r in range(len(g)):
            ti, tr = math.radians(g[r, 0]), math.radians(g[r, 2])
            ps = math.radians(g[r, 3] - g[r, 1] - 180.0)
            m[r] += np.array(lam.MuellerBRDF(ti, tr, ps, 0.0, "psps"), dtype=float)
    return m


def element(m: np.ndarray, name: str) -> np.ndarray:
    return m[:, int(name[1]), int(name[2])]


def write_material(mat: Material, out_dir: str, rng: np.random.Generator, seed: int) -> tuple[int, str]:
    g = goniometer_geometry(mat.fine_halfwidth_deg, mat.specular_raster)
    m = noise_free_mueller(mat, g)
    keep = m[:, 0, 0] >= M00_FLOOR
    g, m = g[keep], m[keep]
    m00 = m[:, 0, 0]
    names = LINEAR_ELEMENTS + (CIRCULAR_ELEMENTS if mat.full_mueller else [])
    values, sigmas = [], []
    for name in names:
        sd = (REL_NOISE_M00 if name == "m00" else REL_NOISE_OTHERS) * m00
        values.append(element(m, name) + sd * rng.standard_normal(len(g)))
        sigmas.append(sd)
    p = mat.surface
    header = [
        f"# material: {mat.name}",
        f"# wavelength_um: {p.wavelength_um:g}",
        "# mueller_convention: psps",
        f"# truth_distribution: {p.distribution}",
        f"# truth_sigma: {p.sigma:g}",
    ]
    if p.distribution == "cauchy":
        header.append(f"# truth_q: {p.q:g}")
    header += [
        f"# truth_n: {p.n:g}",
        f"# truth_k: {p.k:g}",
        f"# truth_rho_d: {mat.rho_d:g}",
        f"# truth_shadowing: {p.shadowing}",
        "# noise: gaussian; m00 * (1 + 0.03 N(0,1)); other elements + 0.01 * m00 * N(0,1) (noise-free m00)",
        "# uncertainty: u_ columns are the standard deviations of that noise (absolute, sr^-1)",
        f"# noise_seed: {seed}",
        "# generator: scripts/make_measurements.py with NIST SCATMECH (pyscatmech 0.1.10)"
        " Shadowed_Facet_BRDF_Model + Lambertian_BRDF_Model",
        f"# {mat.note}",
        "# synthetic data (phi_r = 180 is the specular side, DESIGN §1.1). Absent points are those within",
        "# 3 deg of retro-reflection (detector shadows the source), with theta_r >= 88 deg, or with",
        "# noise-free m00 < 1e-4 per sr (noise floor)",
    ]
    columns = ["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg"] + names + [f"u_{n}" for n in names]
    path = os.path.join(out_dir, f"{mat.name}.csv")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(header) + "\n")
        f.write(",".join(columns) + "\n")
        for r in range(len(g)):
            fields = [f"{x:g}" for x in g[r]]
            fields += [f"{v[r]:.6e}" for v in values]
            fields += [f"{s[r]:.4e}" for s in sigmas]
            f.write(",".join(fields) + "\n")
    os.replace(tmp, path)
    return len(g), path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "measurements"))
    ap.add_argument("--seed", type=int, default=20240611)
    args = ap.parse_args(argv)
    out = os.path.normpath(args.out)
    os.makedirs(out, exist_ok=True)
    for i, mat in enumerate(MATERIALS):
        seed = args.seed + i
        n, path = write_material(mat, out, np.random.default_rng(seed), seed)
        print(f"wrote {path}: {n} points")
    return 0


if __name__ == "__main__":
    sys.exit(main())
