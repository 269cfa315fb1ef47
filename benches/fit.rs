//! Speed of fitting (issue 3): one evaluation of the weighted least-squares objective, and the
//! default fit (`ga+lm`, Cauchy and Gaussian, 5 free parameters, uncertainties and model
//! comparison included) of ~470-point, 9-element measurements — a synthetic goniometer set made
//! with irpol's pBRDF and two of the shipped SCATMECH files. Target: ≤ 0.1 s wall on 2 cores.

#[path = "../tests/fit_support/mod.rs"]
mod fit_support;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fit_support::{goniometer_geometry, model, synthetic_set, LINEAR_ELEMENTS};
use irpol::fit::{
    fit_measurement, DistributionKind, FitOptions, MeasurementData, ModelSpace, Objective,
    Parameter, ParameterBounds, ParameterValues,
};
use irpol::measure::{read_measurement_csv, MeasurementSet};
use irpol::pbrdf::{Shadowing, SlopeDistribution};
use std::path::Path;
use std::time::Duration;

fn synthetic() -> MeasurementSet {
    let truth = model(
        SlopeDistribution::Cauchy {
            sigma: 0.15,
            q: 2.5,
        },
        Shadowing::Smith,
        1.6,
        0.05,
        0.01,
    );
    synthetic_set(
        "synthetic",
        &truth,
        &goniometer_geometry(),
        &LINEAR_ELEMENTS,
        1.0,
        1,
    )
}

fn shipped(name: &str) -> MeasurementSet {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("measurements")
        .join(format!("{name}.csv"));
    read_measurement_csv(&path).unwrap()
}

fn objective(c: &mut Criterion) {
    let set = synthetic();
    let data = MeasurementData::new(&set).unwrap();
    let values = ParameterValues([0.15, 2.5, 1.6, 0.05, 0.01]);
    for kind in [DistributionKind::Cauchy, DistributionKind::Gaussian] {
        let space = ModelSpace::new(
            kind,
            Shadowing::Smith,
            &Parameter::ALL,
            values,
            &ParameterBounds::default(),
        )
        .unwrap();
        let objective = Objective::new(&data, &space, None);
        let search = space.search(&values);
        c.bench_function(&format!("objective_472x9_{}_smith", kind.name()), |b| {
            b.iter(|| objective.cost(black_box(&search)))
        });
    }
}

fn default_fit(c: &mut Criterion) {
    let mut group = c.benchmark_group("default_fit");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(8));
    for (name, set) in [
        ("synthetic_472x9", synthetic()),
        ("smooth_glass_482x9", shipped("smooth_glass")),
        ("anodized_panel_516x9", shipped("anodized_panel")),
    ] {
        let options = FitOptions::default();
        group.bench_function(name, |b| {
            b.iter(|| fit_measurement(black_box(&set), &options).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, objective, default_fit);
criterion_main!(benches);
