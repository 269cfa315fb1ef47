//! One `[[objects]]` entry resolved: its mesh (a file or a procedural shape), its parts checked
//! against the scene, their materials and temperatures, and its world-space shading mesh.

use super::config::{ObjectConfig, ShapeConfig};
use super::heightfield::Heightfield;
use super::mesh::{self, MeshError, ObjectShading, RawMesh, ShadedMesh, Transform};
use super::terrain::TerrainSpectrum;
use super::{obj, ply, procedural, thermal, SceneError, Surface, CELSIUS_SUSPECT_K};
use crate::material::MaterialResolver;
use crate::optics::{valid_temperature, MAX_TEMPERATURE_K};
use crate::text::number;
use std::path::{Path, PathBuf};

/// What an object is built into, shared by all the objects of a scene.
pub(super) struct ObjectSink<'s, 'a> {
    pub materials: &'s mut MaterialResolver<'a>,
    pub surfaces: &'s mut Vec<Surface>,
    pub warnings: &'s mut Vec<String>,
    /// With `[thermal]`: the air temperature at the run's start (§1.8 initial state).
    pub thermal_start_air_k: Option<f64>,
    /// With `[thermal]`: the largest cell of a procedural plane the model solves on.
    pub thermal_plane_cell_m: Option<f64>,
}

/// An object's mesh and where it came from, with what messages call them.
struct LoadedMesh {
    raw: RawMesh,
    /// The mesh file, or `None` for a procedural shape.
    file: Option<PathBuf>,
    /// The mesh file's name, or "the shape".
    name: String,
}

/// Loads an object's mesh, checks its parts against the scene, resolves part materials and
/// temperatures, and returns its world-space shading mesh, with its heightfield when it is an
/// upright terrain. `label` names it in messages ("objects\[0\] 'car'").
pub(super) fn build_object(
    object: &ObjectConfig,
    label: &str,
    object_index: usize,
    sink: &mut ObjectSink,
) -> Result<(ShadedMesh, Option<Heightfield>), SceneError> {
    let scene = sink.materials.scene;
    let fail = |message: String| SceneError::new(scene, format!("{label}: {message}"));
    // Only a plane whose surface temperatures come from the model needs the finer grid.
    let plane_cell_m = sink
        .thermal_plane_cell_m
        .filter(|_| thermal::part_thermal(object, procedural::SHAPE_PART).is_some());
    let loaded = load_object_mesh(object, sink.materials.dir, scene, label, plane_cell_m)?;
    sink.warnings.extend(mesh_warnings(&loaded, label));
    check_parts(object, &loaded, &fail)?;
    let (part_temperature, part_surface) =
        resolve_parts(object, &loaded, label, object_index, sink, &fail)?;
    check_placement(object, &fail)?;
    let setup = ObjectShading {
        transform: Transform::new(object.scale, object.rotate_deg, object.translate),
        crease_angle_deg: object.crease_angle_deg,
        part_temperature: &part_temperature,
        part_surface: &part_surface,
    };
    let (mesh, skipped) =
        mesh::shade_mesh(&loaded.raw, &setup).map_err(|error| match &loaded.file {
            Some(file) => SceneError::Mesh {
                file: file.clone(),
                item: label.to_owned(),
                error,
            },
            None => fail(error.to_string()),
        })?;
    let name = &loaded.name;
    sink.warnings
        .extend(skipped.map(|w| format!("{name} (in {label}): {w}")));
    let heightfield = terrain_heightfield(object, &loaded.raw, &setup);
    Ok((mesh, heightfield))
}

/// The heightfield of a terrain object that stays one in world space (see `heightfield`).
fn terrain_heightfield(
    object: &ObjectConfig,
    raw: &RawMesh,
    setup: &ObjectShading,
) -> Option<Heightfield> {
    let Some(ShapeConfig::Terrain {
        size, divisions, ..
    }) = object.shape
    else {
        return None;
    };
    // A terrain has the one part, `procedural::SHAPE_PART`.
    let part = raw.parts.iter().position(|p| p == procedural::SHAPE_PART)?;
    let surface = setup.part_surface[part];
    Heightfield::of_terrain(
        raw,
        size,
        divisions,
        object.rotate_deg,
        &setup.transform,
        surface,
    )
}

/// The mesh reader's notes, and per-vertex temperatures that look like °C.
fn mesh_warnings(loaded: &LoadedMesh, label: &str) -> Vec<String> {
    let name = &loaded.name;
    let mut warnings: Vec<String> = (loaded.raw.notes.iter())
        .map(|note| format!("{name} (in {label}): {note}"))
        .collect();
    let coldest =
        (loaded.raw.vertex_temperatures.as_ref()).and_then(|t| t.iter().copied().reduce(f64::min));
    if let Some(t) = coldest.filter(|&t| t < CELSIUS_SUSPECT_K) {
        warnings.push(format!(
            "{name} (in {label}): per-vertex temperatures down to {} K look like °C \
             (temperatures are kelvin)",
            number(t)
        ));
    }
    warnings
}

/// An invalid value of an object, as a scene error naming the object.
type Invalid<'f> = &'f dyn Fn(String) -> SceneError;

/// The object's parts exist in its mesh and its temperature is in range.
fn check_parts(
    object: &ObjectConfig,
    loaded: &LoadedMesh,
    invalid: Invalid,
) -> Result<(), SceneError> {
    let used = loaded.raw.used_parts();
    for part in object.parts.keys() {
        if !used.contains(&part.as_str()) {
            return Err(invalid(format!(
                "part '{part}' is not in {} (its parts: {})",
                loaded.name,
                used.join(", ")
            )));
        }
    }
    if let Some(t) = object.temperature_k {
        check_temperature(t, "", invalid)?;
    }
    Ok(())
}

/// The object's scale, placement and crease angle are in range.
fn check_placement(object: &ObjectConfig, invalid: Invalid) -> Result<(), SceneError> {
    if !(object.scale.is_finite() && object.scale > 0.0) {
        return Err(invalid(format!(
            "scale = {} must be finite and > 0",
            number(object.scale)
        )));
    }
    if !object
        .translate
        .iter()
        .chain(object.rotate_deg.iter())
        .all(|v| v.is_finite())
    {
        return Err(invalid("translate and rotate_deg must be finite".into()));
    }
    let crease = object.crease_angle_deg;
    if !(crease.is_finite() && (0.0..=180.0).contains(&crease)) {
        return Err(invalid(format!(
            "crease_angle_deg = {} must be within [0°, 180°]",
            number(crease)
        )));
    }
    Ok(())
}

fn check_temperature(t: f64, what: &str, invalid: Invalid) -> Result<f64, SceneError> {
    if valid_temperature(t) {
        Ok(t)
    } else {
        Err(invalid(format!(
            "{what}temperature_k = {} must be within [0, {MAX_TEMPERATURE_K}] K",
            number(t)
        )))
    }
}

/// Per mesh part: its temperature (typed, or the thermal run's start air) and its surface index
/// (`u32::MAX` for a part with no faces), resolving each used part's material into `sink`.
fn resolve_parts(
    object: &ObjectConfig,
    loaded: &LoadedMesh,
    label: &str,
    object_index: usize,
    sink: &mut ObjectSink,
    invalid: Invalid,
) -> Result<(Vec<Option<f64>>, Vec<u32>), SceneError> {
    let raw = &loaded.raw;
    let used = raw.used_parts();
    let mut part_temperature = Vec::with_capacity(raw.parts.len());
    let mut part_surface = Vec::with_capacity(raw.parts.len());
    for part in &raw.parts {
        if !used.contains(&part.as_str()) {
            // A group with no faces is never drawn and needs no material.
            part_temperature.push(None);
            part_surface.push(u32::MAX);
            continue;
        }
        let settings = object.parts.get(part);
        // A part whose temperatures come from the thermal model starts at the first air
        // temperature unless one is given (§1.8 initial state).
        let temperature = settings
            .and_then(|p| p.temperature_k)
            .or(object.temperature_k)
            .or(sink
                .thermal_start_air_k
                .filter(|_| thermal::part_thermal(object, part).is_some()));
        if let Some(t) = temperature {
            check_temperature(t, &format!("part '{part}': "), invalid)?;
            if raw.vertex_temperatures.is_some() {
                return Err(invalid(format!(
                    "{} has per-vertex temperatures; remove temperature_k \
                     (part '{part}') or the PLY property",
                    loaded.name
                )));
            }
        }
        part_temperature.push(temperature);
        let material_name = settings
            .and_then(|p| p.material.as_deref())
            .or(object.material.as_deref())
            .ok_or_else(|| {
                invalid(format!(
                    "part '{part}' has no material (set material on the object or the part)"
                ))
            })?;
        let material = sink.materials.resolve(material_name).map_err(|error| {
            let item = Some(format!("{label}: part '{part}'"));
            SceneError::material(sink.materials.scene, item, error)
        })?;
        part_surface.push(sink.surfaces.len() as u32);
        sink.surfaces.push(Surface {
            object: object_index,
            part: part.clone(),
            material,
        });
    }
    Ok((part_temperature, part_surface))
}

/// The object's mesh: its file (relative to `dir`, OBJ or PLY) or its procedural shape (a plane
/// cut into cells no larger than `plane_cell_m` when given).
fn load_object_mesh(
    object: &ObjectConfig,
    dir: &Path,
    scene: &Path,
    label: &str,
    plane_cell_m: Option<f64>,
) -> Result<LoadedMesh, SceneError> {
    let invalid = |message: String| SceneError::new(scene, format!("{label}: {message}"));
    let file = match (&object.mesh, &object.shape) {
        (Some(_), Some(_)) => return Err(invalid("give either mesh or shape, not both".into())),
        (None, None) => return Err(invalid("needs a mesh file or a shape".into())),
        (None, Some(shape)) => {
            return Ok(LoadedMesh {
                raw: procedural_shape(shape, plane_cell_m, &invalid)?,
                file: None,
                name: "the shape".to_owned(),
            })
        }
        (Some(file), None) => dir.join(file),
    };
    let bytes = std::fs::read(&file).map_err(|source| SceneError::MeshRead {
        file: file.clone(),
        item: label.to_owned(),
        source,
    })?;
    let raw = parse_mesh(&file, bytes).map_err(|error| SceneError::Mesh {
        file: file.clone(),
        item: label.to_owned(),
        error,
    })?;
    Ok(LoadedMesh {
        raw,
        name: file.display().to_string(),
        file: Some(file),
    })
}

/// A mesh file's bytes, read by its extension.
fn parse_mesh(file: &Path, bytes: Vec<u8>) -> Result<RawMesh, MeshError> {
    let extension = file
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some("obj") => {
            let text = String::from_utf8(bytes).map_err(|_| MeshError::NotUtf8)?;
            obj::parse_obj(&text)
        }
        Some("ply") => ply::parse_ply(&bytes),
        _ => Err(MeshError::UnknownFormat),
    }
}

fn procedural_shape(
    shape: &ShapeConfig,
    plane_cell_m: Option<f64>,
    invalid: Invalid,
) -> Result<RawMesh, SceneError> {
    match *shape {
        ShapeConfig::Sphere {
            radius,
            subdivisions,
        } => {
            if !(radius.is_finite() && radius > 0.0) {
                return Err(invalid(format!(
                    "shape.radius = {} must be finite and > 0",
                    number(radius)
                )));
            }
            if subdivisions > 7 {
                return Err(invalid(format!(
                    "shape.subdivisions = {subdivisions} is too fine (at most 7: 327 680 faces)"
                )));
            }
            Ok(procedural::icosphere(radius, subdivisions))
        }
        ShapeConfig::Plane { size, divisions } => {
            check_grid(size, divisions, invalid)?;
            let divisions = plane_cell_m.map_or(divisions, |cell| {
                procedural::divisions_for_cell(size, divisions, cell)
            });
            Ok(procedural::plane(size, divisions))
        }
        ShapeConfig::Terrain {
            size,
            divisions,
            rms_height_m,
            correlation_length_m,
            hurst,
            seed,
        } => {
            let spectrum = TerrainSpectrum {
                rms_height_m,
                correlation_length_m,
                hurst,
                seed,
            };
            check_terrain(size, divisions, &spectrum, invalid)?;
            Ok(procedural::terrain(size, divisions, &spectrum))
        }
    }
}

/// A plane's or terrain's size and divisions.
fn check_grid(size: [f64; 2], divisions: [u32; 2], invalid: Invalid) -> Result<(), SceneError> {
    if !size.iter().all(|s| s.is_finite() && *s > 0.0) {
        return Err(invalid("shape.size must be finite and > 0".into()));
    }
    if !divisions.iter().all(|d| (1..=4096).contains(d)) {
        return Err(invalid("shape.divisions must be within 1…4096".into()));
    }
    Ok(())
}

/// A terrain's grid and spectrum: the grid must resolve the correlation length (two cells at
/// least), else the tile is white noise at the grid's own scale whatever ℓ says.
fn check_terrain(
    size: [f64; 2],
    divisions: [u32; 2],
    spectrum: &TerrainSpectrum,
    invalid: Invalid,
) -> Result<(), SceneError> {
    check_grid(size, divisions, invalid)?;
    let rms = spectrum.rms_height_m;
    if !(rms.is_finite() && rms >= 0.0) {
        return Err(invalid(format!(
            "shape.rms_height_m = {} must be finite and ≥ 0",
            number(rms)
        )));
    }
    let cell = (size[0] / divisions[0] as f64).max(size[1] / divisions[1] as f64);
    let length = spectrum.correlation_length_m;
    if !(length.is_finite() && length >= 2.0 * cell) {
        return Err(invalid(format!(
            "shape.correlation_length_m = {} must be at least two cells ({} m): use more \
             divisions or a longer correlation length",
            number(length),
            number(2.0 * cell)
        )));
    }
    if let Some(h) = spectrum.hurst {
        if !(h > 0.0 && h <= 1.0) {
            return Err(invalid(format!(
                "shape.hurst = {} must be within (0, 1]",
                number(h)
            )));
        }
    }
    Ok(())
}
