"""Independent numpy form of the model terms of docs/design.md §1.10: the facet term on either side of the
interface and the polarized subsurface term, added to the facet term of pbrdf_numpy.py.

    F = F_facet(facet side) + rho_d/pi diag(1,0,0,0) + F_ss

    F_ss(w_i -> w_r) = rho_s / (pi Z) * T(theta_r) D_plane T(theta_i)        (psps frames, macro normal z)

* T(theta): smooth-interface Fresnel transmission Mueller matrix at cos(theta), eps = N^2 (air ->
  material): R_s = |r_s|^2, R_p = |r_p|^2, t_s = 1 - R_s, t_p = 1 - R_p, T+- = (t_s +- t_p)/2,
  X = sqrt(t_s t_p), T = [[T+, T-, 0, 0], [T-, T+, 0, 0], [0, 0, X, 0], [0, 0, 0, X]].
  In the psps frames of docs/design.md §1.3 the plane of incidence of the macro surface is the
  global frame's own s/p plane, so T needs no rotation.
* D_plane: the residual polarization d in [0, 1] left after volume scattering, referred to the
  SCATTERING PLANE (the plane of w_i and w_r), not to the macro surface.  Built here as a mixture
      D_plane = (1 - d) diag(1, 0, 0, 0) + d M_mirror,
      M_mirror = mueller_from_jones(out_proj @ diag(1, -1) @ in_proj),
  a perfect mirror in the facet term's local frames (s_loc = unit(h x k_in), the normal of the
  scattering plane; pbrdf_numpy.facet_frame_projections): Jones diag(r_s, r_p) = diag(1, -1), whose
  Mueller matrix in those frames is diag(1, 1, -1, -1) (m22 = Re(r_s* r_p) = -1 in pbrdf_numpy's
  convention, the sign a metal's r_s -> -1, r_p -> +1 gives up to a global phase).  The rotations
  leave diag(1,0,0,0) alone, so D_plane = L_out diag(1, d, -d, -d) L_in, the old diagonal D turned
  from the psps frames into the scattering plane's.  Written out (subsurface_elements), with
  C + iS = exp(i(2a - 2b)), a, b the rotation angles of in_proj, out_proj = [[cos, sin], [-sin, cos]]:
      D_plane = [[1, 0, 0, 0], [0, dC, dS, 0], [0, dS, -dC, 0], [0, 0, 0, -d]].
  A circular residual polarization of its own, d_c (D's m33 = -d_c; realizable for
  2d - 1 <= d_c <= 1), adds (d - d_c) diag(0, 0, 0, 1), which the rotations leave alone.
  The term now depends on the azimuths too (at normal incidence C + iS follows 2(phi_r - phi_i)).
* Z = (1 - Rbar) + |d| |Abar|, Rbar = 2 int_0^1 R(mu) mu dmu (R = (R_s + R_p)/2),
  Abar = 2 int_0^1 T-(mu) mu dmu, both by adaptive quadrature to ~1e-14 with a break point at the
  square-root kink mu_c = sqrt(1 - Re eps) when Re eps < 1.  For d = 0 the directional-hemispherical
  reflectance is rho_s (1 - R(theta_i)) exactly; for d > 0 it is at most rho_s I_t, I_t the intensity
  after the interface, since |C| <= 1 (no closed form: C varies with phi_r).

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


def _radians(*angles_deg):
    return np.broadcast_arrays(*(np.radians(np.atleast_1d(np.asarray(x, dtype=float))) for x in angles_deg))


def scattering_plane_mirror(ti, pi_, tr, pr):
    """M_mirror (..., 4, 4): a perfect mirror, Jones diag(1, -1) in the facet-local s/p frames of the
    scattering plane, seen in the psps frames (angles in radians)."""
    _h, _cos_b, out_proj, in_proj = pn.facet_frame_projections(ti, pi_, tr, pr)
    J = out_proj @ (np.array([1.0, -1.0])[:, None] * in_proj)
    return pn.mueller_from_jones(J.astype(complex))


def scattering_plane_cos_sin(ti, pi_, tr, pr):
    """(C, S) = cos, sin of 2a - 2b, a and b the angles of the rotations in_proj, out_proj =
    [[cos, sin], [-sin, cos]] (angles in radians): by double angles from their first rows."""
    _h, _cos_b, out_proj, in_proj = pn.facet_frame_projections(ti, pi_, tr, pr)
    ca, sa = in_proj[..., 0, 0], in_proj[..., 0, 1]
    cb, sb = out_proj[..., 0, 0], out_proj[..., 0, 1]
    c2a, s2a = ca * ca - sa * sa, 2.0 * ca * sa
    c2b, s2b = cb * cb - sb * sb, 2.0 * cb * sb
    return c2a * c2b + s2a * s2b, s2a * c2b - c2a * s2b


def subsurface_mueller(theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg, *, n, k, rho_s, d, d_c=None):
    """F_ss (N, 4, 4) in sr^-1: rho_s/(pi Z) T(theta_r) [(1 - d) diag(1,0,0,0) + d M_mirror
    + (d - d_c) diag(0,0,0,1)] T(theta_i); d_c None means d_c = d.  The last part sets D's m33 to
    -d_c; the frame rotations leave the circular component alone, so it needs no rotation."""
    ti, pi_, tr, pr = _radians(theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg)
    circular = d if d_c is None else d_c
    K = rho_s / (math.pi * normalization(n, k, d))
    depolarizer = np.zeros(ti.shape + (4, 4))
    depolarizer[..., 0, 0] = 1.0
    helicity = np.zeros(ti.shape + (4, 4))
    helicity[..., 3, 3] = 1.0
    D = ((1.0 - d) * depolarizer + d * scattering_plane_mirror(ti, pi_, tr, pr)
         + (d - circular) * helicity)
    return K * (transmission_mueller(np.cos(tr), n, k) @ D @ transmission_mueller(np.cos(ti), n, k))


def subsurface_elements(theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg, *, n, k, rho_s, d, d_c=None):
    """The same matrix from its written-out elements (the specification's check of the product)."""
    ti, pi_, tr, pr = _radians(theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg)
    C, S = scattering_plane_cos_sin(ti, pi_, tr, pr)
    pi_i, mi, xi = transmission_parts(np.cos(ti), n, k)
    pr_, mr, xr = transmission_parts(np.cos(tr), n, k)
    K = rho_s / (math.pi * normalization(n, k, d))
    dC, dS = d * C, d * S
    M = np.zeros(ti.shape + (4, 4))
    M[..., 0, 0] = K * (pr_ * pi_i + dC * mr * mi)
    M[..., 0, 1] = K * (pr_ * mi + dC * mr * pi_i)
    M[..., 0, 2] = K * dS * mr * xi
    M[..., 1, 0] = K * (mr * pi_i + dC * pr_ * mi)
    M[..., 1, 1] = K * (mr * mi + dC * pr_ * pi_i)
    M[..., 1, 2] = K * dS * pr_ * xi
    M[..., 2, 0] = K * dS * xr * mi
    M[..., 2, 1] = K * dS * xr * pi_i
    M[..., 2, 2] = -K * dC * xr * xi
    M[..., 3, 3] = -K * (d if d_c is None else d_c) * xr * xi
    return M


def mueller_brdf(theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg, *, distribution, sigma, q=0.0, n, k,
                 shadowing="none", rho_d=0.0, facet="external", rho_s=0.0, d=0.0, d_c=None):
    """Facet term on the given side + rho_d/pi diag(1,0,0,0) + subsurface term, (N, 4, 4) sr^-1."""
    M = pn.mueller_brdf(theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg, distribution=distribution,
                        sigma=sigma, q=q, n=n, k=k, shadowing=shadowing, rho_d=rho_d, facet=facet)
    if rho_s != 0.0:
        M = M + subsurface_mueller(theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg, n=n, k=k, rho_s=rho_s, d=d,
                                   d_c=d_c)
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
