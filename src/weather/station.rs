//! Hourly station weather (EnergyPlus EPW, NREL TMY3) turned into the thermal model's rows
//! (docs/design.md §2.5).
//!
//! **Time.** Both formats label each row with the *end* of its hour in local standard time (no
//! daylight saving), hours 1…24; the label minus the file's time zone (hours east of UTC) is UTC.
//! - State quantities (dry-bulb and dew point, pressure, wind, sky cover) are observations at the
//!   label: their knot is the label itself.
//! - Radiation (global, direct normal, diffuse and the horizontal infrared) is the energy of the
//!   hour before the label (Wh m⁻² = mean W m⁻²): its knot is the middle of that hour, label −
//!   30 min.
//!
//! Each quantity is interpolated linearly between its own knots and sampled on rows every
//! [`STATION_STEP_S`] aligned to the labels, so the rows hold every knot of both kinds exactly and
//! the model's linear interpolation between rows reproduces each quantity's piecewise-linear curve
//! exactly. The sun direction of a row is the SPA's at its instant, as for the clear day. A file
//! covers from its first label to its last label − 30 min (where both kinds of knot exist).
//!
//! **Sky long-wave.** The file's horizontal infrared where it is valid; otherwise Clark & Allen
//! (1978) as the EnergyPlus documentation gives it for the missing field:
//! E_lw = ε_sky σ T_a⁴, ε_sky = (0.787 + 0.764 ln(T_dp / 273 K)) (1 + 0.0224 N − 0.0035 N² +
//! 0.00028 N³), T_a the dry-bulb and T_dp the dew point (K), N the opaque sky cover in tenths.
//!
//! **Solar.** The file's direct normal and diffuse horizontal where both are valid; otherwise
//! Kasten & Czeplak (Solar Energy 24:177, 1980) from the total sky cover N (fraction 0…1):
//! G = G_clear (1 − 0.75 N^3.4) with G_clear the simplified Solis global irradiance of the clear
//! day (at the row's sun and the station pressure when valid), diffuse D = G (0.3 + 0.7 N²), and
//! the direct normal (G − D)/sin h with the sun up (h the apparent elevation), 0 otherwise.
//!
//! **Missing values.** A field at its format's missing marker is missing. A missing value that
//! the run needs (a knot of a row the run uses, of a quantity with no fallback, or of a fallback's
//! inputs) is refused, naming file, line and field; missing values outside the run are ignored.

use super::{
    simplified_solis, Site, SolisAtmosphere, Weather, WeatherError, WeatherSample, MAX_WEATHER_ROWS,
};
use crate::emitter::sun_position;
use crate::table_text::Problem;
use crate::text::number;
use chrono::{DateTime, NaiveDateTime, TimeDelta, Utc};
use std::path::PathBuf;

/// Rows of a station file's weather every 5 min (as the clear day's): the SPA sun between rows
/// then moves at most 1.25°.
pub const STATION_STEP_S: i64 = 300;

/// Stefan–Boltzmann constant (W m⁻² K⁻⁴).
const SIGMA: f64 = crate::optics::STEFAN_BOLTZMANN;

/// The quantities irpol reads from a station file, in this order in [`HourRecord::values`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// Dry-bulb air temperature (°C), at the label.
    DryBulb,
    /// Dew-point temperature (°C), at the label.
    DewPoint,
    /// Relative humidity (%), at the label (read and reported; the model does not use it).
    RelativeHumidity,
    /// Station pressure (Pa), at the label.
    Pressure,
    /// Horizontal infrared radiation from the sky (W m⁻², hour mean).
    Infrared,
    /// Global horizontal irradiance (W m⁻², hour mean).
    Global,
    /// Direct normal irradiance (W m⁻², hour mean).
    DirectNormal,
    /// Diffuse horizontal irradiance (W m⁻², hour mean).
    DiffuseHorizontal,
    /// Wind direction (° from north), at the label (reported only).
    WindDirection,
    /// Wind speed (m/s), at the label.
    WindSpeed,
    /// Total sky cover (tenths), at the label.
    TotalCover,
    /// Opaque sky cover (tenths), at the label.
    OpaqueCover,
}

/// Number of [`Field`]s.
pub const FIELDS: usize = 12;

impl Field {
    pub const ALL: [Field; FIELDS] = [
        Field::DryBulb,
        Field::DewPoint,
        Field::RelativeHumidity,
        Field::Pressure,
        Field::Infrared,
        Field::Global,
        Field::DirectNormal,
        Field::DiffuseHorizontal,
        Field::WindDirection,
        Field::WindSpeed,
        Field::TotalCover,
        Field::OpaqueCover,
    ];

    /// Whether the value is an hour's mean (knot at the half hour) rather than at the label.
    pub fn is_hour_mean(self) -> bool {
        matches!(
            self,
            Field::Infrared | Field::Global | Field::DirectNormal | Field::DiffuseHorizontal
        )
    }

    /// The accepted range of a present value (the EPW documentation's, wind and irradiance
    /// widened to irpol's weather limits).
    pub fn range(self) -> (f64, f64) {
        match self {
            Field::DryBulb | Field::DewPoint => (-90.0, 70.0),
            Field::RelativeHumidity => (0.0, 110.0),
            Field::Pressure => (31_000.0, 120_000.0),
            Field::Infrared | Field::Global | Field::DirectNormal | Field::DiffuseHorizontal => {
                (0.0, 9_998.0)
            }
            Field::WindDirection => (0.0, 360.0),
            Field::WindSpeed => (0.0, super::MAX_WIND_M_S),
            Field::TotalCover | Field::OpaqueCover => (0.0, 10.0),
        }
    }
}

/// Which station format a file is in (for messages).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StationFormat {
    Epw,
    Tmy3,
}

/// The site of a station file's header.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Station {
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    /// Hours east of UTC of the file's local standard time.
    pub time_zone_h: f64,
    pub elevation_m: f64,
}

/// One hourly row as read.
#[derive(Debug, Clone, PartialEq)]
pub struct HourRecord {
    /// 1-based line of the row in the file.
    pub line: u64,
    /// The row's label: the end of its hour, local standard time (24:00 is the next day's 00:00).
    pub end_local: NaiveDateTime,
    /// The end of its hour in UTC.
    pub end_utc: DateTime<Utc>,
    /// Each [`Field`] by `Field as usize`; `None` where missing.
    pub values: [Option<f64>; FIELDS],
}

/// A station file read: its site and hourly rows (consecutive hours, at least two).
#[derive(Debug, Clone)]
pub struct StationWeather {
    pub source: PathBuf,
    pub format: StationFormat,
    pub station: Station,
    pub records: Vec<HourRecord>,
    /// How each field is named in messages (EPW: "field 7 (dry bulb temperature)"; TMY3: the
    /// column header).
    pub field_names: [String; FIELDS],
}

/// A refusal at a line (before the path is attached).
pub(super) type Refusal = crate::table_text::Refusal<Problem>;

impl StationWeather {
    /// The first instant covered (the first label, UTC).
    pub fn first_utc(&self) -> DateTime<Utc> {
        self.records[0].end_utc
    }

    /// The last instant covered: the last label − 30 min, the last radiation knot.
    pub fn last_utc(&self) -> DateTime<Utc> {
        self.records[self.records.len() - 1].end_utc - TimeDelta::seconds(1800)
    }

    /// The thermal model's rows for a run starting at `site.start_utc` and lasting `duration_s`
    /// (default: to the end of the file): rows every [`STATION_STEP_S`] from the last at or before
    /// the start to the first at or after the end, within what the file covers.
    pub fn to_weather(
        &self,
        site: &Site,
        duration_s: Option<f64>,
    ) -> Result<Weather, WeatherError> {
        site.validate()?;
        let refuse = |refusal: Refusal| WeatherError::Station(refusal.in_file(&self.source));
        let first = self.first_utc().timestamp();
        let last = self.last_utc().timestamp();
        let start = site.start_utc.timestamp();
        let end = match duration_s {
            Some(d) if d.is_finite() => start.saturating_add(d.ceil().min(1e15) as i64),
            _ => last,
        };
        // Grid indices (steps after the first label) of the first and last row.
        let from = (start - first).max(0).div_euclid(STATION_STEP_S);
        if first + (from + 1) * STATION_STEP_S > last {
            let line = self.records[self.records.len() - 1].line;
            let message = format!(
                "the run starts at {}, but the file covers only {} to {} (UTC; its last hour's \
                 radiation is centred 30 min before the last label)",
                crate::emitter::format_time_utc(&site.start_utc),
                crate::emitter::format_time_utc(&self.first_utc()),
                crate::emitter::format_time_utc(&self.last_utc())
            );
            return Err(refuse(Refusal::at_line(line, message.into())));
        }
        let to = (end.clamp(first, last) - first + STATION_STEP_S - 1).div_euclid(STATION_STEP_S);
        let to = to.min((last - first) / STATION_STEP_S).max(from + 1);
        let mut times = Vec::with_capacity((to - from + 1) as usize);
        let mut samples = Vec::with_capacity(times.capacity());
        for k in from..=to {
            let at = self.first_utc() + TimeDelta::seconds(k * STATION_STEP_S);
            let offset = (at - site.start_utc).num_nanoseconds().unwrap_or(0) as f64 * 1e-9;
            times.push(offset);
            samples.push(self.sample(site, k * STATION_STEP_S, &at).map_err(refuse)?);
        }
        Ok(Weather::from_rows(site.start_utc, times, samples))
    }

    /// The weather `since_first_s` seconds after the first label (a multiple of the step).
    fn sample(
        &self,
        site: &Site,
        since_first_s: i64,
        at: &DateTime<Utc>,
    ) -> Result<WeatherSample, Refusal> {
        let sun = sun_position(site.latitude_deg, site.longitude_deg, at)
            .map_err(|e| Refusal::at_line(self.records[0].line, e.to_string().into()))?;
        let value = |field| self.interpolate(field, since_first_s);
        let air_c = value(Field::DryBulb)?;
        let air_k = air_c + 273.15;
        let longwave = match value(Field::Infrared) {
            Ok(v) => v,
            Err(_) => {
                let dew_k = value(Field::DewPoint)? + 273.15;
                clark_allen_longwave_w_m2(air_k, dew_k, value(Field::OpaqueCover)?)
            }
        };
        let (direct, diffuse) = match (value(Field::DirectNormal), value(Field::DiffuseHorizontal))
        {
            (Ok(dn), Ok(dh)) => (dn, dh),
            _ => {
                let mut atmosphere = SolisAtmosphere::DEFAULT;
                if let Ok(p) = value(Field::Pressure) {
                    atmosphere.pressure_pa = p;
                }
                let clear = simplified_solis(sun.elevation_deg, &atmosphere);
                let cover = value(Field::TotalCover)? / 10.0;
                kasten_czeplak(clear.global_horizontal_w_m2, cover, sun.elevation_deg)
            }
        };
        Ok(WeatherSample {
            air_k,
            wind_m_s: value(Field::WindSpeed)?,
            direct_normal_w_m2: direct,
            diffuse_horizontal_w_m2: diffuse,
            longwave_down_w_m2: longwave,
            sun_direction: sun.direction(),
        })
    }

    /// `field` at `since_first_s` after the first label, linear between its knots; a missing
    /// knot that is needed is refused at its line.
    fn interpolate(&self, field: Field, since_first_s: i64) -> Result<f64, Refusal> {
        // Hour means sit half an hour before their label: shift time by +30 min onto their knots.
        let t = since_first_s + if field.is_hour_mean() { 1800 } else { 0 };
        let (i, rest) = (t.div_euclid(3600) as usize, t.rem_euclid(3600));
        let knot = |i: usize| -> Result<f64, Refusal> {
            let record = &self.records[i.min(self.records.len() - 1)];
            record.values[field as usize].ok_or_else(|| {
                let name = &self.field_names[field as usize];
                let message = format!(
                    "{name} is missing at {} local standard time and the run needs it: fill it in \
                     (e.g. from the neighbouring hours) or move the run off it",
                    record.end_local.format("%Y-%m-%d %H:%M")
                );
                Refusal::at_line(record.line, message.into())
            })
        };
        let a = knot(i)?;
        if rest == 0 {
            return Ok(a);
        }
        let b = knot(i + 1)?;
        Ok(a + (b - a) * rest as f64 / 3600.0)
    }
}

/// Clark & Allen's (1978) all-sky long-wave irradiance (W m⁻²), as the EnergyPlus
/// documentation fills a missing horizontal infrared: air and dew point in K, the opaque sky
/// cover in tenths.
pub fn clark_allen_longwave_w_m2(air_k: f64, dew_point_k: f64, opaque_tenths: f64) -> f64 {
    let n = opaque_tenths;
    let clear = 0.787 + 0.764 * (dew_point_k / 273.0).ln();
    let cloud = 1.0 + 0.0224 * n - 0.0035 * n * n + 0.00028 * n * n * n;
    // A dew point far below the air could make ε negative; the sky never emits less than nothing.
    (clear * cloud).max(0.0) * SIGMA * air_k.powi(4)
}

/// Kasten & Czeplak (1980): (direct normal, diffuse horizontal) in W m⁻² from the clear-sky
/// global `clear_global_w_m2`, the total cloud fraction `cover` (0…1) and the apparent solar
/// elevation.
pub fn kasten_czeplak(clear_global_w_m2: f64, cover: f64, elevation_deg: f64) -> (f64, f64) {
    let global = clear_global_w_m2 * (1.0 - 0.75 * cover.powf(3.4));
    let diffuse = global * (0.3 + 0.7 * cover * cover);
    let sin_h = elevation_deg.to_radians().sin();
    if sin_h <= 0.0 {
        return (0.0, global);
    }
    ((global - diffuse) / sin_h, diffuse)
}

/// How a format marks a missing value.
#[derive(Debug, Clone, Copy)]
pub(super) enum Missing {
    /// EPW: the field's marker or more (99.9 for temperatures, 9999 for radiation, …).
    AtOrAbove(f64),
    /// TMY3 (NSRDB): exactly −9900.
    Equal(f64),
}

/// A field's text as a value in irpol's unit (`scale` times the file's): `None` where it is
/// missing; a number outside the field's range is refused.
pub(super) fn field_value(
    field: Field,
    name: &str,
    text: &str,
    missing: Missing,
    scale: f64,
) -> Result<Option<f64>, Problem> {
    let text = text.trim();
    let shown = crate::text::shown(text);
    let v: f64 = text
        .parse()
        .map_err(|_| Problem(format!("{name}: '{shown}' is not a number")))?;
    if !v.is_finite() {
        return Err(Problem(format!("{name}: '{shown}' is not a finite number")));
    }
    let (is_missing, marker) = match missing {
        Missing::AtOrAbove(m) => (v >= m, m),
        Missing::Equal(m) => (v == m, m),
    };
    if is_missing {
        return Ok(None);
    }
    let (low, high) = field.range();
    if !(low..=high).contains(&(v * scale)) {
        return Err(Problem(format!(
            "{name}: {} is outside {}…{} (mark a missing value with {})",
            number(v),
            number(low / scale),
            number(high / scale),
            number(marker)
        )));
    }
    Ok(Some(v * scale))
}

/// The hour-ending label `year-month-day hour:00` (hour 0…24; 0 is the day's start, as 24 the
/// previous day's end) in local standard time and in UTC.
pub(super) fn label(
    year: i32,
    month: u32,
    day: u32,
    hour: u32,
    time_zone_h: f64,
) -> Result<(NaiveDateTime, DateTime<Utc>), Problem> {
    let date = chrono::NaiveDate::from_ymd_opt(year, month, day)
        .ok_or_else(|| Problem(format!("{year:04}-{month:02}-{day:02} is not a date")))?;
    if hour > 24 {
        return Err(Problem(format!(
            "hour {hour} is outside 1…24 (hour-ending labels)"
        )));
    }
    let local = date
        .and_hms_opt(0, 0, 0)
        .and_then(|midnight| midnight.checked_add_signed(TimeDelta::hours(hour as i64)))
        .ok_or_else(|| {
            Problem(format!(
                "{year:04}-{month:02}-{day:02} is beyond the calendar"
            ))
        })?;
    let zone = TimeDelta::seconds((time_zone_h * 3600.0).round() as i64);
    let utc = local.checked_sub_signed(zone).ok_or_else(|| {
        Problem(format!(
            "{year:04}-{month:02}-{day:02} is beyond the calendar"
        ))
    })?;
    Ok((local, utc.and_utc()))
}

/// A header line's site from its fields at `columns` (0-based: time zone, latitude, longitude,
/// elevation), each a finite number, then checked; `line` names the header line in messages.
pub(super) fn header_station<S: AsRef<str>>(
    fields: &[S],
    columns: [usize; 4],
    line: &str,
) -> Result<Station, Problem> {
    let number = |index: usize, what: &str| -> Result<f64, Problem> {
        let field = fields[index].as_ref();
        field
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                Problem(format!(
                    "{line} field {} ({what}): '{}' is not a number",
                    index + 1,
                    crate::text::shown(field)
                ))
            })
    };
    // Read left to right, so a line with several bad fields names its first one.
    let mut order = [0, 1, 2, 3];
    order.sort_by_key(|&i| columns[i]);
    let names = ["time zone", "latitude", "longitude", "elevation"];
    let mut value = [0.0; 4];
    for i in order {
        value[i] = number(columns[i], names[i])?;
    }
    let [time_zone_h, latitude_deg, longitude_deg, elevation_m] = value;
    let station = Station {
        latitude_deg,
        longitude_deg,
        time_zone_h,
        elevation_m,
    };
    check_station(&station).map_err(|e| Problem(format!("{line}: {e}")))?;
    Ok(station)
}

/// Checks the header's site: latitude within ±90°, longitude within ±180°, time zone within
/// −12…+14 h, elevation within −1000…9000 m.
pub(super) fn check_station(station: &Station) -> Result<(), Problem> {
    let checks = [
        ("latitude", station.latitude_deg, -90.0, 90.0, "°"),
        ("longitude", station.longitude_deg, -180.0, 180.0, "°"),
        ("time zone", station.time_zone_h, -12.0, 14.0, " h"),
        ("elevation", station.elevation_m, -1000.0, 9000.0, " m"),
    ];
    for (name, v, low, high, unit) in checks {
        if !(v.is_finite() && (low..=high).contains(&v)) {
            return Err(Problem(format!(
                "the {name} {}{unit} is outside {}…{}{unit}",
                number(v),
                number(low),
                number(high)
            )));
        }
    }
    Ok(())
}

/// The hourly records of a file's data `lines` (numbered from 1; `header_end` the last header
/// line), each parsed by `parse` and stamped with its line: blank lines skipped, at most
/// [`MAX_WEATHER_ROWS`], then [`check_sequence`].
pub(super) fn read_records<'a>(
    lines: impl Iterator<Item = (u64, &'a str)>,
    header_end: u64,
    mut parse: impl FnMut(&str) -> Result<HourRecord, Problem>,
) -> Result<Vec<HourRecord>, Refusal> {
    let mut records = Vec::new();
    let mut last_line = header_end;
    for (line, row) in lines {
        if row.trim().is_empty() {
            continue;
        }
        if records.len() == MAX_WEATHER_ROWS {
            let message =
                format!("more than {MAX_WEATHER_ROWS} rows: split the weather or thin it out");
            return Err(Refusal::at_line(line, message.into()));
        }
        let mut record = parse(row).map_err(|problem| Refusal::at_line(line, problem))?;
        record.line = line;
        records.push(record);
        last_line = line;
    }
    check_sequence(&records, last_line)?;
    Ok(records)
}

/// Rows must follow each other by exactly one hour (a typical-year file mixes years: then give
/// the year to read it in), and there must be at least two.
pub(super) fn check_sequence(records: &[HourRecord], last_line: u64) -> Result<(), Refusal> {
    if records.len() < 2 {
        let message = format!(
            "{} hourly row(s): the weather needs at least two to interpolate between",
            records.len()
        );
        return Err(Refusal::at_line(last_line, message.into()));
    }
    for pair in records.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if b.end_utc - a.end_utc != TimeDelta::hours(1) {
            return Err(Refusal::at_line(
                b.line,
                Problem(format!(
                    "the row for {} does not follow the row for {} on line {} by one hour: rows \
                     must be hourly and in order (a typical-year file mixes years: set \
                     thermal.weather_year = YEAR to read every row in one year)",
                    b.end_local.format("%Y-%m-%d %H:%M"),
                    a.end_local.format("%Y-%m-%d %H:%M"),
                    a.line
                )),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_header_site_is_read_from_its_columns_and_its_first_bad_field_named() {
        let tmy3 = ["724940", "SF", "CA", "-8", "37.6", "-122.4", "2"];
        let station = header_station(&tmy3, [3, 4, 5, 6], "site line").unwrap();
        assert_eq!(
            [
                station.time_zone_h,
                station.latitude_deg,
                station.longitude_deg,
                station.elevation_m
            ],
            [-8.0, 37.6, -122.4, 2.0]
        );
        let bad = ["724940", "SF", "CA", "x", "y", "-122.4", "2"];
        let error = header_station(&bad, [3, 4, 5, 6], "site line").unwrap_err();
        assert_eq!(
            error.0,
            "site line field 4 (time zone): 'x' is not a number"
        );
        // EPW: latitude (field 7) comes before the time zone (field 9).
        let epw = [
            "LOCATION", "M", "-", "DEU", "s", "1", "lat", "11.5", "tz", "520",
        ];
        let error = header_station(&epw, [8, 6, 7, 9], "LOCATION").unwrap_err();
        assert_eq!(
            error.0,
            "LOCATION field 7 (latitude): 'lat' is not a number"
        );
        let far = [
            "LOCATION", "M", "-", "DEU", "s", "1", "95", "11.5", "1", "520",
        ];
        let error = header_station(&far, [8, 6, 7, 9], "LOCATION").unwrap_err();
        assert!(error.0.starts_with("LOCATION: "), "{}", error.0);
    }

    #[test]
    fn clark_allen_clear_and_overcast() {
        // T_a = 293.15 K, T_dp = 283.15 K: ε = 0.787 + 0.764 ln(283.15/273) = 0.81489…; N = 10:
        // × (1 + 0.224 − 0.35 + 0.28) = 1.154.
        let clear = clark_allen_longwave_w_m2(293.15, 283.15, 0.0);
        let eps = 0.787 + 0.764 * (283.15f64 / 273.0).ln();
        assert!((eps - 0.814_90).abs() < 1e-4, "{eps}");
        assert!((clear - eps * SIGMA * 293.15f64.powi(4)).abs() < 1e-9);
        let overcast = clark_allen_longwave_w_m2(293.15, 283.15, 10.0);
        assert!((overcast / clear - 1.154).abs() < 1e-12);
    }

    #[test]
    fn kasten_czeplak_limits() {
        // Clear: G unchanged, D/G = 0.3; overcast: G/4, all... D/G = 1.
        let (dn, dh) = kasten_czeplak(800.0, 0.0, 30.0);
        assert!((dh - 240.0).abs() < 1e-9 && (dn - 560.0 / 0.5).abs() < 1e-9);
        let (dn, dh) = kasten_czeplak(800.0, 1.0, 30.0);
        assert!((dh - 200.0).abs() < 1e-9 && dn.abs() < 1e-9);
        assert_eq!(kasten_czeplak(0.0, 0.5, -3.0), (0.0, 0.0));
    }

    #[test]
    fn labels_are_hour_ending_local_standard_time() {
        let (local, utc) = label(2026, 6, 21, 24, 1.0).unwrap();
        assert_eq!(local.to_string(), "2026-06-22 00:00:00");
        assert_eq!(utc.to_rfc3339(), "2026-06-21T23:00:00+00:00");
        let (_, utc) = label(2026, 1, 1, 1, -5.5).unwrap();
        assert_eq!(utc.to_rfc3339(), "2026-01-01T06:30:00+00:00");
        assert!(label(2026, 2, 29, 1, 0.0).is_err());
        assert!(label(2026, 2, 28, 25, 0.0).is_err());
    }
}
