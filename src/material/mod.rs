//! The material library: one TOML file per material (docs/design.md §2.2) holding the pBRDF model, how it
//! was fitted, and its uncertainties. Written atomically; read by `render` and `report`.

mod comments;
mod fit_record;
mod library;
pub mod pbsdf_export;
mod raw;
mod scene_materials;
mod spectral;

pub use fit_record::{
    pinned_at_bound, AlternativeFit, ConfidenceBound, DispersionChoice, FitRecord, MergedSource,
    WavelengthQuality, MISFIT_REDUCED_CHI2, STRONG_CORRELATION, ZERO_AT_BOUND,
};
pub use library::{find_material, list_library, Library};
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
    FacetSide, LobeKeys, ModelError, ModelTerms, Parameter, Pbrdf, Shadowing, SlopeDistribution,
    Subsurface,
};
use crate::text::{number, shown, shown_at_most};
use serde::{Deserialize, Serialize};
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
    /// The subsurface lobes' keys (ρ_s, d, n_sub, d_c, d1 of docs/design.md §1.10), where
    /// written: ρ_s and d both present or both absent; n_sub absent is n, d_c absent d, d1 0.
    #[serde(flatten)]
    pub lobe_keys: LobeKeys<f64>,
    pub wavelength_um: f64,
}

impl ModelSpec {
    /// The value of a model parameter; `None` for a slope parameter the distribution does not
    /// have (q of the Gaussian) and a lobe's parameter of a model without that lobe.
    pub fn parameter(&self, parameter: Parameter) -> Option<f64> {
        match parameter {
            Parameter::N => Some(self.n),
            Parameter::K => Some(self.k),
            Parameter::RhoD => Some(self.rho_d),
            lobe if lobe.is_lobe() => self
                .subsurface_lobes()
                .iter()
                .find_map(|s| s.value(lobe, self.n)),
            slope => self.distribution.parameter(slope),
        }
    }

    /// The model's terms (docs/design.md §1.10).
    pub fn terms(&self) -> ModelTerms {
        ModelTerms::new(self.facet, self.lobe_keys.body())
    }

    /// The subsurface lobes the model has ([`LobeKeys::lobes`]; keys of a lobe without its
    /// ρ_s, refused by every reader, describe none).
    pub fn subsurface_lobes(&self) -> Vec<Subsurface> {
        self.lobe_keys.lobes().unwrap_or_default()
    }

    pub fn pbrdf(&self) -> Result<Pbrdf, ModelError> {
        Pbrdf::new(
            self.distribution,
            self.shadowing,
            RefractiveIndex::new(self.n, self.k),
            self.rho_d,
        )?
        .with_volume(self.facet, self.subsurface_lobes())
    }
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
                lobe_keys: Default::default(),
                wavelength_um: 9.925,
            }),
            fit: None,
        }
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
