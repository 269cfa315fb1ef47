"""SCATMECH reference for the per-wavelength pBRDF of a spectral material (docs/design.md §1.3, §1.9).

    python scripts/scatmech_spectral_reference.py [--out tests/data/scatmech_spectral.csv]

Writes noise-free Mueller BRDFs of the `silicate_glass` truth of make_measurements.py (Cauchy
sigma = 0.06, q = 2.8, Smith shadowing, rho_d = 0, N from its one-oscillator Lorentz law) at three
wavelengths whose indices differ a lot: 8.0 um (n < 1), 9.0 um (k ~ 2, Re eps < 0) and 11.5 um (an
ordinary dielectric), at the same GEOMETRIES each.  Deterministic, no random numbers.

CSV: `#` comment lines first (how the file was made; `# key: value` lines give the shared model),
then the columns wavelength_um,n,k,theta_i_deg,phi_i_deg,theta_r_deg,phi_r_deg,m00,m01,...,m33
(row-major, sr^-1, psps frames of the global geometry), every number with 17 significant digits so it
parses back to the exact double SCATMECH used.  n and k are the Lorentz law evaluated in Python in
full double precision.

The SCATMECH side is exactly that of scatmech_reference.py (via scatmech_backend.py): phi_s =
phi_r - phi_i - 180 deg, `substrate = "(n,k)"`, `lambda` = the row's wavelength, the Cauchy slope
density as a `Table_Slope_Distribution_Function` formula, and Smith as a `Table_Shadow_Function`
whose nodes are exactly the evaluated angles (G1 by quadrature of Smith's definition), so the table
interpolation adds nothing.  Rows are kept only where scatmech_reference.comparable() keeps them (all
of GEOMETRIES are; the script stops otherwise).  As a sanity check it prints the largest difference
from the numpy port (pbrdf_numpy.py), which is not written to the file.
"""

from __future__ import annotations

import argparse
import csv
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_measurements as mm  # noqa: E402
import pbrdf_numpy as pn  # noqa: E402
import scatmech_backend as sb  # noqa: E402
import scatmech_reference as sr  # noqa: E402

MATERIAL = "silicate_glass"
WAVELENGTHS_UM = [8.0, 9.0, 11.5]
# theta_i, phi_i, theta_r, phi_r in degrees
GEOMETRIES = [
    (0.0, 0.0, 8.0, 180.0),  # normal incidence, near specular
    (30.0, 0.0, 30.0, 180.0),  # specular, in plane
    (20.0, 30.0, 0.0, 300.0),  # normal viewing (theta_r = 0; its psps frame is the limit along phi_r)
    (45.0, 60.0, 40.0, 250.0),  # out of plane near specular (phi_r - phi_i = 190)
    (50.0, 0.0, 35.0, 120.0),  # far out of plane
    (40.0, 0.0, 20.0, 0.0),  # in plane, backward (retro side)
    (75.0, 0.0, 80.0, 180.0),  # near grazing, in plane near specular
    (60.0, 200.0, 80.0, 30.0),  # near grazing viewing, out of plane (phi_r - phi_i = -170)
]
COLUMNS = ["wavelength_um", "n", "k"] + sr.GEOMETRY_COLUMNS + sb.MUELLER_COLUMNS


def spectral_material() -> mm.SpectralMaterial:
    return next(s for s in mm.SPECTRAL_MATERIALS if s.name == MATERIAL)


def header(spec: mm.SpectralMaterial) -> list[str]:
    return [
        "# made by scripts/scatmech_spectral_reference.py (deterministic) with NIST SCATMECH (pyscatmech 0.1.10)",
        "# Shadowed_Facet_BRDF_Model, noise-free. The model is the silicate_glass truth of",
        "# scripts/make_measurements.py at three wavelengths, n and k from its Lorentz law in full precision",
        f"# material: {spec.name}",
        f"# distribution: {spec.distribution}",
        f"# sigma: {sb.fmt(spec.sigma)}",
        f"# q: {sb.fmt(spec.q)}",
        f"# shadowing: {spec.shadowing}",
        f"# rho_d: {sb.fmt(spec.rho_d)}",
        f"# dispersion: {spec.dispersion.describe()}",
        "# SCATMECH angles are phi_s = phi_r - phi_i - 180 deg; Smith through Table_Shadow_Function with the",
        "# evaluated angles as nodes (G1 by quadrature of Smith's definition), as in scatmech_reference.py",
        "# m00 is to agree to 1e-9 relative and every other element to 1e-9 * m00",
    ]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data",
                                                  "scatmech_spectral.csv"))
    args = ap.parse_args(argv)
    path = os.path.normpath(args.out)
    spec = spectral_material()
    g = np.array(GEOMETRIES, dtype=float)
    rows = []
    worst_numpy = 0.0
    for wl in WAVELENGTHS_UM:
        N = spec.dispersion.index(wl)
        mono = spec.at(wl).surface
        m = sb.ScatmechSurface(mono).mueller(g[:, 0], g[:, 1], g[:, 2], g[:, 3])
        keep = sr.comparable(g, m)
        if not keep.all():
            print(f"error: SCATMECH value not comparable at {wl} um for geometries {g[~keep].tolist()}", file=sys.stderr)
            return 1
        port = pn.mueller_brdf(g[:, 0], g[:, 1], g[:, 2], g[:, 3], distribution=mono.distribution, sigma=mono.sigma,
                               q=mono.q, n=mono.n, k=mono.k, shadowing=mono.shadowing)
        worst_numpy = max(worst_numpy, float((np.abs(port - m).max(axis=(1, 2)) / m[:, 0, 0]).max()))
        print(f"{wl:5g} um: N = {N.real:.6f} + {N.imag:.6f}i, eps = {(N * N).real:+.4f} {(N * N).imag:+.4f}i, "
              f"m00 {m[:, 0, 0].min():.3e} .. {m[:, 0, 0].max():.3e} sr^-1")
        for gi, mi in zip(g, m):
            rows.append([sb.fmt(wl), sb.fmt(mono.n), sb.fmt(mono.k)] + [sb.fmt(x) for x in gi]
                        + [sb.fmt(x) for x in mi.ravel()])
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        f.write("\n".join(header(spec)) + "\n")
        w = csv.writer(f, lineterminator="\n")
        w.writerow(COLUMNS)
        w.writerows(rows)
    os.replace(tmp, path)
    print(f"wrote {path}: {len(rows)} rows ({len(GEOMETRIES)} geometries x {len(WAVELENGTHS_UM)} wavelengths); "
          f"numpy port vs SCATMECH: max |diff| / m00 = {worst_numpy:.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
