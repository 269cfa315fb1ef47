//! Writes a dense synthetic measurement file (docs/design.md §2.1) of N rows, for measuring how
//! `irpol fit` and its report scale with the rows (docs/verification.md, Benchmarks):
//!
//! ```text
//! cargo run --release --example dense_measurements -- 200000 /tmp/dense.csv [RHO_D]
//! ```
//!
//! The rows are `fit_support::dense_geometry` (8 incidence angles, a fine raster of detector
//! directions each), the nine linear elements of a Cauchy–Smith paint with 3 % noise on m00 and
//! 1 % of m00 on the others, and u_ columns; ρ_d = 0.01 unless given (0: the fit needs
//! profile-likelihood bounds); seeded, so a row count always gives the same bytes.

#[path = "../tests/it/fit_support.rs"]
mod fit_support;

use fit_support::{dense_geometry, dense_truth, synthetic_set, to_csv, LINEAR_ELEMENTS};
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let rows = args.first().and_then(|n| n.parse::<usize>().ok());
    let rho_d = match args.get(2) {
        None => Some(0.01),
        Some(r) => r.parse::<f64>().ok(),
    };
    let (Some(rows), Some(path), Some(rho_d)) = (rows, args.get(1), rho_d) else {
        eprintln!("usage: dense_measurements ROWS OUT.csv [RHO_D]");
        return ExitCode::FAILURE;
    };
    let set = synthetic_set(
        "dense_paint",
        &dense_truth(rho_d),
        &dense_geometry(rows),
        &LINEAR_ELEMENTS,
        1.0,
        7,
    );
    if let Err(e) = std::fs::write(path, to_csv(&set, true)) {
        eprintln!("dense_measurements: {path}: {e}");
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
