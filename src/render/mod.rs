//! LWIR polarimetric rendering of a scene held in memory (docs/design.md §1.5–1.7, §2.3): primary
//! visibility by z-buffered rasterization ([`raster`]), the Stokes vector leaving each visible
//! point from the scene's integrator ([`crate::transport`]), Gouraud or per-pixel shading, then
//! the atmosphere ([`atmosphere_path`]), the instrument ([`instrument`]) and its noise
//! ([`detector_noise`]) onto the [`film`]. Nothing here writes files
//! (that is [`crate::output`]) or prints (progress goes to a [`Progress`] callback).

pub mod atmosphere_path;
pub mod detector_noise;
pub mod dofp;
pub mod film;
pub mod instrument;
pub mod raster;

use crate::pbrdf::{MaterialOptics, ModelError};
use crate::progress::Progress;
use crate::scene::config::Shading;
use crate::scene::mesh::bounding_diagonal;
use crate::scene::mesh::SurfaceHit;
use crate::scene::{Scene, SceneError, Transport};
use crate::transport::accel::Accelerator;
use crate::transport::kernel::KernelQuadrature;
use crate::transport::open_world::OpenWorld;
use crate::transport::path::{PathTracer, Vertex};
/// Grid sizes of a material's reflection table, as [`Rendered::table_resolutions`] reports them.
pub use crate::transport::tables::TableResolution;
use crate::transport::tables::{MaterialTables, RadianceTable};
use atmosphere_path::through_atmosphere;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use raster::{rasterize, FragmentBuffer, NO_TRIANGLE};
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

pub use film::{StokesImage, SurfaceTruth, BACKGROUND};

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{scene}: material '{material}' ({origin}): {source}")]
    Material {
        scene: PathBuf,
        material: String,
        origin: String,
        source: ModelError,
    },
    #[error("{}: cannot write: {source}", crate::text::path(path))]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// Wall-clock seconds of each stage.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Timings {
    pub load: f64,
    pub tables: f64,
    pub raster: f64,
    pub shade: f64,
    /// The camera: optics, detector, DoFP array, metrics.
    pub camera: f64,
    pub write: f64,
    pub total: f64,
}

/// A render held in memory, before anything is written.
pub struct Rendered {
    pub image: StokesImage,
    /// With `[sensor.dofp]`: the raw mosaic and the Stokes images demosaicked from it.
    pub dofp: Option<instrument::DofpImages>,
    /// Reconstruction quality of the camera against the noise-free radiance (`None` for the
    /// ideal camera).
    pub camera_metrics: Option<instrument::metrics::CameraMetrics>,
    pub timings: Timings,
    pub table_resolutions: Vec<TableResolution>,
}

/// The reflection tables of a scene's materials: built from its materials, environment, sensor
/// band and surface temperature range, not from its camera, so that renders of one scene from
/// several viewpoints can share them ([`render_with_tables`]; the Python sweeps do).
pub struct SceneTables {
    /// What the tables were built from, [`table_inputs`].
    inputs: String,
    tables: MaterialTableSet,
}

/// The tables themselves, as one render builds and uses them.
struct MaterialTableSet {
    tables: Vec<MaterialTables>,
    resolutions: Vec<TableResolution>,
}

impl MaterialTableSet {
    fn build(scene: &Scene) -> Result<MaterialTableSet, RenderError> {
        let (tables, resolutions) = material_tables(scene, surface_temperature_range(scene))?;
        Ok(MaterialTableSet {
            tables,
            resolutions,
        })
    }
}

impl SceneTables {
    pub fn build(scene: &Scene) -> Result<SceneTables, RenderError> {
        // Read before the build, which may fill a model's lazily built tables (part of its Debug).
        let inputs = table_inputs(scene);
        Ok(SceneTables {
            inputs,
            tables: MaterialTableSet::build(scene)?,
        })
    }

    /// Whether these are the tables of `scene` (freshly loaded, as the one they were built for):
    /// built from equal inputs, every number compared exactly.
    pub fn built_for(&self, scene: &Scene) -> bool {
        self.inputs == table_inputs(scene)
    }
}

/// Everything [`material_tables`] reads of a scene, as text: the derived `Debug` of each value,
/// which prints every field and every float exactly (shortest round-trip form).
fn table_inputs(scene: &Scene) -> String {
    let optics: Vec<_> = scene.materials.iter().map(|m| &m.optics).collect();
    let (t_lo, t_hi) = surface_temperature_range(scene);
    format!(
        "{optics:?}\n{:?}\n{:?}\n{:?}",
        scene.environment,
        scene.sensor.band,
        (t_lo.to_bits(), t_hi.to_bits())
    )
}

/// The lowest and highest vertex temperature (K).
fn surface_temperature_range(scene: &Scene) -> (f64, f64) {
    let (t_lo, t_hi) = scene
        .mesh
        .temperatures
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &t| {
            (lo.min(t), hi.max(t))
        });
    (t_lo.min(t_hi), t_hi.max(t_lo))
}

/// Renders a loaded scene in memory, reporting progress (raster tiles, then image rows) to
/// `progress`.
pub fn render(scene: &Scene, progress: &dyn Progress) -> Result<Rendered, RenderError> {
    let start = Instant::now();
    // No sharing key here: a render that builds its own tables never compares them.
    let tables = MaterialTableSet::build(scene)?;
    render_from(scene, &tables, start, progress)
}

/// [`render`] with `tables` built by [`SceneTables::build`] for this scene or one that differs
/// from it only in its camera: the same images bit for bit, without building the tables again.
pub fn render_with_tables(
    scene: &Scene,
    tables: &SceneTables,
    progress: &dyn Progress,
) -> Result<Rendered, RenderError> {
    render_from(scene, &tables.tables, Instant::now(), progress)
}

/// [`render`] with its tables, its timings counted from `start`.
fn render_from(
    scene: &Scene,
    tables: &MaterialTableSet,
    start: Instant,
    progress: &dyn Progress,
) -> Result<Rendered, RenderError> {
    let mut timings = Timings::default();
    let mesh = &scene.mesh;
    let temperatures = surface_temperature_range(scene);
    let radiance = RadianceTable::new(&scene.sensor.band, temperatures.0, temperatures.1);
    timings.tables = start.elapsed().as_secs_f64();

    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let tiles = w.div_ceil(raster::TILE) * h.div_ceil(raster::TILE);
    progress.begin("rendering", (tiles + h) as u64);
    let tick = || progress.advance(1);
    let raster_start = Instant::now();
    // Near plane: far below any scene detail, far above f64 depth resolution.
    let near = (1e-5 * bounding_diagonal(&mesh.positions)).max(1e-9);
    let fragments = rasterize(&scene.camera, &mesh.positions, &mesh.triangles, near, &tick);
    timings.raster = raster_start.elapsed().as_secs_f64();

    let shade_start = Instant::now();
    let open_world = OpenWorld {
        tables: &tables.tables,
        radiance: &radiance,
    };
    let accel;
    let tracer = match scene.transport {
        Transport::OpenWorld => None,
        Transport::Path(settings) => {
            accel = Accelerator::new(mesh, bounding_diagonal(&mesh.positions));
            Some(PathTracer::new(scene, &open_world, &accel, settings))
        }
    };
    let mut image = shade_image(scene, &open_world, tracer.as_ref(), &fragments, &tick);
    progress.end();
    timings.shade = shade_start.elapsed().as_secs_f64();
    let camera_start = Instant::now();
    let recording = instrument::record(&scene.sensor, image.width, image.height, &mut image.stokes);
    image.recorded_polarizers = recording.polarizers;
    timings.camera = camera_start.elapsed().as_secs_f64();
    timings.total = start.elapsed().as_secs_f64();
    Ok(Rendered {
        image,
        dofp: recording.dofp,
        camera_metrics: recording.metrics,
        timings,
        table_resolutions: tables.resolutions.clone(),
    })
}

/// The open-world tables of every material, at resolutions suited to each lobe; band materials'
/// emissivity over the scene's surface temperatures `temperatures_k` (min, max).
fn material_tables(
    scene: &Scene,
    temperatures_k: (f64, f64),
) -> Result<(Vec<MaterialTables>, Vec<TableResolution>), RenderError> {
    let quadrature = KernelQuadrature::default();
    let resolutions: Vec<TableResolution> = scene
        .materials
        .iter()
        .map(|m| TableResolution::for_material(m.optics.sampling_pbrdf()))
        .collect();
    let tables = scene
        .materials
        .iter()
        .zip(&resolutions)
        .map(|(m, &resolution)| {
            let environment = &scene.environment;
            match &m.optics {
                MaterialOptics::Grey(pbrdf) => {
                    MaterialTables::build(pbrdf, environment, resolution, &quadrature)
                }
                MaterialOptics::Band(band) => MaterialTables::build_band(
                    band,
                    environment,
                    &scene.sensor.band,
                    temperatures_k,
                    resolution,
                    &quadrature,
                ),
            }
            .map_err(|source| RenderError::Material {
                scene: scene.path.clone(),
                material: m.name.clone(),
                origin: m.origin.clone(),
                source,
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((tables, resolutions))
}

/// Gouraud shading: Stokes vectors at the vertices, in the pixel frame of each vertex's own ray.
/// A vertex is shaded from its front: one just past a silhouette reads grazing.
fn vertex_stokes(scene: &Scene, open_world: &OpenWorld) -> Vec<[f64; 4]> {
    let mesh = &scene.mesh;
    let mut vertex_material = vec![0usize; mesh.positions.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            vertex_material[v as usize] = scene.triangle_material(t);
        }
    }
    (0..mesh.positions.len())
        .into_par_iter()
        .map(|v| {
            open_world.toward_camera(
                &scene.camera,
                vertex_material[v],
                &mesh.positions[v],
                &mesh.normals[v],
                mesh.temperatures[v],
            )
        })
        .collect()
}

/// What shading a pixel needs besides the pixel itself.
struct PixelShader<'a> {
    scene: &'a Scene,
    open_world: &'a OpenWorld<'a>,
    tracer: Option<&'a PathTracer<'a>>,
    /// Gouraud: the open-world Stokes vector at each vertex (empty for per-pixel shading).
    vertex_stokes: Vec<[f64; 4]>,
}

impl PixelShader<'_> {
    /// (Stokes, standard error, ground truth) of the visible point at barycentric (b1, b2) of
    /// triangle `t`, through the atmosphere; `pixel` indexes the pixel's random stream.
    fn shade(&self, t: usize, b1: f64, b2: f64, pixel: u64) -> ([f64; 4], [f64; 4], SurfaceTruth) {
        let scene = self.scene;
        let hit = scene.mesh.interpolate(t, b1, b2);
        let to_camera = scene.camera.position - hit.point;
        let seen = Vertex::seen_from(hit, &to_camera.normalize()).normal;
        let truth = SurfaceTruth {
            depth_m: scene.camera.to_view(&hit.point).z as f32,
            normal: [seen.x as f32, seen.y as f32, seen.z as f32],
            temperature_k: hit.temperature as f32,
        };
        let (mut s, mut error) = match self.tracer {
            None => (self.open_world_value(t, &hit, &to_camera), [0.0; 4]),
            Some(tracer) => {
                let omega = to_camera.normalize();
                let vertex = Vertex::seen_from(hit, &omega);
                let mut rng = ChaCha8Rng::seed_from_u64(tracer.settings.seed);
                rng.set_stream(pixel);
                let e = tracer.estimate(&vertex, &omega, &scene.camera.right, &mut rng);
                let base = match scene.shading {
                    Shading::Pixel => e.open_world,
                    Shading::Gouraud => self.open_world_value(t, &hit, &to_camera).into(),
                };
                let total = base + e.correction;
                (total.into(), e.standard_error.into())
            }
        };
        if let Some(atmosphere) = &scene.atmosphere {
            (s, error) = through_atmosphere(s, error, to_camera.norm(), atmosphere);
        }
        (s, error, truth)
    }

    /// The open-world value: Gouraud-interpolated from the vertices, or shaded at the point.
    fn open_world_value(&self, t: usize, hit: &SurfaceHit, to_camera: &Vector3<f64>) -> [f64; 4] {
        let scene = self.scene;
        match scene.shading {
            Shading::Gouraud => {
                let [a, b, c] = scene.mesh.triangles[t].map(|v| self.vertex_stokes[v as usize]);
                let [b0, b1, b2] = hit.barycentric;
                [0, 1, 2, 3].map(|j| a[j] * b0 + b[j] * b1 + c[j] * b2)
            }
            Shading::Pixel => {
                let vertex = Vertex::seen_from(*hit, to_camera);
                self.open_world.toward_camera(
                    &scene.camera,
                    scene.triangle_material(t),
                    &hit.point,
                    &vertex.normal,
                    hit.temperature,
                )
            }
        }
    }
}

/// Shades every pixel (per-pixel or Gouraud), adds the background and the atmosphere: the
/// radiance the camera receives.
fn shade_image(
    scene: &Scene,
    open_world: &OpenWorld,
    tracer: Option<&PathTracer>,
    fragments: &FragmentBuffer,
    tick: &(dyn Fn() + Sync),
) -> StokesImage {
    let (width, height) = (fragments.width, fragments.height);
    let shader = PixelShader {
        scene,
        open_world,
        tracer,
        vertex_stokes: match scene.shading {
            Shading::Pixel => Vec::new(),
            Shading::Gouraud => vertex_stokes(scene, open_world),
        },
    };
    let mut stokes = vec![[0.0f64; 4]; width * height];
    let mut standard_error = vec![[0.0f64; 4]; width * height];
    let mut surface = vec![BACKGROUND; width * height];
    let mut truth = vec![SurfaceTruth::default(); width * height];
    stokes
        .par_chunks_mut(width)
        .zip(standard_error.par_chunks_mut(width))
        .zip(surface.par_chunks_mut(width))
        .zip(truth.par_chunks_mut(width))
        .enumerate()
        .for_each(|(y, (((row, row_error), row_surface), row_truth))| {
            for x in 0..width {
                let fragment = fragments.fragments[y * width + x];
                if fragment.triangle == NO_TRIANGLE {
                    // The sky or ground of the environment model, seen directly.
                    let ray = scene.camera.ray_direction(x as f64 + 0.5, y as f64 + 0.5);
                    row[x] = [scene.environment.radiance(&ray), 0.0, 0.0, 0.0];
                    continue;
                }
                let t = fragment.triangle as usize;
                let pixel = (y * width + x) as u64;
                (row[x], row_error[x], row_truth[x]) =
                    shader.shade(t, fragment.b1 as f64, fragment.b2 as f64, pixel);
                row_surface[x] = scene.mesh.triangle_surface[t];
            }
            tick();
        });
    StokesImage {
        width,
        height,
        stokes,
        standard_error,
        surface,
        truth,
        recorded_polarizers: Vec::new(),
    }
}
