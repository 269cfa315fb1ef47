"""`irpol.render`: `irpol render` in memory, numpy images out."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Mapping, Optional, Tuple, Union

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
    "summary" (``summary.json`` as a dict). Raises OSError or ValueError.
    """
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
    )
    if "summary" in images:
        images["summary"] = json.loads(images["summary"])
    return images
