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


def _shown(value: Any, limit: int = 40) -> str:
    """`value` as a message quotes it: control characters escaped, at most `limit` characters."""
    text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(value))
    return text if len(text) <= limit else text[:limit] + "…"


def _unknown(path: Path, table: str, keys, known) -> None:
    unknown = sorted(set(keys) - set(known))
    if unknown:
        raise SpecError(f"{path}: unknown key '{_shown(unknown[0])}'{table} (known: "
                        f"{', '.join(sorted(known))})")


def _typed(path: Path, raw: Dict[str, Any], key: str, kind: type, what: str, default=None):
    """raw[key] if it is a `kind` (bool is not an int), `default` if absent; else SpecError."""
    if key not in raw:
        return default
    value = raw[key]
    if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
        raise SpecError(f"{path}: {key} = {_shown(value)}: expected {what}")
    return value


def _check_render(path: Path, render: Dict[str, Any]) -> None:
    _unknown(path, " in [render]", render, RENDER_OVERRIDES)
    size = render.get("resolution", [1, 1])
    if (not isinstance(size, list) or len(size) != 2
            or not all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in size)):
        raise SpecError(f"{path}: [render] resolution = {_shown(size)}: expected [width, height] "
                        "in pixels, e.g. [320, 240]")
    for key in ("samples", "seed", "bounces"):
        value = _typed(path, render, key, int, "a whole number ≥ 0", 0)
        if value < 0:
            raise SpecError(f"{path}: [render] {key} = {value}: expected a whole number ≥ 0")


def _fit_items(spec: Spec) -> List[Item]:
    pattern = str(spec.path.parent / spec.inputs)
    files = sorted(glob.glob(pattern, recursive=True))
    if not files:
        raise SpecError(f"{spec.path}: inputs = '{_shown(spec.inputs)}' matches no file")
    by_material: Dict[str, List[str]] = {}
    for name in files:
        try:
            material = irpol.read_measurements(name)[0].material
        except ValueError as e:
            raise SpecError(f"{spec.path}: inputs: {e}") from None
        by_material.setdefault(material, []).append(os.path.relpath(name, spec.path.parent))
    return [Item(i, {"material": m, "files": by_material[m]})
            for i, m in enumerate(sorted(by_material))]


def _check_grid(path: Path, grid: Any) -> None:
    if not isinstance(grid, dict) or not grid:
        raise SpecError(f"{path}: [grid] is empty: give at least one key with a list of values")
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            raise SpecError(f"{path}: grid key '{_shown(key)}' needs a non-empty list of values")
    times = grid.get(TIME_KEY, [])
    if not all(isinstance(t, (int, float)) and not isinstance(t, bool) for t in times):
        raise SpecError(f"{path}: grid key '{TIME_KEY}' needs numbers (seconds from "
                        "thermal.start_utc)")


def _read_toml(path: Path) -> Dict[str, Any]:
    with open(path, "rb") as f:
        data = f.read()
    try:
        return tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError as e:
        raise SpecError(f"{path}: not UTF-8 text (byte {e.start})") from None
    except ValueError as e:  # TOMLDecodeError, or a number tomllib refuses (4300+ digits)
        raise SpecError(f"{path}: not a valid TOML: {_shown(e, 200)}") from None
    except RecursionError:  # tomllib reads nested arrays recursively, without a depth limit
        raise SpecError(f"{path}: not a valid sweep spec: arrays or tables nested too deep") \
            from None


def load_spec(path) -> Spec:
    """Reads and checks a spec; raises SpecError (or OSError) before any work starts."""
    path = Path(path)
    raw = _read_toml(path)
    kind = raw.get("kind", "render")
    if kind not in ("render", "fit"):
        raise SpecError(f"{path}: kind = '{_shown(kind)}': use \"render\" or \"fit\"")
    _unknown(path, "", raw, RENDER_KEYS if kind == "render" else FIT_KEYS)
    out = _typed(path, raw, "out", str, "a folder path (text)")
    if out is None:
        raise SpecError(f"{path}: missing key 'out' (the output folder, relative to the spec)")
    spec = Spec(path=path, kind=kind, out=path.parent / out)
    if kind == "fit":
        spec.inputs = _typed(path, raw, "inputs", str, "a glob of measurement files (text)")
        if spec.inputs is None:
            raise SpecError(f"{path}: missing key 'inputs' (a glob of measurement files)")
        spec.options = _typed(path, raw, "options", dict, "a table of fit options", {})
        _unknown(path, " in [options]", spec.options, FIT_OPTIONS)
        return spec
    scene = _typed(path, raw, "scene", str, "a scene path (text)")
    if scene is None:
        raise SpecError(f"{path}: missing key 'scene' (the scene template)")
    spec.scene = path.parent / scene
    spec.render = _typed(path, raw, "render", dict, "a table of render settings", {})
    _check_render(path, spec.render)
    _check_grid(path, raw.get("grid"))
    spec.grid = dict(raw["grid"])
    try:
        irpol._irpol.check_scene_keys(str(spec.scene), [k for k in spec.grid if k != TIME_KEY])
    except ValueError as e:
        raise SpecError(f"{path}: {e}") from None
    return spec
