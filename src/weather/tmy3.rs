//! NREL TMY3 CSV files (Wilcox & Marion, Users Manual for TMY3 Data Sets, NREL/TP-581-43156,
//! 2008): a first line `USAF,name,state,time zone,latitude,longitude,elevation` (hours east of
//! UTC, ° north, ° east, m), a second line of column names, then one row per hour with
//! `Date (MM/DD/YYYY)` and `Time (HH:MM)` (the end of the hour in local standard time, 01:00 …
//! 24:00; 00:00 is read as the day's start) and the columns below, found by their names. TMY3 has
//! no infrared column: the sky's long-wave is always Clark & Allen's. −9900 (NSRDB) is missing.

use super::station::{
    field_value, header_station, label, read_records, Field, HourRecord, Missing, Refusal, Station,
    StationFormat, StationWeather, FIELDS,
};
use super::WeatherError;
use crate::table_text::split_fields;
use crate::table_text::Problem;
use crate::text::shown;
use std::path::Path;

/// Each [`Field`] the file has: its column name and the factor to irpol's unit.
const COLUMNS: [(Field, &str, f64); FIELDS - 1] = [
    (Field::DryBulb, "Dry-bulb (C)", 1.0),
    (Field::DewPoint, "Dew-point (C)", 1.0),
    (Field::RelativeHumidity, "RHum (%)", 1.0),
    (Field::Pressure, "Pressure (mbar)", 100.0),
    (Field::Global, "GHI (W/m^2)", 1.0),
    (Field::DirectNormal, "DNI (W/m^2)", 1.0),
    (Field::DiffuseHorizontal, "DHI (W/m^2)", 1.0),
    (Field::WindDirection, "Wdir (degrees)", 1.0),
    (Field::WindSpeed, "Wspd (m/s)", 1.0),
    (Field::TotalCover, "TotCld (tenths)", 1.0),
    (Field::OpaqueCover, "OpqCld (tenths)", 1.0),
];

const DATE: &str = "Date (MM/DD/YYYY)";
const TIME: &str = "Time (HH:MM)";

/// NSRDB's missing value.
const MISSING: f64 = -9900.0;

/// Whether the bytes look like a TMY3 file: the second line starts with the date column.
pub(super) fn sniff(bytes: &[u8]) -> bool {
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]);
    text.lines()
        .nth(1)
        .is_some_and(|l| l.trim_start_matches('"').starts_with(DATE))
}

/// Reads a TMY3 file's bytes; `year` replaces every row's year (a typical-year file).
pub(super) fn parse(
    path: &Path,
    bytes: &[u8],
    year: Option<i32>,
) -> Result<StationWeather, WeatherError> {
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    let text = String::from_utf8_lossy(bytes);
    let (station, records) =
        parse_text(&text, year).map_err(|refusal| WeatherError::Station(refusal.in_file(path)))?;
    let mut field_names: [String; FIELDS] = Default::default();
    field_names[Field::Infrared as usize] = "horizontal infrared (not in TMY3)".into();
    for (field, name, _) in COLUMNS {
        field_names[field as usize] = format!("column '{name}'");
    }
    Ok(StationWeather {
        source: path.to_path_buf(),
        format: StationFormat::Tmy3,
        station,
        records,
        field_names,
    })
}

/// Splits a line into trimmed fields (a station name may be quoted); a line the tokenizer
/// refuses is one field, refused as such by what reads it.
fn split(line: &str) -> Vec<String> {
    match split_fields(0, line) {
        Ok(fields) => fields.into_iter().map(|f| f.text.into_owned()).collect(),
        Err(_) => vec![line.to_owned()],
    }
}

fn parse_text(text: &str, year: Option<i32>) -> Result<(Station, Vec<HourRecord>), Refusal> {
    let mut lines = text.lines().enumerate().map(|(i, l)| (i as u64 + 1, l));
    let station = match lines.next() {
        Some((_, first)) => site(&split(first)).map_err(|problem| Refusal::at_line(1, problem))?,
        None => {
            return Err(Refusal::at_line(
                1,
                "empty file: a TMY3 file starts with its site line".into(),
            ))
        }
    };
    let Some((_, header)) = lines.next() else {
        return Err(Refusal::at_line(
            1,
            "no column header line after the site line".into(),
        ));
    };
    let header = split(header);
    let find = |name: &str| -> Result<usize, Refusal> {
        header.iter().position(|h| h == name).ok_or_else(|| {
            let message = format!("missing column '{name}' in the column header line");
            Refusal::at_line(2, message.into())
        })
    };
    let (date, time) = (find(DATE)?, find(TIME)?);
    let mut index = [0usize; FIELDS - 1];
    for (i, (_, name, _)) in COLUMNS.iter().enumerate() {
        index[i] = find(name)?;
    }
    let records = read_records(lines, 2, |row| {
        record(&split(row), date, time, &index, year, &station)
    })?;
    Ok((station, records))
}

/// The site line: USAF, name, state, time zone, latitude, longitude, elevation.
fn site(fields: &[String]) -> Result<Station, Problem> {
    if fields.len() < 7 {
        return Err(Problem(format!(
            "the first line must be USAF,name,state,time zone,latitude,longitude,elevation; got \
             {} field(s)",
            fields.len()
        )));
    }
    header_station(fields, [3, 4, 5, 6], "site line")
}

/// One data row.
fn record(
    fields: &[String],
    date: usize,
    time: usize,
    index: &[usize; FIELDS - 1],
    year: Option<i32>,
    station: &Station,
) -> Result<HourRecord, Problem> {
    let get = |i: usize| fields.get(i).map(String::as_str).unwrap_or("");
    let bad_date = || {
        Problem(format!(
            "column '{DATE}': '{}' is not MM/DD/YYYY",
            shown(get(date))
        ))
    };
    let parts: Vec<&str> = get(date).split('/').collect();
    let [month, day, file_year] = parts.as_slice() else {
        return Err(bad_date());
    };
    let (month, day, file_year) = match (month.parse(), day.parse(), file_year.parse::<i32>()) {
        (Ok(m), Ok(d), Ok(y)) if (1..=9999).contains(&y) => (m, d, y),
        _ => return Err(bad_date()),
    };
    let hour = match get(time).split_once(':') {
        Some((h, "00")) => h.parse::<u32>().ok(),
        _ => None,
    }
    .ok_or_else(|| {
        Problem(format!(
            "column '{TIME}': '{}' is not HH:00",
            shown(get(time))
        ))
    })?;
    let year = year.unwrap_or(file_year);
    let (end_local, end_utc) = label(year, month, day, hour, station.time_zone_h)
        .map_err(|e| Problem(format!("columns '{DATE}', '{TIME}': {e}")))?;
    let mut values = [None; FIELDS];
    for (i, (field, name, scale)) in COLUMNS.iter().enumerate() {
        let name = format!("column '{name}'");
        values[*field as usize] = field_value(
            *field,
            &name,
            get(index[i]),
            Missing::Equal(MISSING),
            *scale,
        )?;
    }
    Ok(HourRecord {
        line: 0,
        end_local,
        end_utc,
        values,
    })
}
