"""irpol.dataset: a 40-item sweep on a 2-worker LocalCluster, a worker killed mid-run, a rerun
that does nothing, an external dask-scheduler + dask-worker giving the same manifest, and bad
specs, failing items and an unreachable scheduler with clear messages."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

distributed = pytest.importorskip("distributed")

from irpol.dataset import SpecError, run  # noqa: E402
from irpol.dataset.items import hashes  # noqa: E402
from conftest import cli_output, report  # noqa: E402

# summary.json records wall-clock timings: it differs between any two runs of an item.
VOLATILE = {"summary.json"}


def _write_spec(folder: Path, grid: str, name: str = "spec.toml") -> Path:
    spec = folder / name
    spec.write_text('kind = "render"\nscene = "scene.toml"\nout = "dataset"\n'
                    '[render]\nresolution = [16, 12]\nsamples = 1\n[grid]\n' + grid)
    return spec


@pytest.fixture()
def sweep_folder(tmp_path):
    cli_output("scene", "init", "--out", tmp_path / "scene.toml")
    return tmp_path


GRID_40 = ('"sun.elevation_deg" = [5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0]\n'
           '"objects.0.temperature_k" = [295.0, 300.0, 305.0, 310.0]\n')


def _rows(out: Path) -> list:
    return [json.loads(l) for l in (out / "manifest.jsonl").read_text().splitlines()]


def _check_complete(out: Path, count: int) -> list:
    rows = _rows(out)
    assert sorted(r["item"] for r in rows) == list(range(count))  # one row per item
    assert all(r["status"] == "ok" for r in rows), [r["error"] for r in rows]
    assert sorted(p.name for p in (out / "items").iterdir()) == sorted(map(str, range(count)))
    for r in rows:
        assert hashes(out / "items" / str(r["item"])) == r["outputs"]
    return rows


def test_sweep_survives_a_killed_worker_and_reruns_nothing(sweep_folder):
    spec = _write_spec(sweep_folder, GRID_40)
    out = sweep_folder / "dataset"
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        result = {}
        thread = threading.Thread(target=lambda: result.update(
            summary=run(spec, scheduler=cluster.scheduler_address, progress=False)))
        start = time.perf_counter()
        thread.start()
        while thread.is_alive() and not ((out / "manifest.jsonl").exists()
                                         and len(_rows(out)) >= 8):
            time.sleep(0.05)
        rows_at_kill = len(_rows(out)) if (out / "manifest.jsonl").exists() else 0
        pids = client.run(os.getpid)
        victim = sorted(pids.values())[0]
        os.kill(victim, signal.SIGKILL)
        thread.join(timeout=600)
        seconds = time.perf_counter() - start
    summary = result["summary"]
    assert (summary.items, summary.ok, summary.failed) == (40, 40, 0)
    rows = _check_complete(out, 40)
    assert rows_at_kill < 40, "the sweep ended before the worker was killed"
    report(f"dataset: 40 items on a 2-worker LocalCluster, one worker killed after "
           f"{rows_at_kill} items: {seconds:.1f} s, {len(rows)} rows, all ok")
    manifest = (out / "manifest.jsonl").read_bytes()
    start = time.perf_counter()
    again = run(spec, progress=False)
    assert (again.skipped, again.ok, again.failed) == (40, 0, 0)
    assert (out / "manifest.jsonl").read_bytes() == manifest
    report(f"dataset: rerun of the finished 40-item sweep: {time.perf_counter() - start:.2f} s, "
           "no task")


def test_sweep_on_a_local_cluster_completes(sweep_folder):
    spec = _write_spec(sweep_folder, GRID_40)
    start = time.perf_counter()
    summary = run(spec, workers=2, progress=False)
    assert (summary.items, summary.ok, summary.failed) == (40, 40, 0)
    _check_complete(sweep_folder / "dataset", 40)
    report(f"dataset: 40 items on a 2-worker LocalCluster: {time.perf_counter() - start:.1f} s")


def _comparable(rows):
    return sorted(({**r, "seconds": None,
                    "outputs": {k: v for k, v in r["outputs"].items() if k not in VOLATILE}}
                   for r in rows), key=lambda r: r["item"])


def test_external_scheduler_gives_the_same_manifest(sweep_folder, tmp_path_factory):
    grid = '"sun.elevation_deg" = [10.0, 40.0]\n"camera.fov_deg" = [25.0, 30.0, 35.0]\n'
    spec = _write_spec(sweep_folder, grid)
    run(spec, workers=2, progress=False)
    local = _rows(sweep_folder / "dataset")
    shutil.rmtree(sweep_folder / "dataset")
    folder = tmp_path_factory.mktemp("dask")
    scheduler_file = folder / "scheduler.json"
    bin_dir = Path(sys.executable).parent
    scheduler = subprocess.Popen([str(bin_dir / "dask"), "scheduler", "--no-dashboard", "--port",
                                  "0", "--scheduler-file", str(scheduler_file)],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    worker = None
    try:
        deadline = time.time() + 60
        while not scheduler_file.exists() and time.time() < deadline:
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        worker = subprocess.Popen([str(bin_dir / "dask"), "worker", address, "--nthreads", "1",
                                   "--nworkers", "1", "--no-dashboard"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        summary = run(spec, scheduler=address, progress=False)
    finally:
        for process in (worker, scheduler):
            if process is not None:
                process.terminate()
                process.wait(timeout=30)
    assert (summary.ok, summary.failed) == (6, 0)
    assert _comparable(_rows(sweep_folder / "dataset")) == _comparable(local)


# An item rendered alone, in a fresh process (nothing loaded or built before it).
RENDER_ALONE = """import json, sys
import irpol
irpol.render(sys.argv[1], patch=json.loads(sys.argv[2]), resolution=(16, 12), samples=1,
             out=sys.argv[3])
"""


def test_a_sweep_renders_its_items_bit_for_bit_as_one_process_does(sweep_folder):
    """The workers of a LocalCluster render on their share of the cores (two workers on two
    cores: one thread each) and reuse the tables of their last render where only the camera
    changed (a worker gets every other item: both build the tables of 295 K, one reuses them,
    both build those of 305 K, the other reuses them); each item rendered alone in a fresh
    process on a thread per core writes the same files but the timings, and so does each
    rendered here on one thread."""
    import os

    import irpol
    from irpol.dataset.runner import render_threads

    cores = len(os.sched_getaffinity(0))
    assert render_threads(None, 2) == max(1, cores // 2)
    assert render_threads("tcp://127.0.0.1:8786", 2) is None
    grid = '"objects.0.temperature_k" = [295.0, 305.0]\n"camera.fov_deg" = [25.0, 30.0, 35.0]\n'
    summary = run(_write_spec(sweep_folder, grid), workers=2, progress=False)
    assert (summary.ok, summary.failed) == (6, 0)
    scene = sweep_folder / "scene.toml"
    for row in _rows(sweep_folder / "dataset"):
        alone = sweep_folder / "alone" / str(row["item"])
        subprocess.run([sys.executable, "-c", RENDER_ALONE, str(scene), json.dumps(row["params"]),
                        str(alone)], check=True)
        expected = {k: v for k, v in hashes(alone).items() if k not in VOLATILE}
        assert {k: v for k, v in row["outputs"].items() if k not in VOLATILE} == expected
        one_thread = sweep_folder / "one_thread" / str(row["item"])
        irpol.render(scene, patch=row["params"], resolution=(16, 12), samples=1, threads=1,
                     out=one_thread)
        assert {k: v for k, v in hashes(one_thread).items() if k not in VOLATILE} == expected
    with pytest.raises(ValueError, match="threads must be at least 1"):
        irpol.render(scene, resolution=(16, 12), samples=1, threads=0)


def test_bad_specs_are_refused_before_any_work(sweep_folder):
    out = sweep_folder / "dataset"
    spec = sweep_folder / "unknown.toml"
    spec.write_text('kind = "render"\nscene = "scene.toml"\nout = "dataset"\nsamples = 3\n'
                    '[grid]\n"sun.elevation_deg" = [10.0]\n')
    with pytest.raises(SpecError, match="unknown key 'samples'"):
        run(spec, progress=False)
    with pytest.raises(SpecError, match=r"\[grid\] is empty"):
        run(_write_spec(sweep_folder, "", "empty.toml"), progress=False)
    with pytest.raises(SpecError, match="grid key 'sun.elevation_deg' needs a non-empty list"):
        run(_write_spec(sweep_folder, '"sun.elevation_deg" = []\n', "e2.toml"), progress=False)
    with pytest.raises(SpecError, match="scene key 'sun.elevation_dg': no 'elevation_dg' in 'sun'"):
        run(_write_spec(sweep_folder, '"sun.elevation_dg" = [10.0]\n', "typo.toml"),
            progress=False)
    assert not out.exists()
    done = subprocess.run([sys.executable, "-m", "irpol.dataset", str(spec)],
                          capture_output=True, text=True)
    assert done.returncode == 2
    assert done.stderr.strip().startswith("irpol.dataset: error: ") and "'samples'" in done.stderr


def test_a_failing_item_is_recorded_and_the_rest_kept(sweep_folder):
    spec = _write_spec(sweep_folder, '"camera.fov_deg" = [30.0, 300.0, 35.0]\n')
    summary = run(spec, workers=2, progress=False)
    assert (summary.ok, summary.failed) == (2, 1)
    rows = {r["item"]: r for r in _rows(sweep_folder / "dataset")}
    assert rows[1]["status"] == "failed" and "fov" in rows[1]["error"]
    assert rows[1]["error"].startswith("ValueError: ")
    assert rows[0]["status"] == rows[2]["status"] == "ok"
    assert not (sweep_folder / "dataset" / "items" / "1").exists()


def test_an_unreachable_scheduler_is_a_clear_error(sweep_folder):
    spec = _write_spec(sweep_folder, '"sun.elevation_deg" = [10.0]\n')
    with pytest.raises(SpecError, match="cannot reach the Dask scheduler at tcp://127.0.0.1:9"):
        run(spec, scheduler="tcp://127.0.0.1:9", progress=False)


def test_a_fit_sweep_writes_one_material_per_item(tmp_path):
    from conftest import ROOT

    for name in ("rough_paint.csv", "anodized_panel.csv"):
        shutil.copy(ROOT / "measurements" / name, tmp_path / name)
    spec = tmp_path / "fit.toml"
    spec.write_text('kind = "fit"\ninputs = "*.csv"\nout = "fits"\n[options]\nseed = 3\n')
    summary = run(spec, workers=2, progress=False)
    assert (summary.items, summary.ok, summary.failed) == (2, 2, 0)
    rows = sorted(_rows(tmp_path / "fits"), key=lambda r: r["item"])
    assert [r["params"]["material"] for r in rows] == ["anodized_panel", "rough_paint"]
    assert list(rows[1]["outputs"]) == ["rough_paint.toml"]
    bad = tmp_path / "bad.toml"
    bad.write_text('kind = "fit"\ninputs = "*.csv"\nout = "fits"\n[options]\nsead = 3\n')
    with pytest.raises(SpecError, match="unknown key 'sead' in \\[options\\]"):
        run(bad, progress=False)
