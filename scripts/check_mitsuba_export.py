#!/usr/bin/env python3
"""Mitsuba 3 loads irpol's exported `.pbsdf` tables and evaluates them as irpol does
(docs/design.md §2.10, docs/mitsuba.md).

For each shipped material: `irpol export --to mitsuba` at its default grid; Mitsuba 3
(`scalar_spectral_polarized`, plugin `measured_polarized`) evaluates the table at random direction
pairs with both cosines >= 0.2; each 4x4 result is divided by Mitsuba's cosine, turned from
Mitsuba's Stokes bases into psps (docs/design.md §1.3: s = unit(z x k), p = k x s, and S3 of the
opposite sign) and compared with `irpol eval` at the same geometries, all 16 elements, the
circular ones with their sign. Fails (exit 1) if a material misses the bars: m00 within 1 %
(median) and 5 % (95th percentile), m_ij/m00 within 0.01 (95th percentile).

Then scripts/check_mitsuba_scene.py (unless --no-scene): a sphere and a plane with exported
materials under a constant environment and a directional emitter, rendered by Mitsuba and by
irpol, whose region means of S0..S3 must agree within 1 % (~1.5 min).

Requirements: `pip install mitsuba==3.9.1 drjit==1.5.0 numpy`, a built `irpol` (IRPOL=path, else
target/release/irpol). Usage: python scripts/check_mitsuba_export.py [--pairs 400] [--seed 41]
[--no-scene]
"""

import argparse
import csv
import io
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MATERIALS = ["anodized_panel", "paper_paint", "rough_paint", "silicate_glass", "smooth_glass"]
NAMES = [f"m{i}{j}" for i in range(4) for j in range(4)]


def irpol(*args):
    binary = os.environ.get("IRPOL", os.path.join(ROOT, "target", "release", "irpol"))
    done = subprocess.run([binary, *args], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"irpol {' '.join(args)}: {done.stderr.strip()}")
    return done.stdout


def random_directions(rng, count):
    """Unit vectors with cos theta uniform in [0.2, 1] and a uniform azimuth."""
    z = rng.uniform(0.2, 1.0, count)
    phi = rng.uniform(-np.pi, np.pi, count)
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


def degrees(v):
    return np.degrees(np.arccos(v[2])), np.degrees(np.arctan2(v[1], v[0]))


def irpol_eval(material, wavelength_um, lights, views, folder):
    path = os.path.join(folder, "geometry.csv")
    with open(path, "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg"])
        for light, view in zip(lights, views):
            out.writerow([repr(float(x)) for x in (*degrees(light), *degrees(view))])
    text = irpol("eval", "--material", material, "--wavelength", str(wavelength_um),
                 "--geometry", path)
    lines = [line for line in text.splitlines() if not line.startswith("#")]
    rows = list(csv.DictReader(io.StringIO("\n".join(lines))))
    return np.array([[float(r[n]) for n in NAMES] for r in rows]).reshape(-1, 4, 4)


def psps_axis(k):
    """The psps s axis of light propagating along k: unit(z x k)."""
    s = np.cross([0.0, 0.0, 1.0], k)
    return s / np.linalg.norm(s)


def mitsuba_eval(mi, bsdf, wavelength_nm, light, view):
    """Mitsuba's Mueller BRDF (without its cosine) for light from `light` seen from `view`,
    in psps frames and psps's S3 sign."""
    si = mi.SurfaceInteraction3f()
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    si.wi = mi.Vector3f(*view)
    si.wavelengths = mi.UnpolarizedSpectrum(float(wavelength_nm))
    value = bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(*light))
    k_in, k_out = mi.Vector3f(*(-light)), mi.Vector3f(*view)
    value = mi.mueller.rotate_mueller_basis(
        value,
        k_in, mi.mueller.stokes_basis(k_in), mi.Vector3f(*psps_axis(-light)),
        k_out, mi.mueller.stokes_basis(k_out), mi.Vector3f(*psps_axis(view)))
    m = np.array(value)[:, :, 0] / light[2]
    flip = np.diag([1.0, 1.0, 1.0, -1.0])
    return flip @ m @ flip


def check(mi, name, pairs, rng, folder):
    material = os.path.join(ROOT, "fits", f"{name}.toml")
    table = os.path.join(folder, f"{name}.pbsdf")
    start = time.time()
    printed = irpol("export", material, "--to", "mitsuba", "--out", table).strip()
    seconds = time.time() - start
    bsdf = mi.load_dict({"type": "measured_polarized", "filename": table})
    wavelengths_nm = [int(w) for w in printed.split("wavelengths ")[1].split(" nm")[0].split(", ")]
    m00, ratio, circular = [], [], 0
    for wavelength_nm in wavelengths_nm[1:4]:
        lights, views = random_directions(rng, pairs), random_directions(rng, pairs)
        expected = irpol_eval(material, wavelength_nm / 1000.0, lights, views, folder)
        for light, view, exact in zip(lights, views, expected):
            got = mitsuba_eval(mi, bsdf, wavelength_nm, light, view)
            m00.append(abs(got[0, 0] / exact[0, 0] - 1.0))
            ratio.append(np.max(np.abs(got / got[0, 0] - exact / exact[0, 0])))
            big = abs(exact[2, 3]) > 0.02 * exact[0, 0]
            circular += int(big and np.sign(got[2, 3]) != np.sign(exact[2, 3]))
    m00, ratio = np.array(m00), np.array(ratio)
    line = (f"{name}: {printed.split(': ', 1)[1].split(', wavelengths')[0]}, "
            f"{os.path.getsize(table) / 1e6:.1f} MB, export {seconds:.1f} s; "
            f"{len(m00)} pairs: m00 median {100 * np.median(m00):.2f} % "
            f"p95 {100 * np.percentile(m00, 95):.2f} % max {100 * m00.max():.1f} %; "
            f"m_ij/m00 p95 {np.percentile(ratio, 95):.4f} max {ratio.max():.4f}; "
            f"m23 sign disagreements {circular}")
    print(line, flush=True)
    return (np.median(m00) <= 0.01 and np.percentile(m00, 95) <= 0.05
            and np.percentile(ratio, 95) <= 0.01 and circular == 0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--pairs", type=int, default=400,
                        help="direction pairs per wavelength (3 wavelengths per material)")
    parser.add_argument("--seed", type=int, default=41)
    parser.add_argument("--no-scene", action="store_true",
                        help="skip the rendered scene (scripts/check_mitsuba_scene.py)")
    args = parser.parse_args()
    import mitsuba as mi
    mi.set_variant("scalar_spectral_polarized")
    rng = np.random.default_rng(args.seed)
    with tempfile.TemporaryDirectory() as folder:
        passed = [check(mi, name, args.pairs, rng, folder) for name in MATERIALS]
    if not all(passed):
        sys.exit("FAILED: a material misses the bars (see above)")
    print("all materials within the bars")
    if not args.no_scene:
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import check_mitsuba_scene
        print("Rendered scene (scripts/check_mitsuba_scene.py):", flush=True)
        if check_mitsuba_scene.main([]) != 0:
            sys.exit("FAILED: the rendered scene (see above)")


if __name__ == "__main__":
    main()
