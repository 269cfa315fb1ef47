"""One item of a sweep, as a Dask task runs it: its outputs written into a temporary folder,
hashed, then renamed to ``out/items/<i>/`` in one step; and the thermal run that the renders at
instants of one thermal configuration share, saved once to ``out/thermal/<key>.bin``. Workers
never write the manifest."""

from __future__ import annotations

import hashlib
import os
import shutil
import time
import uuid
from pathlib import Path
from typing import Any, Dict, List, Optional

import irpol

from .spec import TIME_KEY


def sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def hashes(folder: Path) -> Dict[str, str]:
    """SHA-256 of every file under `folder`, by path relative to it."""
    return {p.relative_to(folder).as_posix(): sha256(p)
            for p in sorted(folder.rglob("*")) if p.is_file()}


def item_folder(out: Path, index: int) -> Path:
    return out / "items" / str(index)


def thermal_path(out: Path, key: str) -> Path:
    return out / "thermal" / f"{key}.bin"


def scene_patch(params: Dict[str, Any]) -> Dict[str, Any]:
    """The scene keys an item changes (its grid values but the instant)."""
    return {k: v for k, v in params.items() if k != TIME_KEY}


def solve_thermal(job: Dict[str, Any], key: str, patch: Dict[str, Any],
                  times: List[float]) -> str:
    """Solves and saves the thermal run `key` (the scene with `patch`, recording `times`) and
    returns `key`; the renders that need it wait for this task."""
    path = thermal_path(Path(job["out"]), key)
    solved = irpol.solve_thermal(job["scene"], times, path, patch=patch)
    if solved != key:  # the scene or a file it reads changed since the sweep was planned
        raise ValueError(f"{path}: the scene's thermal inputs changed during the sweep (key "
                         f"{solved[:12]}, planned {key[:12]}): run the sweep again")
    return key


def _render(job: Dict[str, Any], params: Dict[str, Any], folder: Path,
            thermal: Optional[str]) -> None:
    solution = None if thermal is None else thermal_path(Path(job["out"]), thermal)
    irpol.render(job["scene"], patch=scene_patch(params), time_s=params.get(TIME_KEY), out=folder,
                 thermal_solution=solution, threads=job.get("threads"), **job["render"])


def _fit(job: Dict[str, Any], params: Dict[str, Any], folder: Path,
         _thermal: Optional[str]) -> None:
    base = Path(job["spec_dir"])
    [result] = irpol.fit([base / f for f in params["files"]], **job["options"])
    folder.mkdir(parents=True)
    (folder / f"{result.name}.toml").write_text(result.toml)


def _publish(staging: Path, final: Path) -> None:
    """Replaces `final` with `staging` (a task that ran twice leaves the same files)."""
    if final.exists():
        old = final.with_name(f".{final.name}.old-{uuid.uuid4().hex}")
        os.rename(final, old)
        shutil.rmtree(old, ignore_errors=True)
    os.rename(staging, final)


def run_item(job: Dict[str, Any], index: int, params: Dict[str, Any],
             thermal: Optional[str] = None) -> Dict[str, Any]:
    """Runs item `index` and returns its manifest row; raises on failure (Dask retries it).
    `thermal` is the key of the saved thermal run a render takes its temperatures from (the
    result of its :func:`solve_thermal` task), None to solve the run itself (or none needed)."""
    start = time.perf_counter()
    out = Path(job["out"])
    final = item_folder(out, index)
    staging = final.with_name(f".{index}.tmp-{uuid.uuid4().hex}")
    staging.parent.mkdir(parents=True, exist_ok=True)
    try:
        (_render if job["kind"] == "render" else _fit)(job, params, staging, thermal)
        outputs = hashes(staging)
        _publish(staging, final)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return {"item": index, "params": params, "status": "ok", "error": None, "outputs": outputs,
            "thermal": thermal, "seconds": round(time.perf_counter() - start, 6)}
