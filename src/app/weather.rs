//! `irpol weather FILE`: an EPW or TMY3 file as irpol reads it, one CSV row per hour on stdout —
//! the label in UTC, the fields irpol reads in SI units (pressure in Pa, irradiances in W/m²,
//! temperatures in °C, cover in tenths; empty where missing) and the SPA sun at the label for the
//! file's site. With `--step S` instead: the thermal model's forcing every S seconds over the
//! file (what `[thermal] weather` gives the surfaces). Cross-checks compare it with pvlib.

use super::AppError;
use crate::emitter::{format_time_utc, sun_position};
use crate::weather::station::{Field, FIELDS};
use crate::weather::{Site, StationFormat, StationWeather, WeatherFormat};
use std::io::Write;
use std::path::Path;

/// The header of the hourly table (pvlib's column names where it has one).
pub const HOURLY_HEADER: &str = "time_utc,line,temp_air,temp_dew,relative_humidity,\
atmospheric_pressure,ghi_infrared,ghi,dni,dhi,wind_direction,wind_speed,total_sky_cover,\
opaque_sky_cover,sun_elevation_deg,sun_azimuth_deg";

/// The header of the forcing table.
pub const FORCING_HEADER: &str = "time_utc,air_temperature_k,wind_speed_m_s,direct_normal_w_m2,\
diffuse_horizontal_w_m2,longwave_down_w_m2,sun_elevation_deg,sun_azimuth_deg";

/// Reads `path` as `format` (default: by its extension or TMY3 header; irpol's own CSV is refused,
/// it has no site) with every row in `year` when given.
pub fn read_station(
    path: &Path,
    format: Option<WeatherFormat>,
    year: Option<i32>,
) -> Result<StationWeather, AppError> {
    let bytes = std::fs::read(path).map_err(|source| AppError::Read {
        path: path.to_owned(),
        source,
    })?;
    let format =
        match WeatherFormat::detect(path, &bytes, format) {
            WeatherFormat::Epw => StationFormat::Epw,
            WeatherFormat::Tmy3 => StationFormat::Tmy3,
            WeatherFormat::Csv => return Err(AppError::invalid(
                "irpol weather reads EPW (.epw) and TMY3 files; this is neither (give --format \
                 epw or tmy3 if it is one)",
            )),
        };
    Ok(StationWeather::parse(path, &bytes, format, year)?)
}

/// The hourly table: a `#` line with the site, the header, a row per hour.
pub fn write_hourly(file: &StationWeather, out: &mut impl Write) -> Result<(), AppError> {
    let s = file.station;
    writeln!(
        out,
        "# latitude_deg={},longitude_deg={},time_zone_h={},elevation_m={}",
        s.latitude_deg, s.longitude_deg, s.time_zone_h, s.elevation_m
    )?;
    writeln!(out, "{HOURLY_HEADER}")?;
    for record in &file.records {
        write!(out, "{},{}", format_time_utc(&record.end_utc), record.line)?;
        for field in Field::ALL.iter().take(FIELDS) {
            match record.values[*field as usize] {
                Some(v) => write!(out, ",{v}")?,
                None => write!(out, ",")?,
            }
        }
        let sun = sun_position(s.latitude_deg, s.longitude_deg, &record.end_utc)?;
        writeln!(out, ",{},{}", sun.elevation_deg, sun.azimuth_deg)?;
    }
    Ok(())
}

/// The forcing every `step_s` (a positive multiple of the file's 300 s rows) from its first label
/// to its end, at the file's site.
pub fn write_forcing(
    file: &StationWeather,
    step_s: f64,
    out: &mut impl Write,
) -> Result<(), AppError> {
    if !(step_s.is_finite() && step_s > 0.0 && step_s <= 1e7) {
        return Err(AppError::invalid("--step must be within (0, 1e7] s"));
    }
    let site = Site {
        latitude_deg: file.station.latitude_deg,
        longitude_deg: file.station.longitude_deg,
        start_utc: file.first_utc(),
    };
    let weather = file.to_weather(&site, None)?;
    writeln!(out, "{FORCING_HEADER}")?;
    let (_, last_s) = weather.span_s();
    let mut k = 0u64;
    while k as f64 * step_s <= last_s {
        let time_s = k as f64 * step_s;
        let w = weather.at(time_s)?;
        let instant = site.instant(time_s).unwrap_or(site.start_utc);
        let d = w.sun_direction;
        let elevation = d.z.clamp(-1.0, 1.0).asin().to_degrees();
        let azimuth = d.x.atan2(d.y).to_degrees().rem_euclid(360.0);
        writeln!(
            out,
            "{},{},{},{},{},{},{elevation},{azimuth}",
            format_time_utc(&instant),
            w.air_k,
            w.wind_m_s,
            w.direct_normal_w_m2,
            w.diffuse_horizontal_w_m2,
            w.longwave_down_w_m2
        )?;
        k += 1;
    }
    Ok(())
}
