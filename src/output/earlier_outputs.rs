//! Which entries of an output folder an earlier output set wrote, and so which a new set
//! replaces (the folder-replacement policy of docs/design.md §4): a render's own files go, the
//! user's stay.

use std::path::Path;

/// The manifest of a render series (`render --times`): its frames and every entry it wrote.
pub const SERIES_MANIFEST: &str = "series.json";

/// The entries of an output folder that an earlier output set of the same kind wrote: a single
/// render's (listed in its `summary.json`) or a series' (listed in [`SERIES_MANIFEST`], and
/// frame folders `NNN_<t>s/` with a `summary.json`). They are replaced as a set; the other
/// kind's set (a single instant rendered beside a series) and anything else in the folder, the
/// user's, are kept.
pub struct EarlierOutputs {
    dir: std::path::PathBuf,
    listed: Vec<String>,
    frames: bool,
}

impl EarlierOutputs {
    /// What an earlier single render into `out_dir` wrote.
    pub fn single(out_dir: &Path) -> EarlierOutputs {
        EarlierOutputs {
            dir: out_dir.to_owned(),
            listed: listed_files(&out_dir.join("summary.json")),
            frames: false,
        }
    }

    /// What an earlier series into `out_dir` wrote.
    pub fn series(out_dir: &Path) -> EarlierOutputs {
        EarlierOutputs {
            dir: out_dir.to_owned(),
            listed: listed_files(&out_dir.join(SERIES_MANIFEST)),
            frames: true,
        }
    }

    pub fn contains(&self, name: &str) -> bool {
        self.listed.iter().any(|f| f == name)
            || (self.frames
                && is_frame_folder_name(name)
                && self.dir.join(name).join("summary.json").is_file())
    }
}

/// Whether `name` is how a series names a frame's folder, `NNN_<t>s` (a series written before
/// series had a manifest is still recognised).
fn is_frame_folder_name(name: &str) -> bool {
    let Some((index, time)) = name.split_once('_') else {
        return false;
    };
    let digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
    let time = time.strip_suffix('s').unwrap_or("");
    index.len() >= 3 && digits(index) && digits(time.strip_prefix('-').unwrap_or(time))
}

/// The `files` a summary or manifest at `path` lists (none if it is missing or unreadable).
fn listed_files(path: &Path) -> Vec<String> {
    let Ok(text) = std::fs::read(path) else {
        return Vec::new();
    };
    let summary: serde_json::Value = serde_json::from_slice(&text).unwrap_or_default();
    summary["files"]
        .as_array()
        .map(|files| {
            files
                .iter()
                .filter_map(|f| f.as_str().map(str::to_owned))
                .collect()
        })
        .unwrap_or_default()
}
