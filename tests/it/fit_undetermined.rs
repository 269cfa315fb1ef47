//! Parameters the data bound from one side only: a transparent surface measured
//! without circular elements says only that k is small (the linear elements are even in k, so
//! ∂F/∂k = 0 at k = 0 and the linearized "k = 0.016 ± 0.057" is meaningless). The fit must give a
//! one-sided profile-likelihood bound instead, in the record, the summary line and the TOML.

use crate::common;
use crate::fit_support;

use common::fit_into;
use fit_support::{goniometer_geometry, model, synthetic_set, to_csv, LINEAR_ELEMENTS};
use irpol::fit::{fit_measurement, FitOptions, ONE_SIDED_95_DELTA_CHI2};
use irpol::measure::MeasurementSet;
use irpol::pbrdf::{DistributionKind, Parameter};
use irpol::pbrdf::{Shadowing, SlopeDistribution};
use std::collections::BTreeMap;

fn transparent_set() -> MeasurementSet {
    let truth = model(
        SlopeDistribution::Cauchy {
            sigma: 0.15,
            q: 2.5,
        },
        Shadowing::Smith,
        1.6,
        0.0,
        0.01,
    );
    synthetic_set(
        "clear_coat",
        &truth,
        &goniometer_geometry(),
        &LINEAR_ELEMENTS,
        1.0,
        7,
    )
}

fn cauchy() -> FitOptions {
    FitOptions {
        distribution: Some(DistributionKind::Cauchy),
        ..FitOptions::default()
    }
}

/// The bound is where χ² minimized over the other parameters has risen by z²₀.₉₅ s². Checked
/// against independent full fits (genetic search and polish, not the profile's warm-started
/// local steps) with k held at the bound and at 70 % of it.
#[test]
fn an_extinction_consistent_with_zero_gets_a_one_sided_profile_bound() {
    let set = transparent_set();
    let outcome = fit_measurement(&set, &cauchy()).unwrap();
    let record = outcome.material.fit.as_ref().unwrap();
    let bound = record.profile_bounds["k"];
    assert_eq!(bound.lower, None, "k ≥ 0 is the domain, not a bound");
    let upper = bound.upper.expect("the data bound k from above");
    assert!(upper > 0.0 && upper < 1.0, "k < {upper}");
    let shown = irpol::text::significant(upper, 3);
    assert_eq!(bound.describe("k"), format!("k < {shown} (95 %)"));

    let chosen = &outcome.chosen;
    let rise_at = |k: f64| {
        let held = fit_measurement(
            &set,
            &FitOptions {
                fixed: BTreeMap::from([(Parameter::K, k)]),
                ..cauchy()
            },
        )
        .unwrap();
        (held.chosen.chi2 - chosen.chi2) / chosen.reduced_chi2
    };
    let at_bound = rise_at(upper);
    assert!(
        (at_bound / ONE_SIDED_95_DELTA_CHI2 - 1.0).abs() < 0.02,
        "Δχ²/s² at the bound = {at_bound}"
    );
    assert!(rise_at(0.7 * upper) < ONE_SIDED_95_DELTA_CHI2);
}

/// Through the CLI: the summary line lists k with its bound instead of a meaningless ±, and the
/// material TOML records it.
#[test]
fn the_summary_line_and_the_toml_state_the_bound() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("clear_coat.csv");
    std::fs::write(&csv, to_csv(&transparent_set(), true)).unwrap();
    let (ok, stdout, stderr) = fit_into(dir.path(), &[&csv], &["--distribution", "cauchy"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("[bounded only: k < 0."), "{stdout}");
    assert!(!stdout.contains(" k="), "no ± for k: {stdout}");
    let toml = std::fs::read_to_string(dir.path().join("fits/clear_coat.toml")).unwrap();
    assert!(toml.contains("[fit.profile_bounds.k]"), "{toml}");
    assert!(toml.contains("confidence = 0.95"), "{toml}");
}
