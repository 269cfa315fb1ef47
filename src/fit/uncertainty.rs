//! Parameter uncertainties at the optimum from the Jacobian of the normalized residuals
//! (linearized least squares): C = s² (JᵀJ)⁻¹ in physical units, with s² the reduced χ², so that
//! the errors stay honest when the stated measurement uncertainties are too small or too large.
//! With a robust loss the same plain-least-squares covariance is evaluated at the robust
//! optimum; outliers inflate the reduced χ² and so make the errors conservative.
//!
//! A parameter is *undetermined* when the data carry no information on it (its Jacobian column
//! vanishes, e.g. k = 0 without circular elements, or JᵀJ is singular along it), when it is
//! almost perfectly correlated with another one (|ρ| > 0.999), or when its 1-σ error exceeds
//! both half its value and 1 % of its search interval. The second condition keeps a value that
//! is consistent with zero but tightly bounded (ρ_d = 0.00001 ± 0.00002) determined.

use super::objective::{Objective, CHUNK_POINTS};
use super::parameters::{value_per_coordinate, ParameterValues};
use crate::material::ConfidenceBound;
use crate::pbrdf::Parameter;
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::ops::Range;

/// Correlation beyond which two parameters count as not separately determined.
pub const DEGENERATE_CORRELATION: f64 = 0.999;
/// Relative 1-σ error beyond which a parameter counts as undetermined (if its error also exceeds
/// [`UNDETERMINED_RANGE_FRACTION`] of its search interval).
pub const UNDETERMINED_RELATIVE_ERROR: f64 = 0.5;
/// See [`UNDETERMINED_RELATIVE_ERROR`].
pub const UNDETERMINED_RANGE_FRACTION: f64 = 0.01;
/// A search coordinate within this fraction of its box width from a bound rests on it (the
/// sine-mapped Nelder–Mead approaches a bound without reaching it exactly).
const AT_BOUND: f64 = 1e-6;
/// Relative eigenvalue of the scaled JᵀJ below which a direction counts as unconstrained.
const SINGULAR: f64 = 1e-12;
/// Inner dimension up to which nalgebra multiplies matrices itself instead of through
/// matrixmultiply (its `SMALL_DIM`).
const THIN_PRODUCT: usize = 5;

/// 1-σ errors and correlations of the free parameters, in [`Uncertainty::parameters`] order.
#[derive(Clone, Debug, PartialEq)]
pub struct Uncertainty {
    pub parameters: Vec<Parameter>,
    /// 1-σ errors in physical units (∞ where undetermined by the data).
    pub errors: Vec<f64>,
    pub correlation: Vec<Vec<f64>>,
    pub undetermined: Vec<Parameter>,
    /// Parameters resting on a bound of their search interval.
    pub at_bound: Vec<Parameter>,
    /// One-sided profile-likelihood bounds of each undetermined parameter (`super::profile`).
    pub profile_bounds: Vec<(Parameter, ConfidenceBound)>,
}

/// The information matrix JᵀJ of the plain normalized residuals with respect to the physical
/// free parameters, J by central differences in search coordinates (one-sided at a bound) and the
/// chain rule; `None` when a shifted model is invalid.
///
/// J (observations × parameters, 8 B each) is never held whole: it is built a block of
/// [`CHUNK_POINTS`] points at a time and each block's JᵀJ added with nalgebra's `gemm`. Every
/// block but the last starts on a multiple of 256 observations, the depth by which
/// matrixmultiply (behind nalgebra's product of large matrices) splits the inner dimension and
/// accumulates into the result, so the sum is bit-identical to `Jᵀ * J` of the whole J.
fn information_matrix(objective: &Objective, search: &[f64]) -> Option<DMatrix<f64>> {
    let space = objective.space();
    let n = search.len();
    let shifted_models = (0..n)
        .into_par_iter()
        .map(|j| {
            let h = 1e-5 * search[j].abs().max(1.0);
            let lo = (search[j] - h).max(space.lower()[j]);
            let hi = (search[j] + h).min(space.upper()[j]);
            let at = |coordinate: f64| {
                let mut shifted = search.to_vec();
                shifted[j] = coordinate;
                objective.prepared_model(&shifted)
            };
            let above = at(hi)?;
            let below = at(lo)?;
            // d r/d value = (d r/d coordinate) / (d value/d coordinate), at the central point.
            let per_coordinate = value_per_coordinate(space.free()[j], search[j]);
            Some((above, below, hi - lo, per_coordinate))
        })
        .collect::<Option<Vec<_>>>()?;
    let width = objective.data().element_count();
    let mut information = DMatrix::zeros(n, n);
    for (pass, points) in jacobian_blocks(objective.data().points(), width)
        .into_iter()
        .enumerate()
    {
        let rows = points.len() * width;
        let columns: Vec<Vec<f64>> = shifted_models
            .par_iter()
            .map(|(above, below, step, per_coordinate)| {
                let mut column = vec![0.0; rows];
                let mut lower = vec![0.0; rows];
                objective.block_normalized_residuals(above, points.start, &mut column);
                objective.block_normalized_residuals(below, points.start, &mut lower);
                for (c, b) in column.iter_mut().zip(&lower) {
                    *c = ((*c - b) / step) / per_coordinate;
                }
                column
            })
            .collect();
        let block = DMatrix::from_iterator(rows, n, columns.into_iter().flatten());
        add_information(&mut information, &block, pass == 0);
    }
    Some(information)
}

/// Adds JᵀJ of a block of J's rows to `information` (overwritten by the `first` block's).
fn add_information(information: &mut DMatrix<f64>, block: &DMatrix<f64>, first: bool) {
    let beta = if first { 0.0 } else { 1.0 };
    information.gemm(1.0, &block.transpose(), block, beta);
}

/// The point ranges of [`information_matrix`]'s blocks: [`CHUNK_POINTS`] points each (a
/// multiple of 256 observations), the last one longer when the rest would hold 5 observations
/// or fewer: nalgebra multiplies such a thin block by another rule (column by column), which
/// would change the sum's last bits.
fn jacobian_blocks(points: usize, width: usize) -> Vec<Range<usize>> {
    let mut blocks: Vec<Range<usize>> = (0..points)
        .step_by(CHUNK_POINTS)
        .map(|first| first..(first + CHUNK_POINTS).min(points))
        .collect();
    if blocks.len() > 1 && blocks.last().map_or(0, |b| b.len() * width) <= THIN_PRODUCT {
        let last = blocks.pop().expect("more than one block");
        blocks.last_mut().expect("more than one block").end = last.end;
    }
    blocks
}

/// Uncertainties of the free parameters at the optimum `search` (search coordinates), with
/// `reduced_chi2` scaling the covariance.
pub(crate) fn estimate(objective: &Objective, search: &[f64], reduced_chi2: f64) -> Uncertainty {
    let space = objective.space();
    let parameters = space.free().to_vec();
    let dimension = parameters.len();
    let values: ParameterValues = space.values(search);
    let at_bound: Vec<Parameter> = parameters
        .iter()
        .enumerate()
        .filter(|&(i, _)| {
            let margin = AT_BOUND * (space.upper()[i] - space.lower()[i]);
            search[i] <= space.lower()[i] + margin || search[i] >= space.upper()[i] - margin
        })
        .map(|(_, &p)| p)
        .collect();
    let mut uncertainty = Uncertainty {
        parameters: parameters.clone(),
        errors: vec![f64::INFINITY; dimension],
        correlation: identity(dimension),
        undetermined: Vec::new(),
        at_bound,
        profile_bounds: Vec::new(),
    };
    let Some(information) = information_matrix(objective, search) else {
        uncertainty.undetermined = parameters;
        return uncertainty;
    };
    (uncertainty.errors, uncertainty.correlation, _) =
        linearized_errors(&information, reduced_chi2);
    for (i, &parameter) in parameters.iter().enumerate() {
        let degenerate = uncertainty.correlation[i]
            .iter()
            .enumerate()
            .any(|(j, rho)| j != i && rho.abs() > DEGENERATE_CORRELATION);
        let error = uncertainty.errors[i];
        let interval = space.bounds().get(parameter);
        let vague = error > UNDETERMINED_RELATIVE_ERROR * values.get(parameter).abs()
            && error > UNDETERMINED_RANGE_FRACTION * (interval.upper - interval.lower);
        if !uncertainty.errors[i].is_finite() || degenerate || vague {
            uncertainty.undetermined.push(parameter);
        }
    }
    uncertainty
}

/// 1-σ errors s √(C_ii) and correlations of C = (JᵀJ)⁺ from the information matrix JᵀJ (in the
/// parameters' own units), s² the reduced χ²; and which parameters load on a direction the data
/// do not constrain (error ∞, correlations 0 off the diagonal).
pub(crate) fn linearized_errors(
    information: &DMatrix<f64>,
    reduced_chi2: f64,
) -> (Vec<f64>, Vec<Vec<f64>>, Vec<bool>) {
    let dimension = information.nrows();
    let mut errors = vec![f64::INFINITY; dimension];
    let mut correlation = identity(dimension);
    // Scale to unit diagonal so that the singularity test does not depend on units.
    let scale: Vec<f64> = (0..dimension)
        .map(|i| {
            let d = information[(i, i)];
            if d > 0.0 && d.is_finite() {
                1.0 / d.sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let scaled = DMatrix::from_fn(dimension, dimension, |i, j| {
        information[(i, j)] * scale[i] * scale[j]
    });
    let eigen = scaled.symmetric_eigen();
    let largest = eigen.eigenvalues.max();
    // Pseudo-inverse over the constrained directions; a parameter that loads on an
    // unconstrained direction has no finite error.
    let mut inverse = DMatrix::zeros(dimension, dimension);
    let mut unconstrained = vec![false; dimension];
    for (k, &lambda) in eigen.eigenvalues.iter().enumerate() {
        let vector = eigen.eigenvectors.column(k);
        if lambda > SINGULAR * largest {
            inverse += vector * vector.transpose() / lambda;
        } else {
            for i in 0..dimension {
                if vector[i].abs() > 1e-3 {
                    unconstrained[i] = true;
                }
            }
        }
    }
    let variance_scale = if reduced_chi2.is_finite() && reduced_chi2 > 0.0 {
        reduced_chi2
    } else {
        1.0
    };
    for i in 0..dimension {
        if scale[i] == 0.0 {
            unconstrained[i] = true;
        }
        if unconstrained[i] {
            continue;
        }
        errors[i] = (inverse[(i, i)] * variance_scale).sqrt() * scale[i];
        for j in 0..dimension {
            if i != j && !unconstrained[j] && scale[j] != 0.0 {
                let rho = inverse[(i, j)] / (inverse[(i, i)] * inverse[(j, j)]).sqrt();
                correlation[i][j] = rho.clamp(-1.0, 1.0);
            }
        }
    }
    (errors, correlation, unconstrained)
}

fn identity(n: usize) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocked sum is `Jᵀ * J` of the whole J to the last bit, through matrixmultiply (more
    /// than 5 parameters) and through nalgebra's own product (5 or fewer), with a thin tail of
    /// 3 observations folded into the last block.
    #[test]
    fn blocked_information_is_the_whole_product_bit_for_bit() {
        let width = 3;
        let points = 3 * CHUNK_POINTS + 1;
        let blocks = jacobian_blocks(points, width);
        assert_eq!(blocks.len(), 3);
        assert_eq!(blocks[2], 2 * CHUNK_POINTS..points);
        for parameters in [7, 4] {
            let rows = points * width;
            // Entries of mixed sign and magnitude, so that the summation order shows.
            let jacobian = DMatrix::from_fn(rows, parameters, |i, j| {
                ((i * 31 + j * 17) as f64 * 0.37).sin() * 10f64.powi((i % 7) as i32 - 3)
            });
            let whole = jacobian.transpose() * &jacobian;
            let mut blocked = DMatrix::zeros(parameters, parameters);
            for (pass, range) in blocks.iter().enumerate() {
                let block = jacobian
                    .rows(range.start * width, range.len() * width)
                    .into_owned();
                add_information(&mut blocked, &block, pass == 0);
            }
            let bits = |m: &DMatrix<f64>| m.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&blocked), bits(&whole), "{parameters} parameters");
        }
    }
}
