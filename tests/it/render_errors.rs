//! Bad scenes are refused with one clear message naming the file and the item, and nothing is
//! written (docs/design.md §4: errors are one line, never a panic).

use crate::common;

use common::*;
use irpol::app::render::render_scene;
use irpol::progress::Silent;
use std::path::Path;

const TRIANGLE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 0 1\ng panel\nf 1 2 3\n";

/// A valid scene around one mesh object `mesh` with the given part table, plus `extra` lines.
fn scene_with_mesh(mesh: &str, object_extra: &str) -> String {
    format!(
        "{}{}{}[[objects]]\nname = \"thing\"\nmesh = \"{mesh}\"\nmaterial = \"m\"\ntemperature_k = 300.0\n{object_extra}",
        camera_toml(16),
        AUTUMN_ENVIRONMENT,
        material_toml(0.2, 2.0, 1.5, 0.1, 0.0),
    )
}

/// Renders `scene` (with files `extra_files`) and returns the error text; checks that the output
/// folder was not created.
fn refuse(scene: &str, extra_files: &[(&str, &str)]) -> String {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in extra_files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let path = write_scene(dir.path(), scene);
    let out = dir.path().join("out");
    let err = render_scene(&path, &out, &Silent).expect_err("the scene should be refused");
    assert!(!out.exists(), "something was written for a bad scene");
    let text = err.to_string();
    println!("{text}");
    assert!(!text.contains('\n'), "not one line: {text}");
    text
}

fn expect(text: &str, pieces: &[&str]) {
    for piece in pieces {
        assert!(text.contains(piece), "{text:?} lacks {piece:?}");
    }
}

#[test]
fn a_valid_mesh_scene_renders() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("panel.obj"), TRIANGLE_OBJ).unwrap();
    let path = write_scene(dir.path(), &scene_with_mesh("panel.obj", ""));
    render_scene(&path, &dir.path().join("out"), &Silent).unwrap();
    assert!(dir.path().join("out/summary.json").is_file());
}

#[test]
fn missing_mesh_file() {
    let text = refuse(&scene_with_mesh("nowhere.obj", ""), &[]);
    expect(
        &text,
        &["nowhere.obj", "cannot read the mesh", "objects[0] 'thing'"],
    );
}

#[test]
fn missing_material() {
    let scene = scene_with_mesh("panel.obj", "").replace(
        "material = \"m\"\ntemperature",
        "material = \"unobtainium\"\ntemperature",
    );
    let text = refuse(&scene, &[("panel.obj", TRIANGLE_OBJ)]);
    expect(
        &text,
        &[
            "scene.toml",
            "objects[0] 'thing'",
            "part 'panel'",
            "unobtainium",
            "not in the library",
        ],
    );
}

#[test]
fn unknown_part() {
    let scene = scene_with_mesh("panel.obj", "[objects.parts.hood]\ntemperature_k = 320.0\n");
    let text = refuse(&scene, &[("panel.obj", TRIANGLE_OBJ)]);
    expect(
        &text,
        &[
            "scene.toml",
            "part 'hood' is not in",
            "panel.obj",
            "its parts: panel",
        ],
    );
}

#[test]
fn malformed_toml() {
    let text = refuse("[camera\nposition = [0, 0, 0]\n", &[]);
    expect(&text, &["scene.toml", "not a valid scene", "line 1"]);
    let typo = scene_with_mesh("panel.obj", "").replace("fov_deg", "fov");
    let text = refuse(&typo, &[("panel.obj", TRIANGLE_OBJ)]);
    expect(&text, &["scene.toml", "unknown field `fov`"]);
}

/// A degenerate face is skipped with a warning naming it; a mesh of nothing but
/// degenerate faces is refused.
#[test]
fn degenerate_triangles_are_skipped_unless_nothing_remains() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 0 1\ng panel\nf 1 2 4\nf 1 2 3\n";
    std::fs::write(dir.path().join("flat.obj"), obj).unwrap();
    let path = write_scene(dir.path(), &scene_with_mesh("flat.obj", ""));
    let scene = irpol::scene::load_scene(&path).unwrap();
    assert_eq!(scene.mesh.triangles.len(), 1);
    let warning = scene.warnings.join("\n");
    assert!(
        warning.contains(
            "flat.obj (in objects[0] 'thing'): skipped 1 degenerate (zero-area) \
                          triangle(s): line 7 (part 'panel')"
        ),
        "{warning}"
    );
    let only = "v 0 0 0\nv 1 0 0\nv 2 0 0\ng panel\nf 1 2 3\n";
    let text = refuse(&scene_with_mesh("flat.obj", ""), &[("flat.obj", only)]);
    expect(
        &text,
        &[
            "flat.obj",
            "every triangle is degenerate",
            "line 5",
            "part 'panel'",
            "objects[0] 'thing'",
        ],
    );
}

#[test]
fn nan_in_mesh() {
    let obj = "v 0 0 0\nv 1 nan 0\nv 0 0 1\nf 1 2 3\n";
    let text = refuse(&scene_with_mesh("nan.obj", ""), &[("nan.obj", obj)]);
    expect(
        &text,
        &["nan.obj", "line 2", "vertex 2 has a non-finite coordinate"],
    );
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
               property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
               0 0 0\n1 0 inf\n0 0 1\n3 0 1 2\n";
    let text = refuse(&scene_with_mesh("bad.ply", ""), &[("bad.ply", ply)]);
    expect(&text, &["bad.ply"]);
}

/// A binary PLY must hold exactly what its header declares: trailing bytes and a payload that
/// ends inside a face are refused, naming the file and the face. (uchar values keep the bytes
/// ASCII, so the file can be written as text.)
#[test]
fn binary_ply_payloads_must_match_their_header() {
    let header = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty uchar x\n\
                  property uchar y\nproperty uchar z\nelement face 2\n\
                  property list uchar uchar vertex_indices\nend_header\n";
    let payload = "\0\0\0\x01\0\0\0\0\x01\x03\0\x01\x02\x03\0\x02\x01";
    let good = format!("{header}{payload}");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tri.ply"), &good).unwrap();
    let path = write_scene(dir.path(), &scene_with_mesh("tri.ply", ""));
    render_scene(&path, &dir.path().join("out"), &Silent).unwrap();
    let trailing = format!("{good}junk");
    let text = refuse(&scene_with_mesh("tri.ply", ""), &[("tri.ply", &trailing)]);
    expect(
        &text,
        &["tri.ply", "4 bytes follow the items the header declares"],
    );
    let cut = &good[..good.len() - 1];
    let text = refuse(&scene_with_mesh("tri.ply", ""), &[("tri.ply", cut)]);
    expect(
        &text,
        &[
            "tri.ply",
            "face 2: the file ends inside property 'vertex_indices' (payload byte 13)",
        ],
    );
}

/// A PLY header that declares an element or a property twice is refused by line: the reader
/// keys them by name, so the second would silently replace the first.
#[test]
fn duplicate_ply_declarations_are_refused() {
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
               property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
               property list uchar int vertex_indices\nend_header\n\
               0 0 0\n1 0 0\n0 0 1\n3 0 1 2 3 0 1 2\n";
    let text = refuse(&scene_with_mesh("twice.ply", ""), &[("twice.ply", ply)]);
    expect(
        &text,
        &[
            "twice.ply",
            "header line 9: element 'face': property 'vertex_indices' is declared twice \
             (first on line 8)",
        ],
    );
    let ply = ply.replace(
        "element face 1\n",
        "element face 1\nproperty uchar flag\nelement face 1\n",
    );
    let text = refuse(&scene_with_mesh("twice.ply", ""), &[("twice.ply", &ply)]);
    expect(
        &text,
        &["header line 9: element 'face' is declared twice (first on line 7)"],
    );
}

#[test]
fn bad_values_name_their_key() {
    let scene = scene_with_mesh("panel.obj", "")
        .replace("zenith_emissivity = 0.75", "zenith_emissivity = 1.75");
    let text = refuse(&scene, &[("panel.obj", TRIANGLE_OBJ)]);
    expect(
        &text,
        &["scene.toml", "environment.sky.zenith_emissivity = 1.75"],
    );
    let scene = scene_with_mesh("panel.obj", "").replace("sigma = 0.2", "sigma = -0.2");
    let text = refuse(&scene, &[("panel.obj", TRIANGLE_OBJ)]);
    expect(
        &text,
        &["scene.toml", "inline material [materials.m]", "σ = -0.2"],
    );
    let scene =
        scene_with_mesh("panel.obj", "").replace("temperature_k = 300.0", "temperature_k = -4.0");
    let text = refuse(&scene, &[("panel.obj", TRIANGLE_OBJ)]);
    expect(
        &text,
        &["scene.toml", "objects[0] 'thing'", "temperature_k = -4"],
    );
    let text = refuse(
        &scene_with_mesh("panel.stl", ""),
        &[("panel.stl", TRIANGLE_OBJ)],
    );
    expect(&text, &["panel.stl", "must end in .obj or .ply"]);
}

#[test]
fn energy_non_conserving_material_is_named() {
    // No shadowing with a wide Cauchy lobe reflects more than it receives at grazing angles.
    let scene = scene_with_mesh("panel.obj", "")
        .replace("shadowing = \"smith\"", "shadowing = \"none\"")
        .replace("sigma = 0.2\nq = 2.0", "sigma = 0.8\nq = 1.6");
    let text = refuse(&scene, &[("panel.obj", TRIANGLE_OBJ)]);
    expect(
        &text,
        &["scene.toml", "material 'm' (inline)", "reflectance"],
    );
}

#[test]
fn output_folder_is_untouched_on_failure() {
    // An existing output folder keeps its files when a later render fails.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("S0.tif"), b"old").unwrap();
    let path = write_scene(dir.path(), &scene_with_mesh("missing.obj", ""));
    assert!(render_scene(&path, &out, &Silent).is_err());
    assert_eq!(std::fs::read(out.join("S0.tif")).unwrap(), b"old");
    assert!(Path::new(&out).read_dir().unwrap().count() == 1);
}

/// `[render]` transport keys and `[sun]` are checked with messages naming the key.
#[test]
fn bad_transport_and_sun_settings() {
    let base = scene_with_mesh("panel.obj", "");
    let files = [("panel.obj", TRIANGLE_OBJ)];
    for (extra, pieces) in [
        ("[render]\nsamples = 0\n", &["render.samples = 0"][..]),
        ("[render]\nbounces = 1000\n", &["render.bounces = 1000"][..]),
        (
            "[render]\nfirst_bounce_samples = 0\n",
            &["render.first_bounce_samples = 0", "1..=64"][..],
        ),
        ("[render]\nbounce = 2\n", &["unknown field `bounce`"][..]),
        (
            "[sun]\nelevation_deg = 30.0\nazimuth_deg = 10.0\nirradiance_w_m2 = -1.0\n",
            &["sun.irradiance_w_m2"][..],
        ),
        (
            "[sun]\nelevation_deg = nan\nazimuth_deg = 10.0\n",
            &["sun.elevation_deg"][..],
        ),
        (
            "[sun]\nelevation_deg = 30.0\nazimuth_deg = inf\n",
            &["sun.elevation_deg/azimuth_deg"][..],
        ),
        (
            "[sun]\nelevation_deg = 30.0\n",
            &["[sun] needs elevation_deg and azimuth_deg"][..],
        ),
        (
            "[sun]\nelevation_deg = 30.0\nazimuth_deg = 10.0\ntransmittance = 1.5\n",
            &["sun.transmittance"][..],
        ),
        (
            "[sun]\nlatitude_deg = 48.1\nlongitude_deg = 11.6\ntime_utc = \"noon\"\n",
            &["sun.time_utc", "noon"][..],
        ),
        (
            "[sun]\nelevation = 30.0\n",
            &["unknown field `elevation`"][..],
        ),
    ] {
        let text = refuse(&format!("{extra}{base}"), &files);
        expect(&text, &["scene.toml"]);
        expect(&text, pieces);
    }
}

/// A sun below the horizon is allowed: it simply adds nothing.
#[test]
fn a_sun_below_the_horizon_renders_without_a_sun_term() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("panel.obj"), TRIANGLE_OBJ).unwrap();
    let scene = format!(
        "[sun]\nelevation_deg = -5.0\nazimuth_deg = 10.0\n{}",
        scene_with_mesh("panel.obj", "")
    );
    let path = write_scene(dir.path(), &scene);
    let summary = render_scene(&path, &dir.path().join("out"), &Silent).unwrap();
    assert!(summary.transport.sun.is_none());
}

/// Arrays of the wrong length and temperatures beyond finite radiance are refused, not cut or
/// turned into NaN statistics.
#[test]
fn wrong_lengths_and_absurd_temperatures() {
    let files = [("panel.obj", TRIANGLE_OBJ)];
    let base = scene_with_mesh("panel.obj", "");
    let cases: [(String, &[&str]); 6] = [
        (
            base.replace(
                "look_at = [0.0, 0.0, 0.0]",
                "look_at = [0.0, 0.0, 0.0, 9.0]",
            ),
            &["invalid length 4, expected 3 numbers"],
        ),
        (
            base.replace("resolution = [16, 16]", "resolution = [16, 16, 3]"),
            &["invalid length 3, expected 2 numbers"],
        ),
        (
            base.replace("temperature_k = 300.0", "temperature_k = 1e308"),
            &["temperature_k = 1e308 must be within [0, 10000] K"],
        ),
        (
            format!("[sensor]\nnetd_reference_k = inf\n{base}"),
            &["sensor.netd_reference_k = inf"],
        ),
        (
            format!("[sensor]\nresponse = [[8.0, 1.0, 3.0], [14.0, 1.0]]\n{base}"),
            &["a pair [wavelength_um, response]"],
        ),
        (
            base.replace("air_temperature_k = 283.15", "air_temperature_k = 1e300"),
            &["environment.air_temperature_k = 1e300"],
        ),
    ];
    for (scene, pieces) in cases {
        assert_ne!(scene, base, "the case did not change the scene");
        let text = refuse(&scene, &files);
        expect(&text, pieces);
    }
}

/// `[render.preview]` ranges are checked when the scene loads.
#[test]
fn preview_ranges_are_checked_by_key() {
    for (table, expected) in [
        (
            "percentiles = [50.0, 10.0]",
            "render.preview.percentiles = [50, 10] must be two finite numbers, low < high",
        ),
        (
            "percentiles = [-1.0, 99.0]",
            "render.preview.percentiles = [-1, 99] must lie within [0, 100]",
        ),
        ("dolp_percent = [5.0, 5.0]", "render.preview.dolp_percent"),
        ("s0_colormap = \"rainbow\"", "unknown variant `rainbow`"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let text = format!(
            "{}{}{}{}[render.preview]\n{table}\n",
            common::camera_toml(8),
            common::AUTUMN_ENVIRONMENT,
            common::material_toml(0.1, 1.8, 1.2, 0.2, 0.0),
            common::sphere_toml(1, 300.0),
        );
        let path = common::write_scene(dir.path(), &text);
        let err = irpol::scene::load_scene(&path).unwrap_err().to_string();
        assert!(err.contains(expected), "{expected}: {err}");
    }
}

/// Probable mistakes are warned about on stderr, once each, and listed in
/// summary.json — a temperature that looks like °C, an inline material nothing uses, an object the
/// camera cannot see, a PLY property that looks like a temperature but is ignored, a library
/// material measured outside the sensor band — and the render still succeeds.
#[test]
fn likely_mistakes_are_warned_once_and_listed() {
    let dir = tempfile::tempdir().unwrap();
    write_truth_library(&dir.path().join("fits"));
    std::fs::write(
        dir.path().join("tri.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nproperty float temp\nelement face 1\nproperty list uchar int \
         vertex_indices\nend_header\n0 0 0 300\n1 0 0 300\n0 0 1 300\n3 0 1 2\n",
    )
    .unwrap();
    let text = format!(
        "{}[sensor]\nband_um = [3.0, 5.0]\n\n{}{}{}\
         [materials.spare]\ndistribution = \"cauchy\"\nsigma = 0.2\nq = 2.0\nn = 1.5\nk = 0.1\n\n\
         [[objects]]\nname = \"behind\"\nmesh = \"tri.ply\"\nmaterial = \"paper_paint\"\n\
         temperature_k = 300.0\ntranslate = [0.0, -20.0, 0.0]\n",
        camera_toml(16),
        AUTUMN_ENVIRONMENT,
        material_toml(0.1, 1.8, 1.2, 0.2, 0.0),
        sphere_toml(1, 45.0),
    );
    let path = write_scene(dir.path(), &text);
    let out = dir.path().join("out");
    let (ok, _, stderr) = irpol(&[
        "render",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let expected = [
        "objects[0] 'ball': temperature_k = 45 K looks like °C",
        "[materials.spare] is never used by any object",
        "material 'paper_paint'",
        "outside the sensor band 3–5 µm",
        "vertex property 'temp' looks like a temperature but is ignored",
        "object 'behind' covers no pixel",
    ];
    for e in expected {
        assert_eq!(stderr.matches(e).count(), 1, "{e}: {stderr}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["warnings"].as_array().unwrap().len(), 5);
}

/// The camera's sub-tables (`[sensor.optics]`, `[sensor.detector]`, `[sensor.dofp]`) refuse
/// settings that mean nothing, naming the key and what to write instead.
#[test]
fn camera_settings_are_checked_by_key() {
    let files = [("panel.obj", TRIANGLE_OBJ)];
    let base = scene_with_mesh("panel.obj", "");
    let cases: [(&str, &[&str]); 10] = [
        (
            "[sensor.optics]\nf_number = 1.0\n",
            &["sensor.optics.f_number needs pixel_pitch_um"],
        ),
        (
            "[sensor.optics]\npixel_pitch_um = 17.0\n",
            &["pixel_pitch_um is only used with f_number"],
        ),
        (
            "[sensor.optics]\nfill_factor = 1.5\n",
            &["sensor.optics.fill_factor = 1.5 must be within [0, 1]"],
        ),
        (
            "[sensor.optics]\nblur_sigma_px = nan\n",
            &["sensor.optics.blur_sigma_px = NaN"],
        ),
        (
            "[sensor.optics]\nfocal_mm = 25.0\n",
            &["unknown field `focal_mm`"],
        ),
        (
            "[sensor.detector]\nbits = 40\n",
            &["sensor.detector.bits = 40 must be within [0, 32]"],
        ),
        (
            "[sensor.detector]\nrange_k = [350.0, 250.0]\n",
            &[
                "sensor.detector.range_k = [350, 250]",
                "the first below the second",
            ],
        ),
        (
            "[sensor.dofp]\nextinction_ratio = 0.5\n",
            &["sensor.dofp.extinction_ratio = 0.5 must be ≥ 1"],
        ),
        (
            "[sensor.dofp]\ndemosaic = \"cubic\"\n",
            &[
                "sensor.dofp.demosaic = \"cubic\"",
                "\"bilinear\", \"newton\" or \"residual\"",
            ],
        ),
        (
            "[sensor]\ndofp = \"yes\"\n",
            &["expected true, false or a table"],
        ),
    ];
    for (table, pieces) in cases {
        let text = refuse(&format!("{table}{base}"), &files);
        expect(&text, pieces);
    }
}

#[test]
fn terrain_keys_are_checked_by_name() {
    let terrain = |keys: &str| {
        scene_with_mesh("unused.obj", "").replace(
            "mesh = \"unused.obj\"",
            &format!("shape = {{ kind = \"terrain\", size = [10.0, 10.0], divisions = [20, 20], {keys} }}"),
        )
    };
    let cases = [
        (
            "rms_height_m = 0.1, correlation_length_m = 0.5",
            "shape.correlation_length_m = 0.5 must be at least two cells (1 m)",
        ),
        (
            "rms_height_m = -0.1, correlation_length_m = 2.0",
            "shape.rms_height_m = -0.1 must be finite and ≥ 0",
        ),
        (
            "rms_height_m = 0.1, correlation_length_m = 2.0, hurst = 1.5",
            "shape.hurst = 1.5 must be within (0, 1]",
        ),
        (
            "rms_height_m = 0.1, correlation_length_m = 2.0, roughness = 3",
            "unknown field `roughness`",
        ),
        ("rms_height_m = 0.1", "missing field `correlation_length_m`"),
    ];
    for (keys, message) in cases {
        let text = refuse(&terrain(keys), &[]);
        expect(&text, &["scene.toml", message]);
    }
}
