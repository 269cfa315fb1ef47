"""Cross-check of `irpol sun --clear-sky` against pvlib's simplified Solis model (docs/design.md §1.8; the
clear day of the thermal weather, src/weather/solis.rs).

    .venv/bin/python scripts/crosscheck_clearsky.py [--irpol PATH] [--year 2026]

irpol's clear-sky irradiance is the simplified Solis model (Ineichen, Solar Energy 82:758, 2008)
with a fixed atmosphere: aod700 = 0.1, precipitable water 1 cm, pressure 101325 Pa, extraterrestrial
irradiance 1364 W/m². For each site

    Munich 48.14 N 11.58 E,  Sydney 33.87 S 151.21 E,  Tromsø 69.65 N 18.96 E

1. every hour of the year in UTC (8760 instants, 8784 in a leap year) goes into one file, and
   `irpol sun --latitude LAT --longitude LON --times-file FILE --clear-sky` computes them all; its
   header must be `time_utc,elevation_deg,azimuth_deg,dni_w_m2,dhi_w_m2,ghi_w_m2` and its times
   must echo the instants given, in order;
2. `pvlib.clearsky.simplified_solis(apparent_elevation, aod700=0.1, precipitable_water=1.0,
   pressure=101325)` (dni_extra its default 1364) computes DNI, DHI and GHI at irpol's own
   printed elevation, so only the irradiance model is compared, not the sun position
   (scripts/crosscheck_sun.py checks that);
3. every instant is compared, night included (pvlib floors sin h at 1e-30, which gives 0 there as
   irpol does).

PASS for a site when every component at every instant agrees to within 1e-6 relative or 1e-6 W/m²
absolute, |irpol − pvlib| ≤ max(1e-6 |pvlib|, 1e-6): round-off level, the two implementations
evaluating the same closed-form equations. Two guards make sure the comparison can fail: the sun
must be up at some of the instants (some pvlib GHI above 100 W/m²), and irpol's GHI must be the
model's own global equation, not DNI sin h + DHI, which differs from it by far more than the
tolerance (≥ 0.8 % at high sun).

Exit status 0 when every site passes, 1 when one fails, 2 on setup problems (no irpol binary, irpol
failing, output that cannot be read). The last line is `N passed, M failed`.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field

import numpy as np
import pvlib

from crosscheck_sun import SITES, SetupError, find_irpol, hourly_instants

HEADER = "time_utc,elevation_deg,azimuth_deg,dni_w_m2,dhi_w_m2,ghi_w_m2"
COMPONENTS = ("dni", "dhi", "ghi")
RELATIVE_TOLERANCE = 1e-6
ABSOLUTE_TOLERANCE_W_M2 = 1e-6
# irpol's atmosphere (thermal::SolisAtmosphere::DEFAULT).
AOD700 = 0.1
PRECIPITABLE_WATER_CM = 1.0
PRESSURE_PA = 101325.0


@dataclass
class SiteResult:
    name: str
    daylight: int = 0
    worst_absolute: dict[str, float] = field(default_factory=dict)
    worst_relative: dict[str, float] = field(default_factory=dict)
    worst_at: dict[str, str] = field(default_factory=dict)
    failures: list[str] = field(default_factory=list)


def run_irpol(irpol: str, latitude: float, longitude: float, times_file: str) -> tuple[list[str], np.ndarray]:
    """irpol's output: the echoed times and an array of (elevation, azimuth, dni, dhi, ghi) rows."""
    command = [irpol, "sun", "--latitude", repr(latitude), "--longitude", repr(longitude),
               "--times-file", times_file, "--clear-sky"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise SetupError(f"{' '.join(command)} failed ({done.returncode}): {done.stderr.strip()}")
    lines = done.stdout.splitlines()
    if not lines or lines[0] != HEADER:
        raise SetupError(f"irpol sun --clear-sky: expected the header {HEADER!r}, got {lines[:1]!r}")
    stamps, values = [], []
    for number, line in enumerate(lines[1:], start=2):
        fields = line.split(",")
        if len(fields) != 6:
            raise SetupError(f"irpol sun output line {number}: {line!r} has {len(fields)} fields")
        stamps.append(fields[0])
        try:
            values.append([float(f) for f in fields[1:]])
        except ValueError as e:
            raise SetupError(f"irpol sun output line {number}: {line!r}: {e}") from None
    return stamps, np.array(values).reshape(-1, 5)


def check_site(irpol: str, name: str, latitude: float, longitude: float, stamps: list[str],
               times_file: str) -> SiteResult:
    result = SiteResult(name)
    echoed, values = run_irpol(irpol, latitude, longitude, times_file)
    if echoed != stamps:
        result.failures.append(f"irpol's times do not echo the instants given ({len(echoed)} vs {len(stamps)} lines)")
        return result
    elevation = values[:, 0]
    ours = dict(zip(COMPONENTS, (values[:, 2], values[:, 3], values[:, 4])))
    theirs = pvlib.clearsky.simplified_solis(elevation, aod700=AOD700, precipitable_water=PRECIPITABLE_WATER_CM,
                                             pressure=PRESSURE_PA)
    result.daylight = int(np.sum(elevation > 0.0))
    for c in COMPONENTS:
        reference = np.asarray(theirs[c], dtype=float)
        difference = np.abs(ours[c] - reference)
        allowed = np.maximum(RELATIVE_TOLERANCE * np.abs(reference), ABSOLUTE_TOLERANCE_W_M2)
        worst = int(np.argmax(difference / allowed))
        result.worst_absolute[c] = float(np.max(difference))
        result.worst_relative[c] = float(np.max(difference / np.maximum(np.abs(reference), 1e-300)
                                                * (np.abs(reference) > 1.0)))
        result.worst_at[c] = stamps[worst]
        if not np.all(np.isfinite(ours[c])):
            result.failures.append(f"{c}: non-finite values")
        if np.any(difference > allowed):
            result.failures.append(f"{c}: irpol {float(ours[c][worst])!r} vs pvlib {float(reference[worst])!r} W/m² at "
                                   f"{stamps[worst]} (elevation {elevation[worst]:.4f}°), "
                                   f"{int(np.sum(difference > allowed))} instants beyond the tolerance")
    ghi = np.asarray(theirs["ghi"], dtype=float)
    if not np.any(ghi > 100.0):
        result.failures.append("the sun is never high enough for GHI > 100 W/m²: nothing was compared")
    closure = ours["dni"] * np.sin(np.radians(elevation)) + ours["dhi"]
    if np.max(np.abs(closure - ghi)) <= ABSOLUTE_TOLERANCE_W_M2:
        result.failures.append("DNI sin h + DHI equals GHI everywhere: the check cannot tell the model's own "
                               "global equation from the closure")
    return result


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--irpol", help="path to the irpol binary (default: $IRPOL, target/release/irpol, PATH)")
    ap.add_argument("--year", type=int, default=2026, help="the year whose hours are compared (default 2026)")
    args = ap.parse_args(argv)
    t_start = time.perf_counter()
    results: list[SiteResult] = []
    try:
        irpol = find_irpol(args.irpol)
        stamps = [t.strftime("%Y-%m-%dT%H:%M:%SZ") for t in hourly_instants(args.year)]
        with tempfile.TemporaryDirectory() as tmp:
            times_file = os.path.join(tmp, "times.txt")
            with open(times_file, "w") as f:
                f.write("\n".join(stamps) + "\n")
            for name, latitude, longitude in SITES:
                r = check_site(irpol, name, latitude, longitude, stamps, times_file)
                print(f"{name}: " + ("FAIL" if r.failures else "PASS"), flush=True)
                for message in r.failures:
                    print(f"  FAIL {name}: {message}")
                results.append(r)
    except (SetupError, ValueError) as e:
        print(f"setup error: {e}", file=sys.stderr)
        return 2
    print(f"\npvlib {pvlib.__version__}, year {args.year}, aod700 {AOD700}, precipitable water "
          f"{PRECIPITABLE_WATER_CM} cm, {PRESSURE_PA:.0f} Pa; tolerance {RELATIVE_TOLERANCE:g} relative or "
          f"{ABSOLUTE_TOLERANCE_W_M2:g} W/m²")
    print(f"{'site':<8} {'sun up':>6}  " + "  ".join(f"{'max |Δ' + c + '| W/m²':>17} {'rel (>1 W/m²)':>13}"
                                                  for c in COMPONENTS))
    for r in results:
        if not r.worst_absolute:
            continue
        print(f"{r.name:<8} {r.daylight:>6}  " + "  ".join(
            f"{r.worst_absolute[c]:>17.2e} {r.worst_relative[c]:>13.2e}" for c in COMPONENTS))
    print(f"\n(total {time.perf_counter() - t_start:.1f} s)")
    failed = sum(1 for r in results if r.failures)
    print(f"{len(results) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
