"""Cross-check of `irpol sun` against pvlib's NREL SPA (docs/design.md §1.7, "Sun" and "World frame").

    .venv/bin/python scripts/crosscheck_sun.py [--irpol PATH] [--year 2026] [--delta-t pvlib|SECONDS]

irpol's sun position (src/emitter/sun.rs, NREL SPA through the `solar-positioning` crate) is the
apparent, refraction-corrected topocentric position for the standard atmosphere (1013.25 hPa, 15 °C)
at sea level, azimuth clockwise from north. For each site

    Munich 48.14 N 11.58 E,  Sydney 33.87 S 151.21 E,  Tromsø 69.65 N 18.96 E

1. every hour of the year in UTC (8760 instants, 8784 in a leap year) goes into one file, and
   `irpol sun --latitude LAT --longitude LON --times-file FILE` computes them all (one process per
   site); its header must be `time_utc,elevation_deg,azimuth_deg` and its times must echo the
   instants given, in order;
2. `pvlib.solarposition.spa_python` computes the same instants with irpol's assumptions: altitude
   0 m, pressure 101325 Pa, temperature 15 °C (pvlib's default is 12 °C), atmos_refract 0.5667°
   (pvlib's default; refraction is applied above a true elevation of −0.83337°, the same cutoff as
   the crate), how="numpy". Its `apparent_elevation` is compared with irpol's elevation, its
   `azimuth` (clockwise from north, as irpol's) with irpol's azimuth;
3. ΔT = TT − UT1: by default each side uses its own estimate (pvlib's delta_t=None is Espenak &
   Meeus 2006, 75.4 s in 2026; the crate fits IERS data, 69.1 s, close to the observed value). ΔT
   shifts only the ephemeris time, ~1e-4° here; `--delta-t 69.1` gives pvlib the crate's value to
   compare the algorithms alone.

Compared: the instants where either side's elevation is above −0.5° (the sun up, or at most half a
degree below the horizon). Differences: |elevation_irpol − apparent_elevation_pvlib| and the
azimuth difference taken on the circle, |((az_irpol − az_pvlib + 180) mod 360) − 180|, in degrees,
weighted by nothing (not scaled by cos elevation).

PASS for a site when the worst of each is at most 0.01°. A guard makes sure the check can tell the
two kinds of elevation apart: pvlib's apparent and true elevations must differ by more than the
tolerance somewhere among the compared instants (so a true elevation on irpol's side would fail).

Exit status 0 when every site passes, 1 when one fails, 2 on setup problems (no irpol binary, irpol
failing, output that cannot be read). The last line is `N passed, M failed`.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass

import numpy as np
import pandas as pd
import pvlib

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
SITES = (
    ("Munich", 48.14, 11.58),
    ("Sydney", -33.87, 151.21),
    ("Tromsø", 69.65, 18.96),
)
TOLERANCE_DEG = 0.01
MIN_ELEVATION_DEG = -0.5
HEADER = "time_utc,elevation_deg,azimuth_deg"
# irpol's atmosphere (emitter::Atmosphere::STANDARD) in pvlib's units.
PRESSURE_PA = 101325.0
TEMPERATURE_C = 15.0


class SetupError(RuntimeError):
    """A problem with the inputs or the environment, not with the check (exit status 2)."""


@dataclass
class SiteResult:
    name: str
    compared: int
    worst_elevation: float
    worst_elevation_at: str
    worst_azimuth: float
    worst_azimuth_at: str
    worst_azimuth_elevation: float
    refraction_spread: float
    failures: list[str]


def find_irpol(explicit: str | None) -> str:
    candidates = [explicit] if explicit else [
        os.environ.get("IRPOL", ""),
        os.path.join(os.environ["CARGO_TARGET_DIR"], "release", "irpol") if os.environ.get("CARGO_TARGET_DIR") else "",
        os.path.join(REPO, "target", "release", "irpol"),
        shutil.which("irpol") or "",
    ]
    for c in candidates:
        if c and os.path.isfile(c) and os.access(c, os.X_OK):
            return c
    raise SetupError(f"irpol binary not found (tried {', '.join(c for c in candidates if c)}); pass --irpol PATH")


def hourly_instants(year: int) -> pd.DatetimeIndex:
    return pd.date_range(f"{year}-01-01T00:00:00Z", f"{year + 1}-01-01T00:00:00Z", freq="h", inclusive="left")


def run_irpol(irpol: str, latitude: float, longitude: float, times_file: str) -> tuple[list[str], np.ndarray, np.ndarray]:
    command = [irpol, "sun", "--latitude", repr(latitude), "--longitude", repr(longitude), "--times-file", times_file]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise SetupError(f"{' '.join(command)} failed ({done.returncode}): {done.stderr.strip()}")
    lines = done.stdout.splitlines()
    if not lines or lines[0] != HEADER:
        raise SetupError(f"irpol sun: expected the header {HEADER!r}, got {lines[:1]!r}")
    stamps, elevation, azimuth = [], [], []
    for number, line in enumerate(lines[1:], start=2):
        fields = line.split(",")
        if len(fields) != 3:
            raise SetupError(f"irpol sun output line {number}: {line!r} has {len(fields)} fields")
        stamps.append(fields[0])
        try:
            elevation.append(float(fields[1]))
            azimuth.append(float(fields[2]))
        except ValueError as e:
            raise SetupError(f"irpol sun output line {number}: {line!r}: {e}") from None
    return stamps, np.array(elevation), np.array(azimuth)


def check_site(irpol: str, name: str, latitude: float, longitude: float, instants: pd.DatetimeIndex,
               stamps: list[str], times_file: str, delta_t: float | None) -> SiteResult:
    echoed, elevation, azimuth = run_irpol(irpol, latitude, longitude, times_file)
    failures = []
    if echoed != stamps:
        first = next((i for i, (a, b) in enumerate(zip(echoed, stamps)) if a != b), min(len(echoed), len(stamps)))
        failures.append(f"irpol's times do not echo the instants given ({len(echoed)} vs {len(stamps)} lines, "
                        f"first difference at instant {first})")
        return SiteResult(name, 0, np.nan, "", np.nan, "", np.nan, np.nan, failures)
    spa = pvlib.solarposition.spa_python(instants, latitude, longitude, altitude=0.0, pressure=PRESSURE_PA,
                                         temperature=TEMPERATURE_C, delta_t=delta_t, atmos_refract=0.5667,
                                         how="numpy")
    pv_elevation = spa["apparent_elevation"].to_numpy()
    pv_azimuth = spa["azimuth"].to_numpy()
    up = (pv_elevation > MIN_ELEVATION_DEG) | (elevation > MIN_ELEVATION_DEG)
    if not up.any():
        raise SetupError(f"{name}: the sun is never above {MIN_ELEVATION_DEG}° in this year")
    d_elevation = np.abs(elevation - pv_elevation)[up]
    d_azimuth = np.abs((azimuth - pv_azimuth + 180.0) % 360.0 - 180.0)[up]
    when = np.array(stamps)[up]
    i_e, i_a = int(np.argmax(d_elevation)), int(np.argmax(d_azimuth))
    refraction_spread = float(np.max(np.abs(pv_elevation - spa["elevation"].to_numpy())[up]))
    result = SiteResult(name, int(up.sum()), float(d_elevation[i_e]), str(when[i_e]), float(d_azimuth[i_a]),
                        str(when[i_a]), float(elevation[up][i_a]), refraction_spread, failures)
    if not np.all(np.isfinite(d_elevation)) or not np.all(np.isfinite(d_azimuth)):
        failures.append("non-finite positions")
    if result.worst_elevation > TOLERANCE_DEG:
        failures.append(f"elevation differs by {result.worst_elevation:.3g}° at {result.worst_elevation_at}")
    if result.worst_azimuth > TOLERANCE_DEG:
        failures.append(f"azimuth differs by {result.worst_azimuth:.3g}° at {result.worst_azimuth_at}")
    if refraction_spread <= TOLERANCE_DEG:
        failures.append(f"apparent and true elevations differ by at most {refraction_spread:.3g}°: the check "
                        "could not tell which kind irpol returns")
    return result


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--irpol", help="path to the irpol binary (default: $IRPOL, target/release/irpol, PATH)")
    ap.add_argument("--year", type=int, default=2026, help="the year whose hours are compared (default 2026)")
    ap.add_argument("--delta-t", default="pvlib",
                    help="ΔT (s) given to pvlib, or 'pvlib' for its own estimate (default)")
    args = ap.parse_args(argv)
    t_start = time.perf_counter()
    results: list[SiteResult] = []
    try:
        delta_t = None if args.delta_t == "pvlib" else float(args.delta_t)
        irpol = find_irpol(args.irpol)
        instants = hourly_instants(args.year)
        stamps = [t.strftime("%Y-%m-%dT%H:%M:%SZ") for t in instants]
        with tempfile.TemporaryDirectory() as tmp:
            times_file = os.path.join(tmp, "times.txt")
            with open(times_file, "w") as f:
                f.write("\n".join(stamps) + "\n")
            for name, latitude, longitude in SITES:
                r = check_site(irpol, name, latitude, longitude, instants, stamps, times_file, delta_t)
                print(f"{name}: " + ("FAIL" if r.failures else "PASS"), flush=True)
                for message in r.failures:
                    print(f"  FAIL {name}: {message}")
                results.append(r)
    except (SetupError, ValueError) as e:
        print(f"setup error: {e}", file=sys.stderr)
        return 2
    print(f"\npvlib {pvlib.__version__}, year {args.year}, ΔT {args.delta_t}, tolerance {TOLERANCE_DEG}°")
    print(f"{'site':<8} {'hours':>6} {'max |Δelev| °':>14} {'at':<21} {'max |Δaz| °':>12} {'at':<21} {'elev there':>10} "
          f"{'max refr °':>10}")
    for r in results:
        print(f"{r.name:<8} {r.compared:>6} {r.worst_elevation:>14.2e} {r.worst_elevation_at:<21} "
              f"{r.worst_azimuth:>12.2e} {r.worst_azimuth_at:<21} {r.worst_azimuth_elevation:>10.3f} "
              f"{r.refraction_spread:>10.3f}")
    print(f"\n(total {time.perf_counter() - t_start:.1f} s)")
    failed = sum(1 for r in results if r.failures)
    print(f"{len(results) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
