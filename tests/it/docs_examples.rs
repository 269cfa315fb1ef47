//! The documentation works as written: every shipped example in docs/examples/
//! renders, every block of docs/scenes.md marked as a complete scene loads, the shipped example
//! files are exactly the ones the page shows (so the page and the files cannot drift), and the
//! hand-written material of docs/materials.md is a valid library entry.
//!
//! Markers, each on the line just before a fenced block: `<!-- check: scene -->` (a complete
//! scene), `<!-- check: file NAME -->` (a file the scenes on the page may use, written next to
//! them as NAME) and `<!-- check: material -->` (a material TOML).

use irpol::app::render::render_scene;
use irpol::material::Material;
use irpol::progress::Silent;
use irpol::scene::load_scene;
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// What a marked block is.
#[derive(PartialEq)]
enum Kind {
    Scene,
    File(String),
    Material,
}

/// A fenced block of the page that carries a marker.
struct Block {
    kind: Kind,
    /// Line of the marker, for messages.
    line: usize,
    text: String,
}

/// The marked blocks of a Markdown page. A marker not followed by a fenced block is an error,
/// so a broken marker fails the test instead of silently checking less.
fn marked_blocks(page: &str) -> Vec<Block> {
    let lines: Vec<&str> = page.lines().collect();
    let mut blocks = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let Some(marker) = line
            .trim()
            .strip_prefix("<!-- check:")
            .and_then(|m| m.strip_suffix("-->"))
        else {
            continue;
        };
        let kind = match marker.trim() {
            "scene" => Kind::Scene,
            "material" => Kind::Material,
            other => Kind::File(
                other
                    .strip_prefix("file ")
                    .unwrap_or_else(|| panic!("line {}: unknown marker '{other}'", i + 1))
                    .trim()
                    .to_owned(),
            ),
        };
        assert!(
            lines.get(i + 1).is_some_and(|l| l.starts_with("```")),
            "line {}: the marker is not followed by a fenced block",
            i + 1
        );
        let body: Vec<&str> = lines[i + 2..]
            .iter()
            .take_while(|l| !l.starts_with("```"))
            .copied()
            .collect();
        assert!(
            i + 2 + body.len() < lines.len(),
            "line {}: the block is not closed",
            i + 1
        );
        blocks.push(Block {
            kind,
            line: i + 1,
            text: body.join("\n") + "\n",
        });
    }
    blocks
}

fn page(name: &str) -> String {
    std::fs::read_to_string(root().join("docs").join(name)).expect("read the page")
}

/// The shipped example files, sorted.
fn example_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("docs/examples"))
        .expect("docs/examples")
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

#[test]
fn every_shipped_example_renders() {
    let scenes: Vec<PathBuf> = example_files()
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    assert!(!scenes.is_empty(), "no docs/examples/*.toml");
    let dir = tempfile::tempdir().unwrap();
    for scene in scenes {
        let out = dir.path().join(scene.file_stem().unwrap());
        let summary = render_scene(&scene, &out, &Silent)
            .unwrap_or_else(|e| panic!("{} does not render: {e}", scene.display()));
        assert!(
            out.join("S0.tif").is_file(),
            "{}: no S0.tif",
            scene.display()
        );
        let written: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
        assert!(
            written["pixels"]["object"].as_u64().unwrap_or(0) > 0 && summary.pixels.object > 0,
            "{}: the camera sees no object",
            scene.display()
        );
        for (object, pixels) in &summary.pixels.per_object {
            assert!(
                *pixels > 0,
                "{}: '{object}' is not in view",
                scene.display()
            );
        }
    }
}

#[test]
fn complete_scenes_on_the_page_load() {
    let blocks = marked_blocks(&page("scenes.md"));
    let scenes: Vec<&Block> = blocks.iter().filter(|b| b.kind == Kind::Scene).collect();
    // The minimal, the worked and the full example at least: fewer means lost markers.
    assert!(scenes.len() >= 3, "only {} marked scenes", scenes.len());
    for scene in scenes {
        let dir = tempfile::tempdir().unwrap();
        for block in &blocks {
            if let Kind::File(name) = &block.kind {
                std::fs::write(dir.path().join(name), &block.text).unwrap();
            }
        }
        // The library the full example refers to: the repository's fits/ beside the scene.
        let fits = dir.path().join("fits");
        std::fs::create_dir(&fits).unwrap();
        for entry in std::fs::read_dir(root().join("fits")).unwrap() {
            let path = entry.unwrap().path();
            std::fs::copy(&path, fits.join(path.file_name().unwrap())).unwrap();
        }
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, &scene.text).unwrap();
        if let Err(e) = load_scene(&path) {
            panic!(
                "the scene at docs/scenes.md line {} does not load: {e}",
                scene.line
            );
        }
    }
}

#[test]
fn shipped_examples_are_the_files_the_page_shows() {
    let blocks = marked_blocks(&page("scenes.md"));
    for file in example_files() {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(&file).unwrap();
        let shown = blocks.iter().any(|b| {
            let same_kind = match &b.kind {
                Kind::File(block_name) => *block_name == name,
                Kind::Scene => name.ends_with(".toml"),
                Kind::Material => false,
            };
            same_kind && b.text == text
        });
        assert!(
            shown,
            "docs/examples/{name} differs from every marked block of docs/scenes.md"
        );
    }
}

/// docs/camera.md's copy-paste block: the shipped snippet is the tables the page shows, and
/// appended to the car scene it turns the camera on (optics, detector, DoFP array).
#[test]
fn the_camera_snippet_turns_the_camera_on() {
    let snippet =
        std::fs::read_to_string(root().join("docs/examples/snippets/camera.toml")).unwrap();
    let tables = &snippet[snippet.find("[sensor.optics]").expect("the optics table")..];
    assert!(
        page("camera.md").contains(tables),
        "docs/camera.md does not show docs/examples/snippets/camera.toml's tables"
    );
    let car = std::fs::read_to_string(root().join("scenes/car.toml")).unwrap();
    // Beside scenes/car.toml, as the page's copy beside car.obj: the same relative paths.
    let path = root().join("scenes/car_camera.toml");
    let scene = irpol::scene::load_scene_text(&path, &format!("{car}{snippet}")).unwrap();
    let dofp = scene.sensor.dofp.expect("a DoFP array");
    assert_eq!(dofp.demosaic.name(), "newton");
}

#[test]
fn the_hand_written_material_is_a_library_entry() {
    let blocks = marked_blocks(&page("materials.md"));
    let materials: Vec<&Block> = blocks.iter().filter(|b| b.kind == Kind::Material).collect();
    assert!(
        !materials.is_empty(),
        "no marked material in docs/materials.md"
    );
    for block in materials {
        let path = Path::new("docs/materials.md");
        if let Err(e) = Material::from_toml(&block.text, path) {
            panic!(
                "the material at docs/materials.md line {} is invalid: {e}",
                block.line
            );
        }
    }
}

/// The part list of the shipped car in docs/scenes.md names every group of scenes/car.obj.
#[test]
fn the_cars_part_list_names_every_part_of_its_mesh() {
    let obj = std::fs::read_to_string(root().join("scenes/car.obj")).unwrap();
    let groups: Vec<&str> = obj
        .lines()
        .filter_map(|line| line.strip_prefix("g "))
        .map(str::trim)
        .collect();
    assert!(groups.len() > 10, "{groups:?}");
    let page = page("scenes.md");
    let start = page
        .find("The shipped `scenes/car.obj` has the parts")
        .expect("the car's part list");
    let list = &page[start..start + page[start..].find(".\n").unwrap()];
    for group in groups {
        assert!(
            list.contains(&format!("`{group}`")),
            "{group} missing: {list}"
        );
    }
}

/// The pages give the default shadowing of an inline scene material as the loader has it.
#[test]
fn the_pages_state_the_inline_shadowing_default_the_loader_uses() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    // The starter scene with the shadowing lines of its inline materials left out.
    let text: String = include_str!("../../src/app/starter_scene.toml")
        .lines()
        .filter(|line| !line.starts_with("shadowing"))
        .map(|line| format!("{line}\n"))
        .collect();
    assert!(text.contains("[materials.paint]") && !text.contains("\nshadowing"));
    std::fs::write(&scene, text).unwrap();
    let loaded = load_scene(&scene).unwrap_or_else(|e| panic!("{e}"));
    let paint = &loaded.materials[loaded.surfaces[0].material];
    assert_eq!(paint.name, "paint");
    assert_eq!(paint.optics.sampling_pbrdf().shadowing().name(), "smith");
    for name in ["scenes.md", "materials.md"] {
        let page = page(name);
        for claim in ["(the inline default)", "`shadowing` to `\"none\"`"] {
            assert!(!page.contains(claim), "{name} says {claim}");
        }
    }
    assert!(page("materials.md").contains("`shadowing` to `\"smith\"`"));
}
