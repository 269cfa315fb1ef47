//! Why a thermal run fails: its error, the limits on its tables checked before they are
//! allocated, and where in the run a vertex's solve failed.

use super::vertices::{field_sets, shadow_instants_count, vertex_surfaces};
use crate::scene::Scene;
use crate::text::{about, number};
use crate::thermal::setup::ThermalSetup;
use crate::thermal::ThermalError;

/// Why a thermal run failed.
#[derive(Debug, thiserror::Error)]
pub enum ThermalRunError {
    #[error("{0} has no [thermal] section")]
    NotThermal(String),
    /// The weather has no value at a time the run needs.
    #[error("{0}")]
    Weather(crate::weather::WeatherError),
    #[error(
        "thermal time {} s is outside the run 0…{} s",
        number(*time_s), number(*duration_s)
    )]
    OutsideRun { time_s: f64, duration_s: f64 },
    /// A table of the run would outgrow its limit ([`MAX_SHADOW_SAMPLES`],
    /// [`MAX_RECORDED_VALUES`]); refused before it is allocated.
    #[error(
        "{vertices} {} × {instants} {what} = {} values, more than {}: use a coarser mesh or a \
         longer {key}",
        if *what == "shadow instants" { "thermal vertices" } else { "vertices" },
        about((*vertices as f64) * (*instants as f64)), number(*limit as f64)
    )]
    TooLarge {
        vertices: usize,
        instants: usize,
        what: &'static str,
        key: &'static str,
        limit: usize,
    },
    /// The solve of one part's vertex failed; `part` names it ("objects[0] 'car' part 'hood'"),
    /// `at` says when. The solver's error is part of the message, said once.
    #[error("{part}{at}: {error}")]
    Solver {
        part: String,
        at: String,
        error: ThermalError,
    },
    /// An enclosure's air temperature and its members' back faces did not agree (within 1e-3 K)
    /// after the fixed-point iterations of a step.
    #[error(
        "thermal.enclosures.{}{at}: the air temperature did not settle (members and balance {} K \
         apart after {iterations} iterations); try a smaller time_step_s",
        crate::text::shown(name), number(*residual_k)
    )]
    Enclosure {
        name: String,
        at: String,
        residual_k: f64,
        iterations: usize,
    },
}

/// Most (thermal vertex, shadow instant) pairs: one byte of sun visibility each, one shadow ray
/// traced each. The shipped car's day is 9694 × 145 = 1.4e6.
pub const MAX_SHADOW_SAMPLES: usize = 500_000_000;

/// Most (vertex, recorded instant) surface temperatures held (8 bytes each, 0.8 GB at most).
pub const MAX_RECORDED_VALUES: usize = 100_000_000;

/// Where in the run a vertex's solve failed.
pub(super) struct VertexFailure {
    /// Start of the failed step (s from `start_utc`), `None` before the first step.
    pub(super) time_s: Option<f64>,
    pub(super) spinup: bool,
    pub(super) error: ThermalError,
}

impl VertexFailure {
    pub(super) fn before_run(error: ThermalError) -> VertexFailure {
        VertexFailure {
            time_s: None,
            spinup: false,
            error,
        }
    }

    /// ", step from t = 3600 s" (", spin-up step …"), or nothing.
    pub(super) fn at(&self) -> String {
        step_label(self.time_s, self.spinup)
    }
}

/// ", step from t = 3600 s" (", spin-up step …") for a step starting at `time_s`, or nothing.
pub(super) fn step_label(time_s: Option<f64>, spinup: bool) -> String {
    match (time_s, spinup) {
        (None, _) => String::new(),
        (Some(t), false) => format!(", step from t = {} s", number(t)),
        (Some(t), true) => format!(", spin-up step from t = {} s", number(t)),
    }
}

/// A part's vertex solve that failed, named by its part.
pub(super) fn independent_error(
    scene: &Scene,
    surface: usize,
    failure: VertexFailure,
) -> ThermalRunError {
    let object = scene.surfaces[surface].object;
    ThermalRunError::Solver {
        part: format!(
            "objects[{object}] '{}' part '{}'",
            scene.object_names[object], scene.surfaces[surface].part
        ),
        at: failure.at(),
        error: failure.error,
    }
}

/// The run's tables within their limits, before any is allocated: sun visibility per thermal
/// vertex (outside terrain fields) and shadow instant, surface temperatures per vertex and recorded instant (the instants
/// themselves are limited by the `[thermal]` keys, [`crate::thermal::setup`]).
pub(super) fn check_sizes(scene: &Scene, setup: &ThermalSetup) -> Result<(), ThermalRunError> {
    let surfaces = vertex_surfaces(scene);
    // A terrain field's vertices keep no visibility table (see `field`).
    let fields: Vec<u32> = field_sets(scene, setup).iter().map(|f| f.surface).collect();
    let thermal = surfaces
        .iter()
        .filter(|&&s| setup.surfaces[s as usize].is_some() && !fields.contains(&s))
        .count();
    let shadows = shadow_instants_count(setup);
    let recorded = (setup.duration_s / setup.output_step_s).floor() as usize + 2;
    let tables = [
        (
            thermal,
            shadows,
            "shadow instants",
            "shadow_step_s",
            MAX_SHADOW_SAMPLES,
        ),
        (
            surfaces.len(),
            recorded,
            "recorded instants",
            "output_step_s",
            MAX_RECORDED_VALUES,
        ),
    ];
    for (vertices, instants, what, key, limit) in tables {
        if vertices.saturating_mul(instants) > limit {
            return Err(ThermalRunError::TooLarge {
                vertices,
                instants,
                what,
                key,
                limit,
            });
        }
    }
    Ok(())
}
