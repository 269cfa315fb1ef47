//! Angles written in radians where degrees are declared (docs/measurements.md, "Angles in
//! radians"): one check for every table reader (§2.1 files and layouts; a Mitsuba table has no
//! angle columns). A fit of radians read as degrees sees every geometry within 1.6° of the
//! normal and ends in a model that does not describe the data, so such a file is refused unless
//! the command says how to read its angles (`--angles`).

use super::error::{MeasureErrorKind, Refusal};
use super::MeasurementRow;
use std::f64::consts::FRAC_PI_2;

/// How a command reads the angle columns of its measurement files (`--angles`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AngleReading {
    /// As the file declares them (degrees in a §2.1 file, the layout's `angle_unit`), refusing
    /// angles that look like radians declared as degrees.
    #[default]
    Auto,
    /// Degrees, even where they look like radians (a scan within 1.6° of the normal).
    Degrees,
    /// Radians, converted to degrees (a §2.1 file whose `_deg` columns hold radians).
    Radians,
}

impl AngleReading {
    /// `auto`, `degrees` or `radians` (the flag's spelling; `deg`, `rad` too), or `None`.
    pub fn parse(text: &str) -> Option<AngleReading> {
        match text.trim() {
            "auto" => Some(AngleReading::Auto),
            "degrees" | "deg" => Some(AngleReading::Degrees),
            "radians" | "rad" => Some(AngleReading::Radians),
            _ => None,
        }
    }

    /// The flag's spelling.
    pub fn name(self) -> &'static str {
        match self {
            AngleReading::Auto => "auto",
            AngleReading::Degrees => "degrees",
            AngleReading::Radians => "radians",
        }
    }
}

/// What makes a table's zenith angles, read as degrees, look like radians: every |θ| (incidence
/// and detector) within π/2, some not 0, and some not a whole degree. A measurement in degrees
/// has a detector beyond 1.6° of the source somewhere (the two cannot share a direction), so
/// real degree data do not look so; the one that could, every angle 0° or 1°, is whole.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct RadiansEvidence {
    largest: f64,
    example: f64,
    line: u64,
}

impl std::fmt::Display for RadiansEvidence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "every zenith angle is within ±{} (≤ π/2 = 1.5708) and not all whole \
             degrees ({} on line {}): these look like radians",
            crate::text::significant_trimmed(self.largest, 6),
            crate::text::significant_trimmed(self.example, 6),
            self.line
        )
    }
}

/// The evidence that the zenith angles of `rows` (as read, in what the file calls degrees) are
/// radians, if they look so.
pub(crate) fn radians_evidence<'a>(
    rows: impl Iterator<Item = MeasurementRow<'a>> + Clone,
) -> Option<RadiansEvidence> {
    let zeniths = || {
        rows.clone()
            .flat_map(|p| [(p.theta_i_deg.abs(), p.line), (p.theta_r_deg.abs(), p.line)])
    };
    let largest = zeniths().map(|(theta, _)| theta).fold(0.0, f64::max);
    if !(largest > 0.0 && largest <= FRAC_PI_2) {
        return None;
    }
    let whole = |theta: f64| (theta - theta.round()).abs() < 1e-9;
    // The first in the file (θ_i before θ_r on a line): the rows may come wavelength by
    // wavelength, not in file order; min_by_key keeps the first of equal lines.
    let (example, line) = zeniths()
        .filter(|&(theta, _)| !whole(theta))
        .min_by_key(|&(_, line)| line)?;
    Some(RadiansEvidence {
        largest,
        example,
        line,
    })
}

/// What a reader does with angles it reads as degrees: nothing when they look like degrees; a
/// refusal at the line of the evidence (saying `fix`) when they look like radians and the
/// command did not say how to read them; a note (for the caller to print before the fit, and
/// with any fit error) when `--angles degrees` says they are degrees.
pub(crate) fn check_degrees<'a>(
    file: &str,
    rows: impl Iterator<Item = MeasurementRow<'a>> + Clone,
    reading: AngleReading,
    fix: &str,
) -> Result<Option<String>, Refusal> {
    let Some(evidence) = radians_evidence(rows) else {
        return Ok(None);
    };
    match reading {
        AngleReading::Degrees => Ok(Some(format!(
            "{file}: {evidence}; read as degrees, as --angles degrees says"
        ))),
        AngleReading::Auto | AngleReading::Radians => Err(Refusal::new(
            evidence.line,
            1,
            MeasureErrorKind::LooksLikeRadians {
                evidence: evidence.to_string(),
                fix: fix.to_owned(),
            },
        )),
    }
}

/// The note of a file whose angles `--angles radians` converted, said before the fit.
pub(crate) fn converted_note(file: &str) -> String {
    format!("{file}: angles read as radians (--angles radians) and converted to degrees")
}

/// Whether a reader's note is about angle units (the fit repeats those with any error).
pub fn is_angle_note(note: &str) -> bool {
    note.contains("--angles ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{MeasurementPoint, MeasurementRows};

    fn points(angles: &[(f64, f64)]) -> MeasurementRows {
        angles
            .iter()
            .enumerate()
            .map(|(k, &(ti, tr))| MeasurementPoint {
                theta_i_deg: ti,
                phi_i_deg: 0.0,
                theta_r_deg: tr,
                phi_r_deg: 180.0,
                values: vec![1.0],
                uncertainties: vec![None],
                line: k as u64 + 2,
            })
            .collect()
    }

    #[test]
    fn radians_look_like_radians_and_small_degree_grids_do_not() {
        let rad = |degrees: f64| degrees.to_radians();
        let radians = points(&[
            (0.0, rad(10.0)),
            (rad(30.0), rad(60.0)),
            (rad(60.0), rad(80.0)),
        ]);
        let evidence = radians_evidence(radians.iter()).unwrap();
        assert_eq!((evidence.largest, evidence.line), (rad(80.0), 2));
        // Radians written with one decimal, as a coarse scan would be.
        assert!(radians_evidence(points(&[(0.5, 0.7), (1.0, 1.2)]).iter()).is_some());
        // Whole degrees within 1.6° of the normal.
        assert_eq!(
            radians_evidence(points(&[(0.0, 1.0), (1.0, 0.0)]).iter()),
            None
        );
        // Any angle beyond π/2, or all at the normal: degrees.
        assert_eq!(radians_evidence(points(&[(0.3, 60.0)]).iter()), None);
        assert_eq!(radians_evidence(points(&[(0.0, 0.0)]).iter()), None);
    }

    /// A spectral file's rows come wavelength by wavelength; the example is still the file's
    /// first fractional angle.
    #[test]
    fn the_evidence_is_the_first_in_the_file_whatever_the_row_order() {
        let mut later = points(&[(0.5, 1.5)]).to_points();
        later[0].line = 9;
        let later: MeasurementRows = later.into_iter().collect();
        let earlier = points(&[(1.0, 0.25)]);
        let evidence = radians_evidence(later.iter().chain(earlier.iter())).unwrap();
        assert_eq!((evidence.example, evidence.line), (0.25, 2));
    }

    #[test]
    fn the_flag_turns_the_refusal_into_a_note() {
        let radians = points(&[(30f64.to_radians(), 0.5)]);
        let refusal =
            check_degrees("f.csv", radians.iter(), AngleReading::Auto, "FIX").unwrap_err();
        assert!(
            refusal.kind.to_string().ends_with("FIX"),
            "{}",
            refusal.kind
        );
        let note = check_degrees("f.csv", radians.iter(), AngleReading::Degrees, "FIX").unwrap();
        assert!(is_angle_note(&note.unwrap()));
        assert_eq!(AngleReading::parse("rad"), Some(AngleReading::Radians));
        assert_eq!(AngleReading::parse("grad"), None);
    }
}
