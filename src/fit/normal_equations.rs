//! The normal equations (JᵀJ, Jᵀr) of one measurement's objective, summed block by block of
//! points so that the Jacobian J (observations × coordinates, 8 B each: 0.5 KB a row of a
//! 9-element file with 7 free parameters) is never held whole: the working set is a few blocks
//! of [`CHUNK_POINTS`] points, whatever the rows.
//!
//! Each entry is summed in the order of nalgebra's dot product of two columns (eight lanes by
//! observation index mod 8, combined as (l0 + l4) + (l1 + l5) + (l2 + l6) + (l3 + l7), then the
//! last len mod 8 products one by one), which is what the fit used when it held the columns, so
//! the fitted parameters are bit-identical to those of that implementation.

use super::levenberg_marquardt::{forward_step, LeastSquares};
use super::objective::{Objective, PreparedModel, CHUNK_POINTS};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// Lanes of nalgebra's unrolled dot product.
const LANES: usize = 8;
/// Blocks of points whose Jacobian columns are evaluated in one parallel pass before they are
/// summed, in order: enough tasks for the threads, a few MB of columns.
const BLOCKS_PER_PASS: usize = 4;

/// A measurement's objective as the Levenberg–Marquardt stage sees it: its residuals, and its
/// normal equations summed block by block.
impl LeastSquares for Objective<'_> {
    fn lower(&self) -> &[f64] {
        self.space().lower()
    }
    fn upper(&self) -> &[f64] {
        self.space().upper()
    }
    fn residual_count(&self) -> usize {
        self.observations()
    }
    fn residuals_into(&self, s: &[f64], out: &mut DVector<f64>) -> bool {
        self.residuals_at(&self.space().values(s), out.as_mut_slice())
    }
    /// Block by block of points, never holding J ([`normal_equations`]).
    fn normal_equations(
        &self,
        s: &[f64],
        r: &DVector<f64>,
    ) -> Option<(DMatrix<f64>, DVector<f64>)> {
        normal_equations(self, s, r)
    }
}

/// (JᵀJ, Jᵀr) at search coordinates `s` of `objective`, whose residuals there are `r`, J by
/// forward differences (one model evaluation per coordinate); `None` when a shifted model is
/// invalid.
pub(crate) fn normal_equations(
    objective: &Objective,
    s: &[f64],
    r: &DVector<f64>,
) -> Option<(DMatrix<f64>, DVector<f64>)> {
    let upper = objective.space().upper();
    let steps: Vec<f64> = (0..s.len()).map(|j| forward_step(s, j, upper)).collect();
    let models = (0..s.len())
        .into_par_iter()
        .map(|j| {
            let mut shifted = s.to_vec();
            shifted[j] += steps[j];
            objective.prepared_model(&shifted)
        })
        .collect::<Option<Vec<PreparedModel>>>()?;
    let width = objective.data().element_count();
    let points = objective.data().points();
    let blocks = points.div_ceil(CHUNK_POINTS);
    let mut sums = LaneSums::new(s.len(), r.len());
    for pass in (0..blocks).step_by(BLOCKS_PER_PASS) {
        let pass_blocks = pass..(pass + BLOCKS_PER_PASS).min(blocks);
        let tasks: Vec<(usize, usize)> = pass_blocks
            .clone()
            .flat_map(|b| (0..s.len()).map(move |j| (b, j)))
            .collect();
        let columns: Vec<Vec<f64>> = tasks
            .into_par_iter()
            .map(|(b, j)| {
                let first = b * CHUNK_POINTS;
                let start = first * width;
                let end = (first + CHUNK_POINTS).min(points) * width;
                let mut column = vec![0.0; end - start];
                objective.block_residuals(&models[j], first, &mut column);
                for (c, &r0) in column.iter_mut().zip(&r.as_slice()[start..end]) {
                    *c = (*c - r0) / steps[j];
                }
                column
            })
            .collect();
        let start = pass_blocks.start * CHUNK_POINTS * width;
        sums.add(start, &columns, s.len(), r.as_slice());
    }
    Some(sums.finish())
}

/// The running sum of one entry: column `left` times column `right` (or r).
struct EntrySum {
    left: usize,
    /// `None`: the entry of Jᵀr.
    right: Option<usize>,
    lanes: [f64; LANES],
    /// The products of the last observations (fewer than 8), in order.
    tail: Vec<f64>,
}

impl EntrySum {
    /// nalgebra's combination of the lanes, then the tail.
    fn total(&self) -> f64 {
        let l = &self.lanes;
        let mut sum = 0.0;
        sum += l[0] + l[4];
        sum += l[1] + l[5];
        sum += l[2] + l[6];
        sum += l[3] + l[7];
        for product in &self.tail {
            sum += product;
        }
        sum
    }
}

/// Running lane sums of every entry of JᵀJ (p ≤ q, row by row) and then of Jᵀr.
struct LaneSums {
    coordinates: usize,
    /// Observations summed in lanes (the rest, fewer than 8, are added one by one).
    in_lanes: usize,
    entries: Vec<EntrySum>,
}

impl LaneSums {
    fn new(n: usize, observations: usize) -> LaneSums {
        let entry = |left, right| EntrySum {
            left,
            right,
            lanes: [0.0; LANES],
            tail: Vec::new(),
        };
        let products = (0..n).flat_map(|p| (p..n).map(move |q| (p, Some(q))));
        let gradient = (0..n).map(|p| (p, None));
        LaneSums {
            coordinates: n,
            in_lanes: observations - observations % LANES,
            entries: products.chain(gradient).map(|(p, q)| entry(p, q)).collect(),
        }
    }

    /// Adds the products of a pass's columns (`columns[block · n + j]`, blocks in order), whose
    /// first observation is `start` (a multiple of 8), and of `r`.
    fn add(&mut self, start: usize, columns: &[Vec<f64>], n: usize, r: &[f64]) {
        let in_lanes = self.in_lanes;
        self.entries.par_iter_mut().for_each(|entry| {
            let mut offset = start;
            for block in columns.chunks(n) {
                let left = &block[entry.left];
                let right = match entry.right {
                    Some(q) => &block[q][..],
                    None => &r[offset..offset + left.len()],
                };
                let lane_end = in_lanes.saturating_sub(offset).min(left.len());
                let pairs = left[..lane_end].chunks_exact(LANES);
                for (a, b) in pairs.zip(right[..lane_end].chunks_exact(LANES)) {
                    for k in 0..LANES {
                        entry.lanes[k] += a[k] * b[k];
                    }
                }
                let rest = left[lane_end..].iter().zip(&right[lane_end..]);
                entry.tail.extend(rest.map(|(a, b)| a * b));
                offset += left.len();
            }
        });
    }

    /// JᵀJ (symmetric) and Jᵀr.
    fn finish(self) -> (DMatrix<f64>, DVector<f64>) {
        let n = self.coordinates;
        let mut a = DMatrix::zeros(n, n);
        let mut g = DVector::zeros(n);
        for entry in &self.entries {
            let total = entry.total();
            match entry.right {
                Some(q) => {
                    a[(entry.left, q)] = total;
                    a[(q, entry.left)] = total;
                }
                None => g[entry.left] = total,
            }
        }
        (a, g)
    }
}
