//! Enclosures (docs/design.md §1.8): an enclosed air node (a car's cabin) of heat capacity C,
//! exchanging G (T_air − T_c) with the outside air, receiving the sunlight its glazing transmits,
//! and coupled convectively to the back face of every member vertex, h A (T_back − T_c).
//!
//! **Coupling.** The members are the distinct histories of the member parts (vertices with
//! bit-identical forcing share one, exactly as outside an enclosure; it then stands for the summed
//! area of its vertices). They are marched together, one sample step at a time: over a step the
//! node's temperature is linear from T₀ to the unknown end value T₁ (θ = ½), or held at T₁
//! (θ = 1, backward Euler) when the node is faster than the step (Δt (G + Σ h A) > C), which would
//! make the trapezoid ring. Given a guess g of T₁, every member's step is solved with that back
//! air; the node's balance over the step,
//!   C (T₁ − T₀) = −Σ A E_back + Δt G (T̄_air − ((1 − θ) T₀ + θ T₁)) + Δt Q̄_sun,
//! with E_back the heat each member's back face took in (J m⁻², from its solver) and T̄_air, Q̄_sun
//! the step means of the (linear) air temperature and solar gain, then gives T₁. T₁ = g is a scalar
//! fixed point, found by secant iteration to [`NODE_TOLERANCE_K`] from a guess extrapolating the
//! last two steps' rates (the slope carried over from the previous step; on the car's day 1.1
//! member solves per step). The node takes the balance's T₁, so its energy closes exactly
//! whatever residual is left; the members saw g, within the tolerance of it.

use super::{
    Budget, Drive, Exposure, GroundHistory, Groups, History, Run, ThermalRunError, VertexFailure,
};
use crate::progress::Progress;
use crate::scene::mesh::ShadedMesh;
use crate::scene::Scene;
use crate::thermal::setup::{Enclosure, SurfaceThermal};
use crate::thermal::{Back, Forcing, Solver, StepReport, ThermalState};
use rayon::prelude::*;

/// The fixed point is iterated until the members' and the balance's node temperatures agree to
/// this: 20 times below the solver's own bound per sub-step (2e-3 K). On the car's day a hundred
/// times tighter moved no recorded temperature by more than 1e-4 K and took 1.7 times the member
/// solves (about two per step instead of 1.1).
pub const NODE_TOLERANCE_K: f64 = 1e-4;
/// Iterations of one step's fixed point before it is judged.
const NODE_ITERATIONS: usize = 30;
/// After [`NODE_ITERATIONS`], a residual up to this is accepted (the members' adaptive sub-steps
/// make the map slightly discontinuous in g; the energy closes anyway) and a larger one is an
/// error.
pub const NODE_ACCEPT_K: f64 = 1e-3;

/// One distinct history of a member part, standing for `area_m2` of the enclosure's walls.
struct Member<'a> {
    class: usize,
    model: &'a SurfaceThermal,
    exposure: Exposure<'a>,
    initial_k: f64,
    area_m2: f64,
}

/// A member's solver and state, and what it has recorded.
struct Wall {
    solver: Solver,
    state: ThermalState,
    history: History,
    budget: Budget,
}

/// The node between steps.
struct Node {
    temperature_k: f64,
    /// dT/dt of the last step and of the one before: the first guess of the next step
    /// extrapolates them.
    rate_k_s: f64,
    previous_rate_k_s: f64,
    /// d(residual)/d(guess) of the last secant: ≤ −1 (the balance falls as the guess rises).
    slope: f64,
    /// Σ h A over the members (W/K).
    wall_w_k: f64,
    /// The node's own budget over the run (J): stored, net in, through its boundaries.
    budget: Budget,
    residual_k: f64,
}

/// One enclosure's run: its air at the recorded instants, the closure of the budget of node and
/// members together, the worst fixed-point residual.
pub(super) struct NodeRun {
    pub air_k: Vec<f64>,
    pub closure: f64,
    pub residual_k: f64,
}

/// A step of the node: its length and the air and solar gain (W) at its two ends.
struct NodeStep {
    dt_s: f64,
    air_k: [f64; 2],
    gain_w: [f64; 2],
    time_s: f64,
    spinup: bool,
}

/// Why an enclosure's run failed.
enum NodeFailure {
    Member {
        member: usize,
        failure: VertexFailure,
    },
    Settle {
        time_s: f64,
        spinup: bool,
        residual_k: f64,
    },
}

/// Each shading vertex's share of its triangles' area: a third of each (m²).
fn vertex_areas(mesh: &ShadedMesh) -> Vec<f64> {
    let mut area = vec![0.0; mesh.positions.len()];
    for t in &mesh.triangles {
        let p = |k: usize| mesh.positions[t[k] as usize];
        let third = (p(1) - p(0)).cross(&(p(2) - p(0))).norm() / 6.0;
        for &v in t {
            area[v as usize] += third;
        }
    }
    area
}

/// `forcing` with the back face's air at the node's temperature.
fn with_node(forcing: &Forcing, node_k: f64) -> Forcing {
    let back = match forcing.back {
        Back::Convective { h_w_m2k, .. } => Back::Convective {
            h_w_m2k,
            air_k: Some(node_k),
        },
        other => other,
    };
    Forcing { back, ..*forcing }
}

impl Run<'_> {
    /// Every enclosure with its members, each enclosure's members' histories put in `histories`.
    pub(super) fn enclosures(
        &self,
        scene: &Scene,
        groups: &Groups,
        ground: Option<&GroundHistory>,
        histories: &mut [Option<History>],
        progress: &dyn Progress,
    ) -> Result<Vec<NodeRun>, ThermalRunError> {
        let vertices = groups.vertices;
        let areas = vertex_areas(&scene.mesh);
        let mut class_area = vec![0.0; groups.representatives.len()];
        for (i, &v) in vertices.index.iter().enumerate() {
            class_area[groups.class[i]] += areas[v];
        }
        let mut nodes = Vec::with_capacity(self.setup.enclosures.len());
        for (e, enclosure) in self.setup.enclosures.iter().enumerate() {
            let members: Vec<Member> = (groups.representatives.iter().enumerate())
                .filter_map(|(class, &i)| {
                    let surface = vertices.surface[i] as usize;
                    let model = self.setup.surfaces[surface].as_ref()?;
                    (model.enclosure == Some(e)).then(|| Member {
                        class,
                        model,
                        exposure: vertices.exposure(i, &scene.mesh),
                        initial_k: scene.mesh.temperatures[vertices.index[i]],
                        area_m2: class_area[class],
                    })
                })
                .collect();
            let (node, walls) =
                (self.enclosure(enclosure, &members, ground)).map_err(|f| match f {
                    NodeFailure::Member { member, failure } => {
                        let i = groups.representatives[members[member].class];
                        super::independent_error(scene, vertices.surface[i] as usize, failure)
                    }
                    NodeFailure::Settle {
                        time_s,
                        spinup,
                        residual_k,
                    } => ThermalRunError::Enclosure {
                        name: enclosure.name.clone(),
                        at: super::step_label(Some(time_s), spinup),
                        residual_k,
                        iterations: NODE_ITERATIONS,
                    },
                })?;
            for (member, wall) in members.iter().zip(walls) {
                histories[member.class] = Some(wall.history);
            }
            progress.advance(members.len() as u64);
            nodes.push(node);
        }
        Ok(nodes)
    }

    /// One enclosure and its members: spin-up and the run.
    fn enclosure(
        &self,
        enclosure: &Enclosure,
        members: &[Member],
        ground: Option<&GroundHistory>,
    ) -> Result<(NodeRun, Vec<Wall>), NodeFailure> {
        let mut walls = Vec::with_capacity(members.len());
        for (m, member) in members.iter().enumerate() {
            let (solver, state) = (self.start(member.model, member.initial_k))
                .map_err(|failure| NodeFailure::Member { member: m, failure })?;
            walls.push(Wall {
                solver,
                state,
                history: History::new(),
                budget: Budget::default(),
            });
        }
        let wall_w_k = members
            .iter()
            .map(|m| match m.model.back {
                Back::Convective { h_w_m2k, .. } => h_w_m2k * m.area_m2,
                _ => 0.0,
            })
            .sum();
        let mut node = Node {
            temperature_k: self.samples[0].air_k,
            rate_k_s: 0.0,
            previous_rate_k_s: 0.0,
            slope: -1.0,
            wall_w_k,
            budget: Budget::default(),
            residual_k: 0.0,
        };
        for pass in 0..self.setup.spinup_days as usize {
            let slice = ground.map(|g| g.spinup[pass].as_slice());
            let days = 0..self.first_day();
            self.node_pass(enclosure, members, &mut walls, &mut node, slice, days, None)?;
        }
        // The budgets and residual are those of the run.
        for wall in &mut walls {
            wall.budget = Budget::default();
        }
        node.budget = Budget::default();
        node.residual_k = 0.0;
        let mut air_k = Vec::new();
        if self.recorded[0] {
            air_k.push(node.temperature_k);
            for wall in &mut walls {
                wall.history.surface_k.push(wall.state.surface_k());
            }
        }
        let slice = ground.map(|g| g.run.as_slice());
        let all = 0..self.run_samples;
        let record = Some(&mut air_k);
        self.node_pass(
            enclosure, members, &mut walls, &mut node, slice, all, record,
        )?;
        let mut total = node.budget;
        for (wall, member) in walls.iter_mut().zip(members) {
            wall.history.closure = wall.budget.closure();
            total.stored += member.area_m2 * wall.budget.stored;
            total.net_in += member.area_m2 * wall.budget.net_in;
            total.gross += member.area_m2 * wall.budget.gross;
        }
        let run = NodeRun {
            air_k,
            closure: total.closure(),
            residual_k: node.residual_k,
        };
        Ok((run, walls))
    }

    /// The sunlight entering the enclosure through its members at sample `j` (W).
    fn solar_gain_w(&self, members: &[Member], j: usize) -> f64 {
        members
            .iter()
            .filter(|m| m.model.solar_transmittance > 0.0)
            .map(|m| m.model.solar_transmittance * m.area_m2 * self.incident_w_m2(&m.exposure, j))
            .sum()
    }

    /// Node and members through samples `range`; with `record`, the node's and the members'
    /// temperatures at the recorded samples (the run).
    #[allow(clippy::too_many_arguments)]
    fn node_pass(
        &self,
        enclosure: &Enclosure,
        members: &[Member],
        walls: &mut [Wall],
        node: &mut Node,
        ground: Option<&[f64]>,
        range: std::ops::Range<usize>,
        mut record: Option<&mut Vec<f64>>,
    ) -> Result<(), NodeFailure> {
        let spinup = record.is_none();
        let drives: Vec<Drive> = members
            .iter()
            .map(|m| Drive {
                model: m.model,
                exposure: &m.exposure,
                ground,
                spinup,
            })
            .collect();
        let forcing_at =
            |j| -> Vec<Forcing> { drives.iter().map(|d| self.forcing(d, j)).collect() };
        let mut start = forcing_at(range.start);
        let mut gain = self.solar_gain_w(members, range.start);
        for j in range.start + 1..range.end {
            let end = forcing_at(j);
            let gain_end = self.solar_gain_w(members, j);
            let step = NodeStep {
                dt_s: self.times[j] - self.times[j - 1],
                air_k: [self.samples[j - 1].air_k, self.samples[j].air_k],
                gain_w: [gain, gain_end],
                time_s: self.times[j - 1],
                spinup,
            };
            self.node_step(enclosure, members, walls, node, [&start, &end], &step)?;
            if let Some(air_k) = record.as_deref_mut() {
                if self.recorded[j] {
                    air_k.push(node.temperature_k);
                    for wall in walls.iter_mut() {
                        wall.history.surface_k.push(wall.state.surface_k());
                    }
                }
            }
            (start, gain) = (end, gain_end);
        }
        Ok(())
    }

    /// One step of node and members: the fixed point of the module docs.
    fn node_step(
        &self,
        enclosure: &Enclosure,
        members: &[Member],
        walls: &mut [Wall],
        node: &mut Node,
        forcing: [&[Forcing]; 2],
        step: &NodeStep,
    ) -> Result<(), NodeFailure> {
        let (c, g, dt) = (
            enclosure.heat_capacity_j_k,
            enclosure.air_exchange_w_k,
            step.dt_s,
        );
        let theta = if dt * (g + node.wall_w_k) <= c {
            0.5
        } else {
            1.0
        };
        let t0 = node.temperature_k;
        let air = 0.5 * (step.air_k[0] + step.air_k[1]);
        let gain = 0.5 * (step.gain_w[0] + step.gain_w[1]);
        // The rate extrapolated linearly: most steps of a smooth day settle at this first guess.
        let mut guess = t0 + (2.0 * node.rate_k_s - node.previous_rate_k_s) * dt;
        let mut previous: Option<(f64, f64)> = None;
        for iteration in 1..=NODE_ITERATIONS {
            // The node's temperature at the step's start as the members see it: T₀ (linear) or
            // T₁ (held).
            let first = t0 + (2.0 * theta - 1.0) * (guess - t0);
            let trial = walls_trial(walls, forcing, [first, guess], step)?;
            let exchanged: f64 = (members.iter().zip(&trial))
                .map(|(m, (_, report))| m.area_m2 * report.back_in_j_m2)
                .sum();
            let t1 = (c * t0 - exchanged + dt * g * (air - (1.0 - theta) * t0) + dt * gain)
                / (c + theta * dt * g);
            let residual = t1 - guess;
            let done = iteration == NODE_ITERATIONS;
            if residual.abs() <= NODE_TOLERANCE_K || (done && residual.abs() <= NODE_ACCEPT_K) {
                let leak = dt * g * (air - ((1.0 - theta) * t0 + theta * t1));
                node.commit(
                    t1,
                    dt,
                    residual,
                    [c * (t1 - t0), -exchanged, leak, dt * gain],
                );
                for (wall, (state, report)) in walls.iter_mut().zip(trial) {
                    wall.state = state;
                    wall.budget.add(&report);
                    wall.history.substeps += report.substeps as u64;
                }
                return Ok(());
            }
            if done {
                return Err(NodeFailure::Settle {
                    time_s: step.time_s,
                    spinup: step.spinup,
                    residual_k: residual.abs(),
                });
            }
            // Secant on the residual, with the last slope where this step has only one point.
            if let Some((g0, r0)) = previous {
                let slope = (residual - r0) / (guess - g0);
                if slope.is_finite() && slope < 0.0 {
                    node.slope = slope;
                }
            }
            previous = Some((guess, residual));
            guess -= residual / node.slope;
        }
        unreachable!("the last iteration returns")
    }
}

impl Node {
    /// Takes the balance's end temperature `t1`; `energy` is the step's stored heat, heat from
    /// the members, air exchange and sunlight (J).
    fn commit(&mut self, t1: f64, dt: f64, residual: f64, energy: [f64; 4]) {
        let [stored, walls, leak, sun] = energy;
        self.budget.stored += stored;
        self.budget.net_in += walls + leak + sun;
        self.budget.gross += walls.abs() + leak.abs() + sun.abs();
        self.residual_k = self.residual_k.max(residual.abs());
        self.previous_rate_k_s = self.rate_k_s;
        self.rate_k_s = (t1 - self.temperature_k) / dt;
        self.temperature_k = t1;
    }
}

/// Every member's step from its state with the node at `node_k` at the step's two ends; the new
/// states and reports, nothing committed.
fn walls_trial(
    walls: &mut [Wall],
    forcing: [&[Forcing]; 2],
    node_k: [f64; 2],
    step: &NodeStep,
) -> Result<Vec<(ThermalState, StepReport)>, NodeFailure> {
    walls
        .par_iter_mut()
        .enumerate()
        .map(|(m, wall)| {
            let mut state = wall.state.clone();
            let start = with_node(&forcing[0][m], node_k[0]);
            let end = with_node(&forcing[1][m], node_k[1]);
            let report =
                (wall.solver.step(&mut state, step.dt_s, &start, &end)).map_err(|error| {
                    let failure = VertexFailure {
                        time_s: Some(step.time_s),
                        spinup: step.spinup,
                        error,
                    };
                    NodeFailure::Member { member: m, failure }
                })?;
            Ok((state, report))
        })
        .collect()
}
