//! The environment's ground as a surface of its own (docs/design.md §1.8,
//! `environment.ground.thermal`): one vertex, horizontal, the whole sky in view and never
//! shadowed, under the run's weather. It depends on nothing else in the scene, so it is solved
//! first, at every sample of every pass, and its temperature then forces the parts' long-wave
//! below their horizon and sets the ground's radiance of a render at an instant.

use super::{shadow_instants, weather_at, Budget, Drive, Exposure, Run, ThermalRunError};
use nalgebra::Vector3;

/// The ground's surface temperature at every sample of each pass.
pub(super) struct GroundHistory {
    /// Per spin-up pass, at samples 0..first_day of that pass.
    pub spinup: Vec<Vec<f64>>,
    /// At samples 0..run_samples of the run.
    pub run: Vec<f64>,
    pub substeps: u64,
    pub closure: f64,
}

impl Run<'_> {
    /// The environment ground's history, or `None` when its temperature is typed.
    pub(super) fn solve_ground(&self) -> Result<Option<GroundHistory>, ThermalRunError> {
        let Some(ground) = &self.setup.ground else {
            return Ok(None);
        };
        // Unshadowed: lit wherever the sun is above the horizon, as a horizontal vertex nothing
        // blocks (exposure::sun_visibility with n = z and no occluder).
        let lit = shadow_instants(self.setup)
            .iter()
            .map(|&t| weather_at(self.setup, t).map(|w| u8::from(w.sun_direction.z > 0.0)))
            .collect::<Result<Vec<_>, _>>()?;
        let exposure = Exposure {
            normal: Vector3::z(),
            sky_view: 1.0,
            lit: &lit,
        };
        let fail = |failure: super::VertexFailure| ThermalRunError::Solver {
            part: "environment.ground".to_owned(),
            at: failure.at(),
            error: failure.error,
        };
        let model = &ground.surface;
        let (mut solver, mut state) = self.start(model, ground.initial_k).map_err(fail)?;
        // Its own long-wave has no ground term (F_sky = 1), so the typed ground drives it.
        let drive = |spinup| Drive {
            model,
            exposure: &exposure,
            ground: None,
            spinup,
        };
        let mut spinup = Vec::new();
        for _ in 0..self.setup.spinup_days {
            let mut pass = vec![state.surface_k()];
            let days = 0..self.first_day();
            self.march(&mut solver, &mut state, &drive(true), days, |_, s, _| {
                pass.push(s.surface_k())
            })
            .map_err(fail)?;
            spinup.push(pass);
        }
        let mut run = vec![state.surface_k()];
        let mut substeps = 0;
        let all = 0..self.run_samples;
        let budget: Budget = self
            .march(
                &mut solver,
                &mut state,
                &drive(false),
                all,
                |_, s, report| {
                    run.push(s.surface_k());
                    substeps += report.substeps as u64;
                },
            )
            .map_err(fail)?;
        Ok(Some(GroundHistory {
            spinup,
            run,
            substeps,
            closure: budget.closure(),
        }))
    }
}
