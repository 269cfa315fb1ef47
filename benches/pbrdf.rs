//! Speed of the physics core: one full 4×4 Mueller evaluation, the first-column fast path, and an
//! emissivity table 0°–89° in 1° steps at the default (1e-5) accuracy; random geometries in
//! degree columns one at a time and in blocks.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use irpol::optics::RefractiveIndex;
use irpol::pbrdf::{
    Direction, GeometryColumns, HemisphereQuadrature, Pbrdf, Shadowing, SlopeDistribution,
};

fn paper_paint(shadowing: Shadowing) -> Pbrdf {
    Pbrdf::new(
        SlopeDistribution::Cauchy { sigma: 0.1, q: 1.8 },
        shadowing,
        RefractiveIndex::new(1.2, 0.2),
        0.0,
    )
    .unwrap()
}

fn mueller(c: &mut Criterion) {
    let (incident, scattered) = (
        Direction::from_angles(1.0, 0.0),
        Direction::from_angles(0.9, 2.8),
    );
    for shadowing in [
        Shadowing::None,
        Shadowing::TorranceSparrow,
        Shadowing::Smith,
    ] {
        let model = paper_paint(shadowing);
        c.bench_function(&format!("mueller_4x4_cauchy_{}", shadowing.name()), |b| {
            b.iter(|| model.mueller(black_box(&incident), black_box(&scattered)))
        });
        c.bench_function(&format!("first_column_cauchy_{}", shadowing.name()), |b| {
            b.iter(|| model.first_column(black_box(&incident), black_box(&scattered)))
        });
    }
    let gaussian = Pbrdf::new(
        SlopeDistribution::Gaussian { sigma: 0.1 },
        Shadowing::None,
        RefractiveIndex::new(1.2, 0.2),
        0.0,
    )
    .unwrap();
    c.bench_function("mueller_4x4_gaussian_none", |b| {
        b.iter(|| gaussian.mueller(black_box(&incident), black_box(&scattered)))
    });
}

/// The same evaluations over 1000 different geometries in a loop, as the fit and the renderer call
/// them: consecutive evaluations are independent, so the core overlaps their latency chains.
/// Criterion reports the time per 1000 and the throughput in evaluations per second.
fn mueller_loop(c: &mut Criterion) {
    let geometries: Vec<(Direction, Direction)> = (0..1000)
        .map(|j| {
            let t = j as f64 / 1000.0;
            (
                Direction::from_angles(0.2 + 1.2 * t, 0.0),
                Direction::from_angles(1.3 - 1.1 * t, 0.5 + 5.0 * t),
            )
        })
        .collect();
    let model = paper_paint(Shadowing::None);
    let mut group = c.benchmark_group("loop_1000_cauchy_none");
    group.throughput(Throughput::Elements(geometries.len() as u64));
    group.bench_function("mueller_4x4", |b| {
        b.iter(|| {
            geometries
                .iter()
                .map(|(i, r)| model.mueller(i, r)[(1, 1)])
                .sum::<f64>()
        })
    });
    group.bench_function("first_column", |b| {
        b.iter(|| {
            geometries
                .iter()
                .map(|(i, r)| model.first_column(i, r)[1])
                .sum::<f64>()
        })
    });
    group.finish();
}

/// 10⁴ random geometries in degrees (θ, φ uniform), as the Python `mueller` evaluates them: one
/// at a time through `Pbrdf::mueller` of the checked directions, and as columns
/// (`Pbrdf::mueller_columns`, the same numbers computed in blocks). Output into a reused buffer,
/// so the page faults of a fresh array are not timed.
fn mueller_random_columns(c: &mut Criterion) {
    const COUNT: usize = 10_000;
    let mut state = 1u64;
    let mut uniform = |high: f64| {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        high * ((state >> 11) as f64 / (1u64 << 53) as f64)
    };
    let mut angles: [Vec<f64>; 4] = Default::default();
    for _ in 0..COUNT {
        for (column, high) in angles.iter_mut().zip([85.0, 360.0, 85.0, 360.0]) {
            column.push(uniform(high));
        }
    }
    let columns = GeometryColumns {
        theta_i: &angles[0],
        phi_i: &angles[1],
        theta_r: &angles[2],
        phi_r: &angles[3],
    };
    let mut out = vec![0.0; 16 * COUNT];
    let mut group = c.benchmark_group("random_10000_cauchy");
    group.throughput(Throughput::Elements(COUNT as u64));
    for shadowing in [Shadowing::None, Shadowing::Smith] {
        let model = paper_paint(shadowing);
        group.bench_function(format!("one_at_a_time_{}", shadowing.name()), |b| {
            b.iter(|| {
                for (row, m_out) in out.chunks_exact_mut(16).enumerate() {
                    let (incident, scattered) = columns.directions(row).unwrap();
                    let m = model.mueller(&incident, &scattered).transpose();
                    m_out.copy_from_slice(m.as_slice());
                }
            })
        });
        group.bench_function(format!("columns_{}", shadowing.name()), |b| {
            b.iter(|| model.mueller_columns(&columns, 0, &mut out).unwrap())
        });
    }
    group.finish();
}

fn emissivity(c: &mut Criterion) {
    let thetas: Vec<f64> = (0..90).map(|t| (t as f64).to_radians()).collect();
    let quadrature = HemisphereQuadrature::default();
    let mut group = c.benchmark_group("emissivity_table_0_89");
    group.sample_size(20);
    // The model is built inside the timed loop: the table includes its one-time set-up (the
    // Smith–Cauchy Λ table of `Pbrdf::quadrature_masking`).
    let gaussian = || {
        Pbrdf::new(
            SlopeDistribution::Gaussian { sigma: 0.1 },
            Shadowing::Smith,
            RefractiveIndex::new(1.2, 0.2),
            0.0,
        )
        .unwrap()
    };
    let models: [(&str, &dyn Fn() -> Pbrdf); 3] = [
        ("cauchy_none", &|| paper_paint(Shadowing::None)),
        ("cauchy_smith", &|| paper_paint(Shadowing::Smith)),
        ("gaussian_smith", &gaussian),
    ];
    for (name, model) in models {
        group.bench_function(name, |b| {
            b.iter(|| model().emissivity_table(black_box(&thetas), &quadrature))
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    mueller,
    mueller_loop,
    mueller_random_columns,
    emissivity
);
criterion_main!(benches);
