//! The visible-slope sampler's root finding: a bracketed Halley iteration on an increasing CDF,
//! and tables of its solutions on a grid that give each inversion a start close to its root.

use super::{START_COLUMNS, START_ROWS};

/// Solutions on a (w, u) ∈ [0, 1]² grid, interpolated bilinearly.
#[derive(Clone, Debug)]
pub(super) struct StartTable {
    values: Vec<f64>,
}

impl StartTable {
    pub(super) fn new(root: impl Fn(f64, f64) -> f64) -> StartTable {
        let values = (0..=START_ROWS)
            .flat_map(|r| (0..=START_COLUMNS).map(move |c| (r, c)))
            .map(|(r, c)| {
                root(
                    r as f64 / START_ROWS as f64,
                    c as f64 / START_COLUMNS as f64,
                )
            })
            .collect();
        StartTable { values }
    }

    /// The start at (w, u); `None` in the first column of cells, where the root runs off to the
    /// bottom of the support (−∞ for the Gaussian) and a line between nodes is no guide.
    pub(super) fn at(&self, w: f64, u: f64) -> Option<f64> {
        if u * (START_COLUMNS as f64) < 1.0 {
            return None;
        }
        let y = (w * START_ROWS as f64).clamp(0.0, START_ROWS as f64);
        let r = (y as usize).min(START_ROWS - 1);
        let t = y - r as f64;
        let row = |r: usize| &self.values[r * (START_COLUMNS + 1)..(r + 1) * (START_COLUMNS + 1)];
        Some((1.0 - t) * interpolate(row(r), u) + t * interpolate(row(r + 1), u))
    }
}

/// Linear interpolation in a table of values at u = j/N, j = 0..=N.
pub(super) fn interpolate(values: &[f64], u: f64) -> f64 {
    let n = values.len() - 1;
    let x = (u * n as f64).clamp(0.0, n as f64);
    let j = (x as usize).min(n - 1);
    let t = x - j as f64;
    (1.0 - t) * values[j] + t * values[j + 1]
}

/// How close (relative to the solver's length scale) a Halley step's start must be for the step's
/// result to be taken without another evaluation.
const ONE_STEP_REACH: f64 = 1e-4;

/// The root of an increasing f on [lo, hi] (f(lo) ≤ 0 ≤ f(hi)), from `start`: Halley steps
/// (cubic convergence; `f` returns the value and its first two derivatives) kept inside the
/// shrinking bracket, a bisection whenever a step would leave it. From a tabulated start within
/// ~1e-5 one step (taken without re-evaluation) lands within 1e-9 of the CDF. Written here rather than taken from a crate because it
/// runs once or twice per sampled direction and must not allocate; the bracket makes it safe on
/// the CDFs' flat ends, where an unguarded step overshoots.
pub(super) fn solve_increasing(
    mut lo: f64,
    mut hi: f64,
    start: f64,
    f: impl Fn(f64) -> (f64, f64, f64),
) -> f64 {
    let (bottom, top) = (lo, hi);
    let mut v = if start > lo && start < hi {
        start
    } else {
        0.5 * (lo + hi)
    };
    for _ in 0..100 {
        let (value, first, second) = f(v);
        if value == 0.0 {
            return v;
        }
        if value < 0.0 {
            lo = v;
        } else {
            hi = v;
        }
        // Halley's correction to Newton's step, 1/(1 − f f''/(2f'²)), only where it is a
        // correction: on a CDF's far tail f'' dominates and its steps would only crawl.
        let ratio = value * second / (2.0 * first * first);
        let halley = if ratio.abs() < 0.5 {
            v - value / first / (1.0 - ratio)
        } else {
            v - value / first
        };
        if halley > lo && halley < hi {
            let scale = (1.0 + v.abs()).min(v - bottom).min(top - v);
            // One Halley step from within ONE_STEP_REACH of the root leaves an error of order
            // its cube over the derivatives' length scale²: below 1e-12 of the scale. A tabulated
            // start is that close in the bulk, so one CDF evaluation suffices there.
            if ratio.abs() < 0.5 && (halley - v).abs() <= ONE_STEP_REACH * scale {
                return halley;
            }
            // Near the root, after a step of δ the error is ~ δ³ times derivative ratios: δ ≤ 1e-7
            // leaves < 1e-8 of the CDF even where those ratios are large. The Newton step f/f' (the distance to the root to first order) must
            // be small too: far out on a CDF's flat tail a Halley step is short without being
            // close. Both are measured against the distance to the support's ends as well, where
            // the Cauchy CDF in s is steep.
            let tolerance = 1e-7 * scale;
            if (halley - v).abs() <= tolerance && (value / first).abs() <= tolerance {
                return halley;
            }
            v = halley;
        } else {
            v = 0.5 * (lo + hi);
            if hi - lo <= 1e-15 * (1.0 + v.abs()) {
                return v;
            }
        }
    }
    v
}
