//! Scenes (docs/design.md §2.3): the scene TOML, meshes (OBJ with groups as parts, PLY with per-vertex
//! temperature), procedural test objects, the camera, the environment, and the materials of every
//! part, resolved into one world-space [`ShadedMesh`] ready for `render`.
//!
//! Paths in a scene are relative to the scene file. Every error names the file and the item
//! ("scenes/car.toml: objects\[0\] 'car', part 'hood': …", "scenes/car.obj: line 12: …").

pub mod camera;
pub mod car;
pub mod config;
pub mod environment;
pub mod mesh;
pub mod obj;
pub mod ply;
pub mod procedural;
pub mod thermal;

use crate::emitter::{
    default_band_irradiance, parse_time_utc, sun_direction, sun_position, validate_irradiance,
    validate_sun_angles, validate_transmittance, Sun,
};
use crate::material::{Material, MaterialModel, SpectralModel};
use crate::optics::{Band, RefractiveIndex};
use crate::pbrdf::{MaterialOptics, Pbrdf, SlopeDistribution};
use crate::text::number;
use camera::Camera;
use config::{InlineMaterialConfig, ObjectConfig, SceneConfig, Shading, ShapeConfig};
use environment::Environment;
use mesh::{ObjectShading, RawMesh, ShadedMesh, Transform};
use nalgebra::Vector3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

pub use crate::optics::{valid_temperature, MAX_TEMPERATURE_K};

/// A scene or one of its files is unusable; `file` is the file at fault.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", file.display())]
pub struct SceneError {
    pub file: PathBuf,
    pub message: String,
}

impl SceneError {
    /// Messages are kept to one line (some parsers format theirs over several).
    pub fn new(file: &Path, message: impl Into<String>) -> SceneError {
        SceneError {
            file: file.to_owned(),
            message: message
                .into()
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" "),
        }
    }
}

/// A material used by the scene, with its validated pBRDF over the sensor band.
#[derive(Clone, Debug)]
pub struct SceneMaterial {
    /// The name given in the scene.
    pub name: String,
    /// Where it came from: the material file, or "inline".
    pub origin: String,
    /// Grey (one pBRDF), or for a spectral material its pBRDF at each wavelength node of the
    /// sensor band (docs/design.md §1.9).
    pub optics: MaterialOptics,
    /// The wavelength a grey library material was measured at (inline and spectral materials
    /// have none).
    pub wavelength_um: Option<f64>,
    /// A spectral material's table (the thermal emissivity needs wavelengths beyond the band).
    pub spectral_model: Option<SpectralModel>,
}

impl SceneMaterial {
    /// The thermal hemispherical emissivity of docs/design.md §1.8's default: the grey pBRDF's ε_h, or a
    /// spectral table's Planck-weighted one ([`SpectralModel::thermal_emissivity`]).
    pub fn thermal_emissivity(&self) -> Result<f64, String> {
        match (&self.optics, &self.spectral_model) {
            (_, Some(model)) => model
                .thermal_emissivity()
                .map_err(|e| format!("material '{}' ({}): {e}", self.name, self.origin)),
            (optics, None) => Ok(optics.sampling_pbrdf().hemispherical_emissivity()),
        }
    }
}

/// One part of one object: what `ShadedMesh::triangle_surface` indexes.
#[derive(Clone, Debug)]
pub struct Surface {
    pub object: usize,
    pub part: String,
    pub material: usize,
}

#[derive(Clone, Debug)]
pub struct Sensor {
    pub band: Band,
    pub netd_mk: f64,
    pub seed: u64,
    pub netd_reference_k: f64,
    /// Write the division-of-focal-plane mosaic and its demosaicked Stokes images too.
    pub dofp: bool,
}

/// Optional atmospheric path: S_sensor = τ S + (1 − τ) L_bb(T_path) δ_j0, τ = exp(−β·range).
#[derive(Clone, Copy, Debug)]
pub struct Atmosphere {
    pub extinction_per_m: f64,
    pub temperature_k: f64,
}

impl Atmosphere {
    /// τ = exp(−β·range) over `range` metres.
    #[inline]
    pub fn transmittance(&self, range: f64) -> f64 {
        (-self.extinction_per_m * range).exp()
    }
}

/// Monte Carlo settings of the path integrator (`[render]`, docs/design.md §2.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct PathSettings {
    /// Vertex k (0 = the camera's visible point) traces its correction while k ≤ `bounces`:
    /// 0 still occludes the visible point's environment (a blocked direction delivers the
    /// blocker's open-world value); 3 follows three inter-reflections.
    pub bounces: u32,
    /// Paths per pixel.
    pub samples: u32,
    pub seed: u64,
}

/// How light reaches the visible points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// The paper's model (docs/design.md §1.5): every point sees the whole sky and ground; no sun.
    OpenWorld,
    /// Occlusion, inter-reflection and the sun (docs/design.md §1.7).
    Path(PathSettings),
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
    /// `[thermal]`: temperatures from the model of §1.8 (solved by `thermal_scene`).
    pub thermal: Option<std::sync::Arc<thermal::ThermalSetup>>,
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
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::new(path, format!("cannot read the scene: {e}")))?;
    load_scene_text(path, &text)
}

/// [`load_scene`] of a scene's text (e.g. a file's text with some values changed, as the Python
/// bindings' sweeps do); `path` names it in messages and relative paths resolve from its folder.
pub fn load_scene_text(path: &Path, text: &str) -> Result<Scene, SceneError> {
    let config: SceneConfig = toml::from_str(text).map_err(|e| {
        let at = e.span().map_or(String::new(), |span| {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!("line {line}, column {column}: ")
        });
        SceneError::new(path, format!("not a valid scene: {at}{}", e.message()))
    })?;
    build_scene(path, config)
}

fn build_scene(path: &Path, config: SceneConfig) -> Result<Scene, SceneError> {
    let fail = |message: String| SceneError::new(path, message);
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));

    let c = &config.camera;
    let camera = Camera::new(
        Vector3::from(c.position),
        Vector3::from(c.look_at),
        Vector3::from(c.up),
        c.fov_deg,
        c.resolution[0],
        c.resolution[1],
    )
    .map_err(&fail)?;

    let s = &config.sensor;
    let band = Band::new(
        s.band_um[0],
        s.band_um[1],
        s.response
            .as_ref()
            .map(|r| r.iter().map(|&[w, v]| (w, v)).collect()),
    )
    .map_err(|e| fail(format!("sensor: {e}")))?;
    let air = config.environment.air_temperature_k;
    let netd_reference_k = s.netd_reference_k.unwrap_or(air);
    if !(s.netd_mk.is_finite() && s.netd_mk >= 0.0) {
        return Err(fail(format!("sensor.netd_mk = {} must be ≥ 0", s.netd_mk)));
    }
    // An explicit reference is checked here; the default (the air) by the environment below.
    if s.netd_reference_k.is_some()
        && !(valid_temperature(netd_reference_k) && netd_reference_k > 0.0)
    {
        return Err(fail(format!(
            "sensor.netd_reference_k = {} must be within (0, {MAX_TEMPERATURE_K}] K",
            number(netd_reference_k)
        )));
    }
    let environment = Environment::new(&config.environment, &band).map_err(&fail)?;

    let atmosphere = match &config.atmosphere {
        None => None,
        Some(a) => {
            let temperature_k = a.temperature_k.unwrap_or(air);
            if !(a.extinction_per_km.is_finite() && a.extinction_per_km >= 0.0) {
                return Err(fail(format!(
                    "atmosphere.extinction_per_km = {} must be finite and ≥ 0",
                    a.extinction_per_km
                )));
            }
            if !valid_temperature(temperature_k) {
                return Err(fail(format!(
                    "atmosphere.temperature_k = {} must be within [0, {MAX_TEMPERATURE_K}] K",
                    number(temperature_k)
                )));
            }
            Some(Atmosphere {
                extinction_per_m: a.extinction_per_km * 1e-3,
                temperature_k,
            })
        }
    };
    let mask = config.render.aop_mask_dolp;
    if !(mask.is_finite() && (0.0..=1.0).contains(&mask)) {
        return Err(fail(format!(
            "render.aop_mask_dolp = {mask} must be within [0, 1]"
        )));
    }
    if config.objects.is_empty() {
        return Err(fail("the scene has no [[objects]]".into()));
    }
    let transport = transport_settings(&config.render).map_err(&fail)?;
    let thermal_run = match &config.thermal {
        Some(t) => {
            let instants = thermal_instants(&config, &band).map_err(&fail)?;
            let ground_k = config.environment.ground.temperature_k;
            Some(thermal::resolve_run(t, dir, ground_k, instants).map_err(&fail)?)
        }
        None => None,
    };
    let sun = match (&config.sun, &thermal_run) {
        (Some(sun), None) => resolve_sun(sun, &band).map_err(&fail)?,
        _ => None,
    };
    let start_air_k = match &thermal_run {
        Some(run) => Some(run.weather.at(0.0).map_err(|e| fail(e.to_string()))?.air_k),
        None => None,
    };

    let library = dir.join(config.material_library.as_deref().unwrap_or("fits"));
    let mut materials = MaterialResolver {
        scene: path,
        band: &band,
        dir,
        library,
        inline: &config.materials,
        resolved: Vec::new(),
        index_of: HashMap::new(),
    };
    let mut surfaces = Vec::new();
    let mut object_names = Vec::new();
    let mut mesh = ShadedMesh::default();
    let mut warnings = Vec::new();
    for (index, object) in config.objects.iter().enumerate() {
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
        let object_mesh = build_object(
            object,
            &label,
            object_names.len(),
            &mut materials,
            &mut surfaces,
            start_air_k,
            &mut warnings,
        )?;
        object_names.push(name);
        mesh.append(object_mesh);
    }
    share_wavelength_nodes(&mut materials.resolved, &band).map_err(&fail)?;
    warnings.extend(likely_mistakes(&config, &materials.resolved, &band));
    let thermal = match (thermal_run, &config.thermal) {
        (Some(mut run), Some(thermal_config)) => {
            run.surfaces = thermal::resolve_surfaces(
                &config,
                thermal_config,
                &surfaces,
                &object_names,
                &materials.resolved,
            )
            .map_err(&fail)?;
            Some(std::sync::Arc::new(run))
        }
        _ => None,
    };
    let materials = materials.resolved;

    Ok(Scene {
        path: path.to_owned(),
        camera,
        sensor: Sensor {
            band,
            netd_mk: s.netd_mk,
            seed: s.seed,
            netd_reference_k,
            dofp: s.dofp,
        },
        air_temperature_k: air,
        environment,
        atmosphere,
        shading: config.render.shading,
        aop_mask_dolp: mask,
        preview: checked_preview(&config.render.preview).map_err(&fail)?,
        transport,
        sun,
        materials,
        object_names,
        surfaces,
        mesh,
        thermal,
        thermal_instant: None,
        warnings,
    })
}

/// Puts every spectral material of a scene on one set of wavelength nodes (docs/design.md §1.9,
/// [`crate::optics::WavelengthNodes::for_tables`]): the band split at the table wavelengths of
/// all of them, so that light passed from one to another keeps its spectrum node by node.
fn share_wavelength_nodes(materials: &mut [SceneMaterial], band: &Band) -> Result<(), String> {
    let tables: Vec<&[f64]> = materials
        .iter()
        .filter_map(|m| m.spectral_model.as_ref())
        .map(|model| model.wavelength_um.as_slice())
        .collect();
    if tables.len() < 2 {
        return Ok(());
    }
    let nodes =
        crate::optics::WavelengthNodes::for_tables(band, &tables).map_err(|e| e.to_string())?;
    for material in materials.iter_mut() {
        if let Some(model) = &material.spectral_model {
            let band_pbrdf = model
                .band_pbrdf_on(nodes.clone())
                .map_err(|e| format!("material '{}' ({}): {e}", material.name, material.origin))?;
            material.optics = MaterialOptics::Band(band_pbrdf);
        }
    }
    Ok(())
}

/// Below this a temperature is probably in °C (the coldest natural surface, Antarctic snow at
/// night, is ~180 K; nothing a thermal camera images is colder in an irpol scene).
const CELSIUS_SUSPECT_K: f64 = 200.0;

/// Probable mistakes that are not errors: temperatures that look like °C, inline
/// materials nothing uses, library materials measured outside the sensor band.
fn likely_mistakes(config: &SceneConfig, materials: &[SceneMaterial], band: &Band) -> Vec<String> {
    let mut warnings = Vec::new();
    for (i, object) in config.objects.iter().enumerate() {
        let name = object
            .name
            .clone()
            .unwrap_or_else(|| format!("object{}", i + 1));
        let typed = std::iter::once((String::new(), object.temperature_k)).chain(
            object
                .parts
                .iter()
                .map(|(part, p)| (format!(" part '{part}'"), p.temperature_k)),
        );
        for (what, t) in typed {
            if let Some(t) = t.filter(|&t| t < CELSIUS_SUSPECT_K) {
                warnings.push(format!(
                    "objects[{i}] '{name}'{what}: temperature_k = {} K looks like °C \
                     (temperatures are kelvin: {} °C is {} K)",
                    number(t),
                    number(t),
                    number(t + 273.15)
                ));
            }
        }
    }
    for key in config.materials.keys() {
        if !materials
            .iter()
            .any(|m| m.origin == "inline" && &m.name == key)
        {
            warnings.push(format!("[materials.{key}] is never used by any object"));
        }
    }
    let (lo, hi) = band.limits_um();
    for m in materials {
        if let Some(w) = m.wavelength_um.filter(|&w| w < lo || w > hi) {
            warnings.push(format!(
                "material '{}' ({}) was measured at {} µm, outside the sensor band {lo}–{hi} µm: \
                 its index is assumed to hold across the band",
                m.name,
                m.origin,
                number(w)
            ));
        }
    }
    warnings
}

/// What a thermal scene needs to be rendered at an instant of its run: the sky at that instant's
/// air temperature, and the sun's band irradiance (its direction comes from the weather). With
/// `[thermal]`, `[sun]` may only give the irradiance or transmittance.
fn thermal_instants(config: &SceneConfig, band: &Band) -> Result<thermal::InstantSettings, String> {
    let sun = config.sun.as_ref();
    if let Some(s) = sun {
        if s.elevation_deg.is_some()
            || s.azimuth_deg.is_some()
            || s.latitude_deg.is_some()
            || s.longitude_deg.is_some()
            || s.time_utc.is_some()
        {
            return Err(
                "with [thermal] the sun moves with the run (thermal.start_utc, \
                        latitude_deg, longitude_deg): remove the position keys from [sun] \
                        (irradiance_w_m2 and transmittance may stay)"
                    .into(),
            );
        }
    }
    let irradiance = match sun {
        Some(s) => sun_band_irradiance(s, band)?,
        None => default_band_irradiance(band, DEFAULT_SUN_TRANSMITTANCE),
    };
    Ok(thermal::InstantSettings {
        environment: config.environment.clone(),
        atmosphere_temperature_given: config
            .atmosphere
            .as_ref()
            .is_some_and(|a| a.temperature_k.is_some()),
        netd_reference_given: config.sensor.netd_reference_k.is_some(),
        sun_irradiance_w_m2: irradiance,
    })
}

/// `[render.preview]`: percentiles within [0, 100] and increasing, fixed ranges finite and
/// increasing.
fn checked_preview(preview: &config::PreviewConfig) -> Result<config::PreviewConfig, String> {
    let pairs = [
        ("percentiles", preview.percentiles),
        ("s0_k", preview.s0_k),
        ("s1", preview.s1),
        ("s2", preview.s2),
        ("s3", preview.s3),
        ("dolp_percent", preview.dolp_percent),
    ];
    for (key, pair) in pairs {
        if let Some([lo, hi]) = pair {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(format!(
                    "render.preview.{key} = [{lo}, {hi}] must be two finite numbers, low < high"
                ));
            }
        }
    }
    if let Some([lo, hi]) = preview.percentiles {
        if lo < 0.0 || hi > 100.0 {
            return Err(format!(
                "render.preview.percentiles = [{lo}, {hi}] must lie within [0, 100]"
            ));
        }
    }
    Ok(preview.clone())
}

/// The `[render]` transport keys, checked.
fn transport_settings(render: &config::RenderConfig) -> Result<Transport, String> {
    if render.open_world {
        return Ok(Transport::OpenWorld);
    }
    if render.samples == 0 {
        return Err(
            "render.samples = 0: give at least 1 path per pixel (or open_world = true)".into(),
        );
    }
    if render.bounces > MAX_BOUNCES {
        return Err(format!(
            "render.bounces = {} is more than {MAX_BOUNCES}",
            render.bounces
        ));
    }
    Ok(Transport::Path(PathSettings {
        bounces: render.bounces,
        samples: render.samples,
        seed: render.seed,
    }))
}

/// Deeper chains change nothing measurable in thermal scenes (each bounce multiplies by a
/// reflectance well below 1) and only cost time.
const MAX_BOUNCES: u32 = 64;

/// The `[sun]` table: its direction (given, or from place and time) and band irradiance (given,
/// or τ Ω L_bb(5772 K) over the sensor band). A sun at or below the horizon is no sun.
fn resolve_sun(config: &config::SunConfig, band: &Band) -> Result<Option<Sun>, String> {
    let key = |key: &str, e: crate::emitter::SunError| format!("sun.{key}: {e}");
    let place = (config.latitude_deg, config.longitude_deg, &config.time_utc);
    let (elevation, azimuth) = match (config.elevation_deg, config.azimuth_deg, place) {
        (Some(e), Some(a), (None, None, None)) => (e, a),
        (None, None, (Some(latitude), Some(longitude), Some(time))) => {
            let time = parse_time_utc(time).map_err(|e| key("time_utc", e))?;
            let p = sun_position(latitude, longitude, &time)
                .map_err(|e| key("latitude_deg/longitude_deg", e))?;
            (p.elevation_deg, p.azimuth_deg)
        }
        _ => {
            return Err(
                "[sun] needs elevation_deg and azimuth_deg, or latitude_deg, \
                 longitude_deg and time_utc"
                    .into(),
            )
        }
    };
    validate_sun_angles(elevation, azimuth).map_err(|e| key("elevation_deg/azimuth_deg", e))?;
    let irradiance = sun_band_irradiance(config, band)?;
    if elevation <= 0.0 {
        return Ok(None);
    }
    Ok(Some(Sun {
        direction: sun_direction(elevation, azimuth),
        irradiance,
    }))
}

/// The sun's band irradiance on a surface facing it: given, or τ Ω L_bb(5772 K) over the band.
fn sun_band_irradiance(config: &config::SunConfig, band: &Band) -> Result<f64, String> {
    let key = |key: &str, e: crate::emitter::SunError| format!("sun.{key}: {e}");
    let transmittance = config.transmittance.unwrap_or(DEFAULT_SUN_TRANSMITTANCE);
    validate_transmittance(transmittance).map_err(|e| key("transmittance", e))?;
    match config.irradiance_w_m2 {
        Some(e) => {
            validate_irradiance(e).map_err(|err| key("irradiance_w_m2", err))?;
            Ok(e)
        }
        None => Ok(default_band_irradiance(band, transmittance)),
    }
}

/// Atmospheric transmittance of the default solar irradiance (a clear LWIR window).
const DEFAULT_SUN_TRANSMITTANCE: f64 = 0.8;

/// Loads an object's mesh, checks its parts against the scene, resolves part materials and
/// temperatures, and returns its world-space shading mesh.
fn build_object(
    object: &ObjectConfig,
    label: &str,
    object_index: usize,
    materials: &mut MaterialResolver,
    surfaces: &mut Vec<Surface>,
    thermal_start_air_k: Option<f64>,
    warnings: &mut Vec<String>,
) -> Result<ShadedMesh, SceneError> {
    let scene = materials.scene;
    let fail = |message: String| SceneError::new(scene, format!("{label}: {message}"));
    let (raw, mesh_file) = load_object_mesh(object, materials.dir).map_err(|e| match e {
        MeshLoadError::Scene(message) => fail(message),
        MeshLoadError::File(file, message) => {
            SceneError::new(&file, format!("{message} (in {label})"))
        }
    })?;
    let mesh_file_label = mesh_file
        .as_ref()
        .map_or("the shape".to_owned(), |f| f.display().to_string());
    warnings.extend(
        raw.notes
            .iter()
            .map(|note| format!("{mesh_file_label} (in {label}): {note}")),
    );
    let coldest = raw
        .vertex_temperatures
        .as_ref()
        .and_then(|t| t.iter().copied().reduce(f64::min));
    if let Some(t) = coldest.filter(|&t| t < CELSIUS_SUSPECT_K) {
        warnings.push(format!(
            "{mesh_file_label} (in {label}): per-vertex temperatures down to {} K look like °C \
             (temperatures are kelvin)",
            number(t)
        ));
    }

    let used = raw.used_parts();
    for part in object.parts.keys() {
        if !used.contains(&part.as_str()) {
            return Err(fail(format!(
                "part '{part}' is not in {mesh_file_label} (its parts: {})",
                used.join(", ")
            )));
        }
    }
    let has_vertex_temperatures = raw.vertex_temperatures.is_some();
    let check_temperature = |t: f64, what: &str| {
        if valid_temperature(t) {
            Ok(t)
        } else {
            Err(fail(format!(
                "{what}temperature_k = {} must be within [0, {MAX_TEMPERATURE_K}] K",
                number(t)
            )))
        }
    };
    if let Some(t) = object.temperature_k {
        check_temperature(t, "")?;
    }
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
            .or(thermal_start_air_k.filter(|_| thermal::part_thermal(object, part).is_some()));
        if let Some(t) = temperature {
            check_temperature(t, &format!("part '{part}': "))?;
            if has_vertex_temperatures {
                return Err(fail(format!(
                    "{mesh_file_label} has per-vertex temperatures; remove temperature_k \
                     (part '{part}') or the PLY property"
                )));
            }
        }
        part_temperature.push(temperature);
        let material_name = settings
            .and_then(|p| p.material.as_deref())
            .or(object.material.as_deref())
            .ok_or_else(|| {
                fail(format!(
                    "part '{part}' has no material (set material on the object or the part)"
                ))
            })?;
        let material = materials
            .resolve(material_name)
            .map_err(|e| fail(format!("part '{part}': {e}")))?;
        part_surface.push(surfaces.len() as u32);
        surfaces.push(Surface {
            object: object_index,
            part: part.clone(),
            material,
        });
    }

    if !(object.scale.is_finite() && object.scale > 0.0) {
        return Err(fail(format!(
            "scale = {} must be finite and > 0",
            object.scale
        )));
    }
    if !object
        .translate
        .iter()
        .chain(object.rotate_deg.iter())
        .all(|v| v.is_finite())
    {
        return Err(fail("translate and rotate_deg must be finite".into()));
    }
    let crease = object.crease_angle_deg;
    if !(crease.is_finite() && (0.0..=180.0).contains(&crease)) {
        return Err(fail(format!(
            "crease_angle_deg = {crease} must be within [0°, 180°]"
        )));
    }
    let setup = ObjectShading {
        transform: Transform::new(object.scale, object.rotate_deg, object.translate),
        crease_angle_deg: crease,
        part_temperature: &part_temperature,
        part_surface: &part_surface,
    };
    let (mesh, skipped) = mesh::shade_mesh(&raw, &setup).map_err(|message| match &mesh_file {
        Some(file) => SceneError::new(file, format!("{message} (in {label})")),
        None => fail(message),
    })?;
    warnings.extend(skipped.map(|w| format!("{mesh_file_label} (in {label}): {w}")));
    Ok(mesh)
}

enum MeshLoadError {
    /// The object entry itself is wrong.
    Scene(String),
    /// The mesh file is missing or malformed.
    File(PathBuf, String),
}

fn load_object_mesh(
    object: &ObjectConfig,
    dir: &Path,
) -> Result<(RawMesh, Option<PathBuf>), MeshLoadError> {
    match (&object.mesh, &object.shape) {
        (Some(_), Some(_)) => Err(MeshLoadError::Scene(
            "give either mesh or shape, not both".into(),
        )),
        (None, None) => Err(MeshLoadError::Scene("needs a mesh file or a shape".into())),
        (None, Some(shape)) => procedural_shape(shape)
            .map(|m| (m, None))
            .map_err(MeshLoadError::Scene),
        (Some(file), None) => {
            let path = dir.join(file);
            let file_error = |m: String| MeshLoadError::File(path.clone(), m);
            let bytes = std::fs::read(&path)
                .map_err(|e| file_error(format!("cannot read the mesh: {e}")))?;
            let extension = path
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase());
            let raw = match extension.as_deref() {
                Some("obj") => {
                    let text = String::from_utf8(bytes)
                        .map_err(|_| file_error("an OBJ file must be UTF-8 text".into()))?;
                    obj::parse_obj(&text)
                }
                Some("ply") => ply::parse_ply(&bytes),
                _ => {
                    return Err(file_error(
                        "unknown mesh format: the file name must end in .obj or .ply".into(),
                    ))
                }
            }
            .map_err(file_error)?;
            Ok((raw, Some(path)))
        }
    }
}

fn procedural_shape(shape: &ShapeConfig) -> Result<RawMesh, String> {
    match *shape {
        ShapeConfig::Sphere {
            radius,
            subdivisions,
        } => {
            if !(radius.is_finite() && radius > 0.0) {
                return Err(format!("shape.radius = {radius} must be finite and > 0"));
            }
            if subdivisions > 7 {
                return Err(format!(
                    "shape.subdivisions = {subdivisions} is too fine (at most 7: 327 680 faces)"
                ));
            }
            Ok(procedural::icosphere(radius, subdivisions))
        }
        ShapeConfig::Plane { size, divisions } => {
            if !size.iter().all(|s| s.is_finite() && *s > 0.0) {
                return Err("shape.size must be finite and > 0".into());
            }
            if !divisions.iter().all(|d| (1..=4096).contains(d)) {
                return Err("shape.divisions must be within 1…4096".into());
            }
            Ok(procedural::plane(size, divisions))
        }
    }
}

/// Resolves material references: an inline name, a file path (ends in .toml or has a /), or a
/// library name (`<library>/<name>.toml`). Each distinct material is loaded once.
struct MaterialResolver<'a> {
    scene: &'a Path,
    /// The sensor band spectral materials are integrated over.
    band: &'a Band,
    dir: &'a Path,
    library: PathBuf,
    inline: &'a std::collections::BTreeMap<String, InlineMaterialConfig>,
    resolved: Vec<SceneMaterial>,
    index_of: HashMap<String, usize>,
}

impl MaterialResolver<'_> {
    fn resolve(&mut self, reference: &str) -> Result<usize, String> {
        let (key, material) = if let Some(inline) = self.inline.get(reference) {
            let key = format!("inline:{reference}");
            if let Some(&i) = self.index_of.get(&key) {
                return Ok(i);
            }
            let pbrdf = inline_pbrdf(inline)
                .map_err(|e| format!("inline material [materials.{reference}]: {e}"))?;
            (
                key,
                SceneMaterial {
                    name: reference.to_owned(),
                    origin: "inline".into(),
                    optics: MaterialOptics::Grey(pbrdf),
                    wavelength_um: None,
                    spectral_model: None,
                },
            )
        } else {
            let path = if reference.ends_with(".toml") || reference.contains('/') {
                self.dir.join(reference)
            } else {
                crate::material::find_material(&self.library, reference).map_err(|e| {
                    format!(
                        "{e}; define it inline under [materials.{reference}] in {} or set \
                         material_library",
                        self.scene.display()
                    )
                })?
            };
            let key = format!("file:{}", path.display());
            if let Some(&i) = self.index_of.get(&key) {
                return Ok(i);
            }
            let loaded = Material::load(&path).map_err(|e| e.to_string())?;
            let material = self
                .library_material(reference, &path, &loaded)
                .map_err(|e| format!("material '{reference}' ({}): {e}", path.display()))?;
            (key, material)
        };
        self.resolved.push(material);
        self.index_of.insert(key, self.resolved.len() - 1);
        Ok(self.resolved.len() - 1)
    }
}

impl MaterialResolver<'_> {
    /// A material from the library or a file: grey, or spectral and integrated over the band's
    /// wavelength nodes (refused when its table does not span the band).
    fn library_material(
        &self,
        reference: &str,
        path: &Path,
        loaded: &Material,
    ) -> Result<SceneMaterial, String> {
        let (optics, wavelength_um, spectral_model) = match &loaded.model {
            MaterialModel::Grey(model) => (
                MaterialOptics::Grey(model.pbrdf().map_err(|e| e.to_string())?),
                Some(model.wavelength_um),
                None,
            ),
            MaterialModel::Spectral(model) => (
                MaterialOptics::Band(model.band_pbrdf(self.band).map_err(|e| e.to_string())?),
                None,
                Some(model.clone()),
            ),
        };
        Ok(SceneMaterial {
            name: reference.to_owned(),
            origin: path.display().to_string(),
            optics,
            wavelength_um,
            spectral_model,
        })
    }
}

fn inline_pbrdf(m: &InlineMaterialConfig) -> Result<Pbrdf, String> {
    let distribution = match (m.distribution.as_str(), m.q) {
        ("cauchy", Some(q)) => SlopeDistribution::Cauchy { sigma: m.sigma, q },
        ("cauchy", None) => return Err("distribution cauchy needs q".into()),
        ("gaussian", None) => SlopeDistribution::Gaussian { sigma: m.sigma },
        ("gaussian", Some(_)) => return Err("distribution gaussian takes no q".into()),
        (other, _) => {
            return Err(format!(
                "distribution '{other}' is unknown (cauchy or gaussian)"
            ))
        }
    };
    Pbrdf::new(
        distribution,
        m.shadowing,
        RefractiveIndex::new(m.n, m.k),
        m.rho_d,
    )
    .map_err(|e| e.to_string())
}
