//! The joint least-squares problem of a spectral set (docs/design.md §1.9–1.10): one measurement
//! per wavelength, the geometry (σ, q) and the subsurface's d, n_sub, d_c shared by all (unless
//! asked per wavelength), and per wavelength either free n, k and the body reflectances (a table)
//! or the reflectances free with n, k from a Lorentz law whose parameters are shared.
//!
//! The search vector is laid out as [shared…, family₁(λ₁…λ_K), family₂(λ₁…λ_K), …]: the shared
//! coordinates (σ, q, then the law's) move every wavelength's residuals, a family's coordinate of
//! wavelength j moves only that wavelength's. So one residual evaluation with every wavelength's
//! member of a family shifted gives all K columns of that family at once, and a Jacobian costs
//! (shared + families) evaluations instead of (shared + K·families): 5 rather than 29 for nine
//! wavelengths of a table fit.

use super::super::levenberg_marquardt::{forward_step, LeastSquares};
use super::super::objective::Objective;
use super::super::parameters::{Parameter, ParameterValues};
use super::lorentz_start::{law_of, LAW_PER_OSCILLATOR};
use crate::optics::LorentzDispersion;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::ops::Range;

/// What n and k are at each wavelength.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum IndexModel {
    /// Free per wavelength.
    Table,
    /// From a law of this many oscillators: shared coordinates ε_∞, then
    /// [`LAW_PER_OSCILLATOR`] per oscillator, all in physical units.
    Lorentz(usize),
    /// n from Cauchy's normal dispersion n = A + B/λ² (shared coordinates A and B ≥ 0, B in
    /// µm²); k free per wavelength.
    Cauchy,
}

/// One wavelength's measurement and model family.
pub(crate) struct Block<'a> {
    pub objective: Objective<'a>,
    pub wavelength_um: f64,
    /// Its rows in the joint residual vector.
    pub rows: Range<usize>,
}

pub(crate) struct JointProblem<'a> {
    pub blocks: Vec<Block<'a>>,
    pub index_model: IndexModel,
    /// Shared model parameters (σ, q and the shared subsurface ones, where free), in canonical
    /// order.
    pub shared: Vec<Parameter>,
    /// Per-wavelength parameters (n, k, ρ_d, ρ_s of a table; the reflectances of a law), in
    /// canonical order.
    pub families: Vec<Parameter>,
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    pub observations: usize,
}

impl<'a> JointProblem<'a> {
    /// The problem over `blocks` (each with a model space whose free parameters are the shared
    /// ones plus the families) with the law's box, if any, given by `law_bounds`; `shared` says
    /// which parameters take one value for every wavelength.
    pub fn new(
        blocks: Vec<Block<'a>>,
        index_model: IndexModel,
        law_bounds: (Vec<f64>, Vec<f64>),
        shared: &dyn Fn(Parameter) -> bool,
    ) -> JointProblem<'a> {
        let space = blocks[0].objective.space();
        let is_shared = |p: &Parameter| shared(*p);
        let shared: Vec<Parameter> = space.free().iter().copied().filter(is_shared).collect();
        let families: Vec<Parameter> = space
            .free()
            .iter()
            .copied()
            .filter(|p| !is_shared(p))
            .collect();
        let position = |p: Parameter| space.free().iter().position(|&f| f == p).unwrap_or(0);
        let mut lower: Vec<f64> = shared.iter().map(|&p| space.lower()[position(p)]).collect();
        let mut upper: Vec<f64> = shared.iter().map(|&p| space.upper()[position(p)]).collect();
        lower.extend(law_bounds.0);
        upper.extend(law_bounds.1);
        for &p in &families {
            for block in &blocks {
                let space = block.objective.space();
                let i = space.free().iter().position(|&f| f == p).unwrap_or(0);
                lower.push(space.lower()[i]);
                upper.push(space.upper()[i]);
            }
        }
        let observations = blocks.last().map_or(0, |b| b.rows.end);
        JointProblem {
            blocks,
            index_model,
            shared,
            families,
            lower,
            upper,
            observations,
        }
    }

    /// Number of shared coordinates (model and law).
    pub fn shared_len(&self) -> usize {
        self.shared.len() + self.law_len()
    }

    fn law_len(&self) -> usize {
        match self.index_model {
            IndexModel::Table => 0,
            IndexModel::Lorentz(oscillators) => 1 + LAW_PER_OSCILLATOR * oscillators,
            IndexModel::Cauchy => 2,
        }
    }

    /// The law's coordinates of search vector `s`.
    pub fn law_coordinates<'s>(&self, s: &'s [f64]) -> &'s [f64] {
        &s[self.shared.len()..self.shared_len()]
    }

    /// Where `parameter`'s coordinate of wavelength `j` sits in the search vector, when it is a
    /// family's.
    pub fn family_coordinate(&self, parameter: Parameter, j: usize) -> Option<usize> {
        let f = self.families.iter().position(|&p| p == parameter)?;
        Some(self.family_index(f, j))
    }

    /// Where family `f`'s coordinate of wavelength `j` sits in the search vector.
    pub fn family_index(&self, f: usize, j: usize) -> usize {
        self.shared_len() + f * self.blocks.len() + j
    }

    /// The dispersion law of search vector `s` (physical coordinates), for a Lorentz problem.
    pub fn law(&self, s: &[f64]) -> Option<LorentzDispersion> {
        let IndexModel::Lorentz(_) = self.index_model else {
            return None;
        };
        Some(law_of(self.law_coordinates(s)))
    }

    /// The full parameter values of wavelength `j` at search vector `s`.
    pub fn block_values(&self, s: &[f64], j: usize) -> ParameterValues {
        let space = self.blocks[j].objective.space();
        let block_search: Vec<f64> = space
            .free()
            .iter()
            .map(|p| match self.shared.iter().position(|q| q == p) {
                Some(i) => s[i],
                None => {
                    let f = self.families.iter().position(|q| q == p).unwrap_or(0);
                    s[self.family_index(f, j)]
                }
            })
            .collect();
        let mut values = space.values(&block_search);
        let wavelength_um = self.blocks[j].wavelength_um;
        if let Some(law) = self.law(s) {
            let index = law.index(wavelength_um);
            values.set(Parameter::N, index.n);
            values.set(Parameter::K, index.k);
        }
        if let (IndexModel::Cauchy, &[a, b]) = (&self.index_model, self.law_coordinates(s)) {
            values.set(Parameter::N, cauchy_index(a, b, wavelength_um));
        }
        values
    }
}

/// Cauchy's normal dispersion n = A + B/λ² (λ in µm, B in µm²; docs/design.md §1.10).
pub(crate) fn cauchy_index(a: f64, b: f64, wavelength_um: f64) -> f64 {
    a + b / (wavelength_um * wavelength_um)
}

impl LeastSquares for JointProblem<'_> {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    /// Every wavelength's residuals, in parallel, in wavelength order.
    fn residuals(&self, s: &[f64]) -> Option<DVector<f64>> {
        let parts: Option<Vec<Vec<f64>>> = self
            .blocks
            .par_iter()
            .enumerate()
            .map(|(j, block)| {
                let mut r = vec![0.0; block.rows.len()];
                block
                    .objective
                    .residuals_at(&self.block_values(s, j), &mut r)
                    .then_some(r)
            })
            .collect();
        Some(DVector::from_iterator(
            self.observations,
            parts?.into_iter().flatten(),
        ))
    }
    /// Forward differences: one evaluation per shared coordinate (a full column) and one per
    /// family (every wavelength's member shifted at once, each column nonzero on its own rows).
    fn jacobian(&self, s: &[f64], r: &DVector<f64>) -> Option<DMatrix<f64>> {
        let shared = self.shared_len();
        let shifts: Vec<Vec<usize>> = (0..shared)
            .map(|i| vec![i])
            .chain((0..self.families.len()).map(|f| {
                (0..self.blocks.len())
                    .map(|j| self.family_index(f, j))
                    .collect()
            }))
            .collect();
        // Per evaluation: the (coordinate, step) pairs shifted and the change of the residuals.
        type Shifted = (Vec<(usize, f64)>, DVector<f64>);
        let evaluations: Option<Vec<Shifted>> = shifts
            .par_iter()
            .map(|coordinates| {
                let mut shifted = s.to_vec();
                let steps: Vec<(usize, f64)> = coordinates
                    .iter()
                    .map(|&c| (c, forward_step(s, c, &self.upper)))
                    .collect();
                for &(c, h) in &steps {
                    shifted[c] += h;
                }
                Some((steps, self.residuals(&shifted)? - r))
            })
            .collect();
        let mut jacobian = DMatrix::zeros(self.observations, s.len());
        for (steps, difference) in evaluations? {
            if let [(c, h)] = steps[..] {
                if c < shared {
                    jacobian.set_column(c, &(difference / h));
                    continue;
                }
            }
            for (&(c, h), block) in steps.iter().zip(&self.blocks) {
                for row in block.rows.clone() {
                    jacobian[(row, c)] = difference[row] / h;
                }
            }
        }
        Some(jacobian)
    }
    fn jacobian_evaluations(&self) -> u64 {
        (self.shared_len() + self.families.len()) as u64
    }
}
