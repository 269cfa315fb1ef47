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
use super::super::parameters::ParameterValues;
use super::lorentz_start::{law_of, LAW_PER_OSCILLATOR};
use crate::optics::LorentzDispersion;
use crate::pbrdf::Parameter;
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
    fn residual_count(&self) -> usize {
        self.observations
    }
    /// Every wavelength's residuals, in parallel, each written into its rows.
    fn residuals_into(&self, s: &[f64], out: &mut DVector<f64>) -> bool {
        let mut parts = Vec::with_capacity(self.blocks.len());
        let mut rest = out.as_mut_slice();
        for block in &self.blocks {
            let (part, tail) = rest.split_at_mut(block.rows.len());
            parts.push(part);
            rest = tail;
        }
        parts
            .into_par_iter()
            .enumerate()
            .map(|(j, part)| {
                self.blocks[j]
                    .objective
                    .residuals_at(&self.block_values(s, j), part)
            })
            .reduce(|| true, |a, b| a && b)
    }
    /// J by forward differences, one evaluation per shared coordinate (a full column) and one
    /// per family (every wavelength's member shifted at once, each column nonzero on its own
    /// rows), but never assembled: J has observations × coordinates entries and both grow with
    /// the wavelengths (2000 wavelengths of 51 rows would need 78 GB). A family's column of
    /// wavelength j is zero off j's rows, so JᵀJ and Jᵀr are summed wavelength by wavelength
    /// from its (shared + families) local columns, in memory and time linear in the residuals;
    /// the entries between two wavelengths' own coordinates are 0.
    fn normal_equations(
        &self,
        s: &[f64],
        r: &DVector<f64>,
    ) -> Option<(DMatrix<f64>, DVector<f64>)> {
        let evaluations = self.shifted_residual_changes(s, r)?;
        let contributions: Vec<_> = (0..self.blocks.len())
            .into_par_iter()
            .map(|j| self.block_normal_equations(j, &evaluations, r))
            .collect();
        let mut a = DMatrix::zeros(s.len(), s.len());
        let mut g = DVector::zeros(s.len());
        for (coordinates, local_a, local_g) in contributions {
            for (p, &cp) in coordinates.iter().enumerate() {
                g[cp] += local_g[p];
                for (q, &cq) in coordinates.iter().enumerate() {
                    a[(cp, cq)] += local_a[(p, q)];
                }
            }
        }
        Some((a, g))
    }
    fn jacobian_evaluations(&self) -> u64 {
        (self.shared_len() + self.families.len()) as u64
    }
}

/// The coordinates shifted by one forward-difference evaluation, each with its step, and the
/// change of the residuals it caused.
type Shifted = (Vec<(usize, f64)>, DVector<f64>);

impl JointProblem<'_> {
    /// The forward-difference evaluations of J: the shared coordinates one at a time (in
    /// order), then each family with every wavelength's member shifted at once.
    fn shifted_residual_changes(&self, s: &[f64], r: &DVector<f64>) -> Option<Vec<Shifted>> {
        let shifts: Vec<Vec<usize>> = (0..self.shared_len())
            .map(|i| vec![i])
            .chain((0..self.families.len()).map(|f| {
                (0..self.blocks.len())
                    .map(|j| self.family_index(f, j))
                    .collect()
            }))
            .collect();
        shifts
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
                let mut change = DVector::zeros(self.observations);
                if !self.residuals_into(&shifted, &mut change) {
                    return None;
                }
                change -= r;
                Some((steps, change))
            })
            .collect()
    }

    /// Wavelength `j`'s share of the normal equations: the coordinates its rows depend on (the
    /// shared ones and its own member of each family), and the products of their columns on its
    /// rows with each other and with its residuals.
    fn block_normal_equations(
        &self,
        j: usize,
        evaluations: &[Shifted],
        r: &DVector<f64>,
    ) -> (Vec<usize>, DMatrix<f64>, DVector<f64>) {
        let rows = self.blocks[j].rows.clone();
        let shared = self.shared_len();
        let (coordinates, columns): (Vec<usize>, Vec<DVector<f64>>) = evaluations
            .iter()
            .enumerate()
            .map(|(e, (steps, difference))| {
                let (c, h) = if e < shared { steps[0] } else { steps[j] };
                (c, difference.rows(rows.start, rows.len()) / h)
            })
            .unzip();
        let local_r = r.rows(rows.start, rows.len());
        let a = DMatrix::from_fn(columns.len(), columns.len(), |p, q| {
            columns[p].dot(&columns[q])
        });
        let g = DVector::from_fn(columns.len(), |p, _| columns[p].dot(&local_r));
        (coordinates, a, g)
    }
}
