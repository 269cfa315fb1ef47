"""The sweep spec (docs/design.md §2.7): reading, checking, and its items in row-major grid order."""

from __future__ import annotations

import glob
import itertools
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, List, Optional

try:
    import tomllib
except ImportError:  # Python < 3.11
    import tomli as tomllib

import irpol

RENDER_KEYS = {"kind", "scene", "out", "grid", "render"}
FIT_KEYS = {"kind", "inputs", "out", "options"}
RENDER_OVERRIDES = {"resolution", "samples", "seed", "bounces"}
FIT_OPTIONS = {"distribution", "shadowing", "free", "fix", "optimizer", "seed", "robust",
               "dispersion"}
TIME_KEY = "time_s"


class SpecError(ValueError):
    """A sweep spec that cannot run; nothing has been started."""


@dataclass(frozen=True)
class Item:
    """One task: its number and the values that make it (grid values, or the files of a fit)."""

    index: int
    params: Dict[str, Any]


@dataclass
class Spec:
    path: Path
    kind: str
    out: Path
    scene: Optional[Path] = None
    grid: Dict[str, List[Any]] = field(default_factory=dict)
    render: Dict[str, Any] = field(default_factory=dict)
    inputs: Optional[str] = None
    options: Dict[str, Any] = field(default_factory=dict)

    def items(self) -> List[Item]:
        """Render: the grid's Cartesian product, the last key varying fastest. Fit: one item per
        material among the input files, by material name."""
        if self.kind == "render":
            keys = list(self.grid)
            return [Item(i, dict(zip(keys, values)))
                    for i, values in enumerate(itertools.product(*self.grid.values()))]
        return _fit_items(self)


def _unknown(path: Path, table: str, keys, known) -> None:
    unknown = sorted(set(keys) - set(known))
    if unknown:
        raise SpecError(f"{path}: unknown key '{unknown[0]}'{table} (known: "
                        f"{', '.join(sorted(known))})")


def _fit_items(spec: Spec) -> List[Item]:
    pattern = str(spec.path.parent / spec.inputs)
    files = sorted(glob.glob(pattern, recursive=True))
    if not files:
        raise SpecError(f"{spec.path}: inputs = '{spec.inputs}' matches no file")
    by_material: Dict[str, List[str]] = {}
    for name in files:
        material = irpol.read_measurements(name)[0].material
        by_material.setdefault(material, []).append(os.path.relpath(name, spec.path.parent))
    return [Item(i, {"material": m, "files": by_material[m]})
            for i, m in enumerate(sorted(by_material))]


def _check_grid(path: Path, grid: Dict[str, Any]) -> None:
    if not isinstance(grid, dict) or not grid:
        raise SpecError(f"{path}: [grid] is empty: give at least one key with a list of values")
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            raise SpecError(f"{path}: grid key '{key}' needs a non-empty list of values")


def load_spec(path) -> Spec:
    """Reads and checks a spec; raises SpecError (or OSError) before any work starts."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            raw = tomllib.load(f)
    except tomllib.TOMLDecodeError as e:
        raise SpecError(f"{path}: not a valid TOML: {e}") from None
    kind = raw.get("kind", "render")
    if kind not in ("render", "fit"):
        raise SpecError(f"{path}: kind = '{kind}': use \"render\" or \"fit\"")
    _unknown(path, "", raw, RENDER_KEYS if kind == "render" else FIT_KEYS)
    if "out" not in raw:
        raise SpecError(f"{path}: missing key 'out' (the output folder, relative to the spec)")
    spec = Spec(path=path, kind=kind, out=path.parent / raw["out"])
    if kind == "fit":
        if "inputs" not in raw:
            raise SpecError(f"{path}: missing key 'inputs' (a glob of measurement files)")
        spec.inputs = raw["inputs"]
        spec.options = dict(raw.get("options", {}))
        _unknown(path, " in [options]", spec.options, FIT_OPTIONS)
        return spec
    if "scene" not in raw:
        raise SpecError(f"{path}: missing key 'scene' (the scene template)")
    spec.scene = path.parent / raw["scene"]
    spec.render = dict(raw.get("render", {}))
    _unknown(path, " in [render]", spec.render, RENDER_OVERRIDES)
    _check_grid(path, raw.get("grid"))
    spec.grid = dict(raw["grid"])
    try:
        irpol._irpol.check_scene_keys(str(spec.scene), [k for k in spec.grid if k != TIME_KEY])
    except ValueError as e:
        raise SpecError(f"{path}: {e}") from None
    return spec
