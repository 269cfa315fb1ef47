//! `# key: value` header lines of a measurement CSV (docs/design.md §2.1). Every such line is metadata;
//! any other `#` line is a comment. Three keys have a meaning for irpol and are validated:
//! `material`, `wavelength_um` and `mueller_convention`.

use std::collections::BTreeMap;

use super::error::{MeasureErrorKind, Refusal};
use crate::optics::{MAX_WAVELENGTH_UM, MIN_WAVELENGTH_UM};
use crate::text::shown;

const MATERIAL: &str = "material";
const WAVELENGTH: &str = "wavelength_um";
const CONVENTION: &str = "mueller_convention";

/// The metadata key by which a measurement file names its layout (docs/design.md §2.8).
pub const LAYOUT_KEY: &str = "layout";

/// The wavelength given by a `# wavelength_um:` line, with its text and line for messages.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct HeaderWavelength {
    pub um: f64,
    pub text: String,
    pub line: u64,
}

/// All metadata of a file, with the meaningful keys validated.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Metadata {
    pub entries: BTreeMap<String, String>,
    pub material: Option<String>,
    pub wavelength: Option<HeaderWavelength>,
    /// Line of each key, to name the first one when a key comes twice.
    line_of: BTreeMap<String, u64>,
}

/// A `# key: value` line split into key, value and the 1-based column where the value starts
/// (where it would start, if empty). `None` for a comment: a key is one word of ASCII letters,
/// digits, `_`, `-` or `.`, so prose such as `# measured at 10:30` stays a comment.
pub(crate) fn split_metadata_line(line: &str) -> Option<(&str, &str, u64)> {
    let after_hash = line.trim_start().strip_prefix('#')?;
    let (key, rest) = after_hash.split_once(':')?;
    let key = key.trim();
    let is_key_char = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.');
    if key.is_empty() || !key.chars().all(is_key_char) {
        return None;
    }
    let value = rest.trim();
    let value_start = if value.is_empty() {
        line.len() - rest.len()
    } else {
        line.len() - rest.trim_start().len()
    };
    let column = line[..value_start].chars().count() as u64 + 1;
    Some((key, value, column))
}

impl Metadata {
    /// Records one `# key: value` line (1-based `line`), validating the keys irpol uses.
    pub(crate) fn add(
        &mut self,
        line: u64,
        key: &str,
        value: &str,
        value_column: u64,
    ) -> Result<(), Refusal> {
        let refuse = |kind| Err(Refusal::new(line, value_column, kind));
        if let Some(&first_line) = self.line_of.get(key) {
            // Refused rather than overwritten: metadata is provenance and must not be lost.
            return Err(Refusal::new(
                line,
                1,
                MeasureErrorKind::DuplicateHeaderKey {
                    key: key.to_string(),
                    first_line,
                },
            ));
        }
        self.line_of.insert(key.to_string(), line);
        let known = [MATERIAL, WAVELENGTH, CONVENTION].contains(&key);
        if known && value.is_empty() {
            return refuse(MeasureErrorKind::EmptyHeaderValue {
                key: key.to_string(),
            });
        }
        match key {
            MATERIAL => {
                if let Some(reason) = unusable_file_name(value) {
                    return refuse(MeasureErrorKind::BadMaterialName {
                        name: shown(value),
                        reason,
                    });
                }
                self.material = Some(value.to_string());
            }
            WAVELENGTH => match value.parse::<f64>() {
                Ok(um) if um.is_finite() && um > 0.0 && !wavelength_in_range(um) => {
                    return refuse(MeasureErrorKind::WavelengthOutOfRange {
                        place: "header 'wavelength_um'".to_string(),
                        value: shown(value),
                    });
                }
                Ok(um) if um.is_finite() && um > 0.0 => {
                    self.wavelength = Some(HeaderWavelength {
                        um,
                        text: value.to_string(),
                        line,
                    });
                }
                _ => {
                    return refuse(MeasureErrorKind::BadHeaderWavelength {
                        value: shown(value),
                    });
                }
            },
            // Only SCATMECH's psps Stokes convention is modelled (docs/design.md §1.3); the spelling's
            // case carries no meaning, so `PSPS` is the same convention.
            CONVENTION if !value.eq_ignore_ascii_case("psps") => {
                return refuse(MeasureErrorKind::UnsupportedConvention {
                    value: shown(value),
                });
            }
            _ => {}
        }
        self.entries.insert(key.to_string(), value.to_string());
        Ok(())
    }
}

/// Whether a positive wavelength is one irpol models ([`crate::optics::MIN_WAVELENGTH_UM`] to
/// [`crate::optics::MAX_WAVELENGTH_UM`]).
pub(crate) fn wavelength_in_range(um: f64) -> bool {
    (MIN_WAVELENGTH_UM..=MAX_WAVELENGTH_UM).contains(&um)
}

/// Longest material name, in bytes (UTF-8), that a header may give. The name becomes the files
/// `<material>.toml`, `.png`, `.svg` and their temporaries `.<material>.toml.<pid>.tmp`, which must
/// stay within the 255-byte file names of common filesystems.
pub const MAX_MATERIAL_NAME_BYTES: usize = 200;

/// Why a material name cannot become `fits/<material>.toml` (docs/design.md §2.2), if it cannot: a
/// name from a file header must not reach outside the output folder, nor be longer than a file
/// name may be.
fn unusable_file_name(name: &str) -> Option<String> {
    if name.len() > MAX_MATERIAL_NAME_BYTES {
        return Some(format!(
            "it is {} bytes long; at most {MAX_MATERIAL_NAME_BYTES}, as it names the files \
             <material>.toml, .png and .svg",
            name.len()
        ));
    }
    if let Some(c) = name
        .chars()
        .find(|&c| matches!(c, '/' | '\\') || c.is_control())
    {
        return Some(format!("contains '{}'", c.escape_default()));
    }
    if name.starts_with('.') {
        return Some("starts with '.'".to_string());
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_value_lines_are_split_and_prose_is_a_comment() {
        assert_eq!(
            split_metadata_line("# material: gloss_paint"),
            Some(("material", "gloss_paint", 13))
        );
        assert_eq!(
            split_metadata_line("#wavelength_um:9.925"),
            Some(("wavelength_um", "9.925", 16))
        );
        assert_eq!(split_metadata_line("# note:"), Some(("note", "", 8)));
        assert_eq!(split_metadata_line("# measured at 10:30"), None);
        assert_eq!(split_metadata_line("# plain comment"), None);
        assert_eq!(split_metadata_line("#: nothing"), None);
    }

    #[test]
    fn value_column_counts_characters() {
        // A no-break space is two bytes but one column.
        assert_eq!(split_metadata_line("\u{a0}# k: v"), Some(("k", "v", 7)));
        // Keys are ASCII words.
        assert_eq!(split_metadata_line("# λ-note: x"), None);
        assert_eq!(
            split_metadata_line("# op: x σ, y"),
            Some(("op", "x σ, y", 7))
        );
    }

    fn add_all(lines: &[&str]) -> Result<Metadata, Refusal> {
        let mut metadata = Metadata::default();
        for (i, line) in lines.iter().enumerate() {
            let (key, value, column) = split_metadata_line(line).unwrap();
            metadata.add(i as u64 + 1, key, value, column)?;
        }
        Ok(metadata)
    }

    #[test]
    fn known_keys_are_validated() {
        let metadata = add_all(&[
            "# material: gloss_paint",
            "# wavelength_um: 9.925",
            "# mueller_convention: PSPS",
            "# operator: J. Doe",
        ])
        .unwrap();
        assert_eq!(metadata.material.as_deref(), Some("gloss_paint"));
        let wavelength = metadata.wavelength.unwrap();
        assert_eq!((wavelength.um, wavelength.line), (9.925, 2));
        assert_eq!(metadata.entries.len(), 4);
        assert_eq!(metadata.entries["operator"], "J. Doe");

        let refusal = add_all(&["# wavelength_um: 0"]).unwrap_err();
        assert_eq!((refusal.line, refusal.column), (1, 18));
        let refusal = add_all(&["# a: 1", "# a: 2"]).unwrap_err();
        assert_eq!(
            refusal.kind,
            MeasureErrorKind::DuplicateHeaderKey {
                key: "a".into(),
                first_line: 1
            }
        );
        assert!(add_all(&["# material: ../evil"]).is_err());
        assert!(add_all(&["# material: .hidden"]).is_err());
        assert!(add_all(&["# mueller_convention: spsp"]).is_err());
        assert!(add_all(&["# material:"]).is_err());
        assert!(add_all(&["# remark:"]).is_ok());
    }
}
