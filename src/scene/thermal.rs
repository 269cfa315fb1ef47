//! The `[thermal]` section of a scene (docs/design.md §1.8, §2.4) tied to the scene: which parts
//! have a layer stack, the default emissivity from their materials, and how the scene is rebuilt
//! at an instant of the run. The keys themselves are checked by [`crate::thermal::setup`];
//! nothing is solved here (`thermal_scene` runs the model).

use super::config::{EnvironmentConfig, ObjectConfig, PartThermalConfig, SceneConfig};
use super::{SceneError, SceneMaterial, Surface};
use crate::emitter::moving_sun_irradiance;
use crate::optics::Band;
use crate::thermal::setup::{
    resolve_part, resolve_run, Enclosure, GroundSurface, SurfaceThermal, ThermalSetupError,
};
pub use crate::thermal::setup::{Schedule, ThermalSetup};
use std::collections::BTreeMap;
use std::path::Path;

/// How the scene is rebuilt at an instant of the run: the sky follows the air temperature (and so
/// do the atmosphere's path temperature and the NETD reference when the scene does not fix them),
/// the sun follows the weather's direction with this band irradiance.
#[derive(Clone, Debug)]
pub struct InstantSettings {
    pub environment: EnvironmentConfig,
    pub atmosphere_temperature_given: bool,
    pub netd_reference_given: bool,
    pub sun_irradiance_w_m2: f64,
}

/// The run of `[thermal]` (its surfaces come later, [`resolve_surfaces`]), how the scene is
/// rebuilt at its instants, and the air temperature at its start. `None` without `[thermal]`.
pub(super) fn resolve_thermal(
    path: &Path,
    config: &SceneConfig,
    dir: &Path,
    band: &Band,
) -> Result<Option<(ThermalSetup, InstantSettings, f64)>, SceneError> {
    let fail = |error| SceneError::Thermal {
        file: path.to_owned(),
        error,
    };
    let Some(thermal) = &config.thermal else {
        return match config.environment.ground.thermal {
            Some(_) => Err(fail(ThermalSetupError::GroundWithoutRun)),
            None => Ok(None),
        };
    };
    let sun_irradiance_w_m2 =
        moving_sun_irradiance(config.sun.as_ref(), band).map_err(|error| SceneError::Sun {
            file: path.to_owned(),
            error,
        })?;
    let instants = InstantSettings {
        environment: config.environment.clone(),
        atmosphere_temperature_given: config
            .atmosphere
            .as_ref()
            .is_some_and(|a| a.temperature_k.is_some()),
        netd_reference_given: config.sensor.netd_reference_k.is_some(),
        sun_irradiance_w_m2,
    };
    let ground_k = config.environment.ground.temperature_k;
    let mut run = resolve_run(thermal, dir, ground_k).map_err(fail)?;
    run.ground = resolve_ground(config, &run.enclosures).map_err(fail)?;
    let start_air_k = run
        .weather
        .at(0.0)
        .map_err(|e| fail(ThermalSetupError::Weather(e)))?
        .air_k;
    Ok(Some((run, instants, start_air_k)))
}

/// `environment.ground.thermal`: its keys checked as a part's (its emissivity defaults to the
/// ground's), no enclosure; its starting state the ground's typed temperature.
fn resolve_ground(
    config: &SceneConfig,
    enclosures: &[Enclosure],
) -> Result<Option<GroundSurface>, ThermalSetupError> {
    let ground = &config.environment.ground;
    let Some(part) = &ground.thermal else {
        return Ok(None);
    };
    if part.enclosure.is_some() {
        return Err(ThermalSetupError::GroundEnclosure { key: "enclosure" });
    }
    if part.solar_transmittance.is_some() {
        let key = "solar_transmittance";
        return Err(ThermalSetupError::GroundEnclosure { key });
    }
    let no_layers = BTreeMap::new();
    let layers = config.thermal.as_ref().map_or(&no_layers, |t| &t.layers);
    let emissivity = part.emissivity.unwrap_or(ground.emissivity);
    let surface = resolve_part(part, layers, enclosures, emissivity)
        .map_err(ThermalSetupError::GroundSurface)?;
    Ok(Some(GroundSurface {
        surface,
        initial_k: ground.temperature_k,
        occluded_k: config.thermal.as_ref().and_then(|t| t.ground_temperature_k),
    }))
}

/// The thermal stack of an object's part `part`: its own, else the object's.
pub fn part_thermal<'a>(object: &'a ObjectConfig, part: &str) -> Option<&'a PartThermalConfig> {
    object
        .parts
        .get(part)
        .and_then(|p| p.thermal.as_ref())
        .or(object.thermal.as_ref())
}

/// Each surface's thermal model. `materials[i]` is material i (its
/// [`SceneMaterial::thermal_emissivity`] is the default emissivity); every enclosure of
/// `enclosures` must have a member.
pub(super) fn resolve_surfaces(
    path: &Path,
    config: &SceneConfig,
    surfaces: &[Surface],
    object_names: &[String],
    materials: &[SceneMaterial],
    enclosures: &[Enclosure],
) -> Result<Vec<Option<SurfaceThermal>>, SceneError> {
    let no_layers = BTreeMap::new();
    let layers = config.thermal.as_ref().map_or(&no_layers, |t| &t.layers);
    let mut resolved = Vec::with_capacity(surfaces.len());
    let mut emissivity_of = BTreeMap::new();
    for surface in surfaces {
        let Some(part) = part_thermal(&config.objects[surface.object], &surface.part) else {
            resolved.push(None);
            continue;
        };
        let label = format!(
            "objects[{}] '{}' part '{}': thermal",
            surface.object, object_names[surface.object], surface.part
        );
        let emissivity = match part.emissivity {
            Some(e) => e,
            None => match emissivity_of.get(&surface.material) {
                Some(&e) => e,
                None => {
                    let e = materials[surface.material]
                        .thermal_emissivity()
                        .map_err(|error| SceneError::material(path, Some(label.clone()), error))?;
                    emissivity_of.insert(surface.material, e);
                    e
                }
            },
        };
        let model = resolve_part(part, layers, enclosures, emissivity).map_err(|error| {
            let error = ThermalSetupError::Part { part: label, error };
            SceneError::Thermal {
                file: path.to_owned(),
                error,
            }
        })?;
        resolved.push(Some(model));
    }
    let fail = |error| SceneError::Thermal {
        file: path.to_owned(),
        error,
    };
    if resolved.iter().all(Option::is_none) {
        return Err(fail(ThermalSetupError::NoStack));
    }
    let member = |e: usize| resolved.iter().flatten().any(|m| m.enclosure == Some(e));
    if let Some(e) = (0..enclosures.len()).find(|&e| !member(e)) {
        let name = enclosures[e].name.clone();
        return Err(fail(ThermalSetupError::EmptyEnclosure { name }));
    }
    Ok(resolved)
}
