//! STUB (replaced by the weather branch): constant weather with the SPA sun.
use crate::emitter::{sun_direction, sun_position};
use chrono::{DateTime, Utc};
use nalgebra::Vector3;
use std::path::Path;

pub struct Site {
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    pub start_utc: DateTime<Utc>,
}

#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClearDay {
    pub air_min_k: f64,
    pub air_max_k: f64,
    pub wind_m_s: f64,
}

#[derive(Debug, Clone, Copy)]
pub struct WeatherSample {
    pub air_k: f64,
    pub wind_m_s: f64,
    pub direct_normal_w_m2: f64,
    pub diffuse_horizontal_w_m2: f64,
    pub longwave_down_w_m2: f64,
    pub sun_direction: Vector3<f64>,
}

pub struct Weather {
    day: ClearDay,
    lat: f64,
    lon: f64,
    start: DateTime<Utc>,
    end: f64,
}

#[derive(Debug, thiserror::Error)]
pub enum WeatherError {
    #[error("{0}")]
    Message(String),
}

impl Weather {
    pub fn read_csv(path: &Path, _site: &Site) -> Result<Weather, WeatherError> {
        Err(WeatherError::Message(format!("{}: stub", path.display())))
    }
    pub fn clear_day(
        day: &ClearDay,
        site: &Site,
        duration_s: f64,
    ) -> Result<Weather, WeatherError> {
        Ok(Weather {
            day: *day,
            lat: site.latitude_deg,
            lon: site.longitude_deg,
            start: site.start_utc,
            end: duration_s,
        })
    }
    pub fn span_s(&self) -> (f64, f64) {
        (0.0, self.end)
    }
    pub fn at(&self, time_s: f64) -> Result<WeatherSample, WeatherError> {
        let t = self.start + chrono::Duration::milliseconds((time_s * 1000.0) as i64);
        let p = sun_position(self.lat, self.lon, &t).unwrap();
        let s = sun_direction(p.elevation_deg, p.azimuth_deg);
        let up = s.z.max(0.0);
        let air = self.day.air_min_k + (self.day.air_max_k - self.day.air_min_k) * up;
        Ok(WeatherSample {
            air_k: air,
            wind_m_s: self.day.wind_m_s,
            direct_normal_w_m2: if s.z > 0.0 { 800.0 * up.powf(0.3) } else { 0.0 },
            diffuse_horizontal_w_m2: 100.0 * up,
            longwave_down_w_m2: 5.31e-13 * air.powi(6),
            sun_direction: s,
        })
    }
}
