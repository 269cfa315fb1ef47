//! Bounded fuzzing of every reader of user files and flags: the measurement CSV reader, instrument
//! layouts and the tables read through them, the OBJ and PLY mesh readers, the material TOML loader (grey and spectral), the eval geometry reader,
//! the thermal weather CSV reader, the atmosphere table reader, the scene loader (a thermal scene's keys), the `--times`
//! sweep, the `sun --times-file` reader, the text flags of `irpol fit` (with the cost estimate
//! of the options they give) and `validate`'s scoring of a material on measurements get random
//! bytes and mutations of real inputs (the
//! shipped measurements and materials, excerpts of the car mesh, small PLY files, weather CSVs, a
//! thermal scene, sweeps and instants), some with runs of thousands of one character. Whatever
//! they are fed, they must return — a value or an error whose message is one line of at most a
//! few hundred characters without control characters — and never panic. Every reader given a file's
//! name starts its refusals with it (`file:`); those of layouts, layout tables and EPW/TMY3
//! files with the line too (`file:line:`). (The OBJ and PLY parsers take bytes alone; their
//! callers add the file.) EPW header lines in any shape keep every hourly row. (The sweep specs of
//! `python -m irpol.dataset` are read in Python; what they reach in Rust is the scene loader.)
//!
//! Each property runs a fixed number of cases from a fixed seed, so that CI's pass is the same
//! pass every time (the scene loader, the slowest reader, a tenth as many cases); together they
//! take about half a minute in a release build on two shared cores. Raise `FUZZ_CASES` and
//! change `FUZZ_SEED` (environment) to fuzz longer or elsewhere, e.g.
//! `FUZZ_CASES=100000 FUZZ_SEED=7 cargo test --release --test it fuzz_readers`.

use irpol::app::evaluate::{parse_geometry_csv, write_mueller_csv};
use irpol::app::sun::parse_times;
use irpol::app::{one_line, parse_sweep, MAX_SWEEP_VALUES};
use irpol::atmosphere::table::parse_table;
use irpol::material::Material;
use irpol::measure::parse_measurement_csv;
use irpol::optics::RefractiveIndex;
use irpol::pbrdf::{Pbrdf, Shadowing, SlopeDistribution};
use irpol::scene::load_scene_text;
use irpol::scene::obj::parse_obj;
use irpol::scene::ply::parse_ply;
use irpol::weather::{Site, StationFormat, StationWeather, Weather};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::path::Path;

/// Cases per property unless `FUZZ_CASES` says otherwise.
const DEFAULT_CASES: u32 = 30_000;

/// The random generator's seed unless `FUZZ_SEED` says otherwise.
const DEFAULT_SEED: u64 = 20_261_127;

fn config() -> ProptestConfig {
    let cases = std::env::var("FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(DEFAULT_CASES);
    config_of(cases)
}

/// [`config`] with a tenth of the cases, for readers that build a whole scene per case.
fn scene_config() -> ProptestConfig {
    let cases = config().cases;
    config_of((cases / 10).max(1))
}

fn config_of(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        // Failures are reported with the shrunk input; nothing is written into the source tree.
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(
            std::env::var("FUZZ_SEED")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(DEFAULT_SEED),
        ),
        ..ProptestConfig::default()
    }
}

fn shipped(path: &str) -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).unwrap()
}

/// Up to `vertices` vertices of the car mesh and the faces (with their groups) that use only them.
fn car_excerpt(vertices: usize, faces: usize) -> Vec<u8> {
    let text = String::from_utf8(shipped("scenes/car.obj")).unwrap();
    let mut out = String::new();
    let (mut v, mut f) = (0, 0);
    for line in text.lines() {
        let keep = match line.split_whitespace().next() {
            Some("v") => {
                v += 1;
                v <= vertices
            }
            Some("f") => {
                let inside = line
                    .split_whitespace()
                    .skip(1)
                    .all(|c| c.parse::<usize>().is_ok_and(|i| i <= vertices));
                f += usize::from(inside);
                inside && f <= faces
            }
            _ => true,
        };
        if keep {
            out.push_str(line);
            out.push('\n');
        }
    }
    out.into_bytes()
}

const ASCII_PLY: &str = "ply\nformat ascii 1.0\ncomment fuzz seed\nelement vertex 4\n\
    property float x\nproperty float y\nproperty float z\nproperty float temperature\n\
    element face 2\nproperty list uchar int vertex_indices\nend_header\n\
    0 0 0 300\n1 0 0 310\n0 1 0 320\n1 1 0 330\n3 0 1 2\n4 0 1 3 2\n";

fn binary_ply() -> Vec<u8> {
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nproperty float nx\nproperty float ny\n\
        property float nz\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
        .to_vec();
    for v in [
        0.0f32, 0., 0., 0., 0., 1., 1., 0., 0., 0., 0., 1., 0., 1., 0., 0., 0., 1.,
    ] {
        bytes.extend(v.to_le_bytes());
    }
    bytes.push(3);
    for i in [0u32, 1, 2] {
        bytes.extend(i.to_le_bytes());
    }
    bytes
}

const GEOMETRY: &str = "# comment\nlabel,theta_i_deg,phi_i_deg,theta_r_deg,phi_r_deg\n\
    spec,30,0,30,180\n\"a,b\",10,0,70,90\noop, 45 ,0,45,270\n";

/// Text an input may plausibly hold in the wrong place: extreme numbers, separators, controls.
const TOKENS: &[&str] = &[
    "1e308",
    "-1e308",
    "1e-320",
    "0",
    "-0",
    "nan",
    "inf",
    "-inf",
    "4294967295",
    "18446744073709551616",
    "-1",
    "90",
    "1e999",
    ",",
    ";",
    "\"",
    "\"\"",
    "#",
    "\n",
    "\r",
    "\r\n",
    "\t",
    "\0",
    "\u{1b}[2J",
    "\u{feff}",
    "\u{202e}",
    "é",
    "=",
    "[",
    "]",
    "{",
    "}",
    "/",
    "//",
    "element face 4294967295\n",
    "format ascii 2.0\n",
    "property list uchar int vertex_indices\n",
    "end_header\n",
    "f ",
    "v ",
    "g ",
    "rho = 0.5\n",
    "[fit]\n",
    "# wavelength_um: ",
    "m00",
    "u_m00",
    "1e-310",
    "5e-324",
    "1e13",
    "\"thetar\"",
    "f_r11",
    "DATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n",
    "COMMENTS 2,\n",
];

/// One edit of an input.
#[derive(Clone, Debug)]
enum Mutation {
    /// XOR a byte at a relative position with a non-zero mask.
    Flip(f64, u8),
    /// Insert bytes at a relative position.
    Insert(f64, Vec<u8>),
    /// Insert one of [`TOKENS`] at a relative position.
    Token(f64, usize),
    /// Remove a relative range.
    Remove(f64, f64),
    /// Repeat a relative range in place (count from 1 to 8).
    Repeat(f64, f64, usize),
    /// Keep only a relative prefix.
    Truncate(f64),
    /// Insert one byte repeated 1000 to 4000 times (a line or value far too long to quote).
    Long(f64, u8, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let at = 0.0..=1.0f64;
    prop_oneof![
        3 => (at.clone(), 1..=255u8).prop_map(|(p, m)| Mutation::Flip(p, m)),
        2 => (at.clone(), prop::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(p, b)| Mutation::Insert(p, b)),
        4 => (at.clone(), 0..TOKENS.len()).prop_map(|(p, t)| Mutation::Token(p, t)),
        2 => (at.clone(), 0.0..0.2f64).prop_map(|(p, w)| Mutation::Remove(p, w)),
        1 => (at.clone(), 0.0..0.05f64, 1..8usize).prop_map(|(p, w, n)| Mutation::Repeat(p, w, n)),
        1 => at.clone().prop_map(Mutation::Truncate),
        1 => (at, prop_oneof![Just(b'9'), Just(b'a'), Just(0x1e), any::<u8>()], 1000..4000usize)
            .prop_map(|(p, b, n)| Mutation::Long(p, b, n)),
    ]
}

fn apply(mut bytes: Vec<u8>, mutations: &[Mutation]) -> Vec<u8> {
    let index = |len: usize, p: f64| ((len as f64 * p) as usize).min(len);
    for m in mutations {
        let len = bytes.len();
        match m {
            Mutation::Flip(p, mask) if len > 0 => {
                let i = index(len - 1, *p);
                bytes[i] ^= mask;
            }
            Mutation::Flip(..) => {}
            Mutation::Insert(p, new) => {
                let i = index(len, *p);
                bytes.splice(i..i, new.iter().copied());
            }
            Mutation::Token(p, t) => {
                let i = index(len, *p);
                bytes.splice(i..i, TOKENS[*t].bytes());
            }
            Mutation::Remove(p, w) => {
                let start = index(len, *p);
                let end = index(len, p + w).max(start);
                bytes.drain(start..end);
            }
            Mutation::Repeat(p, w, n) => {
                let start = index(len, *p);
                let end = index(len, p + w).max(start);
                let piece = bytes[start..end].repeat(*n);
                bytes.splice(end..end, piece);
            }
            Mutation::Truncate(p) => bytes.truncate(index(len, *p)),
            Mutation::Long(p, byte, n) => {
                let i = index(len, *p);
                bytes.splice(i..i, std::iter::repeat_n(*byte, *n));
            }
        }
    }
    bytes
}

/// A seed input mutated by up to 8 edits.
fn mutated(seeds: Vec<Vec<u8>>) -> impl Strategy<Value = Vec<u8>> {
    (0..seeds.len(), prop::collection::vec(mutation(), 0..8))
        .prop_map(move |(seed, mutations)| apply(seeds[seed].clone(), &mutations))
}

/// Random bytes, or random text made of [`TOKENS`] and digits.
fn noise() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        prop::collection::vec(any::<u8>(), 0..512),
        prop::collection::vec(
            prop_oneof![
                (0..TOKENS.len()).prop_map(|t| TOKENS[t].as_bytes().to_vec()),
                (0..10u8).prop_map(|d| vec![b'0' + d]),
            ],
            0..64
        )
        .prop_map(|pieces| pieces.concat()),
    ]
}

/// An error message as the CLI prints it must be one line without raw control characters, its
/// length bounded whatever the input (quoted text is cut: a 4000-character value stays short).
fn check_message(message: &str) -> Result<(), TestCaseError> {
    prop_assert!(
        !message.chars().any(char::is_control),
        "control character in {message:?}"
    );
    prop_assert!(message.chars().count() < 800, "long message {message:?}");
    Ok(())
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn model() -> Pbrdf {
    Pbrdf::new(
        SlopeDistribution::Cauchy { sigma: 0.2, q: 2.0 },
        Shadowing::Smith,
        RefractiveIndex::new(1.5, 0.1),
        0.0,
    )
    .unwrap()
}

fn measurement_seeds() -> Vec<Vec<u8>> {
    [
        "paper_paint",
        "rough_paint",
        "smooth_glass",
        "anodized_panel",
    ]
    .iter()
    .map(|name| shipped(&format!("measurements/{name}.csv")))
    .collect()
}

fn mesh_seeds() -> Vec<Vec<u8>> {
    vec![
        car_excerpt(60, 60),
        car_excerpt(300, 200),
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 -1//1\n".to_vec(),
    ]
}

fn weather_seeds() -> Vec<Vec<u8>> {
    vec![
        b"# Munich\ntime_s,air_temperature_k,wind_speed_m_s,direct_normal_w_m2\n0,283.4,1.5,0\n\
          21600,285,2,640\n\n# noon\n43200,292.1,3,870\n"
            .to_vec(),
        b"\"sun_azimuth_deg\",time_s,air_temperature_k,sun_elevation_deg,longwave_down_w_m2,\
          diffuse_horizontal_w_m2\r\n180,0,290,60,330,100\r\n240,3600,296,40,340,120\r\n"
            .to_vec(),
    ]
}

/// The shipped sample weather cut to its header and a day, EPW and TMY3.
fn station_seeds() -> Vec<(Vec<u8>, StationFormat)> {
    let cut = |path: &str, lines: usize| {
        let text = String::from_utf8(shipped(path)).unwrap();
        text.lines()
            .take(lines)
            .collect::<Vec<_>>()
            .join("\n")
            .into_bytes()
    };
    vec![
        (
            cut("data/weather/munich_3days.epw", 8 + 26),
            StationFormat::Epw,
        ),
        (
            cut("data/weather/munich_3days_tmy3.csv", 2 + 26),
            StationFormat::Tmy3,
        ),
    ]
}

fn atmosphere_seeds() -> Vec<Vec<u8>> {
    vec![
        b"# source: a code\n# geometry: horizontal\nrange_m,transmittance,path_radiance_w_m2_sr\n\
          100,0.97,1.2\n\n1000,0.8,8.4\r\n5000,0,20.7\n"
            .to_vec(),
        b"wavelength_um,range_m,transmittance,path_radiance_w_m2_sr_um\n7.5,0,1,0\n7.5,50,0.9,0.5\n\
          11,0,1,0\n11,50,0.2,6\n14.5,0,1,0\n14.5,50,0.95,0.3\n"
            .to_vec(),
    ]
}

/// Atmosphere rows with subnormal and tiny transmittances beside ordinary ones (the log-linear
/// interpolation once overflowed between 1e-310 and 0.5).
fn tiny_atmosphere_seeds() -> Vec<Vec<u8>> {
    vec![
        b"range_m,transmittance,path_radiance_w_m2_sr\n100,1e-310,1.2\n1000,0.5,8.4\n\
          2000,5e-324,9\n3000,1,0\n"
            .to_vec(),
    ]
}

/// The shipped PTFE layout, and one with the usual conventions.
fn layout_seeds() -> Vec<Vec<u8>> {
    vec![
        shipped("data/ptfe/layout.toml"),
        b"[columns]\ntheta_i_deg = \"ti\"\ntheta_r_deg = \"tr\"\nphi_r_deg = \"pr\"\n\
          m00 = \"M11\"\nelements = { m01 = \"M12\", m10 = \"M21\" }\n[conventions]\n\
          normalized = false\nangle_unit = \"deg\"\n"
            .to_vec(),
    ]
}

/// The head of the shipped PTFE table (both wavelengths), and a small table for the second seed.
fn layout_table_seeds() -> Vec<Vec<u8>> {
    let text = String::from_utf8(shipped("data/ptfe/PTFE_351_1064.csv")).unwrap();
    let mut lines: Vec<&str> = text.lines().take(12).collect();
    lines.extend(text.lines().skip(1830).take(8));
    vec![
        (lines.join("\n") + "\n").into_bytes(),
        b"# wavelength_um: 10\nti,tr,pr,M11,M12,M21\n30,20,180,0.5,0.1,0.2\n-40,35,0,0.3,0,0\n"
            .to_vec(),
    ]
}

/// A refusal names the file at fault and the line, `file:line:`, as the CLI prints it (every
/// refusal of a layout, a table read through one or an EPW/TMY3 file is about a line).
fn check_names_file(message: &str, files: &[&str]) -> Result<(), TestCaseError> {
    check_message(message)?;
    let named = files.iter().any(|file| {
        message
            .strip_prefix(file)
            .and_then(|rest| rest.strip_prefix(':'))
            .is_some_and(|rest| rest.starts_with(|c: char| c.is_ascii_digit()))
    });
    prop_assert!(
        named,
        "{message:?} does not start with file:line of {files:?}"
    );
    Ok(())
}

/// A refusal starts with the file at fault, `file:`, and its line where it is about one
/// (an atmosphere table's refusal of the whole table, e.g. a band it does not cover, has none).
fn check_names_file_maybe_line(message: &str, file: &str) -> Result<(), TestCaseError> {
    check_message(message)?;
    prop_assert!(
        message.starts_with(&format!("{file}:")),
        "{message:?} does not start with {file}"
    );
    Ok(())
}

fn material_seeds() -> Vec<Vec<u8>> {
    ["paper_paint", "anodized_panel", "silicate_glass"]
        .iter()
        .map(|name| shipped(&format!("fits/{name}.toml")))
        .collect()
}

/// A thermal scene with every kind of thermal key: weather, site, steps, layers, stacks, a
/// part's own stack, back conditions, absorptance; and one with a weather file (not there).
fn scene_seeds() -> Vec<Vec<u8>> {
    let scene = "[camera]\nposition = [6.0, -6.0, 3.0]\nlook_at = [0.0, 0.0, 0.5]\nfov_deg = 40.0\n\
        resolution = [64, 48]\n\
        [environment]\nair_temperature_k = 290.0\n\
        sky = { model = \"window\", zenith_emissivity = 0.75 }\n\
        ground = { temperature_k = 290.0, emissivity = 0.95 }\n\
        [render]\nsamples = 2\n\
        [materials.paint]\ndistribution = \"cauchy\"\nsigma = 0.2\nq = 2.0\nn = 1.5\nk = 0.2\n\
        rho_d = 0.02\nshadowing = \"smith\"\n\
        [thermal]\n\
        weather = { clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }\n\
        start_utc = \"2026-06-21T00:00:00Z\"\nlatitude_deg = 48.14\nlongitude_deg = 11.58\n\
        duration_h = 12\noutput_step_s = 3600\ntime_step_s = 600\nshadow_step_s = 1800\n\
        spinup_days = 1\nground_temperature_k = 288.0\n\
        [thermal.layers.paint]\nconductivity_w_mk = 0.2\ndensity_kg_m3 = 1200.0\n\
        heat_capacity_j_kgk = 1500.0\n\
        [thermal.layers.steel]\nconductivity_w_mk = 45.0\ndensity_kg_m3 = 7850.0\n\
        heat_capacity_j_kgk = 470.0\n\
        [[objects]]\nname = \"ball\"\nshape = { kind = \"sphere\", radius = 0.5, subdivisions = 1 }\n\
        translate = [0.0, 0.0, 0.8]\nmaterial = \"paint\"\n\
        [objects.thermal]\nstack = [[\"paint\", 0.0001], [\"steel\", 0.001]]\n\
        back = { convection_w_m2k = 3.0 }\nsolar_absorptance = 0.6\n\
        [[objects]]\nname = \"ground\"\nshape = { kind = \"plane\", size = [8.0, 8.0], divisions = [2, 2] }\n\
        material = \"paint\"\n\
        [objects.thermal]\nstack = [[\"steel\", 0.2]]\nback = { temperature_k = 290.0 }\n\
        solar_absorptance = 0.9\n";
    let with_file = scene.replace(
        "weather = { clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }",
        "weather = \"munich.csv\"",
    );
    vec![scene.as_bytes().to_vec(), with_file.into_bytes()]
}

fn sweep_seeds() -> Vec<Vec<u8>> {
    [
        "0:86400:10800",
        "0:21600:7200",
        "3600",
        "-1e3:1e3:0.5",
        " 0 : 10 : 1 ",
    ]
    .map(|s| s.as_bytes().to_vec())
    .to_vec()
}

fn times_file_seeds() -> Vec<Vec<u8>> {
    vec![
        b"# Munich, 21 June\n2026-06-21T06:00:00Z\n\n2026-06-21T11:00:00.5+02:00\n".to_vec(),
        b"2026-12-21T12:00:00Z\r\n  2027-01-01T00:00:00-05:30  \r\n".to_vec(),
    ]
}

proptest! {
    #![proptest_config(scene_config())]

    #[test]
    fn thermal_scene_loader_never_panics(bytes in prop_oneof![mutated(scene_seeds()), noise()]) {
        if let Err(e) = load_scene_text(Path::new("fuzz/scene.toml"), &text(&bytes)) {
            check_message(&e.to_string())?;
        }
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn times_sweep_never_panics(bytes in prop_oneof![mutated(sweep_seeds()), noise()]) {
        match parse_sweep(&text(&bytes), "times") {
            Ok(times) => {
                prop_assert!(!times.is_empty() && times.len() <= MAX_SWEEP_VALUES);
                prop_assert!(times.iter().all(|t| t.is_finite()));
            }
            Err(e) => check_message(&one_line(&e))?,
        }
    }

    #[test]
    fn times_file_reader_never_panics(bytes in prop_oneof![mutated(times_file_seeds()), noise()]) {
        if let Err(e) = parse_times(Path::new("times.txt"), &text(&bytes)) {
            check_names_file_maybe_line(&one_line(&e), "times.txt")?;
        }
    }


    #[test]
    fn measurement_reader_never_panics(bytes in prop_oneof![mutated(measurement_seeds()), noise()]) {
        if let Err(e) = parse_measurement_csv(Path::new("fuzz.csv"), &bytes) {
            check_names_file_maybe_line(&e.to_string(), "fuzz.csv")?;
        }
    }

    #[test]
    fn obj_reader_never_panics(bytes in prop_oneof![mutated(mesh_seeds()), noise()]) {
        if let Err(error) = parse_obj(&text(&bytes)) {
            check_message(&error.to_string())?;
        }
    }

    #[test]
    fn ply_reader_never_panics(
        bytes in prop_oneof![mutated(vec![ASCII_PLY.as_bytes().to_vec(), binary_ply()]), noise()]
    ) {
        if let Err(error) = parse_ply(&bytes) {
            check_message(&error.to_string())?;
        }
    }

    #[test]
    fn material_loader_never_panics(bytes in prop_oneof![mutated(material_seeds()), noise()]) {
        match Material::from_toml(&text(&bytes), Path::new("fuzz.toml")) {
            Ok(material) => prop_assert!(material.model.validate().is_ok()),
            Err(e) => check_names_file_maybe_line(&e.to_string(), "fuzz.toml")?,
        }
    }

    #[test]
    fn geometry_reader_never_panics(
        bytes in prop_oneof![mutated(vec![GEOMETRY.as_bytes().to_vec()]), noise()]
    ) {
        match parse_geometry_csv(Path::new("fuzz.csv"), bytes) {
            Ok(table) => {
                let mut out = Vec::new();
                write_mueller_csv(&model(), &table, &mut out).unwrap();
                // Whatever was echoed, the output is a rectangular CSV.
                // The model's `#` lines are comments; a data field starting with '#' is quoted.
                let mut reader = csv::ReaderBuilder::new()
                    .has_headers(false)
                    .comment(Some(b'#'))
                    .from_reader(&out[..]);
                let widths: Vec<usize> = reader.records().map(|r| r.unwrap().len()).collect();
                prop_assert!(widths.windows(2).all(|w| w[0] == w[1]), "ragged output");
            }
            Err(e) => check_names_file_maybe_line(&format!("{e:#}"), "fuzz.csv")?,
        }
    }

    #[test]
    fn atmosphere_table_reader_never_panics(
        bytes in prop_oneof![mutated(atmosphere_seeds()), noise()]
    ) {
        let band = irpol::optics::Band::lwir();
        let read = parse_table(Path::new("fuzz.csv"), &bytes)
            .and_then(|table| table.band_rows(&band, 290.0));
        match read {
            Ok(rows) => {
                for r in [0.0, 0.5, 99.0, 1000.0, 3000.0, 1e7] {
                    let (tau, path) = rows.at(r);
                    prop_assert!((0.0..=1.0).contains(&tau), "τ {tau} at {r} m");
                    prop_assert!(path.is_finite() && path >= 0.0, "L {path} at {r} m");
                }
            }
            Err(e) => check_names_file_maybe_line(&e.to_string(), "fuzz.csv")?,
        }
    }

    #[test]
    fn layouts_refuse_naming_their_file_and_keep_values_finite(
        layout in prop_oneof![mutated(layout_seeds()), noise()],
        table in prop_oneof![mutated(layout_table_seeds()), noise()],
    ) {
        use irpol::measure::{parse_with_layout, Layout, MAX_MUELLER_SR};
        let (layout_file, table_file) = ("fuzz/layout.toml", "fuzz/table.csv");
        let layout = match Layout::parse(Path::new(layout_file), &text(&layout)) {
            Ok(layout) => layout,
            Err(e) => return check_names_file(&e.to_string(), &[layout_file]),
        };
        match parse_with_layout(Path::new(table_file), &table, &layout) {
            Ok(sets) => {
                for point in sets.iter().flat_map(|s| &s.points) {
                    prop_assert!(point.values.iter().all(|v| v.abs() <= MAX_MUELLER_SR));
                    prop_assert!((0.0..90.0).contains(&point.theta_i_deg));
                    prop_assert!((0.0..90.0).contains(&point.theta_r_deg));
                }
            }
            Err(e) => check_names_file(&e.to_string(), &[table_file, layout_file])?,
        }
    }

    #[test]
    fn the_shipped_layout_reads_mutated_tables_or_names_the_line(
        table in mutated(layout_table_seeds()),
    ) {
        use irpol::measure::{parse_with_layout, Layout};
        let layout = Layout::parse(Path::new("fuzz/layout.toml"), &text(&layout_seeds()[0])).unwrap();
        if let Err(e) = parse_with_layout(Path::new("fuzz/table.csv"), &table, &layout) {
            check_names_file(&e.to_string(), &["fuzz/table.csv", "fuzz/layout.toml"])?;
        }
    }

    #[test]
    fn tiny_transmittances_interpolate_finitely(
        bytes in mutated(tiny_atmosphere_seeds()),
    ) {
        let band = irpol::optics::Band::lwir();
        let read = parse_table(Path::new("fuzz.csv"), &bytes)
            .and_then(|table| table.band_rows(&band, 290.0));
        match read {
            Ok(rows) => {
                for k in 0..=64 {
                    let r = k as f64 * 60.0;
                    let (tau, path) = rows.at(r);
                    prop_assert!((0.0..=1.0).contains(&tau), "τ {tau} at {r} m");
                    prop_assert!(path.is_finite() && path >= 0.0, "L {path} at {r} m");
                }
            }
            Err(e) => check_names_file_maybe_line(&e.to_string(), "fuzz.csv")?,
        }
    }

    /// EPW header lines after LOCATION dropped, doubled or reordered: every hourly row is still
    /// read (the header is told by content, not counted), and a refusal names file:line.
    #[test]
    fn epw_headers_in_any_shape_keep_every_row(
        keep in proptest::collection::vec(0usize..7, 0..10),
    ) {
        let (seed, _) = station_seeds().swap_remove(0);
        let text = text(&seed);
        let lines: Vec<&str> = text.lines().collect();
        let mut edited = vec![lines[0]];
        edited.extend(keep.iter().map(|&k| lines[1 + k]));
        edited.extend(&lines[8..]);
        let bytes = (edited.join("\n") + "\n").into_bytes();
        match StationWeather::parse(Path::new("fuzz.epw"), &bytes, StationFormat::Epw, None) {
            Ok(file) => prop_assert_eq!(file.records.len(), lines.len() - 8),
            Err(e) => check_names_file(&e.to_string(), &["fuzz.epw"])?,
        }
    }

    #[test]
    fn station_readers_never_panic(
        (seed, format) in prop_oneof![Just(0usize), Just(1usize)]
            .prop_map(|i| station_seeds().swap_remove(i)),
        mutations in proptest::collection::vec(mutation(), 1..6),
        year in proptest::option::of(-5i32..10_005),
    ) {
        let bytes = apply(seed, &mutations);
        match StationWeather::parse(Path::new("fuzz.epw"), &bytes, format, year) {
            Ok(file) => {
                let site = Site {
                    latitude_deg: file.station.latitude_deg,
                    longitude_deg: file.station.longitude_deg,
                    start_utc: file.first_utc(),
                };
                match file.to_weather(&site, None) {
                    Ok(weather) => {
                        let (first, last) = weather.span_s();
                        let middle = weather.at(0.5 * first + 0.5 * last).unwrap();
                        prop_assert!(middle.air_k.is_finite() && middle.longwave_down_w_m2 >= 0.0);
                    }
                    Err(e) => check_message(&e.to_string())?,
                }
            }
            Err(e) => check_names_file(&e.to_string(), &["fuzz.epw"])?,
        }
    }

    #[test]
    fn weather_reader_never_panics(bytes in prop_oneof![mutated(weather_seeds()), noise()]) {
        let site = Site {
            latitude_deg: 48.14,
            longitude_deg: 11.58,
            start_utc: irpol::emitter::parse_time_utc("2026-06-21T00:00:00Z").unwrap(),
        };
        match Weather::parse_csv(Path::new("fuzz.csv"), &bytes, &site) {
            Ok(weather) => {
                let (first, last) = weather.span_s();
                let middle = weather.at(0.5 * first + 0.5 * last).unwrap();
                prop_assert!((middle.sun_direction.norm() - 1.0).abs() < 1e-9);
            }
            Err(e) => check_names_file_maybe_line(&e.to_string(), "fuzz.csv")?,
        }
    }
}

/// Valid values of each `irpol fit` flag that takes text, mutated into the fuzzed ones.
fn fit_flag_seeds() -> Vec<Vec<u8>> {
    [
        "auto",
        "external+subsurface,internal+subsurface",
        "all",
        "sigma,q,n,k,rho",
        "k=0.1,rho=0",
        "d=0.2,n_sub=1.4",
        "ga+nm+lm",
        "huber:2",
        "cauchy",
        "lorentz:2",
        "d,n_sub",
        "gaussian",
        "torrance-sparrow",
    ]
    .iter()
    .map(|s| s.as_bytes().to_vec())
    .collect()
}

proptest! {
    #![proptest_config(config())]

    /// Every text flag of `irpol fit` (and of Python's `fit`) gives options or one clean line,
    /// whatever it holds; options that parse get a finite, positive cost estimate on a shipped
    /// measurement (the estimate every fit is checked against before any work).
    #[test]
    fn fit_flags_give_options_or_one_clean_line(
        flags in prop::collection::vec(prop_oneof![mutated(fit_flag_seeds()), noise()], 10),
        cv in prop::option::of(0..100_000usize),
        max_minutes in prop_oneof![Just(60.0), any::<f64>()],
    ) {
        use irpol::app::fit::FitFlags;
        let given = |i: usize| text(&flags[i]);
        let optional = |i: usize| (flags[i].len() % 3 != 0).then(|| given(i));
        let flags = FitFlags {
            distribution: optional(0),
            shadowing: given(1),
            free: optional(2),
            fix: optional(3),
            optimizer: given(4),
            seed: 0,
            robust: optional(5),
            dispersion: given(6),
            terms: given(7),
            cv,
            per_wavelength: optional(8),
            max_minutes,
        };
        match flags.options() {
            Ok(options) => {
                let sets = irpol::measure::read_measurement_sets(&irpol_path(
                    "measurements/silicate_glass.csv",
                ))
                .unwrap();
                let estimate = irpol::fit::cost::estimate(&sets, &options);
                prop_assert!(estimate.seconds.is_finite() && estimate.seconds > 0.0);
            }
            Err(e) => check_message(&e.to_string())?,
        }
    }
}

proptest! {
    #![proptest_config(scene_config())]

    /// `validate`'s scoring of a shipped material on mutated measurements: a score with finite
    /// figures, or one clean line; never a panic.
    #[test]
    fn validation_scores_any_measurement_or_refuses_cleanly(
        bytes in mutated(measurement_seeds()),
    ) {
        let Ok(set) = parse_measurement_csv(Path::new("fuzz.csv"), &bytes) else {
            return Ok(());
        };
        let material = Material::load(&irpol_path("fits/paper_paint.toml")).unwrap();
        let model = material.grey_model().unwrap().pbrdf().unwrap();
        match irpol::fit::validate_model(&model, &set) {
            Ok(v) => prop_assert!(v.m00_relative_rms().is_finite()),
            Err(e) => check_message(&e.to_string())?,
        }
    }
}

/// A path inside the repository.
fn irpol_path(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The seeds are valid input, so the mutations start from text that reaches every check.
#[test]
fn the_seeds_are_read() {
    for (seed, format) in station_seeds() {
        let file = StationWeather::parse(Path::new("w"), &seed, format, None).unwrap();
        let site = Site {
            latitude_deg: file.station.latitude_deg,
            longitude_deg: file.station.longitude_deg,
            start_utc: file.first_utc(),
        };
        file.to_weather(&site, None).unwrap();
    }
    for seed in atmosphere_seeds() {
        parse_table(Path::new("t.csv"), &seed)
            .unwrap()
            .band_rows(&irpol::optics::Band::lwir(), 290.0)
            .unwrap();
    }
    for seed in tiny_atmosphere_seeds() {
        parse_table(Path::new("t.csv"), &seed)
            .unwrap()
            .band_rows(&irpol::optics::Band::lwir(), 290.0)
            .unwrap();
    }
    for (layout, table) in layout_seeds().iter().zip(layout_table_seeds()) {
        let layout = irpol::measure::Layout::parse(Path::new("l.toml"), &text(layout)).unwrap();
        let sets = irpol::measure::parse_with_layout(Path::new("t.csv"), &table, &layout).unwrap();
        assert!(!sets.is_empty());
    }
    load_scene_text(Path::new("fuzz/scene.toml"), &text(&scene_seeds()[0])).unwrap();
    for seed in sweep_seeds() {
        parse_sweep(&text(&seed), "times").unwrap();
    }
    for seed in times_file_seeds() {
        assert_eq!(
            parse_times(Path::new("t.txt"), &text(&seed)).unwrap().len(),
            2
        );
    }
}

/// The case the fuzzer found: a scene naming a weather file by a path of thousands of characters
/// (or holding a control character) gets a short one-line message; the path is cut in the middle.
#[test]
fn long_file_paths_are_cut_in_messages() {
    let long_name = format!("mun{}\\u001e.csv", "!".repeat(5000)); // TOML escape: a real \x1e
    let scene = String::from_utf8(scene_seeds().remove(1))
        .unwrap()
        .replace("munich.csv", &long_name);
    let message = load_scene_text(Path::new("fuzz/scene.toml"), &scene)
        .unwrap_err()
        .to_string();
    check_message(&message).unwrap();
    assert!(
        message.contains("fuzz/mun!!!") && message.contains("!\\u{1e}.csv"),
        "{message}"
    );
}
