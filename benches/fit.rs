//! Speed of fitting: one evaluation of the weighted least-squares objective, and the
//! default fit (`ga+lm`, Cauchy and Gaussian, 5 free parameters, uncertainties and model
//! comparison included) of ~470-point, 9-element measurements — a synthetic goniometer set made
//! with irpol's pBRDF and two of the shipped SCATMECH files. Target: ≤ 0.1 s wall on 2 cores.

#[path = "../tests/it/fit_support.rs"]
mod fit_support;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fit_support::{goniometer_geometry, model, synthetic_set, LINEAR_ELEMENTS};
use irpol::fit::{
    fit_grey, fit_measurement, fit_spectral, subset, validate_model, Dispersion, FitOptions,
    MeasurementData, ModelSpace, Objective, ParameterBounds, ParameterValues,
};
use irpol::measure::{
    read_measurement_csv, read_measurement_sets, read_with_layout, Layout, MeasurementSet,
};
use irpol::pbrdf::{DistributionKind, Parameter};
use irpol::pbrdf::{ModelTerms, Shadowing, SlopeDistribution};
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
    let values = ParameterValues([0.15, 2.5, 1.6, 0.05, 0.01, 0.5, 0.0, 1.5, 0.0, 0.0]);
    for kind in [DistributionKind::Cauchy, DistributionKind::Gaussian] {
        let space = ModelSpace::new(
            kind,
            Shadowing::Smith,
            ModelTerms::default(),
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

/// The joint fit of a spectral set (table dispersion, both distributions, each
/// wavelength fitted alone first): nine wavelengths of the silicate truth × the 472-geometry
/// goniometer, and the shipped silicate_glass.csv (nine wavelengths, 3682 rows × 16 elements).
/// Target: ≤ 1 s for 9 × 500 geometries.
fn spectral_fit(c: &mut Criterion) {
    let mut group = c.benchmark_group("spectral_fit");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    let truth = [
        (8.0, 0.517774, 0.543731),
        (8.5, 0.588464, 1.2793),
        (9.0, 1.36346, 2.12223),
        (9.5, 2.87319, 1.38554),
        (10.0, 2.62133, 0.477271),
        (10.6, 2.30722, 0.210027),
        (11.5, 2.08423, 0.100204),
        (12.5, 1.96574, 0.0596999),
        (14.0, 1.87624, 0.0359674),
    ];
    let synthetic: Vec<MeasurementSet> = truth
        .iter()
        .enumerate()
        .map(|(i, &(w, n, k))| {
            let distribution = SlopeDistribution::Cauchy {
                sigma: 0.06,
                q: 2.8,
            };
            let pbrdf = model(distribution, Shadowing::Smith, n, k, 0.0);
            let geometry = goniometer_geometry();
            let mut set = synthetic_set(
                "silicate",
                &pbrdf,
                &geometry,
                &LINEAR_ELEMENTS,
                1.0,
                i as u64,
            );
            set.wavelength_um = w;
            set
        })
        .collect();
    let shipped = read_measurement_sets(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("measurements/silicate_glass.csv"),
    )
    .unwrap();
    for (name, sets) in [
        ("synthetic_9x472x9", synthetic),
        ("silicate_glass_3682x16", shipped),
    ] {
        let options = FitOptions::default();
        group.bench_function(name, |b| {
            b.iter(|| fit_spectral(black_box(sets.clone()), &options, Dispersion::Table).unwrap())
        });
    }
    group.finish();
}

/// NIST's measured PTFE at 1.064 µm (1824 rows × 16 elements, read through its layout): the fit
/// with the volume terms (internal facet + polarized subsurface; Cauchy and Gaussian, energy
/// constraint, uncertainties) and its 5-fold cross-validation, and `validate` of that model on
/// 2000 rows. Targets (docs/design.md §1.10): the fit ≤ 2 s, the validation ≤ 0.2 s.
fn ptfe_volume_fit(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/ptfe");
    let layout = Layout::read(&root.join("layout.toml")).unwrap();
    let set = read_with_layout(&root.join("PTFE_351_1064.csv"), &layout)
        .unwrap()
        .into_iter()
        .find(|s| (s.wavelength_um - 1.064).abs() < 1e-9)
        .unwrap();
    let options = FitOptions {
        terms: ModelTerms::parse("internal+subsurface").unwrap(),
        cv_folds: Some(5),
        ..FitOptions::default()
    };
    let mut group = c.benchmark_group("ptfe_volume");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    group.bench_function("fit_1824x16_cv5", |b| {
        b.iter(|| fit_grey(black_box(&set), &options).unwrap())
    });
    let outcome = fit_grey(&set, &options).unwrap();
    let model = outcome.material.grey_model().unwrap().pbrdf().unwrap();
    let rows: Vec<usize> = (0..2000).map(|i| i % set.points.len()).collect();
    let validation_set = subset(&set, &rows);
    group.bench_function("validate_2000x16", |b| {
        b.iter(|| validate_model(black_box(&model), &validation_set).unwrap())
    });
    group.finish();
}

/// The product's default (`irpol fit` with no flag: three sets of terms, each with both slope
/// laws, 5-fold cross-validated, the kept one's profile bounds) on NIST's PTFE: one wavelength
/// (1824 rows × 16) and both as one spectral material (docs/design.md §1.10). Targets: ≤ 3 s and
/// ≤ 8 s.
fn ptfe_default_fit(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/ptfe");
    let layout = Layout::read(&root.join("layout.toml")).unwrap();
    let sets = read_with_layout(&root.join("PTFE_351_1064.csv"), &layout).unwrap();
    let options = irpol::app::fit::FitFlags::default().options().unwrap();
    let mut group = c.benchmark_group("ptfe_default");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(60));
    for set in &sets {
        let name = format!("grey_{}um", set.wavelength_um);
        group.bench_function(name, |b| {
            b.iter(|| fit_grey(black_box(set), &options).unwrap())
        });
    }
    let path = root.join("PTFE_351_1064.csv");
    let reading = irpol::measure::ReadOptions {
        layout: Some(layout.clone()),
        ..Default::default()
    };
    group.bench_function("spectral_both", |b| {
        b.iter(|| {
            irpol::fit::fit_inputs_with(
                std::slice::from_ref(&path),
                &reading,
                &options,
                &irpol::progress::Silent,
            )
            .unwrap()
        })
    });
    group.finish();
}

criterion_group!(
    benches,
    objective,
    default_fit,
    spectral_fit,
    ptfe_volume_fit,
    ptfe_default_fit
);
criterion_main!(benches);
