"""`irpol.render`: `irpol render` in memory, numpy images out; `irpol.solve_thermal` and
`irpol.thermal_keys`: a scene's thermal run solved once and saved, for renders at its instants."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _irpol


def render(
    scene: Union[str, "os.PathLike[str]"],
    *,
    resolution: Optional[Tuple[int, int]] = None,
    samples: Optional[int] = None,
    seed: Optional[int] = None,
    bounces: Optional[int] = None,
    time_s: Optional[float] = None,
    patch: Optional[Mapping[str, Any]] = None,
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
    thermal_solution: Optional[Union[str, "os.PathLike[str]"]] = None,
    threads: Optional[int] = None,
) -> Dict[str, Any]:
    """Renders a scene TOML as ``irpol render`` does and returns its images.

    Returns a dict of float32 arrays (height, width), rows from the top: "S0", "S1", "S2", "S3"
    and the polarizer images "I0", "I45", "I90", "I135" in W·m⁻²·sr⁻¹, "DoLP" (1), "AoP" (rad),
    and "stderr_S0" (the per-pixel Monte Carlo standard error of S0); each equal to the
    corresponding TIFF of ``irpol render``.

    Overrides: `resolution` (width, height in pixels; ``camera.resolution``), `samples`, `seed`,
    `bounces` (``[render]``). `patch` maps dotted scene keys (``"sun.elevation_deg"``,
    ``"objects.0.parts.hood.temperature_k"``; they must exist in the file) to values. `time_s`
    renders a scene with ``[thermal]`` at that many seconds from ``thermal.start_utc``. With
    `out`, every file of ``irpol render`` is also written there (atomically) and the dict holds
    "summary" (``summary.json`` as a dict). `thermal_solution` is a run saved by
    :func:`solve_thermal` to take the temperatures at `time_s` from instead of solving the run
    again: the same images bit for bit; a file made for other thermal inputs (its key is not the
    scene's, :func:`thermal_keys`), damaged or missing raises ValueError or OSError naming it.
    `threads` renders on that many threads instead of one per core (the same images bit for bit):
    processes rendering side by side each take their share of the cores.
    Raises OSError or ValueError.
    """
    if thermal_solution is not None and time_s is None:
        raise ValueError("thermal_solution needs time_s: the instant of the run to render")
    overrides = []
    if resolution is not None:
        width, height = resolution
        overrides.append(("camera.resolution", [int(width), int(height)]))
    for key, value in (("samples", samples), ("seed", seed), ("bounces", bounces)):
        if value is not None:
            overrides.append((f"render.{key}", int(value)))
    images = _irpol.render_scene(
        os.fspath(scene),
        patch=list((patch or {}).items()),
        overrides=overrides,
        time_s=None if time_s is None else float(time_s),
        out=None if out is None else os.fspath(out),
        thermal_solution=None if thermal_solution is None else os.fspath(thermal_solution),
        threads=None if threads is None else int(threads),
    )
    if "summary" in images:
        images["summary"] = json.loads(images["summary"])
    return images


def thermal_keys(
    scene: Union[str, "os.PathLike[str]"],
    times_s: Sequence[float],
    *,
    patch: Optional[Mapping[str, Any]] = None,
) -> List[str]:
    """The key of the thermal run that rendering the scene (with `patch`) at each of `times_s`
    (seconds from ``thermal.start_utc``) needs: a SHA-256 (hex) of everything that determines the
    run — the ``[thermal]`` section and its weather, the mesh and the parts' stacks, the
    environment — and of the run's sample instants, but not of the camera, sensor or render
    settings. Renders with equal keys can share one :func:`solve_thermal`. An instant between the
    run's own time steps gets a key of its own (solving for it changes the steps around it).
    Raises ValueError for a scene without ``[thermal]`` or an instant outside the run."""
    return _irpol.thermal_keys(os.fspath(scene), [float(t) for t in times_s],
                               patch=list((patch or {}).items()))


def solve_thermal(
    scene: Union[str, "os.PathLike[str]"],
    times_s: Sequence[float],
    out: Union[str, "os.PathLike[str]"],
    *,
    patch: Optional[Mapping[str, Any]] = None,
    threads: Optional[int] = None,
) -> str:
    """Solves the scene's thermal run (with `patch`) recording `times_s`, which must share one
    key (:func:`thermal_keys`), and saves it to the file `out` (atomically; kept as it is when it
    already holds that run with those instants). Returns the key. ``render(…, time_s=t,
    thermal_solution=out)`` then renders any of `times_s` without solving again. `threads` solves
    on that many threads instead of one per core."""
    return _irpol.solve_thermal(os.fspath(scene), [float(t) for t in times_s], os.fspath(out),
                                patch=list((patch or {}).items()),
                                threads=None if threads is None else int(threads))
