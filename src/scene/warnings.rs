//! What in a scene is probably a mistake but not an error (docs/design.md §2.3): the binary prints
//! each once and `summary.json` lists them.

use super::config::SceneConfig;
use super::SceneMaterial;
use crate::optics::Band;
use crate::text::number;

/// Below this a temperature is probably in °C (the coldest natural surface, Antarctic snow at
/// night, is ~180 K; nothing a thermal camera images is colder in an irpol scene).
pub(super) const CELSIUS_SUSPECT_K: f64 = 200.0;

/// Probable mistakes that are not errors: a sun the open-world model ignores, temperatures that
/// look like °C, inline materials nothing uses, library materials measured outside the sensor
/// band.
pub(super) fn likely_mistakes(
    config: &SceneConfig,
    materials: &[SceneMaterial],
    band: &Band,
) -> Vec<String> {
    let mut warnings = Vec::new();
    if config.sun.is_some() && config.render.open_world && config.thermal.is_none() {
        warnings.push(
            "[sun] is ignored with render.open_world = true (the open-world model has no sun): \
             remove open_world to light the scene with the sun"
                .to_owned(),
        );
    }
    for (i, object) in config.objects.iter().enumerate() {
        let name = object
            .name
            .clone()
            .unwrap_or_else(|| format!("object{}", i + 1));
        let typed = std::iter::once((String::new(), object.temperature_k)).chain(
            object
                .parts
                .iter()
                .map(|(part, p)| (format!(" part '{part}'"), p.temperature_k)),
        );
        for (what, t) in typed {
            if let Some(t) = t.filter(|&t| t < CELSIUS_SUSPECT_K) {
                warnings.push(format!(
                    "objects[{i}] '{name}'{what}: temperature_k = {} K looks like °C \
                     (temperatures are kelvin: {} °C is {} K)",
                    number(t),
                    number(t),
                    number(t + 273.15)
                ));
            }
        }
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
