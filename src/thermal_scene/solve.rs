//! Runs the thermal model over a scene (docs/design.md §1.8): every shading vertex of a part with a thermal
//! stack gets its own 1-D solve, forced by the weather, the sun it sees and the sky it sees.
//!
//! **Front forcing per vertex** (§1.8), n its normal, s the sun direction, at each sample time:
//!   absorbed = α_s [E_dn max(0, n·s) V_sun + E_dh F_sky],
//!   long-wave in = ε [E_lw F_sky + σ T_g⁴ (1 − F_sky)],
//!   h = given or 5.7 + 3.8 v (McAdams), T_air from the weather; the solver adds −εσT⁴ + h(T_air − T).
//! V_sun is linear in time between shadow instants (a shadow edge crossing a vertex takes one
//! shadow step); the weather is sampled every `time_step_s` and at every recorded instant, and the
//! solver interpolates linearly in between with its own adaptive sub-steps.
//!
//! **Identical vertices are solved once.** Two vertices of one part with bit-identical normal,
//! F_sky, shadow history and initial temperature have bit-identical forcing, so one solve serves
//! both (most of a ground plane, the flat panels of a box). This is exact, not an approximation.

use super::exposure::Occluders;
use crate::progress::Progress;
use crate::scene::mesh::{bounding_diagonal, ShadedMesh};
use crate::scene::Scene;
use crate::thermal::convection::mcadams_coefficient;
use crate::thermal::setup::{SurfaceThermal, ThermalSetup};
use crate::thermal::{
    Forcing, FrontForcing, Resolution, Solver, SolverControl, StepReport, ThermalState,
};
use crate::transport::accel::Accelerator;
use crate::transport::horizon::HorizonMap;
use crate::weather::WeatherSample;
use rayon::prelude::*;

mod enclosure;
mod field;
mod ground;
mod radiation;
mod run_error;
mod vertices;

pub use run_error::{ThermalRunError, MAX_RECORDED_VALUES, MAX_SHADOW_SAMPLES};
pub use vertices::vertex_surfaces;

use enclosure::NodeRun;
use field::FieldStats;
use ground::GroundHistory;
use radiation::SampleRadiation;
use run_error::{check_sizes, independent_error, step_label, VertexFailure};
use vertices::{occluding_mesh, sampled_end, shadow_instants, Exposure, ThermalVertices};

/// Surface temperatures of every shading vertex at the recorded instants (saved whole by
/// [`super::saved`]).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ThermalSolution {
    /// Recorded instants (s from `start_utc`), ascending: 0, every output step, the end, and any
    /// extra instants asked for.
    pub times_s: Vec<f64>,
    /// `surface_k[i][v]`: vertex v's surface temperature at `times_s[i]` (K). Vertices of parts
    /// without a thermal stack keep their typed temperature.
    pub surface_k: Vec<Vec<f64>>,
    /// The weather at each recorded instant.
    pub weather: Vec<WeatherSample>,
    pub stats: SolveStats,
    /// The environment's ground temperature at each recorded instant (K) when it is solved
    /// (`environment.ground.thermal`); `None` for the typed ground.
    pub ground_k: Option<Vec<f64>>,
    /// `enclosure_air_k[e][i]`: enclosure e's air temperature (in `[thermal.enclosures]` order)
    /// at `times_s[i]` (K).
    pub enclosure_air_k: Vec<Vec<f64>>,
    /// Per enclosure: the largest difference between the node temperature the members saw at
    /// the end of a step and the one the node's energy balance then gave (K, the fixed point's
    /// residual; the energy closes whatever it is).
    pub enclosure_residual_k: Vec<f64>,
}

/// How much work the run took and how well it closed its energy budget.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SolveStats {
    /// Shading vertices whose temperatures the model computes.
    pub thermal_vertices: usize,
    /// Distinct forcing histories among them (each solved once).
    pub distinct_solves: usize,
    /// Accepted solver sub-steps summed over the distinct solves.
    pub substeps: u64,
    /// Worst |stored heat − ∫ net flux| over the run, relative to the ∫|flux| of that vertex.
    pub worst_energy_closure: f64,
}

impl SolveStats {
    /// Counts a terrain field's vertices (each its own solve), sub-steps and closure.
    fn add_field(&mut self, field: &FieldStats) {
        self.thermal_vertices += field.vertices;
        self.distinct_solves += field.vertices;
        self.substeps += field.substeps;
        self.worst_energy_closure = self.worst_energy_closure.max(field.closure);
    }
}

const DAY_S: f64 = 86_400.0;

/// The sample times of the run: every `time_step_s`, every `output_step_s`, the end and `extra`
/// (through the first day too when it is spun up), and which of them are recorded.
pub(crate) fn sample_times(setup: &ThermalSetup, extra: &[f64]) -> (Vec<f64>, Vec<bool>) {
    let end = setup.duration_s;
    let sampled_end = sampled_end(setup);
    let mut times: Vec<(f64, bool)> = Vec::new();
    let mut push_grid = |step: f64, last: f64, record: bool| {
        let n = (last / step).floor() as usize;
        times.extend((0..=n).map(|i| (i as f64 * step, record)));
    };
    push_grid(setup.time_step_s, sampled_end, false);
    push_grid(setup.output_step_s, end, true);
    times.push((end, true));
    times.push((sampled_end, false));
    times.extend(extra.iter().map(|&t| (t, true)));
    times.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut merged: Vec<(f64, bool)> = Vec::with_capacity(times.len());
    for (t, record) in times {
        match merged.last_mut() {
            Some(last) if (t - last.0).abs() < 1e-6 => last.1 |= record,
            _ => merged.push((t, record)),
        }
    }
    merged.into_iter().unzip()
}

fn weather_at(setup: &ThermalSetup, time_s: f64) -> Result<WeatherSample, ThermalRunError> {
    setup.weather.at(time_s).map_err(ThermalRunError::Weather)
}

/// Solves the scene's thermal model, recording every output step plus `extra_times_s`.
pub fn solve_scene(
    scene: &Scene,
    extra_times_s: &[f64],
    progress: &dyn Progress,
) -> Result<ThermalSolution, ThermalRunError> {
    let setup = scene
        .thermal
        .as_deref()
        .ok_or_else(|| ThermalRunError::NotThermal(crate::text::path(&scene.path)))?;
    if let Some(&t) = extra_times_s
        .iter()
        .find(|&&t| !(t.is_finite() && (0.0..=setup.duration_s).contains(&t)))
    {
        return Err(ThermalRunError::OutsideRun {
            time_s: t,
            duration_s: setup.duration_s,
        });
    }
    check_sizes(scene, setup)?;
    let (times, recorded) = sample_times(setup, extra_times_s);
    let samples = times
        .iter()
        .map(|&t| weather_at(setup, t))
        .collect::<Result<Vec<_>, _>>()?;
    let occluding = occluding_mesh(scene);
    let accel = Accelerator::new(&occluding, bounding_diagonal(&scene.mesh.positions));
    let horizons = (scene.heightfields.par_iter())
        .map(HorizonMap::new)
        .collect();
    let occluders = Occluders::new(accel, horizons);
    let (vertices, fields) = ThermalVertices::trace(scene, setup, &occluders, progress)?;
    let (class, representatives) = vertices.group(&scene.mesh);
    let run = Run {
        setup,
        times: &times,
        recorded: &recorded,
        samples: &samples,
        run_samples: times.partition_point(|&t| t <= setup.duration_s + 1e-6),
    };
    // The environment's ground depends on nothing else: solved first, it forces every part.
    let ground = run.solve_ground()?;
    progress.begin("thermal solve", representatives.len() as u64);
    let mut histories = run.independent(
        scene,
        &vertices,
        &representatives,
        ground.as_ref(),
        progress,
    )?;
    let groups = Groups {
        vertices: &vertices,
        class: &class,
        representatives: &representatives,
    };
    let nodes = run.enclosures(scene, &groups, ground.as_ref(), &mut histories, progress)?;
    progress.end();
    let histories: Vec<History> = (histories.into_iter())
        .map(|h| h.expect("every class is solved, on its own or with its enclosure"))
        .collect();
    let mut solution = run.solution(&scene.mesh, &groups, &histories, ground.as_ref(), nodes);
    for field in &fields {
        progress.begin("terrain thermal solve", field.vertex.len() as u64);
        let stats = run.solve_field(
            scene,
            field,
            &occluders,
            ground.as_ref(),
            progress,
            &mut solution.surface_k,
        )?;
        progress.end();
        solution.stats.add_field(&stats);
    }
    Ok(solution)
}

/// The front convective coefficient: the part's, or McAdams' from the wind.
fn front_convection_w_m2k(model: &SurfaceThermal, w: &WeatherSample) -> f64 {
    model
        .convection_w_m2k
        .unwrap_or(mcadams_coefficient(w.wind_m_s))
}

/// The shared inputs of every vertex's solve.
struct Run<'a> {
    setup: &'a ThermalSetup,
    times: &'a [f64],
    recorded: &'a [bool],
    samples: &'a [WeatherSample],
    /// Samples 0..run_samples are the run (the rest only spin up the first day).
    run_samples: usize,
}

/// One vertex's recorded surface temperatures and bookkeeping.
struct History {
    surface_k: Vec<f64>,
    substeps: u64,
    closure: f64,
}

impl History {
    fn new() -> History {
        History {
            surface_k: Vec::new(),
            substeps: 0,
            closure: 0.0,
        }
    }
}

/// What drives one vertex through one pass (a spin-up day or the run): its model, what it sees,
/// and the solved environment ground's temperature at every sample of the pass (`None`: the
/// typed ground).
struct Drive<'a> {
    model: &'a SurfaceThermal,
    exposure: &'a Exposure<'a>,
    ground: Option<&'a [f64]>,
    spinup: bool,
}

/// Energy bookkeeping of a march: stored heat, net heat in and the heat through the boundaries.
#[derive(Clone, Copy, Debug, Default)]
struct Budget {
    stored: f64,
    net_in: f64,
    gross: f64,
}

impl Budget {
    fn add(&mut self, report: &StepReport) {
        self.stored += report.stored_j_m2;
        self.net_in += report.net_in_j_m2();
        self.gross +=
            report.front_in_j_m2.abs() + report.back_in_j_m2.abs() + report.internal_j_m2.abs();
    }

    /// |stored − net in| relative to the heat through the boundaries.
    fn closure(&self) -> f64 {
        (self.stored - self.net_in).abs() / self.gross.max(f64::MIN_POSITIVE)
    }
}

/// Which vertices share a history and which vertex stands for each.
struct Groups<'a> {
    vertices: &'a ThermalVertices,
    /// Each thermal vertex's history class.
    class: &'a [usize],
    /// One thermal vertex per class.
    representatives: &'a [usize],
}

impl Run<'_> {
    /// The recorded temperatures of every shading vertex, each thermal vertex's from its class,
    /// with the environment ground's and the enclosures' when solved.
    fn solution(
        &self,
        mesh: &ShadedMesh,
        groups: &Groups,
        histories: &[History],
        ground: Option<&GroundHistory>,
        nodes: Vec<NodeRun>,
    ) -> ThermalSolution {
        let recorded: Vec<usize> = (0..self.run_samples)
            .filter(|&j| self.recorded[j])
            .collect();
        let mut surface_k = vec![mesh.temperatures.clone(); recorded.len()];
        for (i, &v) in groups.vertices.index.iter().enumerate() {
            let history = &histories[groups.class[i]];
            for (r, row) in surface_k.iter_mut().enumerate() {
                row[v] = history.surface_k[r];
            }
        }
        let mut stats = SolveStats {
            thermal_vertices: groups.vertices.index.len(),
            distinct_solves: histories.len(),
            substeps: histories.iter().map(|h| h.substeps).sum(),
            worst_energy_closure: histories.iter().map(|h| h.closure).fold(0.0, f64::max),
        };
        if let Some(g) = ground {
            stats.distinct_solves += 1;
            stats.substeps += g.substeps;
            stats.worst_energy_closure = stats.worst_energy_closure.max(g.closure);
        }
        for node in &nodes {
            stats.worst_energy_closure = stats.worst_energy_closure.max(node.closure);
        }
        ThermalSolution {
            times_s: recorded.iter().map(|&j| self.times[j]).collect(),
            surface_k,
            weather: recorded.iter().map(|&j| self.samples[j]).collect(),
            stats,
            ground_k: ground.map(|g| recorded.iter().map(|&j| g.run[j]).collect()),
            enclosure_air_k: nodes.iter().map(|n| n.air_k.clone()).collect(),
            enclosure_residual_k: nodes.iter().map(|n| n.residual_k).collect(),
        }
    }

    /// The solves of the vertices outside any enclosure, each on its own, in parallel (`None`
    /// for an enclosure's members, solved with their node).
    fn independent(
        &self,
        scene: &Scene,
        vertices: &ThermalVertices,
        representatives: &[usize],
        ground: Option<&GroundHistory>,
        progress: &dyn Progress,
    ) -> Result<Vec<Option<History>>, ThermalRunError> {
        representatives
            .par_iter()
            .map(|&i| {
                let v = vertices.index[i];
                let surface = vertices.surface[i] as usize;
                let model = self.setup.surfaces[surface]
                    .as_ref()
                    .expect("thermal vertex");
                if model.enclosure.is_some() {
                    return Ok(None);
                }
                let exposure = vertices.exposure(i, &scene.mesh);
                let result = self
                    .vertex(model, &exposure, scene.mesh.temperatures[v], ground)
                    .map(Some)
                    .map_err(|failure| independent_error(scene, surface, failure));
                progress.advance(1);
                result
            })
            .collect()
    }

    /// The sun, the sky and the ground at sample `j`, with the solved ground at `ground_k`.
    fn radiation(&self, j: usize, ground_k: Option<f64>) -> SampleRadiation {
        let occluded_k = (self.setup.ground.as_ref()).and_then(|g| g.occluded_k);
        let typed = self.setup.ground_temperature_k;
        SampleRadiation::new(&self.samples[j], typed, ground_k, occluded_k)
    }

    /// Solar irradiance on a vertex's front at sample `j` (W m⁻²) before absorption: α_s of it
    /// is absorbed, τ of it passes into an enclosure.
    fn incident_w_m2(&self, exposure: &Exposure, j: usize) -> f64 {
        let visible = exposure.sun_visible(self.times[j], self.setup.shadow_step_s);
        (self.radiation(j, None)).incident_w_m2(&exposure.normal, exposure.sky_view, visible)
    }

    /// The forcing of §1.8 at sample `j` (see the module docs).
    fn forcing(&self, drive: &Drive, j: usize) -> Forcing {
        let (t, w) = (self.times[j], &self.samples[j]);
        let model = drive.model;
        let exposure = drive.exposure;
        let radiation = self.radiation(j, drive.ground.map(|g| g[j]));
        let visible = exposure.sun_visible(t, self.setup.shadow_step_s);
        let incident = radiation.incident_w_m2(&exposure.normal, exposure.sky_view, visible);
        Forcing {
            front: FrontForcing {
                absorbed_w_m2: model.solar_absorptance * incident,
                longwave_in_w_m2: radiation.longwave_in_w_m2(
                    model.emissivity,
                    exposure.normal.z,
                    exposure.sky_view,
                ),
                emissivity: model.emissivity,
                h_w_m2k: front_convection_w_m2k(model, w),
                air_k: w.air_k,
            },
            back: model.back,
            internal_w_m2: model.internal_heat.at(t),
        }
    }

    /// A vertex's solver and its uniform starting state.
    fn start(
        &self,
        model: &SurfaceThermal,
        initial_k: f64,
    ) -> Result<(Solver, ThermalState), VertexFailure> {
        let grid = model
            .stack
            .discretise(&Resolution::default())
            .map_err(VertexFailure::before_run)?;
        let state = ThermalState::uniform(&grid, initial_k).map_err(VertexFailure::before_run)?;
        let solver =
            Solver::new(grid, SolverControl::default()).map_err(VertexFailure::before_run)?;
        Ok((solver, state))
    }

    /// Samples 0..first_day are the day a spin-up repeats.
    fn first_day(&self) -> usize {
        self.times.partition_point(|&t| t <= DAY_S + 1e-6)
    }

    /// Spin-up (the first day repeated) and the run, recording the surface temperature.
    fn vertex(
        &self,
        model: &SurfaceThermal,
        exposure: &Exposure,
        initial_k: f64,
        ground: Option<&GroundHistory>,
    ) -> Result<History, VertexFailure> {
        let (mut solver, mut state) = self.start(model, initial_k)?;
        for pass in 0..self.setup.spinup_days as usize {
            let drive = Drive {
                model,
                exposure,
                ground: ground.map(|g| g.spinup[pass].as_slice()),
                spinup: true,
            };
            let days = 0..self.first_day();
            self.march(&mut solver, &mut state, &drive, days, |_, _, _| {})?;
        }
        let mut history = History::new();
        if self.recorded[0] {
            history.surface_k.push(state.surface_k());
        }
        let drive = Drive {
            model,
            exposure,
            ground: ground.map(|g| g.run.as_slice()),
            spinup: false,
        };
        let all = 0..self.run_samples;
        let budget = self.march(&mut solver, &mut state, &drive, all, |j, state, report| {
            history.substeps += report.substeps as u64;
            if self.recorded[j] {
                history.surface_k.push(state.surface_k());
            }
        })?;
        history.closure = budget.closure();
        Ok(history)
    }

    /// Steps through samples `range` (from its first to its last time), calling `each` after
    /// every step with the sample reached, the state and the step's report.
    fn march(
        &self,
        solver: &mut Solver,
        state: &mut ThermalState,
        drive: &Drive,
        range: std::ops::Range<usize>,
        mut each: impl FnMut(usize, &ThermalState, &StepReport),
    ) -> Result<Budget, VertexFailure> {
        let mut budget = Budget::default();
        let mut start = self.forcing(drive, range.start);
        for j in range.start + 1..range.end {
            let end = self.forcing(drive, j);
            let (t0, t1) = (self.times[j - 1], self.times[j]);
            let report =
                solver
                    .step(state, t1 - t0, &start, &end)
                    .map_err(|error| VertexFailure {
                        time_s: Some(t0),
                        spinup: drive.spinup,
                        error,
                    })?;
            budget.add(&report);
            each(j, state, &report);
            start = end;
        }
        Ok(budget)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visibility_is_linear_between_shadow_instants() {
        let lit = [1u8, 0, 0, 1];
        let e = Exposure {
            normal: nalgebra::Vector3::z(),
            sky_view: 1.0,
            lit: &lit,
        };
        assert_eq!(e.sun_visible(0.0, 600.0), 1.0);
        assert!((e.sun_visible(150.0, 600.0) - 0.75).abs() < 1e-12);
        assert_eq!(e.sun_visible(900.0, 600.0), 0.0);
        assert!((e.sun_visible(1500.0, 600.0) - 0.5).abs() < 1e-12);
        assert_eq!(e.sun_visible(1800.0, 600.0), 1.0);
        assert_eq!(e.sun_visible(5000.0, 600.0), 1.0);
    }
}
