//! `irpol fit`'s summary: one line per material with its parameters, fit quality, what the data
//! do not determine, and where the entry and reports went.

use super::progress::TerminalProgress;
use super::terminal::{note_all, warn_once};
use irpol::app::fit::{fit_and_write, FitOutput};
use irpol::fit::{FitInputs, FitOptions, MaterialFit};
use irpol::measure::ReadOptions;
use irpol::text::significant;
use std::path::{Path, PathBuf};

/// Fits, writes the library entries, reports and index (all or nothing) and prints one line per
/// material and where the reports went.
pub(crate) fn fit_and_summarize(
    inputs: &[PathBuf],
    reading: &ReadOptions,
    options: &FitOptions,
    output: &FitOutput,
) -> anyhow::Result<()> {
    let folders = vec![output.fits_dir.to_owned(), output.reports_dir.to_owned()];
    crate::cli::signals::remove_on_interrupt(vec![], folders);
    // The readers' notes are said before the fit starts.
    let read = FitInputs::read(inputs, reading)?;
    note_all(&read.notes());
    let written = fit_and_write(
        read,
        reading,
        options,
        output,
        &TerminalProgress::counting(),
    )?;
    warn_once(&written.warnings);
    warn_once(&written.misfits);
    for (outcome, entry) in written.outcomes.iter().zip(&written.entries) {
        let line = match outcome {
            MaterialFit::Grey(outcome) => fit_summary_line(outcome, entry),
            MaterialFit::Spectral(outcome) => spectral_summary_line(outcome, entry),
        };
        say!("{line}");
        let choice = match outcome {
            MaterialFit::Grey(grey) => &grey.terms_choice,
            MaterialFit::Spectral(spectral) => &spectral.terms_choice,
        };
        if let Some(choice) = choice {
            say!("{}", choice.table());
        }
    }
    for report in &written.reports {
        say!("  report {}", report.display());
    }
    say!("  index  {}", written.index.display());
    Ok(())
}

/// `name: family, N wavelengths a–b µm, dispersion: σ=…±… q=…±… [law …] n a–b, k a–b
/// χ²_red=… → entry`: the shared parameters with their errors and the table's range.
fn spectral_summary_line(outcome: &irpol::fit::SpectralFitOutcome, entry: &Path) -> String {
    let chosen = &outcome.chosen;
    let model = &chosen.model;
    let shared: Vec<String> = chosen
        .names
        .iter()
        .zip(chosen.values.iter().zip(&chosen.errors))
        .filter(|(name, _)| !name.contains('('))
        .map(|(name, (v, e))| format!("{name}={}±{e:.1e}", significant(*v, 6)))
        .collect();
    let range = |values: &[f64]| {
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        format!("{}–{}", significant(lo, 3), significant(hi, 3))
    };
    let (first, last) = model.range_um();
    let terms = match model.terms() {
        t if t == irpol::pbrdf::ModelTerms::default() => String::new(),
        t => format!(" {t}"),
    };
    format!(
        "{}: {}{terms} {}, {} wavelengths {first}–{last} µm: {} n {} k {} χ²_red={}{}{} → {}",
        outcome.material.name,
        chosen.distribution.name(),
        match chosen.dispersion {
            irpol::fit::Dispersion::Cauchy => "normal dispersion (Cauchy)".to_owned(),
            other => other.to_string(),
        },
        model.wavelength_um.len(),
        shared.join(" "),
        range(&model.n),
        range(&model.k),
        chi2(chosen.reduced_chi2),
        realizability_clause(&outcome.measurements),
        identification_clause(outcome.material.fit.as_ref()),
        entry.display()
    )
}

/// `name: family σ=…±… … [bounded only: …] (fixed: …) χ²_red=…; comparison → entry`: the
/// parameters with their errors, except where the ± means nothing (undetermined, or bounded
/// from one side only) and the record's profile bound is listed instead; the parameters held
/// fixed as the record states them.
fn fit_summary_line(outcome: &irpol::fit::FitOutcome, entry: &Path) -> String {
    let chosen = &outcome.chosen;
    let record = outcome.material.fit.as_ref();
    let bound = |p: &irpol::pbrdf::Parameter| record.and_then(|r| r.profile_bounds.get(p.name()));
    let parameters: Vec<String> = chosen
        .free
        .iter()
        .zip(&chosen.values)
        .filter(|(p, _)| bound(p).is_none())
        .map(|(p, v)| match chosen.error(*p) {
            Some(e) => format!("{}={}±{e:.1e}", p.name(), significant(*v, 6)),
            None => format!("{}={}", p.name(), significant(*v, 6)),
        })
        .collect();
    let bounded: Vec<String> = chosen
        .free
        .iter()
        .filter_map(|p| bound(p).map(|b| b.describe(p.name())))
        .collect();
    let fixed: Vec<String> = record
        .map(|r| &r.fixed_parameters)
        .into_iter()
        .flatten()
        .map(|(name, v)| format!("{name}={}", significant(*v, 6)))
        .collect();
    let comparison = outcome
        .comparison
        .as_ref()
        .map_or(String::new(), |c| format!("; {}", c.summary()));
    format!(
        "{}: {}{} {}{}{} χ²_red={}{}{}{comparison} → {}",
        outcome.material.name,
        chosen.distribution.name(),
        if chosen.terms == irpol::pbrdf::ModelTerms::default() {
            String::new()
        } else {
            format!(" {}", chosen.terms)
        },
        parameters.join(" "),
        listed(" [bounded only: ", &bounded, ", ", "]"),
        listed(" (fixed: ", &fixed, " ", ")"),
        chi2(chosen.reduced_chi2),
        realizability_clause(std::slice::from_ref(&outcome.measurement)),
        identification_clause(record),
        entry.display()
    )
}

/// `; NOT DETERMINED by the data: d (at a bound of its search interval), …` (docs/design.md
/// §1.10 "Identification"): a number the data do not determine must not read as a measurement.
/// A spectral fit's per-wavelength coordinates (`rho_d(8.5um)`, …) that share a reason are named
/// once with their count and range, so 50 wavelengths at a bound make one clause, not 50.
fn identification_clause(record: Option<&irpol::material::FitRecord>) -> String {
    let mut groups: Vec<(String, String, Vec<String>)> = Vec::new();
    for (name, why) in record.map(|r| r.identification()).unwrap_or_default() {
        let (base, at) = match name.split_once('(') {
            Some((base, rest)) => (base.to_owned(), Some(rest.trim_end_matches(')').to_owned())),
            None => (name.clone(), None),
        };
        match groups.last_mut() {
            Some((b, w, ats)) if at.is_some() && *b == base && *w == why && !ats.is_empty() => {
                ats.extend(at)
            }
            _ => groups.push((base, why, at.into_iter().collect())),
        }
    }
    let notes: Vec<String> = groups
        .into_iter()
        .map(|(base, why, ats)| match ats.as_slice() {
            [] => format!("{base} {why}"),
            [at] => format!("{base}({at}) {why}"),
            [first, .., last] => {
                format!("{base} at {} wavelengths ({first}–{last}) {why}", ats.len())
            }
        })
        .collect();
    listed("; NOT DETERMINED by the data: ", &notes, ", ", "")
}

/// `; k of N rows not realizable beyond 2σ` (Cloude's test against each row's uncertainty), or
/// nothing when no row has all sixteen elements to test.
fn realizability_clause(sets: &[irpol::measure::MeasurementSet]) -> String {
    let (mut failed, mut checked) = (0, 0);
    for set in sets {
        let outcome = irpol::measure::unrealizable_rows(set, REALIZABILITY_SIGMAS);
        failed += outcome.unrealizable.len();
        checked += outcome.checked;
    }
    if checked == 0 {
        return String::new();
    }
    format!("; {failed} of {checked} rows not realizable beyond {REALIZABILITY_SIGMAS}σ")
}

/// A measured row counts as not realizable when its coherency matrix's smallest eigenvalue is
/// below this many standard deviations of its noise (a bound, so noise alone rarely reaches it).
const REALIZABILITY_SIGMAS: f64 = 2.0;

/// A reduced χ² for the summary line: three decimals, in exponent form from 1e6 on (an absurd
/// fit's 3e50 is not printed as 51 digits).
fn chi2(x: f64) -> String {
    if x.abs() < 1e6 {
        format!("{x:.3}")
    } else {
        format!("{x:.3e}")
    }
}

/// `items` joined by `separator` between `open` and `close`, or nothing when there are none.
fn listed(open: &str, items: &[String], separator: &str, close: &str) -> String {
    if items.is_empty() {
        String::new()
    } else {
        format!("{open}{}{close}", items.join(separator))
    }
}
