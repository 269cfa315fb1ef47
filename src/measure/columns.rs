//! The header row of a measurement CSV: which quantity each column holds (docs/design.md §2.1).
//! Required: theta_i_deg, theta_r_deg, m00. Optional: phi_i_deg, phi_r_deg, wavelength_um, any of
//! m01…m33 and their uncertainties u_m00…u_m33. Names are case-sensitive.

use super::error::{MeasureErrorKind, Refusal};
use super::table_file::fields_of;
use super::MUELLER_ELEMENT_NAMES;
use crate::table_text::{ColumnMap, Field, HeaderProblem};
use crate::text::shown;

const THETA_I: &str = "theta_i_deg";
const PHI_I: &str = "phi_i_deg";
const THETA_R: &str = "theta_r_deg";
const PHI_R: &str = "phi_r_deg";
const WAVELENGTH: &str = "wavelength_um";
const UNCERTAINTY_PREFIX: &str = "u_";

/// What one column of the file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Quantity {
    ThetaI,
    PhiI,
    ThetaR,
    PhiR,
    Wavelength,
    /// Mueller element, row-major index r*4+c.
    Element(usize),
    /// Absolute 1-σ uncertainty of a Mueller element, sr⁻¹.
    Uncertainty(usize),
}

impl Quantity {
    fn from_name(name: &str) -> Option<Self> {
        match name {
            THETA_I => Some(Self::ThetaI),
            PHI_I => Some(Self::PhiI),
            THETA_R => Some(Self::ThetaR),
            PHI_R => Some(Self::PhiR),
            WAVELENGTH => Some(Self::Wavelength),
            _ => match name.strip_prefix(UNCERTAINTY_PREFIX) {
                Some(element) => super::mueller_index(element).map(Self::Uncertainty),
                None => super::mueller_index(name).map(Self::Element),
            },
        }
    }
}

/// The columns of a §2.1 file, in file order, and the Mueller elements they hold.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NativeColumns {
    pub quantities: Vec<Quantity>,
    /// Column names as written, for messages.
    pub names: Vec<String>,
    /// Mueller indices present, ascending (so m00 is first).
    pub elements: Vec<usize>,
}

impl NativeColumns {
    pub(crate) fn has(&self, quantity: Quantity) -> bool {
        self.quantities.contains(&quantity)
    }

    /// Position of Mueller element `index` within [`NativeColumns::elements`].
    pub(crate) fn slot(&self, index: usize) -> Option<usize> {
        self.elements.iter().position(|&e| e == index)
    }
}

/// Reads the header row (1-based line `line`) from its fields.
pub(crate) fn parse_header_row(line: u64, fields: &[Field<'_>]) -> Result<NativeColumns, Refusal> {
    let map = ColumnMap::of_header(line, fields, Quantity::from_name, false)
        .map_err(|refusal| refusal.map(header_problem))?;
    // Every name is known (unknown ones were refused).
    let quantities: Vec<Quantity> = map.known().iter().flatten().copied().collect();
    check_required_columns(line, &quantities)?;
    check_uncertainty_columns(line, fields, &quantities)?;
    let mut elements: Vec<usize> = quantities
        .iter()
        .filter_map(|q| match q {
            Quantity::Element(index) => Some(*index),
            _ => None,
        })
        .collect();
    elements.sort_unstable();
    Ok(NativeColumns {
        quantities,
        names: map.names().to_vec(),
        elements,
    })
}

/// The header row: its line, its columns and the column where m00 stands.
pub(crate) struct HeaderRow {
    pub line: u64,
    pub columns: NativeColumns,
    pub m00_column: u64,
}

impl HeaderRow {
    /// The header row `line` (line `number`) of a file whose metadata gives its wavelength or
    /// not (`header_wavelength`): without it, the columns must.
    pub(crate) fn parse(number: u64, line: &str, header_wavelength: bool) -> Result<Self, Refusal> {
        let fields = fields_of(number, line)?;
        let columns = parse_header_row(number, &fields)?;
        if !header_wavelength && !columns.has(Quantity::Wavelength) {
            return Err(Refusal::new(number, 1, MeasureErrorKind::NoWavelength));
        }
        let m00_column = fields
            .iter()
            .zip(&columns.quantities)
            .find(|(_, q)| **q == Quantity::Element(0))
            .map_or(1, |(field, _)| field.column);
        Ok(Self {
            line: number,
            columns,
            m00_column,
        })
    }
}

/// A header problem in §2.1's words.
fn header_problem(problem: HeaderProblem) -> MeasureErrorKind {
    match problem {
        HeaderProblem::Token(token) => MeasureErrorKind::Token(token),
        HeaderProblem::Empty => MeasureErrorKind::EmptyColumnName,
        HeaderProblem::Unknown(name) => MeasureErrorKind::UnknownColumn {
            name: shown(&name),
            hint: unknown_column_hint(&name),
        },
        HeaderProblem::Duplicate { name, first_column } => {
            MeasureErrorKind::DuplicateColumn { name, first_column }
        }
    }
}

/// Refuses a header without theta_i_deg, theta_r_deg or m00 (pointing at its first column).
fn check_required_columns(line: u64, quantities: &[Quantity]) -> Result<(), Refusal> {
    for (quantity, name) in [
        (Quantity::ThetaI, THETA_I),
        (Quantity::ThetaR, THETA_R),
        (Quantity::Element(0), MUELLER_ELEMENT_NAMES[0]),
    ] {
        if !quantities.contains(&quantity) {
            return Err(Refusal::new(
                line,
                1,
                MeasureErrorKind::MissingColumn {
                    name: name.to_string(),
                },
            ));
        }
    }
    Ok(())
}

/// Refuses an uncertainty column whose element has no column.
fn check_uncertainty_columns(
    line: u64,
    fields: &[Field<'_>],
    quantities: &[Quantity],
) -> Result<(), Refusal> {
    for (field, quantity) in fields.iter().zip(quantities) {
        if let Quantity::Uncertainty(index) = *quantity {
            if !quantities.contains(&Quantity::Element(index)) {
                return Err(Refusal::new(
                    line,
                    field.column,
                    MeasureErrorKind::UncertaintyWithoutElement {
                        name: field.text.to_string(),
                        element: MUELLER_ELEMENT_NAMES[index].to_string(),
                    },
                ));
            }
        }
    }
    Ok(())
}

/// A hint that turns a near miss into a one-edit fix.
fn unknown_column_hint(name: &str) -> String {
    let geometry = [THETA_I, PHI_I, THETA_R, PHI_R, WAVELENGTH];
    let all_names = geometry.into_iter().map(str::to_string).chain(
        MUELLER_ELEMENT_NAMES
            .iter()
            .flat_map(|m| [m.to_string(), format!("{UNCERTAINTY_PREFIX}{m}")]),
    );
    for known in all_names {
        if known.eq_ignore_ascii_case(name) {
            return format!(" (column names are case-sensitive: did you mean '{known}'?)");
        }
    }
    // A geometry name without its unit suffix or with another unit: theta_i, wavelength_nm.
    let without_unit = |n: &str| n.rsplit_once('_').map_or(n.to_string(), |(s, _)| s.into());
    for known in geometry {
        if without_unit(known) == name || without_unit(known) == without_unit(name) {
            return format!(" (did you mean '{known}'? angles are in degrees, wavelengths in µm)");
        }
    }
    let element = name.strip_prefix(UNCERTAINTY_PREFIX).unwrap_or(name);
    if element.starts_with('m') {
        return " (Mueller elements are m00…m33: row then column, each 0–3)".to_string();
    }
    format!(
        " (expected {THETA_I}, {PHI_I}, {THETA_R}, {PHI_R}, {WAVELENGTH}, m00…m33, u_m00…u_m33)"
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table_text::split_fields;

    fn layout(header: &str) -> Result<NativeColumns, Refusal> {
        parse_header_row(4, &split_fields(4, header).unwrap())
    }

    #[test]
    fn columns_map_to_quantities_and_elements_are_sorted() {
        let layout = layout("m11, theta_i_deg ,theta_r_deg,m00,u_m11,wavelength_um,m01").unwrap();
        assert_eq!(layout.elements, vec![0, 1, 5]);
        assert_eq!(layout.quantities[0], Quantity::Element(5));
        assert_eq!(layout.quantities[4], Quantity::Uncertainty(5));
        assert_eq!(layout.names[1], "theta_i_deg");
        assert_eq!(layout.slot(5), Some(2));
        assert!(layout.has(Quantity::Wavelength));
        assert!(!layout.has(Quantity::PhiI));
    }

    #[test]
    fn header_problems_point_at_the_column() {
        let at = |header: &str| {
            let refusal = layout(header).unwrap_err();
            (refusal.line, refusal.column, refusal.kind.to_string())
        };
        assert_eq!(
            at("theta_i_deg,theta_r_deg,M00"),
            (
                4,
                25,
                "unknown column 'M00' (column names are case-sensitive: did you mean 'm00'?)"
                    .into()
            )
        );
        assert_eq!(
            at("theta_i,theta_r_deg,m00").2,
            "unknown column 'theta_i' (did you mean 'theta_i_deg'? angles are in degrees, wavelengths in µm)"
        );
        assert!(at("theta_i_deg,theta_r_deg,m00,wavelength_nm")
            .2
            .contains("did you mean 'wavelength_um'?"));
        assert!(at("theta_i_deg,theta_r_deg,m00,m40").2.contains("m00…m33"));
        assert_eq!(at("theta_i_deg,theta_r_deg,m00,m00").1, 29);
        assert_eq!(
            at("theta_i_deg,m00").2,
            "missing required column 'theta_r_deg'"
        );
        assert_eq!(
            at("theta_i_deg,theta_r_deg,m00,u_m12").2,
            "column 'u_m12' is the uncertainty of 'm12', but there is no 'm12' column"
        );
        assert_eq!(at("theta_i_deg;theta_r_deg;m00").1, 12);
        assert_eq!(
            at("theta_i_deg,,m00").2,
            "empty column name (a doubled or trailing ',' in the header row)"
        );
    }
}
