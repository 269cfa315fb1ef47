//! The layout TOML as written (docs/design.md §2.8): every table denies unknown keys, so a
//! misspelt key is refused by name instead of silently keeping its default.

use std::collections::BTreeMap;
use std::ops::Range;

use serde::Deserialize;
use toml::Spanned;

use super::{AngleUnit, ColumnRoles, Conventions, MuellerBasis, SpecularAzimuth, UncertaintyModel};
use crate::measure::error::{MeasureErrorKind, Refusal};
use crate::measure::{mueller_index, MUELLER_ELEMENT_NAMES};
use crate::text::{shown, shown_at_most};

/// Characters of the TOML parser's message kept in ours.
const PARSER_MESSAGE_CHARS: usize = 300;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLayout {
    columns: RawColumns,
    #[serde(default)]
    conventions: RawConventions,
    #[serde(default)]
    uncertainty: RawUncertainty,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawColumns {
    theta_i_deg: Spanned<String>,
    phi_i_deg: Option<Spanned<String>>,
    theta_r_deg: Spanned<String>,
    phi_r_deg: Option<Spanned<String>>,
    wavelength_um: Option<Spanned<String>>,
    m00: Option<Spanned<String>>,
    /// A pattern string or a table of element names; told apart by hand for a clear message.
    elements: Option<Spanned<toml::Value>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawConventions {
    index_base: Option<Spanned<i64>>,
    normalized: Option<Spanned<bool>>,
    signed_angles: Option<bool>,
    specular_phi_r: Option<RawSpecular>,
    angle_unit: Option<RawAngleUnit>,
    mueller_convention: Option<RawBasis>,
}

#[derive(Deserialize, Clone, Copy)]
enum RawSpecular {
    #[serde(rename = "phi_i + 180")]
    OppositeIncidence,
    #[serde(rename = "phi_i")]
    SameAsIncidence,
}

#[derive(Deserialize, Clone, Copy)]
enum RawAngleUnit {
    #[serde(rename = "deg")]
    Degrees,
    #[serde(rename = "rad")]
    Radians,
}

#[derive(Deserialize, Clone, Copy)]
enum RawBasis {
    #[serde(rename = "psps")]
    Psps,
    #[serde(rename = "xyxy")]
    Xyxy,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawUncertainty {
    model: Option<RawModel>,
}

#[derive(Deserialize, Clone, Copy)]
enum RawModel {
    #[serde(rename = "estimate")]
    Estimate,
    #[serde(rename = "fixed")]
    Fixed,
}

/// A layout's text, validated: the roles, the conventions and the uncertainty model.
pub(super) fn parse_layout(
    text: &str,
) -> Result<(ColumnRoles, Conventions, UncertaintyModel), Refusal> {
    let raw: RawLayout = toml::from_str(text).map_err(|e| syntax_refusal(text, &e))?;
    let conventions = conventions(text, &raw.conventions)?;
    let columns = column_roles(text, raw.columns, &raw.conventions, conventions)?;
    let uncertainty = match raw.uncertainty.model {
        Some(RawModel::Estimate) => UncertaintyModel::Estimate,
        Some(RawModel::Fixed) | None => UncertaintyModel::Fixed,
    };
    Ok((columns, conventions, uncertainty))
}

fn conventions(text: &str, raw: &RawConventions) -> Result<Conventions, Refusal> {
    let index_base = match &raw.index_base {
        None => 0,
        Some(base) if matches!(*base.get_ref(), 0 | 1) => *base.get_ref() as u8,
        Some(base) => {
            return Err(value_refusal(
                text,
                base.span(),
                "[conventions] index_base",
                format!(
                    "{} is not an index base: 0 (element names m00…m33) or 1 (m11…m44)",
                    base.get_ref()
                ),
            ))
        }
    };
    Ok(Conventions {
        index_base,
        normalized: raw.normalized.as_ref().is_some_and(|n| *n.get_ref()),
        signed_angles: raw.signed_angles.unwrap_or(true),
        specular_phi_r: match raw.specular_phi_r {
            Some(RawSpecular::SameAsIncidence) => SpecularAzimuth::SameAsIncidence,
            Some(RawSpecular::OppositeIncidence) | None => SpecularAzimuth::OppositeIncidence,
        },
        angle_unit: match raw.angle_unit {
            Some(RawAngleUnit::Radians) => AngleUnit::Radians,
            Some(RawAngleUnit::Degrees) | None => AngleUnit::Degrees,
        },
        mueller_convention: match raw.mueller_convention {
            Some(RawBasis::Xyxy) => MuellerBasis::Xyxy,
            Some(RawBasis::Psps) | None => MuellerBasis::Psps,
        },
    })
}

fn column_roles(
    text: &str,
    raw: RawColumns,
    raw_conventions: &RawConventions,
    conventions: Conventions,
) -> Result<ColumnRoles, Refusal> {
    let (mut elements, pattern) = match &raw.elements {
        None => (BTreeMap::new(), None),
        Some(value) => element_columns(text, value, conventions.index_base)?,
    };
    // The m00 column: named, else the element pattern's or table's own m00.
    let pattern_m00 = elements.remove(&0);
    let elements_span = raw.elements.as_ref().map_or(0..0, |e| e.span());
    let m00 = match (raw.m00.clone(), pattern_m00) {
        (Some(named), _) => named,
        (None, Some(from_elements)) if !conventions.normalized => {
            Spanned::new(elements_span.clone(), from_elements)
        }
        (None, _) => {
            let (span, message) = match &raw_conventions.normalized {
                Some(normalized) if conventions.normalized => (
                    normalized.span(),
                    "normalized = true multiplies the elements by m00, but [columns] names no \
                     m00 column: add m00 = \"<column of the unpolarized BRDF>\"",
                ),
                _ => (
                    0..0,
                    "[columns] names no m00 column (the unpolarized BRDF, sr⁻¹, required): \
                     add m00 = \"<column>\"",
                ),
            };
            return Err(value_refusal(
                text,
                span,
                "[columns] m00",
                message.to_string(),
            ));
        }
    };
    let mut roles: Vec<(&'static str, &Spanned<String>)> = vec![
        ("theta_i_deg", &raw.theta_i_deg),
        ("theta_r_deg", &raw.theta_r_deg),
    ];
    let optional = [
        ("phi_i_deg", &raw.phi_i_deg),
        ("phi_r_deg", &raw.phi_r_deg),
        ("wavelength_um", &raw.wavelength_um),
    ];
    roles.extend(
        optional
            .iter()
            .filter_map(|(role, c)| c.as_ref().map(|c| (*role, c))),
    );
    roles.push(("m00", &m00));
    let element_roles: Vec<(&'static str, Spanned<String>)> = elements
        .iter()
        .map(|(&i, c)| {
            (
                MUELLER_ELEMENT_NAMES[i],
                Spanned::new(elements_span.clone(), c.clone()),
            )
        })
        .collect();
    roles.extend(element_roles.iter().map(|(role, c)| (*role, c)));
    check_one_role_per_column(text, &roles)?;
    let inner = |c: Option<Spanned<String>>| c.map(Spanned::into_inner);
    Ok(ColumnRoles {
        theta_i: raw.theta_i_deg.into_inner(),
        phi_i: inner(raw.phi_i_deg),
        theta_r: raw.theta_r_deg.into_inner(),
        phi_r: inner(raw.phi_r_deg),
        wavelength: inner(raw.wavelength_um),
        m00: m00.into_inner(),
        elements,
        pattern,
    })
}

/// Refuses a column named for two roles (θ_i and θ_r both "thetar" would read every row as
/// specular), at the second role's value, naming both roles and the column.
fn check_one_role_per_column(
    text: &str,
    roles: &[(&'static str, &Spanned<String>)],
) -> Result<(), Refusal> {
    for (k, (role, column)) in roles.iter().enumerate() {
        let earlier = roles[..k]
            .iter()
            .find(|(_, c)| c.get_ref() == column.get_ref());
        if let Some((first_role, _)) = earlier {
            let (line, column_number) = line_and_column(text, column.span().start);
            return Err(Refusal::new(
                line,
                column_number,
                MeasureErrorKind::LayoutColumnTwoRoles {
                    column: shown(column.get_ref()),
                    first_role,
                    second_role: role,
                },
            ));
        }
    }
    Ok(())
}

/// The file's column name of each Mueller element, by row-major element index.
type ElementColumns = BTreeMap<usize, String>;

/// The column of each element named by `[columns] elements`: a pattern over `{i}` and `{j}`
/// (counted from `index_base`), or a table keyed by irpol's names m00…m33.
fn element_columns(
    text: &str,
    value: &Spanned<toml::Value>,
    index_base: u8,
) -> Result<(ElementColumns, Option<String>), Refusal> {
    let refuse = |message: String| value_refusal(text, value.span(), "[columns] elements", message);
    match value.get_ref() {
        toml::Value::String(pattern) => {
            if !(pattern.contains("{i}") && pattern.contains("{j}")) {
                return Err(refuse(format!(
                    "the pattern '{}' needs both {{i}} (the row) and {{j}} (the column), e.g. \
                     \"M{{i}}{{j}}\"",
                    shown(pattern)
                )));
            }
            let base = usize::from(index_base);
            let names = (0..16)
                .map(|index| {
                    let name = pattern
                        .replace("{i}", &(index / 4 + base).to_string())
                        .replace("{j}", &(index % 4 + base).to_string());
                    (index, name)
                })
                .collect();
            Ok((names, Some(pattern.clone())))
        }
        toml::Value::Table(table) => {
            let mut names = BTreeMap::new();
            for (key, column) in table {
                let Some(index) = mueller_index(key) else {
                    return Err(refuse(format!(
                        "'{}' is not an element name: the table's keys are irpol's m00…m33 \
                         ({} … {})",
                        shown(key),
                        MUELLER_ELEMENT_NAMES[0],
                        MUELLER_ELEMENT_NAMES[15]
                    )));
                };
                let toml::Value::String(column) = column else {
                    return Err(refuse(format!(
                        "{key} must be a column name in quotes, not {column}"
                    )));
                };
                names.insert(index, column.clone());
            }
            Ok((names, None))
        }
        other => Err(refuse(format!(
            "expected a pattern such as \"M{{i}}{{j}}\" or a table of element names, not {other}"
        ))),
    }
}

/// A refusal at the start of `span` in the layout's text (line 1 column 1 for an empty span at 0).
fn value_refusal(text: &str, span: Range<usize>, key: &'static str, message: String) -> Refusal {
    let (line, column) = line_and_column(text, span.start);
    Refusal::new(line, column, MeasureErrorKind::LayoutValue { key, message })
}

fn syntax_refusal(text: &str, error: &toml::de::Error) -> Refusal {
    let (line, column) = error
        .span()
        .map_or((1, 1), |span| line_and_column(text, span.start));
    let message = error
        .message()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    Refusal::new(
        line,
        column,
        MeasureErrorKind::LayoutSyntax {
            message: shown_at_most(&message, PARSER_MESSAGE_CHARS),
        },
    )
}

/// 1-based line and character column of a byte offset.
fn line_and_column(text: &str, offset: usize) -> (u64, u64) {
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() as u64 + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[line_start..].chars().count() as u64 + 1)
}
