//! Scenes (docs/design.md §2.3): the scene TOML, meshes (OBJ with groups as parts, PLY with per-vertex
//! temperature), procedural test objects, the camera, the environment, and the materials of every
//! part, resolved into one world-space [`ShadedMesh`] ready for `render`.
//!
//! Paths in a scene are relative to the scene file. Every error names the file and the item
//! ("scenes/car.toml: objects\[0\] 'car', part 'hood': …", "scenes/car.obj: line 12: …"); see
//! [`SceneError`].
//!
//! This module assembles; each section is resolved by the module that owns it: `[materials]` by
//! [`crate::material::MaterialResolver`], `[sun]` by [`crate::emitter::SunConfig`], the
//! `[thermal]` keys by [`crate::thermal::setup`] (their ties to the scene's parts in [`thermal`]),
//! objects in `object`, camera, sensor, environment and atmosphere in `viewing`, `[render]` in
//! `render_settings` (here, not in `transport`, because `transport` reads the scene).

pub mod camera;
pub mod car;
pub mod config;
pub mod environment;
mod error;
pub mod heightfield;
pub mod mesh;
mod names;
pub mod obj;
mod object;
pub mod ply;
pub mod procedural;
mod render_settings;
pub mod sensor;
pub mod terrain;
pub mod thermal;
mod viewing;
mod warnings;

use crate::emitter::Sun;
use crate::material::MaterialResolver;
use crate::optics::Band;
use camera::Camera;
use config::{ObjectConfig, SceneConfig, Shading, WeatherConfig};
use environment::Environment;
use heightfield::Heightfield;
use mesh::ShadedMesh;
use object::{build_object, ObjectSink};
use std::path::{Path, PathBuf};
use viewing::resolve_viewing;
use warnings::{beyond_atmosphere_table, likely_mistakes, CELSIUS_SUSPECT_K};

pub use crate::atmosphere::Atmosphere;
pub use crate::material::SceneMaterial;
pub use crate::optics::{valid_temperature, MAX_TEMPERATURE_K};
pub use error::SceneError;
pub use render_settings::{PathSettings, Transport};
pub use sensor::{Demosaic, Detector, Diffraction, Dofp, Optics, Sensor};

/// One part of one object: what `ShadedMesh::triangle_surface` indexes.
#[derive(Clone, Debug)]
pub struct Surface {
    pub object: usize,
    pub part: String,
    pub material: usize,
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub path: PathBuf,
    pub camera: Camera,
    pub sensor: Sensor,
    pub air_temperature_k: f64,
    pub environment: Environment,
    pub atmosphere: Option<Atmosphere>,
    pub shading: Shading,
    pub aop_mask_dolp: f64,
    /// `[render.preview]`, checked.
    pub preview: config::PreviewConfig,
    pub transport: Transport,
    /// Above the horizon only (a sun below it lights nothing).
    pub sun: Option<Sun>,
    pub materials: Vec<SceneMaterial>,
    pub object_names: Vec<String>,
    pub surfaces: Vec<Surface>,
    pub mesh: ShadedMesh,
    /// The terrain objects that stay heightfields in world space (upright: no rotation about x
    /// or y), in object order, for the thermal model's horizon maps; empty without terrains.
    pub heightfields: Vec<Heightfield>,
    /// `[thermal]`: temperatures from the model of §1.8 (solved by `thermal_scene`).
    pub thermal: Option<std::sync::Arc<thermal::ThermalSetup>>,
    /// With `[thermal]`: how the scene is rebuilt at an instant of the run.
    pub thermal_rebuild: Option<thermal::InstantSettings>,
    /// Set when the scene is a thermal scene at an instant of its run (`thermal_scene::scene_at`).
    pub thermal_instant: Option<ThermalInstant>,
    /// What is probably a mistake but not an error: the binary prints each once
    /// and `summary.json` lists them.
    pub warnings: Vec<String>,
}

/// The instant of a thermal run a scene shows.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ThermalInstant {
    /// Seconds from `thermal.start_utc`.
    pub time_s: f64,
    /// The same instant as RFC 3339.
    pub time_utc: String,
}

impl Scene {
    /// The material index of triangle `t` of the mesh.
    #[inline]
    pub fn triangle_material(&self, t: usize) -> usize {
        self.surfaces[self.mesh.triangle_surface[t] as usize].material
    }
}

/// Reads and resolves a scene file: meshes, materials, environment. Nothing is written.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    load_scene_text(path, &read_scene_text(path)?)
}

/// A scene file's text, for callers that change it before [`load_scene_text`] (the Python
/// bindings' sweeps); refused as [`load_scene`] refuses an unreadable scene.
pub fn read_scene_text(path: &Path) -> Result<String, SceneError> {
    std::fs::read_to_string(path).map_err(|source| SceneError::Read {
        file: path.to_owned(),
        source,
    })
}

/// [`load_scene`] of a scene's text (e.g. a file's text with some values changed, as the Python
/// bindings' sweeps do); `path` names it in messages and relative paths resolve from its folder.
pub fn load_scene_text(path: &Path, text: &str) -> Result<Scene, SceneError> {
    let config: SceneConfig =
        toml::from_str(text).map_err(|e| SceneError::parse(path, text, &e))?;
    build_scene(path, config)
}

fn build_scene(path: &Path, config: SceneConfig) -> Result<Scene, SceneError> {
    names::check_names(path, &config)?;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let viewing = resolve_viewing(path, &config)?;
    let band = &viewing.sensor.band;
    if config.objects.is_empty() {
        return Err(SceneError::new(path, "the scene has no [[objects]]"));
    }
    let transport = render_settings::transport_settings(path, &config.render)?;
    let thermal_run = thermal::resolve_thermal(path, &config, dir, band)?;
    let sun = fixed_sun(path, &config, band, thermal_run.is_some(), transport)?;
    let start_air_k = thermal_run.as_ref().map(|(_, _, air_k)| *air_k);

    let library = dir.join(config.material_library.as_deref().unwrap_or("fits"));
    let mut materials = MaterialResolver::new(path, band, dir, library, &config.materials);
    let mut surfaces = Vec::new();
    let mut warnings = Vec::new();
    let mut sink = ObjectSink {
        materials: &mut materials,
        surfaces: &mut surfaces,
        warnings: &mut warnings,
        thermal_start_air_k: start_air_k,
        thermal_plane_cell_m: config.thermal.as_ref().map(|t| t.plane_cell_m),
    };
    let (object_names, mesh, heightfields) = build_objects(&config.objects, &mut sink)?;
    let materials = materials
        .finish()
        .map_err(|error| SceneError::material(path, None, error))?;
    let weather_air = weather_file_air(&config, thermal_run.as_ref().map(|(run, _, _)| run));
    warnings.extend(likely_mistakes(&config, &materials, band, weather_air));
    warnings.extend(beyond_atmosphere_table(
        viewing.atmosphere.as_ref(),
        &viewing.camera.position,
        &mesh.positions,
    ));
    let (thermal, thermal_rebuild) = match thermal_run {
        Some((mut run, instants, _)) => {
            run.surfaces = thermal::resolve_surfaces(
                path,
                &config,
                &surfaces,
                &object_names,
                &materials,
                &run.enclosures,
            )?;
            (Some(std::sync::Arc::new(run)), Some(instants))
        }
        None => (None, None),
    };
    Ok(Scene {
        path: path.to_owned(),
        camera: viewing.camera,
        sensor: viewing.sensor,
        air_temperature_k: config.environment.air_temperature_k,
        environment: viewing.environment,
        atmosphere: viewing.atmosphere,
        shading: config.render.shading,
        aop_mask_dolp: viewing.aop_mask_dolp,
        preview: render_settings::checked_preview(path, &config.render.preview)?,
        transport,
        sun,
        materials,
        object_names,
        surfaces,
        mesh,
        heightfields,
        thermal,
        thermal_rebuild,
        thermal_instant: None,
        warnings,
    })
}

/// The `[sun]` of a scene without `[thermal]` (a thermal run moves its own sun).
fn fixed_sun(
    path: &Path,
    config: &SceneConfig,
    band: &Band,
    thermal: bool,
    transport: Transport,
) -> Result<Option<Sun>, SceneError> {
    let sun = match (&config.sun, thermal) {
        (Some(sun), false) => sun.resolve(band).map_err(|error| SceneError::Sun {
            file: path.to_owned(),
            error,
        })?,
        _ => None,
    };
    // The open-world model has no sun (a warning says so); the summary must not claim one.
    Ok(sun.filter(|_| transport != Transport::OpenWorld))
}

/// The weather file and its coldest air, for the warnings (a clear day's air is its own keys,
/// warned about as such).
fn weather_file_air<'a>(
    config: &'a SceneConfig,
    run: Option<&thermal::ThermalSetup>,
) -> Option<(&'a str, f64)> {
    match (&config.thermal, run) {
        (Some(t), Some(run)) => match &t.weather {
            WeatherConfig::File(file) => Some((file.as_str(), run.weather.coldest_air_k())),
            WeatherConfig::Generated(_) => None,
        },
        _ => None,
    }
}

/// Every object, named (given, else its mesh file's stem, else `objectN`), in one mesh, and the
/// heightfields of the upright terrains among them.
fn build_objects(
    objects: &[ObjectConfig],
    sink: &mut ObjectSink,
) -> Result<(Vec<String>, ShadedMesh, Vec<Heightfield>), SceneError> {
    let mut object_names = Vec::new();
    let mut mesh = ShadedMesh::default();
    let mut heightfields = Vec::new();
    for (index, object) in objects.iter().enumerate() {
        let name = object.name.clone().unwrap_or_else(|| {
            object
                .mesh
                .as_deref()
                .and_then(|m| Path::new(m).file_stem())
                .map_or(format!("object{}", index + 1), |s| {
                    s.to_string_lossy().into_owned()
                })
        });
        let label = format!("objects[{index}] '{name}'");
        let (object_mesh, heightfield) = build_object(object, &label, object_names.len(), sink)?;
        object_names.push(name);
        mesh.append(object_mesh);
        heightfields.extend(heightfield);
    }
    Ok((object_names, mesh, heightfields))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere with an inline material, seen from 4 m; `extra` is appended.
    fn scene_text(extra: &str) -> String {
        format!(
            "[camera]\nposition = [0.0, -4.0, 0.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\n\
             fov_deg = 36.0\nresolution = [8, 8]\n\
             [environment]\nair_temperature_k = 283.15\n\
             sky = {{ model = \"window\", zenith_emissivity = 0.75 }}\n\
             ground = {{ temperature_k = 288.0, emissivity = 0.95 }}\n\
             [materials.m]\ndistribution = \"cauchy\"\nsigma = 0.2\nq = 2.0\nn = 1.5\nk = 0.1\n\
             [[objects]]\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 1 }}\n\
             material = \"m\"\ntemperature_k = 300.0\n{extra}"
        )
    }

    #[test]
    fn an_inline_scene_resolves() {
        let scene = load_scene_text(Path::new("dir/s.toml"), &scene_text("")).unwrap();
        assert_eq!(scene.object_names, ["object1"]);
        assert_eq!(scene.materials.len(), 1);
        assert_eq!(scene.materials[0].origin, "inline");
        assert_eq!(scene.surfaces.len(), 1);
        assert!(
            scene.mesh.triangles.len() == 80,
            "{}",
            scene.mesh.triangles.len()
        );
        assert!(matches!(scene.transport, Transport::Path(_)));
        assert!(scene.sun.is_none() && scene.thermal.is_none());
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    }

    #[test]
    fn parse_errors_name_file_line_and_column() {
        let text = scene_text("").replace("fov_deg = 36.0", "fov_deg = \"wide\"");
        let error = load_scene_text(Path::new("s.toml"), &text).unwrap_err();
        assert!(
            matches!(
                error,
                SceneError::Parse {
                    line: Some(5),
                    column: Some(11),
                    ..
                }
            ),
            "{error:?}"
        );
        let message = error.to_string();
        assert!(
            message.starts_with("s.toml: not a valid scene: line 5, column 11: "),
            "{message}"
        );
        assert!(!message.contains('\n'));
    }

    #[test]
    fn value_errors_name_the_file_and_the_item() {
        let text = scene_text("").replace("material = \"m\"", "material = \"nothing\"");
        let error = load_scene_text(Path::new("s.toml"), &text).unwrap_err();
        assert!(matches!(error, SceneError::Material { .. }), "{error:?}");
        let message = error.to_string();
        assert!(
            message.starts_with("s.toml: objects[0] 'object1': part 'surface': material 'nothing'"),
            "{message}"
        );
        let text = scene_text("").replace("radius = 1.0", "radius = -1.0");
        let message = load_scene_text(Path::new("s.toml"), &text)
            .unwrap_err()
            .to_string();
        assert_eq!(
            message,
            "s.toml: objects[0] 'object1': shape.radius = -1 must be finite and > 0"
        );
    }

    #[test]
    fn unreadable_files_keep_their_io_error() {
        let error = load_scene(Path::new("/nonexistent/irpol/s.toml")).unwrap_err();
        assert_eq!(
            error.to_string(),
            "/nonexistent/irpol/s.toml: cannot read the scene"
        );
        let source = std::error::Error::source(&error).expect("the io::Error");
        assert!(source.downcast_ref::<std::io::Error>().is_some());

        let text = scene_text("").replace(
            "shape = { kind = \"sphere\", radius = 1.0, subdivisions = 1 }",
            "mesh = \"missing.obj\"",
        );
        let error = load_scene_text(Path::new("/nonexistent/s.toml"), &text).unwrap_err();
        assert!(matches!(error, SceneError::MeshRead { .. }), "{error:?}");
        assert_eq!(
            error.to_string(),
            "/nonexistent/missing.obj: cannot read the mesh (in objects[0] 'missing')"
        );
        assert!(std::error::Error::source(&error).is_some());
    }

    #[test]
    fn a_sun_in_the_open_world_is_a_warning_and_no_sun() {
        let sun = "[sun]\nelevation_deg = 40.0\nazimuth_deg = 180.0\n";
        let lit = load_scene_text(Path::new("s.toml"), &scene_text(sun)).unwrap();
        assert!(lit.sun.is_some());
        assert!(lit.warnings.is_empty(), "{:?}", lit.warnings);
        let text = scene_text(&format!("[render]\nopen_world = true\n{sun}"));
        let open = load_scene_text(Path::new("s.toml"), &text).unwrap();
        assert!(open.sun.is_none());
        assert_eq!(open.warnings.len(), 1, "{:?}", open.warnings);
        assert!(open.warnings[0].starts_with("[sun] is ignored with render.open_world = true"));
    }
}
