//! The weather CSV of docs/design.md §2.5, read by [`crate::table_text`] and refused, like a
//! measurement CSV, with `file:line:column: what is wrong` (1-based line, 1-based character
//! column of the field).
//!
//! Lines starting with `#` are comments and blank lines are skipped; the first other line is the
//! header row. Columns in any order, names case-sensitive: `time_s` and `air_temperature_k`
//! required; `wind_speed_m_s`, `direct_normal_w_m2`, `diffuse_horizontal_w_m2` (0 when absent),
//! `longwave_down_w_m2` (Swinbank when absent) and `sun_elevation_deg` + `sun_azimuth_deg` (both
//! or neither; the SPA when absent) optional. Every value is a finite number; times strictly
//! ascending (any sign, |time_s| ≤ 1e15: seconds from `start_utc`), air temperatures within
//! (0, 10⁴] K, wind within 0…150 m/s, irradiances within 0…1e5 W/m², elevations within
//! [−90°, 90°]; at least two rows and at most [`MAX_WEATHER_ROWS`].

use super::{
    nlerp_defined, swinbank_longwave_w_m2, Site, Weather, WeatherError, WeatherSample,
    MAX_IRRADIANCE_W_M2, MAX_WEATHER_ROWS, MAX_WIND_M_S,
};
use crate::emitter::{format_time_utc, sun_direction, sun_position};
use crate::optics::MAX_TEMPERATURE_K;
use crate::table_text::{
    self, last_column, parse_finite, split_fields, ColumnMap, Field, HeaderProblem, NumberProblem,
    Problem,
};
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
    fn check(self, value: f64, text: &str) -> Result<(), Problem> {
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
        Err(Problem(format!("column '{}': {problem}", self.name())))
    }
}

/// A refusal at a place in the file, before the path is attached.
type Refusal = table_text::Refusal<Problem>;

/// Parses the bytes of a weather CSV; `path` names it in messages.
pub(super) fn parse(path: &Path, bytes: &[u8], site: &Site) -> Result<Weather, WeatherError> {
    parse_rows(bytes, site).map_err(|refusal| WeatherError::Csv(refusal.in_file(path)))
}

fn parse_rows(bytes: &[u8], site: &Site) -> Result<Weather, Refusal> {
    let text = table_text::decode_utf8(bytes).map_err(|refusal| {
        let message = "invalid UTF-8: a weather CSV must be UTF-8 text";
        Refusal::new(refusal.line, 1, message.into())
    })?;
    let mut lines = table_text::content_lines(text);
    let Some((header_line, header)) = lines.next() else {
        let message = "no header row: the file is empty or only comments";
        return Err(Refusal::new(1, 1, message.into()));
    };
    let columns = header_columns(header_line, header)?;
    let mut rows: Vec<Row> = Vec::new();
    for (line, raw) in lines {
        if rows.len() == MAX_WEATHER_ROWS {
            let message =
                format!("more than {MAX_WEATHER_ROWS} data rows: split the weather or thin it out");
            return Err(Refusal::new(line, 1, message.into()));
        }
        let fields = fields_of(line, raw)?;
        let (time_s, sample) = parse_row(&fields, line, raw, &columns, site)?;
        let row = Row {
            time_s,
            sample,
            line,
        };
        if let Some(previous) = rows.last() {
            follows(previous, &row, &columns, &fields)?;
        }
        rows.push(row);
    }
    if rows.len() < 2 {
        let line = rows.last().map_or(header_line, |row| row.line);
        let message = format!(
            "{} data row(s): the weather needs at least two rows to interpolate between",
            rows.len()
        );
        return Err(Refusal::new(line, 1, message.into()));
    }
    let times = rows.iter().map(|row| row.time_s).collect();
    let samples = rows.iter().map(|row| row.sample).collect();
    Ok(Weather::from_rows(site.start_utc, times, samples))
}

/// The fields of line `line` (its text `raw`).
fn fields_of(line: u64, raw: &str) -> Result<Vec<Field<'_>>, Refusal> {
    split_fields(line, raw).map_err(|r| r.map(|problem| problem.to_string().into()))
}

/// A data row read, with its line for messages.
struct Row {
    time_s: f64,
    sample: WeatherSample,
    line: u64,
}

/// Whether `row` may follow `previous`: a later time, and a sun direction with an nlerp between
/// the two. `fields` are `row`'s.
fn follows(
    previous: &Row,
    row: &Row,
    columns: &ColumnMap<Column>,
    fields: &[Field<'_>],
) -> Result<(), Refusal> {
    if row.time_s <= previous.time_s {
        let message = format!(
            "column 'time_s': {} s is not after {} s on line {}; times must be strictly ascending",
            number(row.time_s),
            number(previous.time_s),
            previous.line
        );
        return Err(at(columns, fields, row.line, Column::Time, message));
    }
    if !nlerp_defined(&previous.sample.sun_direction, &row.sample.sun_direction) {
        let message = format!(
            "the sun is opposite to where it is on line {}: no interpolation between them, add \
             rows in between",
            previous.line
        );
        let sun = sun_column(columns);
        return Err(at(columns, fields, row.line, sun, message));
    }
    Ok(())
}

/// The column that places a refusal about the sun: the given elevation, else the time the SPA
/// took.
fn sun_column(columns: &ColumnMap<Column>) -> Column {
    if columns.has(Column::SunElevation) {
        Column::SunElevation
    } else {
        Column::Time
    }
}

/// A refusal at `column`'s field of a data row (of `fields`).
fn at(
    columns: &ColumnMap<Column>,
    fields: &[Field<'_>],
    line: u64,
    column: Column,
    message: String,
) -> Refusal {
    let index = columns.field(column).unwrap_or(0);
    Refusal::new(line, fields[index].column, message.into())
}

/// The columns of the header row: known names, no duplicates, the required ones, both sun
/// angles or neither.
fn header_columns(line: u64, raw: &str) -> Result<ColumnMap<Column>, Refusal> {
    let fields = fields_of(line, raw)?;
    let known = |name: &str| COLUMNS.iter().find(|(_, k)| *k == name).map(|&(c, _)| c);
    let columns = ColumnMap::of_header(line, &fields, known, false).map_err(|r| {
        r.map(|problem| {
            Problem(match problem {
                HeaderProblem::Token(problem) => problem.to_string(),
                HeaderProblem::Empty => unknown_column(""),
                HeaderProblem::Unknown(name) => unknown_column(&name),
                HeaderProblem::Duplicate { name, first_column } => {
                    format!("duplicate column '{name}' (already column {first_column})")
                }
            })
        })
    })?;
    if let Some(missing) = columns.missing(&[Column::Time, Column::Air]) {
        let message = format!("missing required column '{}'", missing.name());
        return Err(Refusal::new(line, 1, message.into()));
    }
    let (elevation, azimuth) = (Column::SunElevation, Column::SunAzimuth);
    if columns.has(elevation) != columns.has(azimuth) {
        let (given, missing) = if columns.has(elevation) {
            (elevation, azimuth)
        } else {
            (azimuth, elevation)
        };
        let column = columns.header_column(columns.field(given).unwrap_or(0));
        let message = format!(
            "column '{}' without '{}': give both sun angles or neither (then the sun comes from \
             the site and the time)",
            given.name(),
            missing.name()
        );
        return Err(Refusal::new(line, column, message.into()));
    }
    Ok(columns)
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

/// One data row (its `fields`, the text `raw` of line `line`): its time and the weather then.
fn parse_row(
    fields: &[Field<'_>],
    line: u64,
    raw: &str,
    columns: &ColumnMap<Column>,
    site: &Site,
) -> Result<(f64, WeatherSample), Refusal> {
    let width = columns.width();
    if fields.len() != width {
        let column = fields.get(width).map_or(last_column(raw), |f| f.column);
        let message = format!(
            "the row has {} fields, the header row has {width}",
            fields.len()
        );
        return Err(Refusal::new(line, column, message.into()));
    }
    let value = |column: Column| -> Result<Option<f64>, Refusal> {
        let Some(i) = columns.field(column) else {
            return Ok(None);
        };
        let refuse = |problem: Problem| Refusal::new(line, fields[i].column, problem);
        let text = fields[i].text.as_ref();
        let v = parse_number(column.name(), text).map_err(refuse)?;
        column.check(v, text).map_err(refuse)?;
        Ok(Some(v))
    };
    let time = value(Column::Time)?.unwrap_or_default();
    let air_k = value(Column::Air)?.unwrap_or_default();
    let sun_direction = match (value(Column::SunElevation)?, value(Column::SunAzimuth)?) {
        (Some(elevation), Some(azimuth)) => sun_direction(elevation, azimuth),
        _ => spa_direction(site, time)
            .map_err(|problem| at(columns, fields, line, Column::Time, problem.0))?,
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
fn spa_direction(site: &Site, time_s: f64) -> Result<Vector3<f64>, Problem> {
    let instant = site.instant(time_s).ok_or_else(|| {
        Problem(format!(
            "time_s {} s after start_utc {} is not an instant irpol can represent",
            number(time_s),
            format_time_utc(&site.start_utc)
        ))
    })?;
    sun_position(site.latitude_deg, site.longitude_deg, &instant)
        .map(|p| p.direction())
        .map_err(|e| Problem(e.to_string()))
}

/// A field as a finite number.
fn parse_number(column: &str, text: &str) -> Result<f64, Problem> {
    parse_finite(text).map_err(|problem| {
        Problem(match problem {
            NumberProblem::Empty => format!("column '{column}' is empty, expected a number"),
            NumberProblem::NotFinite => {
                format!(
                    "column '{column}': '{}' is not a finite number",
                    shown(text)
                )
            }
            NumberProblem::NotANumber => {
                format!("column '{column}': '{}' is not a number", shown(text))
            }
        })
    })
}
