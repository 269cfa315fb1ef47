//! What a measurement file *says*, hashed: the parsed data (material, wavelength, the columns that
//! carry values, and every row's geometry, values and uncertainties), not its bytes. A comment, a
//! blank line, reordered columns or `60` written `60.0` leave it unchanged, so `irpol report`
//! rebuilds after such edits; a changed number changes it. Digests of groups of rows let a
//! changed file be described ("data in rows 12–14 changed") without keeping the data.

use super::table_file::hex;
use super::{MeasurementRow, MeasurementSet, MUELLER_ELEMENT_NAMES};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// Most row-group digests recorded: the record stays a few kilobytes however long the file.
const MAX_DIGESTS: usize = 256;
/// Hex characters per row-group digest (32 bits: a change escapes one with odds 2⁻³²).
const DIGEST_HEX: usize = 8;
/// Changed row ranges named in a message before "…".
const RANGES_NAMED: usize = 3;

/// The fingerprint of a measurement set's data (the material TOML's `[fit.source_data]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceData {
    /// Lower-case hex SHA-256 of the parsed data.
    pub sha256: String,
    pub material: String,
    pub wavelength_um: f64,
    /// The value columns: Mueller elements, then their `u_` uncertainty columns.
    pub columns: Vec<String>,
    /// Data rows.
    pub rows: usize,
    /// Consecutive data rows per digest in `row_digests`.
    pub rows_per_digest: usize,
    /// One 8-hex-digit digest per group of `rows_per_digest` rows, concatenated.
    pub row_digests: String,
}

impl MeasurementSet {
    /// The fingerprint of the data of the set's own file (`source`: all rows unless files were
    /// merged into it), its rows grouped `rows_per_digest` to a digest (0: as few per group as
    /// keep the digests within `MAX_DIGESTS`).
    pub fn source_data(&self, rows_per_digest: usize) -> SourceData {
        let merged_rows: usize = self.merged.iter().map(|file| file.rows).sum();
        let own = self.points.len().saturating_sub(merged_rows);
        self.fingerprint(own, rows_per_digest)
    }

    /// The fingerprint of the first `rows` rows of this set with this set's material, wavelength
    /// and columns.
    fn fingerprint(&self, rows: usize, rows_per_digest: usize) -> SourceData {
        let rows_per_digest = match rows_per_digest {
            0 => rows.div_ceil(MAX_DIGESTS).max(1),
            given => given,
        };
        let columns = value_columns(self);
        let mut whole = Sha256::new();
        whole.update(self.material.as_bytes());
        whole.update([0]);
        whole.update(canonical(self.wavelength_um).to_le_bytes());
        for column in &columns {
            whole.update(column.as_bytes());
            whole.update([0]);
        }
        let mut row_digests = String::new();
        let mut bytes = Vec::new();
        for start in (0..rows).step_by(rows_per_digest) {
            let mut part = Sha256::new();
            for index in start..(start + rows_per_digest).min(rows) {
                row_bytes(self.points.row(index), &mut bytes);
                whole.update(&bytes);
                part.update(&bytes);
            }
            row_digests.push_str(&hex(&part.finalize())[..DIGEST_HEX]);
        }
        SourceData {
            sha256: hex(&whole.finalize()),
            material: self.material.clone(),
            wavelength_um: self.wavelength_um,
            columns,
            rows,
            rows_per_digest,
            row_digests,
        }
    }
}

/// −0 and +0 are the same measurement.
fn canonical(value: f64) -> u64 {
    (value + 0.0).to_bits()
}

fn value_columns(set: &MeasurementSet) -> Vec<String> {
    let names = set.elements.iter().map(|&e| MUELLER_ELEMENT_NAMES[e]);
    let first = set.points.first();
    let uncertain = set
        .elements
        .iter()
        .enumerate()
        .filter(|&(column, _)| first.is_some_and(|p| p.uncertainty(column).is_some()))
        .map(|(_, &e)| format!("u_{}", MUELLER_ELEMENT_NAMES[e]));
    names.map(str::to_owned).chain(uncertain).collect()
}

/// The bytes a row is hashed as, into `bytes`: its angles, values and uncertainties.
fn row_bytes(point: MeasurementRow<'_>, bytes: &mut Vec<u8>) {
    bytes.clear();
    let geometry = point.angles();
    let uncertainties = point.uncertainties().flatten();
    let numbers = geometry.into_iter().chain(point.values.iter().copied());
    bytes.extend(
        numbers
            .chain(uncertainties)
            .flat_map(|v| canonical(v).to_le_bytes()),
    );
}

impl SourceData {
    /// What differs between the data fingerprinted as `self` (at the fit) and `now` (computed
    /// with `self.rows_per_digest`): material, wavelength, columns, row count, and which rows.
    pub fn describe_change(&self, now: &SourceData) -> String {
        let mut changes = Vec::new();
        if self.material != now.material {
            changes.push(format!("material '{}' → '{}'", self.material, now.material));
        }
        if self.wavelength_um != now.wavelength_um {
            changes.push(format!(
                "wavelength {} → {} µm",
                self.wavelength_um, now.wavelength_um
            ));
        }
        let columns_changed = self.columns != now.columns;
        for (list, verb) in [
            (missing(&self.columns, &now.columns), "removed"),
            (missing(&now.columns, &self.columns), "added"),
        ] {
            match list.as_slice() {
                [] => {}
                [one] => changes.push(format!("column {one} {verb}")),
                many => changes.push(format!("columns {} {verb}", many.join(", "))),
            }
        }
        if now.rows > self.rows {
            changes.push(plural(now.rows - self.rows, "data row", "added"));
        } else if now.rows < self.rows {
            changes.push(plural(self.rows - now.rows, "data row", "removed"));
        }
        if !columns_changed {
            changes.extend(self.changed_rows(now));
        }
        if changes.is_empty() {
            "the data changed".to_owned()
        } else {
            changes.join("; ")
        }
    }

    /// "data in rows 12–14 changed" from the row-group digests both have (a group of several rows
    /// names all of them: the digest says the group changed, not which of its rows).
    fn changed_rows(&self, now: &SourceData) -> Option<String> {
        let groups = |digests: &str| -> Vec<String> {
            digests
                .as_bytes()
                .chunks(DIGEST_HEX)
                .map(|c| String::from_utf8_lossy(c).into_owned())
                .collect()
        };
        let (before, after) = (groups(&self.row_digests), groups(&now.row_digests));
        let common_rows = self.rows.min(now.rows);
        let mut ranges: Vec<(usize, usize)> = Vec::new();
        for (group, (a, b)) in before.iter().zip(&after).enumerate() {
            let first = group * self.rows_per_digest + 1;
            let last = ((group + 1) * self.rows_per_digest).min(common_rows);
            if a == b || first > last {
                continue;
            }
            match ranges.last_mut() {
                Some((_, end)) if *end + 1 == first => *end = last,
                _ => ranges.push((first, last)),
            }
        }
        if ranges.is_empty() {
            return None;
        }
        let named: Vec<String> = ranges
            .iter()
            .take(RANGES_NAMED)
            .map(|&(a, b)| {
                if a == b {
                    a.to_string()
                } else {
                    format!("{a}–{b}")
                }
            })
            .collect();
        let more = if ranges.len() > RANGES_NAMED {
            ", …"
        } else {
            ""
        };
        let single = ranges.len() == 1 && ranges[0].0 == ranges[0].1;
        let noun = if single { "row" } else { "rows" };
        Some(format!("data in {noun} {}{more} changed", named.join(", ")))
    }
}

fn missing(from: &[String], other: &[String]) -> Vec<String> {
    from.iter()
        .filter(|c| !other.contains(c))
        .cloned()
        .collect()
}

fn plural(count: usize, noun: &str, verb: &str) -> String {
    let s = if count == 1 { "" } else { "s" };
    format!("{count} {noun}{s} {verb}")
}

#[cfg(test)]
mod tests {
    use crate::measure::parse_measurement_csv;
    use std::path::Path;

    const HEADER: &str =
        "# material: paint\n# wavelength_um: 10\ntheta_i_deg,theta_r_deg,m00,m01\n";

    fn rows(count: usize) -> String {
        (0..count)
            .map(|i| format!("{},{},0.{},0.01\n", 10 + i % 70, i % 80, i + 1))
            .collect()
    }

    fn data(text: &str) -> crate::measure::MeasurementSet {
        parse_measurement_csv(Path::new("m.csv"), text.as_bytes()).unwrap()
    }

    #[test]
    fn comments_blanks_and_number_spelling_do_not_change_the_data() {
        let text = format!("{HEADER}{}", rows(5));
        let edited = format!(
            "# a comment\n{}\n\n# another\n",
            text.replace("0.01\n", "1e-2\n")
                .replace("10,0,", "10.0,-0,")
        );
        let (a, b) = (data(&text), data(&edited));
        assert_ne!(a.sha256, b.sha256, "the bytes differ");
        assert_eq!(a.source_data(0), b.source_data(0));
    }

    #[test]
    fn a_change_is_described_by_rows_columns_and_metadata() {
        let before = data(&format!("{HEADER}{}", rows(10))).source_data(0);
        let describe = |text: String| before.describe_change(&data(&text).source_data(1));
        let mut changed: Vec<String> = rows(10).lines().map(str::to_owned).collect();
        changed[3] = changed[3].replace("0.01", "0.02");
        changed[4] = changed[4].replace("0.01", "0.02");
        changed[8] = changed[8].replace("0.01", "0.03");
        assert_eq!(
            describe(format!("{HEADER}{}\n", changed.join("\n"))),
            "data in rows 4–5, 9 changed"
        );
        assert_eq!(
            describe(format!("{HEADER}{}", rows(13))),
            "3 data rows added"
        );
        assert_eq!(
            describe(format!("{HEADER}{}", rows(9))),
            "1 data row removed"
        );
        let no_m01: String = rows(10).replace(",0.01\n", "\n");
        assert_eq!(
            describe(format!(
                "{}{no_m01}",
                HEADER.replace(",m01", "").replace("10\n", "11\n")
            )),
            "wavelength 10 → 11 µm; column m01 removed"
        );
    }

    #[test]
    fn long_files_keep_a_bounded_number_of_digests() {
        let set = data(&format!("{HEADER}{}", rows(1000)));
        let record = set.source_data(0);
        assert_eq!(record.rows_per_digest, 4);
        assert_eq!(record.row_digests.len(), 250 * 8);
    }
}
