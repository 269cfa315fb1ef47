//! The thermal keys of a scene file (docs/design.md §1.8, §2.4): `[thermal]`, its layer
//! materials, and the stack of an object or part. Checked by [`super::setup`].

use crate::toml_table::{table, table_map};
use serde::{Deserialize, Deserializer};
use std::collections::BTreeMap;

/// `[thermal]` (docs/design.md §1.8, §2.4): where the weather comes from, where and when the scene is, and
/// how finely the run is sampled.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThermalConfig {
    pub weather: WeatherConfig,
    /// The weather file's format; default from the file (`.epw`, a TMY3 header, else irpol's CSV).
    pub weather_format: Option<crate::weather::WeatherFormat>,
    /// Read every row of an EPW or TMY3 file in this year (typical-year files mix years).
    pub weather_year: Option<i32>,
    /// RFC 3339 instant of time_s = 0 (the weather file's origin); an EPW or TMY3 file's first
    /// hour when not given.
    pub start_utc: Option<String>,
    /// The site; an EPW or TMY3 file's own when not given (required otherwise).
    pub latitude_deg: Option<f64>,
    pub longitude_deg: Option<f64>,
    /// Length of the run; default the weather file's span (24 h for `clear_day`).
    pub duration_h: Option<f64>,
    /// Surface temperatures are recorded (CSV, PLY, plot) every `output_step_s`.
    #[serde(default = "default_output_step")]
    pub output_step_s: f64,
    /// The first day's weather is run this many times before t = 0 (a periodic start).
    #[serde(default)]
    pub spinup_days: u32,
    /// Temperature of what occluded directions and the ground below the horizon radiate (K);
    /// default `environment.ground.temperature_k`.
    pub ground_temperature_k: Option<f64>,
    /// Weather and sun are sampled every `time_step_s`; the solver sub-steps adaptively inside.
    #[serde(default = "default_time_step")]
    pub time_step_s: f64,
    /// Shadow rays toward the sun every `shadow_step_s` (linear in between).
    #[serde(default = "default_shadow_step")]
    pub shadow_step_s: f64,
    /// A procedural plane with a thermal stack is solved on cells no larger than this (m): its
    /// `divisions` are raised to reach it, because the model solves per vertex and a shadow
    /// smaller than a cell would fall between vertices (docs/design.md §1.8).
    #[serde(default = "default_plane_cell")]
    pub plane_cell_m: f64,
    /// Layer materials by name.
    #[serde(default, deserialize_with = "table_map")]
    pub layers: BTreeMap<String, LayerMaterialConfig>,
    /// Enclosed air nodes by name (a car's cabin), coupled to their member parts' back faces.
    #[serde(default, deserialize_with = "table_map")]
    pub enclosures: BTreeMap<String, EnclosureConfig>,
}

/// `[thermal.enclosures.NAME]`: one enclosed air node (docs/design.md §1.8).
#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct EnclosureConfig {
    /// Heat capacity of the enclosed air and what is lumped with it (J/K).
    pub heat_capacity_j_k: f64,
    /// Conductance of the air exchange with the outside air, ventilation and leakage (W/K).
    pub air_exchange_w_k: f64,
}

fn default_output_step() -> f64 {
    600.0
}

fn default_plane_cell() -> f64 {
    0.25
}

fn default_time_step() -> f64 {
    60.0
}

fn default_shadow_step() -> f64 {
    600.0
}

/// `weather = "file.csv"` or `weather = { clear_day = { air_min_k, air_max_k, wind_m_s } }`.
#[derive(Debug, Deserialize)]
#[serde(
    untagged,
    expecting = "a weather CSV path, or { clear_day = { air_min_k = …, air_max_k = …, wind_m_s = … } }"
)]
pub enum WeatherConfig {
    File(String),
    #[serde(deserialize_with = "table")]
    Generated(GeneratedWeather),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeneratedWeather {
    #[serde(deserialize_with = "table")]
    pub clear_day: crate::weather::ClearDay,
}

/// `[thermal.layers.NAME]`: one layer material.
#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct LayerMaterialConfig {
    pub conductivity_w_mk: f64,
    pub density_kg_m3: f64,
    pub heat_capacity_j_kgk: f64,
}

/// `[objects.thermal]` or `[objects.parts.NAME.thermal]` (§2.4).
#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct PartThermalConfig {
    /// Front to back: `[layer name, thickness in m]`.
    #[serde(deserialize_with = "layer_stack")]
    pub stack: Vec<(String, f64)>,
    #[serde(default)]
    pub back: BackConfig,
    /// Fraction of the solar irradiance absorbed (0…1).
    pub solar_absorptance: f64,
    /// Thermal hemispherical emissivity; default the material's ε_0 from its pBRDF.
    pub emissivity: Option<f64>,
    /// Front convective coefficient (W m⁻² K⁻¹); default 5.7 + 3.8 v (McAdams).
    pub convection_w_m2k: Option<f64>,
    /// Heat entering at the back face (W m⁻²): a number, or `[[time_h, w_m2], …]` linear in time
    /// (hours from `start_utc`, non-decreasing; constant outside).
    #[serde(default)]
    pub internal_heat_w_m2: InternalHeatConfig,
    /// The enclosure (`[thermal.enclosures.NAME]`) the back face sees instead of the outside air.
    pub enclosure: Option<String>,
    /// Fraction of the solar irradiance on the front that passes into the enclosure (glazing).
    pub solar_transmittance: Option<f64>,
}

/// `[[name, thickness_m], …]`, refusing other shapes with a message that says what an entry is
/// (serde's tuple error, "expected a tuple of size 2", names neither).
fn layer_stack<'de, D>(deserializer: D) -> Result<Vec<(String, f64)>, D::Error>
where
    D: Deserializer<'de>,
{
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Item {
        Name(String),
        Number(f64),
    }
    let entries = Vec::<Vec<Item>>::deserialize(deserializer).map_err(|_| {
        serde::de::Error::custom("stack must be a list of [layer name, thickness_m] pairs")
    })?;
    entries
        .into_iter()
        .map(|entry| match entry.as_slice() {
            [Item::Name(name), Item::Number(d)] => Ok((name.clone(), *d)),
            _ => Err(serde::de::Error::custom(format!(
                "a stack entry is [layer name, thickness_m], e.g. [\"paint\", 0.0001]; got {} item(s)",
                entry.len()
            ))),
        })
        .collect()
}

/// `back = "adiabatic"`, `{ temperature_k = … }` or `{ convection_w_m2k = … }` (to the air).
#[derive(Debug, Deserialize, Clone, Default)]
#[serde(
    untagged,
    expecting = "\"adiabatic\", { temperature_k = … } or { convection_w_m2k = … }"
)]
pub enum BackConfig {
    #[default]
    #[serde(skip)]
    Adiabatic,
    Keyword(BackKeyword),
    #[serde(deserialize_with = "table")]
    Fixed(FixedBack),
    #[serde(deserialize_with = "table")]
    Convective(ConvectiveBack),
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(rename_all = "lowercase")]
pub enum BackKeyword {
    Adiabatic,
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub struct FixedBack {
    pub temperature_k: f64,
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub struct ConvectiveBack {
    pub convection_w_m2k: f64,
}

/// A constant internal heat flux or a schedule of `[time_h, w_m2]` points.
#[derive(Debug, Deserialize, Clone)]
#[serde(
    untagged,
    expecting = "a number (W m⁻²) or a list of [time_h, w_m2] pairs"
)]
pub enum InternalHeatConfig {
    Constant(f64),
    Schedule(Vec<(f64, f64)>),
}

impl Default for InternalHeatConfig {
    fn default() -> Self {
        InternalHeatConfig::Constant(0.0)
    }
}
