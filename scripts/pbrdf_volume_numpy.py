"""Independent numpy form of the model terms of docs/design.md §1.10: the facet term on either side of the
interface and the polarized subsurface term, added to the facet term of pbrdf_numpy.py.

    F = F_facet(facet side) + rho_d/pi diag(1,0,0,0) + F_ss

    F_ss(w_i -> w_r) = rho_s / (pi Z) * T(theta_r) D T(theta_i)        (psps frames, macro normal z)

* T(theta): smooth-interface Fresnel transmission Mueller matrix at cos(theta), eps = N^2 (air ->
  material): R_s = |r_s|^2, R_p = |r_p|^2, t_s = 1 - R_s, t_p = 1 - R_p, T+- = (t_s +- t_p)/2,
  X = sqrt(t_s t_p), T = [[T+, T-, 0, 0], [T-, T+, 0, 0], [0, 0, X, 0], [0, 0, 0, X]].
  In the psps frames of docs/design.md §1.3 the plane of incidence of the macro surface is the
  global frame's own s/p plane, so T needs no rotation.
* D = diag(1, d, -d, -d), d in [0, 1] the residual polarization after volume scattering.
* Z = (1 - Rbar) + |d| |Abar|, Rbar = 2 int_0^1 R(mu) mu dmu (R = (R_s + R_p)/2),
  Abar = 2 int_0^1 T-(mu) mu dmu, both by adaptive quadrature to ~1e-14 with a break point at the
  square-root kink mu_c = sqrt(1 - Re eps) when Re eps < 1.

Written from docs/design.md and the formulas of the model's specification, not from the Rust code.
The internal facet is pbrdf_numpy.mueller_brdf(..., facet="internal") (eps = 1/N^2).
scripts/check_volume_terms.py compares this module with `irpol eval` and checks reciprocity,
energy and realizability; scripts/make_volume_measurements.py writes synthetic data with it.
"""

from __future__ import annotations

import math
import os
import sys
from functools import lru_cache

import numpy as np
from scipy import integrate

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pbrdf_numpy as pn  # noqa: E402

QUAD_EPSABS = 1e-14
QUAD_EPSREL = 1e-13


def smooth_fresnel_rs_rp(cos_theta, n, k):
    """|r_s|^2, |r_p|^2 of a smooth air -> material interface (eps = N^2) at cos(theta)."""
    r_s, r_p = pn.fresnel(np.asarray(cos_theta, dtype=float), n, k, "external")
    return np.abs(r_s) ** 2, np.abs(r_p) ** 2


def transmission_parts(cos_theta, n, k):
    """(T+, T-, X) of the transmission Mueller matrix at cos(theta).  At grazing incidence R rounds to
    1 + 1e-16 at worst; X takes the root of max(t_s t_p, 0) there."""
    R_s, R_p = smooth_fresnel_rs_rp(cos_theta, n, k)
    t_s, t_p = 1.0 - R_s, 1.0 - R_p
    return 0.5 * (t_s + t_p), 0.5 * (t_s - t_p), np.sqrt(np.maximum(t_s * t_p, 0.0))


def transmission_mueller(cos_theta, n, k):
    """T(theta) (..., 4, 4)."""
    tp, tm, x = transmission_parts(cos_theta, n, k)
    T = np.zeros(np.shape(tp) + (4, 4))
    T[..., 0, 0] = T[..., 1, 1] = tp
    T[..., 0, 1] = T[..., 1, 0] = tm
    T[..., 2, 2] = T[..., 3, 3] = x
    return T


@lru_cache(maxsize=4096)
def hemispherical_moments(n: float, k: float) -> tuple[float, float]:
    """(Rbar, Abar) = (2 int R mu dmu, 2 int T- mu dmu) over mu in [0, 1]."""
    eps = complex(n, k) ** 2
    points = [math.sqrt(1.0 - eps.real)] if eps.real < 1.0 else None

    def quad(f):
        val, _err = integrate.quad(f, 0.0, 1.0, epsabs=QUAD_EPSABS, epsrel=QUAD_EPSREL, limit=200,
                                   points=points)
        return 2.0 * val

    def r_mean(mu):
        R_s, R_p = smooth_fresnel_rs_rp(np.array([mu]), n, k)
        return float(0.5 * (R_s[0] + R_p[0])) * mu

    def t_minus(mu):
        _tp, tm, _x = transmission_parts(np.array([mu]), n, k)
        return float(tm[0]) * mu

    return quad(r_mean), quad(t_minus)


def normalization(n: float, k: float, d: float) -> float:
    """Z = (1 - Rbar) + |d| |Abar|."""
    r_bar, a_bar = hemispherical_moments(float(n), float(k))
    return (1.0 - r_bar) + abs(d) * abs(a_bar)


def subsurface_mueller(theta_i_deg, theta_r_deg, *, n, k, rho_s, d):
    """F_ss (N, 4, 4) in sr^-1; depends on the zenith angles only (azimuths enter through the frames,
    which are the macro surface's own)."""
    ti = np.radians(np.atleast_1d(np.asarray(theta_i_deg, dtype=float)))
    tr = np.radians(np.atleast_1d(np.asarray(theta_r_deg, dtype=float)))
    ti, tr = np.broadcast_arrays(ti, tr)
    K = rho_s / (math.pi * normalization(n, k, d))
    D = np.diag([1.0, d, -d, -d])
    return K * (transmission_mueller(np.cos(tr), n, k) @ D @ transmission_mueller(np.cos(ti), n, k))


def subsurface_elements(theta_i_deg, theta_r_deg, *, n, k, rho_s, d):
    """The same matrix from its written-out elements (the specification's check of the product)."""
    ti = np.radians(np.atleast_1d(np.asarray(theta_i_deg, dtype=float)))
    tr = np.radians(np.atleast_1d(np.asarray(theta_r_deg, dtype=float)))
    ti, tr = np.broadcast_arrays(ti, tr)
    pi_, mi, xi = transmission_parts(np.cos(ti), n, k)
    pr, mr, xr = transmission_parts(np.cos(tr), n, k)
    K = rho_s / (math.pi * normalization(n, k, d))
    M = np.zeros(ti.shape + (4, 4))
    M[..., 0, 0] = (pr * pi_ + d * mr * mi) * K
    M[..., 0, 1] = (pr * mi + d * mr * pi_) * K
    M[..., 1, 0] = (mr * pi_ + d * pr * mi) * K
    M[..., 1, 1] = (mr * mi + d * pr * pi_) * K
    M[..., 2, 2] = M[..., 3, 3] = -d * xr * xi * K
    return M


def mueller_brdf(theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg, *, distribution, sigma, q=0.0, n, k,
                 shadowing="none", rho_d=0.0, facet="external", rho_s=0.0, d=0.0):
    """Facet term on the given side + rho_d/pi diag(1,0,0,0) + subsurface term, (N, 4, 4) sr^-1."""
    M = pn.mueller_brdf(theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg, distribution=distribution,
                        sigma=sigma, q=q, n=n, k=k, shadowing=shadowing, rho_d=rho_d, facet=facet)
    if rho_s != 0.0:
        ti, _, tr, _ = np.broadcast_arrays(*(np.atleast_1d(np.asarray(x, dtype=float))
                                             for x in (theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg)))
        M = M + subsurface_mueller(ti, tr, n=n, k=k, rho_s=rho_s, d=d)
    return M


def coherency_eigenvalues(M):
    """Eigenvalues (..., 4) of the Hermitian coherency (Choi) matrix of Mueller matrices M (..., 4, 4),
    in the Stokes convention of pbrdf_numpy.mueller_from_jones: M = A (J kron J*) A^-1, so
    A^-1 M A = sum_k J_k kron J_k*, whose reshuffle sum_k vec(J_k) vec(J_k)^H is positive
    semidefinite exactly when M is a sum of non-depolarizing (Jones) Mueller matrices (Cloude)."""
    A = np.array([[1, 0, 0, 1], [1, 0, 0, -1], [0, 1, 1, 0], [0, 1j, -1j, 0]], dtype=complex)
    N = np.linalg.inv(A) @ np.asarray(M, dtype=complex) @ A
    # N[(a c), (b d)] = sum J_ab J*_cd  ->  C[(a b), (c d)]
    C = N.reshape(N.shape[:-2] + (2, 2, 2, 2)).swapaxes(-3, -2).reshape(N.shape[:-2] + (4, 4))
    C = 0.5 * (C + np.conj(np.swapaxes(C, -1, -2)))
    return np.linalg.eigvalsh(C)


@lru_cache(maxsize=8)
def gauss_unit(nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    return 0.5 * (x + 1.0), 0.5 * w


def hemispherical_reflectance(theta_i_deg: float, params: dict, nodes: int = 96) -> float:
    """int F_00 cos(theta_r) dOmega_r of the full model: Gauss-Legendre in mu_r and in phi_r over [0, pi]
    (the model is mirror-symmetric about the plane of incidence).  For sigma >= 0.15 it agrees with
    300 nodes to ~1e-4 (the internal facet's kink at the critical angle is the slowest part)."""
    mu, wm = gauss_unit(nodes)
    phi, wp = math.pi * mu, math.pi * wm
    MU, PHI = np.meshgrid(mu, phi, indexing="ij")
    W = np.outer(wm, wp) * 2.0
    tr = np.degrees(np.arccos(MU.ravel()))
    m00 = mueller_brdf(np.full_like(tr, theta_i_deg), 0.0, tr, np.degrees(PHI.ravel()), **params)[:, 0, 0]
    return float(np.sum(W.ravel() * m00 * MU.ravel()))
