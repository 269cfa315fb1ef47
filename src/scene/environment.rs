//! The unpolarized environment seen from the scene (docs/design.md §1.5): sky radiance as a function of
//! elevation above the horizon, and the ground below it. It depends on world elevation only, which
//! the renderer's reflection tables rely on.
//!
//! Ground radiance = ε_g L_bb(T_g) + (1 − ε_g) E_sky/π: the ground emits and reflects the sky
//! diffusely, E_sky/π = 2 ∫₀¹ L_sky(u) u du with u = sin(elevation).

use super::config::{EnvironmentConfig, GroundConfig, SkyConfig};
use super::{valid_temperature, MAX_TEMPERATURE_K};
use crate::optics::Band;
use crate::text::number;
use nalgebra::Vector3;

/// An `[environment]` that cannot be used: the key at fault and why.
pub type EnvironmentError = super::error::InvalidSetting;

/// Samples of the sky radiance over u = sin(elevation) ∈ [0, 1]. The window model is smooth and a
/// 1/1024 step keeps linear interpolation within ~1e-7 relative.
const SKY_SAMPLES: usize = 1025;

#[derive(Clone, Debug)]
pub struct Environment {
    /// Sky radiance at u = i/(SKY_SAMPLES − 1), W·m⁻²·sr⁻¹.
    sky: Vec<f64>,
    ground: f64,
}

impl Environment {
    /// Builds the environment for a sensor band. Errors name the offending key.
    pub fn new(config: &EnvironmentConfig, band: &Band) -> Result<Environment, EnvironmentError> {
        let air = config.air_temperature_k;
        if !valid_temperature(air) {
            return Err(format!(
                "environment.air_temperature_k = {} must be within [0, {MAX_TEMPERATURE_K}] K",
                number(air)
            )
            .into());
        }
        let sky_at = sky_model(&config.sky, air, band)?;
        let sky: Vec<f64> = (0..SKY_SAMPLES)
            .map(|i| sky_at(i as f64 / (SKY_SAMPLES - 1) as f64))
            .collect();
        let ground = ground_radiance(&config.ground, &sky, band)?;
        Ok(Environment { sky, ground })
    }

    /// The same radiance in every direction (an isothermal enclosure at radiance `radiance`).
    pub fn uniform(radiance: f64) -> Environment {
        Environment {
            sky: vec![radiance; SKY_SAMPLES],
            ground: radiance,
        }
    }

    /// Radiance arriving from world direction `direction` (unit, pointing away from the receiver).
    #[inline]
    pub fn radiance(&self, direction: &Vector3<f64>) -> f64 {
        self.radiance_at_sine(direction.z)
    }

    /// Radiance at sin(elevation) = u; the ground below the horizon.
    #[inline]
    pub fn radiance_at_sine(&self, u: f64) -> f64 {
        if u < 0.0 {
            return self.ground;
        }
        let x = u.min(1.0) * (SKY_SAMPLES - 1) as f64;
        let i = (x as usize).min(SKY_SAMPLES - 2);
        let f = x - i as f64;
        self.sky[i] + f * (self.sky[i + 1] - self.sky[i])
    }

    pub fn ground_radiance(&self) -> f64 {
        self.ground
    }

    /// The radiance as a branch-free piecewise-linear function of u ∈ [−1, 1] on `cells` equal
    /// cells (even, so the horizon u = 0 is a cell boundary and the sky/ground jump is exact).
    pub fn sine_table(&self, cells: usize) -> SineTable {
        let cells = cells.max(2) & !1;
        let h = 2.0 / cells as f64;
        let pieces = (0..cells)
            .map(|i| {
                let u0 = -1.0 + i as f64 * h;
                if u0 < -0.5 * h {
                    [self.ground, 0.0]
                } else {
                    let (a, b) = (self.radiance_at_sine(u0), self.radiance_at_sine(u0 + h));
                    [a, b - a]
                }
            })
            .collect();
        SineTable {
            cells_per_unit: 1.0 / h,
            pieces,
        }
    }
}

/// [`Environment::sine_table`]: per cell, the radiance at its left end and its increase across
/// the cell. Lookups take the cell coordinate x = (u + 1)·cells_per_unit, so that callers can fold
/// the scaling into precomputed coefficients.
#[derive(Clone, Debug)]
pub struct SineTable {
    pub cells_per_unit: f64,
    pieces: Vec<[f64; 2]>,
}

impl SineTable {
    /// A table of `cells` (radiance at each cell's left end, its increase across the cell) over
    /// u ∈ [−1, 1], for another function of u on the same cells (e.g. one spectral component of
    /// the environment, `transport::band_environment`).
    pub fn from_cells(cells: Vec<[f64; 2]>) -> SineTable {
        SineTable {
            cells_per_unit: cells.len() as f64 / 2.0,
            pieces: cells,
        }
    }

    /// Each cell's (radiance at its left end, increase across it).
    pub fn cells(&self) -> &[[f64; 2]] {
        &self.pieces
    }

    /// Radiance at cell coordinate x (clamped to the table).
    #[inline]
    pub fn at_cell(&self, x: f64) -> f64 {
        let i = (x.max(0.0) as usize).min(self.pieces.len() - 1);
        let [a, rise] = self.pieces[i];
        a + rise * (x - i as f64)
    }

    /// Radiance at u = sin(elevation).
    #[inline]
    pub fn radiance(&self, u: f64) -> f64 {
        self.at_cell((u + 1.0) * self.cells_per_unit)
    }
}

/// Sky radiance as a function of u = sin(elevation).
fn sky_model<'a>(
    sky: &'a SkyConfig,
    air_k: f64,
    band: &'a Band,
) -> Result<Box<dyn Fn(f64) -> f64 + 'a>, EnvironmentError> {
    match sky {
        SkyConfig::Window { zenith_emissivity } => {
            let e = *zenith_emissivity;
            if !(e.is_finite() && e > 0.0 && e <= 1.0) {
                return Err(format!(
                    "environment.sky.zenith_emissivity = {} must be within (0, 1]",
                    number(e)
                )
                .into());
            }
            let air = band.radiance(air_k);
            // ε_sky(θ_z) = 1 − (1 − ε_zenith)^(1/cos θ_z), cos θ_z = u; → 1 at the horizon.
            Ok(Box::new(move |u: f64| {
                let emissivity = if u <= 0.0 {
                    1.0
                } else {
                    1.0 - (1.0 - e).powf(1.0 / u)
                };
                emissivity * air
            }))
        }
        SkyConfig::Table {
            elevation_deg,
            radiance,
            brightness_temperature_k,
        } => {
            let (values, in_temperature) = match (radiance, brightness_temperature_k) {
                (Some(r), None) => (r, false),
                (None, Some(t)) => (t, true),
                _ => {
                    return Err("environment.sky table needs exactly one of radiance and \
                        brightness_temperature_k"
                        .into())
                }
            };
            validate_sky_table(elevation_deg, values)?;
            let knots: Vec<(f64, f64)> = elevation_deg
                .iter()
                .copied()
                .zip(values.iter().copied())
                .collect();
            // Interpolated in the unit given (a table of brightness temperatures is linear in
            // temperature between its knots), then converted.
            Ok(Box::new(move |u: f64| {
                let elevation = u.clamp(0.0, 1.0).asin().to_degrees();
                let value = interpolate(&knots, elevation);
                if in_temperature {
                    band.radiance(value)
                } else {
                    value
                }
            }))
        }
    }
}

fn validate_sky_table(elevation_deg: &[f64], values: &[f64]) -> Result<(), EnvironmentError> {
    if elevation_deg.len() < 2 || elevation_deg.len() != values.len() {
        return Err(format!(
            "environment.sky table needs ≥ 2 elevations and as many values (got {} and {})",
            elevation_deg.len(),
            values.len()
        )
        .into());
    }
    if elevation_deg[0] != 0.0 || *elevation_deg.last().unwrap_or(&0.0) != 90.0 {
        return Err(
            "environment.sky.elevation_deg must run from 0 (horizon) to 90 (zenith)".into(),
        );
    }
    if elevation_deg.iter().any(|e| !e.is_finite())
        || elevation_deg.windows(2).any(|w| w[1] <= w[0])
    {
        return Err("environment.sky.elevation_deg must be strictly increasing".into());
    }
    if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(format!(
            "environment.sky table value {} must be finite and ≥ 0",
            crate::text::number(*v)
        )
        .into());
    }
    Ok(())
}

fn interpolate(knots: &[(f64, f64)], x: f64) -> f64 {
    let i = knots
        .partition_point(|k| k.0 <= x)
        .clamp(1, knots.len() - 1);
    let ((x0, y0), (x1, y1)) = (knots[i - 1], knots[i]);
    y0 + (y1 - y0) * ((x - x0) / (x1 - x0)).clamp(0.0, 1.0)
}

fn ground_radiance(
    ground: &GroundConfig,
    sky: &[f64],
    band: &Band,
) -> Result<f64, EnvironmentError> {
    let (t, e) = (ground.temperature_k, ground.emissivity);
    if !valid_temperature(t) {
        return Err(format!(
            "environment.ground.temperature_k = {} must be within [0, {MAX_TEMPERATURE_K}] K",
            number(t)
        )
        .into());
    }
    if !(e.is_finite() && (0.0..=1.0).contains(&e)) {
        return Err(format!(
            "environment.ground.emissivity = {} must be within [0, 1]",
            number(e)
        )
        .into());
    }
    // E_sky/π = 2∫₀¹ L(u) u du by the trapezoid rule on the sample grid.
    let h = 1.0 / (sky.len() - 1) as f64;
    let mut irradiance_over_pi = 0.0;
    for (i, pair) in sky.windows(2).enumerate() {
        let (u0, u1) = (i as f64 * h, (i + 1) as f64 * h);
        irradiance_over_pi += (pair[0] * u0 + pair[1] * u1) * h;
    }
    Ok(e * band.radiance(t) + (1.0 - e) * irradiance_over_pi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(sky: SkyConfig, ground_t: f64, ground_e: f64) -> EnvironmentConfig {
        EnvironmentConfig {
            air_temperature_k: 283.15,
            sky,
            ground: GroundConfig {
                temperature_k: ground_t,
                emissivity: ground_e,
                thermal: None,
            },
        }
    }

    #[test]
    fn window_sky_follows_the_model_and_meets_air_at_the_horizon() {
        let band = Band::lwir();
        let env = Environment::new(
            &config(
                SkyConfig::Window {
                    zenith_emissivity: 0.75,
                },
                288.0,
                1.0,
            ),
            &band,
        )
        .unwrap();
        let air = band.radiance(283.15);
        assert!((env.radiance(&Vector3::z()) - 0.75 * air).abs() < 1e-9 * air);
        let u = 30f64.to_radians().sin(); // θ_z = 60°: ε = 1 − 0.25² = 0.9375
        assert!((env.radiance_at_sine(u) - 0.9375 * air).abs() < 1e-6 * air);
        assert!((env.radiance_at_sine(1e-6) - air).abs() < 1e-9 * air);
        assert!((env.radiance_at_sine(-0.2) - band.radiance(288.0)).abs() < 1e-12);
    }

    #[test]
    fn sine_table_keeps_the_horizon_jump() {
        let band = Band::lwir();
        let env = Environment::new(
            &config(
                SkyConfig::Window {
                    zenith_emissivity: 0.75,
                },
                300.0,
                1.0,
            ),
            &band,
        )
        .unwrap();
        let table = env.sine_table(2048);
        for u in [-1.0, -0.3, -1e-9, 0.0, 1e-9, 0.01, 0.2, 0.7, 1.0] {
            let exact = env.radiance_at_sine(u);
            assert!((table.radiance(u) - exact).abs() < 1e-6 * exact, "{u}");
        }
    }

    #[test]
    fn ground_reflects_the_sky_diffusely() {
        let band = Band::lwir();
        let sky = SkyConfig::Table {
            elevation_deg: vec![0.0, 90.0],
            radiance: Some(vec![20.0, 20.0]),
            brightness_temperature_k: None,
        };
        let env = Environment::new(&config(sky, 0.0, 0.25), &band).unwrap();
        // A uniform sky of 20 reflected with 1 − ε = 0.75: 15.
        assert!((env.ground_radiance() - 15.0).abs() < 1e-5);
    }

    #[test]
    fn brightness_temperature_tables_convert_at_the_knots() {
        let band = Band::lwir();
        let sky = SkyConfig::Table {
            elevation_deg: vec![0.0, 30.0, 90.0],
            radiance: None,
            brightness_temperature_k: Some(vec![280.0, 260.0, 240.0]),
        };
        let env = Environment::new(&config(sky, 288.0, 0.9), &band).unwrap();
        let at_30 = env.radiance_at_sine(0.5);
        assert!((at_30 - band.radiance(260.0)).abs() < 1e-3 * at_30);
    }

    #[test]
    fn bad_environments_name_the_key() {
        let band = Band::lwir();
        let cases = [
            (
                SkyConfig::Window {
                    zenith_emissivity: 1.5,
                },
                "zenith_emissivity",
            ),
            (
                SkyConfig::Table {
                    elevation_deg: vec![0.0, 45.0],
                    radiance: Some(vec![1.0, 1.0]),
                    brightness_temperature_k: None,
                },
                "from 0 (horizon) to 90",
            ),
            (
                SkyConfig::Table {
                    elevation_deg: vec![0.0, 90.0],
                    radiance: Some(vec![1.0, 1.0]),
                    brightness_temperature_k: Some(vec![1.0, 1.0]),
                },
                "exactly one",
            ),
        ];
        for (sky, expected) in cases {
            let err = Environment::new(&config(sky, 288.0, 0.9), &band)
                .unwrap_err()
                .to_string();
            assert!(err.contains(expected), "{err}");
        }
        let err = Environment::new(
            &config(
                SkyConfig::Window {
                    zenith_emissivity: 0.7,
                },
                288.0,
                1.2,
            ),
            &band,
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("ground.emissivity"));
    }
}
