//! EnergyPlus weather files (EPW), as the EnergyPlus Auxiliary Programs documentation defines
//! them: header lines (told by their keywords, normally eight), the first `LOCATION,city,state,country,source,WMO,latitude,longitude,
//! time zone,elevation` (° north, ° east, hours east of UTC, m), then one comma-separated row per
//! hour: year, month, day, hour (1…24, the end of the hour in local standard time), minute, the
//! data source flags, and the fields below (1-based positions); a value at or above its missing
//! marker is missing. Fields beyond 24 (visibility, precipitation, …) are not read.

use super::station::{
    field_value, header_station, label, read_records, Field, HourRecord, Missing, Refusal, Station,
    StationFormat, StationWeather, FIELDS,
};
use super::WeatherError;
use crate::table_text::split_fields;
use crate::table_text::Problem;
use crate::text::shown;
use std::path::Path;

/// Each [`Field`]: its 1-based position in a data row, its name, its missing marker.
const LAYOUT: [(Field, usize, &str, f64); FIELDS] = [
    (Field::DryBulb, 7, "dry bulb temperature (°C)", 99.9),
    (Field::DewPoint, 8, "dew point temperature (°C)", 99.9),
    (Field::RelativeHumidity, 9, "relative humidity (%)", 999.0),
    (
        Field::Pressure,
        10,
        "atmospheric station pressure (Pa)",
        999_999.0,
    ),
    (
        Field::Infrared,
        13,
        "horizontal infrared radiation intensity (Wh/m²)",
        9999.0,
    ),
    (
        Field::Global,
        14,
        "global horizontal radiation (Wh/m²)",
        9999.0,
    ),
    (
        Field::DirectNormal,
        15,
        "direct normal radiation (Wh/m²)",
        9999.0,
    ),
    (
        Field::DiffuseHorizontal,
        16,
        "diffuse horizontal radiation (Wh/m²)",
        9999.0,
    ),
    (Field::WindDirection, 21, "wind direction (°)", 999.0),
    (Field::WindSpeed, 22, "wind speed (m/s)", 999.0),
    (Field::TotalCover, 23, "total sky cover (tenths)", 99.0),
    (Field::OpaqueCover, 24, "opaque sky cover (tenths)", 99.0),
];

/// The keywords that start the header lines after LOCATION (EnergyPlus Auxiliary Programs,
/// "EnergyPlus Weather File (EPW) Data Dictionary"). The header is told by these, not by a count:
/// a file that lacks one of them (its DATA PERIODS line, say) must not lose its first data row.
const HEADER_KEYWORDS: [&str; 6] = [
    "DESIGN CONDITIONS",
    "TYPICAL/EXTREME PERIODS",
    "GROUND TEMPERATURES",
    "HOLIDAYS/DAYLIGHT SAVINGS",
    "COMMENTS",
    "DATA PERIODS",
];

/// Whether `line` is one of the EPW header lines after LOCATION (its first field one of
/// [`HEADER_KEYWORDS`], `COMMENTS 1` and `COMMENTS 2` alike).
fn is_header_line(line: &str) -> bool {
    // No keyword holds a ',', so the line starts with one exactly when its first field does.
    let line = line.trim_start().to_ascii_uppercase();
    HEADER_KEYWORDS.iter().any(|k| line.starts_with(k))
}

/// The fields of a line, trimmed and unquoted.
fn split(line: &str) -> Result<Vec<String>, Problem> {
    let fields = split_fields(0, line).map_err(|r| Problem(r.kind.to_string()))?;
    Ok(fields.into_iter().map(|f| f.text.into_owned()).collect())
}

/// Reads an EPW file's bytes; `year` replaces every row's year (a typical-year file).
pub(super) fn parse(
    path: &Path,
    bytes: &[u8],
    year: Option<i32>,
) -> Result<StationWeather, WeatherError> {
    let text = String::from_utf8_lossy(bytes);
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let (station, records) =
        parse_text(text, year).map_err(|refusal| WeatherError::Station(refusal.in_file(path)))?;
    let field_names = LAYOUT.map(|(_, position, name, _)| format!("field {position} ({name})"));
    Ok(StationWeather {
        source: path.to_path_buf(),
        format: StationFormat::Epw,
        station,
        records,
        field_names,
    })
}

fn parse_text(text: &str, year: Option<i32>) -> Result<(Station, Vec<HourRecord>), Refusal> {
    let mut lines = text.lines().enumerate().map(|(i, l)| (i as u64 + 1, l));
    let Some((_, first)) = lines.next() else {
        return Err(Refusal::at_line(
            1,
            "empty file: an EPW file starts with a LOCATION line".into(),
        ));
    };
    let station = location(first).map_err(|problem| Refusal::at_line(1, problem))?;
    let mut lines = lines.peekable();
    let mut header_end = 1;
    while let Some(&(number, _)) = lines.peek().filter(|(_, line)| is_header_line(line)) {
        header_end = number;
        lines.next();
    }
    let records = read_records(lines, header_end, |row| record(row, year, &station))?;
    Ok((station, records))
}

/// The LOCATION line's site.
fn location(line: &str) -> Result<Station, Problem> {
    let fields = split(line)?;
    if !fields[0].eq_ignore_ascii_case("LOCATION") || fields.len() < 10 {
        return Err(Problem(format!(
            "the first line must be LOCATION,city,state,country,source,WMO,latitude,longitude,\
             time zone,elevation; got '{}'",
            crate::text::shown_at_most(line, 80)
        )));
    }
    // LOCATION,city,state,country,source,WMO,latitude,longitude,time zone,elevation.
    header_station(&fields, [8, 6, 7, 9], "LOCATION")
}

/// One data row.
fn record(row: &str, year: Option<i32>, station: &Station) -> Result<HourRecord, Problem> {
    let fields = split(row)?;
    let needed = LAYOUT.iter().map(|l| l.1).max().unwrap_or(0);
    if fields.len() < needed {
        return Err(Problem(format!(
            "{} fields, an EPW data row has at least {needed} (year, month, day, hour, minute, \
             flags, dry bulb, …, opaque sky cover)",
            fields.len()
        )));
    }
    let integer = |index: usize, what: &str| -> Result<i64, Problem> {
        let text = fields[index].as_str();
        text.parse::<i64>().map_err(|_| {
            Problem(format!(
                "field {} ({what}): '{}' is not a whole number",
                index + 1,
                shown(text)
            ))
        })
    };
    let file_year = integer(0, "year")?;
    let month = integer(1, "month")?;
    let day = integer(2, "day")?;
    let hour = integer(3, "hour")?;
    if !(1..=24).contains(&hour) {
        return Err(Problem(format!("field 4 (hour): {hour} is outside 1…24")));
    }
    let year = year.map_or(file_year, i64::from);
    let fits = |v: i64, low: i64, high: i64| (low..=high).contains(&v);
    if !(fits(year, 1, 9999) && fits(month, 1, 12) && fits(day, 1, 31)) {
        return Err(Problem(format!(
            "{year}-{month}-{day} is not a date (fields 1-3)"
        )));
    }
    let (end_local, end_utc) = label(
        year as i32,
        month as u32,
        day as u32,
        hour as u32,
        station.time_zone_h,
    )?;
    let mut values = [None; FIELDS];
    for (field, position, name, marker) in LAYOUT {
        let name = format!("field {position} ({name})");
        values[field as usize] = field_value(
            field,
            &name,
            &fields[position - 1],
            Missing::AtOrAbove(marker),
            1.0,
        )?;
    }
    Ok(HourRecord {
        line: 0,
        end_local,
        end_utc,
        values,
    })
}

/// The EPW text of a station's rows (the fields irpol reads; the others at their missing
/// markers), with `comment` in COMMENTS 1: how a shipped sample or a test writes one.
pub fn write(station: &Station, records: &[HourRecord], comment: &str) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let s = station;
    let _ = writeln!(
        out,
        "LOCATION,irpol,-,-,irpol,000000,{},{},{},{}",
        s.latitude_deg, s.longitude_deg, s.time_zone_h, s.elevation_m
    );
    out.push_str("DESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\n");
    out.push_str("HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\n");
    let _ = writeln!(out, "COMMENTS 1,{}", comment.replace(['\n', '\r'], " "));
    out.push_str("COMMENTS 2,\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n");
    for r in records {
        let mut fields: Vec<String> = vec![String::new(); 35];
        // The hour-ending label: 00:00 is hour 24 of the day before.
        let start = r.end_local - chrono::TimeDelta::hours(1);
        use chrono::{Datelike, Timelike};
        fields[0] = start.year().to_string();
        fields[1] = start.month().to_string();
        fields[2] = start.day().to_string();
        fields[3] = (start.hour() + 1).to_string();
        fields[4] = "0".into();
        fields[5] = "?9?9?9?9E0?9?9?9?9?9?9?9?9?9?9?9?9?9?9?9*9*9?9?9?9".into();
        for (i, text) in [(10, "9999"), (11, "9999"), (16, "999999"), (17, "999999")] {
            fields[i] = text.into();
        }
        for (i, text) in [(18, "999999"), (19, "9999"), (24, "9999"), (25, "99999")] {
            fields[i] = text.into();
        }
        for (i, text) in [(26, "9"), (27, "999999999"), (28, "999"), (29, ".999")] {
            fields[i] = text.into();
        }
        for (i, text) in [
            (30, "999"),
            (31, "99"),
            (32, "999"),
            (33, "999"),
            (34, "99"),
        ] {
            fields[i] = text.into();
        }
        for (field, position, _, marker) in LAYOUT {
            fields[position - 1] = match r.values[field as usize] {
                Some(v) => format!("{v}"),
                None => format!("{marker}"),
            };
        }
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}
