"""Cross-check of irpol's EPW and TMY3 readers and of the sun at a weather file's site against
pvlib (docs/design.md §2.5).

    .venv/bin/python scripts/crosscheck_weather.py [--irpol PATH] [--epw FILE] [--tmy3 FILE]

Default files: the shipped samples data/weather/munich_3days.epw and munich_3days_tmy3.csv.

1. `irpol weather FILE` prints every hourly row as irpol read it: the hour-ending label in UTC,
   the fields in SI units (°C, %, Pa, W/m², °, m/s, tenths; empty where missing), and irpol's sun
   at the label for the file's site. `pvlib.iotools.read_epw` (and `read_tmy3`) read the same
   file. Compared row by row: the label (pvlib's index, local standard time with the file's
   offset, converted to UTC, must equal irpol's), and every field: temp_air, temp_dew,
   relative_humidity, atmospheric_pressure (TMY3: mbar × 100), ghi_infrared (EPW only), ghi, dni,
   dhi, wind_direction, wind_speed, total_sky_cover, opaque_sky_cover. A value at its EPW missing
   marker (pvlib keeps it as a number) must be empty in irpol's; every other value equal within
   1e-9. The site (latitude, longitude, time zone, elevation) must equal pvlib's metadata.
2. `pvlib.solarposition.get_solarposition` (method nrel_numpy) at the same UTC instants and the
   file's latitude, longitude and altitude, with irpol's atmosphere (101325 Pa, 15 °C; irpol's sun
   is for the standard atmosphere at sea level, so pvlib is not given the station pressure):
   apparent elevation and azimuth within 0.01° where either elevation is above −0.5°.
3. Guard: the check must be able to fail. A copy of the EPW with one field changed (row 13's
   dry-bulb + 0.1 °C) must make the comparison fail.

Exit status 0 when everything passes, 1 on a failed check, 2 on a setup problem. The last line is
`N passed, M failed`.
"""

from __future__ import annotations

import argparse
import io
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np
import pandas as pd
import pvlib

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
TOLERANCE_DEG = 0.01
MIN_ELEVATION_DEG = -0.5
# irpol column: (pvlib read_epw column, EPW missing marker, read_tmy3 column with
# map_variables=False (the file's own names), TMY3 factor to irpol's unit)
FIELDS = {
    "temp_air": ("temp_air", 99.9, "Dry-bulb (C)", 1.0),
    "temp_dew": ("temp_dew", 99.9, "Dew-point (C)", 1.0),
    "relative_humidity": ("relative_humidity", 999, "RHum (%)", 1.0),
    "atmospheric_pressure": ("atmospheric_pressure", 999999, "Pressure (mbar)", 100.0),
    "ghi_infrared": ("ghi_infrared", 9999, None, 1.0),
    "ghi": ("ghi", 9999, "GHI (W/m^2)", 1.0),
    "dni": ("dni", 9999, "DNI (W/m^2)", 1.0),
    "dhi": ("dhi", 9999, "DHI (W/m^2)", 1.0),
    "wind_direction": ("wind_direction", 999, "Wdir (degrees)", 1.0),
    "wind_speed": ("wind_speed", 999, "Wspd (m/s)", 1.0),
    "total_sky_cover": ("total_sky_cover", 99, "TotCld (tenths)", 1.0),
    "opaque_sky_cover": ("opaque_sky_cover", 99, "OpqCld (tenths)", 1.0),
}


class SetupError(RuntimeError):
    """A problem with the inputs or the environment (exit status 2)."""


def irpol_hourly(irpol: str, path: str) -> tuple[dict, pd.DataFrame]:
    run = subprocess.run([irpol, "weather", path], capture_output=True, text=True)
    if run.returncode != 0:
        raise SetupError(f"irpol weather {path} failed: {run.stderr.strip()}")
    first, rest = run.stdout.split("\n", 1)
    site = dict(kv.split("=") for kv in first.lstrip("# ").split(","))
    table = pd.read_csv(io.StringIO(rest))
    table["time_utc"] = pd.to_datetime(table["time_utc"], utc=True)
    return {k: float(v) for k, v in site.items()}, table


def compare(irpol_site, irpol_rows, data, meta, tmy3: bool) -> list[str]:
    """Every difference between irpol's and pvlib's reading, as messages."""
    problems = []
    tz = "TZ"
    for ours, theirs in (("latitude_deg", "latitude"), ("longitude_deg", "longitude"),
                         ("time_zone_h", tz), ("elevation_m", "altitude")):
        if abs(irpol_site[ours] - float(meta[theirs])) > 1e-9:
            problems.append(f"site {ours}: irpol {irpol_site[ours]}, pvlib {meta[theirs]}")
    if len(irpol_rows) != len(data):
        return problems + [f"{len(irpol_rows)} rows in irpol, {len(data)} in pvlib"]
    # read_epw's index is the hour's start (0…23 h); the label is its end.
    index = data.index if tmy3 else data.index + pd.Timedelta(hours=1)
    labels = index.tz_convert("UTC")
    bad = np.nonzero(labels.values != irpol_rows["time_utc"].dt.tz_convert("UTC").values)[0]
    if len(bad):
        i = bad[0]
        problems.append(f"row {i}: label irpol {irpol_rows['time_utc'].iloc[i]}, pvlib {labels[i]}")
    for column, (epw_name, marker, tmy3_name, scale) in FIELDS.items():
        name = tmy3_name if tmy3 else epw_name
        if name is None:
            if irpol_rows[column].notna().any():
                problems.append(f"{column}: TMY3 has none, irpol read some")
            continue
        theirs = data[name].to_numpy(dtype=float) * (scale if tmy3 else 1.0)
        ours = irpol_rows[column].to_numpy(dtype=float)
        missing = theirs >= marker if not tmy3 else theirs == -9900 * scale
        wrong = (missing & ~np.isnan(ours)) | (~missing & ~(np.abs(ours - theirs) <= 1e-9))
        for i in np.nonzero(wrong)[0][:3]:
            problems.append(f"{column} row {i} (line {irpol_rows['line'].iloc[i]}): irpol "
                            f"{ours[i]}, pvlib {theirs[i]}")
    return problems


def sun_check(irpol_site, irpol_rows) -> tuple[float, float, int]:
    """Worst |Δ elevation| and |Δ azimuth| (°) against pvlib, and the instants compared."""
    times = pd.DatetimeIndex(irpol_rows["time_utc"])
    pos = pvlib.solarposition.get_solarposition(
        times, irpol_site["latitude_deg"], irpol_site["longitude_deg"],
        altitude=irpol_site["elevation_m"], pressure=101325.0, method="nrel_numpy",
        temperature=15.0)
    elev, az = irpol_rows["sun_elevation_deg"].to_numpy(), irpol_rows["sun_azimuth_deg"].to_numpy()
    p_elev, p_az = pos["apparent_elevation"].to_numpy(), pos["azimuth"].to_numpy()
    up = (elev > MIN_ELEVATION_DEG) | (p_elev > MIN_ELEVATION_DEG)
    d_elev = np.abs(elev - p_elev)[up]
    d_az = np.abs((az - p_az + 180.0) % 360.0 - 180.0)[up]
    return float(d_elev.max()), float(d_az.max()), int(up.sum())


def check_file(irpol: str, path: str, tmy3: bool) -> list[str]:
    site, rows = irpol_hourly(irpol, path)
    if tmy3:
        data, meta = pvlib.iotools.read_tmy3(path, map_variables=False)
    else:
        data, meta = pvlib.iotools.read_epw(path)
    problems = compare(site, rows, data, meta, tmy3)
    worst_elev, worst_az, count = sun_check(site, rows)
    print(f"  {os.path.basename(path)}: {len(rows)} rows; sun at {count} instants: worst "
          f"elevation {worst_elev:.2e}°, azimuth {worst_az:.2e}°")
    if worst_elev > TOLERANCE_DEG or worst_az > TOLERANCE_DEG:
        problems.append(f"sun: worst elevation {worst_elev}°, azimuth {worst_az}°")
    return problems


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--irpol", default=os.path.join(REPO, "target", "release", "irpol"))
    parser.add_argument("--epw", default=os.path.join(REPO, "data", "weather", "munich_3days.epw"))
    parser.add_argument("--tmy3",
                        default=os.path.join(REPO, "data", "weather", "munich_3days_tmy3.csv"))
    args = parser.parse_args()
    if not shutil.which(args.irpol) and not os.path.isfile(args.irpol):
        print(f"no irpol binary at {args.irpol}", file=sys.stderr)
        return 2
    passed = failed = 0
    try:
        for path, tmy3 in ((args.epw, False), (args.tmy3, True)):
            problems = check_file(args.irpol, path, tmy3)
            for p in problems:
                print(f"  FAIL {p}")
            passed, failed = passed + (not problems), failed + bool(problems)
        # Guard: a changed value must be caught.
        with tempfile.TemporaryDirectory() as tmp:
            lines = open(args.epw).read().split("\n")
            fields = lines[8 + 12].split(",")
            fields[6] = str(round(float(fields[6]) + 0.1, 1))
            lines[8 + 12] = ",".join(fields)
            changed = os.path.join(tmp, "changed.epw")
            open(changed, "w").write("\n".join(lines))
            site, rows = irpol_hourly(args.irpol, changed)
            data, meta = pvlib.iotools.read_epw(args.epw)
            caught = any("temp_air" in p for p in compare(site, rows, data, meta, False))
            print(f"  guard: a dry-bulb changed by 0.1 °C is {'caught' if caught else 'MISSED'}")
            passed, failed = passed + caught, failed + (not caught)
    except SetupError as error:
        print(error, file=sys.stderr)
        return 2
    print(f"{passed} passed, {failed} failed")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
