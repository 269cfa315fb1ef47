//! The material library: one TOML file per material (docs/design.md §2.2) holding the pBRDF model, how it
//! was fitted, and its uncertainties. Written atomically; read by `render` and `report`.

mod comments;
pub mod pbsdf_export;
mod raw;
mod scene_materials;
mod spectral;

pub use pbsdf_export::{export_material, Export, ExportError, ExportOptions};
pub use raw::ModelTableError;
pub use scene_materials::{
    inline_pbrdf, share_wavelength_nodes, InlineMaterialConfig, InlineMaterialError,
    MaterialResolver, SceneMaterial, SceneMaterialError,
};
pub use spectral::{
    BandModelError, MaterialModel, OutsideTable, PerWavelength, SpectralModel, SpectralVolume,
    THERMAL_EMISSIVITY_REFERENCE_K,
};

use crate::atomic::write_atomically;
use crate::optics::RefractiveIndex;
use crate::pbrdf::{
    Body, FacetSide, ModelError, ModelTerms, Parameter, Pbrdf, Shadowing, SlopeDistribution,
    Subsurface,
};
use crate::text::{number, shown, shown_at_most, significant};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum MaterialError {
    #[error("{path}: cannot read the material file")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a valid material TOML: {message}")]
    Parse { path: PathBuf, message: String },
    /// The model error is part of the message (not a `source`), so it reads the same with `{}`.
    #[error("{path}: the model is invalid: {error}")]
    Model { path: PathBuf, error: ModelError },
    #[error("material '{name}' is not in the library {dir} (no {dir}/{name}.toml)")]
    NotFound { name: String, dir: PathBuf },
    #[error("material '{name}' is spectral: this needs a grey (single-wavelength) material")]
    Spectral { name: String },
    #[error("material '{name}': wavelength {error}")]
    OutsideTable { name: String, error: OutsideTable },
    /// A value of the entry is NaN or infinite: no file is written (TOML would hold `nan`/`inf`,
    /// which no reader of a material should have to meet).
    #[error(
        "{path}: not written: {key} = {} is not a finite number (the fit did not converge to \
         finite values; look for extreme values or uncertainties in the measurements)",
        number(*value)
    )]
    NotFinite {
        path: PathBuf,
        key: String,
        value: f64,
    },
    #[error("{path}: cannot write")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// The pBRDF parameters of a material (docs/design.md §1.3) at one wavelength. Read through
/// `raw::RawModel`, which refuses unknown keys: serde cannot deny them on a struct with a
/// flattened field, and a typo such as `rho = 0.5` must not silently give ρ_d = 0.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "raw::RawModel<f64>")]
pub struct ModelSpec {
    #[serde(flatten)]
    pub distribution: SlopeDistribution,
    pub shadowing: Shadowing,
    pub n: f64,
    pub k: f64,
    #[serde(default)]
    pub rho_d: f64,
    /// Which side of the facets reflects (docs/design.md §1.10); absent from files for
    /// `external`, so that models without the volume terms are written as before.
    #[serde(default, skip_serializing_if = "FacetSide::is_external")]
    pub facet: FacetSide,
    /// The subsurface term's ρ_s and d, both present or both absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho_s: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d: Option<f64>,
    /// The subsurface interface's own index (absent: n).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub n_sub: Option<f64>,
    /// The subsurface term's circular residual polarization (absent: d).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d_c: Option<f64>,
    /// The change of its residual polarization with the scattering angle (absent: 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d1: Option<f64>,
    pub wavelength_um: f64,
}

impl ModelSpec {
    /// The value of a model parameter; `None` for a slope parameter the distribution does not
    /// have (q of the Gaussian).
    pub fn parameter(&self, parameter: Parameter) -> Option<f64> {
        match parameter {
            Parameter::N => Some(self.n),
            Parameter::K => Some(self.k),
            Parameter::RhoD => Some(self.rho_d),
            Parameter::RhoS => self.rho_s,
            Parameter::D => self.d,
            Parameter::NSub => self.rho_s.map(|_| self.n_sub.unwrap_or(self.n)),
            Parameter::DC => self.subsurface().map(|s| s.circular()),
            Parameter::D1 => self.subsurface().map(|s| s.d1.unwrap_or(0.0)),
            slope => self.distribution.parameter(slope),
        }
    }

    /// The model's terms (docs/design.md §1.10).
    pub fn terms(&self) -> ModelTerms {
        let body = if self.rho_s.is_some() {
            Body::Subsurface
        } else {
            Body::Depolarizer
        };
        ModelTerms::new(self.facet, body)
    }

    /// The subsurface term, if the model has one.
    pub fn subsurface(&self) -> Option<Subsurface> {
        self.rho_s.map(|rho_s| Subsurface {
            rho_s,
            d: self.d.unwrap_or(0.0),
            n_sub: self.n_sub,
            d_c: self.d_c,
            d1: self.d1,
        })
    }

    pub fn pbrdf(&self) -> Result<Pbrdf, ModelError> {
        Pbrdf::new(
            self.distribution,
            self.shadowing,
            RefractiveIndex::new(self.n, self.k),
            self.rho_d,
        )?
        .with_volume(self.facet, self.subsurface())
    }
}

/// How a material was fitted (docs/design.md §2.2): provenance, optimizer, quality and uncertainties.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitRecord {
    /// The measurement file, as given to `irpol fit`, and the SHA-256 of its bytes.
    pub source: PathBuf,
    pub source_sha256: String,
    /// The fingerprint of the source's parsed data (absent in files written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source_data: Option<crate::measure::SourceData>,
    /// The instrument layout the sources were read through (docs/design.md §2.8), as given to
    /// `irpol fit --layout`; absent when the files were read as they say (docs/design.md §2.1,
    /// or through a layout their own `# layout:` line names).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layout: Option<PathBuf>,
    /// The rows of the sources that were fitted (`--wavelength`, `--theta-i`); absent: all.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub selection: Option<crate::measure::RowSelection>,
    /// How the sources' angles were read when `irpol fit --angles` said (`degrees` or
    /// `radians`); absent: as the files declare them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angles: Option<crate::measure::AngleReading>,
    /// Further files of the same material and wavelength fitted with `source` as repeat
    /// measurements, in the order their rows follow its rows; absent for a fit of one file.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub merged_sources: Vec<MergedSource>,
    /// Measured geometries (rows) used, over all source files.
    pub points: usize,
    /// Mueller elements used, e.g. ["m00", "m01", …].
    pub elements: Vec<String>,
    pub free_parameters: Vec<String>,
    /// The model's parameters held fixed (`--fix`, or left out of `--free`), with their values.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub fixed_parameters: BTreeMap<String, f64>,
    pub optimizer: String,
    pub seed: u64,
    pub settings: BTreeMap<String, String>,
    pub iterations: u64,
    pub evaluations: u64,
    pub cost: f64,
    pub reduced_chi2: f64,
    pub degrees_of_freedom: usize,
    pub aic: f64,
    pub bic: f64,
    pub termination: String,
    /// Root-mean-square residual per Mueller element (sr⁻¹).
    pub rmse: BTreeMap<String, f64>,
    /// 1-σ uncertainty per free parameter (scaled by the reduced χ²).
    pub uncertainty: BTreeMap<String, f64>,
    /// Correlation matrix of the free parameters, in `free_parameters` order.
    pub correlation: Vec<Vec<f64>>,
    /// Free parameters the data do not determine (no sensitivity, |ρ| > 0.999, or a 1-σ error
    /// above both 50 % of the value and 1 % of the search interval).
    #[serde(default)]
    pub undetermined: Vec<String>,
    /// Free parameters resting on a bound of their search interval (e.g. ρ_d = 0).
    #[serde(default)]
    pub at_bound: Vec<String>,
    /// The `at_bound` parameters pinned at a bound other than zero (σ at its largest, q at its
    /// smallest, n at 10, …): the search wanted to go where the model means nothing, so the fit
    /// does not describe its data ([`FitRecord::misfit`]). A zero (ρ_d = 0, k = 0, Cauchy B = 0:
    /// the term absent) is an answer of the data, not a sign of a bad fit.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pinned: Vec<String>,
    /// One-sided profile-likelihood bounds of the parameters whose 1-σ `uncertainty` does not
    /// describe what the data allow: the undetermined ones, and those the data bound from one
    /// side only (a linear 95 % interval reaching an end of the search interval).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub profile_bounds: BTreeMap<String, ConfidenceBound>,
    /// A spectral fit's 1-σ errors of the per-wavelength parameters (`n`, `k`, `rho_d`), one per
    /// table wavelength (`uncertainty` holds the shared ones: σ, q and a law's).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub uncertainty_per_wavelength: BTreeMap<String, Vec<f64>>,
    /// A spectral fit's quality at each wavelength.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub wavelengths: Vec<WavelengthQuality>,
    /// A spectral fit's dispersion: which was kept and the information criteria of each fitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dispersion: Option<DispersionChoice>,
    /// How the slope distribution was chosen when both were fitted (AIC/BIC comparison).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_choice: Option<String>,
    /// The competing slope distribution's best fit, for model comparison.
    pub alternative: Option<AlternativeFit>,
    /// Best cost after each global-stage generation, then after each local-stage iteration (for the
    /// report's convergence plot); the first `global_iterations` entries are the global stage.
    #[serde(default)]
    pub convergence: Vec<f64>,
    #[serde(default)]
    pub global_iterations: usize,
}

/// |ρ| above which two fitted parameters count as one combination the data determine, not two
/// (docs/design.md §1.10 "Identification").
pub const STRONG_CORRELATION: f64 = 0.98;

/// χ²_red above which a fit does not describe its data ([`FitRecord::misfit`]): the model's
/// residuals are more than three times the stated noise. The shipped fits reach 1.0 (synthetic
/// data) and 6.0 (NIST's PTFE, whose noise is estimated).
pub const MISFIT_REDUCED_CHI2: f64 = 10.0;

/// |value| below which a parameter on a bound of its search interval counts as zero (a term
/// absent, [`FitRecord::pinned`]); a search coordinate at its bound leaves ρ_d ≈ 1e-6.
pub const ZERO_AT_BOUND: f64 = 1e-4;

/// The parameters of `names` in `at_bound` whose value (aligned with `names`) is not zero: the
/// record's [`FitRecord::pinned`].
pub fn pinned_at_bound(at_bound: &[String], names: &[String], values: &[f64]) -> Vec<String> {
    names
        .iter()
        .zip(values)
        .filter(|(name, value)| at_bound.contains(name) && value.abs() > ZERO_AT_BOUND)
        .map(|(name, _)| name.clone())
        .collect()
}

impl FitRecord {
    /// Why the fit does not describe its data, one clause each (`χ²_red = 1508 > 10`, `pinned at
    /// a bound of the search interval: sigma, q`); empty for a fit that does. The fit warns of
    /// these, `--strict` refuses them, and the report and the library index mark them.
    pub fn misfit(&self) -> Vec<String> {
        let chi2 = (self.reduced_chi2 > MISFIT_REDUCED_CHI2).then(|| {
            format!(
                "χ²_red = {} > {MISFIT_REDUCED_CHI2}",
                crate::text::significant_trimmed(self.reduced_chi2, 4)
            )
        });
        let pinned = (!self.pinned.is_empty()).then(|| {
            format!(
                "pinned at a bound of the search interval: {}",
                self.pinned.join(", ")
            )
        });
        chi2.into_iter().chain(pinned).collect()
    }

    /// The fitted parameters the data do not determine (docs/design.md §1.10
    /// "Identification"), each with why: resting on a bound of its search interval, without
    /// sensitivity or a profile wider than its range (undetermined), or correlated beyond
    /// |ρ| = [`STRONG_CORRELATION`] with another. Names as in `free_parameters`; a pair is named
    /// once, by its first member.
    pub fn identification(&self) -> Vec<(String, String)> {
        let mut notes: Vec<(String, String)> = Vec::new();
        for name in &self.at_bound {
            notes.push((name.clone(), "at a bound of its search interval".into()));
        }
        for name in &self.undetermined {
            if !self.at_bound.contains(name) {
                notes.push((name.clone(), "not determined (no sensitivity)".into()));
            }
        }
        let names = &self.free_parameters;
        for (a, row) in self.correlation.iter().enumerate().take(names.len()) {
            for (b, &rho) in row.iter().enumerate().take(names.len()).skip(a + 1) {
                if rho.abs() > STRONG_CORRELATION {
                    notes.push((
                        names[a].clone(),
                        format!("correlated with {} (ρ = {})", names[b], significant(rho, 3)),
                    ));
                }
            }
        }
        notes
    }

    /// Keeps the record writable when the data do not determine a parameter at all (its 1-σ
    /// error infinite, as for a subsurface term's d and d_c when ρ_s → 0): the parameter is listed
    /// as undetermined, its error left out of `uncertainty` and its correlations written as 0,
    /// instead of the whole entry being refused for a non-finite number.
    pub fn mark_non_finite_as_undetermined(&mut self) {
        let infinite: Vec<String> = self
            .uncertainty
            .iter()
            .filter(|(_, e)| !e.is_finite())
            .map(|(name, _)| name.clone())
            .collect();
        for name in infinite {
            self.uncertainty.remove(&name);
            if !self.undetermined.contains(&name) {
                self.undetermined.push(name);
            }
        }
        for value in self.correlation.iter_mut().flatten() {
            if !value.is_finite() {
                *value = 0.0;
            }
        }
    }
}

/// What the data say about a parameter they do not determine: a one-sided bound on each side of
/// the fitted value from the profile likelihood (χ² minimized over the other parameters rises by
/// z² s² there, z the one-sided quantile of `confidence`). A missing side means the data allow
/// every value on that side within the fit's search interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConfidenceBound {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<f64>,
    /// The confidence of each side's bound (0.95).
    pub confidence: f64,
}

impl ConfidenceBound {
    /// "k < 0.0312 (95 %)", "n > 1.21 (95 %)", "0.8 < n < 2.1 (95 % each side)", or
    /// "k not bounded in the search interval".
    pub fn describe(&self, name: &str) -> String {
        let percent = number(100.0 * self.confidence);
        match (self.lower, self.upper) {
            (None, Some(upper)) => format!("{name} < {} ({percent} %)", significant(upper, 3)),
            (Some(lower), None) => format!("{name} > {} ({percent} %)", significant(lower, 3)),
            (Some(lower), Some(upper)) => format!(
                "{} < {name} < {} ({percent} % each side)",
                significant(lower, 3),
                significant(upper, 3)
            ),
            (None, None) => format!("{name} not bounded in the search interval"),
        }
    }
}

/// How well a spectral fit matches one wavelength's data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WavelengthQuality {
    pub wavelength_um: f64,
    pub points: usize,
    /// χ² of this wavelength's observations over their number.
    pub chi2_per_observation: f64,
}

/// The dispersion of a spectral fit and, when a law was fitted, the comparison with the table
/// (docs/design.md §1.9: the AIC of both).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DispersionChoice {
    /// `table` or `lorentz:N`.
    pub chosen: String,
    pub table_aic: f64,
    pub table_bic: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub law_aic: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub law_bic: Option<f64>,
}

/// A measurement file merged into a fit after [`FitRecord::source`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MergedSource {
    /// The file as given to `irpol fit`, and the SHA-256 of its bytes.
    pub source: PathBuf,
    pub source_sha256: String,
    /// The fingerprint of its parsed data (as [`FitRecord::source_data`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source_data: Option<crate::measure::SourceData>,
    /// Its rows.
    pub points: usize,
}

/// The other distribution's best fit on the same data (model comparison by AIC/BIC).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AlternativeFit {
    pub model: ModelSpec,
    pub cost: f64,
    pub reduced_chi2: f64,
    pub aic: f64,
    pub bic: f64,
}

/// One entry of the material library.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    pub name: String,
    pub tool_version: String,
    pub model: MaterialModel,
    pub fit: Option<FitRecord>,
}

impl Material {
    pub fn load(path: &Path) -> Result<Material, MaterialError> {
        let text = std::fs::read_to_string(path).map_err(|source| MaterialError::Read {
            path: path.to_owned(),
            source,
        })?;
        Material::from_toml(&text, path)
    }

    /// The model at `wavelength_um` ([`MaterialModel::at`]), refused outside a spectral table
    /// with the material's name and the table's range.
    pub fn at(&self, wavelength_um: f64) -> Result<ModelSpec, MaterialError> {
        self.model
            .at(wavelength_um)
            .map_err(|error| MaterialError::OutsideTable {
                name: self.name.clone(),
                error,
            })
    }

    /// [`Material::load`] of a file's text; `path` names it in messages.
    pub fn from_toml(text: &str, path: &Path) -> Result<Material, MaterialError> {
        let material: Material = toml::from_str(text).map_err(|e| MaterialError::Parse {
            path: path.to_owned(),
            message: toml_error_message(text, &e),
        })?;
        // The name is printed by `library` and in messages: it must not act on the terminal.
        if material.name.chars().any(char::is_control) {
            return Err(MaterialError::Parse {
                path: path.to_owned(),
                message: format!(
                    "name '{}' contains a control character",
                    shown(&material.name)
                ),
            });
        }
        material
            .model
            .validate()
            .map_err(|error| MaterialError::Model {
                path: path.to_owned(),
                error,
            })?;
        Ok(material)
    }

    /// The model of a grey material; a spectral one is refused (for what only grey materials
    /// have: a single-wavelength fit report).
    pub fn grey_model(&self) -> Result<&ModelSpec, MaterialError> {
        self.model.grey().ok_or_else(|| MaterialError::Spectral {
            name: self.name.clone(),
        })
    }

    /// The TOML text of the library entry (what [`Material::save`] writes); `path` only names
    /// the file in the error.
    /// The file explains itself: `#` comments give each field's unit and meaning.
    pub fn to_toml(&self, path: &Path) -> Result<String, MaterialError> {
        let error = |e: &dyn std::fmt::Display| MaterialError::Write {
            path: path.to_owned(),
            source: std::io::Error::other(e.to_string()),
        };
        let value = toml::Value::try_from(self).map_err(|e| error(&e))?;
        if let Some((key, value)) = first_non_finite(&value, String::new()) {
            return Err(MaterialError::NotFinite {
                path: path.to_owned(),
                key,
                value,
            });
        }
        let text = toml::to_string_pretty(self).map_err(|e| error(&e))?;
        let identification = self
            .fit
            .as_ref()
            .map(FitRecord::identification)
            .unwrap_or_default();
        comments::commented(&text, &identification).map_err(|e| error(&e))
    }

    /// Writes the TOML atomically: a temporary file in the same folder, then a rename, so a failed
    /// run never leaves a half-written library entry.
    pub fn save(&self, path: &Path) -> Result<(), MaterialError> {
        let text = self.to_toml(path)?;
        write_atomically(path, text.as_bytes()).map_err(|source| MaterialError::Write {
            path: path.to_owned(),
            source,
        })
    }
}

/// The first NaN or infinite number in `value` with its key path (`fit.correlation[3][5]`).
fn first_non_finite(value: &toml::Value, key: String) -> Option<(String, f64)> {
    match value {
        toml::Value::Float(x) if !x.is_finite() => Some((key, *x)),
        toml::Value::Table(table) => table.iter().find_map(|(k, v)| {
            let key = if key.is_empty() {
                k.clone()
            } else {
                format!("{key}.{k}")
            };
            first_non_finite(v, key)
        }),
        toml::Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, v)| first_non_finite(v, format!("{key}[{i}]"))),
        _ => None,
    }
}

/// Characters of the TOML parser's message kept in ours.
const PARSER_MESSAGE_CHARS: usize = 200;

/// A TOML error as one line, `line L, column C: what is wrong`: the parser's own rendering spans
/// several lines and quotes the whole offending line (control characters, megabytes and all).
pub fn toml_error_message(text: &str, error: &toml::de::Error) -> String {
    let at = error.span().map_or(String::new(), |span| {
        let before = text.get(..span.start).unwrap_or(text);
        let line = before.matches('\n').count() + 1;
        let column = before[before.rfind('\n').map_or(0, |i| i + 1)..]
            .chars()
            .count()
            + 1;
        format!("line {line}, column {column}: ")
    });
    let message = error
        .message()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    format!("{at}{}", shown_at_most(&message, PARSER_MESSAGE_CHARS))
}

/// The file of material `name` in the library folder `dir`.
pub fn find_material(dir: &Path, name: &str) -> Result<PathBuf, MaterialError> {
    let path = dir.join(format!("{name}.toml"));
    if path.is_file() {
        Ok(path)
    } else {
        Err(MaterialError::NotFound {
            name: name.to_owned(),
            dir: dir.to_owned(),
        })
    }
}

/// A library folder as read: its materials, and the `.toml` files that are not one.
#[derive(Debug, Default)]
pub struct Library {
    /// Every material, sorted by file name.
    pub materials: Vec<(PathBuf, Material)>,
    /// Each `.toml` file that does not load as a material (a user's notes, a broken entry), with
    /// why: skipped, so one stray file does not stop a fit or a listing of the others.
    pub skipped: Vec<(PathBuf, MaterialError)>,
}

impl Library {
    /// One warning per skipped file.
    pub fn warnings(&self) -> Vec<String> {
        self.skipped
            .iter()
            .map(|(_, error)| {
                let mut text = error.to_string();
                let mut source = std::error::Error::source(error);
                while let Some(cause) = source {
                    text = format!("{text}: {cause}");
                    source = cause.source();
                }
                format!("{text}; skipped, the library holds only material files")
            })
            .collect()
    }
}

/// Every material in a library folder, sorted by file name; `.toml` files that do not load are
/// skipped and reported in [`Library::skipped`]. Only an unreadable folder is an error.
pub fn list_library(dir: &Path) -> Result<Library, MaterialError> {
    let entries = std::fs::read_dir(dir).map_err(|source| MaterialError::Read {
        path: dir.to_owned(),
        source,
    })?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let mut library = Library::default();
    for path in paths {
        match Material::load(&path) {
            Ok(material) => library.materials.push((path, material)),
            Err(error) => library.skipped.push((path, error)),
        }
    }
    Ok(library)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Material {
        Material {
            name: "paper_paint".into(),
            tool_version: "irpol test".into(),
            model: MaterialModel::Grey(ModelSpec {
                distribution: SlopeDistribution::Cauchy { sigma: 0.1, q: 1.8 },
                shadowing: Shadowing::Smith,
                n: 1.2,
                k: 0.2,
                rho_d: 0.0,
                facet: Default::default(),
                rho_s: None,
                d: None,
                n_sub: None,
                d_c: None,
                d1: None,
                wavelength_um: 9.925,
            }),
            fit: None,
        }
    }

    /// A grey model of each term set at `wavelength_um`, with per-wavelength n, k and
    /// reflectances and the subsurface's d, n_sub, d_c shared (`per_wavelength_d` makes d
    /// differ).
    fn node(terms: ModelTerms, wavelength_um: f64, per_wavelength_d: bool) -> ModelSpec {
        let j = if wavelength_um < 1.0 { 0.0 } else { 1.0 };
        let subsurface = terms.body == Body::Subsurface;
        ModelSpec {
            distribution: SlopeDistribution::Cauchy {
                sigma: 0.62,
                q: 2.1,
            },
            shadowing: Shadowing::Smith,
            n: 1.38 - 0.03 * j,
            k: 0.04 + 0.01 * j,
            rho_d: if subsurface { 0.0 } else { 0.7 + 0.05 * j },
            facet: terms.facet_side,
            rho_s: subsurface.then_some(0.96 - 0.01 * j),
            d: subsurface.then_some(0.02 + if per_wavelength_d { 0.01 * j } else { 0.0 }),
            n_sub: subsurface.then_some(1.05),
            d_c: subsurface.then_some(-0.015),
            d1: subsurface.then_some(0.004),
            wavelength_um,
        }
    }

    /// docs/design.md §1.10 "spectral materials carry every term": a spectral material written
    /// and read back is, at each of its wavelengths, the grey material of that wavelength —
    /// facet side and every subsurface parameter included, whether shared or per wavelength.
    #[test]
    fn a_spectral_material_is_its_grey_twin_at_each_wavelength_for_every_term_set() {
        let terms = ModelTerms::ALL
            .into_iter()
            .chain([ModelTerms::new(FacetSide::Internal, Body::Depolarizer)]);
        for (terms, per_wavelength_d) in terms.flat_map(|t| [(t, false), (t, true)]) {
            let nodes = [
                node(terms, 0.351, per_wavelength_d),
                node(terms, 1.064, per_wavelength_d),
            ];
            let material = Material {
                name: "twin".into(),
                tool_version: "irpol test".into(),
                model: MaterialModel::Spectral(SpectralModel::from_nodes(&nodes, None)),
                fit: None,
            };
            let path = Path::new("twin.toml");
            let text = material.to_toml(path).unwrap();
            let read = Material::from_toml(&text, path).unwrap();
            for grey in &nodes {
                let spectral = read.at(grey.wavelength_um).unwrap();
                assert_eq!(&spectral, grey, "{terms} {text}");
                let (a, b) = (spectral.pbrdf().unwrap(), grey.pbrdf().unwrap());
                assert_eq!(a.facet_side(), terms.facet_side);
                for (ti, tr, phi) in [(0.0, 30.0, 180.0), (45.0, 60.0, 90.0), (75.0, 10.0, 0.0)] {
                    let (wi, wr) = (
                        crate::optics::Direction::from_degrees(ti, 0.0),
                        crate::optics::Direction::from_degrees(tr, phi),
                    );
                    let (ma, mb) = (a.mueller(&wi, &wr), b.mueller(&wi, &wr));
                    assert!((ma - mb).abs().max() <= 1e-12 * mb[(0, 0)], "{terms}");
                }
            }
        }
    }

    /// A subsurface key with a table of the wrong length is refused naming the key and the
    /// wavelength that has no value.
    #[test]
    fn a_spectral_term_key_missing_a_wavelength_is_refused_by_name() {
        let terms = ModelTerms::new(FacetSide::Internal, Body::Subsurface);
        let nodes = [node(terms, 0.351, true), node(terms, 1.064, true)];
        let material = Material {
            name: "short".into(),
            tool_version: "irpol test".into(),
            model: MaterialModel::Spectral(SpectralModel::from_nodes(&nodes, None)),
            fit: None,
        };
        let path = Path::new("short.toml");
        let text = material.to_toml(path).unwrap();
        let start = text.find("\nd = [").expect("d is a table");
        let end = start + text[start..].find(']').unwrap();
        let short = format!("{}\nd = [0.02{}", &text[..start], &text[end..]);
        let error = Material::from_toml(&short, path).unwrap_err().to_string();
        assert!(
            error.contains("d has 1 values for 2 wavelengths")
                && error.contains("1.064 µm has none"),
            "{error}"
        );
    }

    #[test]
    fn confidence_bounds_say_which_sides_the_data_bound() {
        let bound = |lower, upper| ConfidenceBound {
            lower,
            upper,
            confidence: 0.95,
        };
        assert_eq!(
            bound(None, Some(0.031234)).describe("k"),
            "k < 0.0312 (95 %)"
        );
        assert_eq!(bound(Some(1.2157), None).describe("n"), "n > 1.22 (95 %)");
        assert_eq!(
            bound(Some(0.8), Some(2.1)).describe("n"),
            "0.800 < n < 2.10 (95 % each side)"
        );
        assert_eq!(
            bound(None, None).describe("q"),
            "q not bounded in the search interval"
        );
    }

    /// Nothing non-finite reaches a written entry: TOML would take `nan` and `inf` as floats.
    #[test]
    fn a_non_finite_value_is_refused_by_key_and_nothing_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("paper_paint.toml");
        for (value, shown) in [(f64::NAN, "NaN"), (f64::INFINITY, "inf")] {
            let mut material = sample();
            if let MaterialModel::Grey(spec) = &mut material.model {
                spec.k = value;
            }
            let error = material.save(&path).unwrap_err();
            let text = error.to_string();
            assert!(matches!(error, MaterialError::NotFinite { .. }), "{text}");
            assert!(
                text.contains(&format!(
                    "not written: model.k = {shown} is not a finite number"
                )),
                "{text}"
            );
            assert!(!path.exists());
        }
        let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("fits/paper_paint.toml");
        let mut material = Material::load(&shipped).unwrap();
        material.fit.as_mut().unwrap().correlation[0][1] = f64::NAN;
        let text = material.to_toml(&path).unwrap_err().to_string();
        assert!(text.contains("fit.correlation[0][1] = NaN"), "{text}");
    }

    #[test]
    fn material_round_trips_through_toml() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("paper_paint.toml");
        sample().save(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.contains("distribution = \"cauchy\"") && text.contains("shadowing = \"smith\""),
            "{text}"
        );
        assert_eq!(Material::load(&path).unwrap(), sample());
        assert_eq!(find_material(dir.path(), "paper_paint").unwrap(), path);
        assert!(find_material(dir.path(), "nope")
            .unwrap_err()
            .to_string()
            .contains("'nope'"));
        assert_eq!(list_library(dir.path()).unwrap().materials.len(), 1);
    }

    /// A written material explains each field in `#` comments, and the
    /// comments change nothing that is read back.
    #[test]
    fn written_files_explain_every_field_and_read_back_unchanged() {
        let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("fits/paper_paint.toml");
        let mut material = Material::load(&shipped).unwrap();
        let source_data = material.fit.as_ref().unwrap().source_data.clone();
        assert!(source_data.is_some(), "the shipped fit records its data");
        material
            .fit
            .as_mut()
            .unwrap()
            .merged_sources
            .push(MergedSource {
                source: "measurements/paper_paint_repeat.csv".into(),
                source_sha256: "0".repeat(64),
                source_data,
                points: 12,
            });
        material.fit.as_mut().unwrap().profile_bounds.insert(
            "k".into(),
            ConfidenceBound {
                lower: None,
                upper: Some(0.03),
                confidence: 0.95,
            },
        );
        let path = Path::new("paper_paint.toml");
        let text = material.to_toml(path).unwrap();
        assert_eq!(Material::from_toml(&text, path).unwrap(), material);
        assert_eq!(
            Material::from_toml(&text, path)
                .unwrap()
                .to_toml(path)
                .unwrap(),
            text
        );
        assert!(
            text.contains(
                "# slope parameter σ (dimensionless): Gaussian rms slope per axis; \
                           Cauchy a = 2σ²"
            ) && text.contains("\nsigma = 0.0999"),
            "{text}"
        );
        let document: toml_edit::DocumentMut = text.parse().unwrap();
        assert_every_field_explained(document.as_table(), "");
    }

    /// The shipped fits were written by `irpol fit`: read and written again, they keep every
    /// byte, comments included (the comments come from the model's registry).
    #[test]
    fn shipped_fits_are_written_back_byte_for_byte() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fits");
        let library = list_library(&dir).unwrap();
        assert!(library.skipped.is_empty(), "{:?}", library.warnings());
        for (path, material) in library.materials {
            let text = std::fs::read_to_string(&path).unwrap();
            assert_eq!(material.to_toml(&path).unwrap(), text, "{}", path.display());
        }
    }

    fn is_comment(decor: &toml_edit::Decor) -> bool {
        decor
            .prefix()
            .and_then(|p| p.as_str())
            .is_some_and(|p| p.trim_start().starts_with('#'))
    }

    /// Every table has a comment block; every key of a table with fixed keys has its line.
    fn assert_every_field_explained(table: &toml_edit::Table, path: &str) {
        let keys = comments::explained_keys(path);
        for (key, item) in table.iter() {
            let path = [path, key]
                .iter()
                .filter(|p| !p.is_empty())
                .copied()
                .collect::<Vec<_>>();
            let path = path.join(".");
            let tables: Vec<&toml_edit::Table> = match item {
                toml_edit::Item::Table(t) => vec![t],
                toml_edit::Item::ArrayOfTables(a) => a.iter().collect(),
                _ => {
                    if let Some(keys) = &keys {
                        assert!(keys.contains(&key), "{path} has no comment");
                        assert!(is_comment(table.key(key).unwrap().leaf_decor()), "{path}");
                    }
                    continue;
                }
            };
            // An implicit table ([fit.profile_bounds] above [fit.profile_bounds.k]) has no header
            // to carry a comment; its subtables do.
            if !tables[0].is_implicit() {
                assert!(comments::has_block(&path), "[{path}] has no comment block");
                assert!(is_comment(tables[0].decor()), "[{path}]");
            }
            for t in tables {
                assert_every_field_explained(t, &path);
            }
        }
    }

    #[test]
    fn invalid_model_in_a_library_file_is_reported_with_its_path() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.toml");
        let text = toml::to_string(&sample())
            .unwrap()
            .replace("q = 1.8", "q = 0.5");
        std::fs::write(&path, text).unwrap();
        let message = Material::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("bad.toml") && message.contains("q = 0.5"),
            "{message}"
        );
        std::fs::write(&path, "name = 3").unwrap();
        assert!(Material::load(&path)
            .unwrap_err()
            .to_string()
            .contains("not a valid material"));
    }

    #[test]
    fn unknown_keys_wrong_wavelengths_and_stray_q_are_refused_on_one_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.toml");
        let good = toml::to_string(&sample()).unwrap();
        let cases = [
            (
                good.replace("rho_d = 0.0", "rho = 0.5"),
                "unknown field `rho`",
            ),
            (
                good.replace("wavelength_um = 9.925", "wavelength_um = -1.0"),
                "wavelength_um = -1 is outside",
            ),
            (
                good.replace("wavelength_um = 9.925", "wavelength_um = nan"),
                "wavelength_um = NaN is outside",
            ),
            (
                good.replace("distribution = \"cauchy\"", "distribution = \"gaussian\""),
                "q applies to the cauchy distribution only",
            ),
            (format!("{good}\nextra = 1\n"), "unknown field `extra`"),
            (
                good.replace("name = \"paper_paint\"", "name = \"a\\u0007b\""),
                "name 'a\\u{7}b' contains a control character",
            ),
            (
                good.replace("name = ", "\"\\u001b[2J\" = 1\nname = "),
                "unknown field `\\u{1b}[2J`",
            ),
            (
                good.replace("name = ", "\"\u{1b}[2J\" = 1\nname = "),
                "line 1, column",
            ),
        ];
        for (text, needle) in cases {
            std::fs::write(&path, &text).unwrap();
            let message = Material::load(&path).unwrap_err().to_string();
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
            assert!(
                !message.contains('\n') && !message.contains('\u{1b}'),
                "{message:?}"
            );
        }
    }
}
