"""Runs a sweep's unfinished items on Dask distributed and records each in the manifest. Renders
at instants of a thermal scene share its runs: one task per distinct run solves and saves it, and
the renders that need it depend on that task instead of each solving the run again."""

from __future__ import annotations

import os
import shutil
import uuid
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, Iterator, List, Optional, Tuple

import irpol

from .items import run_item, scene_patch, solve_thermal
from .manifest import Manifest
from .spec import TIME_KEY, Item, Spec, SpecError, load_spec

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


def _cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def render_threads(scheduler: Optional[str], workers: Optional[int]) -> Optional[int]:
    """Threads per render on a LocalCluster of `workers` processes: its share of the cores, so
    that workers × threads ≤ cores (each render otherwise starts a thread per core, and the
    workers' threads oversubscribe the machine). None (one per core) on an external scheduler,
    whose workers' machines this process does not know."""
    if scheduler is not None:
        return None
    return max(1, _cores() // (workers or 2))


def _job(spec: Spec, threads: Optional[int]) -> dict:
    """What a task needs of the spec, as plain data (sent to every worker)."""
    return {"kind": spec.kind, "out": str(spec.out.resolve()),
            "scene": None if spec.scene is None else str(spec.scene.resolve()),
            "render": spec.render, "options": spec.options,
            "spec_dir": str(spec.path.parent.resolve()), "threads": threads}


def _failed_row(index: int, params: dict, error: BaseException, thermal: Optional[str]) -> dict:
    message = str(error).strip() or type(error).__name__
    return {"item": index, "params": params, "status": "failed",
            "error": f"{type(error).__name__}: {message}", "outputs": {}, "thermal": thermal,
            "seconds": None}


@dataclass
class ThermalPlan:
    """Which saved thermal run each render at an instant takes its temperatures from (by item
    index), and per run the scene keys to solve it with and the instants it records."""

    key_of: Dict[int, str]
    runs: Dict[str, Tuple[dict, List[float]]]


def _run_keys(spec: Spec, items: List[Item], patch: dict) -> List[Optional[str]]:
    """The run key of each item (all with scene keys `patch`); None for an item refused here (an
    instant outside the run, a scene that does not load), which then solves for itself and fails
    with its own error as it would without the plan."""
    def keys(group: List[Item]) -> List[str]:
        return irpol.thermal_keys(spec.scene, [it.params[TIME_KEY] for it in group], patch=patch)

    try:
        return keys(items)
    except (ValueError, OSError, TypeError):
        if len(items) == 1:
            return [None]
        return [_run_keys(spec, [item], patch)[0] for item in items]


def _thermal_plan(spec: Spec, todo: List[Item]) -> ThermalPlan:
    """Items with the same scene keys share a scene; its run keys (irpol.thermal_keys) group
    their instants, and equal keys across scenes (other viewpoints) share a run too."""
    plan = ThermalPlan(key_of={}, runs={})
    if spec.kind != "render" or TIME_KEY not in spec.grid:
        return plan
    scenes: Dict[str, List[Item]] = {}
    for item in todo:
        scenes.setdefault(repr(sorted(scene_patch(item.params).items())), []).append(item)
    for items in scenes.values():
        patch = scene_patch(items[0].params)
        for item, key in zip(items, _run_keys(spec, items, patch)):
            if key is None:
                continue
            plan.key_of[item.index] = key
            _, times = plan.runs.setdefault(key, (patch, []))
            if item.params[TIME_KEY] not in times:
                times.append(item.params[TIME_KEY])
    return plan


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
        job, run_id = _job(spec, render_threads(scheduler, workers)), uuid.uuid4().hex[:12]
        plan = _thermal_plan(spec, todo)
        with dask_client(scheduler, workers) as client:
            # A render's argument is its run's future: Dask starts it once the run is saved.
            solves = {key: client.submit(solve_thermal, job, key, patch, sorted(times),
                                         retries=RETRIES, pure=False,
                                         key=f"irpol-thermal-{key[:16]}-{run_id}")
                      for key, (patch, times) in plan.runs.items()}
            # In grid order (the last key varies fastest): a worker's next item then mostly
            # differs from its last in a camera key only and reuses its tables.
            futures = {client.submit(run_item, job, it.index, it.params,
                                     solves.get(plan.key_of.get(it.index)), retries=RETRIES,
                                     pure=False, priority=-it.index,
                                     key=f"irpol-item-{it.index}-{run_id}"): it
                       for it in todo}
            bar = _progress(len(todo), progress)
            for future in as_completed(futures):
                item = futures.pop(future)
                try:
                    row = future.result()
                    ok += 1
                except Exception as error:  # the item's (or its run's) failure, after a retry
                    row = _failed_row(item.index, item.params, error,
                                      plan.key_of.get(item.index))
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
