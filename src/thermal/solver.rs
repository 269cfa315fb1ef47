//! Implicit time stepping of ρc ∂T/∂t = ∂/∂x (k ∂T/∂x) for one vertex's layer stack (docs/design.md §1.8).
//!
//! **Scheme: backward Euler with step doubling and Richardson extrapolation.** Each sub-step of
//! length h is taken once as one implicit (backward) Euler step and once as two steps of h/2; the
//! accepted state is 2·T(h/2, h/2) − T(h), which is second-order accurate, and the difference of
//! the two surface temperatures estimates the error and sets the next h. Backward Euler rather than
//! Crank–Nicolson because the thin front cells (a paint cell of 0.03 mm relaxes in ~0.01 s) make
//! the system very stiff: Crank–Nicolson's amplification tends to −1 for stiff modes, so a sudden
//! change of forcing (sunrise behind an occluder, an engine switched on) rings for many steps at the
//! surface, exactly where the image samples T. Backward Euler damps those modes, and its
//! extrapolation still damps them (amplification 2/(1 − z/2)² − 1/(1 − z) → 0 as z → −∞) while
//! giving second order. Both half- and full-step states conserve energy exactly, so does their
//! linear combination: the energy bookkeeping closes to round-off.
//!
//! **Surface balance.** The net flux into the front (§1.8) is
//! q = absorbed + ε E_lw,eff − ε σ T_s⁴ + h (T_air − T_s). Only the surface node is non-linear, so
//! the tridiagonal system is eliminated by the Thomas algorithm from the back toward the front; what
//! is left is one scalar equation B T_s + Δt ε σ T_s⁴ = D for the surface, solved by Newton (the T⁴
//! term linearized about the current iterate, iterated until the update is below
//! [`SolverControl::newton_tolerance_k`], 1e-9 K by default), then substituted back. The scalar
//! function is convex and increasing for T > 0, so Newton converges from any positive start.
//!
//! **Sub-step rule.** A step from t to t + Δt is split into sub-steps h accepted when both
//! (i) the step-doubling estimate |T_s(h/2,h/2) − T_s(h)| ≤ [`SolverControl::tolerance_k`] and
//! (ii) the surface changes by at most [`SolverControl::max_surface_change_k`] over the sub-step;
//! otherwise h shrinks and the sub-step is retried. The next h is h·min(4, 0.9 √(tol/err),
//! 0.9 ΔT_max/|ΔT_s|), capped by [`SolverControl::max_substep_s`], and carries over to the next
//! output step. The defaults keep surface temperatures within 0.01 K of the time- and
//! space-converged solution over 48 h of diurnal forcing (§1.8; measured in tests/it/thermal_solver.rs).
//!
//! **Forcing in time.** The caller gives the forcing at the start and the end of a step; each
//! sub-step uses it linearly interpolated to the sub-step's end (backward Euler's evaluation time).
//!
//! **Why a hand-written Thomas algorithm.** It is fifteen lines, O(n), allocation-free, and the
//! front-ward elimination order that reduces the non-linear surface to one scalar equation is not
//! something a general banded solver offers; no crate does it better.
use super::forcing::Forcing;
use super::implicit_rows::{implicit_euler, Crossed, Rows};
use super::layers::{Grid, ThermalError};
use crate::optics::MAX_TEMPERATURE_K;
use crate::text::number;

/// Time-step control (see the module docs for the rule).
#[derive(Debug, Clone, PartialEq)]
pub struct SolverControl {
    /// Bound on the step-doubling error estimate of the surface temperature per sub-step (K).
    pub tolerance_k: f64,
    /// Bound on the surface temperature change per sub-step (K).
    pub max_surface_change_k: f64,
    /// Longest sub-step (s).
    pub max_substep_s: f64,
    /// Shortest sub-step (s): below it a sub-step is accepted whatever its error estimate.
    pub min_substep_s: f64,
    /// Newton stops when the surface update is below this (K).
    pub newton_tolerance_k: f64,
}

impl Default for SolverControl {
    fn default() -> Self {
        Self {
            tolerance_k: 2e-3,
            max_surface_change_k: 1.0,
            max_substep_s: 600.0,
            min_substep_s: 1e-6,
            newton_tolerance_k: 1e-9,
        }
    }
}

impl SolverControl {
    /// A control `factor` times tighter: tolerance, surface change and longest sub-step divided by it.
    pub fn refined(&self, factor: f64) -> Self {
        Self {
            tolerance_k: self.tolerance_k / factor,
            max_surface_change_k: self.max_surface_change_k / factor,
            max_substep_s: self.max_substep_s / factor,
            ..self.clone()
        }
    }

    /// The sub-step rule: error estimate and surface change within bounds, or the step already
    /// at its shortest.
    fn accepts(&self, err: f64, change: f64, h: f64) -> bool {
        (err <= self.tolerance_k && change <= self.max_surface_change_k) || h <= self.min_substep_s
    }

    fn validate(&self) -> Result<(), ThermalError> {
        let fields = [
            ("tolerance_k", self.tolerance_k),
            ("max_surface_change_k", self.max_surface_change_k),
            ("max_substep_s", self.max_substep_s),
            ("min_substep_s", self.min_substep_s),
            ("newton_tolerance_k", self.newton_tolerance_k),
        ];
        for (name, v) in fields {
            if !(v.is_finite() && v > 0.0) {
                return Err(ThermalError::InvalidInput(format!(
                    "control {name} must be positive and finite, got {}",
                    number(v)
                )));
            }
        }
        Ok(())
    }
}

/// One vertex's temperatures and the sub-step its controller would take next.
#[derive(Debug, Clone, PartialEq)]
pub struct ThermalState {
    temperatures_k: Vec<f64>,
    next_substep_s: f64,
}

impl ThermalState {
    /// Uniform temperature on every node of `grid` (§1.8 initial state).
    pub fn uniform(grid: &Grid, temperature_k: f64) -> Result<Self, ThermalError> {
        if !(temperature_k.is_finite() && temperature_k > 0.0) {
            return Err(ThermalError::InvalidInput(format!(
                "initial temperature must be positive and finite, got {} K",
                number(temperature_k)
            )));
        }
        Ok(Self {
            temperatures_k: vec![temperature_k; grid.len()],
            next_substep_s: f64::INFINITY,
        })
    }

    /// Front surface temperature (K).
    pub fn surface_k(&self) -> f64 {
        self.temperatures_k[0]
    }

    /// Node temperatures, front first (K).
    pub fn temperatures_k(&self) -> &[f64] {
        &self.temperatures_k
    }
}

/// What one [`Solver::step`] did, with its energy bookkeeping (all J m⁻²).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepReport {
    /// Change of stored heat ∫ρcΔT dx, from the temperatures before and after.
    pub stored_j_m2: f64,
    /// Time-integrated net flux into the front surface.
    pub front_in_j_m2: f64,
    /// Time-integrated flux into the back face through the back boundary.
    pub back_in_j_m2: f64,
    /// Time-integrated internal heat flux.
    pub internal_j_m2: f64,
    /// Accepted sub-steps.
    pub substeps: usize,
    /// Rejected (retried) sub-steps.
    pub rejected: usize,
}

impl StepReport {
    /// Everything that came in: front + back + internal.
    pub fn net_in_j_m2(&self) -> f64 {
        self.front_in_j_m2 + self.back_in_j_m2 + self.internal_j_m2
    }

    fn add(&mut self, e: Crossed, weight: f64) {
        self.front_in_j_m2 += weight * e.front;
        self.back_in_j_m2 += weight * e.back;
        self.internal_j_m2 += weight * e.internal;
    }
}

/// Integrates one vertex's stack; holds the grid and scratch space, not the temperatures, so one
/// solver serves every vertex that shares a stack.
#[derive(Debug, Clone)]
pub struct Solver {
    grid: Grid,
    control: SolverControl,
    rows: Rows,
    full: Vec<f64>,
    mid: Vec<f64>,
    half: Vec<f64>,
}

impl Solver {
    /// A solver for `grid` under `control`.
    pub fn new(grid: Grid, control: SolverControl) -> Result<Self, ThermalError> {
        control.validate()?;
        let n = grid.len();
        let z = vec![0.0; n];
        Ok(Self {
            rows: Rows::zeros(n),
            full: z.clone(),
            mid: z.clone(),
            half: z,
            grid,
            control,
        })
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The time-step control.
    pub fn control(&self) -> &SolverControl {
        &self.control
    }

    /// Advances `state` by `dt_s` seconds, the forcing going linearly from `start` to `end`.
    pub fn step(
        &mut self,
        state: &mut ThermalState,
        dt_s: f64,
        start: &Forcing,
        end: &Forcing,
    ) -> Result<StepReport, ThermalError> {
        check_step_s(dt_s)?;
        if state.temperatures_k.len() != self.grid.len() {
            return Err(ThermalError::InvalidInput(format!(
                "state has {} nodes, the grid {}",
                state.temperatures_k.len(),
                self.grid.len()
            )));
        }
        start.validate()?;
        end.validate()?;
        let heat_before = self.grid.heat_j_m2(&state.temperatures_k);
        let mut report = StepReport::default();
        let mut t = 0.0;
        let mut h = state.next_substep_s.min(self.control.max_substep_s);
        let cap = MAX_SUBSTEPS_PER_STEP + (dt_s / self.control.max_substep_s).ceil() as usize;
        while t < dt_s {
            if report.substeps + report.rejected >= cap {
                return Err(ThermalError::NotConverged {
                    step_s: dt_s,
                    substeps: report.substeps + report.rejected,
                    surface_k: state.surface_k(),
                });
            }
            let remaining = dt_s - t;
            let take = if h >= 0.99 * remaining { remaining } else { h };
            let (err, change) = self.try_substep(state, t, take, dt_s, start, end, &mut report)?;
            let accepted = self.control.accepts(err, change, take);
            let factor = self.step_factor(err, change);
            if accepted {
                t += take;
                report.substeps += 1;
                // A sub-step cut short by the end of the output step does not shrink the next one.
                h = (if take < h { h } else { take * factor }).min(self.control.max_substep_s);
            } else {
                report.rejected += 1;
                h = (take * factor.min(0.5)).max(self.control.min_substep_s);
            }
        }
        state.next_substep_s = h;
        report.stored_j_m2 = self.grid.heat_j_m2(&state.temperatures_k) - heat_before;
        Ok(report)
    }

    /// Growth factor of the sub-step from the error estimate and the surface change.
    fn step_factor(&self, err: f64, change: f64) -> f64 {
        let c = &self.control;
        let by_err = if err > 0.0 {
            0.9 * (c.tolerance_k / err).sqrt()
        } else {
            4.0
        };
        let by_change = if change > 0.0 {
            0.9 * c.max_surface_change_k / change
        } else {
            4.0
        };
        by_err.min(by_change).clamp(0.2, 4.0)
    }

    /// One step-doubled sub-step of length `h` from `t`; on success (the caller decides from the
    /// returned error estimate and surface change) commits the extrapolated state.
    #[allow(clippy::too_many_arguments)]
    fn try_substep(
        &mut self,
        state: &mut ThermalState,
        t: f64,
        h: f64,
        dt: f64,
        start: &Forcing,
        end: &Forcing,
        report: &mut StepReport,
    ) -> Result<(f64, f64), ThermalError> {
        let f_mid = start.lerp(end, (t + 0.5 * h) / dt);
        let f_end = start.lerp(end, (t + h) / dt);
        let old = &state.temperatures_k;
        let tol = self.control.newton_tolerance_k;
        let e_full = implicit_euler(
            &self.grid,
            old,
            h,
            &f_end,
            tol,
            &mut self.full,
            &mut self.rows,
        )?;
        let e1 = implicit_euler(
            &self.grid,
            old,
            0.5 * h,
            &f_mid,
            tol,
            &mut self.mid,
            &mut self.rows,
        )?;
        let e2 = implicit_euler(
            &self.grid,
            &self.mid,
            0.5 * h,
            &f_end,
            tol,
            &mut self.half,
            &mut self.rows,
        )?;
        let err = (self.half[0] - self.full[0]).abs();
        let change = (self.half[0] - old[0]).abs();
        if self.control.accepts(err, change, h) {
            // Richardson: 2·(two half steps) − (one full step), for the state and the energies.
            for ((t_new, th), tf) in state
                .temperatures_k
                .iter_mut()
                .zip(&self.half)
                .zip(&self.full)
            {
                *t_new = 2.0 * th - tf;
            }
            report.add(e1, 2.0);
            report.add(e2, 2.0);
            report.add(e_full, -1.0);
            if let Some(&t) = state
                .temperatures_k
                .iter()
                .find(|t| !(**t > 0.0 && **t <= MAX_TEMPERATURE_K))
            {
                return Err(ThermalError::Runaway { temperature_k: t });
            }
        }
        Ok((err, change))
    }
}

/// A time step must be positive and finite.
pub(super) fn check_step_s(dt_s: f64) -> Result<(), ThermalError> {
    if dt_s.is_finite() && dt_s > 0.0 {
        return Ok(());
    }
    Err(ThermalError::InvalidInput(format!(
        "time step must be positive and finite, got {} s",
        number(dt_s)
    )))
}

/// Sub-steps (accepted and rejected) one [`Solver::step`] may take beyond the dt/max_substep it
/// needs at least, before it ends in [`ThermalError::NotConverged`]. The shipped car's day takes
/// at most 36 per 60 s step; a stack the round-off defeats (a conductivity of 1e12 W/m/K) took
/// ~19 000 per step and would run for hours.
pub const MAX_SUBSTEPS_PER_STEP: usize = 10_000;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::thermal::{Back, FrontForcing};

    /// A step whose sub-steps never meet their tolerance (here, one no step meets, with a
    /// shortest sub-step too short to advance the clock) ends in a typed error after the cap
    /// instead of looping for ever.
    #[test]
    fn a_step_that_does_not_converge_ends_in_an_error_naming_it() {
        use crate::thermal::{Layer, LayerMaterial, LayerStack, Resolution};
        let stack = LayerStack::new(vec![Layer::new(
            LayerMaterial::new("steel", 45.0, 7850.0, 470.0),
            1e-3,
        )])
        .unwrap();
        let grid = stack.discretise(&Resolution::default()).unwrap();
        let control = SolverControl {
            tolerance_k: 1e-300,
            max_surface_change_k: 1e-300,
            min_substep_s: 1e-300,
            ..SolverControl::default()
        };
        let mut solver = Solver::new(grid.clone(), control).unwrap();
        let mut state = ThermalState::uniform(&grid, 280.0).unwrap();
        let forcing = Forcing {
            front: FrontForcing {
                absorbed_w_m2: 500.0,
                longwave_in_w_m2: 300.0,
                emissivity: 0.9,
                h_w_m2k: 10.0,
                air_k: 290.0,
            },
            back: Back::Adiabatic,
            internal_w_m2: 0.0,
        };
        let error = solver
            .step(&mut state, 60.0, &forcing, &forcing)
            .unwrap_err();
        assert!(
            matches!(error, ThermalError::NotConverged { substeps, .. } if substeps == MAX_SUBSTEPS_PER_STEP + 1),
            "{error:?}"
        );
        let text = error.to_string();
        assert!(
            text.starts_with(
                "the time step of 60 s did not converge in 10001 sub-steps (surface at 280"
            ),
            "{text}"
        );
    }

    #[test]
    fn bad_forcing_is_refused_with_its_name() {
        let f = FrontForcing {
            absorbed_w_m2: 0.0,
            longwave_in_w_m2: 0.0,
            emissivity: 1.5,
            h_w_m2k: 1.0,
            air_k: 280.0,
        };
        assert!(f.validate().unwrap_err().to_string().contains("emissivity"));
        let b = Back::Convective {
            h_w_m2k: f64::INFINITY,
            air_k: None,
        };
        assert!(b
            .validate()
            .unwrap_err()
            .to_string()
            .contains("back h_w_m2k"));
        let c = SolverControl {
            tolerance_k: 0.0,
            ..SolverControl::default()
        };
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .contains("tolerance_k"));
    }
}
