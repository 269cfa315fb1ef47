//! Speed of `irpol fit` on an archive-sized measurement: reading, the default fit (`ga+lm`, both
//! distributions, uncertainties, the profile bound of ρ_d, which the data put on its bound) and
//! the report, in memory, of a dense goniometer scan of 200 000 rows × 9 elements
//! (`fit_support::dense_geometry`, as `examples/dense_measurements` writes it). Required:
//! ≤ 20 s and ≤ 1 GB peak RSS for the whole command on the 2-core machine (docs/verification.md).

#[path = "../tests/it/fit_support.rs"]
mod fit_support;

use criterion::{criterion_group, criterion_main, Criterion};
use fit_support::{dense_geometry, dense_truth, synthetic_set, to_csv, LINEAR_ELEMENTS};
use irpol::fit::{fit_measurement, FitOptions};
use irpol::measure::read_measurement_csv;
use irpol::report::fit_report::encode_fit_report;
use std::time::Duration;

const ROWS: usize = 200_000;

fn dense_fit_and_report(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("dense_paint.csv");
    let set = synthetic_set(
        "dense_paint",
        &dense_truth(0.0),
        &dense_geometry(ROWS),
        &LINEAR_ELEMENTS,
        1.0,
        7,
    );
    std::fs::write(&csv, to_csv(&set, true)).unwrap();
    drop(set);
    let reports = dir.path().join("reports");
    let mut group = c.benchmark_group("dense");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(100));
    group.bench_function(format!("fit_and_report_{ROWS}x9"), |b| {
        b.iter(|| {
            let set = read_measurement_csv(&csv).unwrap();
            let outcome = fit_measurement(&set, &FitOptions::default()).unwrap();
            encode_fit_report(&outcome.material, &outcome.measurement, &reports).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, dense_fit_and_report);
criterion_main!(benches);
