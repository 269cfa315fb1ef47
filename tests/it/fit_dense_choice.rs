//! The choice of terms on a dense scan (docs/design.md §1.10): beyond `fit::CHOICE_POINTS` rows
//! the candidates are compared on every n-th row, and the kept terms are then fitted to every
//! row exactly as a fit of those terms alone would fit them.

use crate::fit_support::{dense_geometry, dense_truth, synthetic_set, LINEAR_ELEMENTS};
use irpol::fit::{fit_grey, FitOptions, CHOICE_POINTS};
use irpol::pbrdf::{DistributionKind, ModelTerms};

#[test]
fn a_dense_scan_chooses_on_a_subsample_and_writes_the_fit_of_every_row() {
    let rows = CHOICE_POINTS + 1;
    let set = synthetic_set(
        "dense_choice",
        &dense_truth(0.01),
        &dense_geometry(rows),
        &LINEAR_ELEMENTS,
        1.0,
        11,
    );
    let default = irpol::app::fit::FitFlags::default().options().unwrap();
    let options = FitOptions {
        distribution: Some(DistributionKind::Cauchy),
        ..default
    };
    let chosen = fit_grey(&set, &options).unwrap();
    let choice = chosen.terms_choice.as_ref().expect("the default chooses");
    // Every second row compared: 25 001 of 50 001.
    assert_eq!(choice.sampled, Some((rows.div_ceil(2), rows)));
    // §1.3's model made the data and is kept, admissible on every row.
    assert_eq!(
        chosen.chosen.terms,
        ModelTerms::default(),
        "{}",
        choice.table()
    );
    assert!(choice.scores[choice.chosen].inadmissible.is_none());
    assert!(choice
        .table()
        .contains(&format!("25001 of the {rows} rows")));

    let alone = fit_grey(
        &set,
        &FitOptions {
            terms: chosen.chosen.terms,
            choose_terms: false,
            term_candidates: Vec::new(),
            ..options
        },
    )
    .unwrap();
    assert!(alone.terms_choice.is_none());
    // The material written is that of the kept terms fitted alone, bit for bit, but for the
    // record of how its terms were chosen.
    let mut written = chosen.material.clone();
    let settings = &mut written.fit.as_mut().unwrap().settings;
    let how = settings.remove("terms_choice").unwrap();
    assert!(how.contains(&format!("25001 of the {rows} rows")), "{how}");
    assert_eq!(written, alone.material);
    assert_eq!(chosen.chosen.chi2.to_bits(), alone.chosen.chi2.to_bits());
}
