//! Weather for the thermal model (docs/design.md §1.8, §2.5): air temperature, wind, solar and long-wave
//! irradiance and the sun's direction as rows in time, from a weather CSV ([`Weather::read_csv`])
//! or a built-in clear day ([`Weather::clear_day`]), read back at any instant by [`Weather::at`].
//!
//! **Interpolation** (§1.8). Between two rows every quantity is interpolated linearly in time on
//! its own; the sun direction is the normalized linear interpolation (nlerp) of the two rows' unit
//! vectors, so it never wraps the long way round in azimuth. Two consecutive rows whose sun
//! directions are opposite have no nlerp and are refused. Outside the first and last rows there is
//! no weather: [`Weather::at`] returns [`WeatherError::OutOfRange`].
//!
//! **Long-wave sky irradiance.** Where the CSV gives none, and always on a clear day, the clear-sky
//! formula of Swinbank (Q. J. R. Meteorol. Soc. 89:339, 1963): E_lw = 5.31e-13 W m⁻² K⁻⁶ · T_air⁶
//! (303.0 W m⁻² at 288 K).
//!
//! **Sun.** Where the CSV gives no `sun_elevation_deg`/`sun_azimuth_deg`, and on a clear day, the
//! apparent position from NREL's SPA at the site and `start_utc + time_s`
//! ([`crate::emitter::sun_position`]); the direction is [`crate::emitter::sun_direction`]'s world
//! frame (z up, azimuth clockwise from north +y toward east +x), z < 0 below the horizon.
//!
//! **Clear day** ([`Weather::clear_day`]): rows every [`CLEAR_DAY_STEP_S`] with
//! - DNI and DHI from the simplified Solis clear-sky model ([`solis`]; Ineichen 2008) at the
//!   apparent solar elevation, with [`SolisAtmosphere::DEFAULT`] (aod700 = 0.1, 1 cm of
//!   precipitable water, 101325 Pa); zero with the sun below the horizon;
//! - the air temperature of a diurnal cycle (`clear_day` module): its minimum `air_min_k` at each
//!   sunrise and its maximum `air_max_k` at 15:00 local apparent solar time (solar transit + 3 h),
//!   joined by half cosines; without a sunrise (polar day or night) the minimum is at 03:00
//!   apparent solar time;
//! - constant wind and Swinbank's long-wave irradiance.

mod clear_day;
mod csv_file;
pub mod epw;
pub mod solis;
pub mod station;
mod tmy3;

pub use solis::{simplified_solis, ClearSkyIrradiance, SolisAtmosphere};
pub use station::{
    clark_allen_longwave_w_m2, kasten_czeplak, Field, HourRecord, Station, StationFormat,
    StationWeather, STATION_STEP_S,
};

use crate::emitter::{format_time_utc, SunError};
use crate::table_text::{Problem, TableError};
use crate::text::number;
use chrono::{DateTime, TimeDelta, Utc};
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

/// Swinbank's clear-sky coefficient (W m⁻² K⁻⁶): E_lw = 5.31e-13 T⁶ (Q. J. R. Meteorol. Soc.
/// 89:339, 1963).
pub const SWINBANK_W_M2_K6: f64 = 5.31e-13;

/// Time between the rows of a clear day (s).
pub const CLEAR_DAY_STEP_S: f64 = 300.0;

/// Longest clear day (s): 400 days of rows every 5 minutes (115 200 rows).
pub const MAX_CLEAR_DAY_DURATION_S: f64 = 400.0 * 86_400.0;

/// Fastest wind (m/s): above the strongest gust measured (113 m/s); the convective coefficient
/// grows with it.
pub const MAX_WIND_M_S: f64 = 150.0;

/// Largest irradiance of any kind (W m⁻²): 70 solar constants, a black body at 1150 K. Beyond
/// it the surface balance runs to temperatures the model does not represent.
pub const MAX_IRRADIANCE_W_M2: f64 = 1e5;

/// Most rows of a weather file: two years of minutes (~100 MB held).
pub const MAX_WEATHER_ROWS: usize = 1_000_000;

/// Clear-sky downwelling long-wave irradiance (W m⁻²) for air at `air_k`, Swinbank (1963).
pub fn swinbank_longwave_w_m2(air_k: f64) -> f64 {
    SWINBANK_W_M2_K6 * air_k.powi(6)
}

/// Where and when the weather is: latitude (° north), longitude (° east), and the instant of
/// `time_s = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    pub start_utc: DateTime<Utc>,
}

impl Site {
    /// Latitude within [−90°, 90°] and longitude within [−180°, 180°], both finite.
    fn validate(&self) -> Result<(), WeatherError> {
        let ok = |v: f64, limit: f64| v.is_finite() && v.abs() <= limit;
        if !ok(self.latitude_deg, 90.0) || !ok(self.longitude_deg, 180.0) {
            return Err(WeatherError::InvalidSite {
                latitude_deg: self.latitude_deg,
                longitude_deg: self.longitude_deg,
            });
        }
        Ok(())
    }

    /// The instant `time_s` seconds after `start_utc` (to the nanosecond), if chrono can hold it.
    pub fn instant(&self, time_s: f64) -> Option<DateTime<Utc>> {
        let whole = time_s.floor();
        if !whole.is_finite() || whole.abs() >= 1e15 {
            return None;
        }
        let nanos = ((time_s - whole) * 1e9).round() as i64;
        let delta = TimeDelta::try_seconds(whole as i64)? + TimeDelta::nanoseconds(nanos);
        self.start_utc.checked_add_signed(delta)
    }
}

/// The built-in clear day of a scene's `[thermal] weather = { clear_day = { … } }`.
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClearDay {
    /// Air temperature at sunrise (K).
    pub air_min_k: f64,
    /// Air temperature at 15:00 apparent solar time (K).
    pub air_max_k: f64,
    /// Constant wind speed (m/s).
    pub wind_m_s: f64,
}

/// The weather at one instant.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct WeatherSample {
    /// Air temperature (K).
    pub air_k: f64,
    /// Wind speed (m/s).
    pub wind_m_s: f64,
    /// Direct normal solar irradiance E_dn (W m⁻²).
    pub direct_normal_w_m2: f64,
    /// Diffuse horizontal solar irradiance E_dh (W m⁻²).
    pub diffuse_horizontal_w_m2: f64,
    /// Downwelling long-wave irradiance E_lw (W m⁻²).
    pub longwave_down_w_m2: f64,
    /// Unit vector toward the sun, world frame z up, azimuth clockwise from north (+y) toward
    /// east (+x) (same as emitter::sun_direction); z < 0 when below the horizon.
    pub sun_direction: Vector3<f64>,
}

/// Everything wrong with weather input or a request for it; each message is one complete line.
#[derive(Debug, thiserror::Error)]
pub enum WeatherError {
    #[error("{}: cannot read the weather file: {reason}", crate::text::path(file))]
    Read { file: PathBuf, reason: String },
    /// An EPW or TMY3 file refused at a line; the message names the field.
    #[error(transparent)]
    Station(TableError<Problem>),
    /// A weather CSV refused at a line and column.
    #[error(transparent)]
    Csv(TableError<Problem>),
    #[error(
        "weather site latitude {}°, longitude {}° is invalid: latitude must be within \
         [-90°, 90°] and longitude within [-180°, 180°]",
        number(*latitude_deg),
        number(*longitude_deg)
    )]
    InvalidSite {
        latitude_deg: f64,
        longitude_deg: f64,
    },
    #[error("clear day: {0}")]
    InvalidClearDay(String),
    #[error("clear day: {0}")]
    Sun(#[from] SunError),
    #[error(
        "no weather at time {} s: the weather covers {} s to {} s after start_utc {start_utc}",
        number(*time_s),
        number(*first_s),
        number(*last_s)
    )]
    OutOfRange {
        time_s: f64,
        first_s: f64,
        last_s: f64,
        start_utc: String,
    },
}

impl WeatherError {
    /// The message without the "clear day: " a caller that names the clear day already says.
    pub fn detail(&self) -> String {
        match self {
            WeatherError::InvalidClearDay(message) => message.clone(),
            WeatherError::Sun(error) => error.to_string(),
            other => other.to_string(),
        }
    }
}

/// The format of a weather file: `weather_format = "epw" | "tmy3" | "csv"` in a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WeatherFormat {
    /// EnergyPlus weather ([`epw`]).
    Epw,
    /// NREL TMY3 CSV.
    Tmy3,
    /// irpol's weather CSV (docs/design.md §2.5).
    Csv,
}

impl WeatherFormat {
    /// The format a file is read in: `given`, else `.epw` (any case) is EPW, and any other file
    /// whose second line starts with TMY3's `Date (MM/DD/YYYY)` column is TMY3, else irpol's CSV.
    pub fn detect(path: &Path, bytes: &[u8], given: Option<WeatherFormat>) -> WeatherFormat {
        if let Some(format) = given {
            return format;
        }
        let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if extension.eq_ignore_ascii_case("epw") {
            WeatherFormat::Epw
        } else if tmy3::sniff(bytes) {
            WeatherFormat::Tmy3
        } else {
            WeatherFormat::Csv
        }
    }
}

impl StationWeather {
    /// Reads an EPW or TMY3 file (`format` [`StationFormat`]); `year`, when given, replaces every
    /// row's year (a typical-year file mixes years).
    pub fn read(
        path: &Path,
        format: StationFormat,
        year: Option<i32>,
    ) -> Result<StationWeather, WeatherError> {
        let bytes = std::fs::read(path).map_err(|e| WeatherError::Read {
            file: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        StationWeather::parse(path, &bytes, format, year)
    }

    /// [`StationWeather::read`] of a file's bytes; `source` names it in messages.
    pub fn parse(
        source: &Path,
        bytes: &[u8],
        format: StationFormat,
        year: Option<i32>,
    ) -> Result<StationWeather, WeatherError> {
        match format {
            StationFormat::Epw => epw::parse(source, bytes, year),
            StationFormat::Tmy3 => tmy3::parse(source, bytes, year),
        }
    }
}

/// Weather rows in time (at least two, strictly ascending), read back by [`Weather::at`].
#[derive(Debug, Clone)]
pub struct Weather {
    start_utc: DateTime<Utc>,
    times_s: Vec<f64>,
    samples: Vec<WeatherSample>,
}

impl Weather {
    /// docs/design.md §2.5 CSV; errors are one line `FILE:LINE:COLUMN: message` (or FILE: message).
    pub fn read_csv(path: &Path, site: &Site) -> Result<Weather, WeatherError> {
        site.validate()?;
        let bytes = std::fs::read(path).map_err(|e| WeatherError::Read {
            file: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        Weather::parse_csv(path, &bytes, site)
    }

    /// [`Weather::read_csv`] of a file's bytes; `source` names it in messages.
    pub fn parse_csv(source: &Path, bytes: &[u8], site: &Site) -> Result<Weather, WeatherError> {
        site.validate()?;
        csv_file::parse(source, bytes, site)
    }

    /// Built-in clear day, covering [0, duration_s] from site.start_utc (any duration, several
    /// days ok): rows every [`CLEAR_DAY_STEP_S`] from 0 to the first multiple of it at or after
    /// `duration_s` (at least one step).
    pub fn clear_day(
        day: &ClearDay,
        site: &Site,
        duration_s: f64,
    ) -> Result<Weather, WeatherError> {
        site.validate()?;
        clear_day::build(day, site, duration_s)
    }

    /// The coldest air temperature of any row (K).
    pub fn coldest_air_k(&self) -> f64 {
        self.samples
            .iter()
            .map(|s| s.air_k)
            .fold(f64::INFINITY, f64::min)
    }

    /// Last time (s) the weather covers; first is 0 for clear_day, the first row for CSV.
    pub fn span_s(&self) -> (f64, f64) {
        (self.times_s[0], self.times_s[self.times_s.len() - 1])
    }

    /// Linear interpolation in time of every quantity on its own; the sun direction is the
    /// normalized linear interpolation of the two rows' unit vectors (no azimuth wrap) — docs/design.md
    /// §1.8. Outside the span: Err(WeatherError::OutOfRange{..}) naming the time and span.
    pub fn at(&self, time_s: f64) -> Result<WeatherSample, WeatherError> {
        let (first_s, last_s) = self.span_s();
        if !(time_s >= first_s && time_s <= last_s) {
            return Err(WeatherError::OutOfRange {
                time_s,
                first_s,
                last_s,
                start_utc: format_time_utc(&self.start_utc),
            });
        }
        // The first row after time_s (1 ≤ i ≤ n − 1 when time_s < last), or an exact hit.
        let i = self.times_s.partition_point(|&t| t <= time_s);
        if i == self.times_s.len() || self.times_s[i - 1] == time_s {
            return Ok(self.samples[i - 1]);
        }
        let (t0, t1) = (self.times_s[i - 1], self.times_s[i]);
        Ok(interpolate(
            &self.samples[i - 1],
            &self.samples[i],
            (time_s - t0) / (t1 - t0),
        ))
    }

    /// Weather from rows the caller has checked: at least two, times strictly ascending, sun
    /// directions of neighbours not opposite.
    fn from_rows(
        start_utc: DateTime<Utc>,
        times_s: Vec<f64>,
        samples: Vec<WeatherSample>,
    ) -> Weather {
        debug_assert!(times_s.len() >= 2 && times_s.len() == samples.len());
        debug_assert!(times_s.windows(2).all(|w| w[0] < w[1]));
        Weather {
            start_utc,
            times_s,
            samples,
        }
    }
}

/// Whether two unit sun directions have a normalized linear interpolation everywhere between
/// them: not opposite (their sum is not (nearly) zero).
fn nlerp_defined(a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
    (a + b).norm() > 1e-6
}

/// The sample a fraction `w` (0…1) of the way from `a` to `b` (docs/design.md §1.8).
fn interpolate(a: &WeatherSample, b: &WeatherSample, w: f64) -> WeatherSample {
    let lerp = |x: f64, y: f64| x + w * (y - x);
    WeatherSample {
        air_k: lerp(a.air_k, b.air_k),
        wind_m_s: lerp(a.wind_m_s, b.wind_m_s),
        direct_normal_w_m2: lerp(a.direct_normal_w_m2, b.direct_normal_w_m2),
        diffuse_horizontal_w_m2: lerp(a.diffuse_horizontal_w_m2, b.diffuse_horizontal_w_m2),
        longwave_down_w_m2: lerp(a.longwave_down_w_m2, b.longwave_down_w_m2),
        sun_direction: ((1.0 - w) * a.sun_direction + w * b.sun_direction).normalize(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emitter::{parse_time_utc, sun_direction};

    fn sample(air_k: f64, elevation: f64, azimuth: f64) -> WeatherSample {
        WeatherSample {
            air_k,
            wind_m_s: air_k / 100.0,
            direct_normal_w_m2: 2.0 * air_k,
            diffuse_horizontal_w_m2: 0.5 * air_k,
            longwave_down_w_m2: swinbank_longwave_w_m2(air_k),
            sun_direction: sun_direction(elevation, azimuth),
        }
    }

    fn two_rows() -> Weather {
        Weather::from_rows(
            parse_time_utc("2026-06-21T00:00:00Z").unwrap(),
            vec![100.0, 700.0, 1300.0],
            vec![
                sample(280.0, 10.0, 350.0),
                sample(290.0, 30.0, 20.0),
                sample(300.0, 40.0, 60.0),
            ],
        )
    }

    #[test]
    fn interpolation_is_linear_and_the_sun_is_nlerped() {
        let weather = two_rows();
        assert_eq!(weather.span_s(), (100.0, 1300.0));
        let half = weather.at(400.0).unwrap();
        assert!((half.air_k - 285.0).abs() < 1e-12);
        assert!((half.wind_m_s - 2.85).abs() < 1e-12);
        assert!((half.direct_normal_w_m2 - 570.0).abs() < 1e-12);
        assert!((half.diffuse_horizontal_w_m2 - 142.5).abs() < 1e-12);
        // Each quantity on its own: the long-wave is the mean of the rows, not Swinbank of the mean.
        let lw = 0.5 * (swinbank_longwave_w_m2(280.0) + swinbank_longwave_w_m2(290.0));
        assert!((half.longwave_down_w_m2 - lw).abs() < 1e-12);
        // The sun halfway: the normalized mean of the two unit vectors, across north (350° → 20°)
        // without wrapping through south.
        let (a, b) = (sun_direction(10.0, 350.0), sun_direction(30.0, 20.0));
        let mean = ((a + b) / 2.0).normalize();
        assert!((half.sun_direction - mean).norm() < 1e-15);
        assert!((half.sun_direction.norm() - 1.0).abs() < 1e-15);
        assert!(half.sun_direction.y > 0.9, "{}", half.sun_direction);
        // A quarter of the way.
        let quarter = weather.at(250.0).unwrap();
        assert!((quarter.air_k - 282.5).abs() < 1e-12);
        let q = (0.75 * a + 0.25 * b).normalize();
        assert!((quarter.sun_direction - q).norm() < 1e-15);
        // Rows are returned exactly, the last included.
        assert_eq!(weather.at(700.0).unwrap().air_k, 290.0);
        assert_eq!(weather.at(1300.0).unwrap().air_k, 300.0);
        assert_eq!(weather.at(100.0).unwrap().sun_direction, a);
    }

    #[test]
    fn outside_the_span_is_an_error_naming_time_and_span() {
        let weather = two_rows();
        for t in [99.999, 1300.001, -5.0, f64::NAN, f64::INFINITY] {
            let error = weather.at(t).unwrap_err();
            assert!(matches!(error, WeatherError::OutOfRange { .. }), "{error}");
            let text = error.to_string();
            assert!(
                text.contains(&format!("{t} s"))
                    && text.contains("100 s to 1300 s")
                    && text.contains("2026-06-21T00:00:00Z"),
                "{text}"
            );
        }
    }

    #[test]
    fn clear_days_deserialize_from_the_scene_toml() {
        // docs/design.md §2.4 writes integers; unknown keys are refused by name.
        let day: ClearDay =
            toml::from_str("air_min_k = 281\nair_max_k = 293.5\nwind_m_s = 2").unwrap();
        assert_eq!(
            (day.air_min_k, day.air_max_k, day.wind_m_s),
            (281.0, 293.5, 2.0)
        );
        let error = toml::from_str::<ClearDay>("air_min_k = 281\nair_max_k = 293\nwind = 2")
            .unwrap_err()
            .to_string();
        assert!(error.contains("unknown field `wind`"), "{error}");
    }

    #[test]
    fn swinbank_at_288_k() {
        // 5.31e-13 · 288⁶ = 303.0047576 W m⁻² (288⁶ = 570 630 428 688 384).
        assert_eq!(288f64.powi(6), 570_630_428_688_384.0);
        assert!((swinbank_longwave_w_m2(288.0) - 303.004_757_6).abs() < 1e-6);
    }

    #[test]
    fn instants_are_offsets_from_the_start() {
        let site = Site {
            latitude_deg: 0.0,
            longitude_deg: 0.0,
            start_utc: parse_time_utc("2026-06-21T00:00:00Z").unwrap(),
        };
        let at = |t: f64| site.instant(t).map(|i| format_time_utc(&i));
        assert_eq!(at(3600.5).as_deref(), Some("2026-06-21T01:00:00.500Z"));
        assert_eq!(at(-0.25).as_deref(), Some("2026-06-20T23:59:59.750Z"));
        assert_eq!(at(1e20), None);
        assert_eq!(at(f64::NAN), None);
        assert!(nlerp_defined(
            &sun_direction(0.0, 0.0),
            &sun_direction(0.0, 179.0)
        ));
        assert!(!nlerp_defined(
            &sun_direction(0.0, 0.0),
            &sun_direction(0.0, 180.0)
        ));
    }
}
