//! The weighted least-squares objective: normalized residuals
//! r = (F_model − F_measured)/σ over every Mueller element present, and the cost Σ r² = χ², or
//! Σ ρ(r) with a [`RobustLoss`]. The model is the pBRDF of `pbrdf` (docs/design.md §1.3); nothing here
//! re-derives physics. One evaluation builds the model once, computes the shadowing factor once
//! per distinct zenith angle and one Mueller matrix per point.

use super::data::MeasurementData;
use super::parameters::ParameterValues;
use super::robust::RobustLoss;
use super::space::ModelSpace;
use crate::optics::Mueller;
use crate::pbrdf::Pbrdf;
use argmin::core::{CostFunction, Error};
use std::sync::atomic::{AtomicU64, Ordering};

/// The objective of one model family on one measurement, as a function of search coordinates
/// ([`ModelSpace`]). Thread-safe: the genetic stage evaluates it in parallel.
pub struct Objective<'a> {
    data: &'a MeasurementData,
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
    pub fn data(&self) -> &MeasurementData {
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

    /// Calls `visit(observation, r)` with every normalized residual of the model `pbrdf`.
    #[inline]
    fn for_each_residual(&self, pbrdf: &Pbrdf, mut visit: impl FnMut(usize, f64)) {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        // Smith's G1 per distinct zenith angle (an incomplete beta for the Cauchy Λ).
        let masking: Vec<f64> = self
            .data
            .zenith_cosines
            .iter()
            .map(|&c| pbrdf.masking_without_table(c))
            .collect();
        let width = self.data.elements.len();
        for (point, g) in self.data.geometry.iter().enumerate() {
            let m = pbrdf.mueller_for_geometry(
                &g.scattering,
                masking[g.incident_zenith],
                masking[g.scattered_zenith],
            );
            let start = point * width;
            for (offset, &(row, column)) in self.data.elements.iter().enumerate() {
                let i = start + offset;
                visit(
                    i,
                    (m[(row, column)] - self.data.values[i]) * self.data.inverse_sigma[i],
                );
            }
        }
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
        let mut total = 0.0;
        match self.robust {
            None => self.for_each_residual(&pbrdf, |_, r| total += r * r),
            Some(loss) => self.for_each_residual(&pbrdf, |_, r| total += loss.rho(r)),
        }
        total
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
            None => self.for_each_residual(&pbrdf, |i, r| out[i] = r),
            Some(loss) => self.for_each_residual(&pbrdf, |i, r| out[i] = loss.pseudo_residual(r)),
        }
        true
    }

    /// Plain normalized residuals r = (model − data)/σ at `values`, whatever the loss.
    pub fn normalized_residuals(&self, values: &ParameterValues) -> Option<Vec<f64>> {
        let pbrdf = self.model(values)?;
        let mut out = vec![0.0; self.observations()];
        self.for_each_residual(&pbrdf, |i, r| out[i] = r);
        Some(out)
    }

    /// The model's full Mueller matrix (sr⁻¹) at every point.
    pub fn model_muellers(&self, values: &ParameterValues) -> Option<Vec<Mueller>> {
        let pbrdf = self.model(values)?;
        Some(
            self.data
                .geometry
                .iter()
                .map(|g| {
                    let s = &g.scattering;
                    let masking = [
                        pbrdf.masking_without_table(s.cos_incident()),
                        pbrdf.masking_without_table(s.cos_scattered()),
                    ];
                    pbrdf.mueller_for_geometry(s, masking[0], masking[1])
                })
                .collect(),
        )
    }
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
