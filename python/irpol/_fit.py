"""`irpol.fit`: the fits of `irpol fit`, returned instead of written."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _irpol
from ._irpol import Material


@dataclass
class FitResult:
    """One material's fit: what ``irpol fit`` writes to ``fits/<name>.toml``, and more.

    `toml` is that file's text exactly. `uncertainty` holds the 1-σ errors of the free
    parameters (scaled by the reduced χ²), `correlation` their correlation matrix in
    `free_parameters` order; `chi2` is Σ r² of the normalized residuals (model − data)/σ, which
    `normalized_residuals` holds, one (points, measured elements) array per wavelength.
    `model_mueller` is the fitted model at each measured geometry, one (points, 4, 4) array per
    wavelength (sr⁻¹). Both lists run beside `measurements` (one item for a grey fit)."""

    name: str
    kind: str
    material: Material
    toml: str
    record: Dict[str, Any]
    free_parameters: List[str]
    uncertainty: Dict[str, float]
    correlation: np.ndarray
    chi2: float
    reduced_chi2: float
    observations: int
    degrees_of_freedom: int
    normalized_residuals: List[np.ndarray]
    model_mueller: List[np.ndarray]
    measurements: list
    notes: List[str]
    per_wavelength_errors: Optional[Dict[str, np.ndarray]] = None


def _result(d: Dict[str, Any]) -> FitResult:
    from . import Measurements

    record = json.loads(d["material"].fit_json)
    per_wavelength = None
    if d["kind"] == "spectral":
        per_wavelength = {k: d[f"{k}_errors"] for k in ("n", "k", "rho_d")}
    return FitResult(
        name=d["name"],
        kind=d["kind"],
        material=d["material"],
        toml=d["toml"],
        record=record,
        free_parameters=list(record["free_parameters"]),
        uncertainty=dict(record["uncertainty"]),
        correlation=np.asarray(record["correlation"], dtype=np.float64),
        chi2=d["chi2"],
        reduced_chi2=record["reduced_chi2"],
        observations=d["observations"],
        degrees_of_freedom=record["degrees_of_freedom"],
        normalized_residuals=list(d["normalized_residuals"]),
        model_mueller=[m.reshape(-1, 4, 4) for m in d["model_mueller"]],
        measurements=[Measurements._from_dict(s) for s in d["measurements"]],
        notes=list(d["notes"]),
        per_wavelength_errors=per_wavelength,
    )


def fit(
    inputs: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]],
    *,
    distribution: Optional[str] = None,
    shadowing: str = "smith",
    free: Optional[Union[str, Sequence[str]]] = None,
    fix: Optional[Union[str, Dict[str, float]]] = None,
    optimizer: str = "ga+lm",
    seed: Optional[int] = None,
    robust: Optional[str] = None,
    dispersion: str = "auto",
    layout: Optional[Union[str, "os.PathLike[str]"]] = None,
    wavelength: Optional[float] = None,
    theta_i: Optional[Sequence[float]] = None,
    terms: str = "auto",
) -> List[FitResult]:
    """Fits every material among `inputs` (measurement CSVs or folders of them) as
    ``irpol fit`` does, with its options (same names, values and defaults: `free` as
    ``"sigma,q,n,k,rho"`` or a list, `fix` as ``"k=0.1,rho=0"`` or a dict, `optimizer` as
    ``"ga+lm"``, `robust` as ``"huber:2"``, `dispersion` as ``"auto"``, ``"table"``,
    ``"cauchy"`` or ``"lorentz:N"``;
    `layout` an instrument layout TOML, `wavelength` (µm) and `theta_i` (degrees) the rows kept,
    as ``--layout``, ``--wavelength``, ``--theta-i``; `terms` the model's terms as
    ``--terms`` takes them: ``"auto"`` (the default: the admissible set that predicts best), one
    set such as ``"internal+subsurface"``, several comma-separated, or ``"all"``). Nothing is written. One :class:`FitResult` per material, in the order ``irpol fit`` prints
    them. Raises OSError (unreadable input) or ValueError (bad data or options)."""
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    if free is not None and not isinstance(free, str):
        free = ",".join(free)
    if isinstance(fix, dict):
        fix = ",".join(f"{k}={v!r}" for k, v in fix.items())
    results = _irpol.fit_materials(
        [os.fspath(p) for p in inputs],
        distribution=distribution,
        shadowing=shadowing,
        free=free,
        fix=fix,
        optimizer=optimizer,
        seed=seed,
        robust=robust,
        dispersion=dispersion,
        layout=None if layout is None else os.fspath(layout),
        wavelength_um=wavelength,
        theta_i_deg=None if theta_i is None else [float(t) for t in theta_i],
        terms=terms,
    )
    return [_result(d) for d in results]
