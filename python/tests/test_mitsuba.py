"""irpol.export_pbsdf / read_pbsdf (docs/mitsuba.md): the same file as `irpol export --to
mitsuba`, its fields as arrays, and the table read back as measurements."""

from __future__ import annotations

import numpy as np
import pytest

import irpol
from conftest import ROOT, cli_output

MATERIAL = ROOT / "fits" / "rough_paint.toml"


def test_export_matches_the_cli_and_reads_back(tmp_path):
    written = irpol.export_pbsdf(MATERIAL, tmp_path / "py.pbsdf", grid=(9, 7, 11))
    assert written["grid"] == [9, 7, 11]
    assert written["wavelengths_nm"] == [8000, 9000, 10000, 11000, 12000]
    cli_output("export", MATERIAL, "--to", "mitsuba", "--out", tmp_path / "cli.pbsdf",
               "--grid", "9,7,11")
    assert (tmp_path / "py.pbsdf").read_bytes() == (tmp_path / "cli.pbsdf").read_bytes()
    table = irpol.read_pbsdf(tmp_path / "py.pbsdf")
    assert table["M"].shape == (9, 7, 11, 5, 4, 4) and table["M"].dtype == np.float32
    assert np.all(np.isfinite(table["M"]))
    assert table["phi_d"][0] == pytest.approx(-np.pi) and table["phi_d"][-1] == pytest.approx(np.pi)
    sets = irpol.read_measurements(tmp_path / "py.pbsdf")
    assert [s.wavelength_um for s in sets] == [8.0, 9.0, 10.0, 11.0, 12.0]


def test_refusals_name_the_flag_or_field(tmp_path):
    with pytest.raises(ValueError, match="reads exactly 5 wavelengths"):
        irpol.export_pbsdf(MATERIAL, tmp_path / "a.pbsdf", wavelengths_nm=[8000, 9000])
    (tmp_path / "bad.pbsdf").write_bytes(b"tensor_file\0\x01\x00" + b"\x00" * 4)
    with pytest.raises(ValueError, match="field 'phi_d': missing"):
        irpol.read_pbsdf(tmp_path / "bad.pbsdf")
    assert not (tmp_path / "a.pbsdf").exists()
