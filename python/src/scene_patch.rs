//! A scene TOML with some values replaced: each key a dotted path into the file (array indices
//! as numbers, `objects.0.parts.hood.temperature_k`), as the sweep spec's grid keys are
//! (docs/design.md §2.7). Every part of the path must already exist in the scene: a misspelt key is an
//! error, never a new, silently ignored entry. The edit keeps the rest of the text as it was.

use crate::errors::{bad_argument, raised};
use irpol::text::{parser_message, shown};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyString};
use std::path::{Path, PathBuf};
use toml_edit::{DocumentMut, Item, TableLike, Value};

/// A Python value as a TOML value: bool, int, float, str, and lists and dicts of them.
pub fn toml_value(object: &Bound<'_, PyAny>) -> PyResult<Value> {
    if let Ok(b) = object.cast::<PyBool>() {
        return Ok(Value::from(b.is_true()));
    }
    if object.is_instance_of::<PyFloat>() {
        return Ok(Value::from(object.extract::<f64>()?));
    }
    if let Ok(i) = object.extract::<i64>() {
        return Ok(Value::from(i));
    }
    if let Ok(x) = object.extract::<f64>() {
        return Ok(Value::from(x));
    }
    if let Ok(s) = object.cast::<PyString>() {
        return Ok(Value::from(s.to_str()?));
    }
    if let Ok(d) = object.cast::<PyDict>() {
        let mut table = toml_edit::InlineTable::new();
        for (k, v) in d.iter() {
            table.insert(&k.extract::<String>()?, toml_value(&v)?);
        }
        return Ok(Value::InlineTable(table));
    }
    if let Ok(items) = object.extract::<Vec<Bound<'_, PyAny>>>() {
        let values: PyResult<Vec<Value>> = items.iter().map(toml_value).collect();
        return Ok(Value::Array(values?.into_iter().collect()));
    }
    Err(bad_argument(format!(
        "cannot write {} into a scene TOML: use numbers, strings, booleans, lists or dicts",
        object.repr()?
    )))
}

/// Where a walk down a key is, for messages: `'sun'`, `'objects.0'`, or the file's top level.
fn place(parts: &[&str], depth: usize) -> String {
    if depth == 0 {
        "the top level".into()
    } else {
        format!("'{}'", shown(&parts[..depth].join(".")))
    }
}

/// Why a dotted key does not name an entry of the scene; `place` is where the walk stopped
/// ([`place`]).
#[derive(Debug, thiserror::Error)]
pub enum KeyError {
    #[error(
        "'{}' is not an index of the array {place} ({len} entries)",
        shown(index)
    )]
    NotAnIndex {
        index: String,
        place: String,
        len: usize,
    },
    #[error("no '{}' in {place}", shown(key))]
    NoKey { key: String, place: String },
    #[error("no {0}")]
    NoEntry(String),
    #[error("{0} is a table: set its keys one by one")]
    Table(String),
    #[error("{0} is a single value, not a table or an array")]
    SingleValue(String),
}

/// Why a scene text could not be changed. The key's error is part of the message, which is what
/// Python's `ValueError` carries.
#[derive(Debug, thiserror::Error)]
pub enum PatchError {
    #[error(
        "{}: not a valid scene: {}",
        irpol::text::path(path),
        parser_message(message, 300)
    )]
    Parse { path: PathBuf, message: String },
    #[error("{}: scene key '{}': {error}", irpol::text::path(path), shown(key))]
    Key {
        path: PathBuf,
        key: String,
        error: KeyError,
    },
}

fn index(parts: &[&str], depth: usize, len: usize) -> Result<usize, KeyError> {
    parts[depth]
        .parse::<usize>()
        .ok()
        .filter(|&i| i < len)
        .ok_or_else(|| KeyError::NotAnIndex {
            index: parts[depth].to_owned(),
            place: place(parts, depth),
            len,
        })
}

/// How a walk treats a missing last key: an error (a sweep's grid keys), or a new entry (the
/// render overrides, whose keys a scene may leave to their defaults).
#[derive(Clone, Copy, PartialEq)]
pub enum Missing {
    Refuse,
    Create,
}

fn set_in_table(
    t: &mut dyn TableLike,
    parts: &[&str],
    depth: usize,
    v: Value,
    missing: Missing,
) -> Result<(), KeyError> {
    if missing == Missing::Create && depth + 1 == parts.len() && t.get(parts[depth]).is_none() {
        t.insert(parts[depth], Item::Value(v));
        return Ok(());
    }
    let child = t.get_mut(parts[depth]).ok_or_else(|| KeyError::NoKey {
        key: parts[depth].to_owned(),
        place: place(parts, depth),
    })?;
    set_in_item(child, parts, depth + 1, v, missing)
}

fn set_in_item(
    item: &mut Item,
    parts: &[&str],
    depth: usize,
    v: Value,
    missing: Missing,
) -> Result<(), KeyError> {
    if depth == parts.len() {
        if !item.is_value() {
            return Err(KeyError::Table(place(parts, depth)));
        }
        *item = Item::Value(v);
        return Ok(());
    }
    match item {
        Item::Table(t) => set_in_table(t, parts, depth, v, missing),
        Item::ArrayOfTables(a) => {
            let i = index(parts, depth, a.len())?;
            let table = a.get_mut(i).expect("index checked");
            if depth + 1 == parts.len() {
                return Err(KeyError::Table(place(parts, depth + 1)));
            }
            set_in_table(table, parts, depth + 1, v, missing)
        }
        Item::Value(value) => set_in_value(value, parts, depth, v, missing),
        Item::None => Err(KeyError::NoEntry(place(parts, depth))),
    }
}

fn set_in_value(
    value: &mut Value,
    parts: &[&str],
    depth: usize,
    v: Value,
    missing: Missing,
) -> Result<(), KeyError> {
    if depth == parts.len() {
        *value = v;
        return Ok(());
    }
    match value {
        Value::Array(a) => {
            let i = index(parts, depth, a.len())?;
            let element = a.get_mut(i).expect("index checked");
            set_in_value(element, parts, depth + 1, v, missing)
        }
        Value::InlineTable(t) => set_in_table(t, parts, depth, v, missing),
        _ => Err(KeyError::SingleValue(place(parts, depth))),
    }
}

/// `text` with each `(key, value)` set; a key that does not name an existing entry is refused
/// with the scene's path and the key (unless `missing` says to create a missing last key).
pub fn patched(
    path: &Path,
    text: &str,
    patch: &[(String, Value)],
    missing: Missing,
) -> Result<String, PatchError> {
    let mut doc: DocumentMut =
        text.parse()
            .map_err(|e: toml_edit::TomlError| PatchError::Parse {
                path: path.to_owned(),
                message: e.to_string(),
            })?;
    for (key, value) in patch {
        let parts: Vec<&str> = key.split('.').collect();
        set_in_item(doc.as_item_mut(), &parts, 0, value.clone(), missing).map_err(|error| {
            PatchError::Key {
                path: path.to_owned(),
                key: key.clone(),
                error,
            }
        })?;
    }
    Ok(doc.to_string())
}

/// A scene file's text, refused as `irpol render` refuses an unreadable scene.
pub fn scene_text(path: &Path) -> PyResult<String> {
    irpol::scene::read_scene_text(path).map_err(raised)
}

/// Checks that every dotted key names an entry of the scene file (a sweep does this before
/// any work starts); raises ValueError naming the first that does not.
#[pyfunction]
pub fn check_scene_keys(scene: PathBuf, keys: Vec<String>) -> PyResult<()> {
    let text = scene_text(&scene)?;
    let patch: Vec<(String, Value)> = keys.into_iter().map(|k| (k, Value::from(0))).collect();
    patched(&scene, &text, &patch, Missing::Refuse)
        .map(drop)
        .map_err(|e| bad_argument(e.to_string()))
}
