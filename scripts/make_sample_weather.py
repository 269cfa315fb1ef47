"""Writes the shipped sample weather: data/weather/munich_3days.epw and the same hours as TMY3,
data/weather/munich_3days_tmy3.csv (docs/design.md §2.5, data/weather/README.md).

    python3 scripts/make_sample_weather.py --irpol target/release/irpol

Made here, not measured: three days at Munich (48.14 N, 11.58 E, 519 m, UTC+1 standard time),
20–22 June 2026, labelled hour-ending 1…24 in local standard time as EPW and TMY3 are.
- Day 1 and day 3 clear (total and opaque sky cover 0), day 2 overcast (10 tenths).
- Solar: each hour's mean of `irpol sun --clear-sky` (the simplified Solis clear sky of irpol's
  clear day) at the 12 five-minute midpoints of the hour; on the overcast day Kasten & Czeplak
  (1980): G = G_clear (1 − 0.75 N^3.4), D = G (0.3 + 0.7 N²), DNI = (G − D)/sin h (0 at N = 1).
  Rounded to whole Wh/m² as the formats store them.
- Air: half cosines from a minimum at 05:00 to a maximum at 15:00 local time (clear 12 → 26 °C,
  overcast 14 → 19 °C); dew point 10 °C clear, 13 °C overcast; relative humidity from the Magnus
  formula; station pressure 955 hPa; wind 2 m/s clear, 4 m/s overcast, from 250°.
- Horizontal infrared: Clark & Allen (1978) as the EnergyPlus documentation gives it, at the middle
  of the hour: σ T_a⁴ (0.787 + 0.764 ln(T_dp/273)) (1 + 0.0224 N − 0.0035 N² + 0.00028 N³).
Only the standard library; deterministic.
"""

from __future__ import annotations

import argparse
import datetime as dt
import math
import os
import subprocess
import tempfile

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
LAT, LON, TZ, ELEV = 48.14, 11.58, 1.0, 519.0
FIRST_DAY = dt.date(2026, 6, 20)
DAYS = 3
SIGMA = 5.670374419e-8
PRESSURE_HPA = 955


def day_kind(local: dt.datetime) -> str:
    """The weather of the local day a state instant belongs to (midnight ends the day before)."""
    day = (local - dt.timedelta(microseconds=1)).date()
    return "overcast" if (day - FIRST_DAY).days == 1 else "clear"


def air_c(local: dt.datetime) -> float:
    kind = day_kind(local)
    low, high = (14.0, 19.0) if kind == "overcast" else (12.0, 26.0)
    h = local.hour + local.minute / 60.0
    if 5.0 <= h <= 15.0:
        x = (h - 5.0) / 10.0
    else:
        x = 1.0 + ((h - 15.0) % 24.0) / 14.0
    return low + (high - low) * (1.0 - math.cos(math.pi * x)) / 2.0


def dew_c(local: dt.datetime) -> float:
    return 13.0 if day_kind(local) == "overcast" else 10.0


def cover(local: dt.datetime) -> int:
    return 10 if day_kind(local) == "overcast" else 0


def magnus_rh(t: float, td: float) -> float:
    e = lambda x: math.exp(17.625 * x / (243.04 + x))
    return 100.0 * e(td) / e(t)


def clark_allen(t_c: float, td_c: float, n: float) -> float:
    eps = (0.787 + 0.764 * math.log((td_c + 273.15) / 273.0)) * (
        1 + 0.0224 * n - 0.0035 * n * n + 0.00028 * n**3)
    return eps * SIGMA * (t_c + 273.15) ** 4


def clear_sky(irpol: str, instants: list[dt.datetime]):
    """irpol's apparent elevation and Solis (DNI, DHI, GHI) at each UTC instant."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "times.txt")
        with open(path, "w") as f:
            f.writelines(t.strftime("%Y-%m-%dT%H:%M:%SZ") + "\n" for t in instants)
        out = subprocess.run([irpol, "sun", "--latitude", str(LAT), "--longitude", str(LON),
                              "--times-file", path, "--clear-sky"],
                             check=True, capture_output=True, text=True).stdout
    rows = [line.split(",") for line in out.strip().splitlines()[1:]]
    return [(float(r[1]), float(r[3]), float(r[4]), float(r[5])) for r in rows]


def hours(irpol: str):
    """One dict per hour: the label (local standard) and every value."""
    labels = [dt.datetime.combine(FIRST_DAY, dt.time()) + dt.timedelta(hours=k + 1)
              for k in range(24 * DAYS)]
    mids = [lab - dt.timedelta(hours=1) + dt.timedelta(minutes=2.5 + 5 * j)
            for lab in labels for j in range(12)]
    sky = clear_sky(irpol, [m - dt.timedelta(hours=TZ) for m in mids])
    rows = []
    for k, label in enumerate(labels):
        mid = label - dt.timedelta(minutes=30)
        n = cover(mid) / 10.0
        g = dh = dn = 0.0
        for elev, c_dn, c_dh, c_g in sky[12 * k:12 * k + 12]:
            if n == 0.0:
                dn, dh, g = dn + c_dn / 12, dh + c_dh / 12, g + c_g / 12
                continue
            gg = c_g * (1 - 0.75 * n**3.4)
            d = gg * (0.3 + 0.7 * n * n)
            s = math.sin(math.radians(elev))
            dn += ((gg - d) / s if s > 0 else 0.0) / 12
            dh, g = dh + d / 12, g + gg / 12
        t, td = air_c(label), dew_c(label)
        rows.append({
            "label": label, "t": round(t, 1), "td": round(td, 1),
            "rh": round(magnus_rh(round(t, 1), round(td, 1))), "p": PRESSURE_HPA,
            "ir": round(clark_allen(air_c(mid), dew_c(mid), cover(mid))),
            "ghi": round(g), "dni": round(dn), "dhi": round(dh),
            "wd": 250, "ws": 4.0 if day_kind(label) == "overcast" else 2.0,
            "tot": cover(label), "opq": cover(label),
        })
    return rows


def write_epw(rows, path):
    head = [
        f"LOCATION,Munich (irpol sample),BY,DEU,irpol sample,000000,{LAT},{LON},{TZ},{ELEV}",
        "DESIGN CONDITIONS,0", "TYPICAL/EXTREME PERIODS,0", "GROUND TEMPERATURES,0",
        "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0",
        "COMMENTS 1,Made by scripts/make_sample_weather.py (not measured): day 1 and 3 clear "
        "(irpol's Solis clear sky) day 2 overcast (Kasten-Czeplak); infrared by Clark-Allen",
        "COMMENTS 2,See data/weather/README.md",
        "DATA PERIODS,1,1,Data,Saturday, 6/20, 6/22",
    ]
    with open(path, "w", newline="\n") as f:
        f.write("\n".join(head) + "\n")
        for r in rows:
            start = r["label"] - dt.timedelta(hours=1)
            fields = [start.year, start.month, start.day, start.hour + 1, 0,
                      "?9?9?9?9E0?9?9?9?9?9?9?9?9?9?9?9?9?9?9?9*9*9?9?9?9",
                      r["t"], r["td"], r["rh"], r["p"] * 100, 9999, 9999, r["ir"],
                      r["ghi"], r["dni"], r["dhi"], 999999, 999999, 999999, 9999,
                      r["wd"], r["ws"], r["tot"], r["opq"], 9999, 99999, 9, 999999999,
                      999, 0.999, 999, 99, 999, 999, 99]
            f.write(",".join(str(x) for x in fields) + "\n")


TMY3_COLUMNS = ("Date (MM/DD/YYYY),Time (HH:MM),GHI (W/m^2),DNI (W/m^2),DHI (W/m^2),"
                "TotCld (tenths),OpqCld (tenths),Dry-bulb (C),Dew-point (C),RHum (%),"
                "Pressure (mbar),Wdir (degrees),Wspd (m/s)")


def write_tmy3(rows, path):
    with open(path, "w", newline="\n") as f:
        f.write(f"000000,\"MUNICH (IRPOL SAMPLE)\",BY,{TZ},{LAT},{LON},{ELEV}\n")
        f.write(TMY3_COLUMNS + "\n")
        for r in rows:
            start = r["label"] - dt.timedelta(hours=1)
            date = start.strftime("%m/%d/%Y")
            fields = [date, f"{start.hour + 1:02d}:00", r["ghi"], r["dni"], r["dhi"], r["tot"],
                      r["opq"], r["t"], r["td"], r["rh"], r["p"], r["wd"], r["ws"]]
            f.write(",".join(str(x) for x in fields) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--irpol", default=os.path.join(REPO, "target", "release", "irpol"))
    args = parser.parse_args()
    rows = hours(args.irpol)
    out = os.path.join(REPO, "data", "weather")
    write_epw(rows, os.path.join(out, "munich_3days.epw"))
    write_tmy3(rows, os.path.join(out, "munich_3days_tmy3.csv"))


if __name__ == "__main__":
    main()
