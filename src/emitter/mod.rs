//! Light sources that are not scene surfaces (docs/design.md §1.7): the sun, its position, its disc
//! radiance and the disc quadrature the renderer integrates reflected sunlight with. (Today's sky and ground environment still lives in `scene::environment`; docs/design.md §3 plans
//! it here as `sky.rs`.)
//!
//! World frame everywhere in this module (docs/design.md §1.7): z up, north +y, east +x; azimuth clockwise
//! from north (+y) toward east (+x), elevation above the xy-plane. Angles are in degrees and say so
//! in their names, because they come straight from scene files, weather files and the CLI.

pub mod disc;
pub mod scene_sun;
pub mod sun;

pub use disc::{DiscQuadrature, Sun};
pub use scene_sun::{moving_sun_irradiance, SunConfig, SunConfigError, DEFAULT_SUN_TRANSMITTANCE};

pub use sun::{
    default_band_irradiance, disc_radiance, format_time_utc, parse_time_utc, sun_direction,
    sun_position, sun_position_with, validate_irradiance, validate_sun_angles,
    validate_transmittance, Atmosphere, SpaOptions, SunError, SunPosition,
    SUN_ANGULAR_DIAMETER_DEG, SUN_HALF_ANGLE_DEG, SUN_SOLID_ANGLE_SR, SUN_TEMPERATURE_K,
};
