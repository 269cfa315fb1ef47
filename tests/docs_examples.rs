//! The scene documentation works as written (issue 16): every shipped example in docs/examples/
//! renders, every block of docs/scenes.md marked as a complete scene loads, and the shipped
//! example files are exactly the ones the page shows, so the page and the files cannot drift.
//!
//! Markers in docs/scenes.md, each on the line just before a fenced block:
//! `<!-- check: scene -->` (a complete scene) and `<!-- check: file NAME -->` (a file the scenes
//! on the page may use, written next to them as NAME).

use irpol::commands::render::render_scene;
use irpol::progress::Silent;
use irpol::scene::load_scene;
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fenced block of the page that carries a marker.
struct Block {
    /// `None` for a scene, the file name for a file block.
    file: Option<String>,
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
        let file = match marker.trim() {
            "scene" => None,
            other => Some(
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
            file,
            line: i + 1,
            text: body.join("\n") + "\n",
        });
    }
    blocks
}

fn scenes_page() -> String {
    std::fs::read_to_string(root().join("docs/scenes.md")).expect("read docs/scenes.md")
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
    let blocks = marked_blocks(&scenes_page());
    let scenes: Vec<&Block> = blocks.iter().filter(|b| b.file.is_none()).collect();
    // The minimal, the worked and the full example at least: fewer means lost markers.
    assert!(scenes.len() >= 3, "only {} marked scenes", scenes.len());
    for scene in scenes {
        let dir = tempfile::tempdir().unwrap();
        for block in &blocks {
            if let Some(name) = &block.file {
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
    let blocks = marked_blocks(&scenes_page());
    for file in example_files() {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(&file).unwrap();
        let shown = blocks.iter().any(|b| {
            let same_kind = match &b.file {
                Some(block_name) => *block_name == name,
                None => name.ends_with(".toml"),
            };
            same_kind && b.text == text
        });
        assert!(
            shown,
            "docs/examples/{name} differs from every marked block of docs/scenes.md"
        );
    }
}
