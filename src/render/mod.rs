//! LWIR polarimetric rendering of a scene (DESIGN §1.5–1.6, §2.3, §4 `irpol render`):
//! per-material emissivity and reflected-environment tables, z-buffered rasterization, Gouraud or
//! per-pixel shading, the atmosphere and detector noise, and the output files (32-bit float TIFF
//! per channel, a multi-channel EXR, PNG previews with colour bars, a composite figure and a JSON
//! summary), all written only after the whole render succeeded, each atomically.
//!
//! Entry points: [`render_scene`] (file in, files out) and [`render`] (scene in, image in memory).

pub mod colormap;
pub mod figure;
pub mod kernel;
pub mod output;
pub mod raster;
pub mod sensor;
pub mod shading;
pub mod tables;

use crate::pbrdf::ModelError;
use crate::scene::config::Shading;
use crate::scene::{load_scene, Scene, SceneError};
use indicatif::{ProgressBar, ProgressStyle};
use kernel::KernelQuadrature;
use raster::{rasterize, FragmentBuffer, NO_TRIANGLE};
use rayon::prelude::*;
use sensor::{through_atmosphere, Noise};
use shading::Shader;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tables::{MaterialTables, RadianceTable, TableResolution};

pub use output::{Channel, RenderSummary};

/// Pixels that see no object.
pub const BACKGROUND: u32 = u32::MAX;

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
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// A rendered Stokes image (pixel frame, W·m⁻²·sr⁻¹), row 0 at the top.
pub struct StokesImage {
    pub width: usize,
    pub height: usize,
    /// (S0, S1, S2) per pixel.
    pub stokes: Vec<[f64; 3]>,
    /// Scene surface (object part, `Scene::surfaces`) seen at each pixel, or [`BACKGROUND`].
    pub surface: Vec<u32>,
}

/// Wall-clock seconds of each stage.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Timings {
    pub load: f64,
    pub tables: f64,
    pub raster: f64,
    pub shade: f64,
    pub write: f64,
    pub total: f64,
}

/// A render held in memory, before anything is written.
pub struct Rendered {
    pub image: StokesImage,
    pub timings: Timings,
    pub table_resolutions: Vec<TableResolution>,
}

/// The default output folder `out/<scene stem>/` (DESIGN §4).
pub fn default_output_dir(scene_path: &Path) -> PathBuf {
    let stem = scene_path
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    Path::new("out").join(stem)
}

/// `irpol render`: loads the scene, renders it and writes every output into `out_dir`.
/// A bad scene (or a failed render) writes nothing. `progress` shows a progress bar on stderr
/// when stderr is a terminal.
pub fn render_scene(
    scene_path: &Path,
    out_dir: &Path,
    progress: bool,
) -> Result<RenderSummary, RenderError> {
    let start = Instant::now();
    let scene = load_scene(scene_path)?;
    let load = start.elapsed().as_secs_f64();
    let mut rendered = render(&scene, progress)?;
    rendered.timings.load = load;
    output::write_outputs(&scene, &rendered, out_dir, start)
}

/// Renders a loaded scene in memory.
pub fn render(scene: &Scene, progress: bool) -> Result<Rendered, RenderError> {
    let mut timings = Timings::default();
    let start = Instant::now();
    let quadrature = KernelQuadrature::default();
    let resolutions: Vec<TableResolution> = scene
        .materials
        .iter()
        .map(|m| TableResolution::for_material(&m.pbrdf))
        .collect();
    let tables = scene
        .materials
        .iter()
        .zip(&resolutions)
        .map(|(m, &resolution)| {
            MaterialTables::build(&m.pbrdf, &scene.environment, resolution, &quadrature).map_err(
                |source| RenderError::Material {
                    scene: scene.path.clone(),
                    material: m.name.clone(),
                    origin: m.origin.clone(),
                    source,
                },
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mesh = &scene.mesh;
    let (t_lo, t_hi) = mesh
        .temperatures
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &t| {
            (lo.min(t), hi.max(t))
        });
    let radiance = RadianceTable::new(&scene.sensor.band, t_lo.min(t_hi), t_hi.max(t_lo));
    timings.tables = start.elapsed().as_secs_f64();

    let bar = progress_bar(progress, scene);
    let tick = || bar.inc(1);
    let raster_start = Instant::now();
    // Near plane: far below any scene detail, far above f64 depth resolution.
    let near = (1e-5 * mesh_extent(&mesh.positions)).max(1e-9);
    let fragments = rasterize(&scene.camera, &mesh.positions, &mesh.triangles, near, &tick);
    timings.raster = raster_start.elapsed().as_secs_f64();

    let shade_start = Instant::now();
    let shader = Shader {
        camera: &scene.camera,
        tables: &tables,
        radiance: &radiance,
    };
    let image = shade_image(scene, &shader, &fragments, &tick);
    bar.finish_and_clear();
    timings.shade = shade_start.elapsed().as_secs_f64();
    timings.total = start.elapsed().as_secs_f64();
    Ok(Rendered {
        image,
        timings,
        table_resolutions: resolutions,
    })
}

/// Diagonal of the bounding box of the vertices.
fn mesh_extent(positions: &[nalgebra::Vector3<f64>]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (0..3)
        .map(|k| (hi[k] - lo[k]).max(0.0).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn progress_bar(progress: bool, scene: &Scene) -> ProgressBar {
    if !(progress && std::io::stderr().is_terminal()) {
        return ProgressBar::hidden();
    }
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let tiles = w.div_ceil(raster::TILE) * h.div_ceil(raster::TILE);
    let bar = ProgressBar::new((tiles + h) as u64);
    if let Ok(style) = ProgressStyle::with_template("rendering {bar:40} {percent:>3}% {elapsed}") {
        bar.set_style(style);
    }
    bar
}

/// Shades every pixel (per-pixel or Gouraud), adds the background, the atmosphere and the noise.
fn shade_image(
    scene: &Scene,
    shader: &Shader,
    fragments: &FragmentBuffer,
    tick: &(dyn Fn() + Sync),
) -> StokesImage {
    let mesh = &scene.mesh;
    let (width, height) = (fragments.width, fragments.height);
    let surface_material: Vec<usize> = scene.surfaces.iter().map(|s| s.material).collect();
    let triangle_material = |t: usize| surface_material[mesh.triangle_surface[t] as usize];

    // Gouraud: Stokes vectors at the vertices, in the pixel frame of each vertex's own ray.
    let vertex_stokes: Vec<[f64; 3]> = match scene.shading {
        Shading::Pixel => Vec::new(),
        Shading::Gouraud => {
            let mut vertex_material = vec![0usize; mesh.positions.len()];
            for (t, tri) in mesh.triangles.iter().enumerate() {
                for &v in tri {
                    vertex_material[v as usize] = triangle_material(t);
                }
            }
            // A vertex is shaded from its front: one just past a silhouette reads grazing.
            (0..mesh.positions.len())
                .into_par_iter()
                .map(|v| {
                    shader.shade(
                        vertex_material[v],
                        &mesh.positions[v],
                        &mesh.normals[v],
                        false,
                        mesh.temperatures[v],
                    )
                })
                .collect()
        }
    };

    let path_radiance = scene
        .atmosphere
        .map(|a| scene.sensor.band.radiance(a.temperature_k));
    let noise = Noise {
        sigma_polarizer: 0.5
            * scene.sensor.netd_mk
            * 1e-3
            * scene
                .sensor
                .band
                .radiance_derivative(scene.sensor.netd_reference_k),
        seed: scene.sensor.seed,
    };
    let mut stokes = vec![[0.0f64; 3]; width * height];
    let mut surface = vec![BACKGROUND; width * height];
    stokes
        .par_chunks_mut(width)
        .zip(surface.par_chunks_mut(width))
        .enumerate()
        .for_each(|(y, (row, row_surface))| {
            for x in 0..width {
                let fragment = fragments.fragments[y * width + x];
                if fragment.triangle == NO_TRIANGLE {
                    // The sky or ground of the environment model, seen directly.
                    let ray = scene.camera.ray_direction(x as f64 + 0.5, y as f64 + 0.5);
                    row[x] = [scene.environment.radiance(&ray), 0.0, 0.0];
                    continue;
                }
                let t = fragment.triangle as usize;
                let [i0, i1, i2] = mesh.triangles[t].map(|v| v as usize);
                let (b1, b2) = (fragment.b1 as f64, fragment.b2 as f64);
                let b0 = 1.0 - b1 - b2;
                let point =
                    mesh.positions[i0] * b0 + mesh.positions[i1] * b1 + mesh.positions[i2] * b2;
                let mut s = match scene.shading {
                    Shading::Gouraud => {
                        let [a, b, c] = [i0, i1, i2].map(|v| vertex_stokes[v]);
                        [0, 1, 2].map(|j| a[j] * b0 + b[j] * b1 + c[j] * b2)
                    }
                    Shading::Pixel => {
                        let normal =
                            (mesh.normals[i0] * b0 + mesh.normals[i1] * b1 + mesh.normals[i2] * b2)
                                .normalize();
                        let geometric = (mesh.positions[i1] - mesh.positions[i0])
                            .cross(&(mesh.positions[i2] - mesh.positions[i0]));
                        // The back of a face is seen when its winding and its interpolated normal
                        // both face away (a silhouette of a closed mesh has only the latter; a
                        // mesh whose winding disagrees with its normals only the former).
                        let to_camera = scene.camera.position - point;
                        let back = geometric.dot(&to_camera) < 0.0 && normal.dot(&to_camera) < 0.0;
                        let temperature = mesh.temperatures[i0] * b0
                            + mesh.temperatures[i1] * b1
                            + mesh.temperatures[i2] * b2;
                        shader.shade(triangle_material(t), &point, &normal, back, temperature)
                    }
                };
                if let (Some(atmosphere), Some(path)) = (&scene.atmosphere, path_radiance) {
                    let range = (point - scene.camera.position).norm();
                    s = through_atmosphere(s, range, atmosphere, path);
                }
                row[x] = s;
                row_surface[x] = mesh.triangle_surface[t];
            }
            noise.apply_to_row(y, row);
            tick();
        });
    StokesImage {
        width,
        height,
        stokes,
        surface,
    }
}
