"""SCATMECH golden data for the irpol pBRDF model (docs/design.md §1.3), and a parity check of the irpol CLI.

    python scripts/scatmech_reference.py [--out tests/data/scatmech_golden.csv] [--seed S]
        Writes the golden CSV (deterministic for a given seed).

    python scripts/scatmech_reference.py --check-cli PATH_TO_IRPOL [--count N] [--seed S]
        Draws a fresh random set of cases (seed from the clock unless --seed), runs
        `irpol eval --sigma S [--q Q] --n N --k K --distribution D --shadowing SH --geometry FILE.csv`
        once per parameter group and compares its Mueller matrices with SCATMECH's.
        Exit 0 on agreement, 1 on a mismatch (with the first offending rows), 2 if the CLI fails.
        Tolerances: m00 within 1e-9 relative, every other element within 1e-9 * m00, Smith included.

    python scripts/scatmech_reference.py --measure-table-interpolation
        What a uniform Smith G1 table would cost instead of the exact-node table used here.

CSV columns: distribution,sigma,q,n,k,shadowing,wavelength_um,theta_i_deg,phi_i_deg,theta_r_deg,
phi_r_deg,m00,m01,...,m33 (row-major, sr^-1, psps frames of the global geometry).  q is EMPTY for the
Gaussian.  Numbers have 17 significant digits, so they parse back to the exact doubles SCATMECH used.
rho_d is 0 throughout (the diffuse term is trivial and not part of SCATMECH's facet model).

Rows are dropped when SCATMECH's value is not trustworthy or not comparable:
* m00 = 0, non-finite, or below 1e-280 (subnormal results lose relative precision);
* 0 < beta < 0.5 deg (near retro-reflection): SCATMECH's facet Jones matrix divides by
  sin^2(2 iota) with iota = acos(...), so it loses ~eps/beta^2 relative accuracy (measured: 2e-8 at
  beta = 0.005 deg, 2e-4 at 5e-5 deg, while the vector form of docs/design.md §1.3 is smooth there);
* theta_i = theta_r = 0 with phi_r - phi_i not a multiple of 180 deg: SCATMECH's exact-retro branch
  ignores the viewer azimuth there, while docs/design.md §1.3 takes the theta -> 0+ limit along each azimuth.
  (theta_i = theta_r = 0 with phi_r = phi_i + 180 is kept: both conventions agree.)
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scatmech_backend as sb  # noqa: E402

GEOMETRY_COLUMNS = ["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg"]
PARAM_COLUMNS = ["distribution", "sigma", "q", "n", "k", "shadowing", "wavelength_um"]
COLUMNS = PARAM_COLUMNS + GEOMETRY_COLUMNS + sb.MUELLER_COLUMNS

THETA_MAX_DEG = 89.0
RETRO_MIN_BETA_DEG = 0.5
M00_MIN = 1e-280

# Paints/dielectrics of docs/design.md §1.3 and the task, a metal, a glass, and a non-absorbing dielectric.
INDICES = [(1.2, 0.2), (1.5, 0.1), (2.4, 0.05), (10.0, 30.0), (2.2, 0.6), (1.55, 0.05), (1.8, 0.0)]
WAVELENGTHS = [9.925, 10.0, 10.6]
CAUCHY_FIXED = [(0.05, 1.6), (0.1, 1.8), (0.2, 2.0), (0.3, 2.5), (0.5, 4.0)]
GAUSSIAN_FIXED = [0.05, 0.1, 0.15, 0.3, 0.5]

# Tolerances of the CLI check.  The Smith reference uses a shadow table whose nodes are exactly the
# evaluated angles, so SCATMECH's table interpolation adds nothing and Smith gets the same bound.
# (A uniform table would not do: 1e3 nodes cost ~1e-4, 1e4 ~1e-6, 1e5 ~1e-8 relative to m00;
# --measure-table-interpolation reproduces this.)
TOL_M00_REL = 1e-9
TOL_ELEMENT_REL_M00 = 1e-9


# ---------------------------------------------------------------------------------------------
# Drawing cases
# ---------------------------------------------------------------------------------------------


def draw_params(rng: np.random.Generator, groups_per_combo: int, corners_first: bool) -> list[sb.SurfaceParams]:
    """Parameter groups per (distribution, shadowing) pair: optionally the fixed corner values first,
    then random sigma in [0.05, 0.5] and q in [1.6, 4]."""
    out = []
    for dist in sb.DISTRIBUTIONS:
        for shadowing in sb.SHADOWINGS:
            fixed = CAUCHY_FIXED if dist == "cauchy" else [(s, 0.0) for s in GAUSSIAN_FIXED]
            fixed = fixed if corners_first else []
            for g in range(groups_per_combo):
                if g < len(fixed):
                    sigma, q = fixed[g]
                else:
                    sigma = float(rng.uniform(0.05, 0.5))
                    q = float(rng.uniform(1.6, 4.0)) if dist == "cauchy" else 0.0
                if corners_first:
                    # every (distribution, shadowing) pair sees every index, paired differently
                    offset = 2 * sb.SHADOWINGS.index(shadowing) + sb.DISTRIBUTIONS.index(dist)
                    n, k = INDICES[(g + offset) % len(INDICES)]
                else:
                    n, k = INDICES[int(rng.integers(len(INDICES)))]
                wl = WAVELENGTHS[int(rng.integers(len(WAVELENGTHS)))]
                out.append(sb.SurfaceParams(dist, sigma, q, n, k, shadowing, wl))
    return out


def draw_geometries(rng: np.random.Generator, count: int) -> np.ndarray:
    """(count, 4) degrees: theta_i, phi_i, theta_r, phi_r with phi in [0, 360).

    Mix: in-plane forward (phi_r = phi_i + 180) and backward (phi_r = phi_i) sweeps, theta_i = 0,
    theta_r = 0, both zero (specular azimuth), near-specular, grazing (80..89 deg), and the rest
    uniformly out of plane."""
    kinds = ["forward", "backward", "normal_i", "normal_r", "near_specular", "grazing"]
    rows = []
    for j in range(count):
        kind = kinds[j % len(kinds)] if j < count // 2 else "random"
        phi_i = float(rng.uniform(0.0, 360.0))
        ti = float(rng.uniform(0.0, THETA_MAX_DEG))
        tr = float(rng.uniform(0.0, THETA_MAX_DEG))
        dphi = float(rng.uniform(0.0, 360.0))
        if kind == "forward":
            dphi = 180.0
        elif kind == "backward":
            dphi = 0.0
        elif kind == "normal_i":
            ti = 0.0
        elif kind == "normal_r":
            tr = 0.0
        elif kind == "near_specular":
            tr = float(np.clip(ti + rng.normal(0.0, 3.0), 0.0, THETA_MAX_DEG))
            dphi = 180.0 + float(rng.normal(0.0, 5.0))
        elif kind == "grazing":
            if rng.uniform() < 0.5:
                ti = float(rng.uniform(80.0, THETA_MAX_DEG))
            else:
                tr = float(rng.uniform(80.0, THETA_MAX_DEG))
        rows.append((ti, phi_i, tr, (phi_i + dphi) % 360.0))
    # one double-normal row (specular azimuth), which both conventions define the same way
    phi = float(rng.uniform(0.0, 180.0))
    rows.append((0.0, phi, 0.0, phi + 180.0))
    # parse back from 17 significant digits so the CSV text is exactly what SCATMECH saw
    return np.array([[float(sb.fmt(x)) for x in r] for r in rows])


def half_angle_beta_deg(g: np.ndarray) -> np.ndarray:
    """Local incidence angle beta (docs/design.md §1.1) from cos 2beta = w_i . w_r."""
    ti, pi_, tr, pr = np.radians(g.T)
    c2b = np.cos(ti) * np.cos(tr) + np.sin(ti) * np.sin(tr) * np.cos(pr - pi_)
    return np.degrees(0.5 * np.arccos(np.clip(c2b, -1.0, 1.0)))


def comparable(g: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Row mask: see the module docstring for why each rule exists."""
    m00 = m[:, 0, 0]
    finite = np.all(np.isfinite(m.reshape(len(m), -1)), axis=1)
    beta = half_angle_beta_deg(g)
    double_normal = (g[:, 0] == 0.0) & (g[:, 2] == 0.0)
    dphi = np.mod(g[:, 3] - g[:, 1], 180.0)
    double_normal_ok = double_normal & ((dphi == 0.0) | np.isclose(dphi, 0.0, atol=1e-12)
                                        | np.isclose(dphi, 180.0, atol=1e-12))
    near_retro = (beta < RETRO_MIN_BETA_DEG) & ~double_normal_ok
    return finite & (m00 >= M00_MIN) & ~near_retro


def evaluate_group(params: sb.SurfaceParams, geoms: np.ndarray) -> np.ndarray:
    surf = sb.ScatmechSurface(params)
    return surf.mueller(geoms[:, 0], geoms[:, 1], geoms[:, 2], geoms[:, 3])


# ---------------------------------------------------------------------------------------------
# Golden CSV
# ---------------------------------------------------------------------------------------------


def param_fields(p: sb.SurfaceParams) -> list[str]:
    q = sb.fmt(p.q) if p.distribution == "cauchy" else ""
    return [p.distribution, sb.fmt(p.sigma), q, sb.fmt(p.n), sb.fmt(p.k), p.shadowing, sb.fmt(p.wavelength_um)]


def write_golden(path: str, seed: int, groups_per_combo: int, per_group: int) -> None:
    rng = np.random.default_rng(seed)
    params = draw_params(rng, groups_per_combo, corners_first=True)
    rows = []
    calls = 0
    t_eval = 0.0
    stats: dict[tuple[str, str], int] = {}
    dropped = 0
    for p in params:
        g = draw_geometries(rng, per_group)
        t0 = time.perf_counter()
        m = evaluate_group(p, g)
        t_eval += time.perf_counter() - t0
        calls += len(g)
        keep = comparable(g, m)
        dropped += int((~keep).sum())
        for gi, mi in zip(g[keep], m[keep]):
            rows.append(param_fields(p) + [sb.fmt(x) for x in gi] + [sb.fmt(x) for x in mi.ravel()])
        stats[(p.distribution, p.shadowing)] = stats.get((p.distribution, p.shadowing), 0) + int(keep.sum())
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(COLUMNS)
        w.writerows(rows)
    os.replace(tmp, path)
    print(f"wrote {path}: {len(rows)} rows from {len(params)} parameter groups (seed {seed}), "
          f"{dropped} candidate rows dropped")
    for (d, s), c in sorted(stats.items()):
        print(f"  {d:8s} {s:17s} {c:5d} rows")
    geo = np.array([[float(r[7]), float(r[9])] for r in rows])
    print(f"  theta_i = 0: {int((geo[:, 0] == 0).sum())} rows, theta_r = 0: {int((geo[:, 1] == 0).sum())} rows, "
          f"theta >= 80: {int((geo.max(axis=1) >= 80).sum())} rows, max theta {geo.max():.3f}")
    print(f"SCATMECH evaluation incl. Smith tables: {1e6 * t_eval / calls:.1f} us per geometry")


# ---------------------------------------------------------------------------------------------
# CLI parity check
# ---------------------------------------------------------------------------------------------


def run_cli(irpol: str, p: sb.SurfaceParams, geometry_csv: str) -> np.ndarray:
    cmd = [irpol, "eval", "--sigma", sb.fmt(p.sigma)]
    if p.distribution == "cauchy":
        cmd += ["--q", sb.fmt(p.q)]
    cmd += ["--n", sb.fmt(p.n), "--k", sb.fmt(p.k), "--distribution", p.distribution,
            "--shadowing", p.shadowing, "--geometry", geometry_csv]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        raise CliError(f"`{' '.join(cmd)}` exited {proc.returncode}: {proc.stderr.strip()}")
    lines = [ln for ln in proc.stdout.splitlines() if ln.strip() and not ln.startswith("#")]
    reader = csv.DictReader(io.StringIO("\n".join(lines)))
    missing = [c for c in GEOMETRY_COLUMNS + sb.MUELLER_COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise CliError(f"`{' '.join(cmd)}`: output lacks columns {missing}; header {reader.fieldnames}")
    out = [[float(r[c]) for c in GEOMETRY_COLUMNS + sb.MUELLER_COLUMNS] for r in reader]
    return np.array(out, dtype=float).reshape(-1, 4 + 16)


class CliError(RuntimeError):
    pass


def check_cli(irpol: str, count: int, seed: int) -> int:
    rng = np.random.default_rng(seed)
    per_group = 40
    combos = len(sb.DISTRIBUTIONS) * len(sb.SHADOWINGS)
    groups_per_combo = max(1, math.ceil(count / (per_group * combos)))
    # random groups only: the fixed corner values are already in the golden file
    params = draw_params(rng, groups_per_combo, corners_first=False)
    per_group = math.ceil(count / len(params))
    workdir = tempfile.mkdtemp(prefix="irpol_check_")
    failures = []
    compared = 0
    worst = 0.0
    for gi, p in enumerate(params):
        g = draw_geometries(rng, per_group)
        m = evaluate_group(p, g)
        keep = comparable(g, m)
        g, m = g[keep], m[keep]
        geo_path = os.path.join(workdir, f"geometry_{gi}.csv")
        with open(geo_path, "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(GEOMETRY_COLUMNS)
            w.writerows([[sb.fmt(x) for x in row] for row in g])
        try:
            out = run_cli(irpol, p, geo_path)
        except (CliError, OSError, subprocess.TimeoutExpired) as e:
            print(f"error: {e}", file=sys.stderr)
            return 2
        if out.shape[0] != len(g):
            failures.append(f"{p}: CLI returned {out.shape[0]} rows for {len(g)} geometries ({geo_path})")
            continue
        if not np.array_equal(out[:, :4], g):
            bad = int(np.argmax(np.any(out[:, :4] != g, axis=1)))
            failures.append(f"{p}: row {bad} geometry echoed as {out[bad, :4]} instead of {g[bad]}")
            continue
        ours = out[:, 4:].reshape(-1, 4, 4)
        m00 = m[:, 0, 0]
        err = np.abs(ours - m) / m00[:, None, None]
        tol = np.full((4, 4), TOL_ELEMENT_REL_M00)
        tol[0, 0] = TOL_M00_REL
        compared += len(g)
        worst = max(worst, float(err.max()) if err.size else 0.0)
        for r, c_i, c_j in zip(*np.nonzero(err > tol)):
            failures.append(
                f"{p.distribution} sigma={sb.fmt(p.sigma)} q={sb.fmt(p.q)} n={p.n} k={p.k} {p.shadowing}: "
                f"geometry (theta_i, phi_i, theta_r, phi_r) = ({', '.join(sb.fmt(x) for x in g[r])}): "
                f"m{c_i}{c_j} irpol {ours[r, c_i, c_j]:.17g} vs SCATMECH {m[r, c_i, c_j]:.17g} "
                f"(|diff|/m00 = {err[r, c_i, c_j]:.3e} > {tol[c_i, c_j]:.0e})")
    print(f"check-cli: seed {seed}, {compared} geometries in {len(params)} parameter groups, "
          f"max |irpol - SCATMECH| / m00 = {worst:.3e}")
    if failures:
        for f in failures[:20]:
            print("MISMATCH:", f, file=sys.stderr)
        if len(failures) > 20:
            print(f"... and {len(failures) - 20} more", file=sys.stderr)
        print(f"0 passed, 1 failed ({len(failures)} mismatching elements)")
        return 1
    print("1 passed, 0 failed")
    return 0


def measure_table_interpolation(seed: int) -> int:
    """What SCATMECH's linear interpolation of a uniform Smith G1 table would cost, relative to the
    exact-node table the golden data uses: max |M_grid - M_exact| / m00 over random geometries."""
    rng = np.random.default_rng(seed)
    g = draw_geometries(rng, 300)
    print("uniform theta grid nodes:        1e3       1e4       1e5")
    for dist, sigma, q in [("cauchy", 0.05, 1.6), ("cauchy", 0.3, 2.5), ("gaussian", 0.05, 0.0), ("gaussian", 0.5, 0.0)]:
        surf = sb.ScatmechSurface(sb.SurfaceParams(dist, sigma, q, 1.5, 0.1, "smith", 10.0))
        exact = surf.mueller(g[:, 0], g[:, 1], g[:, 2], g[:, 3])
        ok = comparable(g, exact)
        line = f"{dist:8s} sigma={sigma:<4} q={q:<3}:"
        for nodes in (1000, 10000, 100000):
            surf.set_smith_nodes(np.linspace(0.0, math.pi / 2, nodes)[:-1])
            grid = surf.mueller(g[:, 0], g[:, 1], g[:, 2], g[:, 3], smith_exact_nodes=False)
            err = np.abs(grid - exact)[ok].max(axis=(1, 2)) / exact[ok, 0, 0]
            line += f"  {err.max():.1e}"
        print(line)
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "..", "tests", "data",
                                                  "scatmech_golden.csv"))
    ap.add_argument("--seed", type=int, default=None, help="golden default 20240611; check-cli default: clock")
    ap.add_argument("--groups-per-combo", type=int, default=7,
                    help="parameter groups per (distribution, shadowing) pair for the golden file")
    ap.add_argument("--per-group", type=int, default=64, help="candidate geometries per group (golden)")
    ap.add_argument("--check-cli", metavar="PATH_TO_IRPOL")
    ap.add_argument("--count", type=int, default=500, help="geometries to check with --check-cli")
    ap.add_argument("--measure-table-interpolation", action="store_true",
                    help="report the error a uniform Smith table would add (slow: ~2 min)")
    args = ap.parse_args(argv)
    if args.measure_table_interpolation:
        return measure_table_interpolation(args.seed if args.seed is not None else 1)
    if args.check_cli:
        seed = args.seed if args.seed is not None else int(time.time())
        return check_cli(args.check_cli, args.count, seed)
    write_golden(os.path.normpath(args.out), args.seed if args.seed is not None else 20240611,
                 args.groups_per_combo, args.per_group)
    return 0


if __name__ == "__main__":
    sys.exit(main())
