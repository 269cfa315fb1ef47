//! Instrument layouts (docs/design.md §2.8): the shipped PTFE table read through its layout
//! equals a conversion written independently here; every refusal with its exact message; and a
//! docs/design.md §2.1 file written out in an instrument's conventions and read back.

use std::path::Path;

use irpol::measure::{
    parse_with_layout, read_measurement_file, read_measurement_sets, read_with_layout, Layout,
    MeasurementPoint, MeasurementSet, MUELLER_ELEMENT_NAMES,
};

const PTFE: &str = "data/ptfe/PTFE_351_1064.csv";
const PTFE_LAYOUT: &str = "data/ptfe/layout.toml";

// ---------------------------------------------------------------------------------------------
// An independent conversion: plain radians trigonometry and 4×4 matrix products.
// ---------------------------------------------------------------------------------------------

type Matrix = [[f64; 4]; 4];

/// The Stokes rotation L(η) of docs/design.md §1.3, η in degrees.
fn stokes_rotation(eta_deg: f64) -> Matrix {
    let (s, c) = (2.0 * eta_deg.to_radians()).sin_cos();
    [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, c, s, 0.0],
        [0.0, -s, c, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

fn product(a: &Matrix, b: &Matrix) -> Matrix {
    let mut out = [[0.0; 4]; 4];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, value) in row.iter_mut().enumerate() {
            *value = (0..4).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    out
}

/// SCATMECH's sample-frame xyxy into psps: L(φ_r) M L(φ_i + 180°).
fn psps_from_xyxy(m: &Matrix, phi_i: f64, phi_r: f64) -> Matrix {
    product(
        &product(&stokes_rotation(phi_r), m),
        &stokes_rotation(phi_i + 180.0),
    )
}

/// The inverse: L(−φ_r) M L(−φ_i − 180°).
fn xyxy_from_psps(m: &Matrix, phi_i: f64, phi_r: f64) -> Matrix {
    product(
        &product(&stokes_rotation(-phi_r), m),
        &stokes_rotation(-phi_i - 180.0),
    )
}

/// A signed zenith angle and its azimuth as a direction above the surface.
fn unsigned(theta: f64, phi: f64) -> (f64, f64) {
    if theta < 0.0 {
        (-theta, (phi + 180.0).rem_euclid(360.0))
    } else {
        (theta, phi)
    }
}

/// One PTFE row as the test reads it: wavelength, irpol geometry and the psps matrix in sr⁻¹.
struct ExpectedRow {
    wavelength: f64,
    geometry: [f64; 4],
    psps: Matrix,
    xyxy: Matrix,
}

fn ptfe_rows_by_hand() -> Vec<ExpectedRow> {
    let text = std::fs::read_to_string(PTFE).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    // f_rIJ/f_r11 at columns 6…20 is element (I − 1, J − 1).
    let element_of = |name: &str| -> (usize, usize) {
        let digits: Vec<usize> = name[3..5].bytes().map(|b| (b - b'1') as usize).collect();
        (digits[0], digits[1])
    };
    lines
        .map(|line| {
            let v: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
            let (theta_i, phi_i) = unsigned(v[1], v[2]);
            let (theta_r, phi_r) = unsigned(v[3], v[4]);
            let mut xyxy = [[0.0; 4]; 4];
            xyxy[0][0] = v[5];
            for (column, name) in header.iter().enumerate().skip(6) {
                let (r, c) = element_of(name);
                xyxy[r][c] = v[column] * v[5];
            }
            ExpectedRow {
                wavelength: v[0],
                geometry: [theta_i, phi_i, theta_r, phi_r],
                psps: psps_from_xyxy(&xyxy, phi_i, phi_r),
                xyxy,
            }
        })
        .collect()
}

fn matrix_of(set: &MeasurementSet, point: usize) -> Matrix {
    let mut m = [[0.0; 4]; 4];
    for (slot, &index) in set.elements.iter().enumerate() {
        m[index / 4][index % 4] = set.points.row(point).values[slot];
    }
    m
}

#[test]
fn the_shipped_ptfe_table_equals_an_independent_conversion() {
    let layout = Layout::read(Path::new(PTFE_LAYOUT)).unwrap();
    let sets = read_with_layout(Path::new(PTFE), &layout).unwrap();
    let wavelengths: Vec<f64> = sets.iter().map(|s| s.wavelength_um).collect();
    assert_eq!(wavelengths, [0.351, 1.064]);
    let expected = ptfe_rows_by_hand();
    let (mut worst, mut largest_rotation) = (0.0f64, 0.0f64);
    for set in &sets {
        assert_eq!(set.elements, (0..16).collect::<Vec<_>>());
        assert_eq!(set.material, "PTFE_351_1064");
        let rows: Vec<&ExpectedRow> = expected
            .iter()
            .filter(|r| r.wavelength == set.wavelength_um)
            .collect();
        assert_eq!((rows.len(), set.points.len()), (1824, 1824));
        for (k, (point, row)) in set.points.iter().zip(&rows).enumerate() {
            let geometry = [
                point.theta_i_deg,
                point.phi_i_deg,
                point.theta_r_deg,
                point.phi_r_deg,
            ];
            assert_eq!(geometry, row.geometry, "line {}", point.line);
            let m = matrix_of(set, k);
            for (r, c) in (0..16).map(|k| (k / 4, k % 4)) {
                let error = (m[r][c] - row.psps[r][c]).abs();
                assert!(error <= 1e-12, "line {} m{r}{c}: {error:e}", point.line);
                worst = worst.max(error);
                largest_rotation = largest_rotation.max((m[r][c] - row.xyxy[r][c]).abs());
            }
            assert!(point.uncertainties().all(|u| u.is_some_and(|u| u > 0.0)));
        }
        assert_eq!(set.metadata["uncertainty_model"], "estimate (mirror pairs)");
        // The fit takes the set as it takes a file of docs/design.md §2.1.
        irpol::fit::MeasurementData::new(set).unwrap();
        eprintln!("{}", set.notes.join("\n"));
        let note = set.notes.last().unwrap();
        assert!(note.contains("mirror pairs"), "{note}");
    }
    eprintln!(
        "PTFE: max |reader − independent| = {worst:e} sr⁻¹; max |psps − xyxy| = \
         {largest_rotation:e} sr⁻¹"
    );
    // The rotation matters: out-of-plane rows differ between the bases.
    assert!(largest_rotation > 1e-3);
    assert_eq!(
        sets[0].notes[..2],
        [
            format!(
                "{PTFE}: read through the layout {PTFE_LAYOUT}: elements normalized by m00 \
                 multiplied by 'f_r11'; Mueller matrices rotated from the sample's xyxy basis \
                 into psps"
            ),
            // Every row of both wavelengths: the source sits at azimuth 180°.
            format!("{PTFE}: 3648 rows with θ_i < 0 read as (|θ_i|, φ_i + 180°)"),
        ]
    );
}

// ---------------------------------------------------------------------------------------------
// Refusals.
// ---------------------------------------------------------------------------------------------

const GOOD_LAYOUT: &str = "[columns]
theta_i_deg = \"ti\"
theta_r_deg = \"tr\"
phi_r_deg = \"pr\"
m00 = \"M11\"
elements = \"M{i}{j}\"
[conventions]
index_base = 1
";

const GOOD_TABLE: &str = "# wavelength_um: 10\nti,tr,pr,M11,M12,M21\n30,20,180,0.5,0.1,0.2\n";

fn layout_message(layout: &str) -> String {
    Layout::parse(Path::new("mem/layout.toml"), layout)
        .unwrap_err()
        .to_string()
}

fn table_message(layout: &str, table: &str) -> String {
    let layout = Layout::parse(Path::new("mem/layout.toml"), layout).unwrap();
    parse_with_layout(Path::new("mem/table.csv"), table.as_bytes(), &layout)
        .unwrap_err()
        .to_string()
}

#[test]
fn the_good_example_reads() {
    let layout = Layout::parse(Path::new("mem/layout.toml"), GOOD_LAYOUT).unwrap();
    let sets = parse_with_layout(Path::new("t.csv"), GOOD_TABLE.as_bytes(), &layout).unwrap();
    assert_eq!(sets[0].elements, [0, 1, 4]);
    assert_eq!(sets[0].points.row(0).values, [0.5, 0.1, 0.2]);
    assert!(sets[0].points.row(0).uncertainties().all(|u| u.is_none()));
    assert_eq!(sets[0].metadata["uncertainty_model"], "fixed");
    assert!(sets[0].notes.iter().all(|n| !n.contains("radians")));
    // Radians declared as degrees are refused at the row that shows it, saying what to fix.
    let narrow = "# wavelength_um: 10\nti,tr,pr,M11,M12\n0.52,0.35,3.14,0.5,0.1\n";
    assert_eq!(
        parse_with_layout(Path::new("t.csv"), narrow.as_bytes(), &layout)
            .unwrap_err()
            .to_string(),
        "t.csv:3:1: every zenith angle is within ±0.52 (≤ π/2 = 1.5708) and not all whole \
         degrees (0.52 on line 3): these look like radians, but the angles are declared in \
         degrees: set angle_unit = \"rad\" in the layout mem/layout.toml (--angles degrees if \
         they are degrees)"
    );
}

#[test]
fn layout_mistakes_are_refused_naming_the_key() {
    assert_eq!(
        layout_message(&GOOD_LAYOUT.replace("phi_r_deg", "phi_r")),
        "mem/layout.toml:4:1: not a valid layout: unknown field `phi_r`, expected one of \
         `theta_i_deg`, `phi_i_deg`, `theta_r_deg`, `phi_r_deg`, `wavelength_um`, `m00`, \
         `elements`"
    );
    assert_eq!(
        layout_message(&format!("{GOOD_LAYOUT}normalised = true\n")),
        "mem/layout.toml:9:1: not a valid layout: unknown field `normalised`, expected one of \
         `index_base`, `normalized`, `signed_angles`, `specular_phi_r`, `angle_unit`, \
         `mueller_convention`"
    );
    assert_eq!(
        layout_message(&format!("{GOOD_LAYOUT}mueller_convention = \"spsp\"\n")),
        "mem/layout.toml:9:22: not a valid layout: unknown variant `spsp`, expected `psps` or \
         `xyxy`"
    );
    assert_eq!(
        layout_message(&format!("{GOOD_LAYOUT}[uncertainty]\nmodel = \"guess\"\n")),
        "mem/layout.toml:10:9: not a valid layout: unknown variant `guess`, expected \
         `estimate` or `fixed`"
    );
    assert_eq!(
        layout_message(&GOOD_LAYOUT.replace("index_base = 1", "index_base = 2")),
        "mem/layout.toml:8:14: layout key [conventions] index_base: 2 is not an index base: 0 \
         (element names m00…m33) or 1 (m11…m44)"
    );
    assert_eq!(
        layout_message(&GOOD_LAYOUT.replace("\"M{i}{j}\"", "\"M{i}\"")),
        "mem/layout.toml:6:12: layout key [columns] elements: the pattern 'M{i}' needs both {i} \
         (the row) and {j} (the column), e.g. \"M{i}{j}\""
    );
    assert_eq!(
        layout_message(&GOOD_LAYOUT.replace("\"M{i}{j}\"", "{ m01 = \"a\", M10 = \"b\" }")),
        "mem/layout.toml:6:12: layout key [columns] elements: 'M10' is not an element name: the \
         table's keys are irpol's m00…m33 (m00 … m33)"
    );
    assert_eq!(
        layout_message(
            &GOOD_LAYOUT
                .replace("m00 = \"M11\"\n", "")
                .replace("index_base = 1", "index_base = 1\nnormalized = true")
        ),
        "mem/layout.toml:8:14: layout key [columns] m00: normalized = true multiplies the \
         elements by m00, but [columns] names no m00 column: add m00 = \"<column of the \
         unpolarized BRDF>\""
    );
    assert!(layout_message("[columns]\ntheta_i_deg = \"a\"\n")
        .starts_with("mem/layout.toml:1:1: not a valid layout: missing field `theta_r_deg`"));
}

#[test]
fn tables_that_do_not_fit_the_layout_are_refused_with_line_and_column() {
    let table = |header: &str, row: &str| format!("# wavelength_um: 10\n{header}\n{row}\n");
    assert_eq!(
        table_message(GOOD_LAYOUT, &table("ti,TR,pr,M11,M12", "30,20,180,0.5,0.1")),
        "mem/table.csv:2:1: column 'tr', which the layout mem/layout.toml names for \
         theta_r_deg, is not in the header row: fix [columns] theta_r_deg (names are \
         case-sensitive)"
    );
    assert_eq!(
        table_message(GOOD_LAYOUT, &table("ti,tr,pr,M11,m12", "30,20,180,0.5,0.1")),
        "mem/table.csv:2:1: the element pattern 'M{i}{j}' of the layout mem/layout.toml matches \
         no column of the header row (it names 'M12' … 'M44'): fix the pattern or index_base"
    );
    assert_eq!(
        table_message(GOOD_LAYOUT, &table("ti,tr,pr,M11,M12", "30,20,180,0.5,x")),
        "mem/table.csv:3:15: column 'M12': 'x' is not a number"
    );
    assert_eq!(
        table_message(
            GOOD_LAYOUT,
            &table("ti,tr,pr,M11,M12", "30,120,180,0.5,0.1")
        ),
        "mem/table.csv:3:4: column 'tr': 120° is not a zenith angle within (−90°, 90°): the \
         layout says angle_unit = \"deg\"; if the file's angles are in radians, set \
         angle_unit = \"rad\""
    );
    let radians = GOOD_LAYOUT.replace("index_base = 1", "index_base = 1\nangle_unit = \"rad\"");
    assert_eq!(
        table_message(&radians, &table("ti,tr,pr,M11,M12", "30,0.2,3.14,0.5,0.1")),
        "mem/table.csv:3:1: column 'ti': 30 rad is not a zenith angle within (−π/2, π/2): the \
         layout says angle_unit = \"rad\"; if the file's angles are in degrees, set \
         angle_unit = \"deg\""
    );
    let unsigned = GOOD_LAYOUT.replace("index_base = 1", "index_base = 1\nsigned_angles = false");
    assert_eq!(
        table_message(&unsigned, &table("ti,tr,pr,M11,M12", "30,-20,180,0.5,0.1")),
        "mem/table.csv:3:4: column 'tr': -20 is negative, but the layout says signed_angles = \
         false: set signed_angles = true if θ < 0 is the direction across the normal"
    );
    assert_eq!(
        table_message(
            GOOD_LAYOUT,
            &table("ti,tr,pr,M11,M12", "30,20,180,-0.5,0.1")
        ),
        "mem/table.csv:3:11: column 'M11' (the layout's m00): -0.5 is negative, but m00 (the \
         unpolarized BRDF, sr⁻¹) is ≥ 0"
    );
    assert_eq!(
        table_message(GOOD_LAYOUT, &table("ti,tr,pr,M11,M12", "30,20,180,0.5")),
        "mem/table.csv:3:14: the row has 4 fields, the header row has 5"
    );
    assert_eq!(
        table_message(GOOD_LAYOUT, "ti,tr,pr,M11,M12\n30,20,180,0.5,0.1\n"),
        "mem/table.csv:1:1: no wavelength: add a 'wavelength_um' column or a '# wavelength_um: \
         <micrometres>' header line"
    );
    assert_eq!(
        table_message(GOOD_LAYOUT, &table("ti;tr;pr;M11;M12", "30;20;180;0.5;0.1")),
        "mem/table.csv:2:3: fields are separated by ';', expected ','"
    );
}

#[test]
fn the_xyxy_basis_needs_the_elements_it_mixes_and_a_header_that_agrees() {
    let xyxy = GOOD_LAYOUT.replace(
        "index_base = 1",
        "index_base = 1\nmueller_convention = \"xyxy\"",
    );
    assert_eq!(
        table_message(&xyxy, GOOD_TABLE),
        "mem/table.csv:2:1: the layout's mueller_convention = \"xyxy\" is rotated into psps, \
         which mixes m01 with m02, but the file has no column for m02: add it, or say \
         mueller_convention = \"psps\" if the file already is psps"
    );
    assert_eq!(
        table_message(
            GOOD_LAYOUT,
            &format!("# mueller_convention: xyxy\n{GOOD_TABLE}")
        ),
        "mem/table.csv:1:23: header 'mueller_convention': 'xyxy' disagrees with the layout's \
         mueller_convention = \"psps\""
    );
    // A header that agrees is kept as metadata.
    let layout = Layout::parse(Path::new("l.toml"), &xyxy).unwrap();
    let table =
        "# mueller_convention: XYXY\n# wavelength_um: 10\nti,tr,pr,M11,M14\n30,20,0,1,0.5\n";
    let sets = parse_with_layout(Path::new("t.csv"), table.as_bytes(), &layout).unwrap();
    assert_eq!(sets[0].metadata["mueller_convention"], "XYXY");
    assert_eq!(sets[0].points.row(0).values, [1.0, 0.5]);
}

// ---------------------------------------------------------------------------------------------
// Round trips.
// ---------------------------------------------------------------------------------------------

const SPECTRAL: &str = "measurements/silicate_glass.csv";

fn geometry_values(set: &MeasurementSet) -> Vec<([f64; 4], Vec<f64>)> {
    set.points
        .iter()
        .map(|p| {
            (
                [p.theta_i_deg, p.phi_i_deg, p.theta_r_deg, p.phi_r_deg],
                p.values.to_vec(),
            )
        })
        .collect()
}

#[test]
fn an_identity_layout_reads_a_design_2_1_file_exactly_as_its_own_reader() {
    let layout = Layout::parse(
        Path::new("identity.toml"),
        "[columns]\ntheta_i_deg = \"theta_i_deg\"\nphi_i_deg = \"phi_i_deg\"\n\
         theta_r_deg = \"theta_r_deg\"\nphi_r_deg = \"phi_r_deg\"\n\
         wavelength_um = \"wavelength_um\"\nelements = \"m{i}{j}\"\n",
    )
    .unwrap();
    let own = read_measurement_sets(Path::new(SPECTRAL)).unwrap();
    let through = read_with_layout(Path::new(SPECTRAL), &layout).unwrap();
    assert_eq!(own.len(), through.len());
    for (a, b) in own.iter().zip(&through) {
        assert_eq!(
            (a.wavelength_um, &a.material, &a.elements, &a.sha256),
            (b.wavelength_um, &b.material, &b.elements, &b.sha256)
        );
        assert_eq!(geometry_values(a), geometry_values(b));
    }
    // The u_ columns are not the layout's: named in a note, not read.
    assert!(through[0]
        .notes
        .iter()
        .any(|n| n.contains("columns the layout does not name, not read: u_m00")));
}

/// The spectral file written out as an instrument would (radians, signed θ_r, specular at φ_i,
/// elements from 1 and normalized by m00, in the xyxy basis) and read back through the layout
/// that says so.
#[test]
fn a_design_2_1_file_written_in_an_instruments_conventions_reads_back() {
    let own = read_measurement_sets(Path::new(SPECTRAL)).unwrap();
    let mut text = String::from("lambda,ti,pi,tr,pr,BRDF");
    for r in 1..=4 {
        for c in 1..=4 {
            if (r, c) != (1, 1) {
                text.push_str(&format!(",N{r}{c}"));
            }
        }
    }
    text.push('\n');
    for set in &own {
        for (k, p) in set.points.iter().enumerate() {
            let xyxy = xyxy_from_psps(&matrix_of(set, k), p.phi_i_deg, p.phi_r_deg);
            // Every other row with the detector written across the normal.
            let (theta_r, phi_r) = if k % 2 == 1 && p.theta_r_deg > 0.0 {
                (-p.theta_r_deg, p.phi_r_deg + 180.0)
            } else {
                (p.theta_r_deg, p.phi_r_deg)
            };
            let m00 = xyxy[0][0];
            text.push_str(&format!(
                "{:?},{:?},{:?},{:?},{:?},{:?}",
                set.wavelength_um,
                p.theta_i_deg.to_radians(),
                p.phi_i_deg.to_radians(),
                theta_r.to_radians(),
                (phi_r - 180.0).to_radians(),
                m00
            ));
            for (r, row) in xyxy.iter().enumerate() {
                for (c, value) in row.iter().enumerate() {
                    if (r, c) != (0, 0) {
                        text.push_str(&format!(",{:?}", value / m00));
                    }
                }
            }
            text.push('\n');
        }
    }
    let layout = Layout::parse(
        Path::new("instrument.toml"),
        "[columns]\ntheta_i_deg = \"ti\"\nphi_i_deg = \"pi\"\ntheta_r_deg = \"tr\"\n\
         phi_r_deg = \"pr\"\nwavelength_um = \"lambda\"\nm00 = \"BRDF\"\nelements = \"N{i}{j}\"\n\
         [conventions]\nindex_base = 1\nnormalized = true\nspecular_phi_r = \"phi_i\"\n\
         angle_unit = \"rad\"\nmueller_convention = \"xyxy\"\n[uncertainty]\nmodel = \"estimate\"\n",
    )
    .unwrap();
    let back = parse_with_layout(Path::new("instrument.csv"), text.as_bytes(), &layout).unwrap();
    assert_eq!(back.len(), own.len());
    let same_angle = |a: f64, b: f64| {
        let d = (a - b).rem_euclid(360.0);
        d.min(360.0 - d) <= 1e-12
    };
    for (a, b) in own.iter().zip(&back) {
        assert_eq!(
            (a.wavelength_um, &a.elements),
            (b.wavelength_um, &b.elements)
        );
        for (p, q) in a.points.iter().zip(&b.points) {
            assert!((p.theta_i_deg - q.theta_i_deg).abs() <= 1e-12);
            assert!((p.theta_r_deg - q.theta_r_deg).abs() <= 1e-12);
            assert!(
                same_angle(p.phi_i_deg, q.phi_i_deg),
                "{} {}",
                p.phi_i_deg,
                q.phi_i_deg
            );
            assert!(
                same_angle(p.phi_r_deg, q.phi_r_deg),
                "{} {}",
                p.phi_r_deg,
                q.phi_r_deg
            );
            for (slot, (x, y)) in p.values.iter().zip(q.values).enumerate() {
                let name = MUELLER_ELEMENT_NAMES[a.elements[slot]];
                assert!((x - y).abs() <= 1e-12, "line {} {name}: {x} vs {y}", q.line);
            }
            assert!(q.uncertainties().all(|u| u.is_some_and(|u| u > 0.0)));
        }
    }
    let rows_across = own.iter().map(|s| s.points.len() / 2).sum::<usize>();
    assert!(back[0].notes.iter().any(|n| n.contains(
        "read through the layout instrument.toml: \
         angles in radians converted to degrees; φ_r turned by 180° (the file's specular azimuth \
         is φ_i); elements normalized by m00 multiplied by 'BRDF'; Mueller matrices rotated from \
         the sample's xyxy basis into psps"
    )));
    assert!(rows_across > 0);
}

/// docs/measurements.md's worked example shows the shipped layout and the notes the reader gives.
#[test]
fn the_worked_example_shows_the_shipped_layout_and_its_notes() {
    let page = std::fs::read_to_string("docs/measurements.md").unwrap();
    let layout_text = std::fs::read_to_string(PTFE_LAYOUT).unwrap();
    let body = &layout_text[layout_text.find("[columns]").unwrap()..];
    assert!(
        page.contains(&format!("```toml\n{body}```")),
        "docs/measurements.md does not show {PTFE_LAYOUT} from [columns] on"
    );
    let layout = Layout::read(Path::new(PTFE_LAYOUT)).unwrap();
    let sets = read_with_layout(Path::new(PTFE), &layout).unwrap();
    for note in sets.iter().flat_map(|s| &s.notes) {
        assert!(
            page.contains(&format!("\n{note}\n")),
            "docs/measurements.md does not show the note: {note}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// The command line: `irpol fit --layout`, a file's own `# layout:` line, row selection, and the
// fit record that lets `irpol report` read the source the same way.
// ---------------------------------------------------------------------------------------------

/// `irpol fit INPUT EXTRA… --out DIR/fits --reports DIR/reports`: (success, stdout, stderr).
fn fit_cli(dir: &Path, input: &Path, extra: &[&str]) -> (bool, String, String) {
    let (fits, reports) = (dir.join("fits"), dir.join("reports"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_irpol"))
        .arg("fit")
        .arg(input)
        .args(extra)
        .args(["--out", fits.to_str().unwrap(), "--reports"])
        .arg(&reports)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The rows of the shipped file at 1.064 µm and θ_i ∈ {0, 30, 60, 75}°, counted independently
/// of the selection code: from the file's own signed `thetai` column.
fn ptfe_rows_at(wavelength: &str, thetas: &[f64]) -> usize {
    let text = std::fs::read_to_string(PTFE).unwrap();
    text.lines()
        .skip(1)
        .filter(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            let theta: f64 = fields[1].parse().unwrap();
            fields[0] == wavelength && thetas.iter().any(|t| (theta.abs() - t).abs() <= 0.05)
        })
        .count()
}

#[test]
fn fit_through_the_layout_records_it_and_report_rebuilds_the_same_figure() {
    let dir = tempfile::tempdir().unwrap();
    let extra = [
        "--layout",
        PTFE_LAYOUT,
        "--wavelength",
        "1.064",
        "--theta-i",
        "0,30,60,75",
    ];
    let (ok, stdout, stderr) = fit_cli(dir.path(), Path::new(PTFE), &extra);
    assert!(ok, "{stderr}");
    let rows = ptfe_rows_at("1.064", &[0.0, 30.0, 60.0, 75.0]);
    assert!(rows > 1000, "{rows}");
    assert!(stdout.starts_with("PTFE_351_1064: "), "{stdout}");
    // Every row of PTFE's strongly depolarizing matrices passes Cloude's test.
    assert!(
        stdout.contains(&format!("; 0 of {rows} rows not realizable beyond 2σ")),
        "{stdout}"
    );
    // docs/measurements.md's worked example shows the command and these notes.
    let page = std::fs::read_to_string("docs/measurements.md").unwrap();
    assert!(page.contains(&format!("\nirpol fit {PTFE} {}", extra.join(" "))));
    for note in [
        format!("{PTFE}: kept the rows at 1.064 µm, one of its 2 wavelengths"),
        format!("{PTFE} at 1.064 µm: kept {rows} rows of 1824 with θ_i = 0, 30, 60, 75°"),
    ] {
        assert!(stderr.contains(&format!("note: {note}\n")), "{stderr}");
        assert!(
            page.contains(&format!("\n{note}\n")),
            "the page lacks: {note}"
        );
    }
    // The notes are those of the kept wavelength, each once: not the other wavelength's.
    assert!(!stderr.contains("0.351 µm"), "{stderr}");
    let notes: Vec<&str> = stderr.lines().filter(|l| l.contains("note:")).collect();
    let once: std::collections::BTreeSet<&&str> = notes.iter().collect();
    assert_eq!(once.len(), notes.len(), "{stderr}");
    let entry = dir.path().join("fits/PTFE_351_1064.toml");
    let material = irpol::material::Material::load(&entry).unwrap();
    let record = material.fit.unwrap();
    assert_eq!(record.layout.as_deref(), Some(Path::new(PTFE_LAYOUT)));
    assert_eq!(record.points, rows);
    let selection = record.selection.unwrap();
    assert_eq!(selection.wavelength_um, Some(1.064));
    assert_eq!(selection.theta_i_deg, [0.0, 30.0, 60.0, 75.0]);

    let rebuilt = dir.path().join("rebuilt");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_irpol"))
        .arg("report")
        .arg(&entry)
        .arg("--reports")
        .arg(&rebuilt)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let figure = |folder: &Path| std::fs::read(folder.join("PTFE_351_1064.png")).unwrap();
    assert!(
        figure(&dir.path().join("reports")) == figure(&rebuilt),
        "the rebuilt report differs from the fit's"
    );

    // Without the layout the report cannot read the file as it was fitted: the record's layout
    // is what makes the rebuild possible.
    let text = std::fs::read_to_string(&entry).unwrap();
    let without = text.replace(&format!("layout = \"{PTFE_LAYOUT}\"\n"), "");
    assert_ne!(without, text);
    std::fs::write(&entry, without).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_irpol"))
        .arg("report")
        .arg(&entry)
        .arg("--reports")
        .arg(&rebuilt)
        .output()
        .unwrap();
    assert!(!out.status.success());
}

/// A copy of the shipped table that names its layout on a `# layout:` line, beside the layout.
fn ptfe_naming_its_layout(dir: &Path) -> std::path::PathBuf {
    std::fs::create_dir_all(dir.join("data")).unwrap();
    std::fs::copy(PTFE_LAYOUT, dir.join("data/instrument.toml")).unwrap();
    let table = dir.join("data/ptfe.csv");
    let text = std::fs::read_to_string(PTFE).unwrap();
    std::fs::write(&table, format!("# layout: instrument.toml\n{text}")).unwrap();
    table
}

#[test]
fn a_file_naming_its_layout_is_read_through_it_and_a_different_layout_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let table = ptfe_naming_its_layout(dir.path());
    let own = read_measurement_file(&table, None).unwrap();
    let layout = Layout::read(Path::new(PTFE_LAYOUT)).unwrap();
    let shipped = read_with_layout(Path::new(PTFE), &layout).unwrap();
    assert_eq!(own.len(), 2);
    for (a, b) in own.iter().zip(&shipped) {
        assert_eq!(a.points.len(), b.points.len());
        for (p, q) in a.points.iter().zip(&b.points) {
            assert_eq!(p.values, q.values);
            assert!(p.uncertainties().eq(q.uncertainties()));
        }
    }
    // The same layout given again (another path, same content) is no disagreement.
    assert!(read_measurement_file(&table, Some(&layout)).is_ok());

    let extra = ["--wavelength", "1.064", "--theta-i", "0,30,60,75"];
    let (ok, _, stderr) = fit_cli(dir.path(), &table, &extra);
    assert!(ok, "{stderr}");
    let entry = dir.path().join("fits/ptfe.toml");
    let record = irpol::material::Material::load(&entry)
        .unwrap()
        .fit
        .unwrap();
    assert_eq!(record.layout, None, "the file names its layout itself");
    let text = std::fs::read_to_string(&entry).unwrap();
    assert!(!text.contains("\nlayout ="), "{text}");

    let other = dir.path().join("fixed.toml");
    let fixed = std::fs::read_to_string(PTFE_LAYOUT)
        .unwrap()
        .replace("model = \"estimate\"", "model = \"fixed\"");
    std::fs::write(&other, fixed).unwrap();
    let (ok, _, stderr) = fit_cli(
        &dir.path().join("refused"),
        &table,
        &["--layout", other.to_str().unwrap()],
    );
    assert!(!ok);
    assert_eq!(
        stderr.trim_end(),
        format!(
            "irpol: error: {}:1:11: header 'layout': the file names the layout {}, but the \
             layout {} was given too and reads the table differently: give one of them (drop \
             --layout, or the '# layout:' line)",
            table.display(),
            dir.path().join("data/instrument.toml").display(),
            other.display()
        )
    );
    assert!(!dir.path().join("refused").exists());

    let missing = dir.path().join("data/missing.csv");
    let text = std::fs::read_to_string(&table).unwrap();
    std::fs::write(&missing, text.replace("instrument.toml", "gone.toml")).unwrap();
    assert_eq!(
        read_measurement_file(&missing, None)
            .unwrap_err()
            .to_string(),
        format!(
            "{}:1:11: header 'layout': 'gone.toml' (looked for at {}, beside the file): no such \
             file or directory: fix the path, relative to the measurement file's folder",
            missing.display(),
            dir.path().join("data/gone.toml").display()
        )
    );
}

#[test]
fn a_selection_the_file_does_not_hold_is_refused_naming_what_it_holds() {
    let dir = tempfile::tempdir().unwrap();
    let refused = |extra: &[&str]| {
        let mut args = vec!["--layout", PTFE_LAYOUT];
        args.extend_from_slice(extra);
        let (ok, stdout, stderr) = fit_cli(dir.path(), Path::new(PTFE), &args);
        assert!(!ok && stdout.is_empty(), "{stdout}");
        stderr.trim_end().to_string()
    };
    assert_eq!(
        refused(&["--wavelength", "10.6"]),
        format!(
            "irpol: error: {PTFE}: holds no rows at the selected wavelength 10.6 µm; it holds \
             0.351, 1.064 µm: select one of those"
        )
    );
    assert_eq!(
        refused(&["--wavelength", "1.064", "--theta-i", "0,45.5"]),
        format!(
            "irpol: error: {PTFE}: no row has θ_i within 0.05° of the selected 45.5°; its rows \
             have θ_i = 0, 15, 30, 45, 60, 75°: select among those"
        )
    );
    assert_eq!(
        refused(&["--theta-i", "95"]),
        "irpol: error: selected incidence angle 95°: not a zenith angle in [0°, 90°)"
    );
    assert!(!dir.path().join("fits").exists());
}

/// The bad inputs a layout is most often wrong in, refused by `irpol fit --layout` with the
/// file, the line and what to fix, before anything is written.
#[test]
fn fit_refuses_a_layout_that_does_not_fit_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let table = dir.path().join("table.csv");
    std::fs::write(
        &table,
        "# wavelength_um: 10\nti,tr,pr,M11,M12,M21\n30,20,180,0.5,0.1,0.2\n60,50,180,0.6,0.1,0.2\n",
    )
    .unwrap();
    let layout = dir.path().join("layout.toml");
    let refused = |layout_text: &str| {
        std::fs::write(&layout, layout_text).unwrap();
        let args = ["--layout", layout.to_str().unwrap()];
        let (ok, _, stderr) = fit_cli(dir.path(), &table, &args);
        assert!(!ok);
        stderr.trim_end().to_string()
    };
    let (t, l) = (table.display(), layout.display());
    // A column the file lacks.
    assert_eq!(
        refused(&GOOD_LAYOUT.replace("\"tr\"", "\"thetar\"")),
        format!(
            "irpol: error: {t}:2:1: column 'thetar', which the layout {l} names for \
             theta_r_deg, is not in the header row: fix [columns] theta_r_deg (names are \
             case-sensitive)"
        )
    );
    // A basis irpol does not know.
    assert_eq!(
        refused(&format!("{GOOD_LAYOUT}mueller_convention = \"spsp\"\n")),
        format!(
            "irpol: error: {l}:9:22: not a valid layout: unknown variant `spsp`, expected `psps` \
             or `xyxy`"
        )
    );
    // Normalized elements without m00.
    assert_eq!(
        refused(
            &GOOD_LAYOUT
                .replace("m00 = \"M11\"\n", "")
                .replace("index_base = 1", "index_base = 1\nnormalized = true")
        ),
        format!(
            "irpol: error: {l}:8:14: layout key [columns] m00: normalized = true multiplies the \
             elements by m00, but [columns] names no m00 column: add m00 = \"<column of the \
             unpolarized BRDF>\""
        )
    );
    // Degrees read as radians: θ beyond the hemisphere in the declared unit.
    assert_eq!(
        refused(&GOOD_LAYOUT.replace("index_base = 1", "index_base = 1\nangle_unit = \"rad\"")),
        format!(
            "irpol: error: {t}:3:1: column 'ti': 30 rad is not a zenith angle within (−π/2, \
             π/2): the layout says angle_unit = \"rad\"; if the file's angles are in degrees, \
             set angle_unit = \"deg\""
        )
    );
    // A layout file that is not there.
    std::fs::remove_file(&layout).unwrap();
    let args = ["--layout", layout.to_str().unwrap()];
    let (ok, _, stderr) = fit_cli(dir.path(), &table, &args);
    assert!(!ok);
    assert_eq!(
        stderr.trim_end(),
        format!("irpol: error: {l}:1:1: no such file or directory")
    );
    assert!(!dir.path().join("fits").exists() && !dir.path().join("reports").exists());
}

/// Radians declared as degrees through a layout: refused before the fit, with the layout's fix;
/// `--angles degrees` reads them as degrees with a note said before the fit and repeated with a
/// fit error; `--angles radians` is refused, since the layout states the unit.
#[test]
fn fit_refuses_radians_through_a_layout_unless_told() {
    let dir = tempfile::tempdir().unwrap();
    let table = dir.path().join("table.csv");
    let mut text = String::from("# wavelength_um: 10\nti,tr,pr,M11\n");
    for (ti, tr) in [(0.5, 0.5), (0.5, 0.7), (1.0, 0.9), (1.0, 1.2)] {
        text.push_str(&format!("{ti},{tr},180,0.5\n"));
    }
    std::fs::write(&table, text).unwrap();
    let layout = dir.path().join("layout.toml");
    std::fs::write(&layout, GOOD_LAYOUT.replace("elements = \"M{i}{j}\"\n", "")).unwrap();
    let args = ["--layout", layout.to_str().unwrap(), "--free", "sigma,rho"];
    let (ok, _, stderr) = fit_cli(dir.path(), &table, &args);
    assert!(!ok);
    let evidence = "every zenith angle is within ±1.2 (≤ π/2 = 1.5708) and not all whole degrees \
                    (0.5 on line 3): these look like radians";
    assert_eq!(
        stderr.trim_end(),
        format!(
            "irpol: error: {}:3:1: {evidence}, but the angles are declared in degrees: set \
             angle_unit = \"rad\" in the layout {} (--angles degrees if they are degrees)",
            table.display(),
            layout.display()
        )
    );
    assert!(!dir.path().join("fits").exists());
    // Told they are degrees: the note comes before the fit's output and with its error (a
    // dispersion law for one wavelength fails the fit after the files are read).
    let told = [
        &args[..],
        &["--angles", "degrees", "--dispersion", "cauchy"],
    ]
    .concat();
    let (ok, _, stderr) = fit_cli(dir.path(), &table, &told);
    let note = format!(
        "{}: {evidence}; read as degrees, as --angles degrees says",
        table.display()
    );
    assert!(!ok);
    assert!(
        stderr.starts_with(&format!("irpol: note: {note}\n")),
        "{stderr}"
    );
    assert!(
        stderr.trim_end().ends_with(&format!("; note: {note}")),
        "{stderr}"
    );
    // A layout states its unit: --angles radians is refused, pointing at it.
    let radians = [&args[..], &["--angles", "radians"]].concat();
    let (ok, _, stderr) = fit_cli(dir.path(), &table, &radians);
    assert!(!ok);
    assert!(stderr.contains("--angles radians: the layout"), "{stderr}");
    assert!(
        stderr.contains("fix angle_unit there and drop --angles"),
        "{stderr}"
    );
}

// ---------------------------------------------------------------------------------------------
// Realizability of measured rows (Cloude's test against each row's own noise).
// ---------------------------------------------------------------------------------------------

#[test]
fn rows_are_flagged_unrealizable_only_beyond_their_noise() {
    let layout = Layout::parse(
        Path::new("l.toml"),
        "[columns]\ntheta_i_deg = \"ti\"\ntheta_r_deg = \"tr\"\nm00 = \"M00\"\n\
         elements = \"M{i}{j}\"\n",
    )
    .unwrap();
    let names: Vec<String> = (0..16).map(|k| format!("M{}{}", k / 4, k % 4)).collect();
    let mut table = format!("# wavelength_um: 10\nti,tr,{}\n", names.join(","));
    let diagonal = |d: [f64; 4]| {
        (0..16)
            .map(|k| {
                if k % 5 == 0 {
                    d[k / 4].to_string()
                } else {
                    "0".into()
                }
            })
            .collect::<Vec<_>>()
            .join(",")
    };
    // The identity, a realizable depolarizer, and diag(1, 1, 1, −1): eigenvalue −½.
    for d in [
        [1.0, 1.0, 1.0, 1.0],
        [1.0, 0.2, -0.2, -0.2],
        [1.0, 1.0, 1.0, -1.0],
    ] {
        table.push_str(&format!("10,20,{}\n", diagonal(d)));
    }
    let set = parse_with_layout(Path::new("t.csv"), table.as_bytes(), &layout)
        .unwrap()
        .remove(0);
    // No uncertainties: any negative eigenvalue beyond rounding counts, a pure one does not.
    let checked = irpol::measure::unrealizable_rows(&set, 2.0);
    assert_eq!(
        (checked.unrealizable.as_slice(), checked.checked),
        (&[2][..], 3)
    );
    let mut noisy = set.clone();
    // noise 0.4: −½ is within 2σ
    noisy.points = (noisy.points.iter())
        .map(|row| MeasurementPoint {
            uncertainties: vec![Some(0.2); 16],
            ..row.to_point()
        })
        .collect();
    assert!(irpol::measure::unrealizable_rows(&noisy, 2.0)
        .unrealizable
        .is_empty());
    let mut partial = set;
    partial.elements.truncate(4);
    let none = irpol::measure::unrealizable_rows(&partial, 2.0);
    assert_eq!((none.checked, none.unchecked), (0, 3));
}

/// The shipped PTFE rows read through the layout, with their estimated uncertainties: a
/// strongly depolarizing sample, every row realizable with a wide margin.
#[test]
fn the_shipped_ptfe_rows_are_all_realizable() {
    let layout = Layout::read(Path::new(PTFE_LAYOUT)).unwrap();
    for set in read_with_layout(Path::new(PTFE), &layout).unwrap() {
        let outcome = irpol::measure::unrealizable_rows(&set, 2.0);
        let at_1 = irpol::measure::unrealizable_rows(&set, 1.0)
            .unrealizable
            .len();
        let at_3 = irpol::measure::unrealizable_rows(&set, 3.0)
            .unrealizable
            .len();
        let smallest = set
            .points
            .iter()
            .map(|p| {
                let m = irpol::optics::Mueller::from_row_slice(p.values);
                irpol::optics::coherency_eigenvalues(&m)[0] / p.values[0]
            })
            .fold(f64::INFINITY, f64::min);
        eprintln!(
            "PTFE {} µm: {} of {} rows not realizable beyond 2σ (1σ: {at_1}, 3σ: {at_3}); \
             smallest eigenvalue {smallest:.4} m00",
            set.wavelength_um,
            outcome.unrealizable.len(),
            outcome.checked
        );
        assert_eq!((outcome.checked, outcome.unchecked), (1824, 0));
        assert!(outcome.unrealizable.len() <= at_1 && at_3 <= outcome.unrealizable.len());
        assert!(at_1 == 0 && smallest > 0.05, "{smallest}");
    }
}

/// A layout table meets the value limit of every table reader (±1e12 sr⁻¹), its normalized
/// elements once multiplied by m00, refused at file:line:column (issue 42: m00 = 1e13 was fitted,
/// a normalized 1e308 became inf).
#[test]
fn layout_values_meet_the_limit_of_every_table_reader() {
    let table = |row: &str| format!("# wavelength_um: 10\nti,tr,pr,M11,M12\n{row}\n");
    assert_eq!(
        table_message(GOOD_LAYOUT, &table("30,20,180,1e13,0.1")),
        "mem/table.csv:3:11: column 'M11': 1e13 sr⁻¹ is beyond ±1e12 sr⁻¹, far above any \
         measurable BRDF (the mirror peak of the smoothest model is ~1e7 sr⁻¹): a fit of it has \
         no finite χ²"
    );
    assert!(table_message(GOOD_LAYOUT, &table("30,20,180,0.5,-2e12"))
        .starts_with("mem/table.csv:3:15: column 'M12': -2e12 sr⁻¹ is beyond ±1e12 sr⁻¹"));
    let normalized = GOOD_LAYOUT.replace("index_base = 1", "index_base = 1\nnormalized = true");
    assert!(
        table_message(&normalized, &table("30,20,180,2,1e308"))
            .starts_with("mem/table.csv:3:13: column 'M12': 1e308 sr⁻¹ is beyond ±1e12 sr⁻¹"),
        "{}",
        table_message(&normalized, &table("30,20,180,2,1e308"))
    );
    // 1e12 / m00 passes alone, not once multiplied by m00 = 10.
    assert!(table_message(&normalized, &table("30,20,180,10,1e12"))
        .starts_with("mem/table.csv:3:14: column 'M12': 1e12 × m00 = 1e13 sr⁻¹ is beyond"));
    let layout = Layout::parse(Path::new("mem/layout.toml"), &normalized).unwrap();
    let sets = parse_with_layout(
        Path::new("t.csv"),
        table("30,20,180,10,1e11").as_bytes(),
        &layout,
    )
    .unwrap();
    assert_eq!(sets[0].points.row(0).values, [10.0, 1e12]);
}

/// One column named for two roles is refused at the second role's value, naming both roles and
/// the column (issue 42: θ_i and θ_r both `thetar` read every row as specular).
#[test]
fn one_column_for_two_roles_is_refused_naming_both() {
    assert_eq!(
        layout_message(&GOOD_LAYOUT.replace("theta_i_deg = \"ti\"", "theta_i_deg = \"tr\"")),
        "mem/layout.toml:3:15: column 'tr' is named for both theta_i_deg and theta_r_deg: one \
         column holds one role; fix [columns] theta_r_deg"
    );
    assert_eq!(
        layout_message(&GOOD_LAYOUT.replace("phi_r_deg = \"pr\"", "phi_r_deg = \"M11\"")),
        "mem/layout.toml:5:7: column 'M11' is named for both phi_r_deg and m00: one column holds \
         one role; fix [columns] m00"
    );
    assert!(layout_message(
        &GOOD_LAYOUT.replace("elements = \"M{i}{j}\"", "elements = { m01 = \"ti\" }")
    )
    .contains("column 'ti' is named for both theta_i_deg and m01"));
}
