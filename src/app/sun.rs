//! `irpol sun`: the apparent sun position (SPA, standard atmosphere; see `emitter::sun`) at one site
//! for one instant or a file of them, as CSV, and with `--clear-sky` the simplified Solis clear-sky
//! irradiance at that elevation (`weather::solis`, its default atmosphere). The batch form
//! exists so that a cross-check over a year of hours runs one process, not thousands.

use super::AppError;
use crate::emitter::{format_time_utc, parse_time_utc, sun_position, SunPosition};
use crate::table_text::{self, Refusal};
use crate::weather::{simplified_solis, SolisAtmosphere};
use chrono::{DateTime, Utc};
use std::io::Write;
use std::path::Path;

pub const SUN_HEADER: &str = "time_utc,elevation_deg,azimuth_deg";
/// The columns `--clear-sky` appends: DNI, DHI and GHI of the simplified Solis model (W m⁻²).
pub const CLEAR_SKY_COLUMNS: &str = "dni_w_m2,dhi_w_m2,ghi_w_m2";

/// One RFC 3339 instant per line; blank lines and lines starting with `#` are skipped. A bad line is
/// refused as `FILE:LINE: …`.
pub fn read_times_file(path: &Path) -> Result<Vec<DateTime<Utc>>, AppError> {
    let text = std::fs::read_to_string(path).map_err(|source| AppError::Read {
        path: path.to_owned(),
        source,
    })?;
    parse_times(path, &text)
}

/// [`read_times_file`] of a file's text; `path` names it in messages.
pub fn parse_times(path: &Path, text: &str) -> Result<Vec<DateTime<Utc>>, AppError> {
    let mut times = Vec::new();
    for (number, line) in table_text::content_lines(text) {
        let time = parse_time_utc(line.trim()).map_err(|problem| {
            AppError::TimesLine(Refusal::at_line(number, problem).in_file(path))
        })?;
        times.push(time);
    }
    if times.is_empty() {
        return Err(AppError::NoTimes(path.to_owned()));
    }
    Ok(times)
}

/// The instants `irpol sun` is given: one `--time-utc`, or the lines of a `--times-file`.
pub fn given_times(
    time_utc: Option<&str>,
    times_file: Option<&Path>,
) -> Result<Vec<DateTime<Utc>>, AppError> {
    match (time_utc, times_file) {
        (Some(text), None) => Ok(vec![parse_time_utc(text)?]),
        (None, Some(path)) => read_times_file(path),
        _ => Err(AppError::invalid(
            "give either --time-utc RFC3339 or --times-file FILE",
        )),
    }
}

/// The sun position at every instant, or the first error (nothing is returned half-done).
pub fn sun_table(
    latitude_deg: f64,
    longitude_deg: f64,
    times: &[DateTime<Utc>],
) -> Result<Vec<(DateTime<Utc>, SunPosition)>, AppError> {
    times
        .iter()
        .map(|time| Ok((*time, sun_position(latitude_deg, longitude_deg, time)?)))
        .collect()
}

/// Writes `time_utc,elevation_deg,azimuth_deg` and one line per instant, the angles in degrees to
/// full (round-trip) precision; with `clear_sky` also `dni_w_m2,dhi_w_m2,ghi_w_m2`, the simplified
/// Solis irradiance ([`SolisAtmosphere::DEFAULT`]) at the apparent elevation, to full precision.
/// Every position is computed before anything is written.
pub fn write_sun_csv(
    latitude_deg: f64,
    longitude_deg: f64,
    times: &[DateTime<Utc>],
    clear_sky: bool,
    out: &mut impl Write,
) -> Result<(), AppError> {
    let table = sun_table(latitude_deg, longitude_deg, times)?;
    if clear_sky {
        writeln!(out, "{SUN_HEADER},{CLEAR_SKY_COLUMNS}")?;
    } else {
        writeln!(out, "{SUN_HEADER}")?;
    }
    for (time, position) in table {
        write!(
            out,
            "{},{},{}",
            format_time_utc(&time),
            position.elevation_deg,
            position.azimuth_deg
        )?;
        if clear_sky {
            let sky = simplified_solis(position.elevation_deg, &SolisAtmosphere::DEFAULT);
            write!(
                out,
                ",{},{},{}",
                sky.direct_normal_w_m2, sky.diffuse_horizontal_w_m2, sky.global_horizontal_w_m2
            )?;
        }
        writeln!(out)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_has_the_header_and_one_line_per_instant() {
        let times = [
            parse_time_utc("2026-06-21T10:00:00Z").unwrap(),
            parse_time_utc("2026-12-21T10:00:00+01:00").unwrap(),
        ];
        let mut out = Vec::new();
        write_sun_csv(48.14, 11.58, &times, false, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0], SUN_HEADER);
        assert!(
            lines[1].starts_with("2026-06-21T10:00:00Z,"),
            "{}",
            lines[1]
        );
        assert!(
            lines[2].starts_with("2026-12-21T09:00:00Z,"),
            "{}",
            lines[2]
        );
        let fields: Vec<f64> = lines[1]
            .split(',')
            .skip(1)
            .map(|f| f.parse().unwrap())
            .collect();
        let expected = sun_position(48.14, 11.58, &times[0]).unwrap();
        assert_eq!(fields, vec![expected.elevation_deg, expected.azimuth_deg]);
    }

    #[test]
    fn clear_sky_appends_the_solis_irradiance_at_the_apparent_elevation() {
        let times = [
            parse_time_utc("2026-06-21T11:00:00Z").unwrap(),
            parse_time_utc("2026-06-21T23:00:00Z").unwrap(),
        ];
        let mut out = Vec::new();
        write_sun_csv(48.14, 11.58, &times, true, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "time_utc,elevation_deg,azimuth_deg,dni_w_m2,dhi_w_m2,ghi_w_m2"
        );
        let row = |i: usize| -> Vec<f64> {
            lines[i]
                .split(',')
                .skip(1)
                .map(|f| f.parse().unwrap())
                .collect()
        };
        let noon = row(1);
        let expected = simplified_solis(noon[0], &SolisAtmosphere::DEFAULT);
        assert_eq!(
            noon[2..],
            [
                expected.direct_normal_w_m2,
                expected.diffuse_horizontal_w_m2,
                expected.global_horizontal_w_m2
            ]
        );
        assert!(noon[2] > 800.0 && noon[4] > 800.0, "{noon:?}");
        // Midnight: the sun below the horizon, no irradiance.
        assert_eq!(row(2)[2..], [0.0, 0.0, 0.0]);
    }

    #[test]
    fn times_files_skip_blanks_and_comments_and_name_bad_lines() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("good.txt");
        std::fs::write(
            &good,
            "# instants\n2026-06-21T10:00:00Z\n\n  2026-06-21T11:00:00Z  \n",
        )
        .unwrap();
        assert_eq!(read_times_file(&good).unwrap().len(), 2);
        let bad = dir.path().join("bad.txt");
        std::fs::write(&bad, "2026-06-21T10:00:00Z\n2026-06-21 11:00\n").unwrap();
        let error = crate::app::one_line(&read_times_file(&bad).unwrap_err());
        assert!(
            error.contains("bad.txt:2:") && error.contains("RFC 3339"),
            "{error}"
        );
        let empty = dir.path().join("empty.txt");
        std::fs::write(&empty, "# nothing\n").unwrap();
        assert!(read_times_file(&empty)
            .unwrap_err()
            .to_string()
            .contains("no times"));
        assert!(read_times_file(&dir.path().join("missing.txt")).is_err());
    }

    #[test]
    fn a_bad_site_writes_nothing() {
        let times = [parse_time_utc("2026-06-21T10:00:00Z").unwrap()];
        let mut out = Vec::new();
        let error = write_sun_csv(95.0, 0.0, &times, true, &mut out).unwrap_err();
        assert!(error.to_string().contains("latitude"), "{error}");
        assert!(out.is_empty());
    }
}
