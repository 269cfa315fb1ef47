//! The `[thermal]` keys of a scene, checked (docs/design.md §1.8, §2.4): the weather, the site and
//! the run's time sampling ([`ThermalSetup`]), and a part's layer stack and surface properties
//! ([`SurfaceThermal`]). Nothing is solved here; `thermal_scene` runs the model. Which parts have
//! a stack, and their materials' emissivities, are the scene's to say.

use super::config::{EnclosureConfig, ThermalConfig, WeatherConfig};
use crate::emitter::{parse_time_utc, SunError};
use crate::optics::{valid_temperature, MAX_TEMPERATURE_K};
use crate::text::{about, number};
use crate::weather::{Site, StationFormat, StationWeather, Weather, WeatherError, WeatherFormat};
use std::collections::BTreeMap;
use std::path::Path;

mod part;

pub use part::{
    resolve_part, PartThermalError, Schedule, SurfaceThermal, MAX_CONVECTION_W_M2K,
    MAX_INTERNAL_HEAT_W_M2, MAX_SCHEDULE_H,
};

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
    /// The environment's ground as a surface of its own (`environment.ground.thermal`), or `None`
    /// for the typed ground temperature.
    pub ground: Option<GroundSurface>,
    /// `[thermal.enclosures]` in name order; [`SurfaceThermal::enclosure`] indexes it.
    pub enclosures: Vec<Enclosure>,
}

/// The environment's ground solved with the run: horizontal, unshadowed, the whole sky in view.
pub struct GroundSurface {
    pub surface: SurfaceThermal,
    /// The starting state (`environment.ground.temperature_k`).
    pub initial_k: f64,
    /// `thermal.ground_temperature_k` when given: what blocked directions radiate (below the
    /// horizon is the solved ground); `None`: the solved ground there too.
    pub occluded_k: Option<f64>,
}

/// One enclosed air node (`[thermal.enclosures.NAME]`).
#[derive(Clone, Debug, PartialEq)]
pub struct Enclosure {
    pub name: String,
    /// Heat capacity C (J/K).
    pub heat_capacity_j_k: f64,
    /// Air-exchange conductance G to the outside air (W/K).
    pub air_exchange_w_k: f64,
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

/// A `[thermal]` key that cannot be used. The inner errors are part of the message.
#[derive(Debug, thiserror::Error)]
pub enum ThermalSetupError {
    #[error("thermal.start_utc: {0}")]
    StartUtc(SunError),
    #[error(
        "thermal.{key} is required with a weather CSV or a clear day (an EPW or TMY3 weather \
         file gives it)"
    )]
    Required { key: &'static str },
    #[error("thermal.{key} applies only to {} weather file: remove it", if *key == "weather_year" { "an EPW or TMY3" } else { "a" })]
    StationOnly { key: &'static str },
    #[error("thermal.latitude_deg = {} must be within [-90°, 90°]", number(*.0))]
    Latitude(f64),
    #[error("thermal.longitude_deg = {} must be within [-180°, 360°]", number(*.0))]
    Longitude(f64),
    #[error("thermal.duration_h = {} must be positive", number(*.0))]
    Duration(f64),
    /// The weather file cannot be read, or the weather has no value at an instant.
    #[error("{0}")]
    Weather(WeatherError),
    #[error("thermal.weather.clear_day: {}", .0.detail())]
    ClearDay(WeatherError),
    #[error(
        "thermal: the weather covers {}…{} s but the run needs 0…{} s (duration_h = {})",
        number(*first_s), number(*last_s), number(*duration_s), number(*duration_s / 3600.0)
    )]
    WeatherSpan {
        first_s: f64,
        last_s: f64,
        duration_s: f64,
    },
    #[error(
        "thermal.spinup_days = {spinup_days} repeats the first day, but the weather covers only {} s",
        number(*last_s)
    )]
    SpinupSpan { spinup_days: u32, last_s: f64 },
    #[error("thermal.{key} = {} must be positive", number(*step))]
    Step { key: &'static str, step: f64 },
    #[error(
        "thermal.{key} = {} s makes {} steps over the run of {} s (at most {}): use a longer step \
         or a shorter run",
        number(*step_s), about(*steps), number(*duration_s), number(*limit as f64)
    )]
    TooManySteps {
        key: &'static str,
        step_s: f64,
        duration_s: f64,
        steps: f64,
        limit: usize,
    },
    #[error("thermal.spinup_days = {0} is more than {MAX_SPINUP_DAYS} days: a periodic start needs a few")]
    Spinup(u32),
    #[error(
        "thermal.ground_temperature_k = {} must be within (0, {MAX_TEMPERATURE_K}] K",
        number(*ground_k)
    )]
    Ground { ground_k: f64 },
    #[error(
        "[thermal] is given but no part has a thermal stack: add [objects.thermal] or \
         [objects.parts.NAME.thermal] with a stack"
    )]
    NoStack,
    /// A part's `thermal` table; `part` names it ("objects\[0\] 'car' part 'hood': thermal").
    #[error("{part}.{error}")]
    Part {
        part: String,
        error: PartThermalError,
    },
    /// `environment.ground.thermal`, its keys checked as a part's.
    #[error("environment.ground.thermal.{0}")]
    GroundSurface(PartThermalError),
    #[error(
        "environment.ground.thermal.{key}: the environment's ground has no enclosure behind it; \
         remove {key}"
    )]
    GroundEnclosure { key: &'static str },
    #[error(
        "environment.ground.thermal needs a [thermal] section (the weather, site and layers that \
         drive it)"
    )]
    GroundWithoutRun,
    #[error(
        "thermal.enclosures.{}.{key} = {} must be within {range}",
        crate::text::shown(name), number(*value)
    )]
    Enclosure {
        name: String,
        key: &'static str,
        value: f64,
        range: &'static str,
    },
    #[error(
        "thermal.enclosures.{}: no part's thermal table has enclosure = \"{}\"; add it to the \
         member parts or remove the enclosure",
        crate::text::shown(name),
        crate::text::shown(name)
    )]
    EmptyEnclosure { name: String },
}

/// The weather, site and sampling of `[thermal]`; the surfaces come later (they need the scene's
/// parts and materials, [`resolve_part`]). `default_ground_k` is the scene's ground temperature.
pub fn resolve_run(
    config: &ThermalConfig,
    dir: &Path,
    default_ground_k: f64,
) -> Result<ThermalSetup, ThermalSetupError> {
    if config.spinup_days > MAX_SPINUP_DAYS {
        return Err(ThermalSetupError::Spinup(config.spinup_days));
    }
    let requested_s = match config.duration_h {
        Some(h) if h.is_finite() && h > 0.0 => Some(h * 3600.0),
        Some(h) => return Err(ThermalSetupError::Duration(h)),
        None => None,
    };
    let (site, weather) = resolve_weather(config, dir, requested_s)?;
    let (first, last) = weather.span_s();
    let duration_s = requested_s.unwrap_or(last);
    if first > 0.0 || last < duration_s {
        return Err(ThermalSetupError::WeatherSpan {
            first_s: first,
            last_s: last,
            duration_s,
        });
    }
    if config.spinup_days > 0 && last < DAY_S {
        return Err(ThermalSetupError::SpinupSpan {
            spinup_days: config.spinup_days,
            last_s: last,
        });
    }
    check_steps(config, duration_s)?;
    let ground = config.ground_temperature_k.unwrap_or(default_ground_k);
    if !(valid_temperature(ground) && ground > 0.0) {
        return Err(ThermalSetupError::Ground { ground_k: ground });
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
        ground: None,
        enclosures: resolve_enclosures(&config.enclosures)?,
    })
}

/// `[thermal.enclosures]` checked, in name order (members are checked with the parts).
fn resolve_enclosures(
    configs: &BTreeMap<String, EnclosureConfig>,
) -> Result<Vec<Enclosure>, ThermalSetupError> {
    configs
        .iter()
        .map(|(name, c)| {
            let check = |key, value: f64, ok: bool, range| {
                if ok {
                    Ok(value)
                } else {
                    Err(ThermalSetupError::Enclosure {
                        name: name.clone(),
                        key,
                        value,
                        range,
                    })
                }
            };
            let capacity = c.heat_capacity_j_k;
            let exchange = c.air_exchange_w_k;
            Ok(Enclosure {
                name: name.clone(),
                heat_capacity_j_k: check(
                    "heat_capacity_j_k",
                    capacity,
                    capacity > 0.0 && capacity <= MAX_ENCLOSURE_CAPACITY_J_K,
                    "(0, 1e12] J/K",
                )?,
                air_exchange_w_k: check(
                    "air_exchange_w_k",
                    exchange,
                    (0.0..=MAX_AIR_EXCHANGE_W_K).contains(&exchange),
                    "[0, 1e9] W/K",
                )?,
            })
        })
        .collect()
}

/// Where and when the run is: the scene's keys, each defaulting to the station file's (its site,
/// its first hour) when the weather is one.
fn resolve_site(
    config: &ThermalConfig,
    station: Option<&StationWeather>,
) -> Result<Site, ThermalSetupError> {
    let required = |key: &'static str| ThermalSetupError::Required { key };
    let start_utc = match (&config.start_utc, station) {
        (Some(text), _) => parse_time_utc(text).map_err(ThermalSetupError::StartUtc)?,
        (None, Some(file)) => file.first_utc(),
        (None, None) => return Err(required("start_utc")),
    };
    let file = station.map(|f| f.station);
    let lat = config
        .latitude_deg
        .or(file.map(|s| s.latitude_deg))
        .ok_or(required("latitude_deg"))?;
    let lon = config
        .longitude_deg
        .or(file.map(|s| s.longitude_deg))
        .ok_or(required("longitude_deg"))?;
    if !(lat.is_finite() && (-90.0..=90.0).contains(&lat)) {
        return Err(ThermalSetupError::Latitude(lat));
    }
    if !(lon.is_finite() && (-180.0..=360.0).contains(&lon)) {
        return Err(ThermalSetupError::Longitude(lon));
    }
    Ok(Site {
        latitude_deg: lat,
        longitude_deg: lon,
        start_utc,
    })
}

/// The site and the weather: a file (relative to `dir`) in its format, or a generated clear day
/// long enough for the run and its spin-up day.
fn resolve_weather(
    config: &ThermalConfig,
    dir: &Path,
    requested_s: Option<f64>,
) -> Result<(Site, Weather), ThermalSetupError> {
    let days = config.spinup_days as f64 * DAY_S;
    let file = match &config.weather {
        WeatherConfig::File(file) => dir.join(file),
        WeatherConfig::Generated(g) => {
            if let Some(key) = station_only_key(config) {
                return Err(ThermalSetupError::StationOnly { key });
            }
            let site = resolve_site(config, None)?;
            let weather =
                Weather::clear_day(&g.clear_day, &site, requested_s.unwrap_or(DAY_S).max(days))
                    .map_err(ThermalSetupError::ClearDay)?;
            return Ok((site, weather));
        }
    };
    let weather_error = ThermalSetupError::Weather;
    let bytes = std::fs::read(&file).map_err(|e| {
        weather_error(WeatherError::Read {
            file: file.clone(),
            reason: e.to_string(),
        })
    })?;
    let station_format = match WeatherFormat::detect(&file, &bytes, config.weather_format) {
        WeatherFormat::Epw => StationFormat::Epw,
        WeatherFormat::Tmy3 => StationFormat::Tmy3,
        WeatherFormat::Csv => {
            if config.weather_year.is_some() {
                return Err(ThermalSetupError::StationOnly {
                    key: "weather_year",
                });
            }
            let site = resolve_site(config, None)?;
            let weather = Weather::parse_csv(&file, &bytes, &site).map_err(weather_error)?;
            return Ok((site, weather));
        }
    };
    let station = StationWeather::parse(&file, &bytes, station_format, config.weather_year)
        .map_err(weather_error)?;
    let site = resolve_site(config, Some(&station))?;
    let span = requested_s.map(|s| s.max(if days > 0.0 { DAY_S } else { 0.0 }));
    let weather = station.to_weather(&site, span).map_err(weather_error)?;
    Ok((site, weather))
}

/// A key that only a station file (EPW, TMY3) uses, given with a clear day.
fn station_only_key(config: &ThermalConfig) -> Option<&'static str> {
    if config.weather_format.is_some() {
        Some("weather_format")
    } else if config.weather_year.is_some() {
        Some("weather_year")
    } else {
        None
    }
}

/// The three time steps (and the plane cell) are positive and the run has no more of each step
/// than its limit, checked before anything is allocated (a 1e-300 s output step once asked for 1e304 recorded instants).
fn check_steps(config: &ThermalConfig, duration_s: f64) -> Result<(), ThermalSetupError> {
    // Weather and shadow samples run through the spun-up first day too.
    let sampled_s = if config.spinup_days > 0 {
        duration_s.max(DAY_S)
    } else {
        duration_s
    };
    let steps = [
        (
            "output_step_s",
            config.output_step_s,
            duration_s,
            MAX_RECORDED_INSTANTS,
        ),
        ("time_step_s", config.time_step_s, sampled_s, MAX_STEPS),
        ("shadow_step_s", config.shadow_step_s, sampled_s, MAX_STEPS),
    ];
    if !(config.plane_cell_m.is_finite() && config.plane_cell_m > 0.0) {
        return Err(ThermalSetupError::Step {
            key: "plane_cell_m",
            step: config.plane_cell_m,
        });
    }
    for (key, step_s, span_s, limit) in steps {
        if !(step_s.is_finite() && step_s > 0.0) {
            return Err(ThermalSetupError::Step { key, step: step_s });
        }
        let count = (span_s / step_s).floor() + 1.0;
        if count > limit as f64 {
            return Err(ThermalSetupError::TooManySteps {
                key,
                step_s,
                duration_s: span_s,
                steps: count,
                limit,
            });
        }
    }
    Ok(())
}

const DAY_S: f64 = 86_400.0;
/// Most weather and shadow samples of a run: a year at the default 60 s is 525 600; each sample
/// holds a weather row (~80 bytes) and, per thermal vertex, a byte of sun visibility.
pub const MAX_STEPS: usize = 2_000_000;
/// Most recorded instants (rows of temperatures.csv per part, one PLY each): 10 days every minute.
pub const MAX_RECORDED_INSTANTS: usize = 15_000;
/// Most spin-up days: the periodic state is reached in one to a few.
pub const MAX_SPINUP_DAYS: u32 = 100;
/// Largest enclosure heat capacity (J/K): a hall of 1e5 m³ of air with its contents is ~1e9.
pub const MAX_ENCLOSURE_CAPACITY_J_K: f64 = 1e12;
/// Largest air-exchange conductance (W/K): a wide-open hall.
pub const MAX_AIR_EXCHANGE_W_K: f64 = 1e9;
