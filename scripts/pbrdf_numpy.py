"""Independent numpy port of the irpol polarized BRDF (docs/design.md §1.1–1.3), vectorized over geometries.

F(w_i -> w_r) = P(theta) G M(beta, eta_i, eta_r) / (4 cos(theta) cos(theta_i) cos(theta_r)) + rho_d/pi diag(1,0,0,0)

The facet Fresnel matrix uses eps = N^2 (`facet="external"`, reflection off the material from air) or
eps = N^2/|N|^4 = conj(1/N^2) (`facet="internal"`, reflection inside the material off grain/air facets,
docs/design.md §1.10: the conjugate keeps Im eps >= 0, so total internal reflection stays on the physical
branch for k > 0); the subsurface term of §1.10 is in pbrdf_volume_numpy.py.

Written from docs/design.md, not from the Rust code; the SCATMECH side (scatmech_backend.py) is the
external reference.  Used by the nlopt/emcee cross-checks as a fast model.

    python scripts/pbrdf_numpy.py --self-test [--count N] [--seed S]

compares it with SCATMECH on random geometries and parameter sets and exits non-zero on mismatch.
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import sys
import time

import numpy as np
from scipy import special

DISTRIBUTIONS = ("cauchy", "gaussian")
SHADOWINGS = ("none", "torrance-sparrow", "smith")


# ---------------------------------------------------------------------------------------------
# Geometry (docs/design.md §1.1) and frames (§1.3)
# ---------------------------------------------------------------------------------------------


def direction(theta, phi):
    """Unit vectors (..., 3) pointing away from the surface."""
    st = np.sin(theta)
    return np.stack([st * np.cos(phi), st * np.sin(phi), np.cos(theta)], axis=-1)


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def global_frames(theta_i, phi_i, theta_r, phi_r):
    """psps frames of docs/design.md §1.3: s = unit(z x k), p = k x s for k_in = -w_i and k_out = w_r.

    z x k is written out from the azimuth, which is the theta -> 0+ limit along phi at normal
    incidence/viewing and needs no special case: for w = (sin t cos f, sin t sin f, cos t),
    z x w = sin t (-sin f, cos f, 0)."""
    w_i = direction(theta_i, phi_i)
    w_r = direction(theta_r, phi_r)
    k_in, k_out = -w_i, w_r
    zeros = np.zeros_like(phi_i)
    s_in = np.stack([np.sin(phi_i), -np.cos(phi_i), zeros], axis=-1)  # unit(z x (-w_i))
    s_out = np.stack([-np.sin(phi_r), np.cos(phi_r), np.zeros_like(phi_r)], axis=-1)  # unit(z x w_r)
    p_in = np.cross(k_in, s_in)
    p_out = np.cross(k_out, s_out)
    return w_i, w_r, k_in, k_out, s_in, p_in, s_out, p_out


def facet_frame_projections(theta_i, phi_i, theta_r, phi_r):
    """The facet term's change of frames (docs/design.md §1.3), angles in radians.

    Returns (h, cos_beta, out_proj, in_proj): the half vector h (..., 3), cos_beta = h . w_i clipped to
    [0, 1], and the 2x2 projections between the psps frames g = (s, p) of the global geometry and the
    facet-local frames f = (s_loc, p_loc), s_loc = unit(h x k_in) (the normal of the plane of w_i and
    w_r, the same vector on both sides), p_loc = k x s_loc:
        out_proj[a, c] = g_out_a . f_out_c,   in_proj[c, b] = f_in_c . g_in_b,
    so that a Jones matrix diag(r_s, r_p) in the facet frames is out_proj @ diag(r_s, r_p) @ in_proj in
    the psps frames.  Both are rotations (the frames share k and are right-handed)."""
    w_i, w_r, k_in, k_out, s_in, p_in, s_out, p_out = global_frames(theta_i, phi_i, theta_r, phi_r)

    h = _unit(w_i + w_r)
    cos_b = np.clip(_dot(h, w_i), 0.0, 1.0)

    # Facet frames: s_loc = unit(h x k_in) (the same vector on both sides), p_loc = k x s_loc.
    # At exact retro-reflection h || k_in; then r_p = -r_s makes the result frame independent,
    # so any s_loc perpendicular to k_in works: take the global s_in.
    hxk = np.cross(h, k_in)
    norm = np.linalg.norm(hxk, axis=-1, keepdims=True)
    # |h x k_in| of unit vectors: at exact retro-reflection rounding leaves ~1e-17, not 0.
    degenerate = norm[..., 0] < 1e-12
    s_loc = np.where(degenerate[..., None], s_in, hxk / np.where(norm > 0, norm, 1.0))
    p_loc_in = np.cross(k_in, s_loc)
    p_loc_out = np.cross(k_out, s_loc)

    out_proj = np.stack(
        [
            np.stack([_dot(s_out, s_loc), _dot(s_out, p_loc_out)], axis=-1),
            np.stack([_dot(p_out, s_loc), _dot(p_out, p_loc_out)], axis=-1),
        ],
        axis=-2,
    )
    in_proj = np.stack(
        [
            np.stack([_dot(s_loc, s_in), _dot(s_loc, p_in)], axis=-1),
            np.stack([_dot(p_loc_in, s_in), _dot(p_loc_in, p_in)], axis=-1),
        ],
        axis=-2,
    )
    return h, cos_b, out_proj, in_proj


# ---------------------------------------------------------------------------------------------
# Fresnel (docs/design.md §1.3), exp(-i w t) convention, N = n + i k
# ---------------------------------------------------------------------------------------------


FACETS = ("external", "internal")


def permittivity(n, k, facet="external"):
    """Relative permittivity of the facet's far side: N^2 seen from air, conj(1/N^2) seen from inside."""
    if facet == "external":
        return complex(n, k) ** 2
    if facet == "internal":
        return (1.0 / complex(n, k) ** 2).conjugate()
    raise ValueError(f"unknown facet side {facet!r}")


def fresnel(cos_beta, n, k, facet="external"):
    """r_s, r_p of docs/design.md §1.3 with the principal root (Re >= 0).  The `+ 0j` makes the imaginary
    part of eps - sin^2 a +0 for real eps (k = 0), so total internal reflection takes +i sqrt(...) there,
    whatever the sign of zero 1/N^2 carries."""
    eps = permittivity(n, k, facet)
    sin2 = 1.0 - cos_beta**2
    root = np.sqrt(eps - sin2 + 0j)
    r_s = (cos_beta - root) / (cos_beta + root)
    r_p = (eps * cos_beta - root) / (eps * cos_beta + root)
    return r_s, r_p


# ---------------------------------------------------------------------------------------------
# Slope distributions (docs/design.md §1.2) and shadowing (§1.3)
# ---------------------------------------------------------------------------------------------


def slope_density(tan2, distribution, sigma, q):
    """Slope-space density p(m), m^2 = tan^2(theta); P(theta) = p / cos^3(theta)."""
    s2 = sigma * sigma
    if distribution == "gaussian":
        return np.exp(-tan2 / (2.0 * s2)) / (2.0 * math.pi * s2)
    a = 2.0 * s2
    return (q - 1.0) * a ** (q - 1.0) / (math.pi * (tan2 + a) ** q)


def smith_lambda(theta, distribution, sigma, q):
    """Closed forms of docs/design.md §1.3. theta = 0 gives Lambda = 0."""
    theta = np.asarray(theta, dtype=float)
    lam = np.zeros_like(theta)
    pos = theta > 0.0
    mu = np.cos(theta[pos]) / np.sin(theta[pos])
    if distribution == "gaussian":
        a = mu / (math.sqrt(2.0) * sigma)
        lam[pos] = -0.5 * special.erfc(a) + np.exp(-a * a) / (2.0 * math.sqrt(math.pi) * a)
    else:
        if not q > 1.5:
            raise ValueError(f"Smith shadowing for the Cauchy distribution needs q > 3/2, got q = {q}")
        a = 2.0 * sigma * sigma
        c = math.exp(special.gammaln(q - 0.5) - special.gammaln(q - 1.0)) / math.sqrt(math.pi)
        first = c * math.sqrt(a) / ((2.0 * q - 3.0) * mu) * (1.0 + mu * mu / a) ** (1.5 - q)
        lam[pos] = first - 0.5 * special.betainc(q - 1.0, 0.5, a / (a + mu * mu))
    return lam


def smith_g1(theta, distribution, sigma, q):
    return 1.0 / (1.0 + smith_lambda(theta, distribution, sigma, q))


def shadowing_factor(shadowing, cos_t, cos_b, theta_i, theta_r, distribution, sigma, q):
    if shadowing == "none":
        return np.ones_like(cos_t)
    if shadowing == "torrance-sparrow":
        cti, ctr = np.cos(theta_i), np.cos(theta_r)
        return np.minimum(1.0, np.minimum(2.0 * cos_t * cti / cos_b, 2.0 * cos_t * ctr / cos_b))
    if shadowing == "smith":
        return smith_g1(theta_i, distribution, sigma, q) * smith_g1(theta_r, distribution, sigma, q)
    raise ValueError(f"unknown shadowing {shadowing!r}")


# ---------------------------------------------------------------------------------------------
# Jones -> Mueller in the docs/design.md §1.3 Stokes convention
# ---------------------------------------------------------------------------------------------


def mueller_from_jones(J):
    """J (..., 2, 2) acting on (E_s, E_p) -> M (..., 4, 4) for
    S = (|Es|^2+|Ep|^2, |Es|^2-|Ep|^2, 2 Re(Es* Ep), 2 Im(Es* Ep))."""
    # Stokes = A . (Es Es*, Es Ep*, Ep Es*, Ep Ep*)
    A = np.array(
        [[1, 0, 0, 1], [1, 0, 0, -1], [0, 1, 1, 0], [0, 1j, -1j, 0]],
        dtype=complex,
    )
    A_inv = np.linalg.inv(A)
    # (E' E'^*) = (J kron J*) (E E^*)
    kron = np.einsum("...ab,...cd->...acbd", J, np.conj(J)).reshape(J.shape[:-2] + (4, 4))
    M = A @ kron @ A_inv
    return M.real


def mueller_brdf(
    theta_i_deg,
    phi_i_deg,
    theta_r_deg,
    phi_r_deg,
    *,
    distribution,
    sigma,
    q=0.0,
    n,
    k,
    shadowing="none",
    rho_d=0.0,
    facet="external",
):
    """Mueller BRDF (N, 4, 4) in sr^-1, psps frames of the global geometry (docs/design.md §1.3)."""
    if distribution not in DISTRIBUTIONS:
        raise ValueError(f"unknown distribution {distribution!r}")
    ti, pi_, tr, pr = (
        np.radians(np.atleast_1d(np.asarray(x, dtype=float)))
        for x in (theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg)
    )
    ti, pi_, tr, pr = np.broadcast_arrays(ti, pi_, tr, pr)
    h, cos_b, out_proj, in_proj = facet_frame_projections(ti, pi_, tr, pr)
    cos_t = h[..., 2]

    r_s, r_p = fresnel(cos_b, n, k, facet)
    # J[a, b] = sum_c (g_out_a . f_out_c) r_c (f_in_c . g_in_b), g = global (s, p), f = facet (s, p)
    r = np.stack([r_s, r_p], axis=-1)
    J = out_proj @ (r[..., :, None] * in_proj)
    M = mueller_from_jones(J)

    tan2 = np.maximum(1.0 - cos_t**2, 0.0) / cos_t**2
    p = slope_density(tan2, distribution, sigma, q)
    G = shadowing_factor(shadowing, cos_t, cos_b, ti, tr, distribution, sigma, q)
    scale = p / cos_t**3 * G / (4.0 * cos_t * np.cos(ti) * np.cos(tr))
    M = M * scale[..., None, None]
    M[..., 0, 0] += rho_d / math.pi
    return M


# ---------------------------------------------------------------------------------------------
# Self-test against SCATMECH
# ---------------------------------------------------------------------------------------------


def compare_with_golden(path: str) -> tuple[float, int]:
    """Largest |numpy - file| / m00 over all rows of a scatmech_golden.csv, and the row count."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        key = tuple(r[c] for c in ("distribution", "sigma", "q", "n", "k", "shadowing"))
        groups.setdefault(key, []).append(r)
    worst = 0.0
    cols = [f"m{i}{j}" for i in range(4) for j in range(4)]
    for (dist, sigma, q, n, k, shadowing), rs in groups.items():
        g = np.array([[float(r[c]) for c in ("theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg")] for r in rs])
        ref = np.array([[float(r[c]) for c in cols] for r in rs]).reshape(-1, 4, 4)
        ours = mueller_brdf(g[:, 0], g[:, 1], g[:, 2], g[:, 3], distribution=dist, sigma=float(sigma),
                            q=float(q) if q else 0.0, n=float(n), k=float(k), shadowing=shadowing)
        worst = max(worst, float((np.abs(ours - ref) / ref[:, 0, 0][:, None, None]).max()))
    return worst, len(rows)


def _self_test(count: int, seed: int) -> int:
    sys.path.insert(0, __file__.rsplit("/", 1)[0])
    import scatmech_backend as sb
    import scatmech_reference as ref
    from scipy import integrate

    failures = []

    # 1. docs/design.md §1.3 known values (Gaussian s = 0.3 -> sigma = 0.3/sqrt 2, N = 1.5+0.1i, G = 1).
    sig = 0.3 / math.sqrt(2.0)
    M = mueller_brdf(30, 0, 30, 180, distribution="gaussian", sigma=sig, n=1.5, k=0.1)[0]
    known = {(0, 0): 5.08136012e-02, (0, 1): 1.98022899e-02, (1, 0): 1.98022899e-02,
             (2, 2): -4.67727312e-02, (3, 3): -4.67727312e-02, (2, 3): 1.48424927e-03,
             (3, 2): -1.48424927e-03}
    for (i, j), v in known.items():
        if abs(M[i, j] - v) > 5e-9 * abs(v) + 1e-17:
            failures.append(f"known value m{i}{j}: {M[i, j]:.9e} != {v:.9e}")
    # phi_s = phi_r - phi_i - 180 = -90  ->  phi_i = 0, phi_r = 90
    M = mueller_brdf(10, 0, 70, 90, distribution="gaussian", sigma=sig, n=1.5, k=0.1)[0]
    for (i, j), v in {(0, 0): 8.50772992e-04, (1, 0): 4.25135713e-04, (2, 0): 1.65370386e-04}.items():
        if abs(M[i, j] - v) > 5e-9 * abs(v):
            failures.append(f"known value (10,70,-90) m{i}{j}: {M[i, j]:.9e} != {v:.9e}")
    M = mueller_brdf(10, 0, 70, 90, distribution="gaussian", sigma=sig, n=1.5, k=0.1,
                     shadowing="torrance-sparrow")[0]
    if abs(M[0, 0] - 5.77611334e-04) > 5e-9 * 5.77611334e-04:
        failures.append(f"known value TS m00: {M[0, 0]:.9e}")

    # 2. Smith closed forms (docs/design.md §1.3) vs quadrature of Smith's definition; the Cauchy marginal
    #    used by that quadrature vs a 2-D integral of the slope density; q = 2 closed form.
    for dist, s, qq in [("gaussian", 0.1, 0.0), ("gaussian", 0.4, 0.0), ("cauchy", 0.1, 1.6),
                        ("cauchy", 0.3, 2.0), ("cauchy", 0.2, 2.5), ("cauchy", 0.5, 4.0)]:
        for deg in (5.0, 30.0, 60.0, 80.0, 87.0, 89.0, 89.9):
            th = math.radians(deg)
            closed = float(smith_lambda(np.array([th]), dist, s, qq)[0])
            quad = sb.smith_lambda_quadrature(th, dist, s, qq)
            g_err = abs(1 / (1 + closed) - 1 / (1 + quad)) / (1 / (1 + quad))
            if g_err > 1e-11:
                failures.append(f"Smith G1 {dist} sigma={s} q={qq} theta={deg}: closed vs quadrature {g_err:.2e}")
            if dist == "cauchy" and qq == 2.0:
                q2 = 0.5 * (math.sqrt(1 + 2 * s * s * math.tan(th) ** 2) - 1)
                if abs(closed - q2) > 1e-12 * max(1.0, q2):
                    failures.append(f"Smith q=2 closed form theta={deg}: {closed} vs {q2}")
        if dist == "cauchy":
            for m in (0.0, 0.1, 1.0):
                two_d = integrate.quad(
                    lambda y: float(slope_density(np.array(m * m + y * y), dist, s, qq)), -np.inf, np.inf,
                    epsabs=0, epsrel=1e-13)[0]
                one_d = sb.marginal_slope_density(m, dist, s, qq)
                if abs(two_d - one_d) > 1e-10 * one_d:
                    failures.append(f"Cauchy marginal m={m}: {one_d} vs 2-D {two_d}")

    # 3. Random parameter groups and geometries (the golden file's sampler and row filter) vs SCATMECH.
    rng = np.random.default_rng(seed)
    worst = 0.0
    checked = 0
    params_list = ref.draw_params(rng, 1, corners_first=False)
    groups = len(params_list)
    per_group = max(8, count // groups)
    for params in params_list:
        g = ref.draw_geometries(rng, per_group)
        m_ref = ref.evaluate_group(params, g)
        ok = ref.comparable(g, m_ref)
        g, m_ref = g[ok], m_ref[ok]
        ours = mueller_brdf(g[:, 0], g[:, 1], g[:, 2], g[:, 3], distribution=params.distribution,
                            sigma=params.sigma, q=params.q, n=params.n, k=params.k,
                            shadowing=params.shadowing)
        err = np.abs(ours - m_ref) / m_ref[:, 0, 0][:, None, None]
        checked += len(g)
        e = float(err.max()) if err.size else 0.0
        worst = max(worst, e)
        if e > 1e-9:
            bad = int(np.argmax(err.reshape(len(err), -1).max(axis=1)))
            failures.append(f"{params}: max |numpy - SCATMECH|/m00 = {e:.2e} at (theta_i, phi_i, theta_r, "
                            f"phi_r) = {tuple(g[bad])}")

    print(f"self-test: {checked} geometries in {groups} parameter groups, "
          f"max |numpy - SCATMECH| / m00 = {worst:.2e}")

    # 4. The shipped golden file, if present (it was written by scatmech_reference.py).
    golden = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data", "scatmech_golden.csv")
    if os.path.exists(golden):
        e, rows = compare_with_golden(golden)
        print(f"golden file: {rows} rows, max |numpy - golden| / m00 = {e:.2e}")
        if e > 1e-9:
            failures.append(f"golden file {golden}: max |numpy - golden| / m00 = {e:.2e}")
    if failures:
        for f in failures:
            print("FAIL:", f)
        print(f"0 passed, {len(failures)} failed")
        return 1
    print("1 passed, 0 failed")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--self-test", action="store_true", help="compare against SCATMECH")
    ap.add_argument("--count", type=int, default=300, help="random geometries for --self-test")
    ap.add_argument("--seed", type=int, default=20240611)
    args = ap.parse_args(argv)
    if args.self_test:
        t0 = time.time()
        rc = _self_test(args.count, args.seed)
        print(f"({time.time() - t0:.1f} s)")
        return rc
    ap.print_help()
    return 0


if __name__ == "__main__":
    sys.exit(main())
