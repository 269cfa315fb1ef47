"""Shared parts of the fit cross-checks (`crosscheck_nlopt.py`, `crosscheck_emcee.py`).

* reading a measurement CSV (docs/design.md §2.1) with its u_ columns into arrays;
* the weighted least-squares objective of `irpol fit`, chi2 = sum(((model - data) / u)^2) over every
  Mueller element present, on a fast form of the numpy port (`pbrdf_numpy.py`) that is vectorized
  over parameter sets as well as geometries;
* irpol's free parameters, bounds and search coordinates (src/fit/parameters.rs on branch `fit`);
* running `irpol fit` on one file and reading the material TOML it writes (docs/design.md §2.2).

Fast form of the model.  For fixed geometry the Jones matrix is J = P_out diag(r_s, r_p) P_in
(docs/design.md §1.3), so every Mueller element is a fixed real linear combination of the four real numbers
|r_s|^2, |r_p|^2, Re(r_s r_p*), Im(r_s r_p*).  The four coefficient matrices per geometry are
computed once from the port's own frames and Jones -> Mueller map; a parameter set then costs one
Fresnel evaluation per point, one Smith G1 per distinct zenith angle and a small matrix product.
`FastModel.verify_against_port` checks it against `pbrdf_numpy.mueller_brdf` before it is trusted,
and `verify_port_against_scatmech` checks the port against SCATMECH on geometries of the file.
"""

from __future__ import annotations

import csv
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from dataclasses import dataclass, field

import numpy as np
from scipy import special

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pbrdf_numpy as port  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def _single_wavelength(path: str) -> bool:
    """Whether a shipped file is of one wavelength (a `# wavelength_um:` header line): the
    cross-checks fit one wavelength; the spectral set (a wavelength_um column) is checked against
    its truth by tests/it/spectral_materials.rs."""
    with open(path) as f:
        return any(line.startswith("# wavelength_um:") for line in f if line.startswith("#"))


SHIPPED = sorted(
    os.path.join(REPO, "measurements", f)
    for f in os.listdir(os.path.join(REPO, "measurements"))
    if f.endswith(".csv") and _single_wavelength(os.path.join(REPO, "measurements", f))
)


class SetupError(RuntimeError):
    """A problem with the inputs or the environment, not with the check (exit status 2)."""


# ---------------------------------------------------------------------------------------------
# Parameters, bounds and search coordinates: the values of src/fit/parameters.rs (branch `fit`)
# ---------------------------------------------------------------------------------------------

PARAMETERS = ("sigma", "q", "n", "k", "rho_d")
BOUNDS = {
    "sigma": (0.005, 1.5),
    "q": (1.51, 50.0),  # 1.05 without Smith; Smith's Cauchy Lambda needs q > 3/2 (docs/design.md §1.3)
    "n": (0.05, 10.0),
    "k": (0.0, 50.0),
    "rho_d": (0.0, 1.0),
}
# Where irpol's local search starts (Parameter::starting_value): off the k = 0 boundary, where the
# linear Mueller elements are stationary in k.
START = {"sigma": 0.2, "q": 3.0, "n": 1.8, "k": 0.1, "rho_d": 0.02}
K_SCALE = 0.1  # k's search coordinate is asinh(k / 0.1)
# Values of the parameters that are not free (Parameter::default_value): q for the Gaussian.
FIXED_DEFAULTS = {"sigma": 0.2, "q": 2.0, "n": 1.5, "k": 0.0, "rho_d": 0.0}


def free_parameters(distribution: str) -> list[str]:
    """irpol's default free set: all five for the Cauchy, no q for the Gaussian."""
    return [p for p in PARAMETERS if not (p == "q" and distribution == "gaussian")]


def to_search(name: str, value):
    value = np.asarray(value, dtype=float)
    if name == "sigma":
        return np.log(value)
    if name == "q":
        return np.log(value - 1.0)
    if name == "k":
        return np.arcsinh(value / K_SCALE)
    return value


def from_search(name: str, coord):
    coord = np.asarray(coord, dtype=float)
    if name == "sigma":
        return np.exp(coord)
    if name == "q":
        return 1.0 + np.exp(coord)
    if name == "k":
        return K_SCALE * np.sinh(coord)
    return coord


# ---------------------------------------------------------------------------------------------
# Measurement files (docs/design.md §2.1)
# ---------------------------------------------------------------------------------------------

ELEMENTS = [f"m{i}{j}" for i in range(4) for j in range(4)]


@dataclass
class Measurement:
    path: str
    name: str
    wavelength_um: float
    geometry: np.ndarray  # (N, 4) theta_i, phi_i, theta_r, phi_r in degrees
    elements: list[str]  # Mueller elements present, in file order
    data: np.ndarray  # (N, E) sr^-1
    u: np.ndarray  # (N, E) sr^-1, 1-sigma
    truth: dict[str, str] = field(default_factory=dict)

    @property
    def observations(self) -> int:
        return self.data.size


def read_measurement(path: str) -> Measurement:
    """The subset of docs/design.md §2.1 the shipped files use; every element must have its u_ column
    (the cross-checks weight by the file's own uncertainties, not irpol's defaults)."""
    meta: dict[str, str] = {}
    lines = []
    try:
        with open(path, newline="") as f:
            for line in f:
                if line.startswith("#"):
                    body = line[1:].strip()
                    if ":" in body:
                        key, _, value = body.partition(":")
                        meta.setdefault(key.strip(), value.strip())
                elif line.strip():
                    lines.append(line)
    except OSError as e:
        raise SetupError(f"cannot read {path}: {e}") from e
    rows = list(csv.reader(lines))
    if len(rows) < 2:
        raise SetupError(f"{path}: no data rows")
    header, body = rows[0], rows[1:]
    col = {name: i for i, name in enumerate(header)}
    try:
        values = np.array([[float(x) for x in r] for r in body])
    except ValueError as e:
        raise SetupError(f"{path}: {e}") from e

    def column(name, default=None):
        if name in col:
            return values[:, col[name]]
        if default is None:
            raise SetupError(f"{path}: missing column {name}")
        return np.full(len(values), default)

    geometry = np.stack(
        [column("theta_i_deg"), column("phi_i_deg", 0.0), column("theta_r_deg"), column("phi_r_deg", 180.0)],
        axis=1,
    )
    if "wavelength_um" in col:
        wl = np.unique(column("wavelength_um"))
        if len(wl) != 1:
            raise SetupError(f"{path}: the cross-checks need a single wavelength, found {wl}")
        wavelength = float(wl[0])
    elif "wavelength_um" in meta:
        wavelength = float(meta["wavelength_um"])
    else:
        raise SetupError(f"{path}: no wavelength")
    elements = [e for e in header if e in ELEMENTS]
    missing_u = [e for e in elements if f"u_{e}" not in col]
    if missing_u:
        raise SetupError(f"{path}: no uncertainty column for {', '.join(missing_u)}")
    data = np.stack([column(e) for e in elements], axis=1)
    u = np.stack([column(f"u_{e}") for e in elements], axis=1)
    if not np.all(u > 0):
        raise SetupError(f"{path}: uncertainties must be > 0")
    name = meta.get("material", os.path.splitext(os.path.basename(path))[0])
    truth = {k[len("truth_"):]: v for k, v in meta.items() if k.startswith("truth_")}
    return Measurement(path, name, wavelength, geometry, elements, data, u, truth)


# ---------------------------------------------------------------------------------------------
# Fast model and objective
# ---------------------------------------------------------------------------------------------


def _smith_lambda_batch(theta: np.ndarray, distribution: str, sigma: np.ndarray, q: np.ndarray) -> np.ndarray:
    """docs/design.md §1.3 closed-form Lambda for W parameter sets (sigma, q of shape (W,)) and U zenith
    angles (U,) -> (W, U); theta = 0 gives 0.  Same formulas as pbrdf_numpy.smith_lambda, with
    the parameters as arrays (checked against it in verify_against_port)."""
    lam = np.zeros((len(sigma), len(theta)))
    pos = theta > 0.0
    mu = (np.cos(theta[pos]) / np.sin(theta[pos]))[None, :]
    s = sigma[:, None]
    if distribution == "gaussian":
        a = mu / (math.sqrt(2.0) * s)
        lam[:, pos] = -0.5 * special.erfc(a) + np.exp(-a * a) / (2.0 * math.sqrt(math.pi) * a)
        return lam
    qq = q[:, None]
    a = 2.0 * s * s
    c = np.exp(special.gammaln(qq - 0.5) - special.gammaln(qq - 1.0)) / math.sqrt(math.pi)
    first = c * np.sqrt(a) / ((2.0 * qq - 3.0) * mu) * (1.0 + mu * mu / a) ** (1.5 - qq)
    lam[:, pos] = first - 0.5 * special.betainc(qq - 1.0, 0.5, a / (a + mu * mu))
    return lam


class FastModel:
    """The pBRDF of docs/design.md §1.3 on one file's geometries, with Smith shadowing (irpol's default)
    or none/torrance-sparrow, vectorized over parameter sets."""

    def __init__(self, m: Measurement, distribution: str, shadowing: str = "smith"):
        if distribution not in port.DISTRIBUTIONS or shadowing not in port.SHADOWINGS:
            raise SetupError(f"unsupported model {distribution}/{shadowing}")
        self.m = m
        self.distribution = distribution
        self.shadowing = shadowing
        g = m.geometry
        ti, pi_, tr, pr = (np.radians(g[:, c]) for c in range(4))
        w_i, w_r, k_in, k_out, s_in, p_in, s_out, p_out = port.global_frames(ti, pi_, tr, pr)
        h = w_i + w_r
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        self.cos_t = h[:, 2]
        self.cos_b = np.clip(np.sum(h * w_i, axis=-1), 0.0, 1.0)
        hxk = np.cross(h, k_in)
        norm = np.linalg.norm(hxk, axis=-1, keepdims=True)
        if np.any(norm < 1e-12):
            raise SetupError(f"{m.path}: a geometry at exact retro-reflection")
        s_loc = hxk / norm
        p_loc_in, p_loc_out = np.cross(k_in, s_loc), np.cross(k_out, s_loc)

        def d(a, b):
            return np.sum(a * b, axis=-1)

        out_proj = np.stack(
            [np.stack([d(s_out, s_loc), d(s_out, p_loc_out)], -1), np.stack([d(p_out, s_loc), d(p_out, p_loc_out)], -1)],
            -2,
        )
        in_proj = np.stack(
            [np.stack([d(s_loc, s_in), d(s_loc, p_in)], -1), np.stack([d(p_loc_in, s_in), d(p_loc_in, p_in)], -1)],
            -2,
        )

        def mueller_for(r_s, r_p):
            r = np.array([r_s, r_p], dtype=complex)
            return port.mueller_from_jones(out_proj @ (r[:, None] * in_proj))

        # Mueller(r) = |rs|^2 B0 + |rp|^2 B1 + Re(rs rp*) B2 + Im(rs rp*) B3.
        b0 = mueller_for(1, 0)
        b1 = mueller_for(0, 1)
        b2 = mueller_for(1, 1) - b0 - b1  # rs rp* = 1
        b3 = b0 + b1 - mueller_for(1, 1j)  # rs rp* = -i
        idx = [ELEMENTS.index(e) for e in m.elements]
        basis = np.stack([b.reshape(len(g), 16)[:, idx] for b in (b0, b1, b2, b3)], axis=1)  # (N, 4, E)
        self.basis = basis
        self.m00_column = m.elements.index("m00") if "m00" in m.elements else None
        tan2 = np.maximum(1.0 - self.cos_t**2, 0.0) / self.cos_t**2
        self.tan2 = tan2
        self.geometric = 1.0 / (4.0 * self.cos_t**4 * np.cos(ti) * np.cos(tr))  # 1/cos^3 * 1/(4 cos cos cos)
        self.ti, self.tr = ti, tr
        zeniths, inverse = np.unique(np.concatenate([ti, tr]), return_inverse=True)
        self.zeniths = zeniths
        self.zi, self.zr = inverse[: len(ti)], inverse[len(ti):]

    def mueller_batch(self, params: np.ndarray) -> np.ndarray:
        """params (W, 5) physical sigma, q, n, k, rho_d -> (W, N, E) model values of the elements
        present in the file."""
        params = np.atleast_2d(np.asarray(params, dtype=float))
        sigma, q, n, k, rho_d = params.T
        eps = ((n + 1j * k) ** 2)[:, None]
        cb = self.cos_b[None, :]
        root = np.sqrt(eps - (1.0 - cb * cb))
        r_s = (cb - root) / (cb + root)
        r_p = (eps * cb - root) / (eps * cb + root)
        cross = r_s * np.conj(r_p)
        quad = np.stack([np.abs(r_s) ** 2, np.abs(r_p) ** 2, cross.real, cross.imag], axis=-1)  # (W, N, 4)
        out = np.einsum("wnc,nce->wne", quad, self.basis)

        s2 = (sigma * sigma)[:, None]
        t2 = self.tan2[None, :]
        if self.distribution == "gaussian":
            slope = np.exp(-t2 / (2.0 * s2)) / (2.0 * math.pi * s2)
        else:
            a = 2.0 * s2
            qq = q[:, None]
            slope = (qq - 1.0) * a ** (qq - 1.0) / (math.pi * (t2 + a) ** qq)
        scale = slope * self.geometric[None, :] * self._shadowing(sigma, q)
        out *= scale[..., None]
        if self.m00_column is not None:
            out[..., self.m00_column] += (rho_d / math.pi)[:, None]
        return out

    def _shadowing(self, sigma, q):
        if self.shadowing == "none":
            return np.ones((len(sigma), len(self.cos_t)))
        if self.shadowing == "torrance-sparrow":
            ct, cb = self.cos_t, self.cos_b
            g = np.minimum(1.0, np.minimum(2 * ct * np.cos(self.ti) / cb, 2 * ct * np.cos(self.tr) / cb))
            return np.broadcast_to(g, (len(sigma), len(ct)))
        g1 = 1.0 / (1.0 + _smith_lambda_batch(self.zeniths, self.distribution, sigma, q))
        return g1[:, self.zi] * g1[:, self.zr]

    def chi2_batch(self, params: np.ndarray) -> np.ndarray:
        r = (self.mueller_batch(params) - self.m.data[None]) / self.m.u[None]
        return np.einsum("wne,wne->w", r, r)

    def chi2(self, params) -> float:
        return float(self.chi2_batch(np.asarray(params, dtype=float)[None, :])[0])

    def verify_against_port(self, rng: np.random.Generator, sets: int = 4) -> float:
        """Largest |fast - pbrdf_numpy| / |m00| over the file's geometries for `sets` random
        parameter sets inside the bounds (plus the start point)."""
        trials = [np.array([START[p] for p in PARAMETERS])]
        for _ in range(sets):
            trials.append(np.array([
                math.exp(rng.uniform(math.log(0.02), math.log(0.6))), rng.uniform(1.6, 8.0),
                rng.uniform(1.1, 4.0), rng.uniform(0.0, 2.0), rng.uniform(0.0, 0.1)]))
        worst = 0.0
        g = self.m.geometry
        idx = [ELEMENTS.index(e) for e in self.m.elements]
        for p in trials:
            ref = port.mueller_brdf(g[:, 0], g[:, 1], g[:, 2], g[:, 3], distribution=self.distribution,
                                    sigma=p[0], q=p[1], n=p[2], k=p[3], shadowing=self.shadowing, rho_d=p[4])
            ref = ref.reshape(len(g), 16)
            ours = self.mueller_batch(p[None, :])[0]
            worst = max(worst, float(np.max(np.abs(ours - ref[:, idx]) / np.abs(ref[:, :1]))))
        return worst


def verify_port_against_scatmech(m: Measurement, distribution: str, params: dict[str, float],
                                 rng: np.random.Generator, count: int = 6) -> float:
    """Largest |pbrdf_numpy - SCATMECH| / m00 (facet term; rho_d adds to m00 only and is left out)
    over `count` geometries of the file drawn with `rng`."""
    try:
        import scatmech_backend as sb  # imported here: only this check needs pyscatmech
    except ImportError as e:
        raise SetupError(f"pyscatmech is needed to check the numpy port ({e}); see scripts/README.md") from e

    pick = rng.choice(len(m.geometry), size=min(count, len(m.geometry)), replace=False)
    g = m.geometry[pick]
    sp = sb.SurfaceParams(distribution, params["sigma"], params.get("q", 0.0) if distribution == "cauchy" else 0.0,
                          params["n"], params["k"], "smith", m.wavelength_um)
    ref = sb.ScatmechSurface(sp).mueller(g[:, 0], g[:, 1], g[:, 2], g[:, 3])
    ours = port.mueller_brdf(g[:, 0], g[:, 1], g[:, 2], g[:, 3], distribution=distribution, sigma=sp.sigma,
                             q=sp.q, n=sp.n, k=sp.k, shadowing="smith")
    return float(np.max(np.abs(ours - ref) / ref[:, 0, 0][:, None, None]))


def check_model(m: Measurement, distribution: str, seed: int, with_scatmech: bool = True) -> str:
    """Runs both model checks on this file's geometries; raises SetupError if either is off by more
    than 1e-9 relative to m00.  Returns a one-line summary."""
    rng = np.random.default_rng(seed)
    fast = FastModel(m, distribution)
    e_fast = fast.verify_against_port(rng)
    if e_fast > 1e-9:
        raise SetupError(f"{m.name}: fast model differs from pbrdf_numpy by {e_fast:.2e} (relative to m00)")
    text = f"fast model vs numpy port {e_fast:.1e}"
    if with_scatmech:
        # At irpol's start point and, for the shipped synthetic files, at the generating parameters.
        sets = [dict(START)]
        if m.truth.get("distribution") == distribution:
            sets.append({p: float(m.truth[p]) for p in PARAMETERS if m.truth.get(p)})
        e_sm = max(verify_port_against_scatmech(m, distribution, s, rng) for s in sets)
        if e_sm > 1e-9:
            raise SetupError(f"{m.name}: numpy port differs from SCATMECH by {e_sm:.2e} (relative to m00)")
        text += f", numpy port vs SCATMECH {e_sm:.1e} ({6 * len(sets)} geometries of the file)"
    return text


# ---------------------------------------------------------------------------------------------
# irpol
# ---------------------------------------------------------------------------------------------


def find_irpol(explicit: str | None) -> str:
    candidates = [explicit] if explicit else [
        os.environ.get("IRPOL", ""),
        os.path.join(os.environ.get("CARGO_TARGET_DIR", ""), "release", "irpol") if os.environ.get("CARGO_TARGET_DIR") else "",
        os.path.join(REPO, "target", "release", "irpol"),
        shutil.which("irpol") or "",
    ]
    for c in candidates:
        if c and os.path.isfile(c) and os.access(c, os.X_OK):
            return c
    raise SetupError(f"irpol binary not found (tried {', '.join(c for c in candidates if c)}); pass --irpol PATH")


@dataclass
class IrpolFit:
    toml: dict
    wall_seconds: float
    path: str

    @property
    def model(self) -> dict:
        return self.toml["model"]

    @property
    def fit(self) -> dict:
        return self.toml["fit"]

    @property
    def distribution(self) -> str:
        return self.model["distribution"]

    @property
    def free(self) -> list[str]:
        return [normalize_name(p) for p in self.fit["free_parameters"]]

    def value(self, name: str) -> float:
        return float(self.model[name])

    def uncertainty(self, name: str) -> float | None:
        unc = self.fit.get("uncertainty", {})
        for key in (name, "rho" if name == "rho_d" else name):
            if key in unc:
                return float(unc[key])
        return None


def normalize_name(name: str) -> str:
    return "rho_d" if name in ("rho", "rho_d") else name


def _fit_takes_reports(irpol: str) -> bool:
    """Whether this irpol build has `fit --reports` (docs/design.md §4); earlier builds write no reports."""
    try:
        help_text = subprocess.run([irpol, "fit", "--help"], capture_output=True, text=True, timeout=60).stdout
    except (OSError, subprocess.TimeoutExpired) as e:
        raise SetupError(f"{irpol} fit --help: {e}") from e
    return "--reports" in help_text


def run_irpol_fit(irpol: str, csv_path: str, extra: list[str] | None = None, timeout: float = 1800) -> IrpolFit:
    """`irpol fit CSV --out TMP --reports TMP2` (wall clock timed); returns the parsed material TOML."""
    with tempfile.TemporaryDirectory(prefix="xcheck_fits_") as out, tempfile.TemporaryDirectory(prefix="xcheck_reports_") as rep:
        cmd = [irpol, "fit", csv_path, "--out", out, *(["--reports", rep] if _fit_takes_reports(irpol) else []),
               *(extra or [])]
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except (OSError, subprocess.TimeoutExpired) as e:
            raise SetupError(f"{' '.join(cmd)}: {e}") from e
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            raise SetupError(f"{' '.join(cmd)} exited {proc.returncode}: {proc.stderr.strip()[-2000:]}")
        tomls = [f for f in os.listdir(out) if f.endswith(".toml")]
        if len(tomls) != 1:
            raise SetupError(f"{' '.join(cmd)}: expected one TOML in {out}, found {tomls}")
        path = os.path.join(out, tomls[0])
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    return IrpolFit(doc, wall, tomls[0])


# ---------------------------------------------------------------------------------------------
# Gauss-Newton covariance (the numpy side's own version of irpol's [fit.uncertainty])
# ---------------------------------------------------------------------------------------------


def full_parameters(free: list[str], values: np.ndarray, fixed: dict[str, float]) -> np.ndarray:
    """(W, len(free)) free values -> (W, 5) sigma, q, n, k, rho_d with the rest from `fixed`."""
    values = np.atleast_2d(values)
    out = np.tile(np.array([fixed[p] for p in PARAMETERS], dtype=float), (len(values), 1))
    out[:, [PARAMETERS.index(p) for p in free]] = values
    return out


def gauss_newton_covariance(fast: FastModel, free: list[str], x: np.ndarray, fixed: dict[str, float]) -> np.ndarray:
    """(J^T J)^-1 * chi2/(observations - free) of the normalized residuals at x (physical free
    parameters), J by central differences (one-sided into the box at a bound)."""
    m = fast.m

    def residuals(v):
        return ((fast.mueller_batch(full_parameters(free, v, fixed))[0] - m.data) / m.u).ravel()

    columns = []
    for i, p in enumerate(free):
        lo, hi = BOUNDS[p]
        h = 1e-6 * max(abs(x[i]), 1e-3 * (hi - lo))
        up, down = x.copy(), x.copy()
        up[i] = min(x[i] + h, hi)
        down[i] = max(x[i] - h, lo)
        columns.append((residuals(up) - residuals(down)) / (up[i] - down[i]))
    jac = np.stack(columns, axis=1)
    r = residuals(x)
    dof = m.observations - len(free)
    return np.linalg.inv(jac.T @ jac) * float(r @ r) / dof
