//! The scene's view of the world (docs/design.md §2.3, §2.4): camera, sensor, environment,
//! atmosphere and the AoP mask, checked in the order their errors are reported.

use super::camera::Camera;
use super::config::{AtmosphereConfig, SceneConfig};
use super::environment::Environment;
use super::sensor::{resolve_sensor, Sensor};
use super::{Atmosphere, SceneError};
use crate::atmosphere::read_table;
use crate::optics::{valid_temperature, MAX_TEMPERATURE_K};
use crate::text::number;
use nalgebra::Vector3;
use std::path::Path;
use std::sync::Arc;

/// The scene's own sections (camera, sensor, environment, atmosphere, render), checked in the
/// order their errors are reported.
pub(super) struct Viewing {
    pub camera: Camera,
    pub sensor: Sensor,
    pub environment: Environment,
    pub atmosphere: Option<Atmosphere>,
    pub aop_mask_dolp: f64,
}

/// Camera, sensor, environment, atmosphere and the AoP mask, checked.
pub(super) fn resolve_viewing(path: &Path, config: &SceneConfig) -> Result<Viewing, SceneError> {
    let fail = |message: String| SceneError::new(path, message);
    let c = &config.camera;
    let camera = Camera::new(
        Vector3::from(c.position),
        Vector3::from(c.look_at),
        Vector3::from(c.up),
        c.fov_deg,
        c.resolution[0],
        c.resolution[1],
    )
    .map_err(|e| fail(e.to_string()))?;
    let sensor = resolve_sensor(path, config)?;
    let environment =
        Environment::new(&config.environment, &sensor.band).map_err(|e| fail(e.to_string()))?;
    let atmosphere = match &config.atmosphere {
        None => None,
        Some(a) => Some(resolve_atmosphere(
            path,
            a,
            config.environment.air_temperature_k,
            &sensor,
        )?),
    };
    let mask = config.render.aop_mask_dolp;
    if !(mask.is_finite() && (0.0..=1.0).contains(&mask)) {
        return Err(fail(format!(
            "render.aop_mask_dolp = {} must be within [0, 1]",
            number(mask)
        )));
    }
    Ok(Viewing {
        camera,
        sensor,
        environment,
        atmosphere,
        aop_mask_dolp: mask,
    })
}

/// `[atmosphere]`: extinction and path temperature (default the air's), or a table.
fn resolve_atmosphere(
    path: &Path,
    a: &AtmosphereConfig,
    air_k: f64,
    sensor: &Sensor,
) -> Result<Atmosphere, SceneError> {
    let extinction_per_km = match (a.extinction_per_km, &a.table) {
        (Some(_), Some(_)) => {
            return Err(SceneError::new(
                path,
                "atmosphere: extinction_per_km and table both describe the path: keep one",
            ))
        }
        (None, None) => {
            return Err(SceneError::new(
                path,
                "atmosphere: give extinction_per_km (a grey path) or table = \"path.csv\" (a \
                 radiative-transfer table), or remove [atmosphere]",
            ))
        }
        (None, Some(table)) => return atmosphere_table(path, a, table, sensor),
        (Some(beta), None) => beta,
    };
    let temperature_k = a.temperature_k.unwrap_or(air_k);
    if !(extinction_per_km.is_finite() && extinction_per_km >= 0.0) {
        return Err(SceneError::new(
            path,
            format!(
                "atmosphere.extinction_per_km = {} must be finite and ≥ 0",
                number(extinction_per_km)
            ),
        ));
    }
    if !valid_temperature(temperature_k) {
        return Err(SceneError::new(
            path,
            format!(
                "atmosphere.temperature_k = {} must be within [0, {MAX_TEMPERATURE_K}] K",
                number(temperature_k)
            ),
        ));
    }
    Ok(Atmosphere::extinction(
        extinction_per_km * 1e-3,
        temperature_k,
        &sensor.band,
    ))
}

/// `atmosphere.table`, relative to the scene file, over the sensor band; a spectral table's
/// transmittance is weighted by a blackbody at the NETD reference (docs/design.md §1.12).
fn atmosphere_table(
    path: &Path,
    a: &AtmosphereConfig,
    table: &str,
    sensor: &Sensor,
) -> Result<Atmosphere, SceneError> {
    if a.temperature_k.is_some() {
        return Err(SceneError::new(
            path,
            "atmosphere.temperature_k belongs to extinction_per_km: a table gives its own path \
             radiance, remove temperature_k",
        ));
    }
    if table.trim().is_empty() {
        return Err(SceneError::new(
            path,
            "atmosphere.table is empty: give the CSV file's path (relative to the scene file)",
        ));
    }
    let refuse = |error| SceneError::Atmosphere {
        file: path.to_owned(),
        error,
    };
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let table = read_table(&dir.join(table)).map_err(refuse)?;
    Atmosphere::from_table(Arc::new(table), &sensor.band, sensor.netd_reference_k).map_err(refuse)
}
