//! The vertices of an upright terrain tile (docs/design.md §1.8 at terrain scale): millions of
//! vertices that share one layer stack, one weather and one back boundary, and differ only in
//! what they see. They are marched [`LANES`] at a time by the batched solver
//! (`thermal::batch`), which eliminates the shared conduction matrix once per step for all
//! lanes; what each sees comes from the terrain's horizon map and rays against the other
//! objects ([`Occluders`]), computed per block as it is solved, so nothing per vertex and
//! instant is ever stored but the recorded temperatures.
//!
//! The forcing is the same §1.8 balance as every other vertex's ([`super::radiation`]); only the
//! time stepping differs: fixed sub-steps of at most `thermal::batch::BATCH_MAX_SUBSTEP_S`
//! instead of the adaptive controller, on the grid of `Resolution::batch` (the accuracy both
//! cost is measured in tests/it/thermal_batch.rs and tests/it/thermal_field.rs).

use super::radiation::ShadowInterval;
use super::{
    front_convection_w_m2k, ground::GroundHistory, independent_error, shadow_instants, weather_at,
    Run, ThermalRunError, VertexFailure,
};
use crate::progress::Progress;
use crate::scene::Scene;
use crate::thermal::batch::{
    BatchForcing, BatchReport, BatchSolver, BatchState, Lanes, BATCH_MAX_SUBSTEP_S, LANES,
};
use crate::thermal::setup::SurfaceThermal;
use crate::thermal::{Resolution, SolverControl, ThermalError};
use crate::thermal_scene::exposure::{sky_rule, Occluders, VertexFrame};
use nalgebra::Vector3;
use rayon::prelude::*;

/// The thermal vertices of one terrain tile solved as a field.
pub(super) struct FieldVertices {
    /// Index into `Scene::heightfields`.
    pub heightfield: usize,
    /// The tile's scene surface (its one part).
    pub surface: u32,
    /// Shading vertex of each field vertex.
    pub vertex: Vec<usize>,
    /// Its grid point on the tile.
    pub grid: Vec<usize>,
}

/// Blocks solved between two scatters of their results into the solution: bounds the memory of
/// results in flight to ~4096 × LANES × recorded instants values.
const BLOCKS_PER_BATCH: usize = 4096;

/// What one block of lanes sees: normals, F_sky, and V_sun at each shadow instant.
struct BlockView {
    normal: [Vector3<f64>; LANES],
    sky_view: Lanes,
    lit: [Vec<u8>; LANES],
}

/// What drives a block through one pass: its model, what it sees, and the solved ground at every
/// sample of the pass (`None`: the typed ground).
struct FieldDrive<'a> {
    model: &'a SurfaceThermal,
    view: &'a BlockView,
    ground: Option<&'a [f64]>,
}

/// The recorded surface temperatures of a block ([recorded instant][lane]), its worst energy
/// closure and the sub-steps each of its lanes took.
struct BlockResult {
    surface_k: Vec<Lanes>,
    closure: f64,
    substeps: u64,
}

/// A block's energy bookkeeping per lane (the batched solver's stored heat plus its deferred
/// heat changes by exactly the booked fluxes).
#[derive(Default)]
struct BatchBudget {
    stored: Lanes,
    net_in: Lanes,
    gross: Lanes,
    /// Sub-steps taken (the same for every lane).
    substeps: u64,
}

impl BatchBudget {
    fn add(&mut self, report: &BatchReport) {
        self.substeps += report.substeps as u64;
        for (l, net_in) in report.net_in_j_m2().into_iter().enumerate() {
            self.stored[l] += report.stored_j_m2[l] + report.deferred_j_m2[l];
            self.net_in[l] += net_in;
            self.gross[l] += report.front_in_j_m2[l].abs()
                + report.back_in_j_m2[l].abs()
                + report.internal_j_m2[l].abs();
        }
    }

    /// The worst lane's |stored − net in| relative to the heat through its boundaries.
    fn closure(&self) -> f64 {
        (0..LANES)
            .map(|l| (self.stored[l] - self.net_in[l]).abs() / self.gross[l].max(f64::MIN_POSITIVE))
            .fold(0.0, f64::max)
    }
}

/// What the whole field's solve adds to the run's statistics.
#[derive(Default)]
pub(super) struct FieldStats {
    pub vertices: usize,
    pub substeps: u64,
    pub closure: f64,
}

impl Run<'_> {
    /// Solves `field`, writing its vertices' recorded temperatures into `surface_k`
    /// (`[recorded instant][shading vertex]`).
    pub(super) fn solve_field(
        &self,
        scene: &Scene,
        field: &FieldVertices,
        occluders: &Occluders,
        ground: Option<&GroundHistory>,
        progress: &dyn Progress,
        surface_k: &mut [Vec<f64>],
    ) -> Result<FieldStats, ThermalRunError> {
        let surface = field.surface as usize;
        let model = self.setup.surfaces[surface]
            .as_ref()
            .expect("a field is a thermal surface");
        let fail = |error, time_s, spinup| field_error(scene, surface, error, time_s, spinup);
        let grid = (model.stack)
            .discretise(&Resolution::batch())
            .map_err(|e| fail(e, None, false))?;
        let newton = SolverControl::default().newton_tolerance_k;
        let solver = BatchSolver::new(grid, BATCH_MAX_SUBSTEP_S, newton)
            .map_err(|e| fail(e, None, false))?;
        let sun = (shadow_instants(self.setup).iter())
            .map(|&t| weather_at(self.setup, t).map(|w| w.sun_direction))
            .collect::<Result<Vec<_>, _>>()?;
        let rule = sky_rule();
        let lanes: Vec<usize> = (0..field.vertex.len()).collect();
        let blocks: Vec<&[usize]> = lanes.chunks(LANES).collect();
        let mut stats = FieldStats {
            vertices: field.vertex.len(),
            ..FieldStats::default()
        };
        for batch in blocks.chunks(BLOCKS_PER_BATCH) {
            let results = (batch.par_iter())
                .map_init(
                    || solver.clone(),
                    |solver, block| {
                        let frames = block_frames(scene, field, block);
                        let view = BlockView::new(occluders, &frames, &sun, &rule);
                        let result = self.block(solver, model, &view, scene, ground, block, field);
                        progress.advance(block.len() as u64);
                        result
                    },
                )
                .collect::<Result<Vec<_>, _>>()?;
            for (block, result) in batch.iter().zip(results) {
                stats.closure = stats.closure.max(result.closure);
                stats.substeps += result.substeps * block.len() as u64;
                for (row, lanes) in surface_k.iter_mut().zip(&result.surface_k) {
                    for (l, &i) in block.iter().enumerate() {
                        row[field.vertex[i]] = lanes[l];
                    }
                }
            }
        }
        Ok(stats)
    }

    /// One block through the spin-up days and the run, recording its surface temperatures.
    #[allow(clippy::too_many_arguments)]
    fn block(
        &self,
        solver: &mut BatchSolver,
        model: &SurfaceThermal,
        view: &BlockView,
        scene: &Scene,
        ground: Option<&GroundHistory>,
        block: &[usize],
        field: &FieldVertices,
    ) -> Result<BlockResult, ThermalRunError> {
        let surface = field.surface as usize;
        let initial: Lanes =
            std::array::from_fn(|l| scene.mesh.temperatures[field.vertex[lane(block, l)]]);
        let fail = |error, time_s, spinup| field_error(scene, surface, error, time_s, spinup);
        let mut state =
            BatchState::uniform(solver.grid(), initial).map_err(|e| fail(e, None, false))?;
        let (mut closure, mut substeps): (f64, u64) = (0.0, 0);
        for pass in 0..self.setup.spinup_days as usize {
            let drive = FieldDrive {
                model,
                view,
                ground: ground.map(|g| g.spinup[pass].as_slice()),
            };
            let budget = self
                .march_field(solver, &mut state, &drive, 0..self.first_day(), |_, _| {})
                .map_err(|(e, t)| fail(e, Some(t), true))?;
            closure = closure.max(budget.closure());
            substeps += budget.substeps;
        }
        let mut surface_k = Vec::new();
        if self.recorded[0] {
            surface_k.push(state.surface_k());
        }
        let drive = FieldDrive {
            model,
            view,
            ground: ground.map(|g| g.run.as_slice()),
        };
        let budget = self
            .march_field(solver, &mut state, &drive, 0..self.run_samples, |j, s| {
                if self.recorded[j] {
                    surface_k.push(s.surface_k());
                }
            })
            .map_err(|(e, t)| fail(e, Some(t), false))?;
        Ok(BlockResult {
            surface_k,
            closure: closure.max(budget.closure()),
            substeps: substeps + budget.substeps,
        })
    }

    /// Steps a block through samples `range`, calling `each` after every step; returns its
    /// energy bookkeeping, or the error and the start of the failed step.
    fn march_field(
        &self,
        solver: &mut BatchSolver,
        state: &mut BatchState,
        drive: &FieldDrive,
        range: std::ops::Range<usize>,
        mut each: impl FnMut(usize, &BatchState),
    ) -> Result<BatchBudget, (ThermalError, f64)> {
        let mut budget = BatchBudget::default();
        let mut start = self.field_forcing(drive, range.start);
        for j in range.start + 1..range.end {
            let end = self.field_forcing(drive, j);
            let (t0, t1) = (self.times[j - 1], self.times[j]);
            let report = solver
                .step(state, t1 - t0, &start, &end)
                .map_err(|e| (e, t0))?;
            budget.add(&report);
            each(j, state);
            start = end;
        }
        Ok(budget)
    }

    /// The forcing of every lane of a block at sample `j` (the §1.8 balance of
    /// [`super::radiation`], lane by lane).
    fn field_forcing(&self, drive: &FieldDrive, j: usize) -> BatchForcing {
        let (t, w) = (self.times[j], &self.samples[j]);
        let (model, view) = (drive.model, drive.view);
        let radiation = self.radiation(j, drive.ground.map(|g| g[j]));
        let interval = ShadowInterval::at(t, self.setup.shadow_step_s, view.lit[0].len());
        let absorbed = std::array::from_fn(|l| {
            let visible = interval.visible(&view.lit[l]);
            model.solar_absorptance
                * radiation.incident_w_m2(&view.normal[l], view.sky_view[l], visible)
        });
        let longwave = std::array::from_fn(|l| {
            radiation.longwave_in_w_m2(model.emissivity, view.normal[l].z, view.sky_view[l])
        });
        BatchForcing {
            absorbed_w_m2: absorbed,
            longwave_in_w_m2: longwave,
            emissivity: model.emissivity,
            h_w_m2k: front_convection_w_m2k(model, w),
            air_k: w.air_k,
            back: model.back,
            internal_w_m2: model.internal_heat.at(t),
        }
    }
}

/// A field's failed solve, named by its part and the step (`time_s`, `None` before the run).
fn field_error(
    scene: &Scene,
    surface: usize,
    error: ThermalError,
    time_s: Option<f64>,
    spinup: bool,
) -> ThermalRunError {
    let failure = VertexFailure {
        time_s,
        spinup,
        error,
    };
    independent_error(scene, surface, failure)
}

/// The field vertex of lane `l` of a block: the block's own, the last repeated to fill the lanes
/// of a short block.
fn lane(block: &[usize], l: usize) -> usize {
    block[l.min(block.len() - 1)]
}

/// The frames of a block's vertices, the last repeated to fill the lanes.
fn block_frames(scene: &Scene, field: &FieldVertices, block: &[usize]) -> [VertexFrame; LANES] {
    std::array::from_fn(|l| {
        let i = lane(block, l);
        let v = field.vertex[i];
        VertexFrame {
            position: scene.mesh.positions[v],
            normal: scene.mesh.normals[v],
            grid: Some((field.heightfield, field.grid[i])),
        }
    })
}

impl BlockView {
    fn new(
        occluders: &Occluders,
        frames: &[VertexFrame; LANES],
        sun: &[Vector3<f64>],
        rule: &[(Vector3<f64>, f64)],
    ) -> BlockView {
        BlockView {
            normal: frames.map(|f| f.normal),
            sky_view: frames.map(|f| occluders.sky_view(&f, rule)),
            lit: frames.map(|f| occluders.sun_visible(&f, sun)),
        }
    }
}
