"""Runs a sweep's unfinished items on Dask distributed and records each in the manifest."""

from __future__ import annotations

import shutil
import uuid
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator, Optional

from .items import run_item
from .manifest import Manifest
from .spec import Spec, SpecError, load_spec

# A failed item is run once more before it is recorded as failed.
RETRIES = 1


@dataclass
class RunSummary:
    items: int
    skipped: int
    ok: int
    failed: int
    seconds: float


@contextmanager
def dask_client(scheduler: Optional[str], workers: Optional[int]) -> Iterator[object]:
    """A client of the scheduler at `scheduler`, or of a LocalCluster of `workers` processes."""
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as e:
            raise SpecError(f"cannot reach the Dask scheduler at {scheduler}: {e}") from None
        with client:
            yield client
        return
    with LocalCluster(n_workers=workers or 2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        yield client


def _job(spec: Spec) -> dict:
    """What a task needs of the spec, as plain data (sent to every worker)."""
    return {"kind": spec.kind, "out": str(spec.out.resolve()),
            "scene": None if spec.scene is None else str(spec.scene.resolve()),
            "render": spec.render, "options": spec.options,
            "spec_dir": str(spec.path.parent.resolve())}


def _failed_row(index: int, params: dict, error: BaseException) -> dict:
    message = str(error).strip() or type(error).__name__
    return {"item": index, "params": params, "status": "failed",
            "error": f"{type(error).__name__}: {message}", "outputs": {}, "seconds": None}


def _progress(total: int, enabled: bool):
    try:
        from tqdm import tqdm
    except ImportError:
        tqdm = None
    if not enabled or tqdm is None:
        return None
    return tqdm(total=total, unit="item", desc="sweep")


def _remove_staging(out: Path) -> None:
    """Temporary folders of tasks that died (a killed worker) are not outputs."""
    for stale in (out / "items").glob(".*"):
        shutil.rmtree(stale, ignore_errors=True)


def run(spec_path, scheduler: Optional[str] = None, workers: Optional[int] = None,
        progress: bool = True) -> RunSummary:
    """Runs every unfinished item of the spec; returns what was done."""
    from distributed import as_completed

    start = time.perf_counter()
    spec = load_spec(spec_path)
    items = spec.items()
    manifest = Manifest(spec.out)
    done = manifest.finished(items, spec.out)
    todo = [item for item in items if item.index not in done]
    ok = failed = 0
    if todo:
        job, run_id = _job(spec), uuid.uuid4().hex[:12]
        with dask_client(scheduler, workers) as client:
            futures = {client.submit(run_item, job, it.index, it.params, retries=RETRIES,
                                     pure=False, key=f"irpol-item-{it.index}-{run_id}"): it
                       for it in todo}
            bar = _progress(len(todo), progress)
            for future in as_completed(futures):
                item = futures.pop(future)
                try:
                    row = future.result()
                    ok += 1
                except Exception as error:  # the item's own failure, after its retry
                    row = _failed_row(item.index, item.params, error)
                    failed += 1
                # Released once recorded: a result held by a worker that dies later would
                # otherwise be computed again, replacing the files the row describes.
                future.release()
                manifest.append(row)
                if bar is not None:
                    bar.update(1)
            if bar is not None:
                bar.close()
        _remove_staging(spec.out)
    return RunSummary(items=len(items), skipped=len(done), ok=ok, failed=failed,
                      seconds=time.perf_counter() - start)
