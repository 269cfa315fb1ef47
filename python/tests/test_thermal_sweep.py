"""Renders at instants of a thermal scene from one saved run (docs/design.md §2.7): a sweep solves
each distinct run once, every item's images are those of the item rendered alone (solving its own
run), the manifest names the run each item used, and a saved run made for other inputs, damaged
or missing is refused with a message naming it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import irpol

PLATE = """[camera]
position = [6.0, -6.0, 3.0]
look_at = [0.0, 0.0, 0.5]
fov_deg = 40.0
resolution = [16, 12]

[render]
samples = 4

[environment]
air_temperature_k = 290.0
sky = { model = "window", zenith_emissivity = 0.75 }
ground = { temperature_k = 290.0, emissivity = 0.95 }

[materials.paint]
distribution = "cauchy"
sigma = 0.2
q = 2.0
n = 1.5
k = 0.2

[thermal]
weather = { clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }
start_utc = "2026-06-21T00:00:00Z"
latitude_deg = 48.14
longitude_deg = 11.58
output_step_s = 3600
duration_h = 2

[thermal.layers.steel]
conductivity_w_mk = 45.0
density_kg_m3 = 7850.0
heat_capacity_j_kgk = 470.0

[[objects]]
name = "plate"
shape = { kind = "plane", size = [0.5, 0.5], divisions = [2, 2] }
material = "paint"
[objects.thermal]
stack = [["steel", 0.001]]
solar_absorptance = 0.6
"""

VIEWS = [[6.0, -6.0, 3.0], [-6.0, 6.0, 3.0]]
# summary.json records wall-clock timings and the staging folder: it differs between two runs.
VOLATILE = {"summary.json"}


@pytest.fixture()
def plate(tmp_path) -> Path:
    scene = tmp_path / "plate.toml"
    scene.write_text(PLATE)
    return scene


def _spec(folder: Path, times: str) -> Path:
    spec = folder / "spec.toml"
    spec.write_text('kind = "render"\nscene = "plate.toml"\nout = "dataset"\n'
                    '[render]\nresolution = [16, 12]\nsamples = 1\n[grid]\n'
                    f'time_s = {times}\n"camera.position" = {json.dumps(VIEWS)}\n')
    return spec


def _rows(out: Path) -> dict:
    lines = (out / "manifest.jsonl").read_text().splitlines()
    return {r["item"]: r for r in map(json.loads, lines)}


def test_a_sweep_solves_each_run_once_and_renders_as_each_item_alone(plate, tmp_path):
    distributed = pytest.importorskip("distributed")  # noqa: F841
    from irpol.dataset import run
    from irpol.dataset.items import hashes

    # 0, 3600 and 7200 s are on the run's sample grid (one run records them all); 1234.5 s is not.
    summary = run(_spec(tmp_path, "[0, 3600, 1234.5, 7200]"), workers=2, progress=False)
    assert (summary.items, summary.ok, summary.failed) == (8, 8, 0)
    out = tmp_path / "dataset"
    rows = _rows(out)
    on_grid = {rows[i]["thermal"] for i in rows if rows[i]["params"]["time_s"] != 1234.5}
    off_grid = {rows[i]["thermal"] for i in rows if rows[i]["params"]["time_s"] == 1234.5}
    assert len(on_grid) == 1 and len(off_grid) == 1 and on_grid != off_grid, rows
    runs = sorted(p.name for p in (out / "thermal").iterdir())
    assert runs == sorted(f"{k}.bin" for k in on_grid | off_grid)
    for index, row in rows.items():
        params = row["params"]
        patch = {"camera.position": params["camera.position"]}
        assert irpol.thermal_keys(plate, [params["time_s"]], patch=patch) == [row["thermal"]]
        alone = tmp_path / "alone" / str(index)
        irpol.render(plate, patch=patch, time_s=params["time_s"], resolution=(16, 12),
                     samples=1, out=alone)
        expected = {k: v for k, v in hashes(alone).items() if k not in VOLATILE}
        got = {k: v for k, v in row["outputs"].items() if k not in VOLATILE}
        assert got == expected, index
    # A rerun finds every item done and solves nothing.
    solved = {p: p.stat().st_mtime_ns for p in (out / "thermal").iterdir()}
    again = run(_spec(tmp_path, "[0, 3600, 1234.5, 7200]"), workers=2, progress=False)
    assert (again.skipped, again.ok, again.failed) == (8, 0, 0)
    assert {p: p.stat().st_mtime_ns for p in (out / "thermal").iterdir()} == solved


def test_an_instant_outside_the_run_fails_alone(plate, tmp_path):
    pytest.importorskip("distributed")
    from irpol.dataset import run

    summary = run(_spec(tmp_path, "[3600, 9000]"), workers=2, progress=False)
    assert (summary.ok, summary.failed) == (2, 2)
    rows = _rows(tmp_path / "dataset")
    for row in rows.values():
        if row["params"]["time_s"] == 9000:
            assert row["status"] == "failed" and row["thermal"] is None
            assert "thermal time 9000 s is outside the run 0…7200 s" in row["error"], row
        else:
            assert row["status"] == "ok" and len(row["thermal"]) == 64


def test_a_saved_run_renders_the_same_images_and_a_foreign_one_is_refused(plate, tmp_path):
    saved = tmp_path / "run.bin"
    key = irpol.solve_thermal(plate, [7200, 3600], saved)
    assert irpol.thermal_keys(plate, [3600.0, 7200.0]) == [key, key]
    for time_s in (3600.0, 7200.0):
        alone = irpol.render(plate, time_s=time_s, samples=1)
        shared = irpol.render(plate, time_s=time_s, samples=1, thermal_solution=saved)
        assert alone.keys() == shared.keys()
        for name in alone:
            assert np.array_equal(alone[name], shared[name], equal_nan=True), name
    # Another weather's scene: the run is refused, not used.
    warmer = {"thermal.weather.clear_day.air_max_k": 305.0}
    with pytest.raises(ValueError, match="solved for other thermal inputs") as error:
        irpol.render(plate, time_s=3600.0, patch=warmer, thermal_solution=saved)
    assert str(saved) in str(error.value)
    with pytest.raises(ValueError, match="records no t = 1800 s"):
        irpol.render(plate, time_s=1800.0, thermal_solution=saved)
    damaged = tmp_path / "damaged.bin"
    data = bytearray(saved.read_bytes())
    data[-5] ^= 0xFF
    damaged.write_bytes(bytes(data))
    with pytest.raises(ValueError, match="damaged thermal solution"):
        irpol.render(plate, time_s=3600.0, thermal_solution=damaged)
    with pytest.raises(OSError, match="cannot read the thermal solution"):
        irpol.render(plate, time_s=3600.0, thermal_solution=tmp_path / "missing.bin")
    with pytest.raises(ValueError, match="thermal_solution needs time_s"):
        irpol.render(plate, thermal_solution=saved)
    with pytest.raises(ValueError, match="need separate thermal runs"):
        irpol.solve_thermal(plate, [3600.0, 1234.5], tmp_path / "two.bin")
