"""Cross-check of irpol's division-of-focal-plane output (docs/scenes.md, "Division of focal plane")
against an independent numpy form of the bilinear demosaicking, written from the docs' description.

    .venv/bin/python scripts/check_dofp_numpy.py [--irpol PATH] [--size 63x47 --size 64x48]

The docs describe the camera as: a polarizer on every pixel repeating over 2x2 superpixels,

    row 0:  90   45   90   45 ...
    row 1: 135    0  135    0 ...

(x to the right, row 0 at the top); `dofp_mosaic.tif` holds each pixel's recorded value at its own
orientation; each orientation's samples form a lattice of spacing 2 that is bilinearly interpolated
to every pixel, the nearest lattice rows/columns beyond the last sample; then S0 = (I0 + I45 + I90 +
I135)/2, S1 = I0 - I90, S2 = I45 - I135.

For each size the shipped car scene (scenes/car.toml, its NETD noise kept, so the four polarizer
images differ pixel by pixel) is rendered with `[sensor] dofp = true` at that resolution, and

1. the mosaic must equal, pixel by pixel and exactly, the recorded polarizer image I0.tif ... I135.tif
   of the orientation the pattern above puts there;
2. numpy demosaicks the mosaic (np.interp along each lattice row, then each lattice column: the
   separable form of bilinear interpolation, clamped at the ends) and its S0, S1, S2 must match
   dofp_S0.tif, dofp_S1.tif, dofp_S2.tif to 1e-6 of the largest |S0| (irpol works in f32: ~1e-7);
3. the check must be able to fail: the same numpy demosaicking with the pattern's rows swapped
   (and separately with 0 and 90 exchanged) must miss irpol's S1 or S2 by more than 100 times the
   tolerance.

Odd sizes give orientations lattices of different lengths, so both border rules are exercised.
Exit status 0 when every check passes, 1 when one fails, 2 on setup problems (no irpol binary,
irpol failing, outputs that cannot be read). The last line is `N passed, M failed`.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
# Orientation (degrees) at (row % 2, column % 2), as the docs draw the superpixel.
PATTERN = {(0, 0): 90, (0, 1): 45, (1, 0): 135, (1, 1): 0}
ANGLES = (0, 45, 90, 135)
TOLERANCE = 1e-6


class SetupError(Exception):
    """A problem with the inputs or the environment, not with the check (exit status 2)."""


def render(irpol: str, workdir: str, width: int, height: int) -> str:
    """Renders the car at width x height with dofp = true; returns the output folder."""
    scenes = os.path.join(workdir, "scenes")
    os.makedirs(scenes, exist_ok=True)
    shutil.copy(os.path.join(REPO, "scenes", "car.obj"), scenes)
    with open(os.path.join(REPO, "scenes", "car.toml"), encoding="utf-8") as f:
        text = f.read()
    replaced = {
        'material_library = "../fits"': f'material_library = "{os.path.join(REPO, "fits")}"',
        "resolution = [640, 480]": f"resolution = [{width}, {height}]",
        "[sensor]\n": "[sensor]\ndofp = true\n",
    }
    for old, new in replaced.items():
        if old not in text:
            raise SetupError(f"scenes/car.toml no longer contains {old!r}")
        text = text.replace(old, new, 1)
    scene = os.path.join(scenes, "car.toml")
    with open(scene, "w", encoding="utf-8") as f:
        f.write(text)
    out = os.path.join(workdir, "out")
    done = subprocess.run([irpol, "render", scene, "--out", out], capture_output=True, text=True)
    if done.returncode != 0:
        raise SetupError(f"irpol render failed ({done.returncode}): {done.stderr.strip()}")
    return out


def bilinear(raw: np.ndarray, pattern: dict) -> dict:
    """Each orientation's lattice interpolated to every pixel: {angle: image}."""
    height, width = raw.shape
    planes = {}
    for (r0, c0), angle in pattern.items():
        lattice = raw[r0::2, c0::2].astype(np.float64)
        # Pixel coordinate -> lattice coordinate (sample j sits at pixel c0 + 2 j).
        u = (np.arange(width) - c0) / 2.0
        v = (np.arange(height) - r0) / 2.0
        rows = np.array([np.interp(u, np.arange(lattice.shape[1]), row) for row in lattice])
        planes[angle] = np.array([np.interp(v, np.arange(rows.shape[0]), col) for col in rows.T]).T
    return planes


def stokes(planes: dict) -> list:
    i0, i45, i90, i135 = (planes[a] for a in ANGLES)
    return [0.5 * (i0 + i45 + i90 + i135), i0 - i90, i45 - i135]


def check_size(irpol: str, width: int, height: int) -> list:
    """[(name, passed, detail)] for one rendered size."""
    import tifffile

    with tempfile.TemporaryDirectory() as workdir:
        out = render(irpol, workdir, width, height)
        try:
            raw = tifffile.imread(os.path.join(out, "dofp_mosaic.tif"))
            recorded = {a: tifffile.imread(os.path.join(out, f"I{a}.tif")) for a in ANGLES}
            irpol_s = [tifffile.imread(os.path.join(out, f"dofp_S{c}.tif")).astype(np.float64) for c in range(3)]
        except (OSError, ValueError) as e:
            raise SetupError(f"cannot read irpol's output: {e}") from e
    if raw.shape != (height, width):
        raise SetupError(f"dofp_mosaic.tif is {raw.shape}, expected {(height, width)}")
    results = []
    rows, cols = np.indices(raw.shape)
    expected = np.zeros_like(raw)
    for (r0, c0), angle in PATTERN.items():
        mask = (rows % 2 == r0) & (cols % 2 == c0)
        expected[mask] = recorded[angle][mask]
    mismatches = int(np.count_nonzero(raw != expected))
    results.append((f"{width}x{height} mosaic = recorded I at the pattern's orientation", mismatches == 0,
                    f"{mismatches} pixels differ"))
    scale = float(np.max(np.abs(irpol_s[0])))
    ours = stokes(bilinear(raw, PATTERN))
    worst = max(float(np.max(np.abs(a - b))) for a, b in zip(ours, irpol_s))
    results.append((f"{width}x{height} S0, S1, S2 against numpy", worst <= TOLERANCE * scale,
                    f"worst |diff| {worst:.3e} = {worst / scale:.2e} of max |S0| (tolerance {TOLERANCE:g})"))
    wrong_patterns = {
        "rows swapped": {((r + 1) % 2, c): a for (r, c), a in PATTERN.items()},
        "0 and 90 exchanged": {k: {0: 90, 90: 0}.get(a, a) for k, a in PATTERN.items()},
    }
    for name, pattern in wrong_patterns.items():
        wrong = stokes(bilinear(raw, pattern))
        miss = max(float(np.max(np.abs(a - b))) for a, b in zip(wrong[1:], irpol_s[1:]))
        results.append((f"{width}x{height} a {name} pattern is caught", miss > 100 * TOLERANCE * scale,
                        f"worst |diff| {miss:.3e} = {miss / scale:.2e} of max |S0|"))
    return results


def parse_size(text: str) -> tuple:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError as e:
        raise argparse.ArgumentTypeError(f"size {text!r} is not WIDTHxHEIGHT") from e
    return w, h


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--irpol", default=os.path.join(REPO, "target", "release", "irpol"))
    parser.add_argument("--size", type=parse_size, action="append", help="WIDTHxHEIGHT (repeatable)")
    args = parser.parse_args()
    sizes = args.size or [(63, 47), (64, 48)]
    try:
        if not os.path.isfile(args.irpol):
            raise SetupError(f"no irpol binary at {args.irpol} (cargo build --release)")
        results = [r for w, h in sizes for r in check_size(args.irpol, w, h)]
    except SetupError as e:
        print(f"setup problem: {e}")
        return 2
    failed = 0
    for name, passed, detail in results:
        print(f"{'PASS' if passed else 'FAIL'}  {name}: {detail}")
        failed += not passed
    print(f"{len(results) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
