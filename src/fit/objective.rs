//! The weighted least-squares objective: normalized residuals
//! r = (F_model − F_measured)/σ over every Mueller element present, and the cost Σ r² = χ², or
//! Σ ρ(r) with a [`RobustLoss`]. The model is the pBRDF of `pbrdf` (docs/design.md §1.3); nothing here
//! re-derives physics. One evaluation builds the model once, computes the shadowing factor once
//! per distinct zenith angle and one Mueller matrix per point, in parallel over blocks of points.

use super::data::MeasurementData;
use super::data_view::DataView;
use super::parameters::ParameterValues;
use super::robust::RobustLoss;
use super::space::ModelSpace;
use crate::optics::Mueller;
use crate::pbrdf::Pbrdf;
use argmin::core::{CostFunction, Error};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Points per block of an evaluation run in parallel: more than the shipped measurements hold
/// (≤ 4000 rows), so their costs are summed exactly as serially, and enough work per block
/// (≈ 0.4 ms) that the threads' overhead does not show.
/// A multiple of 8, so a block's observations start on a lane of the normal equations' sums
/// ([`super::normal_equations`]).
pub(crate) const CHUNK_POINTS: usize = 4096;

/// Blocks of points whose residuals [`Objective::visit_normalized_residuals`] evaluates in one
/// parallel pass before handing them on in order: enough tasks for the threads, 2.4 MB of a
/// 9-element file's residuals.
const BLOCKS_PER_PASS: usize = 8;

/// The objective of one model family on one measurement, as a function of search coordinates
/// ([`ModelSpace`]). Thread-safe: the genetic stage evaluates it in parallel.
pub struct Objective<'a> {
    data: DataView<'a>,
    space: &'a ModelSpace,
    robust: Option<RobustLoss>,
    evaluations: AtomicU64,
}

impl<'a> Objective<'a> {
    pub fn new(
        data: &'a MeasurementData,
        space: &'a ModelSpace,
        robust: Option<RobustLoss>,
    ) -> Objective<'a> {
        Objective::over(data.into(), space, robust)
    }

    /// The objective over the points of `data` (all of a measurement's, or a fold's).
    pub(crate) fn over(
        data: DataView<'a>,
        space: &'a ModelSpace,
        robust: Option<RobustLoss>,
    ) -> Objective<'a> {
        Objective {
            data,
            space,
            robust,
            evaluations: AtomicU64::new(0),
        }
    }

    pub fn space(&self) -> &ModelSpace {
        self.space
    }
    pub(crate) fn data(&self) -> DataView<'a> {
        self.data
    }
    pub fn robust(&self) -> Option<RobustLoss> {
        self.robust
    }
    /// Size of the residual vector.
    pub fn observations(&self) -> usize {
        self.data.observations()
    }
    /// Model evaluations so far (all stages, all threads).
    pub fn evaluations(&self) -> u64 {
        self.evaluations.load(Ordering::Relaxed)
    }

    /// Counts `count` evaluations made elsewhere on this objective's behalf (the search on a
    /// subsample of a large set, [`super::optimize`]).
    pub(crate) fn add_evaluations(&self, count: u64) {
        self.evaluations.fetch_add(count, Ordering::Relaxed);
    }

    /// Smith's G1 per distinct zenith angle (an incomplete beta for the Cauchy Λ), counting one
    /// model evaluation.
    fn masking(&self, pbrdf: &Pbrdf) -> Vec<f64> {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        self.masking_factors(pbrdf)
    }

    fn masking_factors(&self, pbrdf: &Pbrdf) -> Vec<f64> {
        self.data
            .zenith_cosines()
            .iter()
            .map(|&c| pbrdf.masking_without_table(c))
            .collect()
    }

    /// Calls `visit(offset, r)` with the normalized residual of each element of `point`.
    #[inline]
    fn point_residuals(
        &self,
        pbrdf: &Pbrdf,
        masking: &[f64],
        point: usize,
        mut visit: impl FnMut(usize, f64),
    ) {
        let whole = self.data.whole;
        let at = self.data.whole_point(point);
        let m = self.model_at(pbrdf, masking, at);
        let start = at * whole.elements.len();
        for (offset, &(row, column)) in whole.elements.iter().enumerate() {
            visit(
                offset,
                (m[(row, column)] - whole.values[start + offset])
                    * self.data.inverse_sigma(start, offset),
            );
        }
    }

    /// The model's Mueller matrix at point `at` of the whole data.
    #[inline]
    fn model_at(&self, pbrdf: &Pbrdf, masking: &[f64], at: usize) -> Mueller {
        let g = &self.data.whole.geometry[at];
        pbrdf.mueller_for_geometry(
            &g.scattering,
            masking[self.data.zenith(g.incident_zenith())],
            masking[self.data.zenith(g.scattered_zenith())],
        )
    }

    /// Writes `map(r)` of every normalized residual of the model `pbrdf` into `out`, in parallel
    /// over blocks of [`CHUNK_POINTS`] points (each value is the same whatever the threads).
    fn fill_residuals(&self, pbrdf: &Pbrdf, out: &mut [f64], map: impl Fn(f64) -> f64 + Sync) {
        let masking = self.masking(pbrdf);
        self.fill_points(pbrdf, &masking, 0, out, &map);
    }

    /// Writes `map(r)` of the points from `first` on into `out` (whole points), in parallel over
    /// blocks of [`CHUNK_POINTS`] points.
    fn fill_points(
        &self,
        pbrdf: &Pbrdf,
        masking: &[f64],
        first: usize,
        out: &mut [f64],
        map: &(impl Fn(f64) -> f64 + Sync),
    ) {
        let width = self.data.element_count();
        let fill = |(chunk, block): (usize, &mut [f64])| {
            self.fill_block(pbrdf, masking, first + chunk * CHUNK_POINTS, block, map);
        };
        // One block (every shipped file) runs on the calling thread: no task to hand out.
        if out.len() <= CHUNK_POINTS * width {
            fill((0, out));
        } else {
            out.par_chunks_mut(CHUNK_POINTS * width)
                .enumerate()
                .for_each(fill);
        }
    }

    /// Writes `map(r)` of the points from `first` on into `block` (whole points).
    #[inline]
    fn fill_block(
        &self,
        pbrdf: &Pbrdf,
        masking: &[f64],
        first: usize,
        block: &mut [f64],
        map: &impl Fn(f64) -> f64,
    ) {
        let width = self.data.element_count();
        for (p, values) in block.chunks_mut(width).enumerate() {
            self.point_residuals(pbrdf, masking, first + p, |e, r| values[e] = map(r));
        }
    }

    /// The model at search coordinates `s` and its shadowing factors, counting one evaluation;
    /// `None` for an invalid model. What [`Objective::block_residuals`] evaluates.
    pub(crate) fn prepared_model(&self, s: &[f64]) -> Option<PreparedModel> {
        let pbrdf = self.model(&self.space.values(s))?;
        let masking = self.masking(&pbrdf);
        Some(PreparedModel { pbrdf, masking })
    }

    /// The residuals of [`LeastSquares::residuals`](super::levenberg_marquardt::LeastSquares)
    /// of the points from `first` on, written into `block` (whole points): the same values as
    /// the whole vector's, a block at a time.
    pub(crate) fn block_residuals(&self, model: &PreparedModel, first: usize, block: &mut [f64]) {
        let (pbrdf, masking) = (&model.pbrdf, model.masking.as_slice());
        match self.robust {
            None => self.fill_block(pbrdf, masking, first, block, &|r| r),
            Some(loss) => {
                self.fill_block(pbrdf, masking, first, block, &|r| loss.pseudo_residual(r))
            }
        }
    }

    /// The plain normalized residuals of the points from `first` on, written into `block` (whole
    /// points), whatever the loss: the values of [`Objective::normalized_residuals`], a block
    /// at a time.
    pub(crate) fn block_normalized_residuals(
        &self,
        model: &PreparedModel,
        first: usize,
        block: &mut [f64],
    ) {
        self.fill_block(&model.pbrdf, &model.masking, first, block, &|r| r);
    }

    /// Σ map(r) over every normalized residual of the model `pbrdf`: partial sums over blocks of
    /// [`CHUNK_POINTS`] points in parallel, added in block order, so that the sum does not depend
    /// on the thread count (and is the serial sum for a set of one block).
    fn sum_residuals(&self, pbrdf: &Pbrdf, map: impl Fn(f64) -> f64 + Sync) -> f64 {
        let masking = self.masking(pbrdf);
        let points = self.data.points();
        let block = |chunk: usize| {
            let mut total = 0.0;
            for point in chunk * CHUNK_POINTS..((chunk + 1) * CHUNK_POINTS).min(points) {
                self.point_residuals(pbrdf, &masking, point, |_, r| total += map(r));
            }
            total
        };
        if points <= CHUNK_POINTS {
            return block(0);
        }
        let partial: Vec<f64> = (0..points.div_ceil(CHUNK_POINTS))
            .into_par_iter()
            .map(block)
            .collect();
        partial.iter().sum()
    }

    /// The model at `values`, or `None` if they do not make a valid one (cannot happen inside
    /// the box, whose bounds are validated).
    fn model(&self, values: &ParameterValues) -> Option<Pbrdf> {
        self.space.pbrdf(values).ok()
    }

    /// Cost at `values`: χ² = Σ r², or Σ ρ(r) with a robust loss; +∞ for an invalid model.
    pub fn cost_at(&self, values: &ParameterValues) -> f64 {
        let Some(pbrdf) = self.model(values) else {
            return f64::INFINITY;
        };
        match self.robust {
            None => self.sum_residuals(&pbrdf, |r| r * r),
            Some(loss) => self.sum_residuals(&pbrdf, |r| loss.rho(r)),
        }
    }

    /// Cost at search coordinates (clamped into the box).
    pub fn cost(&self, search: &[f64]) -> f64 {
        self.cost_at(&self.space.values(search))
    }

    /// Residuals whose sum of squares is the cost (r, or sign(r)√ρ(r) with a robust loss),
    /// written into `out` (length [`Objective::observations`]). Returns false for an invalid
    /// model.
    pub fn residuals_at(&self, values: &ParameterValues, out: &mut [f64]) -> bool {
        let Some(pbrdf) = self.model(values) else {
            return false;
        };
        match self.robust {
            None => self.fill_residuals(&pbrdf, out, |r| r),
            Some(loss) => self.fill_residuals(&pbrdf, out, |r| loss.pseudo_residual(r)),
        }
        true
    }

    /// Plain normalized residuals r = (model − data)/σ at `values`, whatever the loss.
    pub fn normalized_residuals(&self, values: &ParameterValues) -> Option<Vec<f64>> {
        let pbrdf = self.model(values)?;
        let mut out = vec![0.0; self.observations()];
        self.fill_residuals(&pbrdf, &mut out, |r| r);
        Some(out)
    }

    /// Calls `visit` with the plain normalized residuals at `values`, whatever the loss, a pass
    /// of [`BLOCKS_PER_PASS`] blocks of points at a time, in order: the values of
    /// [`Objective::normalized_residuals`] (counting one evaluation), for a sum over them in
    /// order without holding them all (14 MB at 2e5 rows of 9 elements). Returns false for an
    /// invalid model.
    pub(crate) fn visit_normalized_residuals(
        &self,
        values: &ParameterValues,
        mut visit: impl FnMut(&[f64]),
    ) -> bool {
        let Some(pbrdf) = self.model(values) else {
            return false;
        };
        let masking = self.masking(&pbrdf);
        let (points, width) = (self.data.points(), self.data.element_count());
        let pass_points = BLOCKS_PER_PASS * CHUNK_POINTS;
        let mut pass = vec![0.0; points.min(pass_points) * width];
        for first in (0..points).step_by(pass_points) {
            let block = &mut pass[..(points - first).min(pass_points) * width];
            self.fill_points(&pbrdf, &masking, first, block, &|r| r);
            visit(block);
        }
        true
    }

    /// Σ r² of the plain normalized residuals at `values`, summed in order as `Iterator::sum`
    /// sums [`Objective::normalized_residuals`], and their number; `None` for an invalid model.
    pub(crate) fn chi2(&self, values: &ParameterValues) -> Option<(f64, usize)> {
        // −0.0: where `Iterator::sum` of f64 starts.
        let mut chi2 = -0.0;
        self.visit_normalized_residuals(values, |block| {
            for r in block {
                chi2 += r * r;
            }
        })
        .then_some((chi2, self.observations()))
    }

    /// The first point where the model's Mueller matrix (sr⁻¹) at `values` satisfies
    /// `predicate`, in parallel and without holding the matrices; `None` for an invalid model.
    pub(crate) fn first_point_where(
        &self,
        values: &ParameterValues,
        predicate: impl Fn(&Mueller) -> bool + Sync,
    ) -> Option<Option<usize>> {
        let pbrdf = self.model(values)?;
        let masking = self.masking_factors(&pbrdf);
        Some(
            (0..self.data.points())
                .into_par_iter()
                .position_first(|point| {
                    predicate(&self.model_at(&pbrdf, &masking, self.data.whole_point(point)))
                }),
        )
    }

    /// The model's full Mueller matrix (sr⁻¹) at every point.
    pub fn model_muellers(&self, values: &ParameterValues) -> Option<Vec<Mueller>> {
        let pbrdf = self.model(values)?;
        let masking = self.masking_factors(&pbrdf);
        Some(
            (0..self.data.points())
                .into_par_iter()
                .map(|point| self.model_at(&pbrdf, &masking, self.data.whole_point(point)))
                .collect(),
        )
    }
}

/// A model and its shadowing factor per distinct zenith angle, ready to evaluate blocks of
/// points.
pub(crate) struct PreparedModel {
    pbrdf: Pbrdf,
    masking: Vec<f64>,
}

/// The objective as an argmin cost function of search coordinates (the genetic stage's box).
pub struct BoxCost<'o, 'a>(pub &'o Objective<'a>);

impl CostFunction for BoxCost<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, search: &Vec<f64>) -> Result<f64, Error> {
        Ok(self.0.cost(search))
    }
}
