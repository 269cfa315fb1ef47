"""One item of a sweep, as a Dask task runs it: its outputs written into a temporary folder,
hashed, then renamed to ``out/items/<i>/`` in one step. Workers never write the manifest."""

from __future__ import annotations

import hashlib
import os
import shutil
import time
import uuid
from pathlib import Path
from typing import Any, Dict

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


def _render(job: Dict[str, Any], params: Dict[str, Any], folder: Path) -> None:
    patch = {k: v for k, v in params.items() if k != TIME_KEY}
    irpol.render(job["scene"], patch=patch, time_s=params.get(TIME_KEY), out=folder,
                 **job["render"])


def _fit(job: Dict[str, Any], params: Dict[str, Any], folder: Path) -> None:
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


def run_item(job: Dict[str, Any], index: int, params: Dict[str, Any]) -> Dict[str, Any]:
    """Runs item `index` and returns its manifest row; raises on failure (Dask retries it)."""
    start = time.perf_counter()
    out = Path(job["out"])
    final = item_folder(out, index)
    staging = final.with_name(f".{index}.tmp-{uuid.uuid4().hex}")
    staging.parent.mkdir(parents=True, exist_ok=True)
    try:
        (_render if job["kind"] == "render" else _fit)(job, params, staging)
        outputs = hashes(staging)
        _publish(staging, final)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return {"item": index, "params": params, "status": "ok", "error": None, "outputs": outputs,
            "seconds": round(time.perf_counter() - start, 6)}
