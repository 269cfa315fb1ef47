//! Fixed-step BDF2 for many vertices that share one layer stack, [`LANES`] at a time
//! (docs/design.md §1.8): the terrain's millions of vertices, which differ only in what they absorb.
//!
//! **Scheme: BDF2 with variable step.** With ω = hₙ/hₙ₋₁ each sub-step solves
//! α₀ C Tⁿ⁺¹ − α₁ C Tⁿ + α₂ C Tⁿ⁻¹ = hₙ (−K Tⁿ⁺¹ + boundary fluxes at tⁿ⁺¹), α₀ = (1+2ω)/(1+ω),
//! α₁ = 1+ω, α₂ = ω²/(1+ω). Second order with one elimination per sub-step (the adaptive
//! [`Solver`](super::Solver) takes three), and its amplification tends to 0 for stiff modes, so a
//! thin paint cell does not ring after a sudden shadow as under Crank–Nicolson. From a fresh state
//! ω = 0, which is exactly backward Euler (α₀ = α₁ = 1, α₂ = 0).
//!
//! **One matrix for every lane.** The rows' left-hand side depends only on (h, ω, the front h and
//! the back boundary's coefficient), all shared, so its front-ward Thomas factors (the elimination
//! order of [`Solver`](super::Solver): the surface last) are computed once and cached; each lane
//! only sweeps its right-hand side, solves its scalar surface balance
//! B T_s + h ε σ T_s⁴ = D by Newton (vectorized over lanes, each lane stopping when its own update
//! is below the tolerance, so no lane's result depends on its neighbours), and substitutes back.
//! The boundary rows, the surface Newton step and the crossed energies are the adaptive solver's
//! functions.
//!
//! **Energy bookkeeping.** Summed over the nodes the conduction cancels, and a sub-step reads
//! α₀ ΔEₙ₊₁ − α₂ ΔEₙ = hₙ Qₙ₊₁ (E = Σ C T the stored heat, ΔEₙ₊₁ = Eⁿ⁺¹ − Eⁿ, Q the net
//! boundary flux at the sub-step's end). The plain stored heat therefore does not equal the
//! booked Σ h Q; but with the deferred heat P, Pⁿ⁺¹ = Pⁿ + (α₀ − 1) ΔEₙ₊₁ − α₂ ΔEₙ (zero from a
//! fresh state), E + P changes by exactly hₙ Qₙ₊₁ every sub-step, for any sequence of ω. P is
//! the BDF2 weights' lag: under a steady step it is ≈ h (Qₙ − Q₁)/2, the difference between the
//! end-point sum Σ h Q and the integral of the flux. [`BatchReport`] gives both, so
//! stored + deferred − net in closes to round-off (tests/it/thermal_batch.rs).

// Lane loops index several per-lane arrays at once: plain indices are what the vectorizer
// turns into one vector operation per statement.
#![allow(clippy::needless_range_loop)]

use super::forcing::{Back, Forcing, FrontForcing};
use super::implicit_rows::{
    back_row, crossed, front_row, surface_newton_step, BackRow, NEWTON_ITERATIONS,
};
use super::layers::{Grid, ThermalError};
use super::solver::{check_step_s, MAX_SUBSTEPS_PER_STEP};
use crate::optics::MAX_TEMPERATURE_K;
use crate::optics::STEFAN_BOLTZMANN;
use crate::text::number;

/// Vertices marched together: eight f64 fill one AVX-512 register (or two AVX2 ones). Sixteen
/// measured ~10 % faster in the bench and no faster on a whole terrain (the block's state then
/// outgrows the first-level cache).
pub const LANES: usize = 8;

/// One value per lane.
pub type Lanes = [f64; LANES];

/// Default longest sub-step (s): one sub-step per 60 s sample, which keeps 2.56 M vertices × 1440
/// steps within minutes of CPU (~50 ns a vertex-step on the loaded CI machine). Measured against
/// the adaptive solver over 24 h of diurnal forcing with a shadow that falls and lifts within one
/// 60 s sample (tests/it/thermal_batch.rs), largest |ΔT_s| (everywhere / outside the 10 min after a
/// shadow edge): asphalt over soil 0.221 / 0.043 K at 60 s, 0.057 / 0.010 K at 30 s, 0.011 /
/// 0.001 K at 15 s; painted steel panel 1.27 / 0.085 K at 60 s, 0.41 / 0.020 K at 30 s,
/// 0.10 / 0.006 K at 15 s. The error falls as h² and sits where the forcing's slope jumps (the
/// end-point evaluation meets a kink); a caller that needs the panel's shadow edges within
/// 0.1 K passes 15 s to [`BatchSolver::new`], at four times the cost.
pub const BATCH_MAX_SUBSTEP_S: f64 = 60.0;

/// What drives [`LANES`] vertices of one stack at one instant: per lane what they absorb, the
/// rest shared. Meanings as in [`FrontForcing`] and [`Forcing`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BatchForcing {
    /// Absorbed short-wave per lane (W m⁻²).
    pub absorbed_w_m2: Lanes,
    /// Absorbed long-wave per lane (W m⁻², already times ε).
    pub longwave_in_w_m2: Lanes,
    /// Thermal emissivity ε.
    pub emissivity: f64,
    /// Front convective coefficient (W m⁻² K⁻¹).
    pub h_w_m2k: f64,
    /// Air temperature (K).
    pub air_k: f64,
    /// Back boundary.
    pub back: Back,
    /// Internal heat flux entering at the back face (W m⁻²).
    pub internal_w_m2: f64,
}

impl BatchForcing {
    /// Lane `l`'s forcing as the one-vertex solver takes it.
    pub fn lane(&self, l: usize) -> Forcing {
        Forcing {
            front: FrontForcing {
                absorbed_w_m2: self.absorbed_w_m2[l],
                longwave_in_w_m2: self.longwave_in_w_m2[l],
                emissivity: self.emissivity,
                h_w_m2k: self.h_w_m2k,
                air_k: self.air_k,
            },
            back: self.back,
            internal_w_m2: self.internal_w_m2,
        }
    }

    fn validate(&self) -> Result<(), ThermalError> {
        // The common case in one pass over the lanes; a lane at fault is named by the check below.
        let fine = |v: &Lanes| {
            v.iter()
                .fold(true, |ok, x| ok & (x.is_finite() & (*x >= 0.0)))
        };
        if fine(&self.absorbed_w_m2) && fine(&self.longwave_in_w_m2) {
            return self.lane(0).validate();
        }
        for l in 0..LANES {
            self.lane(l).validate().map_err(|e| match e {
                ThermalError::InvalidInput(m) => {
                    ThermalError::InvalidInput(format!("lane {l}: {m}"))
                }
                other => other,
            })?;
        }
        Ok(())
    }
}

/// Temperatures of [`LANES`] vertices on one grid, node-major (front first), with the previous
/// sub-step's state that BDF2 needs.
#[derive(Debug, Clone, PartialEq)]
pub struct BatchState {
    now: Vec<Lanes>,
    before: Vec<Lanes>,
    /// Length of the last sub-step (s); `None` for a fresh state (the next is backward Euler).
    last_substep_s: Option<f64>,
    /// Stored-heat change of the last sub-step, ΔEₙ (J m⁻²).
    last_change_j_m2: Lanes,
    /// The deferred heat P of the module docs (J m⁻²).
    deferred_j_m2: Lanes,
}

impl BatchState {
    /// Uniform temperature per lane on every node of `grid`.
    pub fn uniform(grid: &Grid, initial_k: Lanes) -> Result<Self, ThermalError> {
        if let Some(l) = (0..LANES).find(|&l| !(initial_k[l].is_finite() && initial_k[l] > 0.0)) {
            return Err(ThermalError::InvalidInput(format!(
                "lane {l}: initial temperature must be positive and finite, got {} K",
                number(initial_k[l])
            )));
        }
        Ok(Self {
            now: vec![initial_k; grid.len()],
            before: vec![initial_k; grid.len()],
            last_substep_s: None,
            last_change_j_m2: [0.0; LANES],
            deferred_j_m2: [0.0; LANES],
        })
    }

    /// Front surface temperatures (K).
    pub fn surface_k(&self) -> Lanes {
        self.now[0]
    }

    /// Node temperatures, front first, each node's lanes together (K).
    pub fn temperatures_k(&self) -> &[Lanes] {
        &self.now
    }

    /// Heat stored relative to 0 K per lane, Σ Cᵢ Tᵢ (J m⁻²).
    pub fn heat_j_m2(&self, grid: &Grid) -> Lanes {
        let mut e = [0.0; LANES];
        for (c, t) in grid.capacities_j_m2k().iter().zip(&self.now) {
            for l in 0..LANES {
                e[l] += c * t[l];
            }
        }
        e
    }

    /// The deferred heat P (J m⁻²): stored heat plus it changes by exactly the booked fluxes.
    pub fn deferred_j_m2(&self) -> Lanes {
        self.deferred_j_m2
    }
}

/// What one [`BatchSolver::step`] did, per lane (J m⁻²).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BatchReport {
    /// Change of the stored heat Σ C T.
    pub stored_j_m2: Lanes,
    /// Change of the deferred heat P (module docs).
    pub deferred_j_m2: Lanes,
    /// Σ h × net flux into the front at each sub-step's end.
    pub front_in_j_m2: Lanes,
    /// Σ h × flux in through the back boundary.
    pub back_in_j_m2: Lanes,
    /// Σ h × internal flux.
    pub internal_j_m2: Lanes,
    /// Sub-steps taken.
    pub substeps: usize,
}

impl BatchReport {
    /// Everything booked as coming in: front + back + internal.
    pub fn net_in_j_m2(&self) -> Lanes {
        std::array::from_fn(|l| {
            self.front_in_j_m2[l] + self.back_in_j_m2[l] + self.internal_j_m2[l]
        })
    }
}

/// What the shared left-hand side depends on, bit for bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct FactorKey {
    h: u64,
    omega: u64,
    front_b: u64,
    /// 0 linear back row with this diagonal addition, 1 fixed back temperature.
    back: (u8, u64),
}

/// The front-ward Thomas factors of one left-hand side: row i reads
/// bpᵢ Tᵢ + aᵢ Tᵢ₋₁ = dpᵢ with dpᵢ = dᵢ − mᵢ dpᵢ₊₁.
#[derive(Debug, Clone)]
struct Factors {
    key: FactorKey,
    /// aᵢ / bpᵢ: the substitution reads Tᵢ = dpᵢ / bpᵢ − (aᵢ / bpᵢ) Tᵢ₋₁.
    a_over_bp: Vec<f64>,
    m: Vec<f64>,
    inv_bp: Vec<f64>,
    /// bp₀, the surface's linear coefficient B.
    b0: f64,
}

/// Left-hand sides kept: the steady case needs one; a front h that alternates between a few
/// values (a sub-step cut by a step's end, a wind that changes every hour) a few more.
const FACTOR_CACHE: usize = 4;

/// BDF2 coefficients (α₀, α₁, α₂) for the step ratio ω (0: backward Euler).
fn bdf2(omega: f64) -> (f64, f64, f64) {
    (
        (1.0 + 2.0 * omega) / (1.0 + omega),
        1.0 + omega,
        omega * omega / (1.0 + omega),
    )
}

/// Marches [`BatchState`]s of one grid; holds the grid, the factor cache and scratch, so one
/// solver serves every block of lanes of a stack.
#[derive(Debug, Clone)]
pub struct BatchSolver {
    grid: Grid,
    max_substep_s: f64,
    newton_tolerance_k: f64,
    cache: Vec<Factors>,
    next_slot: usize,
    dp: Vec<Lanes>,
    out: Vec<Lanes>,
}

impl BatchSolver {
    /// A solver for `grid` with sub-steps of at most `max_substep_s` and the surface Newton
    /// iterated until every lane's update is below `newton_tolerance_k`.
    pub fn new(
        grid: Grid,
        max_substep_s: f64,
        newton_tolerance_k: f64,
    ) -> Result<Self, ThermalError> {
        for (name, v) in [
            ("max_substep_s", max_substep_s),
            ("newton_tolerance_k", newton_tolerance_k),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(ThermalError::InvalidInput(format!(
                    "batch solver {name} must be positive and finite, got {}",
                    number(v)
                )));
            }
        }
        let n = grid.len();
        Ok(Self {
            grid,
            max_substep_s,
            newton_tolerance_k,
            cache: Vec::with_capacity(FACTOR_CACHE),
            next_slot: 0,
            dp: vec![[0.0; LANES]; n],
            out: vec![[0.0; LANES]; n],
        })
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Advances `state` by `dt_s`, the forcing linear from `start` to `end`, in
    /// ceil(dt/max_substep) equal sub-steps, each evaluated at its end (so `start` is read, and
    /// checked, only when the step is split).
    pub fn step(
        &mut self,
        state: &mut BatchState,
        dt_s: f64,
        start: &BatchForcing,
        end: &BatchForcing,
    ) -> Result<BatchReport, ThermalError> {
        check_step_s(dt_s)?;
        let count = (dt_s / self.max_substep_s).ceil();
        if count > MAX_SUBSTEPS_PER_STEP as f64 {
            return Err(ThermalError::InvalidInput(format!(
                "a time step of {} s needs more than {MAX_SUBSTEPS_PER_STEP} sub-steps of {} s",
                number(dt_s),
                number(self.max_substep_s)
            )));
        }
        if state.now.len() != self.grid.len() {
            return Err(ThermalError::InvalidInput(format!(
                "state has {} nodes, the grid {}",
                state.now.len(),
                self.grid.len()
            )));
        }
        let count = count as usize;
        // One sub-step (the usual case: samples as far apart as the longest sub-step) evaluates
        // the end alone, so the start is neither interpolated nor needed.
        if count > 1 {
            start.validate()?;
        }
        end.validate()?;
        let h = dt_s / count as f64;
        let deferred_before = state.deferred_j_m2;
        let mut report = BatchReport::default();
        for k in 0..count {
            let f: [Forcing; LANES] = if k + 1 == count {
                std::array::from_fn(|l| end.lane(l))
            } else {
                let s = (k + 1) as f64 / count as f64;
                std::array::from_fn(|l| start.lane(l).lerp(&end.lane(l), s))
            };
            self.substep(state, h, &f, &mut report)?;
            report.substeps += 1;
        }
        for l in 0..LANES {
            report.deferred_j_m2[l] = state.deferred_j_m2[l] - deferred_before[l];
        }
        Ok(report)
    }

    /// One BDF2 sub-step of length `h` under the lanes' forcing `f` at its end.
    fn substep(
        &mut self,
        state: &mut BatchState,
        h: f64,
        f: &[Forcing; LANES],
        report: &mut BatchReport,
    ) -> Result<(), ThermalError> {
        let omega = state.last_substep_s.map_or(0.0, |last| h / last);
        let (a0, a1, a2) = bdf2(omega);
        let fi = self.factors(h, omega, &f[0]);
        let factors = &self.cache[fi];
        let cap = self.grid.capacities_j_m2k();
        let n = cap.len();
        let history =
            |i: usize, l: usize| history_j_m2(cap[i], a1, a2, &state.now[i], &state.before[i], l);
        let d0 = sweep_toward_front(factors, cap, state, (a1, a2), h, f, &mut self.dp);
        let k4 = h * f[0].front.emissivity * STEFAN_BOLTZMANN;
        let guess: Lanes = std::array::from_fn(|l| {
            state.now[0][l] + omega * (state.now[0][l] - state.before[0][l])
        });
        let t_s = solve_surfaces(factors.b0, k4, &d0, &guess, self.newton_tolerance_k)?;
        // Substitution toward the back, with each lane's stored-heat change.
        self.out[0] = t_s;
        let mut change: Lanes = std::array::from_fn(|l| cap[0] * (t_s[l] - state.now[0][l]));
        let (mut low, mut high) = (t_s, t_s);
        let mut prev = t_s;
        for i in 1..n {
            let (a, inv, c) = (factors.a_over_bp[i], factors.inv_bp[i], cap[i]);
            let (dp, now) = (self.dp[i], state.now[i]);
            let mut row = [0.0; LANES];
            for l in 0..LANES {
                row[l] = (-a).mul_add(prev[l], dp[l] * inv);
                change[l] += c * (row[l] - now[l]);
                // min/max that a NaN passes through, for the range check below.
                low[l] = if row[l] < low[l] { row[l] } else { low[l] };
                high[l] = if row[l] > high[l] || row[l].is_nan() {
                    row[l]
                } else {
                    high[l]
                };
            }
            self.out[i] = row;
            prev = row;
        }
        check_range(&low, &high)?;
        let g = self.grid.conductances_w_m2k()[n - 2];
        for l in 0..LANES {
            let back_stored = a0 * cap[n - 1] * self.out[n - 1][l] - history(n - 1, l);
            let back = [self.out[n - 2][l], self.out[n - 1][l]];
            let e = crossed(h, &f[l], t_s[l], back, g, back_stored);
            report.front_in_j_m2[l] += e.front;
            report.back_in_j_m2[l] += e.back;
            report.internal_j_m2[l] += e.internal;
            state.deferred_j_m2[l] += (a0 - 1.0) * change[l] - a2 * state.last_change_j_m2[l];
            report.stored_j_m2[l] += change[l];
        }
        state.last_change_j_m2 = change;
        state.last_substep_s = Some(h);
        std::mem::swap(&mut state.before, &mut state.now);
        std::mem::swap(&mut state.now, &mut self.out);
        Ok(())
    }

    /// Index in the cache of the factors for this sub-step, computed on a miss.
    fn factors(&mut self, h: f64, omega: f64, f: &Forcing) -> usize {
        let (front_b, _) = front_row(h, &f.front, 0.0);
        let back = match back_row(h, f, 0.0) {
            BackRow::Linear { b_add, .. } => (0, b_add.to_bits()),
            BackRow::Fixed(_) => (1, 0),
        };
        let key = FactorKey {
            h: h.to_bits(),
            omega: omega.to_bits(),
            front_b: front_b.to_bits(),
            back,
        };
        if let Some(i) = self.cache.iter().position(|c| c.key == key) {
            return i;
        }
        let factors = factorize(&self.grid, h, bdf2(omega).0, front_b, key);
        if self.cache.len() < FACTOR_CACHE {
            self.cache.push(factors);
            self.cache.len() - 1
        } else {
            let slot = self.next_slot;
            self.cache[slot] = factors;
            self.next_slot = (slot + 1) % FACTOR_CACHE;
            slot
        }
    }
}

/// The left-hand side α₀ C + h K (+ the boundaries' linear terms) eliminated from the back toward
/// the front, as the adaptive solver's Thomas algorithm does.
fn factorize(grid: &Grid, h: f64, a0: f64, front_b: f64, key: FactorKey) -> Factors {
    let cap = grid.capacities_j_m2k();
    let g = grid.conductances_w_m2k();
    let n = cap.len();
    let link = |i: usize| if i < n - 1 { h * g[i] } else { 0.0 };
    let mut a: Vec<f64> = (0..n)
        .map(|i| if i > 0 { -h * g[i - 1] } else { 0.0 })
        .collect();
    let mut b: Vec<f64> = (0..n).map(|i| a0 * cap[i] - a[i] + link(i)).collect();
    b[0] += front_b;
    match key.back {
        (0, b_add) => b[n - 1] += f64::from_bits(b_add),
        _ => {
            a[n - 1] = 0.0;
            b[n - 1] = 1.0;
        }
    }
    let mut m = vec![0.0; n];
    let mut bp = b[n - 1];
    let mut inv_bp = vec![0.0; n];
    inv_bp[n - 1] = 1.0 / bp;
    for i in (0..n - 1).rev() {
        m[i] = -link(i) / bp;
        bp = b[i] - m[i] * a[i + 1];
        inv_bp[i] = 1.0 / bp;
    }
    Factors {
        key,
        a_over_bp: a.iter().zip(&inv_bp).map(|(a, i)| a * i).collect(),
        m,
        inv_bp,
        b0: bp,
    }
}

/// The history part α₁ C Tⁿ − α₂ C Tⁿ⁻¹ of one node's right-hand side, lane `l`.
fn history_j_m2(cap: f64, a1: f64, a2: f64, now: &Lanes, before: &Lanes, l: usize) -> f64 {
    a1 * cap * now[l] - a2 * cap * before[l]
}

/// Builds every lane's right-hand side and eliminates it from the back toward the front into
/// `dp`; returns row 0's dp₀, the D of the surface balance.
fn sweep_toward_front(
    factors: &Factors,
    cap: &[f64],
    state: &BatchState,
    (a1, a2): (f64, f64),
    h: f64,
    f: &[Forcing; LANES],
    dp: &mut [Lanes],
) -> Lanes {
    let n = cap.len();
    let history =
        |i: usize, l: usize| history_j_m2(cap[i], a1, a2, &state.now[i], &state.before[i], l);
    for l in 0..LANES {
        dp[n - 1][l] = match back_row(h, &f[l], history(n - 1, l)) {
            BackRow::Linear { d, .. } => d,
            BackRow::Fixed(t) => t,
        };
    }
    // The carried row stays in registers, so the sweep vectorizes over lanes.
    let mut next = dp[n - 1];
    for i in (1..n - 1).rev() {
        let (m, c1, c2) = (factors.m[i], a1 * cap[i], a2 * cap[i]);
        let (now, before) = (state.now[i], state.before[i]);
        let mut row = [0.0; LANES];
        for l in 0..LANES {
            // One fused multiply–add on the node-to-node chain, which sets the sweep's speed.
            row[l] = (-m).mul_add(next[l], c1 * now[l] - c2 * before[l]);
        }
        dp[i] = row;
        next = row;
    }
    std::array::from_fn(|l| front_row(h, &f[l].front, history(0, l)).1 - factors.m[0] * dp[1][l])
}

/// Newton on B T + K T⁴ = Dₗ for every lane, each lane stopping at its own convergence.
fn solve_surfaces(
    b: f64,
    k4: f64,
    d: &Lanes,
    start: &Lanes,
    tol: f64,
) -> Result<Lanes, ThermalError> {
    if !(b > 0.0 && d.iter().all(|&d| d > 0.0)) {
        return Err(ThermalError::NoSurfaceTemperature);
    }
    let mut t: Lanes = std::array::from_fn(|l| start[l].max(1.0));
    let mut done = [false; LANES];
    for _ in 0..NEWTON_ITERATIONS {
        for l in 0..LANES {
            let (next, step) = surface_newton_step(b, k4, d[l], t[l]);
            if !done[l] {
                t[l] = next;
                done[l] = step.abs() <= tol;
            }
        }
        if done.iter().all(|&d| d) {
            return Ok(t);
        }
    }
    let l = done.iter().position(|&d| !d).unwrap_or(0);
    Err(ThermalError::NewtonDiverged {
        iterations: NEWTON_ITERATIONS,
        last_k: t[l],
    })
}

/// Every lane's lowest and highest temperature within (0, MAX_TEMPERATURE_K].
fn check_range(low: &Lanes, high: &Lanes) -> Result<(), ThermalError> {
    for (&lo, &hi) in low.iter().zip(high) {
        let within = lo > 0.0 && hi <= MAX_TEMPERATURE_K;
        if !within {
            let temperature_k = if lo > 0.0 { hi } else { lo };
            return Err(ThermalError::Runaway { temperature_k });
        }
    }
    Ok(())
}
