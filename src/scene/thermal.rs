//! The `[thermal]` section of a scene, resolved (docs/design.md §1.8, §2.4): the weather, the site and
//! the run's time sampling, and per surface (object part) its layer stack and surface properties.
//! Nothing is solved here; `thermal_scene` runs the model.

use super::config::{
    BackConfig, EnvironmentConfig, InternalHeatConfig, LayerMaterialConfig, ObjectConfig,
    PartThermalConfig, SceneConfig, ThermalConfig, WeatherConfig,
};
use super::{valid_temperature, SceneMaterial, Surface, MAX_TEMPERATURE_K};
use crate::emitter::parse_time_utc;
use crate::text::number;
use crate::thermal::{Back, Layer, LayerMaterial, LayerStack, Site, Weather};
use std::collections::BTreeMap;
use std::path::Path;

/// The resolved `[thermal]` section.
pub struct ThermalSetup {
    pub site: Site,
    pub weather: Weather,
    /// The run covers [0, duration_s] seconds from `site.start_utc`.
    pub duration_s: f64,
    pub output_step_s: f64,
    pub time_step_s: f64,
    pub shadow_step_s: f64,
    pub spinup_days: u32,
    /// What occluded directions and the ground radiate in the long-wave balance (K).
    pub ground_temperature_k: f64,
    /// Per scene surface (indexed like `Scene::surfaces`): its thermal model, or `None` for a part
    /// held at its typed temperature.
    pub surfaces: Vec<Option<SurfaceThermal>>,
    pub instants: InstantSettings,
}

impl std::fmt::Debug for ThermalSetup {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ThermalSetup")
            .field("start_utc", &self.site.start_utc)
            .field("duration_s", &self.duration_s)
            .field("thermal_surfaces", &self.surfaces.iter().flatten().count())
            .finish_non_exhaustive()
    }
}

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

/// One part's thermal description.
pub struct SurfaceThermal {
    pub stack: LayerStack,
    pub back: Back,
    pub solar_absorptance: f64,
    /// Thermal hemispherical emissivity (given, or the material's ε_0 of §1.4).
    pub emissivity: f64,
    /// Front convective coefficient; `None` = 5.7 + 3.8 v (McAdams).
    pub convection_w_m2k: Option<f64>,
    pub internal_heat: Schedule,
}

/// A quantity piecewise linear in time (s), constant beyond its first and last points.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    points: Vec<(f64, f64)>,
}

impl Schedule {
    pub fn constant(value: f64) -> Schedule {
        Schedule {
            points: vec![(0.0, value)],
        }
    }

    /// The value at `time_s`. Equal times make a step (the later point wins from then on).
    pub fn at(&self, time_s: f64) -> f64 {
        let p = &self.points;
        let after = p.partition_point(|&(t, _)| t <= time_s);
        match after {
            0 => p[0].1,
            n if n == p.len() => p[n - 1].1,
            n => {
                let ((t0, v0), (t1, v1)) = (p[n - 1], p[n]);
                v0 + (v1 - v0) * (time_s - t0) / (t1 - t0)
            }
        }
    }
}

/// The weather, site and sampling of `[thermal]`; the surfaces come later
/// ([`resolve_surfaces`]) because they need the scene's parts and materials.
pub fn resolve_run(
    config: &ThermalConfig,
    dir: &Path,
    default_ground_k: f64,
    instants: InstantSettings,
) -> Result<ThermalSetup, String> {
    let start_utc =
        parse_time_utc(&config.start_utc).map_err(|e| format!("thermal.start_utc: {e}"))?;
    let (lat, lon) = (config.latitude_deg, config.longitude_deg);
    if !(lat.is_finite() && (-90.0..=90.0).contains(&lat)) {
        return Err(format!(
            "thermal.latitude_deg = {lat} must be within [-90°, 90°]"
        ));
    }
    if !(lon.is_finite() && (-180.0..=360.0).contains(&lon)) {
        return Err(format!(
            "thermal.longitude_deg = {lon} must be within [-180°, 360°]"
        ));
    }
    let site = Site {
        latitude_deg: lat,
        longitude_deg: lon,
        start_utc,
    };
    let requested_s = match config.duration_h {
        Some(h) if h.is_finite() && h > 0.0 => Some(h * 3600.0),
        Some(h) => return Err(format!("thermal.duration_h = {h} must be positive")),
        None => None,
    };
    let weather = match &config.weather {
        WeatherConfig::File(file) => {
            Weather::read_csv(&dir.join(file), &site).map_err(|e| e.to_string())?
        }
        WeatherConfig::Generated(g) => {
            let days = config.spinup_days as f64 * DAY_S;
            Weather::clear_day(&g.clear_day, &site, requested_s.unwrap_or(DAY_S).max(days))
                .map_err(|e| format!("thermal.weather.clear_day: {e}"))?
        }
    };
    let (first, last) = weather.span_s();
    let duration_s = requested_s.unwrap_or(last);
    if first > 0.0 || last < duration_s {
        return Err(format!(
            "thermal: the weather covers {}…{} s but the run needs 0…{} s (duration_h = {})",
            number(first),
            number(last),
            number(duration_s),
            number(duration_s / 3600.0)
        ));
    }
    if config.spinup_days > 0 && last < DAY_S {
        return Err(format!(
            "thermal.spinup_days = {} repeats the first day, but the weather covers only {} s",
            config.spinup_days,
            number(last)
        ));
    }
    let steps = [
        ("output_step_s", config.output_step_s),
        ("time_step_s", config.time_step_s),
        ("shadow_step_s", config.shadow_step_s),
    ];
    for (key, step) in steps {
        if !(step.is_finite() && step > 0.0) {
            return Err(format!("thermal.{key} = {step} must be positive"));
        }
    }
    if duration_s / config.time_step_s.min(config.shadow_step_s) > MAX_STEPS {
        return Err(format!(
            "thermal: {} s in steps of {} s is more than {MAX_STEPS} steps; use longer steps",
            number(duration_s),
            number(config.time_step_s.min(config.shadow_step_s))
        ));
    }
    let ground = config.ground_temperature_k.unwrap_or(default_ground_k);
    if !(valid_temperature(ground) && ground > 0.0) {
        return Err(format!(
            "thermal.ground_temperature_k = {} must be within (0, {MAX_TEMPERATURE_K}] K",
            number(ground)
        ));
    }
    Ok(ThermalSetup {
        site,
        weather,
        duration_s,
        output_step_s: config.output_step_s,
        time_step_s: config.time_step_s,
        shadow_step_s: config.shadow_step_s,
        spinup_days: config.spinup_days,
        ground_temperature_k: ground,
        surfaces: Vec::new(),
        instants,
    })
}

const DAY_S: f64 = 86_400.0;
/// Longest run in forcing or shadow steps: a 10-year run at 60 s is 5e6, far beyond any use.
const MAX_STEPS: f64 = 1e7;

/// The thermal stack of an object's part `part`: its own, else the object's.
pub fn part_thermal<'a>(object: &'a ObjectConfig, part: &str) -> Option<&'a PartThermalConfig> {
    object
        .parts
        .get(part)
        .and_then(|p| p.thermal.as_ref())
        .or(object.thermal.as_ref())
}

/// Each surface's thermal model. `materials[i]` is material i (its
/// [`SceneMaterial::thermal_emissivity`] is the default emissivity).
pub fn resolve_surfaces(
    config: &SceneConfig,
    thermal: &ThermalConfig,
    surfaces: &[Surface],
    object_names: &[String],
    materials: &[SceneMaterial],
) -> Result<Vec<Option<SurfaceThermal>>, String> {
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
                        .map_err(|e| format!("{label}: {e}"))?;
                    emissivity_of.insert(surface.material, e);
                    e
                }
            },
        };
        let model =
            resolve_part(part, &thermal.layers, emissivity).map_err(|e| format!("{label}.{e}"))?;
        resolved.push(Some(model));
    }
    if resolved.iter().all(Option::is_none) {
        return Err("[thermal] is given but no part has a thermal stack: add \
                    [objects.thermal] or [objects.parts.NAME.thermal] with a stack"
            .into());
    }
    Ok(resolved)
}

/// One part's keys, checked; errors start with the key at fault.
fn resolve_part(
    part: &PartThermalConfig,
    layers: &BTreeMap<String, LayerMaterialConfig>,
    emissivity: f64,
) -> Result<SurfaceThermal, String> {
    if part.stack.is_empty() {
        return Err("stack is empty: give [[layer name, thickness_m], …] front to back".into());
    }
    let mut stack = Vec::with_capacity(part.stack.len());
    for (name, thickness) in &part.stack {
        let m = layers.get(name).ok_or_else(|| {
            let known: Vec<&str> = layers.keys().map(String::as_str).collect();
            format!(
                "stack: layer '{name}' is not defined in [thermal.layers] (defined: {})",
                if known.is_empty() {
                    "none".into()
                } else {
                    known.join(", ")
                }
            )
        })?;
        let material = LayerMaterial::new(
            name,
            m.conductivity_w_mk,
            m.density_kg_m3,
            m.heat_capacity_j_kgk,
        );
        stack.push(Layer::new(material, *thickness));
    }
    let stack = LayerStack::new(stack).map_err(|e| format!("stack: {e}"))?;
    let fraction = |key: &str, v: f64| {
        if v.is_finite() && (0.0..=1.0).contains(&v) {
            Ok(v)
        } else {
            Err(format!("{key} = {v} must be within [0, 1]"))
        }
    };
    fraction("solar_absorptance", part.solar_absorptance)?;
    fraction("emissivity", emissivity)?;
    if let Some(h) = part.convection_w_m2k {
        if !(h.is_finite() && h >= 0.0) {
            return Err(format!("convection_w_m2k = {h} must be ≥ 0"));
        }
    }
    Ok(SurfaceThermal {
        stack,
        back: resolve_back(&part.back)?,
        solar_absorptance: part.solar_absorptance,
        emissivity,
        convection_w_m2k: part.convection_w_m2k,
        internal_heat: resolve_schedule(&part.internal_heat_w_m2)?,
    })
}

fn resolve_back(back: &BackConfig) -> Result<Back, String> {
    match *back {
        BackConfig::Adiabatic | BackConfig::Keyword(_) => Ok(Back::Adiabatic),
        BackConfig::Fixed(f) if valid_temperature(f.temperature_k) && f.temperature_k > 0.0 => {
            Ok(Back::Fixed(f.temperature_k))
        }
        BackConfig::Fixed(f) => Err(format!(
            "back.temperature_k = {} must be within (0, {MAX_TEMPERATURE_K}] K",
            number(f.temperature_k)
        )),
        BackConfig::Convective(c)
            if c.convection_w_m2k.is_finite() && c.convection_w_m2k >= 0.0 =>
        {
            Ok(Back::Convective {
                h_w_m2k: c.convection_w_m2k,
                air_k: None,
            })
        }
        BackConfig::Convective(c) => Err(format!(
            "back.convection_w_m2k = {} must be ≥ 0",
            c.convection_w_m2k
        )),
    }
}

fn resolve_schedule(heat: &InternalHeatConfig) -> Result<Schedule, String> {
    let points: Vec<(f64, f64)> = match heat {
        InternalHeatConfig::Constant(q) => vec![(0.0, *q)],
        InternalHeatConfig::Schedule(points) => {
            points.iter().map(|&(h, q)| (h * 3600.0, q)).collect()
        }
    };
    if points.is_empty() {
        return Err("internal_heat_w_m2 is an empty schedule: give [[time_h, w_m2], …]".into());
    }
    if let Some((t, q)) = points
        .iter()
        .find(|(t, q)| !(t.is_finite() && q.is_finite()))
    {
        return Err(format!(
            "internal_heat_w_m2 has a non-finite point [{}, {q}]",
            t / 3600.0
        ));
    }
    if let Some(w) = points.windows(2).find(|w| w[1].0 < w[0].0) {
        return Err(format!(
            "internal_heat_w_m2: times must not decrease ({} h after {} h)",
            number(w[1].0 / 3600.0),
            number(w[0].0 / 3600.0)
        ));
    }
    Ok(Schedule { points })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedules_interpolate_step_and_hold() {
        let s = resolve_schedule(&InternalHeatConfig::Schedule(vec![
            (1.0, 0.0),
            (1.0, 400.0),
            (2.0, 400.0),
            (3.0, 0.0),
        ]))
        .unwrap();
        assert_eq!(s.at(0.0), 0.0);
        assert_eq!(s.at(3599.0), 0.0);
        assert_eq!(s.at(3600.0), 400.0);
        assert_eq!(s.at(7200.0), 400.0);
        assert!((s.at(9000.0) - 200.0).abs() < 1e-12);
        assert_eq!(s.at(1e6), 0.0);
        assert_eq!(Schedule::constant(5.0).at(-3.0), 5.0);
    }

    #[test]
    fn decreasing_schedules_are_refused() {
        let e = resolve_schedule(&InternalHeatConfig::Schedule(vec![(2.0, 0.0), (1.0, 1.0)]))
            .unwrap_err();
        assert!(e.contains("must not decrease (1 h after 2 h)"), "{e}");
    }
}
