"""irpol — infrared polarimetry in Python: the irpol Rust library with numpy arrays in and out.

Every number comes from the Rust library (the one implementation, bit for bit the same as the
``irpol`` command line); this package only broadcasts arrays and wraps results.

Units: angles in degrees, wavelengths in µm, temperatures in K, BRDF values in sr⁻¹, radiances
in W·m⁻²·sr⁻¹. Mueller matrices are in SCATMECH's psps frames (docs/design.md §1.3), row-major.

>>> import irpol
>>> paint = irpol.Material.load("fits/paper_paint.toml")
>>> irpol.mueller(paint, 60.0, 0.0, [-30.0, 0.0, 30.0], 180.0).shape
(3, 4, 4)

Errors raise ``ValueError`` (bad input) or ``OSError`` (a file), with the command line's message.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _irpol
from ._irpol import Material

__version__ = _irpol.__version__
__all__ = [
    "Material",
    "mueller",
    "emissivity",
    "band_radiance",
    "brightness_temperature",
    "read_measurements",
    "Measurements",
    "fit",
    "FitResult",
    "validate",
    "Validation",
    "render",
    "solve_thermal",
    "thermal_keys",
    "export_pbsdf",
    "read_pbsdf",
]

PathLike = Union[str, "os.PathLike[str]"]
LWIR_BAND_UM = (8.0, 14.0)


def _material(material: Union[Material, PathLike]) -> Material:
    """A Material, or the material file at a path."""
    return material if isinstance(material, Material) else Material.load(os.fspath(material))


def _real(name: str, values: Any) -> np.ndarray:
    """`values` as a float64 array; refuses complex, boolean and non-numeric input."""
    array = np.asarray(values)
    if array.dtype.kind not in "iuf":
        raise ValueError(f"{name} must be real numbers (got dtype {array.dtype})")
    return array.astype(np.float64, copy=False)


def _flat(*arrays: np.ndarray) -> Tuple[Tuple[int, ...], List[np.ndarray]]:
    """The broadcast shape and each array broadcast to it, flat and contiguous."""
    broadcast = np.broadcast_arrays(*arrays)
    shape = broadcast[0].shape
    return shape, [np.ascontiguousarray(a.reshape(-1)) for a in broadcast]


def mueller(
    material: Union[Material, PathLike],
    theta_i: Any,
    phi_i: Any,
    theta_r: Any,
    phi_r: Any,
    wavelength_um: Optional[float] = None,
) -> np.ndarray:
    """Mueller BRDF of `material` (sr⁻¹, psps frames) at the given geometries.

    The four angle arguments (degrees) are broadcast together (numpy rules); the result has
    shape ``broadcast_shape + (4, 4)``, float64, ``[..., row, column]`` = m_row,column. θ_i must lie
    in [0°, 90°); θ_r in (−90°, 90°), a negative θ_r being the detector across the normal,
    (|θ_r|, φ_r + 180°), as ``irpol eval`` reads it. `wavelength_um` (µm) selects where a
    spectral material is evaluated (required for one). Raises ValueError on an invalid angle.
    """
    model = _material(material)
    shape, flat = _flat(*(_real(n, v) for n, v in
                          (("theta_i", theta_i), ("phi_i", phi_i),
                           ("theta_r", theta_r), ("phi_r", phi_r))))
    values = _irpol.mueller_flat(model, wavelength_um, *flat)
    return values.reshape(shape + (4, 4))


def emissivity(
    material: Union[Material, PathLike], theta: Any, wavelength_um: Optional[float] = None
) -> np.ndarray:
    """Polarized emissivity (ε0, ε1, ε2, ε3), dimensionless, at emission zeniths `theta` (degrees,
    in [0°, 90°)), as ``irpol emissivity`` computes it (Kirchhoff: 1 minus the hemispherical
    reflectance, docs/design.md §1.4). Shape ``theta.shape + (4,)``, float64."""
    model = _material(material)
    angles = _real("theta", theta)
    values = _irpol.emissivity_flat(model, wavelength_um, np.ascontiguousarray(angles.reshape(-1)))
    return values.reshape(angles.shape + (4,))


def band_radiance(temperature_k: Any, band_um: Tuple[float, float] = LWIR_BAND_UM) -> Any:
    """Blackbody band radiance ∫ B_λ(T) dλ over `band_um` (µm, flat response), W·m⁻²·sr⁻¹, at
    each temperature (K, finite, in [0, 1e4]); the shape of `temperature_k`."""
    t = _real("temperature_k", temperature_k)
    values = _irpol.band_radiance_flat(np.ascontiguousarray(t.reshape(-1)), tuple(band_um))
    return values.reshape(t.shape)[()]


def brightness_temperature(radiance: Any, band_um: Tuple[float, float] = LWIR_BAND_UM) -> Any:
    """The inverse of :func:`band_radiance`: the temperature (K) whose blackbody band radiance is
    `radiance` (W·m⁻²·sr⁻¹, finite, ≥ 0); the shape of `radiance`."""
    r = _real("radiance", radiance)
    values = _irpol.brightness_temperature_flat(np.ascontiguousarray(r.reshape(-1)), tuple(band_um))
    return values.reshape(r.shape)[()]


@dataclass(repr=False)
class Measurements:
    """One wavelength of a measurement file (docs/design.md §2.1), validated by irpol's reader.

    Angles in degrees (θ_r < 0 in the file already read as (|θ_r|, φ_r + 180°)); `values` and
    `uncertainties` have shape (points, len(elements)) in sr⁻¹, NaN where the file gives no
    uncertainty for an element."""

    material: str
    wavelength_um: float
    source: str
    sha256: str
    metadata: Dict[str, str]
    elements: List[str]
    theta_i_deg: np.ndarray
    phi_i_deg: np.ndarray
    theta_r_deg: np.ndarray
    phi_r_deg: np.ndarray
    values: np.ndarray
    uncertainties: np.ndarray
    line: np.ndarray
    merged: List[str]
    notes: List[str]

    def __repr__(self) -> str:
        # A summary: the arrays hold thousands of rows, which a repr must not print.
        merged = f", merged={len(self.merged)} files" if self.merged else ""
        return (
            f"Measurements(material={self.material!r}, wavelength_um={self.wavelength_um!r}, "
            f"rows={len(self.theta_i_deg)}, elements={self.elements!r}, "
            f"source={self.source!r}{merged})"
        )

    @classmethod
    def _from_dict(cls, d: Dict[str, Any]) -> "Measurements":
        d = dict(d)
        d["source"] = os.fspath(d["source"])
        d["merged"] = [os.fspath(p) for p in d["merged"]]
        return cls(**d)


def read_measurements(
    path: PathLike,
    *,
    layout: Optional[PathLike] = None,
    wavelength: Optional[float] = None,
    theta_i: Optional[Sequence[float]] = None,
) -> List[Measurements]:
    """Reads a measurement CSV: one :class:`Measurements` per wavelength, ascending. `layout` is
    an instrument layout TOML to read an instrument's own table through (a file may name its own
    with a ``# layout: FILE`` line); `wavelength` (µm) and `theta_i` (degrees) keep only those
    rows, as ``irpol fit --layout --wavelength --theta-i``. Raises OSError (unreadable) or
    ValueError (``file:line:column: what is wrong``)."""
    sets = _irpol.read_measurement_sets(
        os.fspath(path),
        layout=None if layout is None else os.fspath(layout),
        wavelength_um=wavelength,
        theta_i_deg=None if theta_i is None else [float(t) for t in theta_i],
    )
    return [Measurements._from_dict(d) for d in sets]


@dataclass
class Validation:
    """How a material predicts one measurement set it was not fitted to (``irpol validate``,
    docs/design.md §1.10): `m00_relative_rms` is the RMS of model/measured − 1 of m00 (a
    fraction; ``irpol validate`` prints it in %), `normalized_rms` the RMS over the other
    elements of m_ij/m00 (model) − m_ij/m00 (measured), `chi2_per_observation` the mean of
    ((model − measured)/σ)², `elements` maps each element to (RMS in sr⁻¹, normalized RMS), and
    `model_mueller` holds the model's matrices at every row, shape (rows, 4, 4)."""

    measurements: Measurements
    rows: int
    m00_relative_rms: float
    normalized_rms: float
    chi2_per_observation: float
    max_abs_residual: float
    uncertainties_from_file: bool
    elements: Dict[str, Tuple[float, float]]
    model_mueller: np.ndarray

    def __repr__(self) -> str:
        return (
            f"Validation(material={self.measurements.material!r}, rows={self.rows}, "
            f"m00_relative_rms={self.m00_relative_rms:.4g}, "
            f"normalized_rms={self.normalized_rms:.4g}, "
            f"chi2_per_observation={self.chi2_per_observation:.4g})"
        )


def validate(
    material: Union[Material, PathLike],
    path: PathLike,
    *,
    layout: Optional[PathLike] = None,
    wavelength: Optional[float] = None,
    theta_i: Optional[Sequence[float]] = None,
) -> List[Validation]:
    """Scores `material` (a :class:`Material` or a material TOML) on every set of the measurement
    file `path`, read as :func:`read_measurements` reads it (`layout`, `wavelength`, `theta_i`):
    the numbers of ``irpol validate``, without its report page. One :class:`Validation` per set.
    Raises OSError (unreadable) or ValueError (bad data, or a spectral material outside its
    table)."""
    results = _irpol.validate_material(
        _material(material),
        os.fspath(path),
        layout=None if layout is None else os.fspath(layout),
        wavelength_um=wavelength,
        theta_i_deg=None if theta_i is None else [float(t) for t in theta_i],
    )
    out = []
    for d in results:
        d = dict(d)
        d["measurements"] = Measurements._from_dict(d["measurements"])
        d["model_mueller"] = np.asarray(d["model_mueller"]).reshape(-1, 4, 4)
        out.append(Validation(**d))
    return out


def export_pbsdf(
    material: Union[Material, PathLike],
    path: PathLike,
    *,
    wavelengths_nm: Optional[Sequence[int]] = None,
    grid: Optional[Tuple[int, int, int]] = None,
) -> Dict[str, Any]:
    """Writes `material` (a Material or a material TOML) as the `.pbsdf` table of Mitsuba 3's
    ``measured_polarized`` plugin, as ``irpol export --to mitsuba`` (docs/mitsuba.md): five
    increasing whole-nm `wavelengths_nm` (default: 8000…12000 for a grey material, five across a
    spectral one's table), `grid` = (N_phi_d, N_theta_d, N_theta_h) node counts (default: chosen
    for the material). Returns path, bytes, grid, wavelengths_nm and notes. Raises ValueError
    (refused) or OSError (not written)."""
    return _irpol.export_pbsdf(
        _material(material),
        os.fspath(path),
        wavelengths_nm=None if wavelengths_nm is None else [int(w) for w in wavelengths_nm],
        grid=None if grid is None else [int(n) for n in grid],
    )


def read_pbsdf(path: PathLike) -> Dict[str, np.ndarray]:
    """The fields of a Mitsuba `.pbsdf` table as arrays: phi_d, theta_d, theta_h (radians), wvls
    (nm) and M (float32, (N_phi_d, N_theta_d, N_theta_h, N_lambda, 4, 4), in the table's frames
    and Mitsuba's S3 sign; docs/design.md §2.10). To read it as psps measurements, use
    :func:`read_measurements`. Raises ValueError naming the field when the table is malformed."""
    return _irpol.read_pbsdf(os.fspath(path))


from ._fit import FitResult, fit  # noqa: E402  (needs Measurements)
from ._render import render, solve_thermal, thermal_keys  # noqa: E402
