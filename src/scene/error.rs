//! What can be wrong with a scene (docs/design.md §2.3). Every message is one line that starts with
//! the file at fault: "scenes/car.toml: objects\[0\] 'car', part 'hood': …", "scenes/car.obj:
//! line 12: … (in objects\[0\] 'car')". An unreadable file keeps its `std::io::Error` as the
//! `source` (its text follows in the `{:#}` chain), so callers can tell a missing file from bad
//! content; other inner errors are part of the message.

use super::mesh::MeshError;
use crate::emitter::SunConfigError;
use crate::material::SceneMaterialError;
use crate::thermal::setup::ThermalSetupError;
use std::path::{Path, PathBuf};

/// A setting of the scene (the camera, the environment) that cannot be used: the key at fault and
/// why, as one message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct InvalidSetting(pub String);

impl From<String> for InvalidSetting {
    fn from(message: String) -> Self {
        InvalidSetting(message)
    }
}

impl From<&str> for InvalidSetting {
    fn from(message: &str) -> Self {
        InvalidSetting(message.to_owned())
    }
}

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file cannot be read.
    #[error("{}: cannot read the scene", crate::text::path(file))]
    Read {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The scene file is not valid TOML or has wrong keys; `line` and `column` (from 1) point at
    /// the fault when the TOML reader knows it.
    #[error("{}: not a valid scene: {}{}", crate::text::path(file), at(*line, *column), one_line(message))]
    Parse {
        file: PathBuf,
        line: Option<usize>,
        column: Option<usize>,
        message: String,
    },
    /// A material cannot be resolved; `item` is the object part (or thermal part) that uses it.
    #[error("{}: {}", crate::text::path(file), one_line(&labelled(item, error)))]
    Material {
        file: PathBuf,
        item: Option<String>,
        /// Boxed: material errors are large and scene errors travel through every render call.
        error: Box<SceneMaterialError>,
    },
    /// The `[sun]` table.
    #[error("{}: {}", crate::text::path(file), one_line(&error.to_string()))]
    Sun {
        file: PathBuf,
        error: SunConfigError,
    },
    /// A mesh file (`file`) of object `item` cannot be read.
    #[error("{}: cannot read the mesh (in {item})", crate::text::path(file))]
    MeshRead {
        file: PathBuf,
        item: String,
        #[source]
        source: std::io::Error,
    },
    /// A mesh file's content (OBJ, PLY) or the shaded mesh is unusable.
    #[error("{}: {} (in {item})", crate::text::path(file), one_line(&error.to_string()))]
    Mesh {
        file: PathBuf,
        item: String,
        error: MeshError,
    },
    /// The `[thermal]` section or a part's thermal keys.
    #[error("{}: {}", crate::text::path(file), one_line(&error.to_string()))]
    Thermal {
        file: PathBuf,
        error: ThermalSetupError,
    },
    /// The `[atmosphere]` table.
    #[error("{}: atmosphere.table: {}", crate::text::path(file), one_line(&error.to_string()))]
    Atmosphere {
        file: PathBuf,
        error: crate::atmosphere::AtmosphereTableError,
    },
    /// Any other value out of its range or keys that do not fit together.
    #[error("{}: {}", crate::text::path(file), one_line(message))]
    Invalid { file: PathBuf, message: String },
}

impl SceneError {
    /// An invalid value of `file`, described by `message`.
    pub fn new(file: &Path, message: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            file: file.to_owned(),
            message: message.into(),
        }
    }

    /// Material `error` of `file`, used by `item` (an object part) if given.
    pub fn material(file: &Path, item: Option<String>, error: SceneMaterialError) -> SceneError {
        SceneError::Material {
            file: file.to_owned(),
            item,
            error: Box::new(error),
        }
    }

    /// The file at fault.
    pub fn file(&self) -> &Path {
        match self {
            SceneError::Read { file, .. }
            | SceneError::Parse { file, .. }
            | SceneError::Material { file, .. }
            | SceneError::Sun { file, .. }
            | SceneError::MeshRead { file, .. }
            | SceneError::Mesh { file, .. }
            | SceneError::Thermal { file, .. }
            | SceneError::Atmosphere { file, .. }
            | SceneError::Invalid { file, .. } => file,
        }
    }

    /// A TOML reader's error of the scene text `text`, with its line and column.
    pub(super) fn parse(file: &Path, text: &str, error: &toml::de::Error) -> SceneError {
        let (line, column) = error.span().map_or((None, None), |span| {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            (Some(line), Some(column))
        });
        SceneError::Parse {
            file: file.to_owned(),
            line,
            column,
            message: crate::text::parser_message(error.message(), PARSER_MESSAGE_CHARS),
        }
    }
}

/// "line L, column C: " where known.
fn at(line: Option<usize>, column: Option<usize>) -> String {
    match (line, column) {
        (Some(line), Some(column)) => format!("line {line}, column {column}: "),
        _ => String::new(),
    }
}

fn labelled(item: &Option<String>, error: &SceneMaterialError) -> String {
    match item {
        Some(item) => format!("{item}: {error}"),
        None => error.to_string(),
    }
}

/// Characters of the TOML reader's own message kept in ours (it may quote a whole value).
const PARSER_MESSAGE_CHARS: usize = 200;

/// Characters of a message kept at most: a safety net over the quoting of each value.
const MESSAGE_CHARS: usize = 800;

/// Messages are kept to one short line of printable characters (some parsers format theirs over
/// several, and a message may carry text of the scene's files).
fn one_line(message: &str) -> String {
    crate::text::parser_message(message, MESSAGE_CHARS)
}
