//! The scene TOML as written by the user (docs/design.md §2.3), before paths, meshes and materials are
//! resolved. Every table refuses unknown keys so that a typo is an error, not a silent default.
//!
//! ```toml
//! material_library = "../fits"        # optional; default "fits" next to the scene file
//!
//! [camera]
//! position = [6.0, -7.0, 2.2]         # metres, world frame, z up
//! look_at = [0.0, 0.0, 0.7]
//! up = [0.0, 0.0, 1.0]                # optional, default +z
//! fov_deg = 35.0                      # vertical field of view
//! resolution = [640, 480]             # width, height in pixels
//!
//! [sensor]                            # optional
//! band_um = [8.0, 14.0]
//! response = [[8.0, 0.5], [10.0, 1.0], [14.0, 0.5]]   # optional (µm, relative response)
//! netd_mk = 30.0                      # 0 = noise free
//! seed = 1
//! netd_reference_k = 300.0            # optional: where dL/dT is taken; default the air temperature
//!
//! [environment]
//! air_temperature_k = 283.15
//! sky = { model = "window", zenith_emissivity = 0.75 }
//! # sky = { model = "table", elevation_deg = [0, 10, 90], brightness_temperature_k = [283, 270, 240] }
//! # sky = { model = "table", elevation_deg = [0, 90], radiance = [30.0, 12.0] }
//! ground = { temperature_k = 288.0, emissivity = 0.95 }
//!
//! [atmosphere]                        # optional: S_sensor = τS + (1−τ) L_bb(T_air) δ_j0
//! extinction_per_km = 0.2             # τ = exp(−β·range)
//! # table = "path.csv"                # or a radiative-transfer table (docs/design.md §2.9)
//!
//! [render]                            # optional
//! shading = "pixel"                   # or "gouraud"
//! aop_mask_dolp = 0.002               # AoP preview masked where DoLP is below this
//! bounces = 3                         # surface hits followed (occlusion, inter-reflection)
//! samples = 16                        # paths per pixel for the occluded correction
//! first_bounce_samples = 1            # lobe samples per path at the visible point
//! seed = 1
//! open_world = false                  # true: the paper's model (no occlusion, no sun)
//!
//! [sun]                               # optional
//! elevation_deg = 35.0                # or: latitude_deg, longitude_deg, time_utc = "…Z"
//! azimuth_deg = 200.0                 # clockwise from north (+y) toward east (+x)
//! irradiance_w_m2 = 1.6               # optional band irradiance; default τ Ω L_bb(5772 K)
//! transmittance = 0.8                 # τ for the default
//!
//! [materials.asphalt]                 # inline materials, referred to by name
//! distribution = "cauchy"
//! sigma = 0.5
//! q = 2.0
//! n = 1.6
//! k = 0.1
//! rho_d = 0.05
//! shadowing = "smith"
//!
//! [[objects]]
//! name = "car"
//! mesh = "car.obj"                    # OBJ (groups are parts) or PLY (per-vertex temperature)
//! material = "paper_paint"            # default for parts not listed below
//! temperature_k = 290.0
//! translate = [0.0, 0.0, 0.0]         # transform: scale, then rotate x, y, z, then translate
//! rotate_deg = [0.0, 0.0, 0.0]
//! scale = 1.0
//! [objects.parts.hood]
//! temperature_k = 320.0
//! ```

pub use crate::emitter::SunConfig;
pub use crate::material::InlineMaterialConfig;
pub use crate::thermal::config::{
    BackConfig, BackKeyword, ConvectiveBack, EnclosureConfig, FixedBack, GeneratedWeather,
    InternalHeatConfig, LayerMaterialConfig, PartThermalConfig, ThermalConfig, WeatherConfig,
};
use crate::toml_table::{optional_table, table, table_list, table_map, table_or_flag};
use serde::{Deserialize, Deserializer};
use std::collections::BTreeMap;

/// A fixed-length array that refuses any other length (serde's arrays let the TOML reader drop
/// extra items: `look_at = [0, 0, 1, 9]` was silently read as three numbers).
fn exactly<'de, D, T, const N: usize>(deserializer: D) -> Result<[T; N], D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let items = Vec::<T>::deserialize(deserializer)?;
    let len = items.len();
    items
        .try_into()
        .map_err(|_| serde::de::Error::invalid_length(len, &format!("{N} numbers").as_str()))
}

/// An optional list of (x, y) pairs, each exactly two numbers.
fn optional_pairs<'de, D>(deserializer: D) -> Result<Option<Vec<[f64; 2]>>, D::Error>
where
    D: Deserializer<'de>,
{
    let rows = Vec::<Vec<f64>>::deserialize(deserializer)?;
    rows.into_iter()
        .map(|row| {
            let len = row.len();
            row.try_into().map_err(|_| {
                serde::de::Error::invalid_length(len, &"a pair [wavelength_um, response]")
            })
        })
        .collect::<Result<Vec<[f64; 2]>, _>>()
        .map(Some)
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneConfig {
    /// Folder of the material library (names resolve to `<dir>/<name>.toml`), relative to the
    /// scene file; default `fits`.
    pub material_library: Option<String>,
    #[serde(deserialize_with = "table")]
    pub camera: CameraConfig,
    #[serde(default, deserialize_with = "table")]
    pub sensor: SensorConfig,
    #[serde(deserialize_with = "table")]
    pub environment: EnvironmentConfig,
    #[serde(default, deserialize_with = "optional_table")]
    pub atmosphere: Option<AtmosphereConfig>,
    #[serde(default, deserialize_with = "table")]
    pub render: RenderConfig,
    #[serde(default, deserialize_with = "optional_table")]
    pub sun: Option<SunConfig>,
    /// Temperatures from the thermal model (docs/design.md §1.8, §2.4) instead of typed in.
    #[serde(default, deserialize_with = "optional_table")]
    pub thermal: Option<ThermalConfig>,
    /// Inline material definitions by name.
    #[serde(default, deserialize_with = "table_map")]
    pub materials: BTreeMap<String, InlineMaterialConfig>,
    #[serde(default, deserialize_with = "table_list")]
    pub objects: Vec<ObjectConfig>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraConfig {
    #[serde(deserialize_with = "exactly")]
    pub position: [f64; 3],
    #[serde(deserialize_with = "exactly")]
    pub look_at: [f64; 3],
    #[serde(default = "world_up", deserialize_with = "exactly")]
    pub up: [f64; 3],
    pub fov_deg: f64,
    #[serde(deserialize_with = "exactly")]
    pub resolution: [u32; 2],
}

fn world_up() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorConfig {
    #[serde(default = "lwir_band", deserialize_with = "exactly")]
    pub band_um: [f64; 2],
    /// Spectral response (wavelength µm, relative response), piecewise linear.
    #[serde(default, deserialize_with = "optional_pairs")]
    pub response: Option<Vec<[f64; 2]>>,
    /// Noise-equivalent temperature difference of each polarizer image, mK; 0 = no noise.
    #[serde(default)]
    pub netd_mk: f64,
    #[serde(default)]
    pub seed: u64,
    /// Temperature at which NETD is converted to radiance (dL/dT); default the air temperature.
    pub netd_reference_k: Option<f64>,
    /// `[sensor.optics]`: the lens and the pixel aperture (docs/design.md §1.11); none = point samples.
    #[serde(default, deserialize_with = "optional_table")]
    pub optics: Option<OpticsConfig>,
    /// `[sensor.detector]`: fixed-pattern noise and quantization; none = an ideal detector.
    #[serde(default, deserialize_with = "optional_table")]
    pub detector: Option<DetectorConfig>,
    /// `[sensor.dofp]` (or `dofp = true`, an ideal one): also write the raw division-of-focal-plane
    /// mosaic and the Stokes images demosaicked from it.
    #[serde(default, deserialize_with = "table_or_flag")]
    pub dofp: Option<DofpConfig>,
}

/// `[sensor.optics]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OpticsConfig {
    /// Diffraction of a circular aperture; none = no diffraction.
    pub f_number: Option<f64>,
    /// Pixel pitch (µm): the scale of the diffraction pattern in pixels; needed with `f_number`.
    pub pixel_pitch_um: Option<f64>,
    /// The pixel's square aperture as a fraction of its area (0 = point samples).
    #[serde(default = "one")]
    pub fill_factor: f64,
    /// Gaussian blur (defocus, jitter), σ in pixels.
    #[serde(default)]
    pub blur_sigma_px: f64,
}

fn one() -> f64 {
    1.0
}

/// `[sensor.detector]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DetectorConfig {
    /// Residual gain non-uniformity after NUC, a fraction (σ of the per-pixel gain).
    #[serde(default)]
    pub fpn_gain_sigma: f64,
    /// Residual offset non-uniformity, mK at `netd_reference_k` (σ of the per-pixel offset).
    #[serde(default)]
    pub fpn_offset_mk: f64,
    /// Quantization to this many bits over `range_k`; 0 = none.
    #[serde(default)]
    pub bits: u32,
    /// The scene temperatures (K) that map to the first and last digital number.
    #[serde(default = "detector_range_k", deserialize_with = "exactly")]
    pub range_k: [f64; 2],
}

fn detector_range_k() -> [f64; 2] {
    [250.0, 350.0]
}

/// `[sensor.dofp]` as written; `Default` is the ideal camera of `dofp = true`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DofpConfig {
    /// Each pixel polarizer's extinction ratio; none (or `inf`) = a perfect polarizer.
    pub extinction_ratio: Option<f64>,
    /// σ of each pixel polarizer's orientation error (degrees), fixed per seed.
    #[serde(default)]
    pub orientation_sigma_deg: f64,
    /// Fraction of a pixel's signal recorded by each of its four neighbours.
    #[serde(default)]
    pub crosstalk: f64,
    /// "bilinear", "newton" or "residual".
    #[serde(default = "bilinear")]
    pub demosaic: String,
    /// Reconstruct the Stokes images with the known diattenuation and orientations.
    #[serde(default = "yes")]
    pub calibrated: bool,
}

fn bilinear() -> String {
    "bilinear".into()
}

fn yes() -> bool {
    true
}

impl Default for DofpConfig {
    fn default() -> Self {
        DofpConfig {
            extinction_ratio: None,
            orientation_sigma_deg: 0.0,
            crosstalk: 0.0,
            demosaic: bilinear(),
            calibrated: true,
        }
    }
}

fn lwir_band() -> [f64; 2] {
    [8.0, 14.0]
}

impl Default for SensorConfig {
    fn default() -> Self {
        SensorConfig {
            band_um: lwir_band(),
            response: None,
            netd_mk: 0.0,
            seed: 0,
            netd_reference_k: None,
            optics: None,
            detector: None,
            dofp: None,
        }
    }
}

#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentConfig {
    pub air_temperature_k: f64,
    #[serde(deserialize_with = "table")]
    pub sky: SkyConfig,
    #[serde(deserialize_with = "table")]
    pub ground: GroundConfig,
}

#[derive(Debug, Deserialize, Clone)]
#[serde(tag = "model", rename_all = "lowercase", deny_unknown_fields)]
pub enum SkyConfig {
    /// Clear-sky window model ε_sky(θ_z) = 1 − (1 − ε_zenith)^(1/cos θ_z) (docs/design.md §1.5).
    Window { zenith_emissivity: f64 },
    /// A user table over elevation (degrees, 0 = horizon, 90 = zenith), in radiance
    /// (W·m⁻²·sr⁻¹, band-integrated) or in brightness temperature (K); linear in between.
    Table {
        elevation_deg: Vec<f64>,
        radiance: Option<Vec<f64>>,
        brightness_temperature_k: Option<Vec<f64>>,
    },
}

#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct GroundConfig {
    /// The ground's temperature; with `thermal`, its starting state.
    pub temperature_k: f64,
    pub emissivity: f64,
    /// With `[thermal]`: the ground below the horizon is a surface of its own, solved with the
    /// run (horizontal, unshadowed, the same weather), its stack and surface as a part's.
    #[serde(default, deserialize_with = "optional_table")]
    pub thermal: Option<PartThermalConfig>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtmosphereConfig {
    /// Extinction coefficient β (per km); τ = exp(−β·range). This or `table`.
    pub extinction_per_km: Option<f64>,
    /// Path temperature of `extinction_per_km`; default the air temperature.
    pub temperature_k: Option<f64>,
    /// A radiative-transfer table (CSV, relative to the scene file; docs/design.md §2.9).
    pub table: Option<String>,
}

#[derive(Debug, Deserialize, Default, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Shading {
    /// Stokes vectors at the vertices, interpolated over triangles (the paper's Gouraud shading).
    Gouraud,
    /// Stokes vectors at every pixel from the interpolated normal and temperature.
    #[default]
    Pixel,
}

impl Shading {
    /// The shading in words, as captions and the command line's summary print it.
    pub fn describe(self) -> &'static str {
        match self {
            Shading::Pixel => "per-pixel",
            Shading::Gouraud => "Gouraud",
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderConfig {
    #[serde(default)]
    pub shading: Shading,
    #[serde(default = "default_aop_mask")]
    pub aop_mask_dolp: f64,
    /// Surface hits followed by the path integrator (docs/design.md §1.7, §2.4).
    #[serde(default = "default_bounces")]
    pub bounces: u32,
    /// Paths per pixel for the occluded correction.
    #[serde(default = "default_samples")]
    pub samples: u32,
    /// Lobe samples per path at the visible point (1: no split; docs/design.md §1.7).
    #[serde(default = "default_first_bounce_samples")]
    pub first_bounce_samples: u32,
    #[serde(default = "default_render_seed")]
    pub seed: u64,
    /// The paper's model (no occlusion, no sun): today's images exactly.
    #[serde(default)]
    pub open_world: bool,
    /// `[render.preview]`: colour ranges and maps of the PNG previews.
    #[serde(default, deserialize_with = "table")]
    pub preview: PreviewConfig,
}

/// `[render.preview]`: how the PNG previews map values to colours. The data
/// files (TIFF, EXR) are never affected.
#[derive(Debug, Deserialize, Clone, Default, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PreviewConfig {
    /// `"percentile"` (default: the 0.1th–99.9th percentiles over object pixels, or
    /// `percentiles`) or `"minmax"` (the full range of the object pixels, nothing clipped).
    #[serde(default)]
    pub range: PreviewRange,
    /// [low, high] percentiles of the `"percentile"` range; default [0.1, 99.9].
    #[serde(default, deserialize_with = "optional_pair")]
    pub percentiles: Option<[f64; 2]>,
    /// Fixed ranges, overriding `range` for their panel: apparent temperature (K), S1, S2, S3
    /// (W m⁻² sr⁻¹), DoLP (%).
    #[serde(default, deserialize_with = "optional_pair")]
    pub s0_k: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "optional_pair")]
    pub s1: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "optional_pair")]
    pub s2: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "optional_pair")]
    pub s3: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "optional_pair")]
    pub dolp_percent: Option<[f64; 2]>,
    /// Colour map of the S0 panel: `"thermal"` (default) or `"gray"` (white hot).
    #[serde(default)]
    pub s0_colormap: S0Colormap,
}

#[derive(Debug, Deserialize, Clone, Copy, Default, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum PreviewRange {
    #[default]
    Percentile,
    Minmax,
}

#[derive(Debug, Deserialize, Clone, Copy, Default, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum S0Colormap {
    #[default]
    Thermal,
    Gray,
}

/// An optional `[low, high]` pair, exactly two numbers.
fn optional_pair<'de, D>(deserializer: D) -> Result<Option<[f64; 2]>, D::Error>
where
    D: Deserializer<'de>,
{
    exactly(deserializer).map(Some)
}

fn default_bounces() -> u32 {
    3
}

fn default_samples() -> u32 {
    16
}

fn default_first_bounce_samples() -> u32 {
    1
}

fn default_render_seed() -> u64 {
    1
}

fn default_aop_mask() -> f64 {
    0.002
}

impl Default for RenderConfig {
    fn default() -> Self {
        RenderConfig {
            shading: Shading::default(),
            aop_mask_dolp: default_aop_mask(),
            bounces: default_bounces(),
            samples: default_samples(),
            first_bounce_samples: default_first_bounce_samples(),
            seed: default_render_seed(),
            open_world: false,
            preview: PreviewConfig::default(),
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectConfig {
    pub name: Option<String>,
    /// OBJ or PLY file, relative to the scene file. Exactly one of `mesh` and `shape`.
    pub mesh: Option<String>,
    #[serde(default, deserialize_with = "optional_table")]
    pub shape: Option<ShapeConfig>,
    /// Default material and temperature of every part not listed in `parts`.
    pub material: Option<String>,
    pub temperature_k: Option<f64>,
    #[serde(default, deserialize_with = "exactly")]
    pub translate: [f64; 3],
    #[serde(default, deserialize_with = "exactly")]
    pub rotate_deg: [f64; 3],
    #[serde(default = "unit_scale")]
    pub scale: f64,
    /// Normals of faces meeting at less than this angle are averaged (meshes without `vn`).
    #[serde(default = "default_crease")]
    pub crease_angle_deg: f64,
    #[serde(default, deserialize_with = "table_map")]
    pub parts: BTreeMap<String, PartConfig>,
    /// Thermal stack of every part that has none of its own (§2.4 `[objects.thermal]`).
    #[serde(default, deserialize_with = "optional_table")]
    pub thermal: Option<PartThermalConfig>,
}

fn unit_scale() -> f64 {
    1.0
}

fn default_crease() -> f64 {
    35.0
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartConfig {
    pub material: Option<String>,
    pub temperature_k: Option<f64>,
    /// With `[thermal]`: this part's temperatures come from the model (§2.4).
    #[serde(default, deserialize_with = "optional_table")]
    pub thermal: Option<PartThermalConfig>,
}

/// Procedural test objects (one part named `surface`), centred at the object origin.
#[derive(Debug, Deserialize, Clone)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum ShapeConfig {
    /// Icosphere: the icosahedron subdivided `subdivisions` times (20·4^n faces), smooth normals.
    Sphere { radius: f64, subdivisions: u32 },
    /// Square grid in the xy plane facing +z, `size` metres wide, `divisions` cells a side.
    Plane {
        #[serde(deserialize_with = "exactly")]
        size: [f64; 2],
        #[serde(deserialize_with = "exactly")]
        divisions: [u32; 2],
    },
    /// A random heightfield tile over the `size` plane (docs/scenes.md, `scene::terrain`): its
    /// rms height, correlation length, optional Hurst exponent (von Kármán, else Gaussian) and
    /// seed.
    Terrain {
        #[serde(deserialize_with = "exactly")]
        size: [f64; 2],
        #[serde(deserialize_with = "exactly")]
        divisions: [u32; 2],
        rms_height_m: f64,
        correlation_length_m: f64,
        hurst: Option<f64>,
        #[serde(default)]
        seed: u64,
    },
}
