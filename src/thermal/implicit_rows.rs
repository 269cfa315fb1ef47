//! One implicit (backward Euler) step of the 1-D conduction equation as tridiagonal rows
//! (docs/design.md §1.8): assembly with the linear boundary terms, the Thomas elimination toward
//! the front, the scalar Newton solve of the non-linear surface balance, and back substitution.
//! See the solver's module docs for why the elimination runs toward the front.

use super::forcing::{Back, Forcing, FrontForcing};
use super::layers::{Grid, ThermalError};
use crate::optics::STEFAN_BOLTZMANN;

/// Energies (J m⁻²) that crossed the boundaries in one implicit Euler step.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Crossed {
    pub(super) front: f64,
    pub(super) back: f64,
    pub(super) internal: f64,
}

/// Tridiagonal rows a_i T_{i−1} + b_i T_i + c_i T_{i+1} = d_i and the elimination's working rows.
#[derive(Debug, Clone)]
pub(super) struct Rows {
    a: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    d: Vec<f64>,
    bp: Vec<f64>,
    dp: Vec<f64>,
}

impl Rows {
    /// Rows of a system of `n` unknowns, all zero.
    pub(super) fn zeros(n: usize) -> Rows {
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

/// One backward Euler step of length `h` from `old` under forcing `f` (taken at the step's end);
/// writes the new temperatures to `out` and returns the energies that crossed the boundaries.
pub(super) fn implicit_euler(
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
}
