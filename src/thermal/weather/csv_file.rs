//! The weather CSV of docs/design.md §2.5, read with the `csv` crate and refused, like a measurement CSV,
//! with `file:line:column: what is wrong` (1-based line, 1-based character column of the field).
//!
//! Lines starting with `#` are comments and blank lines are skipped; the first other line is the
//! header row. Columns in any order, names case-sensitive: `time_s` and `air_temperature_k`
//! required; `wind_speed_m_s`, `direct_normal_w_m2`, `diffuse_horizontal_w_m2` (0 when absent),
//! `longwave_down_w_m2` (Swinbank when absent) and `sun_elevation_deg` + `sun_azimuth_deg` (both
//! or neither; the SPA when absent) optional. Every value is a finite number; times strictly
//! ascending (any sign, |time_s| ≤ 1e15: seconds from `start_utc`), air temperatures within
//! (0, 10⁴] K, wind within 0…150 m/s, irradiances within 0…1e5 W/m², elevations within
//! [−90°, 90°]; at least two rows and at most [`MAX_WEATHER_ROWS`].

use super::FieldProblem;
use super::{
    nlerp_defined, swinbank_longwave_w_m2, Site, Weather, WeatherError, WeatherSample,
    MAX_IRRADIANCE_W_M2, MAX_WEATHER_ROWS, MAX_WIND_M_S,
};
use crate::emitter::{format_time_utc, sun_direction, sun_position};
use crate::optics::MAX_TEMPERATURE_K;
use crate::text::{number, shown};
use nalgebra::Vector3;
use std::path::Path;

/// Largest |time_s| (s): ~31.7 million years, far beyond the SPA's years, and small enough that
/// differences of times never overflow.
const MAX_TIME_S: f64 = 1e15;

/// What a column of the file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Column {
    Time,
    Air,
    Wind,
    Direct,
    Diffuse,
    Longwave,
    SunElevation,
    SunAzimuth,
}

/// Every column, by its name in the file.
const COLUMNS: [(Column, &str); 8] = [
    (Column::Time, "time_s"),
    (Column::Air, "air_temperature_k"),
    (Column::Wind, "wind_speed_m_s"),
    (Column::Direct, "direct_normal_w_m2"),
    (Column::Diffuse, "diffuse_horizontal_w_m2"),
    (Column::Longwave, "longwave_down_w_m2"),
    (Column::SunElevation, "sun_elevation_deg"),
    (Column::SunAzimuth, "sun_azimuth_deg"),
];

impl Column {
    fn name(self) -> &'static str {
        COLUMNS[self as usize].1
    }

    /// Whether `value` is a valid value of this column; otherwise why not.
    fn check(self, value: f64, text: &str) -> Result<(), FieldProblem> {
        let text = shown(text);
        let problem = match self {
            Column::Time if value.abs() > MAX_TIME_S => {
                format!("{text} s is beyond ±1e15 s (31.7 million years) from start_utc")
            }
            Column::Air if !(value > 0.0 && value <= MAX_TEMPERATURE_K) => {
                format!("{text} K is outside (0, {MAX_TEMPERATURE_K}] K")
            }
            Column::Wind if !(0.0..=MAX_WIND_M_S).contains(&value) => {
                format!("{text} m/s is outside 0…{MAX_WIND_M_S} m/s")
            }
            Column::Direct | Column::Diffuse | Column::Longwave
                if !(0.0..=MAX_IRRADIANCE_W_M2).contains(&value) =>
            {
                format!(
                    "{text} W/m² is outside 0…{} W/m² (an irradiance)",
                    number(MAX_IRRADIANCE_W_M2)
                )
            }
            Column::SunElevation if value.abs() > 90.0 => {
                format!("{text}° is outside [-90°, 90°]")
            }
            _ => return Ok(()),
        };
        Err(FieldProblem(format!("column '{}': {problem}", self.name())))
    }
}

/// Where each column is in the records.
struct Layout {
    /// Record index of each [`Column`] (by `Column as usize`), if present.
    index: [Option<usize>; 8],
    /// Number of fields of the header row.
    width: usize,
}

impl Layout {
    fn has(&self, column: Column) -> bool {
        self.index[column as usize].is_some()
    }
}

/// A refusal at a place in the file, before the path is attached.
type Refusal = (u64, u64, String);

/// Parses the bytes of a weather CSV; `path` names it in messages.
pub(super) fn parse(path: &Path, bytes: &[u8], site: &Site) -> Result<Weather, WeatherError> {
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    parse_rows(bytes, site).map_err(|(line, column, message)| WeatherError::Csv {
        file: path.to_path_buf(),
        line,
        column,
        message,
    })
}

fn parse_rows(bytes: &[u8], site: &Site) -> Result<Weather, Refusal> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(bytes);
    let mut records = reader.records().filter(|r| match r {
        // A line of blanks is one empty field: skip it like an empty line.
        Ok(record) => !(record.len() == 1 && record[0].is_empty()),
        Err(_) => true,
    });
    let header = match records.next() {
        None => {
            return Err((
                1,
                1,
                "no header row: the file is empty or only comments".into(),
            ))
        }
        Some(record) => record.map_err(|e| csv_refusal(bytes, e))?,
    };
    let (header_line, header_raw) = locate(bytes, header.position());
    let layout = header_layout(&header, header_line, header_raw)?;
    let mut rows: Vec<Row> = Vec::new();
    for record in records {
        let record = record.map_err(|e| csv_refusal(bytes, e))?;
        let (line, raw) = locate(bytes, record.position());
        if rows.len() == MAX_WEATHER_ROWS {
            let message =
                format!("more than {MAX_WEATHER_ROWS} data rows: split the weather or thin it out");
            return Err((line, 1, message));
        }
        let (time_s, sample) = parse_row(&record, line, raw, &layout, site)?;
        let row = Row {
            time_s,
            sample,
            line,
        };
        if let Some(previous) = rows.last() {
            follows(previous, &row, &layout, raw)?;
        }
        rows.push(row);
    }
    if rows.len() < 2 {
        let line = rows.last().map_or(header_line, |row| row.line);
        let message = format!(
            "{} data row(s): the weather needs at least two rows to interpolate between",
            rows.len()
        );
        return Err((line, 1, message));
    }
    let times = rows.iter().map(|row| row.time_s).collect();
    let samples = rows.iter().map(|row| row.sample).collect();
    Ok(Weather::from_rows(site.start_utc, times, samples))
}

/// A data row read, with its line for messages.
struct Row {
    time_s: f64,
    sample: WeatherSample,
    line: u64,
}

/// Whether `row` may follow `previous`: a later time, and a sun direction with an nlerp between
/// the two. `raw` is the text of `row`'s line.
fn follows(previous: &Row, row: &Row, layout: &Layout, raw: &str) -> Result<(), Refusal> {
    if row.time_s <= previous.time_s {
        let message = format!(
            "column 'time_s': {} s is not after {} s on line {}; times must be strictly ascending",
            number(row.time_s),
            number(previous.time_s),
            previous.line
        );
        return Err(at(layout, raw, row.line, Column::Time, message));
    }
    if !nlerp_defined(&previous.sample.sun_direction, &row.sample.sun_direction) {
        let message = format!(
            "the sun is opposite to where it is on line {}: no interpolation between them, add \
             rows in between",
            previous.line
        );
        return Err(at(layout, raw, row.line, sun_column(layout), message));
    }
    Ok(())
}

/// The column that places a refusal about the sun: the given elevation, else the time the SPA
/// took.
fn sun_column(layout: &Layout) -> Column {
    if layout.has(Column::SunElevation) {
        Column::SunElevation
    } else {
        Column::Time
    }
}

/// A refusal at `column`'s field of a data row.
fn at(layout: &Layout, raw: &str, line: u64, column: Column, message: String) -> Refusal {
    let index = layout.index[column as usize].unwrap_or(0);
    (line, field_column(raw, index), message)
}

/// Where a record is: its line (1-based) and the text of that line. The csv crate's position of a
/// record is where its reader started looking for it, before the comment and empty lines it
/// skipped, so those are skipped here too.
fn locate<'a>(bytes: &'a [u8], position: Option<&csv::Position>) -> (u64, &'a str) {
    let (mut line, mut start) = position.map_or((1, 0), |p| (p.line(), p.byte() as usize));
    loop {
        let rest = &bytes[start.min(bytes.len())..];
        let end = rest
            .iter()
            .position(|&b| b == b'\n' || b == b'\r')
            .unwrap_or(rest.len());
        let text = &rest[..end];
        let skipped = text.is_empty() || text[0] == b'#';
        if !skipped || end == rest.len() {
            return (line, std::str::from_utf8(text).unwrap_or(""));
        }
        let crlf = rest[end] == b'\r' && rest.get(end + 1) == Some(&b'\n');
        start += end + if crlf { 2 } else { 1 };
        line += 1;
    }
}

/// The csv crate's own refusals: invalid UTF-8 (the only one possible with flexible records read
/// from memory), placed on the record's line.
fn csv_refusal(bytes: &[u8], error: csv::Error) -> Refusal {
    let (line, _) = locate(bytes, error.position());
    let message = match error.kind() {
        csv::ErrorKind::Utf8 { .. } => "invalid UTF-8: a weather CSV must be UTF-8 text".into(),
        _ => shown(&error.to_string()),
    };
    (line, 1, message)
}

/// 1-based character column of field `index` of `line`: its first non-blank character, or, for a
/// blank field, the column just after the preceding ','; just past the end for a missing field.
fn field_column(line: &str, index: usize) -> u64 {
    let (mut field, mut quoted, mut start) = (0, false, 1u64);
    for (i, c) in line.chars().enumerate() {
        let column = i as u64 + 1;
        if field == index && !c.is_whitespace() {
            return if c == ',' { start } else { column };
        }
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => {
                field += 1;
                start = column + 1;
            }
            _ => {}
        }
    }
    if field == index {
        start
    } else {
        line.chars().count() as u64 + 1
    }
}

/// The columns of the header row: known names, no duplicates, the required ones, both sun
/// angles or neither.
fn header_layout(header: &csv::StringRecord, line: u64, raw: &str) -> Result<Layout, Refusal> {
    let mut index = [None; 8];
    for (i, name) in header.iter().enumerate() {
        let refuse = |message: String| Err((line, field_column(raw, i), message));
        let Some(&(column, _)) = COLUMNS.iter().find(|(_, known)| *known == name) else {
            return refuse(unknown_column(name));
        };
        if let Some(first) = index[column as usize] {
            let first = field_column(raw, first);
            return refuse(format!(
                "duplicate column '{name}' (already column {first})"
            ));
        }
        index[column as usize] = Some(i);
    }
    let layout = Layout {
        index,
        width: header.len(),
    };
    for required in [Column::Time, Column::Air] {
        if !layout.has(required) {
            let message = format!("missing required column '{}'", required.name());
            return Err((line, 1, message));
        }
    }
    let (elevation, azimuth) = (Column::SunElevation, Column::SunAzimuth);
    if layout.has(elevation) != layout.has(azimuth) {
        let (given, missing) = if layout.has(elevation) {
            (elevation, azimuth)
        } else {
            (azimuth, elevation)
        };
        let column = field_column(raw, layout.index[given as usize].unwrap_or(0));
        return Err((
            line,
            column,
            format!(
                "column '{}' without '{}': give both sun angles or neither (then the sun comes \
             from the site and the time)",
                given.name(),
                missing.name()
            ),
        ));
    }
    Ok(layout)
}

fn unknown_column(name: &str) -> String {
    if name.is_empty() {
        return "empty column name (a doubled or trailing ',' in the header row)".into();
    }
    let hint = match COLUMNS.iter().find(|(_, k)| k.eq_ignore_ascii_case(name)) {
        Some((_, known)) => format!("column names are case-sensitive: did you mean '{known}'?"),
        None => format!("expected {}", COLUMNS.map(|(_, known)| known).join(", ")),
    };
    format!("unknown column '{}' ({hint})", shown(name))
}

/// One data row: its time and the weather then.
fn parse_row(
    record: &csv::StringRecord,
    line: u64,
    raw: &str,
    layout: &Layout,
    site: &Site,
) -> Result<(f64, WeatherSample), Refusal> {
    if record.len() != layout.width {
        let column = field_column(raw, record.len().min(layout.width));
        let message = format!(
            "the row has {} fields, the header row has {}",
            record.len(),
            layout.width
        );
        return Err((line, column, message));
    }
    let value = |column: Column| -> Result<Option<f64>, Refusal> {
        let Some(i) = layout.index[column as usize] else {
            return Ok(None);
        };
        let refuse = |problem: FieldProblem| (line, field_column(raw, i), problem.0);
        let v = parse_number(column.name(), &record[i]).map_err(refuse)?;
        column.check(v, &record[i]).map_err(refuse)?;
        Ok(Some(v))
    };
    let time = value(Column::Time)?.unwrap_or_default();
    let air_k = value(Column::Air)?.unwrap_or_default();
    let sun_direction = match (value(Column::SunElevation)?, value(Column::SunAzimuth)?) {
        (Some(elevation), Some(azimuth)) => sun_direction(elevation, azimuth),
        _ => spa_direction(site, time)
            .map_err(|problem| at(layout, raw, line, Column::Time, problem.0))?,
    };
    let sample = WeatherSample {
        air_k,
        wind_m_s: value(Column::Wind)?.unwrap_or(0.0),
        direct_normal_w_m2: value(Column::Direct)?.unwrap_or(0.0),
        diffuse_horizontal_w_m2: value(Column::Diffuse)?.unwrap_or(0.0),
        longwave_down_w_m2: value(Column::Longwave)?.unwrap_or(swinbank_longwave_w_m2(air_k)),
        sun_direction,
    };
    Ok((time, sample))
}

/// The SPA's sun direction at the site, `time_s` after its start.
fn spa_direction(site: &Site, time_s: f64) -> Result<Vector3<f64>, FieldProblem> {
    let instant = site.instant(time_s).ok_or_else(|| {
        FieldProblem(format!(
            "time_s {} s after start_utc {} is not an instant irpol can represent",
            number(time_s),
            format_time_utc(&site.start_utc)
        ))
    })?;
    sun_position(site.latitude_deg, site.longitude_deg, &instant)
        .map(|p| p.direction())
        .map_err(|e| FieldProblem(e.to_string()))
}

/// A field as a finite number.
fn parse_number(column: &str, text: &str) -> Result<f64, FieldProblem> {
    if text.is_empty() {
        return Err(FieldProblem(format!(
            "column '{column}' is empty, expected a number"
        )));
    }
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(FieldProblem(format!(
            "column '{column}': '{}' is not a finite number",
            shown(text)
        ))),
        Err(_) => Err(FieldProblem(format!(
            "column '{column}': '{}' is not a number",
            shown(text)
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_columns_count_characters_and_skip_blanks() {
        assert_eq!(field_column("a,b,c", 0), 1);
        assert_eq!(field_column("a, b ,c", 1), 4);
        assert_eq!(field_column("a,b,c", 2), 5);
        assert_eq!(field_column("é,\"x,y\", z", 2), 10);
        assert_eq!(field_column("a,,c", 1), 3);
        assert_eq!(field_column("a,b", 3), 4);
        assert_eq!(field_column("θ,", 1), 3);
    }
}
