//! Integration tests of measurement ingestion (docs/design.md §2.1): a corpus of malformed files, each
//! refused with an exact `file:line:column: what is wrong` message; good files parsed to known
//! values; and random or truncated input that must give Ok or Err, never a panic.

use crate::common;

use std::path::{Path, PathBuf};

use irpol::measure::{
    collect_measurement_files, parse_measurement_csv, read_measurement_csv, MeasureErrorKind,
    MUELLER_ELEMENT_NAMES,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const BAD: &str = "tests/data/bad_csv";
const GOOD: &str = "tests/data/good_csv";

/// Every malformed file and its exact message after `tests/data/bad_csv/<file>:`.
const BAD_FILES: &[(&str, &str)] = &[
    // Header row.
    ("unknown_column.csv", "2:29: unknown column 'brdf' (expected theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg, wavelength_um, m00…m33, u_m00…u_m33)"),
    ("unknown_column_case.csv", "2:25: unknown column 'M00' (column names are case-sensitive: did you mean 'm00'?)"),
    ("duplicate_column.csv", "2:33: duplicate column 'm11' (already column 29 of the header row)"),
    ("missing_theta_r.csv", "2:1: missing required column 'theta_r_deg'"),
    ("missing_m00.csv", "2:1: missing required column 'm00'"),
    ("uncertainty_without_element.csv", "2:35: column 'u_m22' is the uncertainty of 'm22', but there is no 'm22' column"),
    ("empty_column_name.csv", "2:29: empty column name (a doubled or trailing ',' in the header row)"),
    ("unterminated_quote.csv", "2:15: quoted field has no closing '\"'"),
    ("text_after_quote.csv", "2:14: unexpected text after the closing '\"' of a quoted field"),
    // Delimiters.
    ("semicolon_delimited.csv", "2:12: fields are separated by ';', expected ','"),
    ("tab_delimited.csv", "2:12: fields are separated by tabs, expected ','"),
    ("semicolon_in_row.csv", "4:3: fields are separated by ';', expected ','"),
    // Data values.
    ("not_a_number.csv", "4:7: column 'm00': 'n/a' is not a number"),
    ("nan_value.csv", "3:12: column 'm01': 'NaN' is not a finite number"),
    ("overflow_value.csv", "3:7: column 'm00': '1e999' is not a finite number"),
    ("empty_field.csv", "3:7: column 'm00' is empty, expected a number"),
    ("theta_i_90.csv", "3:1: column 'theta_i_deg': 90 is outside [0°, 90°) (zenith angles of the hemisphere above the surface)"),
    ("theta_r_minus_90.csv", "3:4: column 'theta_r_deg': -90 is outside (−90°, 90°) (detector zenith angles; a negative one is read as (|θ_r|, φ_r + 180°))"),
    ("negative_m00.csv", "3:7: column 'm00': -0.002 is negative, but m00 (the unpolarized BRDF, sr⁻¹) is ≥ 0"),
    ("zero_uncertainty.csv", "3:12: column 'u_m00': 0 is not a positive uncertainty"),
    ("negative_uncertainty.csv", "3:17: column 'u_m11': -1e-3 is not a positive uncertainty"),
    ("too_few_fields.csv", "4:6: the row has 2 fields, the header row has 3"),
    ("too_many_fields.csv", "3:12: the row has 4 fields, the header row has 3"),
    // Whole file.
    ("empty.csv", "1:1: the file is empty"),
    ("whitespace_only.csv", "1:1: the file is empty"),
    ("comments_only.csv", "1:1: no header row: the file holds only comments and metadata"),
    ("header_only.csv", "2:1: a header row but no data rows"),
    ("latin1_degree_sign.csv", "2:13: invalid UTF-8 (byte 0xB0): a measurement CSV must be UTF-8 text"),
    // Wavelength.
    ("no_wavelength.csv", "2:1: no wavelength: add a 'wavelength_um' column or a '# wavelength_um: <micrometres>' header line"),
    ("wavelength_disagrees.csv", "4:7: column 'wavelength_um': 10.6 disagrees with the header '# wavelength_um: 9.925' (line 1)"),
    ("mixed_wavelengths.csv", "4:7: column 'wavelength_um': 10.6 differs from 9.925 on line 2: the file holds several wavelengths, a spectral set, which `irpol fit` reads as one material but this reader of one wavelength cannot"),
    ("bad_header_wavelength.csv", "1:18: header 'wavelength_um': '9,925' is not a positive number of micrometres"),
    ("nonpositive_wavelength.csv", "2:7: column 'wavelength_um': 0 is not a positive wavelength"),
    // Metadata.
    ("unsupported_convention.csv", "2:23: header 'mueller_convention': 'spsp' is not supported; irpol uses 'psps' (SCATMECH's Stokes convention)"),
    ("empty_header_value.csv", "1:12: header 'material' has no value"),
    ("duplicate_header_key.csv", "3:1: header 'material' given twice (first on line 2)"),
    ("material_escapes_folder.csv", "1:13: header 'material': '../../etc/paint' cannot name a file (contains '/')"),
];

#[test]
fn every_malformed_file_is_refused_with_its_exact_message() {
    let mut wrong = Vec::new();
    for (name, expected) in BAD_FILES {
        let path = Path::new(BAD).join(name);
        let expected = format!("{}:{expected}", path.display());
        match read_measurement_csv(&path) {
            Ok(_) => wrong.push(format!("{name}: accepted, expected `{expected}`")),
            Err(e) if e.to_string() != expected => wrong.push(format!(
                "{name}:\n  got      `{e}`\n  expected `{expected}`"
            )),
            Err(_) => {}
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn the_corpus_and_the_table_list_the_same_files() {
    let mut on_disk: Vec<String> = std::fs::read_dir(BAD)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    on_disk.sort();
    let mut in_table: Vec<String> = BAD_FILES.iter().map(|(n, _)| n.to_string()).collect();
    in_table.sort();
    assert_eq!(on_disk, in_table);
    assert!(in_table.len() >= 15);
}

#[test]
fn error_fields_match_the_message() {
    let path = Path::new(BAD).join("negative_m00.csv");
    let err = read_measurement_csv(&path).unwrap_err();
    assert_eq!(
        (err.file.as_path(), err.line, err.column),
        (path.as_path(), 3, 7)
    );
    assert_eq!(
        err.kind,
        MeasureErrorKind::NegativeM00 {
            value: "-0.002".into()
        }
    );
}

#[test]
fn a_directory_or_a_missing_file_is_refused() {
    let err = read_measurement_csv(Path::new(BAD)).unwrap_err();
    assert_eq!(
        err.to_string(),
        "tests/data/bad_csv:1:1: is a directory, expected a CSV file"
    );
    let err = read_measurement_csv(Path::new("bad\0name.csv")).unwrap_err();
    assert!(
        matches!(err.kind, MeasureErrorKind::Unreadable { .. }),
        "{err}"
    );
    let err = read_measurement_csv(Path::new("tests/data/no_such.csv")).unwrap_err();
    assert_eq!(
        err.to_string(),
        "tests/data/no_such.csv:1:1: no such file or directory"
    );
}

#[test]
fn full_file_parses_with_metadata_elements_and_provenance() {
    let path = Path::new(GOOD).join("gloss_paint.csv");
    let set = read_measurement_csv(&path).unwrap();
    assert_eq!(set.source, path);
    // `sha256sum tests/data/good_csv/gloss_paint.csv`
    assert_eq!(
        set.sha256,
        "412fdcecad1a799424559346d565e301a9bbdcd6c40d635e23f8211d166a936e"
    );
    assert_eq!(set.material, "gloss_paint");
    assert_eq!(set.wavelength_um, 9.925);
    let keys: Vec<&str> = set.metadata.keys().map(String::as_str).collect();
    assert_eq!(
        keys,
        [
            "material",
            "mueller_convention",
            "operator",
            "wavelength_um"
        ]
    );
    assert_eq!(set.metadata["operator"], "J. Doe");
    let names: Vec<&str> = set
        .elements
        .iter()
        .map(|&i| MUELLER_ELEMENT_NAMES[i])
        .collect();
    assert_eq!(
        names,
        ["m00", "m01", "m02", "m10", "m11", "m12", "m20", "m21", "m22"]
    );
    assert_eq!(set.points.len(), 3);
    let last = set.points.row(2);
    assert_eq!(last.line, 11);
    assert_eq!(
        (
            last.theta_i_deg,
            last.phi_i_deg,
            last.theta_r_deg,
            last.phi_r_deg
        ),
        (60.0, 0.0, 45.0, 135.0)
    );
    assert_eq!(
        last.values,
        [5.0e-02, 4.0e-03, -1.2e-03, 4.1e-03, 4.9e-02, 3e-04, 1.1e-03, -2e-04, -4.4e-02]
    );
    assert!(last.uncertainties().all(|u| u.is_none()));
    assert_eq!(set.points.row(0).values[0], 0.192);
}

#[test]
fn minimal_file_gets_default_azimuths_and_the_stem_as_material() {
    let set = read_measurement_csv(&Path::new(GOOD).join("minimal.csv")).unwrap();
    assert_eq!(set.material, "minimal");
    assert_eq!(set.wavelength_um, 10.6);
    assert_eq!(set.elements, [0]);
    let geometry: Vec<_> = set
        .points
        .iter()
        .map(|p| {
            (
                p.theta_i_deg,
                p.phi_i_deg,
                p.theta_r_deg,
                p.phi_r_deg,
                p.values[0],
                p.line,
            )
        })
        .collect();
    assert_eq!(
        geometry,
        [
            (0.0, 0.0, 0.0, 180.0, 0.31, 3),
            (30.0, 0.0, 30.0, 180.0, 0.25, 4)
        ]
    );
}

#[test]
fn uncertainties_may_cover_a_subset_of_the_elements() {
    let set = read_measurement_csv(&Path::new(GOOD).join("uncertain.csv")).unwrap();
    // Columns in any order, padded with spaces; elements come out ascending.
    assert_eq!(set.elements, [0, 5, 10]);
    assert_eq!(set.wavelength_um, 8.5);
    assert_eq!(set.metadata["date"], "2024-05-01");
    let second = set.points.row(1);
    assert_eq!(second.line, 4);
    assert_eq!(
        (
            second.theta_i_deg,
            second.phi_i_deg,
            second.theta_r_deg,
            second.phi_r_deg
        ),
        (20.0, 0.0, 40.0, 190.5)
    );
    assert_eq!(second.values, [0.020, 0.019, -0.020]);
    let uncertainties = |row: usize| set.points.row(row).uncertainties().collect::<Vec<_>>();
    assert_eq!(uncertainties(1), [Some(0.0010), None, Some(0.0011)]);
    assert_eq!(uncertainties(0), [Some(0.0012), None, Some(0.0009)]);
}

#[test]
fn spreadsheet_export_with_bom_crlf_and_quoted_names_parses() {
    let set = read_measurement_csv(&Path::new(GOOD).join("spreadsheet_export.csv")).unwrap();
    assert_eq!(set.material, "primer");
    assert_eq!(set.wavelength_um, 12.0);
    assert_eq!(set.elements, [0, 4]);
    assert_eq!(set.points.row(0).values, [0.11, -0.02]);
    assert_eq!(set.points.row(0).line, 4);
}

#[test]
fn collecting_a_folder_lists_its_csv_files_sorted() {
    let files = collect_measurement_files(&[PathBuf::from(GOOD)]).unwrap();
    let expected: Vec<PathBuf> = [
        "gloss_paint.csv",
        "minimal.csv",
        "spreadsheet_export.csv",
        "uncertain.csv",
    ]
    .iter()
    .map(|n| Path::new(GOOD).join(n))
    .collect();
    assert_eq!(files, expected);
    for file in &files {
        assert!(read_measurement_csv(file).is_ok(), "{}", file.display());
    }
    let err = collect_measurement_files(&[PathBuf::from(GOOD), PathBuf::from("tests/data/nope")])
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "tests/data/nope:1:1: no such file or directory"
    );
}

/// Checks that an error's position is inside the input: line within the file, column ≥ 1.
fn assert_located_in(
    input: &[u8],
    result: Result<irpol::measure::MeasurementSet, irpol::measure::MeasureError>,
) {
    if let Err(e) = result {
        // "\r\n", "\n" and a bare "\r" each end a line.
        let breaks = input
            .iter()
            .enumerate()
            .filter(|&(i, &b)| b == b'\n' || (b == b'\r' && input.get(i + 1) != Some(&b'\n')))
            .count();
        let lines = breaks as u64 + 1;
        assert!(
            e.line >= 1 && e.line <= lines && e.column >= 1,
            "{e} (input has {lines} lines)"
        );
    }
}

#[test]
fn random_bytes_never_panic() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x1e0_7a7);
    // Mostly the CSV alphabet, so that the parser gets past UTF-8 and the header row.
    let alphabet: &[u8] = b"theta_i_deg,theta_r_deg,phi_r_deg,wavelength_um,m00,u_m00,m22\n\r\t #:;\"0123456789.-+eEnaif";
    for case in 0..3000 {
        let len = rng.random_range(0..200);
        let bytes: Vec<u8> = (0..len)
            .map(|_| {
                if case % 3 == 0 {
                    rng.random()
                } else {
                    alphabet[rng.random_range(0..alphabet.len())]
                }
            })
            .collect();
        assert_located_in(&bytes, parse_measurement_csv(Path::new("fuzz.csv"), &bytes));
    }
}

#[test]
fn truncated_and_mutated_good_files_never_panic() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for name in ["gloss_paint.csv", "uncertain.csv", "spreadsheet_export.csv"] {
        let bytes = std::fs::read(Path::new(GOOD).join(name)).unwrap();
        for cut in 0..=bytes.len() {
            let truncated = &bytes[..cut];
            assert_located_in(truncated, parse_measurement_csv(Path::new(name), truncated));
        }
        for _ in 0..2000 {
            let mut mutated = bytes.clone();
            for _ in 0..rng.random_range(1..4) {
                let at = rng.random_range(0..mutated.len());
                mutated[at] = rng.random();
            }
            assert_located_in(&mutated, parse_measurement_csv(Path::new(name), &mutated));
        }
    }
    // A good file cut right after its header row is refused for having no data rows.
    let bytes = std::fs::read(Path::new(GOOD).join("minimal.csv")).unwrap();
    let header_end = bytes
        .iter()
        .enumerate()
        .filter(|(_, &b)| b == b'\n')
        .nth(1)
        .unwrap()
        .0;
    let err = parse_measurement_csv(Path::new("m.csv"), &bytes[..=header_end]).unwrap_err();
    assert_eq!(err.kind, MeasureErrorKind::NoDataRows);
}

/// A material name too long to name its files is refused at the CSV's `# material:` line, with
/// the limit, before anything is fitted or written (not by the report file it would have named).
#[test]
fn a_material_name_too_long_for_a_file_is_refused_at_its_header_line() {
    let dir = tempfile::tempdir().unwrap();
    let shipped = std::fs::read_to_string("measurements/paper_paint.csv").unwrap();
    let long = "p".repeat(300);
    let csv = dir.path().join("long.csv");
    std::fs::write(
        &csv,
        shipped.replace("# material: paper_paint", &format!("# material: {long}")),
    )
    .unwrap();
    let (ok, _, stderr) = common::fit_into(dir.path(), &[&csv], &[]);
    assert!(!ok);
    let expected = format!(
        "{}:1:13: header 'material': '{}…' cannot name a file (it is 300 bytes long; at most 200",
        csv.display(),
        "p".repeat(40)
    );
    assert!(stderr.contains(&expected), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(!dir.path().join("fits").exists() && !dir.path().join("reports").exists());
}

/// Where the reader's buffer of the file ends (it reads 64 KiB at a time).
const READ_BUFFER: usize = 1 << 16;

/// `text` extended with a comment line that ends just before byte `offset`, then `end`.
fn pad_to(text: &mut String, offset: usize, end: &str) {
    let pad = offset - text.len() - 1;
    text.push('#');
    text.push_str(&"x".repeat(pad));
    text.push_str(end);
}

/// `text` extended with rows (each ended by `terminator`) until within 64 bytes of `offset`.
fn rows_until(text: &mut String, offset: usize, terminator: &str) {
    let mut row = text.len();
    while text.len() + 64 < offset {
        text.push_str(&format!(
            "{},{},0.{}{terminator}",
            row % 80,
            row % 70,
            row % 997 + 1
        ));
        row += 1;
    }
}

/// A file several buffers long, whose lines span the buffers' ends, with a bare '\r' as the
/// last byte of one buffer and a two-byte character split between two, is read from disk as
/// its bytes are parsed in memory, rows and line numbers included, and refused at the same
/// place when a row past the buffers' ends is wrong.
#[test]
fn a_file_longer_than_the_read_buffer_streams_as_its_bytes_parse() {
    let mut text = "# wavelength_um: 10\ntheta_i_deg,theta_r_deg,m00\n".to_string();
    rows_until(&mut text, READ_BUFFER, "\r\n");
    pad_to(&mut text, READ_BUFFER - 1, "\r");
    rows_until(&mut text, 2 * READ_BUFFER, "\r");
    pad_to(&mut text, 2 * READ_BUFFER - 1, "\u{b5}\n");
    rows_until(&mut text, 3 * READ_BUFFER + 700, "\n");
    let bytes = text.as_bytes();
    assert!(bytes[READ_BUFFER - 1] == b'\r' && bytes[READ_BUFFER].is_ascii_digit());
    assert_eq!(&bytes[2 * READ_BUFFER - 1..][..2], "\u{b5}".as_bytes());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("long.csv");
    std::fs::write(&path, &text).unwrap();
    let streamed = read_measurement_csv(&path).unwrap();
    let parsed = parse_measurement_csv(&path, text.as_bytes()).unwrap();
    assert_eq!(streamed, parsed);
    let lines = text.split(['\r', '\n']).filter(|l| !l.is_empty()).count();
    assert_eq!(streamed.points.len(), lines - 4);
    let last = text.trim_end().rfind('\n').unwrap() + 1;
    let wrong = format!("{}1,1,-1\n", &text[..last]);
    std::fs::write(&path, &wrong).unwrap();
    let refused = read_measurement_csv(&path).unwrap_err();
    assert_eq!(
        refused,
        parse_measurement_csv(&path, wrong.as_bytes()).unwrap_err()
    );
    assert_eq!(
        (refused.line, refused.column),
        (streamed.points.row(streamed.points.len() - 1).line, 5)
    );
}
