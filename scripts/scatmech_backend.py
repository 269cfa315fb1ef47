"""NIST SCATMECH (PyPI `pyscatmech`) as the independent reference for the irpol pBRDF model.

Maps the irpol model of docs/design.md §1.3 onto SCATMECH's `Shadowed_Facet_BRDF_Model`:

* geometry: irpol uses global spherical angles with directions pointing away from the surface
  (specular at phi_r = phi_i + 180°).  SCATMECH puts the source in the x-z plane and measures the
  viewer azimuth from the specular direction, in radians, so
  thetai = theta_i, thetas = theta_r, phis = phi_r - phi_i - 180° (docs/design.md §1.3).  Mueller matrices are
  requested in SCATMECH's "psps" frames, which are rotation invariant about z, so the irpol value at
  any phi_i equals SCATMECH's at the relative azimuth.
* slope distribution: Cauchy/Student-t as a `Table_Slope_Distribution_Function` whose table is the
  slope-space density of docs/design.md §1.2 written as a SCATMECH formula string; Gaussian as SCATMECH's
  native `Gaussian_Slope_Distribution_Function` with s = sqrt(2) sigma (its density is
  exp(-(m/s)^2)/(pi s^2)).
* shadowing: none -> `Unit_Shadow_Function`; torrance-sparrow -> `Torrance_Sparrow_Shadow_Function`;
  smith -> `Table_Shadow_Function`, which SCATMECH evaluates as T(theta_i) T(theta_s), with T a
  two-column table file of (theta [rad], G1).  SCATMECH's own `Smith_Shadow_Function` is NOT used: it
  is Smith's 1967 form with an extra factor (1 - erfc(mu/(sqrt2 w))/2) and only for the Gaussian; it is
  not the G1 = 1/(1+Lambda) of docs/design.md §1.3.
  G1 is computed here by quadrature of Smith's definition
  Lambda(mu) = (1/mu) int_mu^inf (m - mu) p1(m) dm with p1 the one-dimensional marginal slope density
  (not with the closed forms of docs/design.md §1.3, which the numpy port uses), and the table holds the exact
  evaluation angles as nodes, so SCATMECH's linear table interpolation returns node values and adds no
  error (`scatmech_reference.py --measure-table-interpolation` shows what a plain grid would cost).
"""

from __future__ import annotations

import math
import os
import tempfile
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import integrate, special

from pySCATMECH.brdf import BRDF_Model

DISTRIBUTIONS = ("cauchy", "gaussian")
SHADOWINGS = ("none", "torrance-sparrow", "smith")
MUELLER_COLUMNS = [f"m{i}{j}" for i in range(4) for j in range(4)]

_SHADOW_CLASS = {
    "none": "Unit_Shadow_Function",
    "torrance-sparrow": "Torrance_Sparrow_Shadow_Function",
    "smith": "Table_Shadow_Function",
}


def fmt(x: float) -> str:
    """17 significant digits: round-trips a double exactly through text."""
    return f"{x:.17g}"


@dataclass(frozen=True)
class SurfaceParams:
    """One irpol surface model (docs/design.md §1.3) without the diffuse term."""

    distribution: str
    sigma: float
    q: float  # ignored for the Gaussian
    n: float
    k: float
    shadowing: str
    wavelength_um: float = 10.0

    def validate(self) -> None:
        if self.distribution not in DISTRIBUTIONS:
            raise ValueError(f"unknown distribution {self.distribution!r}")
        if self.shadowing not in SHADOWINGS:
            raise ValueError(f"unknown shadowing {self.shadowing!r}")
        if not self.sigma > 0:
            raise ValueError(f"sigma must be > 0, got {self.sigma}")
        if self.distribution == "cauchy":
            if not self.q > 1:
                raise ValueError(f"Cauchy needs q > 1, got {self.q}")
            if self.shadowing == "smith" and not self.q > 1.5:
                raise ValueError(f"Smith shadowing for Cauchy needs q > 3/2, got {self.q}")


def cauchy_slope_formula(sigma: float, q: float) -> str:
    """SCATMECH formula string for p(m) = (q-1) a^(q-1) / (pi (m^2+a)^q), a = 2 sigma^2 (docs/design.md §1.2).

    SCATMECH's evaluator has no `pi` and evaluates ^ left to right, so everything is parenthesized
    and the numbers are substituted with 17 significant digits."""
    a = 2.0 * sigma * sigma
    return (
        f"@x:({fmt(q - 1.0)})*({fmt(a)})^({fmt(q - 1.0)})"
        f"/(3.141592653589793*((x^2)+({fmt(a)}))^({fmt(q)}))"
    )


# ---------------------------------------------------------------------------------------------
# Smith G1 by quadrature of the definition (independent of the closed forms in docs/design.md §1.3)
# ---------------------------------------------------------------------------------------------


def marginal_slope_density(m: float, distribution: str, sigma: float, q: float) -> float:
    """One-dimensional marginal p1(m) = int p(m, y) dy of the isotropic slope density.

    Cauchy: int (m^2 + a + y^2)^-q dy = sqrt(pi) Gamma(q-1/2)/Gamma(q) (m^2+a)^(1/2-q), hence
    p1 = Gamma(q-1/2) / (sqrt(pi) Gamma(q-1)) a^(q-1) (m^2+a)^(1/2-q)  (checked against a 2-D
    quadrature in `pbrdf_numpy.py --self-test`).  Gaussian: the normal density of std sigma."""
    if distribution == "gaussian":
        return math.exp(-m * m / (2.0 * sigma * sigma)) / (math.sqrt(2.0 * math.pi) * sigma)
    a = 2.0 * sigma * sigma
    log_c = special.gammaln(q - 0.5) - special.gammaln(q - 1.0) - 0.5 * math.log(math.pi)
    return math.exp(log_c + (q - 1.0) * math.log(a) + (0.5 - q) * math.log(m * m + a))


def smith_lambda_quadrature(theta: float, distribution: str, sigma: float, q: float) -> float:
    """Smith's Lambda(mu), mu = cot(theta): (1/mu) int_mu^inf (m - mu) p1(m) dm, by adaptive quadrature."""
    if theta <= 0.0:
        return 0.0
    mu = math.cos(theta) / math.sin(theta)
    if distribution == "gaussian":
        # t = m - mu; the integrand decays like exp(-mu t / sigma^2) beyond the peak.
        scale = sigma * min(1.0, sigma / mu)

        def integrand(t: float) -> float:
            return t * marginal_slope_density(mu + t, distribution, sigma, q)

        knots = [0.0, scale, 4.0 * scale, 16.0 * scale, 64.0 * scale, np.inf]
    else:
        # m = sqrt(a) sinh(u) turns the algebraic tail (m - mu) m^(1-2q) into exp((3-2q) u), which
        # QUADPACK integrates reliably on a finite range; the range stops where the tail is e^-60.
        a = 2.0 * sigma * sigma
        ra = math.sqrt(a)
        log_c = special.gammaln(q - 0.5) - special.gammaln(q - 1.0) - 0.5 * math.log(math.pi)
        u0 = math.asinh(mu / ra)

        def integrand(u: float) -> float:
            log_cosh = u + math.log1p(math.exp(-2.0 * u)) - math.log(2.0)
            return (ra * math.sinh(u) - mu) * math.exp(log_c + (2.0 - 2.0 * q) * log_cosh)

        length = 60.0 / (2.0 * q - 3.0)
        knots = [u0 + x for x in (0.0, 0.25, 1.0, 3.0, *np.arange(10.0, length, 10.0), length)]

    # QUADPACK may warn that it cannot reach epsrel = 2e-14 (near the double-precision floor); its
    # error estimate is checked instead: G1 = 1/(1+Lambda) needs Lambda to 1e-12 absolute.
    total = 0.0
    error = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        for lo, hi in zip(knots[:-1], knots[1:]):
            value, err = integrate.quad(integrand, lo, hi, epsabs=0.0, epsrel=2e-14, limit=400)
            total += value
            error += err
    if error / mu > 1e-12 * (1.0 + total / mu):
        raise RuntimeError(
            f"Smith Lambda quadrature did not converge: theta={theta}, {distribution}, sigma={sigma}, "
            f"q={q}: estimate {total} +- {error}"
        )
    return total / mu


def smith_g1_quadrature(theta: float, distribution: str, sigma: float, q: float) -> float:
    return 1.0 / (1.0 + smith_lambda_quadrature(theta, distribution, sigma, q))


class SmithTable:
    """Table file of (theta [rad], G1) for SCATMECH's `Table_Shadow_Function`.

    SCATMECH caches table files by file name for the life of the process, so every table gets a
    fresh, unique name."""

    _counter = 0

    def __init__(self, params: SurfaceParams, directory: str):
        self.params = params
        self.directory = directory
        self.cache: dict[float, float] = {}

    def g1(self, theta: float) -> float:
        if theta not in self.cache:
            p = self.params
            self.cache[theta] = smith_g1_quadrature(theta, p.distribution, p.sigma, p.q)
        return self.cache[theta]

    def write(self, nodes: np.ndarray) -> str:
        """Write a table whose nodes are exactly `nodes` (plus theta = 0 and pi/2 end points)."""
        thetas = sorted({0.0, *map(float, nodes)})
        thetas = [t for t in thetas if t < math.pi / 2]
        SmithTable._counter += 1
        path = os.path.join(self.directory, f"smith_g1_{os.getpid()}_{SmithTable._counter}.dat")
        with open(path, "w") as f:
            for t in thetas:
                f.write(f"{fmt(t)} {fmt(self.g1(t))}\n")
            f.write(f"{fmt(math.pi / 2)} 0\n")
        return path


class ScatmechSurface:
    """A configured SCATMECH `Shadowed_Facet_BRDF_Model` for one `SurfaceParams`."""

    def __init__(self, params: SurfaceParams, workdir: str | None = None):
        params.validate()
        self.params = params
        self.model = BRDF_Model("Shadowed_Facet_BRDF_Model")
        self.model.setParameters(
            {
                "lambda": fmt(params.wavelength_um),
                "substrate": f"({fmt(params.n)},{fmt(params.k)})",
                "type": "0",
            }
        )
        if params.distribution == "gaussian":
            self.model.setParameter("sdf", "Gaussian_Slope_Distribution_Function")
            self.model.setParameter("sdf.s", fmt(math.sqrt(2.0) * params.sigma))
        else:
            self.model.setParameter("sdf", "Table_Slope_Distribution_Function")
            self.model.setParameter("sdf.T", cauchy_slope_formula(params.sigma, params.q))
        self.model.setParameter("shadow", _SHADOW_CLASS[params.shadowing])
        self.smith = None
        if params.shadowing == "smith":
            self._tmp = workdir or tempfile.mkdtemp(prefix="scatmech_smith_")
            self.smith = SmithTable(params, self._tmp)

    def set_smith_nodes(self, thetas_rad: np.ndarray) -> None:
        """Point the shadow table at a fresh file with these nodes. With every angle to be evaluated
        among the nodes the table is exact; any other grid measures SCATMECH's interpolation error."""
        path = self.smith.write(np.asarray(thetas_rad, dtype=float).ravel())
        self.model.setParameter("shadow.T", path)

    def mueller_scatmech_angles(self, thetai: float, thetas: float, phis: float) -> np.ndarray:
        return np.array(self.model.MuellerBRDF(thetai, thetas, phis, 0.0, "psps"), dtype=float)

    def mueller(self, theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg, smith_exact_nodes=True):
        """Mueller BRDF (N, 4, 4) in sr^-1 for irpol global angles in degrees (psps frames)."""
        ti = np.radians(np.atleast_1d(np.asarray(theta_i_deg, dtype=float)))
        tr = np.radians(np.atleast_1d(np.asarray(theta_r_deg, dtype=float)))
        ps = np.radians(
            np.atleast_1d(np.asarray(phi_r_deg, dtype=float) - np.asarray(phi_i_deg, dtype=float) - 180.0)
        )
        ti, tr, ps = np.broadcast_arrays(ti, tr, ps)
        if self.smith is not None and smith_exact_nodes:
            self.set_smith_nodes(np.concatenate([ti.ravel(), tr.ravel()]))
        out = np.empty(ti.shape + (4, 4))
        for idx in np.ndindex(ti.shape):
            out[idx] = self.mueller_scatmech_angles(float(ti[idx]), float(tr[idx]), float(ps[idx]))
        return out
