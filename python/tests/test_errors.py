"""Errors raise by kind: a file that cannot be read is an OSError, input that is wrong a ValueError,
each with the message `irpol` prints after `irpol: error: ` for the same input."""

from __future__ import annotations

import pytest

import irpol
from conftest import cli_error, cli_output

MUELLER_CSV_HEADER = "theta_i_deg,theta_r_deg,m00\n"


@pytest.fixture
def starter_scene(tmp_path):
    """`irpol scene init`'s scene in a fresh folder (procedural shapes, no other file)."""
    path = tmp_path / "scene.toml"
    cli_output("scene", "init", "--out", path)
    return path


def raised_by(kind, call, *args):
    with pytest.raises(kind) as raised:
        call(*args)
    return str(raised.value)


def test_a_scene_whose_mesh_is_missing_raises_oserror(starter_scene, tmp_path):
    text = starter_scene.read_text()
    sphere = 'shape = { kind = "sphere", radius = 0.5, subdivisions = 5 }'
    assert sphere in text
    starter_scene.write_text(text.replace(sphere, 'mesh = "missing.obj"'))
    message = cli_error("render", starter_scene, "--out", tmp_path / "out")
    assert "missing.obj" in message
    assert raised_by(OSError, irpol.render, starter_scene) == message


def test_a_scene_with_an_unknown_key_raises_valueerror(starter_scene, tmp_path):
    starter_scene.write_text("colour = \"red\"\n" + starter_scene.read_text())
    message = cli_error("render", starter_scene, "--out", tmp_path / "out")
    assert "colour" in message
    assert raised_by(ValueError, irpol.render, starter_scene) == message


def test_a_missing_measurement_file_raises_oserror(tmp_path):
    missing = tmp_path / "missing.csv"
    message = cli_error("fit", missing, "--out", tmp_path / "f", "--reports", tmp_path / "r")
    assert raised_by(OSError, irpol.read_measurements, missing) == message


def test_a_malformed_measurement_csv_raises_valueerror(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text(MUELLER_CSV_HEADER + "10,20,abc\n")
    message = cli_error("fit", bad, "--out", tmp_path / "f", "--reports", tmp_path / "r")
    assert raised_by(ValueError, irpol.read_measurements, bad) == message


def test_a_material_with_an_unknown_key_raises_valueerror(tmp_path):
    material = tmp_path / "paint.toml"
    material.write_text(
        'name = "paint"\n\n[model]\ndistribution = "cauchy"\nsigma = 0.2\nq = 2.0\n'
        'shadowing = "smith"\nn = 1.5\nk = 0.1\nrho = 0.5\nwavelength_um = 10.0\n'
    )
    message = cli_error("eval", "--material", material, "--theta-i", "10", "--theta-r", "20")
    assert "rho" in message
    assert raised_by(ValueError, irpol.Material.load, material) == message


def test_a_missing_material_file_raises_oserror(tmp_path):
    missing = tmp_path / "missing.toml"
    message = cli_error("eval", "--material", missing, "--theta-i", "10", "--theta-r", "20")
    assert raised_by(OSError, irpol.Material.load, missing) == message
