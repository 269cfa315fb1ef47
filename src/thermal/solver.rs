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

use super::layers::{Grid, ThermalError};
use crate::optics::MAX_TEMPERATURE_K;
use crate::text::number;

pub use crate::optics::STEFAN_BOLTZMANN;

/// Front-surface forcing of §1.8 at one instant, with the sun and sky already reduced to numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrontForcing {
    /// Absorbed solar irradiance α_s [E_dn max(0, n·s) V_sun + E_dh F_sky] (W m⁻²).
    pub absorbed_w_m2: f64,
    /// Absorbed long-wave ε [E_lw F_sky + σ T_g⁴ (1 − F_sky)] (W m⁻², already times ε).
    pub longwave_in_w_m2: f64,
    /// Thermal hemispherical emissivity ε of the surface (0…1).
    pub emissivity: f64,
    /// Convective coefficient h (W m⁻² K⁻¹).
    pub h_w_m2k: f64,
    /// Air temperature (K).
    pub air_k: f64,
}

impl FrontForcing {
    /// Net flux into the surface at surface temperature `surface_k` (W m⁻²), §1.8.
    pub fn net_flux_w_m2(&self, surface_k: f64) -> f64 {
        self.absorbed_w_m2 + self.longwave_in_w_m2
            - self.emissivity * STEFAN_BOLTZMANN * surface_k.powi(4)
            + self.h_w_m2k * (self.air_k - surface_k)
    }

    pub(super) fn lerp(&self, end: &Self, s: f64) -> Self {
        let l = |a: f64, b: f64| a + (b - a) * s;
        Self {
            absorbed_w_m2: l(self.absorbed_w_m2, end.absorbed_w_m2),
            longwave_in_w_m2: l(self.longwave_in_w_m2, end.longwave_in_w_m2),
            emissivity: l(self.emissivity, end.emissivity),
            h_w_m2k: l(self.h_w_m2k, end.h_w_m2k),
            air_k: l(self.air_k, end.air_k),
        }
    }

    pub(super) fn validate(&self) -> Result<(), ThermalError> {
        let bad = |what: &str, v: f64, rule: &str| {
            Err(ThermalError::InvalidInput(format!(
                "front forcing {what} must be {rule}, got {}",
                number(v)
            )))
        };
        if !(self.absorbed_w_m2.is_finite() && self.absorbed_w_m2 >= 0.0) {
            return bad("absorbed_w_m2", self.absorbed_w_m2, "finite and >= 0");
        }
        if !(self.longwave_in_w_m2.is_finite() && self.longwave_in_w_m2 >= 0.0) {
            return bad("longwave_in_w_m2", self.longwave_in_w_m2, "finite and >= 0");
        }
        if !(0.0..=1.0).contains(&self.emissivity) {
            return bad("emissivity", self.emissivity, "in [0, 1]");
        }
        if !(self.h_w_m2k.is_finite() && self.h_w_m2k >= 0.0) {
            return bad("h_w_m2k", self.h_w_m2k, "finite and >= 0");
        }
        if !(self.air_k.is_finite() && self.air_k > 0.0) {
            return bad("air_k", self.air_k, "positive and finite");
        }
        Ok(())
    }
}

/// Back-face boundary (§1.8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Back {
    /// No heat crosses the back face (other than the internal flux).
    Adiabatic,
    /// The back face is held at this temperature (K).
    Fixed(f64),
    /// Convection to air: coefficient h (W m⁻² K⁻¹) and the air temperature (K); `None` takes
    /// the front forcing's air temperature.
    Convective {
        /// Back convective coefficient (W m⁻² K⁻¹).
        h_w_m2k: f64,
        /// Back air temperature (K), or the front air's.
        air_k: Option<f64>,
    },
}

impl Back {
    pub(super) fn lerp(&self, end: &Self, s: f64) -> Self {
        let l = |a: f64, b: f64| a + (b - a) * s;
        match (self, end) {
            (Back::Fixed(a), Back::Fixed(b)) => Back::Fixed(l(*a, *b)),
            (
                Back::Convective {
                    h_w_m2k: ha,
                    air_k: Some(ta),
                },
                Back::Convective {
                    h_w_m2k: hb,
                    air_k: Some(tb),
                },
            ) => Back::Convective {
                h_w_m2k: l(*ha, *hb),
                air_k: Some(l(*ta, *tb)),
            },
            (
                Back::Convective {
                    h_w_m2k: ha,
                    air_k: None,
                },
                Back::Convective {
                    h_w_m2k: hb,
                    air_k: None,
                },
            ) => Back::Convective {
                h_w_m2k: l(*ha, *hb),
                air_k: None,
            },
            // A change of kind takes effect over the whole step, as the end value.
            _ => *end,
        }
    }

    pub(super) fn validate(&self) -> Result<(), ThermalError> {
        let temp_ok = |t: f64| t.is_finite() && t > 0.0;
        match *self {
            Back::Adiabatic => Ok(()),
            Back::Fixed(t) if temp_ok(t) => Ok(()),
            Back::Fixed(t) => Err(ThermalError::InvalidInput(format!(
                "back temperature must be positive and finite, got {} K",
                number(t)
            ))),
            Back::Convective { h_w_m2k, air_k } => {
                if !(h_w_m2k.is_finite() && h_w_m2k >= 0.0) {
                    return Err(ThermalError::InvalidInput(format!(
                        "back h_w_m2k must be finite and >= 0, got {}",
                        number(h_w_m2k)
                    )));
                }
                match air_k {
                    Some(t) if !temp_ok(t) => Err(ThermalError::InvalidInput(format!(
                        "back air temperature must be positive and finite, got {} K",
                        number(t)
                    ))),
                    _ => Ok(()),
                }
            }
        }
    }
}

/// Everything that drives one vertex at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Forcing {
    /// Front surface energy balance inputs.
    pub front: FrontForcing,
    /// Back boundary.
    pub back: Back,
    /// Internal heat flux entering at the back face (W m⁻²; an engine under a hood).
    pub internal_w_m2: f64,
}

impl Forcing {
    pub(super) fn lerp(&self, end: &Self, s: f64) -> Self {
        Self {
            front: self.front.lerp(&end.front, s),
            back: self.back.lerp(&end.back, s),
            internal_w_m2: self.internal_w_m2 + (end.internal_w_m2 - self.internal_w_m2) * s,
        }
    }

    pub(super) fn validate(&self) -> Result<(), ThermalError> {
        self.front.validate()?;
        self.back.validate()?;
        if !self.internal_w_m2.is_finite() {
            return Err(ThermalError::InvalidInput(format!(
                "internal_w_m2 must be finite, got {}",
                number(self.internal_w_m2)
            )));
        }
        Ok(())
    }
}

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

/// Energies (J m⁻²) that crossed the boundaries in one implicit Euler step.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Crossed {
    pub(super) front: f64,
    pub(super) back: f64,
    pub(super) internal: f64,
}

/// Tridiagonal rows a_i T_{i−1} + b_i T_i + c_i T_{i+1} = d_i and the elimination's working rows.
#[derive(Debug, Clone)]
struct Rows {
    a: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    d: Vec<f64>,
    bp: Vec<f64>,
    dp: Vec<f64>,
}

impl Rows {
    /// Rows of a system of `n` unknowns, all zero.
    fn zeros(n: usize) -> Rows {
        let z = vec![0.0; n];
        Rows {
            a: z.clone(),
            b: z.clone(),
            c: z.clone(),
            d: z.clone(),
            bp: z.clone(),
            dp: z,
        }
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

/// One backward Euler step of length `h` from `old` under forcing `f` (taken at the step's end);
/// writes the new temperatures to `out` and returns the energies that crossed the boundaries.
fn implicit_euler(
    grid: &Grid,
    old: &[f64],
    h: f64,
    f: &Forcing,
    newton_tol: f64,
    out: &mut [f64],
    rows: &mut Rows,
) -> Result<Crossed, ThermalError> {
    assemble(grid, old, h, f, rows);
    let n = old.len();
    eliminate_towards_front(rows);
    // Row 0 now reads bp₀ T_s = dp₀ − h ε σ T_s⁴ (the radiation term kept out of the rows).
    let k4 = h * f.front.emissivity * STEFAN_BOLTZMANN;
    let t_s = solve_surface(rows.bp[0], k4, rows.dp[0], old[0], newton_tol)?;
    substitute_from_front(rows, t_s, out);
    let back_stored = grid.capacities_j_m2k()[n - 1] * (out[n - 1] - old[n - 1]);
    let g = grid.conductances_w_m2k()[n - 2];
    Ok(crossed(h, f, t_s, [out[n - 2], out[n - 1]], g, back_stored))
}

/// Energies that crossed the boundaries in one implicit step of length `h` ending at surface
/// temperature `t_s` and back nodes `back_k` = [T_{n−2}, T_{n−1}] linked by conductance `g`.
/// `back_stored` is what the step's left-hand side books as the back node's heat change (C ΔT
/// for backward Euler, the BDF2 combination in the batch solver): with a fixed back, what the
/// reservoir supplies to hold the node is that balance closed by hand.
pub(super) fn crossed(
    h: f64,
    f: &Forcing,
    t_s: f64,
    back_k: [f64; 2],
    g: f64,
    back_stored: f64,
) -> Crossed {
    let front = h * f.front.net_flux_w_m2(t_s);
    let internal = h * f.internal_w_m2;
    let back = match f.back {
        Back::Adiabatic => 0.0,
        Back::Convective { h_w_m2k, air_k } => {
            h * h_w_m2k * (air_k.unwrap_or(f.front.air_k) - back_k[1])
        }
        Back::Fixed(_) => back_stored - h * g * (back_k[0] - back_k[1]) - internal,
    };
    Crossed {
        front,
        back,
        internal,
    }
}

/// Rows of (C/h + conduction) multiplied by h, with the linear boundary terms.
fn assemble(grid: &Grid, old: &[f64], h: f64, f: &Forcing, rows: &mut Rows) {
    let n = old.len();
    let cap = grid.capacities_j_m2k();
    let g = grid.conductances_w_m2k();
    for i in 0..n {
        let g_left = if i > 0 { h * g[i - 1] } else { 0.0 };
        let g_right = if i + 1 < n { h * g[i] } else { 0.0 };
        rows.a[i] = -g_left;
        rows.c[i] = -g_right;
        rows.b[i] = cap[i] + g_left + g_right;
        rows.d[i] = cap[i] * old[i];
    }
    let (b_add, d) = front_row(h, &f.front, rows.d[0]);
    rows.b[0] += b_add;
    rows.d[0] = d;
    let last = n - 1;
    match back_row(h, f, rows.d[last]) {
        BackRow::Linear { b_add, d } => {
            rows.b[last] += b_add;
            rows.d[last] = d;
        }
        BackRow::Fixed(t) => {
            rows.a[last] = 0.0;
            rows.b[last] = 1.0;
            rows.d[last] = t;
        }
    }
}

/// The front row's linear boundary terms for a step of length `h` (the row multiplied by h):
/// what convection adds to the diagonal, and the right-hand side given its history part
/// `d_history` (C T_old for backward Euler). The radiation ε σ T⁴ stays out of the rows.
pub(super) fn front_row(h: f64, fr: &FrontForcing, d_history: f64) -> (f64, f64) {
    let d = d_history + h * (fr.absorbed_w_m2 + fr.longwave_in_w_m2 + fr.h_w_m2k * fr.air_k);
    (h * fr.h_w_m2k, d)
}

/// The back row of a step of length `h`: the internal flux and the back boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum BackRow {
    /// Add `b_add` to the diagonal; the right-hand side becomes `d`.
    Linear { b_add: f64, d: f64 },
    /// The row becomes T_back = this temperature.
    Fixed(f64),
}

/// The back row's boundary terms given the right-hand side's history part `d_history`.
pub(super) fn back_row(h: f64, f: &Forcing, d_history: f64) -> BackRow {
    let d = d_history + h * f.internal_w_m2;
    match f.back {
        Back::Adiabatic => BackRow::Linear { b_add: 0.0, d },
        Back::Convective { h_w_m2k, air_k } => BackRow::Linear {
            b_add: h * h_w_m2k,
            d: d + h * h_w_m2k * air_k.unwrap_or(f.front.air_k),
        },
        Back::Fixed(t) => BackRow::Fixed(t),
    }
}

/// Thomas algorithm, eliminating from the last row toward row 0: afterwards row i reads
/// bp_i T_i + a_i T_{i−1} = dp_i, and row 0 (a₀ = 0) bp₀ T₀ = dp₀. Stable without pivoting because
/// the rows are diagonally dominant (b = C + Σ conductances ≥ |a| + |c|).
fn eliminate_towards_front(r: &mut Rows) {
    let n = r.b.len();
    r.bp[n - 1] = r.b[n - 1];
    r.dp[n - 1] = r.d[n - 1];
    for i in (0..n - 1).rev() {
        let m = r.c[i] / r.bp[i + 1];
        r.bp[i] = r.b[i] - m * r.a[i + 1];
        r.dp[i] = r.d[i] - m * r.dp[i + 1];
    }
}

/// Back substitution from the known surface temperature toward the back face.
fn substitute_from_front(r: &Rows, t_s: f64, out: &mut [f64]) {
    out[0] = t_s;
    for i in 1..out.len() {
        out[i] = (r.dp[i] - r.a[i] * out[i - 1]) / r.bp[i];
    }
}

/// Newton on B T + K T⁴ = D (B > 0, K ≥ 0): convex and increasing for T > 0, so one positive root.
fn solve_surface(b: f64, k4: f64, d: f64, start: f64, tol: f64) -> Result<f64, ThermalError> {
    if !(d > 0.0 && b > 0.0) {
        return Err(ThermalError::NoSurfaceTemperature);
    }
    let mut t = start.max(1.0);
    for _ in 0..NEWTON_ITERATIONS {
        let step;
        (t, step) = surface_newton_step(b, k4, d, t);
        if step.abs() <= tol {
            return Ok(t);
        }
    }
    Err(ThermalError::NewtonDiverged {
        iterations: NEWTON_ITERATIONS,
        last_k: t,
    })
}

/// One Newton iteration on B T + K T⁴ = D from `t`: the new iterate and the update taken.
#[inline(always)]
pub(super) fn surface_newton_step(b: f64, k4: f64, d: f64, t: f64) -> (f64, f64) {
    let t3 = t * t * t;
    let step = (b * t + k4 * t3 * t - d) / (b + 4.0 * k4 * t3);
    // From the left, Newton may overshoot below zero only if it started there; keep T > 0.
    ((t - step).max(0.5 * t), step)
}

/// Newton iterations of the surface balance before it is given up: it converges quadratically
/// from any positive start (a few iterations); halving from far above takes at most ~60.
pub(super) const NEWTON_ITERATIONS: usize = 100;

/// Sub-steps (accepted and rejected) one [`Solver::step`] may take beyond the dt/max_substep it
/// needs at least, before it ends in [`ThermalError::NotConverged`]. The shipped car's day takes
/// at most 36 per 60 s step; a stack the round-off defeats (a conductivity of 1e12 W/m/K) took
/// ~19 000 per step and would run for hours.
pub const MAX_SUBSTEPS_PER_STEP: usize = 10_000;

#[cfg(test)]
mod tests {
    use super::*;

    /// The front-ward Thomas elimination plus substitution solves a tridiagonal system exactly
    /// (checked against the residual of a random diagonally dominant system).
    #[test]
    fn thomas_solves_tridiagonal_systems() {
        let n = 9;
        let mut seed = 12345_u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut r = Rows::zeros(n);
        for i in 0..n {
            r.a[i] = if i > 0 { -rnd() } else { 0.0 };
            r.c[i] = if i + 1 < n { -rnd() } else { 0.0 };
            r.b[i] = 2.5 + rnd();
            r.d[i] = rnd() * 10.0 - 5.0;
        }
        eliminate_towards_front(&mut r);
        let mut x = vec![0.0; n];
        substitute_from_front(&r, r.dp[0] / r.bp[0], &mut x);
        for i in 0..n {
            let left = if i > 0 { r.a[i] * x[i - 1] } else { 0.0 };
            let right = if i + 1 < n { r.c[i] * x[i + 1] } else { 0.0 };
            let res = left + r.b[i] * x[i] + right - r.d[i];
            assert!(res.abs() < 1e-12, "row {i}: residual {res}");
        }
    }

    #[test]
    fn surface_newton_finds_the_root_from_either_side() {
        let (b, k) = (50.0, 3e-8);
        for start in [1.0, 250.0, 5000.0] {
            let t = solve_surface(b, k, 20_000.0, start, 1e-12).unwrap();
            assert!(
                (b * t + k * t.powi(4) - 20_000.0).abs() < 1e-8,
                "{start}: {t}"
            );
        }
        assert!(solve_surface(b, k, -1.0, 300.0, 1e-9).is_err());
    }

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
