//! A Lorentz law to start the joint fit from (docs/design.md §1.9): fitted to the permittivities
//! ε_j = (n_j + i k_j)² of the table fit, where the data are already condensed to one complex
//! number per wavelength. Each oscillator starts at a peak of Im ε (its resonance, with the
//! strength and width that peak implies); a few ε_∞ are tried; a small Levenberg–Marquardt fit of
//! Re ε and Im ε then gives the start.

use super::super::levenberg_marquardt::{
    forward_step, levenberg_marquardt, LeastSquares, LevenbergMarquardtSettings,
};
use crate::optics::{LorentzDispersion, LorentzOscillator};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// Lorentz law coordinates per oscillator: resonance λ_j, strength Δε_j, width w_j (µm).
pub(crate) const LAW_PER_OSCILLATOR: usize = 3;

/// The box of the law's coordinates (ε_∞, then resonance, strength, width per oscillator) for
/// tables over `first..=last` µm: resonances within half the range beyond its ends.
pub(crate) fn law_bounds(oscillators: usize, first: f64, last: f64) -> (Vec<f64>, Vec<f64>) {
    let span = last - first;
    let mut lower = vec![1.0];
    let mut upper = vec![30.0];
    for _ in 0..oscillators {
        lower.extend([(first - 0.5 * span).max(0.1), 1e-6, 1e-4]);
        upper.extend([last + 0.5 * span, 100.0, 10.0 * span.max(1.0)]);
    }
    (lower, upper)
}

/// The law's coordinates (in [`law_bounds`] order) fitted to the permittivities `eps` at
/// `wavelengths` (µm, ascending).
pub(crate) fn lorentz_start(
    oscillators: usize,
    wavelengths: &[f64],
    eps: &[Complex64],
) -> Vec<f64> {
    let (first, last) = (wavelengths[0], wavelengths[wavelengths.len() - 1]);
    let (lower, upper) = law_bounds(oscillators, first, last);
    let peaks = peaks_of_absorption(oscillators, wavelengths, eps);
    let problem = PermittivityFit {
        wavelengths,
        eps,
        lower,
        upper,
    };
    let settings = LevenbergMarquardtSettings::default();
    [1.5, 2.5, 4.0]
        .into_iter()
        .map(|eps_inf| {
            let mut start = vec![eps_inf];
            for &(resonance, strength, width) in &peaks {
                start.extend([resonance, strength, width]);
            }
            let (best, _) = levenberg_marquardt(&problem, &start, &settings);
            let cost = problem
                .residuals(&best)
                .map_or(f64::INFINITY, |r| r.norm_squared());
            (cost, best)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, best)| best)
        .unwrap_or_default()
}

/// (resonance, strength, width) for each oscillator from the largest local maxima of Im ε: at a
/// Lorentz resonance Im ε = Δε λ₀/w, and its half-maximum width in λ is about w.
fn peaks_of_absorption(
    oscillators: usize,
    wavelengths: &[f64],
    eps: &[Complex64],
) -> Vec<(f64, f64, f64)> {
    let count = wavelengths.len();
    let mut maxima: Vec<usize> = (0..count)
        .filter(|&i| {
            let left = i == 0 || eps[i].im >= eps[i - 1].im;
            let right = i + 1 == count || eps[i].im >= eps[i + 1].im;
            left && right
        })
        .collect();
    maxima.sort_by(|&a, &b| eps[b].im.total_cmp(&eps[a].im));
    let span = wavelengths[count - 1] - wavelengths[0];
    (0..oscillators)
        .map(|o| match maxima.get(o) {
            Some(&i) => {
                let half = 0.5 * eps[i].im;
                let below = (0..i).rev().find(|&m| eps[m].im < half);
                let above = (i + 1..count).find(|&m| eps[m].im < half);
                let width = match (below, above) {
                    (Some(b), Some(a)) => wavelengths[a] - wavelengths[b],
                    (Some(b), None) => 2.0 * (wavelengths[i] - wavelengths[b]),
                    (None, Some(a)) => 2.0 * (wavelengths[a] - wavelengths[i]),
                    (None, None) => 0.2 * span,
                }
                .max(1e-3);
                let strength = (eps[i].im.max(1e-6) * width / wavelengths[i]).max(1e-6);
                (wavelengths[i], strength, width)
            }
            // More oscillators than peaks: weak ones spread over the range.
            None => (
                wavelengths[0] + span * (o as f64 + 0.5) / oscillators as f64,
                0.01,
                0.1 * span.max(0.1),
            ),
        })
        .collect()
}

/// Re ε and Im ε of the law minus the table's, at each wavelength.
struct PermittivityFit<'a> {
    wavelengths: &'a [f64],
    eps: &'a [Complex64],
    lower: Vec<f64>,
    upper: Vec<f64>,
}

impl LeastSquares for PermittivityFit<'_> {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn residual_count(&self) -> usize {
        2 * self.wavelengths.len()
    }
    fn residuals_into(&self, s: &[f64], out: &mut DVector<f64>) -> bool {
        let law = law_of(s);
        for ((&w, e), pair) in self
            .wavelengths
            .iter()
            .zip(self.eps)
            .zip(out.as_mut_slice().chunks_exact_mut(2))
        {
            let d = law.permittivity(w) - e;
            pair.copy_from_slice(&[d.re, d.im]);
        }
        out.iter().all(|x| x.is_finite())
    }
    /// From J by forward differences (a few columns of 2 × wavelengths rows).
    fn normal_equations(
        &self,
        s: &[f64],
        r: &DVector<f64>,
    ) -> Option<(DMatrix<f64>, DVector<f64>)> {
        let columns: Option<Vec<DVector<f64>>> = (0..s.len())
            .map(|j| {
                let mut shifted = s.to_vec();
                let h = forward_step(s, j, &self.upper);
                shifted[j] += h;
                self.residuals(&shifted).map(|rh| (rh - r) / h)
            })
            .collect();
        let jacobian = DMatrix::from_columns(&columns?);
        Some((jacobian.tr_mul(&jacobian), jacobian.tr_mul(r)))
    }
}

/// The law of coordinates (ε_∞, then resonance, strength, width per oscillator).
pub(crate) fn law_of(s: &[f64]) -> LorentzDispersion {
    LorentzDispersion {
        eps_inf: s[0],
        oscillators: s[1..]
            .chunks_exact(LAW_PER_OSCILLATOR)
            .map(|c| LorentzOscillator {
                resonance_um: c[0],
                strength: c[1],
                damping_um: c[2],
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// From exact permittivities of a one-oscillator law the start is that law.
    #[test]
    fn an_exact_law_is_found_from_its_permittivities() {
        let truth = law_of(&[2.1, 9.3, 0.8, 0.744]);
        let wavelengths = [8.0, 8.5, 9.0, 9.5, 10.0, 10.6, 11.5, 12.5, 14.0];
        let eps: Vec<Complex64> = wavelengths.iter().map(|&w| truth.permittivity(w)).collect();
        let start = lorentz_start(1, &wavelengths, &eps);
        for (got, want) in start.iter().zip([2.1, 9.3, 0.8, 0.744]) {
            assert!((got / want - 1.0).abs() < 1e-6, "{start:?}");
        }
    }
}
