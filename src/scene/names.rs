//! The names a scene gives and refers to (materials, layers, objects, parts), checked once so
//! that every message and summary can quote them whole on one short printable line.

use super::config::SceneConfig;
use super::SceneError;
use std::path::Path;

/// Refuses a name (of a material, layer, object or part, given or referred to) that holds a
/// control character or is longer than [`crate::text::MAX_NAME_CHARS`]: messages and summaries
/// quote names whole, and each must stay one short printable line.
pub(super) fn check_names(path: &Path, config: &SceneConfig) -> Result<(), SceneError> {
    let mut names: Vec<(String, &str)> = Vec::new();
    names.extend(
        config
            .materials
            .keys()
            .map(|k| ("materials".to_owned(), k.as_str())),
    );
    if let Some(thermal) = &config.thermal {
        let layers = thermal.layers.keys();
        names.extend(layers.map(|k| ("thermal.layers".to_owned(), k.as_str())));
    }
    for (i, object) in config.objects.iter().enumerate() {
        let key = |what: &str| format!("objects[{i}].{what}");
        names.extend(object.name.as_deref().map(|n| (key("name"), n)));
        names.extend(object.material.as_deref().map(|n| (key("material"), n)));
        for (part, config) in &object.parts {
            names.push((key("parts"), part.as_str()));
            names.extend(
                config
                    .material
                    .as_deref()
                    .map(|n| (key("parts.material"), n)),
            );
        }
    }
    match names
        .into_iter()
        .find_map(|(key, name)| crate::text::name_problem(name).map(|p| (key, p)))
    {
        Some((key, problem)) => Err(SceneError::new(path, format!("{key}: the name {problem}"))),
        None => Ok(()),
    }
}
