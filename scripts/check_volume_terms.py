"""Checks the model terms of docs/design.md §1.10 (internal facets, polarized subsurface term) in numpy, and
`irpol eval` against the independent numpy form of them (pbrdf_volume_numpy.py).

    .venv/bin/python scripts/check_volume_terms.py --irpol target/release/irpol [--sets-per-combo 3]
        [--count 40] [--seed S]
    .venv/bin/python scripts/check_volume_terms.py --no-irpol          # the numpy checks alone

Numpy checks (printed with their worst value; each must pass):
1. the subsurface matrix product T(theta_r) [(1 - d) diag(1,0,0,0) + d M_mirror] T(theta_i), M_mirror a
   perfect mirror in the scattering plane's s/p frames, equals its written-out elements with
   C + iS = exp(i(2a - 2b)) from the frame rotations (3e-15 of m00, random azimuths: rounding); with N = 1 and
   d = 0 it is (rho_s/pi) diag(1, 0, 0, 0) (1e-15); its m00 is mirror-symmetric about the plane of
   incidence (phi_r -> 2 phi_i - phi_r, 1e-13), as pbrdf_volume_numpy.hemispherical_reflectance assumes;
2. Z's integrals Rbar, Abar (scipy quad) against Gauss-Legendre on panels split at the kink
   mu_c = sqrt(1 - Re eps), in s with mu = mu_c -+ s^2 (which removes the square root) (1e-13);
   Rbar(n = 1.5) = 0.0918 (the textbook diffuse reflectance of glass, 1e-4);
3. the internal facet's Fresnel coefficients satisfy Stokes' relations r'(theta_t) = -r(theta_i)
   for k = 0 (1e-12), and |r_s| = |r_p| = 1 beyond the critical angle;
4. reciprocity M(w_r -> w_i) = Q M(w_i -> w_r)^T Q: Q found among the eight diag(1, +-1, +-1, +-1) on
   today's external facet term (exactly one fits), then required of the internal facet term, the
   subsurface term and the full model (1e-12 of m00);
5. energy: the subsurface term's directional-hemispherical reflectance for d = 0 (quadrature over mu_r)
   equals its closed form rho_s (1 - R(theta_i)) (1e-10); for any d (2-D quadrature over mu_r and phi_r:
   C varies with phi_r, so there is no closed form) it is <= rho_s (1 - R(theta_i)) for unpolarized
   light and <= rho_s I_t for fully polarized incident states +-Q, +-U, +-V, I_t the first element of
   T(theta_i) S (1e-12); the full model's (facet + subsurface, rho_s = 1) is printed for information,
   by a product Gauss rule over the outgoing hemisphere;
6. realizability (Cloude): every full-model matrix of the random sets has coherency eigenvalues
   >= -1e-12 m00.
CLI check: random parameter sets, 2 distributions x {smith, none} x {external, internal} facets times
--sets-per-combo (sigma in [0.05, 0.5], q in [1.6, 4], n in [1.2, 2.5], k in [0, 0.5] with every
third set at k = 0 exactly, rho_s and d in [0, 1], rho_d 0 or in [0, 0.2]) plus two corner sets
(N = 1, d = 0; k = 0, d = 1, internal), --count random geometries each (theta_i, theta_r in
[0, 85] deg, phi_i and phi_r in [0, 360), a few at theta = 0 and in the plane), evaluated with
`irpol eval --facet F --rho-s X --d X ...`; all 16 elements must agree to 1e-9 of the row's m00.

Exit 0 when all pass, 1 on a failed check (with the worst rows), 2 on a setup problem (no irpol,
an irpol without the flags). Ends with `N passed, M failed`.
"""

from __future__ import annotations

import argparse
import csv
import io
import itertools
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pbrdf_numpy as pn  # noqa: E402
import pbrdf_volume_numpy as pv  # noqa: E402

GEOMETRY_COLUMNS = ["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg"]
MUELLER_COLUMNS = [f"m{i}{j}" for i in range(4) for j in range(4)]
TOL_CLI = 1e-9
# The product goes through a Jones mirror and mueller_from_jones, the elements through double angles of the
# same projections; each is ~1.2e-15 from a long-double evaluation (the projections' unit vectors are unit
# to rounding only), so the two agree to ~1.3e-15, not 1e-15.
TOL_ELEMENTS = 3e-15
TOL_RECIPROCITY = 1e-12
TOL_REALIZABLE = 1e-12
THETA_MAX_DEG = 85.0
M00_MIN = 1e-280


# The truths of tests/data/volume/ (scripts/make_volume_measurements.py).
DATA_SETS = {
    "external_subsurface": dict(distribution="cauchy", sigma=0.15, q=2.5, n=1.45, k=0.01, shadowing="smith",
                                facet="external", rho_s=0.8, d=0.2),
    "internal_subsurface": dict(distribution="gaussian", sigma=0.8, q=0.0, n=1.35, k=0.0, shadowing="smith",
                                facet="internal", rho_s=0.6, d=0.1),
}


class SetupError(RuntimeError):
    pass


class Results:
    """Collects named checks; each prints one line."""

    def __init__(self):
        self.passed = 0
        self.failed: list[str] = []

    def check(self, name: str, ok: bool, detail: str) -> None:
        print(f"{'ok  ' if ok else 'FAIL'} {name}: {detail}")
        if ok:
            self.passed += 1
        else:
            self.failed.append(name)


# ---------------------------------------------------------------------------------------------
# Random cases
# ---------------------------------------------------------------------------------------------


def draw_sets(rng: np.random.Generator, per_combo: int) -> list[dict]:
    sets = []
    for dist, shadowing, facet in itertools.product(pn.DISTRIBUTIONS, ("smith", "none"), pn.FACETS):
        for j in range(per_combo):
            sets.append(dict(
                distribution=dist, shadowing=shadowing, facet=facet,
                sigma=float(rng.uniform(0.05, 0.5)),
                q=float(rng.uniform(1.6, 4.0)) if dist == "cauchy" else 0.0,
                n=float(rng.uniform(1.2, 2.5)),
                k=0.0 if j % 3 == 2 else float(rng.uniform(0.0, 0.5)),
                rho_s=float(rng.uniform(0.0, 1.0)), d=float(rng.uniform(0.0, 1.0)),
                rho_d=0.0 if rng.uniform() < 0.5 else float(rng.uniform(0.0, 0.2)),
            ))
            # Every other set with a circular residual polarization of its own, realizable:
            # d_c in [2d - 1, 1].
            d = sets[-1]["d"]
            sets[-1]["d_c"] = float(rng.uniform(2.0 * d - 1.0, 1.0)) if j % 2 == 1 else None
    sets.append(dict(distribution="cauchy", shadowing="smith", facet="external", sigma=0.2, q=2.5, n=1.0, k=0.0,
                     rho_s=0.5, d=0.0, rho_d=0.0, d_c=None))
    sets.append(dict(distribution="gaussian", shadowing="smith", facet="internal", sigma=0.25, q=0.0, n=1.35,
                     k=0.0, rho_s=0.9, d=1.0, rho_d=0.0, d_c=None))
    sets.append(dict(distribution="cauchy", shadowing="smith", facet="internal", sigma=0.87, q=2.4, n=1.23,
                     k=0.075, rho_s=0.96, d=0.027, rho_d=0.0, d_c=-0.019))  # PTFE's fit
    return sets


def draw_geometries(rng: np.random.Generator, count: int) -> np.ndarray:
    """(count, 4) degrees; the first rows are theta_i = 0, theta_r = 0 and in-plane, the rest random."""
    g = np.column_stack([rng.uniform(0.0, THETA_MAX_DEG, count), rng.uniform(0.0, 360.0, count),
                         rng.uniform(0.0, THETA_MAX_DEG, count), rng.uniform(0.0, 360.0, count)])
    g[0, 0] = 0.0
    g[1, 2] = 0.0
    g[2, 3] = (g[2, 1] + 180.0) % 360.0
    g[3, 3] = g[3, 1]
    # 17 significant digits parse back to the same doubles irpol reads
    return np.array([[float(f"{x:.17g}") for x in row] for row in g])


def model(g: np.ndarray, p: dict) -> np.ndarray:
    return pv.mueller_brdf(g[:, 0], g[:, 1], g[:, 2], g[:, 3], **p)


def describe(p: dict) -> str:
    q = f" q={p['q']:.4g}" if p["distribution"] == "cauchy" else ""
    return (f"{p['distribution']} sigma={p['sigma']:.4g}{q} n={p['n']:.4g} k={p['k']:.4g} {p['shadowing']} "
            f"{p['facet']} rho_s={p['rho_s']:.4g} d={p['d']:.4g} rho_d={p['rho_d']:.4g}"
            + ("" if p.get("d_c") is None else f" d_c={p['d_c']:.4g}"))


# ---------------------------------------------------------------------------------------------
# Numpy checks
# ---------------------------------------------------------------------------------------------


def check_subsurface_algebra(res: Results, rng: np.random.Generator) -> None:
    worst = 0.0
    for _ in range(20):
        n, k, d = rng.uniform(0.6, 3.0), rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0)
        d_c = float(rng.uniform(2.0 * d - 1.0, 1.0))
        g = draw_geometries(rng, 200)
        a = pv.subsurface_mueller(*g.T, n=n, k=k, rho_s=0.8, d=d, d_c=d_c)
        b = pv.subsurface_elements(*g.T, n=n, k=k, rho_s=0.8, d=d, d_c=d_c)
        worst = max(worst, float((np.abs(a - b) / a[:, 0, 0][:, None, None]).max()))
    res.check("subsurface product = written-out elements", worst <= TOL_ELEMENTS, f"max |diff|/m00 = {worst:.2e}")
    g = draw_geometries(rng, 500)
    M = pv.subsurface_mueller(*g.T, n=1.0, k=0.0, rho_s=0.7, d=0.0)
    target = np.zeros((4, 4))
    target[0, 0] = 0.7 / math.pi
    e = float(np.abs(M - target).max() / target[0, 0])
    res.check("subsurface with N = 1, d = 0 is (rho_s/pi) diag(1,0,0,0)", e <= 1e-15, f"max |diff|/m00 = {e:.2e}")
    worst = 0.0
    for n, k, d in ((1.5, 0.0, 1.0), (1.45, 0.01, 0.2), (0.7, 0.2, 0.6), (2.5, 0.5, 1.0)):
        g = draw_geometries(rng, 500)
        mirrored = g.copy()
        mirrored[:, 3] = (2.0 * g[:, 1] - g[:, 3]) % 360.0
        a = pv.subsurface_mueller(*g.T, n=n, k=k, rho_s=1.0, d=d)[:, 0, 0]
        b = pv.subsurface_mueller(*mirrored.T, n=n, k=k, rho_s=1.0, d=d)[:, 0, 0]
        worst = max(worst, float((np.abs(a - b) / a).max()))
    res.check("subsurface m00 mirror-symmetric about the plane of incidence", worst <= 1e-13,
              f"max |diff|/m00 = {worst:.2e}")


def mu_panels(n: float, k: float, nodes: int = 200) -> tuple[np.ndarray, list]:
    """Weights and (mu, dmu/ds) panels over mu in [0, 1] split at the kink mu_c = sqrt(1 - Re eps), in s
    with mu = mu_c - mu_c s^2 and mu_c + (1 - mu_c) s^2, which makes the square root smooth in s."""
    eps = complex(n, k) ** 2
    mu_c = math.sqrt(1.0 - eps.real) if eps.real < 1.0 else 0.0
    s, w = pv.gauss_unit(nodes)
    panels = [(mu_c - mu_c * s * s, 2.0 * mu_c * s)] if mu_c > 0 else []
    panels.append((mu_c + (1.0 - mu_c) * s * s, 2.0 * (1.0 - mu_c) * s))
    return w, panels


def gauss_moments(n: float, k: float) -> tuple[float, float]:
    """Rbar, Abar by the split Gauss rule of mu_panels."""
    w, panels = mu_panels(n, k)
    r_bar = a_bar = 0.0
    for mu, jac in panels:
        R_s, R_p = pv.smooth_fresnel_rs_rp(mu, n, k)
        _tp, tm, _x = pv.transmission_parts(mu, n, k)
        r_bar += 2.0 * float(np.sum(w * jac * 0.5 * (R_s + R_p) * mu))
        a_bar += 2.0 * float(np.sum(w * jac * tm * mu))
    return r_bar, a_bar


def check_normalization(res: Results, rng: np.random.Generator) -> None:
    worst = 0.0
    cases = [(1.5, 0.0), (1.45, 0.01), (1.35, 0.0), (0.7, 0.2), (0.5, 0.0), (2.5, 0.5), (1.0, 0.0), (3.0, 1.0)]
    cases += [(float(rng.uniform(0.3, 3.0)), float(rng.uniform(0.0, 1.0))) for _ in range(20)]
    for n, k in cases:
        q_r, q_a = pv.hemispherical_moments(n, k)
        g_r, g_a = gauss_moments(n, k)
        worst = max(worst, abs(q_r - g_r), abs(q_a - g_a))
    res.check("Z integrals: scipy quad = split Gauss-Legendre", worst <= 1e-13, f"max |diff| = {worst:.2e}")
    r_glass = pv.hemispherical_moments(1.5, 0.0)[0]
    res.check("Rbar(n = 1.5) = 0.0918", abs(r_glass - 0.0918) < 1e-4, f"Rbar = {r_glass:.6f}")


def check_internal_fresnel(res: Results) -> None:
    worst = 0.0
    for n in (1.2, 1.35, 1.5, 2.5):
        ti = np.radians(np.linspace(0.0, 89.0, 90))
        tt = np.arcsin(np.sin(ti) / n)
        rs, rp = pn.fresnel(np.cos(ti), n, 0.0, "external")
        rs_int, rp_int = pn.fresnel(np.cos(tt), n, 0.0, "internal")
        worst = max(worst, float(np.abs(rs + rs_int).max()), float(np.abs(rp + rp_int).max()))
    res.check("internal facet: Stokes relations r'(theta_t) = -r(theta_i), k = 0", worst <= 1e-12,
              f"max |r' + r| = {worst:.2e}")
    beyond = np.cos(np.radians(np.linspace(48.0, 89.9, 50)))  # critical angle of n = 1.35 is 47.8 deg
    rs, rp = pn.fresnel(beyond, 1.35, 0.0, "internal")
    e = float(max(np.abs(np.abs(rs) - 1).max(), np.abs(np.abs(rp) - 1).max()))
    res.check("internal facet: total internal reflection beyond the critical angle", e <= 1e-14,
              f"max ||r| - 1| = {e:.2e}")


def reciprocity_residual(p: dict, g: np.ndarray, Q: np.ndarray, term) -> float:
    fwd = term(g, p)
    back = term(g[:, [2, 3, 0, 1]], p)
    res = np.abs(back - Q @ np.swapaxes(fwd, -1, -2) @ Q).max(axis=(1, 2))
    keep = fwd[:, 0, 0] >= M00_MIN  # a narrow lobe underflows to 0 far from specular
    return float((res[keep] / fwd[keep, 0, 0]).max())


def check_reciprocity(res: Results, rng: np.random.Generator, sets: list[dict]) -> None:
    g = draw_geometries(rng, 300)
    facet_only = lambda gg, p: model(gg, {**p, "rho_s": 0.0, "rho_d": 0.0})  # noqa: E731
    external = [{**p, "facet": "external"} for p in sets if p["n"] != 1.0]
    fits = []
    for signs in itertools.product((1.0, -1.0), repeat=3):
        Q = np.diag([1.0, *signs])
        r = max(reciprocity_residual(p, g, Q, facet_only) for p in external)
        print(f"     external facet term, Q = diag(1, {signs[0]:+.0f}, {signs[1]:+.0f}, {signs[2]:+.0f}): "
              f"max residual / m00 = {r:.2e}")
        if r <= TOL_RECIPROCITY:
            fits.append(Q)
    res.check("exactly one Q makes today's external facet term reciprocal", len(fits) == 1,
              f"{len(fits)} fit: " + ", ".join(str(np.diag(Q).astype(int).tolist()) for Q in fits))
    if len(fits) != 1:
        return
    Q = fits[0]
    internal = [{**p, "facet": "internal"} for p in sets if p["n"] != 1.0]
    r_int = max(reciprocity_residual(p, g, Q, facet_only) for p in internal)
    res.check("reciprocity of the internal facet term", r_int <= TOL_RECIPROCITY, f"max residual / m00 = {r_int:.2e}")
    subsurface = lambda gg, p: pv.subsurface_mueller(*gg.T, n=p["n"], k=p["k"], rho_s=1.0, d=p["d"],  # noqa: E731
                                                     d_c=p.get("d_c"))
    r_ss = max(reciprocity_residual(p, g, Q, subsurface) for p in sets)
    any_q = max(reciprocity_residual(p, g, np.diag([1.0, *s]), subsurface) for p in sets[:4]
                for s in itertools.product((1.0, -1.0), repeat=3))
    res.check("reciprocity of the subsurface term", r_ss <= TOL_RECIPROCITY,
              f"max residual / m00 = {r_ss:.2e} (with any of the eight Q: {any_q:.2e})")
    r_all = max(reciprocity_residual(p, g, Q, model) for p in sets)
    res.check("reciprocity of the full model", r_all <= TOL_RECIPROCITY, f"max residual / m00 = {r_all:.2e}")


PHI_NODES = 64
INCIDENT_STATES = {"unpolarized": (1.0, 0.0, 0.0, 0.0), "+Q": (1.0, 1.0, 0.0, 0.0), "-Q": (1.0, -1.0, 0.0, 0.0),
                   "+U": (1.0, 0.0, 1.0, 0.0), "-U": (1.0, 0.0, -1.0, 0.0), "+V": (1.0, 0.0, 0.0, 1.0),
                   "-V": (1.0, 0.0, 0.0, -1.0)}


def subsurface_albedo(theta_i_deg: float, n: float, k: float, rho_s: float, d: float,
                      phi_nodes: int = PHI_NODES) -> np.ndarray:
    """int (F_ss S)_0 cos(theta_r) dOmega_r for each of INCIDENT_STATES (phi_i = 0): the split Gauss rule
    of mu_panels in mu_r times the trapezoid rule (exact to rounding for a smooth periodic integrand)
    in phi_r over [0, 2 pi).  d = 0 makes m00 independent of phi_r, and the phi rule exact."""
    w, panels = mu_panels(n, k)
    phi = 2.0 * math.pi * np.arange(phi_nodes) / phi_nodes
    states = np.array(list(INCIDENT_STATES.values()))
    total = np.zeros(len(states))
    for mu, jac in panels:
        MU, PHI = np.meshgrid(np.clip(mu, 0.0, 1.0), phi, indexing="ij")
        theta_r = np.degrees(np.arccos(MU.ravel()))
        first_row = pv.subsurface_mueller(np.full_like(theta_r, theta_i_deg), 0.0, theta_r, np.degrees(PHI.ravel()),
                                          n=n, k=k, rho_s=rho_s, d=d)[:, 0, :]
        weights = (np.outer(w * jac * mu, np.full(phi_nodes, 2.0 * math.pi / phi_nodes))).ravel()
        total += (weights @ first_row) @ states.T
    return total


def check_energy(res: Results) -> None:
    worst_closed, worst_margin, worst_pol = 0.0, -1.0, (-1.0, "")
    states = np.array(list(INCIDENT_STATES.values()))
    for n, k, d in itertools.product((1.2, 1.45, 2.5, 0.7), (0.0, 0.1, 0.5), (0.0, 0.2, 0.6, 1.0)):
        for ti in (0.0, 30.0, 60.0, 80.0, 89.0):
            alb = subsurface_albedo(ti, n, k, 1.0, d)
            T_i = pv.transmission_mueller(np.array([math.cos(math.radians(ti))]), n, k)[0]
            i_t = states @ T_i[0]  # first element of T(theta_i) S; unpolarized: T+ = 1 - R(theta_i)
            if d == 0.0:
                worst_closed = max(worst_closed, abs(alb[0] - i_t[0]))
            worst_margin = max(worst_margin, alb[0] - i_t[0])
            for name, a, b in zip(list(INCIDENT_STATES)[1:], alb[1:], i_t[1:]):
                if a - b > worst_pol[0]:
                    worst_pol = (a - b, f"{name}, n={n} k={k} d={d} theta_i={ti:g}: albedo {a:.6f}, I_t {b:.6f}")
    res.check("subsurface albedo, d = 0: closed form rho_s (1 - R(theta_i))", worst_closed <= 1e-10,
              f"max |diff| = {worst_closed:.2e}")
    res.check("subsurface albedo <= rho_s (1 - R(theta_i)), 2-D quadrature", worst_margin <= 1e-12,
              f"max of albedo - rho_s (1 - R(theta_i)) = {worst_margin:.2e} (rho_s = 1; n, k, d, theta_i grid)")
    res.check("subsurface albedo <= rho_s I_t for incident +-Q, +-U, +-V", worst_pol[0] <= 1e-12,
              f"max of albedo - rho_s I_t = {worst_pol[0]:.2e} ({worst_pol[1]})")
    for facet in pn.FACETS:
        worst = (0.0, "")
        for dist, sigma, n, rho_s in itertools.product(pn.DISTRIBUTIONS, (0.15, 0.4), (1.2, 1.5, 2.5), (0.0, 1.0)):
            p = dict(distribution=dist, sigma=sigma, q=2.5 if dist == "cauchy" else 0.0, n=n, k=0.0,
                     shadowing="smith", facet=facet, rho_s=rho_s, d=0.0)
            for ti in (0.0, 40.0, 70.0, 85.0):
                a = pv.hemispherical_reflectance(ti, p)
                if a > worst[0]:
                    worst = (a, f"{dist} sigma={sigma} n={n} rho_s={rho_s} theta_i={ti:g}")
        print(f"     info: largest hemispherical reflectance, {facet} facets + subsurface (Smith, k = 0, "
              f"rho_s in {{0, 1}}): {worst[0]:.4f} ({worst[1]})")
    for name, p in DATA_SETS.items():
        albedo = [pv.hemispherical_reflectance(ti, p) for ti in (0.0, 20.0, 40.0, 60.0, 80.0)]
        print(f"     info: hemispherical reflectance of {name} at theta_i = 0, 20, 40, 60, 80: "
              + ", ".join(f"{a:.4f}" for a in albedo))


def check_realizable(res: Results, rng: np.random.Generator, sets: list[dict]) -> None:
    worst, where = math.inf, ""
    for p in sets:
        g = draw_geometries(rng, 200)
        M = model(g, p)
        lam = pv.coherency_eigenvalues(M).min(axis=-1) / M[:, 0, 0]
        if lam.min() < worst:
            worst, where = float(lam.min()), describe(p)
    res.check("Cloude: coherency eigenvalues >= 0 (full model, random sets)", worst >= -TOL_REALIZABLE,
              f"min eigenvalue / m00 = {worst:.2e} ({where})")


# ---------------------------------------------------------------------------------------------
# irpol eval
# ---------------------------------------------------------------------------------------------


def eval_flags(p: dict) -> list[str]:
    f = [f"{x:.17g}" for x in (p["sigma"], p["n"], p["k"], p["rho_d"], p["rho_s"], p["d"])]
    cmd = ["--distribution", p["distribution"], "--sigma", f[0]]
    if p["distribution"] == "cauchy":
        cmd += ["--q", f"{p['q']:.17g}"]
    cmd += ["--n", f[1], "--k", f[2], "--rho", f[3], "--shadowing", p["shadowing"], "--facet", p["facet"],
            "--rho-s", f[4], "--d", f[5]]
    if p.get("d_c") is not None:
        cmd += ["--d-c", f"{p['d_c']:.17g}"]
    return cmd


def run_eval(irpol: str, p: dict, geometry_csv: str) -> np.ndarray:
    cmd = [irpol, "eval", *eval_flags(p), "--geometry", geometry_csv]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        raise SetupError(f"`{' '.join(cmd)}` exited {proc.returncode}: {proc.stderr.strip()}")
    lines = [ln for ln in proc.stdout.splitlines() if ln.strip() and not ln.startswith("#")]
    reader = csv.DictReader(io.StringIO("\n".join(lines)))
    missing = [c for c in GEOMETRY_COLUMNS + MUELLER_COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise SetupError(f"`{' '.join(cmd)}`: output lacks columns {missing}")
    return np.array([[float(r[c]) for c in GEOMETRY_COLUMNS + MUELLER_COLUMNS] for r in reader]).reshape(-1, 20)


def require_flags(irpol: str) -> None:
    try:
        help_text = subprocess.run([irpol, "eval", "--help"], capture_output=True, text=True, timeout=60).stdout
    except OSError as e:
        raise SetupError(f"cannot run {irpol}: {e}") from e
    lacking = [f for f in ("--facet", "--rho-s", "--d", "--d-c") if f not in help_text.split()]
    if lacking:
        raise SetupError(f"{irpol} eval has no {', '.join(lacking)} (build a version with the §1.10 terms)")


def check_cli(res: Results, irpol: str, rng: np.random.Generator, sets: list[dict], count: int) -> None:
    require_flags(irpol)
    workdir = tempfile.mkdtemp(prefix="irpol_volume_")
    worst, where, compared, bad = 0.0, "", 0, []
    for si, p in enumerate(sets):
        g = draw_geometries(rng, count)
        ref = model(g, p)
        keep = ref[:, 0, 0] >= M00_MIN
        g, ref = g[keep], ref[keep]
        path = os.path.join(workdir, f"geometry_{si}.csv")
        with open(path, "w") as f:
            f.write(",".join(GEOMETRY_COLUMNS) + "\n")
            f.writelines(",".join(f"{x:.17g}" for x in row) + "\n" for row in g)
        out = run_eval(irpol, p, path)
        if out.shape[0] != len(g) or not np.array_equal(out[:, :4], g):
            bad.append(f"{describe(p)}: rows or geometries echoed differently ({path})")
            continue
        err = np.abs(out[:, 4:].reshape(-1, 4, 4) - ref) / ref[:, 0, 0][:, None, None]
        compared += len(g)
        r, i, j = np.unravel_index(int(np.argmax(err)), err.shape)
        if err[r, i, j] > worst:
            worst = float(err[r, i, j])
            where = (f"m{i}{j} at (theta_i, phi_i, theta_r, phi_r) = ({', '.join(f'{x:.6g}' for x in g[r])}), "
                     f"{describe(p)}: irpol {out[r, 4 + 4 * i + j]:.17g}, numpy {ref[r, i, j]:.17g}")
        if err.max() > TOL_CLI:
            bad.append(f"{describe(p)}: {int((err > TOL_CLI).sum())} elements beyond {TOL_CLI:g} m00")
    for b in bad[:20]:
        print("     MISMATCH:", b)
    res.check(f"irpol eval = numpy, {compared} geometries in {len(sets)} parameter sets", not bad,
              f"max |irpol - numpy| / m00 = {worst:.2e}" + (f"; worst {where}" if where else ""))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    who = ap.add_mutually_exclusive_group(required=True)
    who.add_argument("--irpol", help="path to the irpol binary")
    who.add_argument("--no-irpol", action="store_true", help="only the numpy checks")
    ap.add_argument("--sets-per-combo", type=int, default=3)
    ap.add_argument("--count", type=int, default=40, help="geometries per parameter set")
    ap.add_argument("--seed", type=int, default=None, help="default: from the clock (printed)")
    args = ap.parse_args(argv)
    seed = args.seed if args.seed is not None else int(time.time())
    print(f"check_volume_terms: seed {seed}")
    rng = np.random.default_rng(seed)
    sets = draw_sets(rng, args.sets_per_combo)
    res = Results()
    t0 = time.time()
    check_subsurface_algebra(res, rng)
    check_normalization(res, rng)
    check_internal_fresnel(res)
    check_reciprocity(res, rng, sets)
    check_energy(res)
    check_realizable(res, rng, sets)
    if args.irpol:
        try:
            check_cli(res, args.irpol, rng, sets, args.count)
        except (SetupError, subprocess.TimeoutExpired) as e:
            print(f"error: {e}", file=sys.stderr)
            print(f"{res.passed} passed, {len(res.failed)} failed (setup error)")
            return 2
    print(f"({time.time() - t0:.1f} s)")
    print(f"{res.passed} passed, {len(res.failed)} failed")
    return 1 if res.failed else 0


if __name__ == "__main__":
    sys.exit(main())
