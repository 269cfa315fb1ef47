"""Type stubs of irpol's public API (docstrings in irpol/__init__.py)."""

import os
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._irpol import Material as Material

__version__: str
PathLike = Union[str, os.PathLike[str]]
ArrayLike = npt.ArrayLike
LWIR_BAND_UM: Tuple[float, float]

def mueller(material: Union[Material, PathLike], theta_i: ArrayLike, phi_i: ArrayLike, theta_r: ArrayLike, phi_r: ArrayLike, wavelength_um: Optional[float] = None) -> npt.NDArray[np.float64]: ...
def emissivity(material: Union[Material, PathLike], theta: ArrayLike, wavelength_um: Optional[float] = None) -> npt.NDArray[np.float64]: ...
def band_radiance(temperature_k: ArrayLike, band_um: Tuple[float, float] = ...) -> Union[float, npt.NDArray[np.float64]]: ...
def brightness_temperature(radiance: ArrayLike, band_um: Tuple[float, float] = ...) -> Union[float, npt.NDArray[np.float64]]: ...

@dataclass
class Measurements:
    material: str
    wavelength_um: float
    source: str
    sha256: str
    metadata: Dict[str, str]
    elements: List[str]
    theta_i_deg: npt.NDArray[np.float64]
    phi_i_deg: npt.NDArray[np.float64]
    theta_r_deg: npt.NDArray[np.float64]
    phi_r_deg: npt.NDArray[np.float64]
    values: npt.NDArray[np.float64]
    uncertainties: npt.NDArray[np.float64]
    line: npt.NDArray[np.uint64]
    merged: List[str]
    notes: List[str]

def read_measurements(path: PathLike, *, layout: Optional[PathLike] = None, wavelength: Optional[float] = None, theta_i: Optional[Sequence[float]] = None) -> List[Measurements]: ...
def export_pbsdf(material: Union[Material, PathLike], path: PathLike, *, wavelengths_nm: Optional[Sequence[int]] = None, grid: Optional[Tuple[int, int, int]] = None) -> Dict[str, Any]: ...
def read_pbsdf(path: PathLike) -> Dict[str, np.ndarray]: ...

@dataclass
class FitResult:
    name: str
    kind: str
    material: Material
    toml: str
    record: Dict[str, Any]
    free_parameters: List[str]
    uncertainty: Dict[str, float]
    correlation: npt.NDArray[np.float64]
    chi2: float
    reduced_chi2: float
    observations: int
    degrees_of_freedom: int
    normalized_residuals: List[npt.NDArray[np.float64]]
    model_mueller: List[npt.NDArray[np.float64]]
    measurements: List[Measurements]
    notes: List[str]
    per_wavelength_errors: Optional[Dict[str, npt.NDArray[np.float64]]] = ...

def fit(inputs: Union[PathLike, Sequence[PathLike]], *, distribution: Optional[str] = None, shadowing: str = "smith", free: Optional[Union[str, Sequence[str]]] = None, fix: Optional[Union[str, Mapping[str, float]]] = None, optimizer: str = "ga+lm", seed: Optional[int] = None, robust: Optional[str] = None, dispersion: str = "table", layout: Optional[PathLike] = None, wavelength: Optional[float] = None, theta_i: Optional[Sequence[float]] = None, terms: str = "external+depolarizer") -> List[FitResult]: ...
class Validation:
    measurements: Measurements
    rows: int
    m00_relative_rms: float
    normalized_rms: float
    chi2_per_observation: float
    max_abs_residual: float
    uncertainties_from_file: bool
    elements: Dict[str, Tuple[float, float]]
    model_mueller: npt.NDArray[np.float64]
def validate(material: Union[Material, PathLike], path: PathLike, *, layout: Optional[PathLike] = None, wavelength: Optional[float] = None, theta_i: Optional[Sequence[float]] = None) -> List[Validation]: ...
def render(scene: PathLike, *, resolution: Optional[Tuple[int, int]] = None, samples: Optional[int] = None, seed: Optional[int] = None, bounces: Optional[int] = None, time_s: Optional[float] = None, patch: Optional[Mapping[str, Any]] = None, out: Optional[PathLike] = None, thermal_solution: Optional[PathLike] = None, threads: Optional[int] = None) -> Dict[str, Any]: ...
def thermal_keys(scene: PathLike, times_s: Sequence[float], *, patch: Optional[Mapping[str, Any]] = None) -> List[str]: ...
def solve_thermal(scene: PathLike, times_s: Sequence[float], out: PathLike, *, patch: Optional[Mapping[str, Any]] = None, threads: Optional[int] = None) -> str: ...
