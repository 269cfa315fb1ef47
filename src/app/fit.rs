//! `irpol fit` as a whole: fit every input, then write the library entries (`fits/*.toml`), the
//! fit reports and the library index as one [`OutputSet`]. Everything is encoded in memory
//! before the first byte is written, so a fit or a report that fails leaves the library and the
//! reports exactly as they were; the library entries are renamed into place last.

use super::AppError;
use crate::atomic::OutputSet;
use crate::fit::{
    fit_read_inputs, parse_parameter_list, parse_parameter_values, Dispersion, FitInputs,
    FitOptions, MaterialFit, Optimizer, RobustLoss,
};
use crate::material::{list_library, Library, Material};
use crate::measure::{is_angle_note, ReadOptions};
use crate::pbrdf::DistributionKind;
use crate::pbrdf::{ModelTerms, Shadowing};
use crate::report::fit_report::encode_fit_report;
use crate::report::index::library_index_html;
use crate::report::spectral_report::encode_spectral_report;
use crate::report::ReportError;
use std::path::{Path, PathBuf};

/// The options of `irpol fit` as its flags give them, as text: parsed into [`FitOptions`] by one
/// function for the command line and the Python bindings alike, so both refuse the same input
/// with the same message.
#[derive(Clone, Debug)]
pub struct FitFlags {
    /// `cauchy` or `gaussian`; `None` fits both and keeps the preferred.
    pub distribution: Option<String>,
    pub shadowing: String,
    /// e.g. `sigma,q,n,k,rho`.
    pub free: Option<String>,
    /// e.g. `k=0.1,rho=0`.
    pub fix: Option<String>,
    /// Stages joined by `+`: ga, nm, lm.
    pub optimizer: String,
    pub seed: u64,
    /// `huber` or `cauchy`, optionally with a scale (`huber:2`).
    pub robust: Option<String>,
    /// `table` or `lorentz:N`.
    pub dispersion: String,
    /// The model's terms, or several to choose among: `auto` (the default: the admissible set
    /// that predicts best, docs/design.md §1.10), `external+depolarizer`, `external+subsurface`,
    /// `internal+subsurface`, `internal+depolarizer`, comma-separated, or `all`.
    pub terms: String,
    /// K-fold cross-validation (K ≥ 2) of each candidate set of terms.
    pub cv: Option<usize>,
    /// Parameters a spectral fit frees at each wavelength instead of sharing them, e.g.
    /// `d,n_sub` (docs/design.md §1.10).
    pub per_wavelength: Option<String>,
    /// The longest fit started without a word (`--max-minutes`, [`crate::fit::cost`]).
    pub max_minutes: f64,
}

impl Default for FitFlags {
    /// The command line's defaults.
    fn default() -> FitFlags {
        FitFlags {
            distribution: None,
            shadowing: "smith".into(),
            free: None,
            fix: None,
            optimizer: "ga+lm".into(),
            seed: FitOptions::default().seed,
            robust: None,
            dispersion: "auto".into(),
            terms: AUTO_TERMS.to_owned(),
            cv: None,
            per_wavelength: None,
            max_minutes: crate::fit::cost::DEFAULT_MAX_MINUTES,
        }
    }
}

impl FitFlags {
    /// The fit options, or the message naming the flag that is wrong.
    pub fn options(&self) -> Result<FitOptions, AppError> {
        let shadowing = &self.shadowing;
        let mut options = FitOptions {
            dispersion: Dispersion::parse(&self.dispersion)?,
            shadowing: Shadowing::parse(shadowing).ok_or_else(|| {
                AppError::invalid(format!(
                    "unknown shadowing '{}': use none, torrance-sparrow or smith",
                    crate::text::shown(shadowing)
                ))
            })?,
            optimizer: Optimizer::parse(&self.optimizer)?,
            seed: self.seed,
            ..FitOptions::default()
        };
        if let Some(name) = &self.distribution {
            options.distribution = Some(DistributionKind::parse(name)?);
        }
        if let Some(list) = &self.free {
            options.free = Some(parse_parameter_list(list)?);
        }
        if let Some(values) = &self.fix {
            options.fixed = parse_parameter_values(values)?;
        }
        if let Some(loss) = &self.robust {
            options.robust = Some(RobustLoss::parse(loss)?);
        }
        options.choose_terms = self.terms.trim() == AUTO_TERMS;
        let candidates = terms_with_parameters(parse_terms(&self.terms)?, &options)?;
        options.terms = candidates[0];
        if candidates.len() > 1 {
            options.term_candidates = candidates;
        }
        options.cv_folds = self.cv;
        options.max_minutes = self.max_minutes;
        if let Some(list) = &self.per_wavelength {
            options.per_wavelength = per_wavelength_parameters(list)?;
        }
        Ok(options)
    }
}

/// `--per-wavelength LIST`: parameters a spectral fit shares unless told (the subsurface's d,
/// n_sub, d_c, d1); the geometry's σ, q are refused (the surface is one at every wavelength),
/// and so is a parameter already free at each wavelength.
fn per_wavelength_parameters(list: &str) -> Result<Vec<crate::pbrdf::Parameter>, AppError> {
    let parameters = parse_parameter_list(list)?;
    for p in &parameters {
        match p.info().spectral {
            crate::pbrdf::SpectralRole::SharedByDefault => {}
            crate::pbrdf::SpectralRole::Shared => {
                return Err(AppError::invalid(format!(
                    "--per-wavelength {p}: the slope parameters describe the surface's geometry, \
                     which does not depend on wavelength; they are always shared"
                )))
            }
            crate::pbrdf::SpectralRole::PerWavelength => {
                return Err(AppError::invalid(format!(
                    "--per-wavelength {p}: {p} is fitted at each wavelength already; the list \
                     takes d, n_sub, d_c, d1"
                )))
            }
        }
    }
    Ok(parameters)
}

/// `--terms auto`: choose among [`ModelTerms::ALL`] (docs/design.md §1.10).
pub const AUTO_TERMS: &str = "auto";

/// The `candidates` that have every parameter `--free` and `--fix` name: under `auto` the others
/// are dropped (`--fix rho_s=…` asks for a subsurface term); a set given by name that lacks one
/// is refused, so that no flag is silently ignored.
fn terms_with_parameters(
    candidates: Vec<ModelTerms>,
    options: &FitOptions,
) -> Result<Vec<ModelTerms>, AppError> {
    let named: Vec<crate::pbrdf::Parameter> = options
        .free
        .iter()
        .flatten()
        .chain(options.fixed.keys())
        .copied()
        .collect();
    let has_all = |t: &ModelTerms| named.iter().all(|&p| t.has(p));
    if options.choose_terms {
        let kept: Vec<ModelTerms> = candidates.into_iter().filter(has_all).collect();
        if kept.is_empty() {
            return Err(AppError::invalid(
                "--free/--fix name parameters of different terms (rho_d belongs to the \
                 depolarizer, rho_s, d, n_sub, d_c to the subsurface term): give --terms",
            ));
        }
        return Ok(kept);
    }
    for terms in &candidates {
        if let Some(p) = named.iter().find(|&&p| !terms.has(p)) {
            return Err(AppError::invalid(format!(
                "--free/--fix name {p}, which the terms {terms} do not have: drop it or choose \
                 terms that have it (--terms)"
            )));
        }
    }
    Ok(candidates)
}

/// `--terms`: one or more sets of model terms, comma-separated, or `all` or `auto`.
fn parse_terms(text: &str) -> Result<Vec<ModelTerms>, AppError> {
    if text.trim() == "all" || text.trim() == AUTO_TERMS {
        return Ok(ModelTerms::ALL.to_vec());
    }
    let mut list = Vec::new();
    for name in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let terms = ModelTerms::parse(name).ok_or_else(|| {
            let known: Vec<String> = ModelTerms::ALL.iter().map(|t| t.to_string()).collect();
            AppError::invalid(format!(
                "unknown terms '{name}' in --terms: use {} (comma-separated), all or auto",
                known.join(", ")
            ))
        })?;
        if !list.contains(&terms) {
            list.push(terms);
        }
    }
    if list.is_empty() {
        return Err(AppError::invalid(
            "--terms is empty: name at least one set of terms",
        ));
    }
    Ok(list)
}

/// What a fit wrote.
pub struct FitWritten {
    pub outcomes: Vec<MaterialFit>,
    /// Each material's library entry.
    pub entries: Vec<PathBuf>,
    /// Each material's report figure (PNG; an SVG lies beside it).
    pub reports: Vec<PathBuf>,
    pub index: PathBuf,
    /// Files of the library folder the index skipped (not materials), one warning each.
    pub warnings: Vec<String>,
    /// Each fit that does not describe its data, one warning each ([`misfit_warning`]).
    pub misfits: Vec<String>,
}

/// Where `irpol fit` writes, and whether a fit that does not describe its data is refused.
pub struct FitOutput<'a> {
    /// The library folder (`--out`).
    pub fits_dir: &'a Path,
    /// The reports' folder (`--reports`).
    pub reports_dir: &'a Path,
    /// `--strict`: a misfit is an error and nothing is written.
    pub strict: bool,
}

/// `MATERIAL: the fit does not describe its data: χ²_red = 1508 > 10, sigma pinned at a bound
/// of its search interval`, or `None` for a fit that does ([`crate::material::FitRecord::misfit`]).
pub fn misfit_warning(material: &Material) -> Option<String> {
    let misfit = material.fit.as_ref()?.misfit();
    (!misfit.is_empty()).then(|| {
        format!(
            "{}: the fit does not describe its data: {}",
            material.name,
            misfit.join(", ")
        )
    })
}

/// Fits `inputs` (read as `reading` says) and writes `<fits_dir>/<material>.toml`,
/// `<reports_dir>/<material>.png|svg` and `<reports_dir>/index.html`, all or nothing. Any error
/// repeats the readers' notes about angle units (`--angles`), which may be its cause.
pub fn fit_and_write(
    inputs: FitInputs,
    reading: &ReadOptions,
    options: &FitOptions,
    output: &FitOutput,
    progress: &dyn crate::progress::Progress,
) -> Result<FitWritten, AppError> {
    let angle_notes: Vec<String> = inputs
        .notes()
        .into_iter()
        .filter(|note| is_angle_note(note))
        .collect();
    fit_and_write_read(inputs, reading, options, output, progress).map_err(|error| {
        if angle_notes.is_empty() {
            error
        } else {
            AppError::WithAngleNotes {
                error: Box::new(error),
                notes: angle_notes.join("; "),
            }
        }
    })
}

fn fit_and_write_read(
    inputs: FitInputs,
    reading: &ReadOptions,
    options: &FitOptions,
    output: &FitOutput,
    progress: &dyn crate::progress::Progress,
) -> Result<FitWritten, AppError> {
    let (fits_dir, reports_dir) = (output.fits_dir, output.reports_dir);
    let outcomes = fit_read_inputs(inputs, reading, options, progress)?;
    let misfits: Vec<String> = outcomes
        .iter()
        .filter_map(|o| misfit_warning(o.material()))
        .collect();
    if output.strict && !misfits.is_empty() {
        return Err(AppError::Misfit(misfits.join("; ")));
    }
    let mut entries = Vec::new();
    let mut report_files = Vec::new();
    let mut reports = Vec::new();
    for outcome in &outcomes {
        let path = entry_path(fits_dir, outcome.material());
        let text = outcome.material().to_toml(&path)?;
        entries.push((path, text));
        let report = match outcome {
            MaterialFit::Grey(o) => encode_fit_report(&o.material, &o.measurement, reports_dir)?,
            MaterialFit::Spectral(o) => encode_spectral_report(o, reports_dir)?,
        };
        reports.extend(report.files.first().map(|(path, _)| path.clone()));
        report_files.extend(report.files);
    }
    let index = reports_dir.join("index.html");
    let (html, warnings) = index_html(&outcomes, fits_dir, reports_dir)?;

    let mut set = OutputSet::new();
    let stage = |set: &mut OutputSet, path: &Path, bytes: &[u8]| {
        set.stage(path, bytes).map_err(|source| AppError::Write {
            path: path.to_owned(),
            source,
        })
    };
    for (path, bytes) in &report_files {
        stage(&mut set, path, bytes)?;
    }
    stage(&mut set, &index, html.as_bytes())?;
    for (path, text) in &entries {
        stage(&mut set, path, text.as_bytes())?;
    }
    set.commit().map_err(|source| AppError::WriteFit {
        dir: fits_dir.to_owned(),
        source,
    })?;
    Ok(FitWritten {
        outcomes,
        entries: entries.into_iter().map(|(path, _)| path).collect(),
        reports,
        index,
        warnings,
        misfits,
    })
}

fn entry_path(fits_dir: &Path, material: &Material) -> PathBuf {
    fits_dir.join(format!("{}.toml", material.name))
}

/// The index of the library as it will be once the new entries are in: the entries on disk,
/// with the fitted ones added or replaced; and a warning for each other file of the folder that
/// is not a material (skipped: an unrelated file must not stop the fit).
fn index_html(
    outcomes: &[MaterialFit],
    fits_dir: &Path,
    reports_dir: &Path,
) -> Result<(String, Vec<String>), ReportError> {
    let mut library = if fits_dir.is_dir() {
        list_library(fits_dir)?
    } else {
        Library::default()
    };
    for outcome in outcomes {
        let path = entry_path(fits_dir, outcome.material());
        library.materials.retain(|(existing, _)| *existing != path);
        library.skipped.retain(|(existing, _)| *existing != path);
        library.materials.push((path, outcome.material().clone()));
    }
    let warnings = library.warnings();
    let mut materials = library.materials;
    materials.sort_by(|a, b| a.0.cmp(&b.0));
    let fitted: Vec<&str> = outcomes
        .iter()
        .map(|o| o.material().name.as_str())
        .collect();
    let html = library_index_html(fits_dir, reports_dir, &materials, &fitted);
    Ok((html, warnings))
}
