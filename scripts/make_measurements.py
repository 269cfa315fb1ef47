"""Synthetic Mueller-matrix BRDF "measurements" (docs/design.md §2.1) generated with NIST SCATMECH plus seeded noise.

    python scripts/make_measurements.py [--out measurements] [--seed 20240611]

Each material's noise-free Mueller BRDF is SCATMECH's `Shadowed_Facet_BRDF_Model` (see
scatmech_backend.py for the mapping of docs/design.md §1.3 onto it) plus SCATMECH's `Lambertian_BRDF_Model`
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

Spectral materials (docs/design.md §1.9) share sigma, q, shadowing and rho_d over wavelength and take
N = n + ik at each wavelength from a dispersion law evaluated here in Python (`Lorentz`, written
from docs/design.md §1.9, not from the Rust code).  SCATMECH is called once per wavelength with that
wavelength's n, k (full double precision) and `lambda`.  The rows of all wavelengths go into one file
with a `wavelength_um` column, one block per wavelength (ascending), and their noise comes from one
seeded stream drawn in that order.  Seeds: --seed + index, MATERIALS first, then SPECTRAL_MATERIALS,
so adding a material at the end leaves every existing file's bytes unchanged.
"""

from __future__ import annotations

import argparse
import cmath
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


@dataclass(frozen=True)
class Lorentz:
    """One Lorentz oscillator over wavenumber nu = 1/lambda (um^-1), exp(-i omega t) convention:
    eps(nu) = eps_inf + strength nu0^2 / (nu0^2 - nu^2 - i gamma nu), nu0 = 1/resonance_um and
    gamma = damping_um / resonance_um^2 (damping_um is the line width expressed in wavelength at the
    resonance).  N = sqrt(eps) on the branch Im N >= 0 (k >= 0 absorbs)."""

    eps_inf: float
    strength: float
    resonance_um: float
    damping_um: float

    def index(self, wavelength_um: float) -> complex:
        nu = 1.0 / wavelength_um
        nu0 = 1.0 / self.resonance_um
        gamma = self.damping_um / (self.resonance_um * self.resonance_um)
        eps = self.eps_inf + self.strength * nu0 * nu0 / complex(nu0 * nu0 - nu * nu, -gamma * nu)
        root = cmath.sqrt(eps)
        return -root if root.imag < 0 else root

    def describe(self) -> str:
        return (f"lorentz eps_inf={self.eps_inf:g} strength={self.strength:g} "
                f"resonance_um={self.resonance_um:g} damping_um={self.damping_um:g}")


@dataclass(frozen=True)
class SpectralMaterial:
    """One surface (sigma, q, shadowing, rho_d shared) measured at several wavelengths, N from `dispersion`."""

    name: str
    distribution: str
    sigma: float
    q: float
    shadowing: str
    dispersion: Lorentz
    wavelengths_um: tuple[float, ...]  # ascending
    rho_d: float
    full_mueller: bool
    fine_halfwidth_deg: int
    specular_raster: bool
    note: str

    def at(self, wavelength_um: float) -> Material:
        """The grey material this one is at one wavelength."""
        N = self.dispersion.index(wavelength_um)
        surface = sb.SurfaceParams(self.distribution, self.sigma, self.q, N.real, N.imag, self.shadowing,
                                   wavelength_um)
        return Material(self.name, surface, self.rho_d, self.full_mueller, self.fine_halfwidth_deg,
                        self.specular_raster, self.note)


SPECTRAL_MATERIALS = [
    SpectralMaterial("silicate_glass", "cauchy", 0.06, 2.8, "smith", Lorentz(2.1, 0.8, 9.3, 0.744),
                     (8.0, 8.5, 9.0, 9.5, 10.0, 10.6, 11.5, 12.5, 14.0), 0.0, True, 10, False,
                     "polished silicate glass across its 9 um reststrahlen band (n < 1 at 8-8.5 um, k up to ~2)"),
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


def noisy_rows(mat: Material, rng: np.random.Generator):
    """Geometry (N, 4), element names, and per element the noisy values and their standard deviations."""
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
    return g, names, values, sigmas


def data_fields(values: list, sigmas: list, r: int) -> list[str]:
    """Row r's element values (7 significant digits) and standard deviations (5)."""
    fields = [f"{v[r]:.6e}" for v in values]
    fields += [f"{s[r]:.4e}" for s in sigmas]
    return fields


def provenance_header(seed: int, note: str) -> list[str]:
    """The header lines after the truth: noise, seed, generator, the material's note, what is absent."""
    return [
        "# noise: gaussian; m00 * (1 + 0.03 N(0,1)); other elements + 0.01 * m00 * N(0,1) (noise-free m00)",
        "# uncertainty: u_ columns are the standard deviations of that noise (absolute, sr^-1)",
        f"# noise_seed: {seed}",
        "# generator: scripts/make_measurements.py with NIST SCATMECH (pyscatmech 0.1.10)"
        " Shadowed_Facet_BRDF_Model + Lambertian_BRDF_Model",
        f"# {note}",
        "# synthetic data (phi_r = 180 is the specular side, docs/design.md §1.1). Absent points are those within",
        "# 3 deg of retro-reflection (detector shadows the source), with theta_r >= 88 deg, or with",
        "# noise-free m00 < 1e-4 per sr (noise floor)",
    ]


def write_csv(path: str, header: list[str], columns: list[str], rows: list[list[str]]) -> None:
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(header) + "\n")
        f.write(",".join(columns) + "\n")
        for fields in rows:
            f.write(",".join(fields) + "\n")
    os.replace(tmp, path)


def write_material(mat: Material, out_dir: str, rng: np.random.Generator, seed: int) -> tuple[int, str]:
    g, names, values, sigmas = noisy_rows(mat, rng)
    p = mat.surface
    header = [
        f"# material: {mat.name}",
        f"# wavelength_um: {p.wavelength_um:g}",
        "# mueller_convention: psps",
        *slope_truth(p.distribution, p.sigma, p.q),
        f"# truth_n: {p.n:g}",
        f"# truth_k: {p.k:g}",
        f"# truth_rho_d: {mat.rho_d:g}",
        f"# truth_shadowing: {p.shadowing}",
    ]
    header += provenance_header(seed, mat.note)
    columns = ["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg"] + names + [f"u_{n}" for n in names]
    rows = [[f"{x:g}" for x in g[r]] + data_fields(values, sigmas, r) for r in range(len(g))]
    path = os.path.join(out_dir, f"{mat.name}.csv")
    write_csv(path, header, columns, rows)
    return len(g), path


def slope_truth(distribution: str, sigma: float, q: float) -> list[str]:
    """The header lines of the slope distribution's truth (q only for the Cauchy one)."""
    lines = [f"# truth_distribution: {distribution}", f"# truth_sigma: {sigma:g}"]
    if distribution == "cauchy":
        lines.append(f"# truth_q: {q:g}")
    return lines


def truth_n_k(spec: SpectralMaterial) -> str:
    """`8.0:0.517774+0.543731i, 8.5:...`: N at every wavelength to 6 significant digits."""
    parts = []
    for wl in spec.wavelengths_um:
        N = spec.dispersion.index(wl)
        parts.append(f"{wl!r}:{N.real:.6g}+{N.imag:.6g}i")
    return ", ".join(parts)


def write_spectral_material(spec: SpectralMaterial, out_dir: str, rng: np.random.Generator,
                            seed: int) -> tuple[list[int], str]:
    """One file, one block of rows per wavelength (ascending), all noise from `rng` in that order."""
    rows, counts = [], []
    for wl in spec.wavelengths_um:
        g, names, values, sigmas = noisy_rows(spec.at(wl), rng)
        rows += [[f"{x:g}" for x in g[r]] + [f"{wl:g}"] + data_fields(values, sigmas, r) for r in range(len(g))]
        counts.append(len(g))
    header = [
        f"# material: {spec.name}",
        "# mueller_convention: psps",
        *slope_truth(spec.distribution, spec.sigma, spec.q),
        f"# truth_dispersion: {spec.dispersion.describe()}",
        f"# truth_n_k: {truth_n_k(spec)}",
        f"# truth_rho_d: {spec.rho_d:g}",
        f"# truth_shadowing: {spec.shadowing}",
    ]
    header += provenance_header(seed, spec.note)
    header += [
        "# spectral (docs/design.md §1.9) with one block of rows per wavelength_um, ascending. n and k at each",
        "# wavelength come from the truth_dispersion law (evaluated in make_measurements.py, full double",
        "# precision; truth_n_k rounds them), sigma, q and rho_d are shared",
    ]
    columns = (["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg", "wavelength_um"]
               + names + [f"u_{n}" for n in names])
    path = os.path.join(out_dir, f"{spec.name}.csv")
    write_csv(path, header, columns, rows)
    return counts, path


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
    for i, spec in enumerate(SPECTRAL_MATERIALS, start=len(MATERIALS)):
        seed = args.seed + i
        counts, path = write_spectral_material(spec, out, np.random.default_rng(seed), seed)
        per = ", ".join(f"{wl:g} um: {c}" for wl, c in zip(spec.wavelengths_um, counts))
        print(f"wrote {path}: {sum(counts)} points ({per})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
