//! A scene's `[sun]` table (docs/design.md §2.4) resolved into a [`Sun`]: its direction, given or
//! from place and time, and its band irradiance, given or τ Ω L_bb(5772 K) over the sensor band.

use super::{
    default_band_irradiance, parse_time_utc, sun_direction, sun_position, validate_irradiance,
    validate_sun_angles, validate_transmittance, Sun, SunError,
};
use crate::optics::Band;
use serde::Deserialize;

/// `[sun]` (docs/design.md §2.4): a direction and an optional band irradiance.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunConfig {
    pub elevation_deg: Option<f64>,
    /// Clockwise from north (+y) toward east (+x).
    pub azimuth_deg: Option<f64>,
    /// Instead of elevation and azimuth: the place and the instant (RFC 3339, e.g.
    /// "2026-06-21T10:00:00Z"); the position comes from NREL's SPA (apparent elevation).
    pub latitude_deg: Option<f64>,
    pub longitude_deg: Option<f64>,
    pub time_utc: Option<String>,
    /// Band irradiance on a surface facing the sun (W m⁻²); default τ Ω L_bb(5772 K).
    pub irradiance_w_m2: Option<f64>,
    /// τ of the default irradiance.
    pub transmittance: Option<f64>,
}

/// A `[sun]` table that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum SunConfigError {
    /// One key's value is wrong (`key` as written in the scene, without `sun.`).
    #[error("sun.{key}: {error}")]
    Key { key: &'static str, error: SunError },
    #[error(
        "[sun] needs elevation_deg and azimuth_deg, or latitude_deg, longitude_deg and time_utc"
    )]
    Position,
    /// With `[thermal]` the run's weather places the sun.
    #[error(
        "with [thermal] the sun moves with the run (thermal.start_utc, latitude_deg, \
         longitude_deg): remove the position keys from [sun] (irradiance_w_m2 and transmittance \
         may stay)"
    )]
    PositionWithThermal,
}

fn key(key: &'static str) -> impl Fn(SunError) -> SunConfigError {
    move |error| SunConfigError::Key { key, error }
}

/// Atmospheric transmittance of the default solar irradiance (a clear LWIR window).
pub const DEFAULT_SUN_TRANSMITTANCE: f64 = 0.8;

impl SunConfig {
    /// The sun of this table over `band`. A sun at or below the horizon is no sun.
    pub fn resolve(&self, band: &Band) -> Result<Option<Sun>, SunConfigError> {
        let place = (self.latitude_deg, self.longitude_deg, &self.time_utc);
        let (elevation, azimuth) = match (self.elevation_deg, self.azimuth_deg, place) {
            (Some(e), Some(a), (None, None, None)) => (e, a),
            (None, None, (Some(latitude), Some(longitude), Some(time))) => {
                let time = parse_time_utc(time).map_err(key("time_utc"))?;
                let p = sun_position(latitude, longitude, &time)
                    .map_err(key("latitude_deg/longitude_deg"))?;
                (p.elevation_deg, p.azimuth_deg)
            }
            _ => return Err(SunConfigError::Position),
        };
        validate_sun_angles(elevation, azimuth).map_err(key("elevation_deg/azimuth_deg"))?;
        let irradiance = self.band_irradiance(band)?;
        if elevation <= 0.0 {
            return Ok(None);
        }
        Ok(Some(Sun {
            direction: sun_direction(elevation, azimuth),
            irradiance,
        }))
    }

    /// The sun's band irradiance on a surface facing it: given, or τ Ω L_bb(5772 K) over the band.
    pub fn band_irradiance(&self, band: &Band) -> Result<f64, SunConfigError> {
        let transmittance = self.transmittance.unwrap_or(DEFAULT_SUN_TRANSMITTANCE);
        validate_transmittance(transmittance).map_err(key("transmittance"))?;
        match self.irradiance_w_m2 {
            Some(e) => {
                validate_irradiance(e).map_err(key("irradiance_w_m2"))?;
                Ok(e)
            }
            None => Ok(default_band_irradiance(band, transmittance)),
        }
    }

    /// Whether the table places the sun (with `[thermal]` the weather does).
    pub fn has_position(&self) -> bool {
        self.elevation_deg.is_some()
            || self.azimuth_deg.is_some()
            || self.latitude_deg.is_some()
            || self.longitude_deg.is_some()
            || self.time_utc.is_some()
    }
}

/// The band irradiance of the sun of a thermal scene, whose direction comes from the weather:
/// `[sun]` may only give the irradiance or transmittance.
pub fn moving_sun_irradiance(sun: Option<&SunConfig>, band: &Band) -> Result<f64, SunConfigError> {
    match sun {
        Some(s) if s.has_position() => Err(SunConfigError::PositionWithThermal),
        Some(s) => s.band_irradiance(band),
        None => Ok(default_band_irradiance(band, DEFAULT_SUN_TRANSMITTANCE)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> SunConfig {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn a_sun_needs_a_direction_or_a_place_and_time() {
        let band = Band::new(8.0, 12.0, None).unwrap();
        let e = table("elevation_deg = 30").resolve(&band).unwrap_err();
        assert!(
            e.to_string().starts_with("[sun] needs elevation_deg"),
            "{e}"
        );
        let sun = table("elevation_deg = 30\nazimuth_deg = 90\nirradiance_w_m2 = 10")
            .resolve(&band)
            .unwrap()
            .unwrap();
        assert_eq!(sun.irradiance, 10.0);
        assert!(table("elevation_deg = -5\nazimuth_deg = 90")
            .resolve(&band)
            .unwrap()
            .is_none());
        let e = table("transmittance = 2")
            .band_irradiance(&band)
            .unwrap_err();
        assert!(e.to_string().starts_with("sun.transmittance: "), "{e}");
    }
}
