//! A thermal scene as it is at one recorded instant of its run: the solved surface temperatures,
//! the sky at that instant's air temperature, and the sun where the weather puts it (docs/design.md §2.6,
//! `render --time`).

use super::ThermalSolution;
use crate::emitter::format_time_utc;
use crate::emitter::Sun;
use crate::scene::environment::{Environment, EnvironmentError};
use crate::scene::{Scene, ThermalInstant};
use std::path::PathBuf;

/// Why a scene cannot be shown at an instant of its thermal run.
#[derive(Debug, thiserror::Error)]
pub enum InstantError {
    #[error("{} has no [thermal] section", crate::text::path(path))]
    NoThermal { path: PathBuf },
    /// The sky at the instant's air temperature.
    #[error("{0}")]
    Environment(EnvironmentError),
}

/// `scene` at recorded instant `index` of `solution`. The sky is rebuilt at the instant's air
/// temperature, the ground at its solved temperature when it is a thermal surface, and so are the atmosphere's path temperature and the NETD reference unless the
/// scene fixes them; the sun is the weather's direction with the scene's band irradiance (none
/// below the horizon).
pub fn scene_at(
    scene: &Scene,
    solution: &ThermalSolution,
    index: usize,
) -> Result<Scene, InstantError> {
    let no_thermal = || InstantError::NoThermal {
        path: scene.path.clone(),
    };
    let setup = scene.thermal.as_deref().ok_or_else(no_thermal)?;
    let instants = scene.thermal_rebuild.as_ref().ok_or_else(no_thermal)?;
    let w = &solution.weather[index];
    let mut at = scene.clone();
    at.mesh.temperatures = solution.surface_k[index].clone();
    at.air_temperature_k = w.air_k;
    let mut environment = instants.environment.clone();
    environment.air_temperature_k = w.air_k;
    // A solved ground radiates at its temperature of the instant (the typed one was its start).
    if let Some(ground_k) = &solution.ground_k {
        environment.ground.temperature_k = ground_k[index];
    }
    at.environment =
        Environment::new(&environment, &scene.sensor.band).map_err(InstantError::Environment)?;
    let band = &scene.sensor.band;
    if let Some(a) = &mut at.atmosphere {
        // The path follows the air unless the scene fixes its temperature; a spectral table's
        // weight follows the NETD reference as the sensor's does below.
        if !instants.atmosphere_temperature_given {
            *a = a.with_path_temperature(w.air_k, band);
        }
        if !instants.netd_reference_given {
            *a = a.with_reference_temperature(w.air_k, band);
        }
    }
    if !instants.netd_reference_given {
        at.sensor.netd_reference_k = w.air_k;
    }
    let time_s = solution.times_s[index];
    let instant =
        setup.site.start_utc + chrono::Duration::milliseconds((time_s * 1e3).round() as i64);
    at.thermal_instant = Some(ThermalInstant {
        time_s,
        time_utc: format_time_utc(&instant),
    });
    at.sun = (w.sun_direction.z > 0.0).then_some(Sun {
        direction: w.sun_direction,
        irradiance: instants.sun_irradiance_w_m2,
    });
    Ok(at)
}
