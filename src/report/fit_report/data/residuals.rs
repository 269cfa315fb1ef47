//! The normalized residuals (data − model)/σ of a fit report, summarized for panels (g) and (h)
//! rather than kept: a dense scan has millions of them (24 bytes each as [`Residual`]s), while
//! the panels draw only their extreme, their histogram, mean and spread, and their density — or,
//! when they are few, each of them. The summary takes two passes over the rows (the second needs
//! the first's extreme and mean), re-evaluating the model rather than storing anything per
//! observation.

use super::points::{own_frame, residual_zenith};
use super::{ModelCurveSource, Reading, ReportError};
use crate::measure::MeasurementSet;
use crate::optics::Mueller;

/// One normalized residual (data − model)/σ, both in the measured row's own psps frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Residual {
    /// θ_r signed by hemisphere: + when the detector is on the forward (specular) half,
    /// 90° ≤ φ_r − φ_i ≤ 270°. Equals the point's signed zenith in the plane.
    pub forward_zenith: f64,
    pub element: usize,
    pub value: f64,
}

/// Most residuals panel (g) draws one by one (and the summary keeps); beyond it, it draws their
/// density as a 2-D histogram ([`DENSITY_X_DEG`] × [`DENSITY_Y_SIGMA`] cells), whose size does
/// not grow with the file.
pub const MAX_RESIDUAL_POINTS: usize = 20_000;
pub const DENSITY_X_DEG: f64 = 2.0;
pub const DENSITY_Y_SIGMA: f64 = 0.25;

/// Bins of the residual histogram of panel (h): 0.25σ wide over ±5σ.
pub const BIN_WIDTH: f64 = 0.25;
pub const HISTOGRAM_LIMIT: f64 = 5.0;

/// What panels (g) and (h) draw of the residuals of every measured element of every row, in
/// the order of the file and, within a row, of the Mueller index.
pub struct ResidualSummary {
    /// All residuals, finite or not.
    pub count: usize,
    /// Each residual when there are at most [`MAX_RESIDUAL_POINTS`], else none.
    pub each: Vec<Residual>,
    /// Panel (g)'s half-height: the largest finite |residual| with a 10 % margin, within 4…12σ.
    pub bound: f64,
    /// Residuals that are NaN or beyond ±`bound` (not drawn in (g)).
    pub hidden: usize,
    /// Panel (g)'s density over ±`bound`, when there are more than [`MAX_RESIDUAL_POINTS`].
    pub density: Option<ResidualDensity>,
    /// The finite residuals: how many, their histogram, mean and standard deviation (panel (h)).
    pub finite: usize,
    pub histogram: Histogram,
    pub mean: f64,
    pub standard_deviation: f64,
}

/// Counts per [`BIN_WIDTH`] bin over ±[`HISTOGRAM_LIMIT`], and how many fall outside.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    pub counts: Vec<usize>,
    pub outside: usize,
}

impl Histogram {
    pub fn empty() -> Histogram {
        let bins = (2.0 * HISTOGRAM_LIMIT / BIN_WIDTH).round() as usize;
        Histogram {
            counts: vec![0; bins],
            outside: 0,
        }
    }

    pub fn add(&mut self, value: f64) {
        let bin = ((value + HISTOGRAM_LIMIT) / BIN_WIDTH).floor();
        if bin >= 0.0 && (bin as usize) < self.counts.len() {
            self.counts[bin as usize] += 1;
        } else {
            self.outside += 1;
        }
    }
}

/// Counts of residuals within ±`bound` in cells of [`DENSITY_X_DEG`] × [`DENSITY_Y_SIGMA`]
/// over −90…90° × ±`bound`, one run of `rows` y bins per x bin.
#[derive(Clone, Debug, PartialEq)]
pub struct ResidualDensity {
    pub counts: Vec<usize>,
    pub rows: usize,
    bound: f64,
}

impl ResidualDensity {
    pub fn new(bound: f64) -> ResidualDensity {
        let columns = (180.0 / DENSITY_X_DEG).round() as usize;
        let rows = ((2.0 * bound / DENSITY_Y_SIGMA).ceil() as usize).max(1);
        ResidualDensity {
            counts: vec![0; columns * rows],
            rows,
            bound,
        }
    }

    pub fn add(&mut self, r: &Residual) {
        let (bound, rows) = (self.bound, self.rows);
        if !(r.value.abs() <= bound && r.forward_zenith.is_finite()) {
            return;
        }
        let columns = self.counts.len() / rows;
        let column = (((r.forward_zenith + 90.0) / DENSITY_X_DEG).floor().max(0.0) as usize)
            .min(columns - 1);
        let row = (((r.value + bound) / DENSITY_Y_SIGMA).floor().max(0.0) as usize).min(rows - 1);
        self.counts[column * rows + row] += 1;
    }
}

impl ResidualSummary {
    /// The residuals of every row of `set` (standard deviations `sigmas`, point-major) against
    /// the `chosen` model, summarized in two passes.
    pub fn new(
        set: &MeasurementSet,
        sigmas: &[f64],
        chosen: &ModelCurveSource,
    ) -> Result<ResidualSummary, ReportError> {
        let (mut count, mut finite) = (0, 0);
        let (mut each, mut histogram) = (Vec::new(), Histogram::empty());
        let (mut largest, mut sum) = (0.0, 0.0);
        for_each_residual(set, sigmas, chosen, |r| {
            count += 1;
            if count <= MAX_RESIDUAL_POINTS {
                each.push(r);
            }
            if r.value.is_finite() {
                finite += 1;
                sum += r.value;
                largest = f64::max(largest, r.value.abs());
                histogram.add(r.value);
            }
        })?;
        let bound = (largest * 1.1).clamp(4.0, 12.0);
        let mean = sum / finite as f64;
        let mut density = (count > MAX_RESIDUAL_POINTS).then(|| ResidualDensity::new(bound));
        let (mut hidden, mut squares) = (0, 0.0);
        let mut second = |r: &Residual| {
            if r.value.is_nan() || r.value.abs() > bound {
                hidden += 1;
            }
            if r.value.is_finite() {
                squares += (r.value - mean).powi(2);
            }
            if let Some(density) = density.as_mut() {
                density.add(r);
            }
        };
        if count > MAX_RESIDUAL_POINTS {
            each = Vec::new();
            for_each_residual(set, sigmas, chosen, |r| second(&r))?;
        } else {
            each.iter().for_each(second);
        }
        Ok(ResidualSummary {
            count,
            each,
            bound,
            hidden,
            density,
            finite,
            histogram,
            mean,
            standard_deviation: (squares / finite as f64).sqrt(),
        })
    }
}

/// Rows whose residuals one thread computes at a time ([`for_each_residual`]).
const ROWS_PER_BLOCK: usize = 2048;

/// Hands every normalized residual of `set` to `visit`, row by row in the order of the file,
/// within a row by Mueller index; the model is evaluated at the row's own geometry and both are
/// in the row's own frame, as the fit compared them. The rows are evaluated a block per thread
/// at a time, in parallel, and their residuals handed on in order: the same values in the same
/// order as one row after the other, holding a few blocks' residuals, not the file's.
pub(in crate::report::fit_report) fn for_each_residual(
    set: &MeasurementSet,
    sigmas: &[f64],
    chosen: &ModelCurveSource,
    mut visit: impl FnMut(Residual),
) -> Result<(), ReportError> {
    use rayon::prelude::*;
    let rows = set.points.len();
    let wave = ROWS_PER_BLOCK * rayon::current_num_threads();
    for start in (0..rows).step_by(wave) {
        let end = (start + wave).min(rows);
        let blocks: Vec<_> = (start..end)
            .step_by(ROWS_PER_BLOCK)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|first| {
                block_residuals(
                    set,
                    sigmas,
                    chosen,
                    first..(first + ROWS_PER_BLOCK).min(end),
                )
            })
            .collect();
        // The first refusal in file order, whichever thread met it first.
        for block in blocks {
            block?.into_iter().for_each(&mut visit);
        }
    }
    Ok(())
}

/// The normalized residuals of rows `rows` of `set`, in order.
fn block_residuals(
    set: &MeasurementSet,
    sigmas: &[f64],
    chosen: &ModelCurveSource,
    rows: std::ops::Range<usize>,
) -> Result<Vec<Residual>, ReportError> {
    let mut residuals = Vec::with_capacity(rows.len() * set.elements.len());
    for point in rows {
        let forward_zenith = residual_zenith(set.points.row(point));
        let (readings, model) = own_frame(set, sigmas, point, chosen)?;
        residuals.extend(normalized_residuals(&readings, &model, forward_zenith));
    }
    Ok(residuals)
}

/// (data − model)/σ for each measured element, in the frame both are given in.
fn normalized_residuals<'a>(
    readings: &'a [Option<Reading>; 16],
    model: &'a Mueller,
    forward_zenith: f64,
) -> impl Iterator<Item = Residual> + 'a {
    readings.iter().enumerate().filter_map(move |(element, r)| {
        r.map(|r| Residual {
            forward_zenith,
            element,
            value: (r.value - model[(element / 4, element % 4)]) / r.sigma,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::super::tests::{exact, material, set_of};
    use super::super::ReportData;
    use super::*;
    use crate::fit::observation_sigmas;

    #[test]
    fn residuals_are_data_minus_model_over_sigma() {
        let geometry = [(40.0, 0.0, 40.0, 180.0), (40.0, 0.0, 20.0, 0.0)];
        let exact_set = set_of(&geometry, exact, [None, None]);
        let data = ReportData::new(&material(false), &exact_set).unwrap();
        assert_eq!(data.residuals.count, 4);
        assert!(data.residuals.each.iter().all(|r| r.value.abs() < 1e-12));

        // Without u_ columns: σ(m00) = 3 % and σ(m10) = 1 % of the measured m00 (the fit's noise
        // model), so a reading 3 % high is 1/1.03 σ off.
        let shifted = set_of(
            &geometry,
            |m| [1.03 * m[(0, 0)], m[(1, 0)] - 0.02 * m[(0, 0)]],
            [None, None],
        );
        let data = ReportData::new(&material(false), &shifted).unwrap();
        let values: Vec<f64> = data.residuals.each.iter().map(|r| r.value).collect();
        let (up, down) = (1.0 / 1.03, -2.0 / 1.03);
        for (got, want) in values.iter().zip([up, down, up, down]) {
            assert!((got - want).abs() < 1e-9, "{values:?}");
        }
        // With them, the file's σ is used as is.
        let with_u = set_of(
            &geometry,
            |m| [m[(0, 0)] + 0.004, m[(1, 0)]],
            [Some(0.002), Some(1.0)],
        );
        let data = ReportData::new(&material(false), &with_u).unwrap();
        assert!((data.residuals.each[0].value - 2.0).abs() < 1e-9);
        assert_eq!(data.residuals.each[0].forward_zenith, 40.0);
        assert_eq!(data.residuals.each[2].forward_zenith, -20.0);
    }

    #[test]
    fn a_dense_summary_is_that_of_every_residual_kept() {
        // 10 001 rows of m00 and m10: more residuals than are kept, so the second pass evaluates
        // them anew; it must find what one pass over all of them in memory finds.
        let geometry: Vec<(f64, f64, f64, f64)> = (0..10_001)
            .map(|i| {
                let theta_i = 20.0 + (i % 7) as f64 * 5.0;
                (theta_i, 0.0, (i % 89) as f64, (i % 360) as f64)
            })
            .collect();
        let set = set_of(
            &geometry,
            |m| [1.03 * m[(0, 0)], m[(1, 0)] + 0.3 * m[(0, 0)].sqrt()],
            [None, None],
        );
        let material = material(false);
        let summary = ReportData::new(&material, &set).unwrap().residuals;
        let chosen = ModelCurveSource {
            label: String::new(),
            pbrdf: material.grey_model().unwrap().pbrdf().unwrap(),
        };
        let mut all = Vec::new();
        for_each_residual(&set, &observation_sigmas(&set).unwrap(), &chosen, |r| {
            all.push(r)
        })
        .unwrap();
        assert_eq!((summary.count, all.len()), (20_002, 20_002));
        assert!(summary.each.is_empty(), "too many to keep");

        let largest = all.iter().map(|r| r.value.abs()).fold(0.0, f64::max);
        let bound = (largest * 1.1).clamp(4.0, 12.0);
        assert_eq!(summary.bound, bound);
        let hidden = all.iter().filter(|r| r.value.abs() > bound).count();
        assert!(hidden > 0 && hidden < all.len(), "{hidden}");
        assert_eq!(summary.hidden, hidden);
        let mut density = ResidualDensity::new(bound);
        let mut histogram = Histogram::empty();
        for r in &all {
            density.add(r);
            histogram.add(r.value);
        }
        assert_eq!(summary.density, Some(density));
        assert_eq!(summary.histogram, histogram);
        let n = all.len() as f64;
        let mean = all.iter().map(|r| r.value).sum::<f64>() / n;
        let variance = all.iter().map(|r| (r.value - mean).powi(2)).sum::<f64>() / n;
        assert_eq!(summary.finite, all.len());
        assert_eq!(summary.mean, mean);
        assert_eq!(summary.standard_deviation, variance.sqrt());
    }

    #[test]
    fn histogram_bins_are_quarter_sigma_and_count_the_overflow() {
        let mut histogram = Histogram::empty();
        for v in [-5.0, -0.1, 0.0, 0.1, 0.26, 4.99, 5.0, -7.0, f64::NAN] {
            histogram.add(v);
        }
        let Histogram { counts, outside } = histogram;
        assert_eq!(counts.len(), 40);
        assert_eq!(counts[0], 1, "−5 opens the first bin");
        assert_eq!(
            (counts[19], counts[20], counts[21], counts[39]),
            (1, 2, 1, 1)
        );
        assert_eq!(outside, 3, "5.0, −7 and NaN");
        assert_eq!(counts.iter().sum::<usize>() + outside, 9);
    }

    #[test]
    fn residual_density_counts_cells_of_two_degrees_and_a_quarter_sigma() {
        let at = |forward_zenith, value| Residual {
            forward_zenith,
            element: 0,
            value,
        };
        let mut density = ResidualDensity::new(4.0);
        for r in [
            at(-90.0, -4.0),
            at(-89.0, -3.9),
            at(0.5, 0.1),
            at(90.0, 3.99),
            at(10.0, 4.5),
            at(10.0, f64::NAN),
        ] {
            density.add(&r);
        }
        let ResidualDensity { counts, rows, .. } = density;
        assert_eq!((counts.len(), rows), (90 * 32, 32));
        assert_eq!(counts[0], 2, "the first cell holds both corner points");
        assert_eq!(counts[45 * rows + 16], 1, "0.5°, +0.1σ");
        assert_eq!(
            counts[89 * rows + 31],
            1,
            "the top edge closes the last cell"
        );
        assert_eq!(
            counts.iter().sum::<usize>(),
            4,
            "beyond the bound or NaN: not counted"
        );
    }
}
