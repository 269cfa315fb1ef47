//! What in a scene is probably a mistake but not an error (docs/design.md §2.3): the binary prints
//! each once and `summary.json` lists them.

use super::config::{BackConfig, PartThermalConfig, SceneConfig, SkyConfig, WeatherConfig};
use super::{Atmosphere, SceneMaterial};
use crate::optics::Band;
use crate::text::{number, shown};
use nalgebra::Vector3;

/// Below this a temperature is probably in °C (the coldest natural surface, Antarctic snow at
/// night, is ~180 K; nothing a thermal camera images is colder in an irpol scene).
pub(super) const CELSIUS_SUSPECT_K: f64 = 200.0;

/// Probable mistakes that are not errors: a sun the open-world model ignores, temperatures that
/// look like °C (every temperature key, and the air of a weather file, whose coldest row is
/// `weather_coldest_air_k` with the file's name), inline materials nothing uses, library materials measured outside the sensor
/// band.
pub(super) fn likely_mistakes(
    config: &SceneConfig,
    materials: &[SceneMaterial],
    band: &Band,
    weather_coldest_air_k: Option<(&str, f64)>,
) -> Vec<String> {
    let mut warnings = Vec::new();
    if config.sun.is_some() && config.render.open_world && config.thermal.is_none() {
        warnings.push(
            "[sun] is ignored with render.open_world = true (the open-world model has no sun): \
             remove open_world to light the scene with the sun"
                .to_owned(),
        );
    }
    for (key, t) in typed_temperatures(config) {
        if t < CELSIUS_SUSPECT_K {
            warnings.push(looks_like_celsius(&key, t));
        }
    }
    if let Some((file, t)) = weather_coldest_air_k.filter(|&(_, t)| t < CELSIUS_SUSPECT_K) {
        warnings.push(format!(
            "thermal.weather '{}': air temperatures down to {} K look like °C (temperatures are \
             kelvin: {} °C is {} K)",
            shown(file),
            number(t),
            number(t),
            number(t + 273.15)
        ));
    }
    for key in config.materials.keys() {
        if !materials
            .iter()
            .any(|m| m.origin == "inline" && &m.name == key)
        {
            warnings.push(format!("[materials.{key}] is never used by any object"));
        }
    }
    let (lo, hi) = band.limits_um();
    for m in materials {
        if let Some(w) = m.wavelength_um.filter(|&w| w < lo || w > hi) {
            warnings.push(format!(
                "material '{}' ({}) was measured at {} µm, outside the sensor band {lo}–{hi} µm: \
                 its index is assumed to hold across the band",
                m.name,
                m.origin,
                number(w)
            ));
        }
    }
    warnings
}

/// An atmosphere table that ends before the farthest object point (a mesh vertex: a triangle's
/// farthest point from the camera is one of its corners): beyond its last range the render holds
/// the last row's τ and path radiance, which a user should know of rather than find.
pub(super) fn beyond_atmosphere_table(
    atmosphere: Option<&Atmosphere>,
    camera: &Vector3<f64>,
    positions: &[Vector3<f64>],
) -> Option<String> {
    let atmosphere = atmosphere?;
    let last = atmosphere.last_range_m()?;
    let farthest = positions
        .iter()
        .map(|p| (p - camera).norm())
        .fold(0.0, f64::max);
    (farthest > last).then(|| {
        format!(
            "atmosphere.table '{}' ends at {} m but objects reach {} m from the camera: beyond \
             {} m τ and path radiance are those of its last row (extend the table to the \
             farthest range)",
            crate::text::path(atmosphere.table_file().unwrap_or(std::path::Path::new(""))),
            number(last),
            crate::text::about(farthest),
            number(last)
        )
    })
}

/// `key = t K looks like °C …`, the one wording of every such warning.
fn looks_like_celsius(key: &str, t: f64) -> String {
    format!(
        "{key} = {} K looks like °C (temperatures are kelvin: {} °C is {} K)",
        number(t),
        number(t),
        number(t + 273.15)
    )
}

/// Every temperature typed in the scene file, with the key that holds it (the coldest of a sky
/// table). Part temperatures are the starting state of a thermal run, still kelvin.
fn typed_temperatures(config: &SceneConfig) -> Vec<(String, f64)> {
    let env = &config.environment;
    let mut typed = vec![
        (
            "environment.air_temperature_k".to_owned(),
            env.air_temperature_k,
        ),
        (
            "environment.ground.temperature_k".to_owned(),
            env.ground.temperature_k,
        ),
    ];
    typed.extend(back_temperature(&env.ground.thermal).map(|t| {
        (
            "environment.ground.thermal.back.temperature_k".to_owned(),
            t,
        )
    }));
    if let SkyConfig::Table {
        brightness_temperature_k: Some(table),
        ..
    } = &env.sky
    {
        if let Some(&coldest) = table.iter().min_by(|a, b| a.total_cmp(b)) {
            typed.push((
                "environment.sky.brightness_temperature_k".to_owned(),
                coldest,
            ));
        }
    }
    let optional = [
        (
            "atmosphere.temperature_k",
            config.atmosphere.as_ref().and_then(|a| a.temperature_k),
        ),
        ("sensor.netd_reference_k", config.sensor.netd_reference_k),
    ];
    if let Some(thermal) = &config.thermal {
        typed.extend(
            thermal
                .ground_temperature_k
                .map(|t| ("thermal.ground_temperature_k".to_owned(), t)),
        );
        if let WeatherConfig::Generated(g) = &thermal.weather {
            let day = &g.clear_day;
            typed.push((
                "thermal.weather.clear_day.air_min_k".to_owned(),
                day.air_min_k,
            ));
            typed.push((
                "thermal.weather.clear_day.air_max_k".to_owned(),
                day.air_max_k,
            ));
        }
    }
    typed.extend(
        optional
            .into_iter()
            .filter_map(|(k, t)| Some((k.to_owned(), t?))),
    );
    typed.extend(object_temperatures(config));
    typed
}

/// The temperatures typed on objects and parts: their starting (or fixed) temperature and a
/// stack's fixed back face.
fn object_temperatures(config: &SceneConfig) -> Vec<(String, f64)> {
    let mut typed = Vec::new();
    for (i, object) in config.objects.iter().enumerate() {
        let name = object
            .name
            .clone()
            .unwrap_or_else(|| format!("object{}", i + 1));
        let label = format!("objects[{i}] '{}'", shown(&name));
        typed.extend(
            object
                .temperature_k
                .map(|t| (format!("{label}: temperature_k"), t)),
        );
        typed.extend(
            back_temperature(&object.thermal)
                .map(|t| (format!("{label}: thermal.back.temperature_k"), t)),
        );
        for (part, p) in &object.parts {
            let label = format!("{label} part '{}'", shown(part));
            typed.extend(
                p.temperature_k
                    .map(|t| (format!("{label}: temperature_k"), t)),
            );
            typed.extend(
                back_temperature(&p.thermal)
                    .map(|t| (format!("{label}: thermal.back.temperature_k"), t)),
            );
        }
    }
    typed
}

/// The fixed back temperature of a part's thermal stack, if it has one.
fn back_temperature(thermal: &Option<PartThermalConfig>) -> Option<f64> {
    match thermal.as_ref()?.back {
        BackConfig::Fixed(f) => Some(f.temperature_k),
        _ => None,
    }
}
