//! Reading a table through a [`Layout`] (docs/design.md §2.8): the header row resolved to
//! roles, each row converted to docs/design.md §2.1's meaning, the rows split by wavelength.
//! Refusals point at `file:line:column` like the §2.1 reader's, and say what to fix.

use std::collections::BTreeMap;
use std::path::Path;

use sha2::{Digest, Sha256};

use super::basis::{mixed_with, xyxy_to_psps};
use super::uncertainty::apply_uncertainty_model;
use super::{AngleUnit, Layout, MuellerBasis, SpecularAzimuth};
use crate::measure::error::{MeasureError, MeasureErrorKind, Refusal};
use crate::measure::metadata::{split_metadata_line, HeaderWavelength, Metadata};
use crate::measure::table_file::{
    check_width, decode_utf8, fields_of, hex, material_of, parse_number, row_wavelength,
    table_lines, FileFacts, WavelengthGroups,
};
use crate::measure::table_file::{element_value_refusal, wavelength_refusal};
use crate::measure::units::{check_degrees, AngleReading};
use crate::measure::{MeasurementRow, MeasurementSet, MUELLER_ELEMENT_NAMES};
use crate::pbrdf::{fold_signed_zenith, signed_zenith_note};
use crate::table_text::{wrong_delimiter, Field};
use crate::text::shown;

/// irpol's azimuths when the layout names no column for them (docs/design.md §2.1).
const DEFAULT_PHI_I_DEG: f64 = 0.0;
const DEFAULT_PHI_R_DEG: f64 = 180.0;

/// The field index of each role in the header row.
struct Resolved {
    theta_i: usize,
    phi_i: Option<usize>,
    theta_r: usize,
    phi_r: Option<usize>,
    wavelength: Option<usize>,
    /// (Mueller index, field index), ascending by Mueller index, m00 first.
    elements: Vec<(usize, usize)>,
    /// The header's names, by field index.
    names: Vec<String>,
}

/// Everything read from the table, before it is split by wavelength.
struct ParsedTable {
    metadata: Metadata,
    elements: Vec<usize>,
    /// The rows by wavelength (the header's, or each row's own).
    groups: WavelengthGroups,
    folded_incident: usize,
    folded_detector: usize,
    unused_columns: Vec<String>,
}

pub(super) fn parse_table(
    source: &Path,
    bytes: &[u8],
    layout: &Layout,
    angles: AngleReading,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    let sha256 = hex(&Sha256::digest(bytes));
    let text = decode_utf8(bytes).map_err(|r| r.in_file(source))?;
    let parsed = parse_text(text, layout).map_err(|r| r.in_file(source))?;
    let angle_note = check_layout_angles(source, parsed.groups.rows(), layout, angles)
        .map_err(|r| r.in_file(source))?;
    build_sets(source, sha256, parsed, layout, angle_note).map_err(|r| r.in_file(source))
}

/// The table's angles against the layout's `angle_unit` and `--angles`: radians declared as
/// degrees are refused unless `--angles degrees` says they are degrees (then a note); a layout
/// states its unit, so `--angles` naming the other one is refused.
fn check_layout_angles<'a>(
    source: &Path,
    rows: impl Iterator<Item = MeasurementRow<'a>> + Clone,
    layout: &Layout,
    angles: AngleReading,
) -> Result<Option<String>, Refusal> {
    let layout_file = crate::text::path(&layout.source);
    let conflict = match (layout.conventions.angle_unit, angles) {
        (AngleUnit::Radians, _) if angles != AngleReading::Degrees => return Ok(None),
        (AngleUnit::Radians, _) => Some(("--angles degrees", "\"rad\"")),
        (AngleUnit::Degrees, AngleReading::Radians) => Some(("--angles radians", "\"deg\"")),
        (AngleUnit::Degrees, _) => None,
    };
    if let Some((flag, unit)) = conflict {
        return Err(Refusal::new(
            1,
            1,
            MeasureErrorKind::AnglesFlag {
                flag,
                reason: format!(
                    "the layout {layout_file} says angle_unit = {unit}; a layout states the unit \
                     of its table's angles: fix angle_unit there and drop --angles"
                ),
            },
        ));
    }
    let fix = format!(
        "set angle_unit = \"rad\" in the layout {layout_file} (--angles degrees if they are \
         degrees)"
    );
    check_degrees(&source.display().to_string(), rows, angles, &fix)
}

fn parse_text(text: &str, layout: &Layout) -> Result<ParsedTable, Refusal> {
    let lines = table_lines(text)?;
    let mut metadata = Metadata::default();
    for &(number, line) in &lines.comments {
        add_metadata(&mut metadata, number, line, layout)?;
    }
    let (header_line, header) = lines.header()?;
    let header_fields = fields_of(header_line, header)?;
    let resolved = resolve_header(header_line, &header_fields, layout)?;
    if resolved.wavelength.is_none() && metadata.wavelength.is_none() {
        return Err(Refusal::new(header_line, 1, MeasureErrorKind::NoWavelength));
    }
    // A layout's table has no uncertainty columns: its model gives them once the rows are in.
    let no_uncertainties = vec![None; resolved.elements.len()];
    let mut groups = WavelengthGroups::new(
        metadata.wavelength.as_ref(),
        true,
        vec![false; resolved.elements.len()],
        lines.rows().len(),
    );
    let (mut folded_incident, mut folded_detector) = (0, 0);
    for &(number, line) in lines.rows() {
        let row = parse_row(
            number,
            line,
            &resolved,
            layout,
            metadata.wavelength.as_ref(),
        )?;
        folded_incident += usize::from(row.folded.0);
        folded_detector += usize::from(row.folded.1);
        let (angles, values) = (row.angles, &row.values);
        groups.push(row.wavelength, angles, values, &no_uncertainties, number);
    }
    if groups.len() == 0 {
        return Err(Refusal::new(header_line, 1, MeasureErrorKind::NoDataRows));
    }
    if groups.rows().all(|p| p.values[0] == 0.0) {
        let m00_column = header_fields[resolved.elements[0].1].column;
        return Err(Refusal::new(
            header_line,
            m00_column,
            MeasureErrorKind::AllM00Zero,
        ));
    }
    let used = used_fields(&resolved);
    let unused_columns = (0..resolved.names.len())
        .filter(|i| !used.contains(i))
        .map(|i| resolved.names[i].clone())
        .collect();
    Ok(ParsedTable {
        metadata,
        elements: resolved.elements.iter().map(|&(index, _)| index).collect(),
        groups,
        folded_incident,
        folded_detector,
        unused_columns,
    })
}

/// Records a `# key: value` line. A `# mueller_convention:` line must agree with the layout (the
/// §2.1 reader accepts only psps; through a layout the file may say xyxy).
fn add_metadata(
    metadata: &mut Metadata,
    number: u64,
    line: &str,
    layout: &Layout,
) -> Result<(), Refusal> {
    let Some((key, value, column)) = split_metadata_line(line) else {
        return Ok(());
    };
    let basis = layout.conventions.mueller_convention;
    if key == "mueller_convention" && !value.eq_ignore_ascii_case(basis.name()) {
        return Err(Refusal::new(
            number,
            column,
            MeasureErrorKind::ConventionDisagreesWithLayout {
                value: shown(value),
                layout_value: basis.name(),
            },
        ));
    }
    if key == "mueller_convention" && basis != MuellerBasis::Psps {
        // Agrees with the layout; the set's own convention is psps once converted.
        metadata.entries.insert(key.to_string(), value.to_string());
        return Ok(());
    }
    metadata.add(number, key, value, column)
}

/// The field index of every role, refusing a named column the header lacks (or holds twice), an
/// element pattern that matches nothing, and an element set the basis rotation cannot convert.
fn resolve_header(line: u64, fields: &[Field<'_>], layout: &Layout) -> Result<Resolved, Refusal> {
    let names: Vec<String> = fields.iter().map(|f| f.text.to_string()).collect();
    let roles = &layout.columns;
    let find = |column: &str, role: &'static str| find_column(line, fields, layout, column, role);
    let find_optional = |column: &Option<String>, role: &'static str| {
        column.as_deref().map(|c| find(c, role)).transpose()
    };
    let mut elements = vec![(0, find(&roles.m00, "m00")?)];
    for (&index, column) in &roles.elements {
        match (&roles.pattern, names.iter().position(|n| n == column)) {
            (_, Some(_)) | (None, None) => {
                elements.push((index, find(column, MUELLER_ELEMENT_NAMES[index])?))
            }
            (Some(_), None) => {} // a pattern names all fifteen; the file holds a subset
        }
    }
    if let (Some(pattern), 1) = (&roles.pattern, elements.len()) {
        return Err(Refusal::new(
            line,
            1,
            MeasureErrorKind::ElementPatternMatchesNothing {
                pattern: shown(pattern),
                layout: crate::text::path(&layout.source),
                names: pattern_names(&roles.elements),
            },
        ));
    }
    if layout.conventions.mueller_convention == MuellerBasis::Xyxy {
        check_rotation_closure(line, &elements)?;
    }
    Ok(Resolved {
        theta_i: find(&roles.theta_i, "theta_i_deg")?,
        phi_i: find_optional(&roles.phi_i, "phi_i_deg")?,
        theta_r: find(&roles.theta_r, "theta_r_deg")?,
        phi_r: find_optional(&roles.phi_r, "phi_r_deg")?,
        wavelength: find_optional(&roles.wavelength, "wavelength_um")?,
        elements,
        names,
    })
}

/// The field index of `column`, which the layout names for `role`.
fn find_column(
    line: u64,
    fields: &[Field<'_>],
    layout: &Layout,
    column: &str,
    role: &'static str,
) -> Result<usize, Refusal> {
    let mut matches = fields.iter().enumerate().filter(|(_, f)| f.text == column);
    let Some((index, first)) = matches.next() else {
        if let Some(refusal) = wrong_delimiter(line, fields) {
            return Err(refusal.map(MeasureErrorKind::Token));
        }
        return Err(Refusal::new(
            line,
            1,
            MeasureErrorKind::LayoutColumnMissing {
                column: shown(column),
                role,
                layout: layout.source.display().to_string(),
            },
        ));
    };
    if let Some((_, second)) = matches.next() {
        return Err(Refusal::new(
            line,
            second.column,
            MeasureErrorKind::DuplicateColumn {
                name: shown(column),
                first_column: first.column,
            },
        ));
    }
    Ok(index)
}

/// The xyxy → psps rotation mixes rows 1 and 2 and columns 1 and 2: every element it mixes with
/// a present one must be present too, or the converted value would be wrong.
fn check_rotation_closure(line: u64, elements: &[(usize, usize)]) -> Result<(), Refusal> {
    let present: Vec<usize> = elements.iter().map(|&(index, _)| index).collect();
    for &index in &present {
        if let Some(missing) = mixed_with(index).into_iter().find(|m| !present.contains(m)) {
            return Err(Refusal::new(
                line,
                1,
                MeasureErrorKind::BasisNeedsElement {
                    present: MUELLER_ELEMENT_NAMES[index],
                    missing: MUELLER_ELEMENT_NAMES[missing],
                },
            ));
        }
    }
    Ok(())
}

/// The first and last names of an element pattern, quoted, for messages.
fn pattern_names(names: &BTreeMap<usize, String>) -> String {
    let quoted = |name: Option<&String>| format!("'{}'", shown(name.map_or("", |n| n.as_str())));
    format!(
        "{} … {}",
        quoted(names.values().next()),
        quoted(names.values().last())
    )
}

fn used_fields(resolved: &Resolved) -> Vec<usize> {
    let mut used = vec![resolved.theta_i, resolved.theta_r];
    used.extend(resolved.phi_i);
    used.extend(resolved.phi_r);
    used.extend(resolved.wavelength);
    used.extend(resolved.elements.iter().map(|&(_, field)| field));
    used
}

/// One converted row: (θ_i, φ_i, θ_r, φ_r) in degrees, the values of the layout's elements.
struct Row {
    angles: [f64; 4],
    values: Vec<f64>,
    wavelength: Option<(HeaderWavelength, u64)>,
    /// Whether θ_i and θ_r were negative (read across the normal).
    folded: (bool, bool),
}

fn parse_row(
    number: u64,
    line: &str,
    resolved: &Resolved,
    layout: &Layout,
    header_wavelength: Option<&HeaderWavelength>,
) -> Result<Row, Refusal> {
    let fields = fields_of(number, line)?;
    check_width(number, line, &fields, resolved.names.len())?;
    let cells = Cells {
        number,
        fields: &fields,
        names: &resolved.names,
    };
    let wavelength = match resolved.wavelength {
        Some(field) => row_wavelength_of(&cells, field, header_wavelength)?,
        None => None,
    };
    let conventions = &layout.conventions;
    let azimuth = |field: Option<usize>, default: f64| -> Result<f64, Refusal> {
        field.map_or(Ok(default), |f| {
            cells
                .number(f)
                .map(|v| in_degrees(v, conventions.angle_unit))
        })
    };
    let theta_i = cells.zenith(resolved.theta_i, layout)?;
    let phi_i = azimuth(resolved.phi_i, DEFAULT_PHI_I_DEG)?;
    let theta_r = cells.zenith(resolved.theta_r, layout)?;
    let mut phi_r = azimuth(resolved.phi_r, DEFAULT_PHI_R_DEG)?;
    if resolved.phi_r.is_some() && conventions.specular_phi_r == SpecularAzimuth::SameAsIncidence {
        phi_r = (phi_r + 180.0).rem_euclid(360.0);
    }
    let (theta_i_deg, phi_i_deg) = fold_signed_zenith(theta_i, phi_i);
    let (theta_r_deg, phi_r_deg) = fold_signed_zenith(theta_r, phi_r);
    let values = cells.elements(resolved, layout, phi_i_deg, phi_r_deg)?;
    Ok(Row {
        angles: [theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg],
        values,
        wavelength,
        folded: (theta_i < 0.0, theta_r < 0.0),
    })
}

fn in_degrees(value: f64, unit: AngleUnit) -> f64 {
    match unit {
        AngleUnit::Degrees => value,
        AngleUnit::Radians => value.to_degrees(),
    }
}

/// A row's wavelength: checked against the `# wavelength_um:` line if there is one (then `None`),
/// else the row's own, with its column.
fn row_wavelength_of(
    cells: &Cells<'_>,
    field: usize,
    header: Option<&HeaderWavelength>,
) -> Result<Option<(HeaderWavelength, u64)>, Refusal> {
    let um = cells.number(field)?;
    let (text, column) = (
        cells.fields[field].text.as_ref(),
        cells.fields[field].column,
    );
    if let Some(kind) = wavelength_refusal(um, text) {
        return Err(Refusal::new(cells.number, column, kind));
    }
    row_wavelength(header, cells.number, column, um, text)
}

/// The fields of one data row, with what messages need to point at them.
struct Cells<'a> {
    number: u64,
    fields: &'a [Field<'a>],
    names: &'a [String],
}

impl Cells<'_> {
    fn refusal(&self, field: usize, kind: MeasureErrorKind) -> Refusal {
        Refusal::new(self.number, self.fields[field].column, kind)
    }

    fn number(&self, field: usize) -> Result<f64, Refusal> {
        parse_number(&self.names[field], &self.fields[field].text)
            .map_err(|kind| self.refusal(field, kind))
    }

    /// A zenith angle in degrees, still signed; refused beyond the hemisphere in the layout's
    /// unit (the usual sign of an angle column in another unit than the layout says) or, without
    /// signed angles, below 0.
    fn zenith(&self, field: usize, layout: &Layout) -> Result<f64, Refusal> {
        let value = self.number(field)?;
        let conventions = &layout.conventions;
        let degrees = in_degrees(value, conventions.angle_unit);
        let column = self.names[field].clone();
        let text = shown(&self.fields[field].text);
        if degrees < 0.0 && !conventions.signed_angles {
            let kind = MeasureErrorKind::LayoutNegativeAngle {
                column,
                value: text,
            };
            return Err(self.refusal(field, kind));
        }
        if degrees.abs() >= 90.0 {
            let signed = conventions.signed_angles;
            let kind = match conventions.angle_unit {
                AngleUnit::Degrees => MeasureErrorKind::LayoutDegreesOutOfRange {
                    column,
                    value: text,
                    signed,
                },
                AngleUnit::Radians => MeasureErrorKind::LayoutRadiansOutOfRange {
                    column,
                    value: text,
                    signed,
                },
            };
            return Err(self.refusal(field, kind));
        }
        Ok(degrees)
    }

    /// The value limit of every table reader on an element as written (`value`) and in sr⁻¹
    /// (`sr`, the written one times m00 where the layout says normalized): a normalized 1e308
    /// would otherwise become inf.
    fn check_element(&self, field: usize, value: f64, sr: f64) -> Result<(), Refusal> {
        let name = &self.names[field];
        let text = &self.fields[field].text;
        let refusal = element_value_refusal(name, value, text).or_else(|| {
            let product = format!("{} × m00 = {}", shown(text), crate::text::number(sr));
            element_value_refusal(name, sr, &product)
        });
        refusal.map_or(Ok(()), |kind| Err(self.refusal(field, kind)))
    }

    /// The row's Mueller elements in sr⁻¹, psps, aligned with the resolved elements.
    fn elements(
        &self,
        resolved: &Resolved,
        layout: &Layout,
        phi_i_deg: f64,
        phi_r_deg: f64,
    ) -> Result<Vec<f64>, Refusal> {
        let m00_field = resolved.elements[0].1;
        let m00 = self.number(m00_field)?;
        if m00 < 0.0 {
            let kind = MeasureErrorKind::LayoutNegativeM00 {
                column: self.names[m00_field].clone(),
                value: shown(&self.fields[m00_field].text),
            };
            return Err(self.refusal(m00_field, kind));
        }
        let mut matrix = [0.0; 16];
        for &(index, field) in &resolved.elements {
            let value = self.number(field)?;
            matrix[index] = match index {
                0 => m00,
                _ if layout.conventions.normalized => value * m00,
                _ => value,
            };
            self.check_element(field, value, matrix[index])?;
        }
        if layout.conventions.mueller_convention == MuellerBasis::Xyxy {
            xyxy_to_psps(&mut matrix, phi_i_deg, phi_r_deg);
        }
        Ok(resolved
            .elements
            .iter()
            .map(|&(index, _)| matrix[index])
            .collect())
    }
}

/// The table's rows as one set per wavelength, ascending, each with its uncertainties and the
/// notes that tell the user what the conversion did.
fn build_sets(
    source: &Path,
    sha256: String,
    parsed: ParsedTable,
    layout: &Layout,
    angle_note: Option<String>,
) -> Result<Vec<MeasurementSet>, Refusal> {
    let file = source.display().to_string();
    let mut file_notes: Vec<String> = angle_note.into_iter().collect();
    file_notes.extend(file_notes_of(&file, &parsed, layout));
    let mut facts = FileFacts {
        sha256,
        material: material_of(parsed.metadata.material.as_ref(), source),
        metadata: parsed.metadata.entries,
        elements: parsed.elements,
    };
    facts
        .metadata
        .insert("layout".to_string(), layout.source.display().to_string());
    let groups = parsed.groups.finish()?;
    let mut sets = Vec::with_capacity(groups.len());
    for (wavelength_um, mut points) in groups {
        let applied = apply_uncertainty_model(layout.uncertainty, &mut points, &facts.elements);
        // The file's notes go with every set, as read_measurement_sets does (a set chosen by
        // wavelength keeps them; the fit says each note once).
        let mut notes = file_notes.clone();
        notes.push(format!("{file} at {wavelength_um} µm: {}", applied.note));
        let mut set = facts.set(source, wavelength_um, points, notes);
        set.metadata
            .insert("uncertainty_model".to_string(), applied.label.clone());
        sets.push(set);
    }
    Ok(sets)
}

/// What the layout changed, said once per file.
fn file_notes_of(file: &str, parsed: &ParsedTable, layout: &Layout) -> Vec<String> {
    let conventions = &layout.conventions;
    let mut done = Vec::new();
    if conventions.angle_unit == AngleUnit::Radians {
        done.push("angles in radians converted to degrees".to_string());
    }
    if conventions.specular_phi_r == SpecularAzimuth::SameAsIncidence {
        done.push("φ_r turned by 180° (the file's specular azimuth is φ_i)".to_string());
    }
    if conventions.normalized {
        done.push(format!(
            "elements normalized by m00 multiplied by '{}'",
            layout.columns.m00
        ));
    }
    if conventions.mueller_convention == MuellerBasis::Xyxy {
        done.push("Mueller matrices rotated from the sample's xyxy basis into psps".to_string());
    }
    let mut notes = Vec::new();
    if !done.is_empty() {
        notes.push(format!(
            "{file}: read through the layout {}: {}",
            crate::text::path(&layout.source),
            done.join("; ")
        ));
    }
    if parsed.folded_incident > 0 {
        notes.push(format!(
            "{file}: {} with θ_i < 0 read as (|θ_i|, φ_i + 180°)",
            crate::text::counted(parsed.folded_incident, "row")
        ));
    }
    notes.extend(signed_zenith_note(file, parsed.folded_detector));
    if !parsed.unused_columns.is_empty() {
        notes.push(format!(
            "{file}: columns the layout does not name, not read: {}",
            parsed.unused_columns.join(", ")
        ));
    }
    notes
}
