//! The path integrator (docs/design.md §1.7): occlusion, polarized inter-reflection and the sun, as a
//! correction to the exact open-world value.
//!
//! The Stokes vector leaving a point x along ω_o is
//!
//!   S(x, ω_o) = S_open(x, ω_o) + S_sun(x, ω_o)
//!             + ∫ F(ω_i→ω_o) [S_in(ω_i) − L_env(ω_i) e₀] cosθ_i dΩ_i,
//!
//! where S_open is the open-world table value (emission plus the unoccluded sky and ground), and
//! the integrand of the correction vanishes wherever the ray escapes (S_in = L_env there). Only
//! directions that hit geometry contribute, so an unoccluded point gets no correction and no
//! noise (a control variate with exact expectation). The correction is estimated by importance
//! sampling the pBRDF ([`Pbrdf::sample_incident`]); at a hit y the incident Stokes vector is the
//! full vector leaving y toward x, computed by the same formula one level deeper and rotated from
//! y's outgoing psps frame into x's incident psps frame (full 4×4 Mueller chains, so circular
//! polarization appears after two conductor bounces). Vertex k (the camera's visible point is
//! k = 0) traces its correction while k ≤ `bounces`; deeper hits take the open-world value.
//!
//! The sun (see [`crate::emitter`]) is added at every vertex as next-event estimation: the disc
//! integral of F times a shadow-ray visibility. It is not part of the control variate (the
//! open-world tables hold no sun), and escaped correction rays never count it, so it is not
//! counted twice.
//!
//! A band material (docs/design.md §1.9) scatters each source with its band-weighted Mueller matrix
//! Σ_m f_m F(λ_m), f the shares of that source's spectrum over the wavelength nodes: the sun's
//! as a 5772 K blackbody through the band; the environment a correction replaces, grey at its
//! brightness temperature; the light of a surface hit as its emission, node by node, plus what
//! it reflects, modelled as a uniform grey source reflected by the hit (`band_scattering`).
//! Only the hit's emission is exact: the approximation is measured in docs/spectral.md ("Band
//! rendering"). A ray that escapes still adds exactly zero (no hit, no correction).

use super::accel::Accelerator;
use super::band_scattering::{band_scattering, BandScattering, BandSources, EmittedLight};
use super::open_world::OpenWorld;
use super::sampler::PixelSampler;
use super::tables::THETA_MAX;
use crate::emitter::{DiscQuadrature, Sun};
use crate::optics::band_nodes::BrightnessGrid;
use crate::optics::{
    camera_frame_turn, rotation_between_frames, Direction, FrameTurn, Mueller, OutgoingFrame,
    SpectralMix, Stokes,
};
use crate::pbrdf::{MaterialOptics, Pbrdf, ScatteredView};
use crate::scene::mesh::SurfaceHit;
use crate::scene::{PathSettings, Scene};
use nalgebra::Vector3;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// A pixel's sample points and random stream.
type Sampler<'a> = PixelSampler<'a, ChaCha8Rng>;

/// Shadow rays toward the sun per visible point (stratified over the disc's area).
const SHADOW_RAYS_PER_PIXEL: u32 = 4;

/// A surface point seen from a given side: the hit, its normal turned toward the viewer, and the
/// geometric normal on the same side (for ray offsets and the true horizon).
#[derive(Clone, Copy, Debug)]
pub struct Vertex {
    pub hit: SurfaceHit,
    pub normal: Vector3<f64>,
    pub geometric_normal: Vector3<f64>,
}

impl Vertex {
    /// The side of `hit` seen from direction `toward_viewer` (from the point to the viewer, any
    /// length). The back is shaded when the winding and the interpolated normal both face away:
    /// a silhouette of a closed mesh has only the latter (its normal is read at grazing), a mesh
    /// whose winding disagrees with its normals only the former.
    pub fn seen_from(hit: SurfaceHit, toward_viewer: &Vector3<f64>) -> Vertex {
        let geometric_front = hit.geometric_normal.dot(toward_viewer) >= 0.0;
        let back = !geometric_front && hit.normal.dot(toward_viewer) < 0.0;
        let unit = hit.geometric_normal.normalize();
        Vertex {
            hit,
            normal: if back { -hit.normal } else { hit.normal },
            geometric_normal: if geometric_front { unit } else { -unit },
        }
    }
}

/// A vertex prepared for shading light that leaves it along ω: the outgoing frame, the material
/// and, when ω is above the shading normal (below it nothing is reflected), what every sample
/// drawn there shares ([`Outgoing`]).
struct ShadingPoint<'v> {
    vertex: &'v Vertex,
    frame: OutgoingFrame,
    material: usize,
    outgoing: Option<Outgoing>,
}

/// ω in the local frame, computed once per vertex: the sampling pBRDF's view of it, its local
/// psps axes, and the turn from those axes into the outgoing frame's s axis (the frame a
/// vertex's estimates are returned in).
struct Outgoing {
    view: ScatteredView,
    scattered: Direction,
    to_frame: FrameTurn,
}

/// A direction drawn from a shading point's pBRDF and the surface it hits.
struct Bounce {
    /// ω_i in the point's local frame and its density (sr⁻¹).
    w_i: Vector3<f64>,
    pdf: f64,
    /// ω_i in the world, and −ω_i (from the hit back toward the point).
    direction: Vector3<f64>,
    toward_x: Vector3<f64>,
    /// The hit, seen from the point.
    next: Vertex,
}

impl PathTracer<'_> {
    fn shading_point<'v>(&self, vertex: &'v Vertex, omega: &Vector3<f64>) -> ShadingPoint<'v> {
        let frame = OutgoingFrame::new(&vertex.normal, omega);
        let material = self.scene.triangle_material(vertex.hit.triangle);
        let w_o = frame.to_local(omega);
        let pbrdf = self.scene.materials[material].optics.sampling_pbrdf();
        let outgoing = (w_o.z > 0.0).then(|| {
            let scattered = Direction::from_unit_vector(w_o);
            let s_local = frame.to_world(&scattered.azimuthal_axis);
            let k = frame.to_world(&scattered.vector);
            Outgoing {
                view: pbrdf.scattered_view(&w_o),
                to_frame: rotation_between_frames(&s_local, &frame.s_axis, &k),
                scattered,
            }
        });
        ShadingPoint {
            vertex,
            frame,
            material,
            outgoing,
        }
    }
}

/// One pixel's estimate in the pixel frame: the exact open-world value, the mean of the
/// correction (occlusion, inter-reflection, sun) and the correction's standard error.
pub struct Estimate {
    pub open_world: Stokes,
    pub correction: Stokes,
    pub standard_error: Stokes,
}

/// Everything the path integrator shares across pixels.
pub struct PathTracer<'a> {
    pub scene: &'a Scene,
    pub open_world: &'a OpenWorld<'a>,
    pub accel: &'a Accelerator<'a>,
    pub settings: PathSettings,
    /// The sun and its disc quadrature per material.
    pub sun: Option<(Sun, Vec<DiscQuadrature>)>,
    /// Per material, the source spectra a band material weights its models with (`None`: grey).
    band_sources: Vec<Option<BandSources>>,
}

impl PathTracer<'_> {
    pub fn new<'a>(
        scene: &'a Scene,
        open_world: &'a OpenWorld<'a>,
        accel: &'a Accelerator<'a>,
        settings: PathSettings,
    ) -> PathTracer<'a> {
        let sun = scene.sun.map(|sun| {
            let rules = scene
                .materials
                .iter()
                .map(|m| sun.quadrature(m.optics.sampling_pbrdf()))
                .collect();
            (sun, rules)
        });
        let any_band = scene.materials.iter().any(|m| m.optics.band().is_some());
        let grid = any_band.then(|| BrightnessGrid::new(&scene.sensor.band));
        let band_sources = scene
            .materials
            .iter()
            .map(|m| Some(BandSources::new(m.optics.band()?, grid.as_ref()?)))
            .collect();
        PathTracer {
            scene,
            open_world,
            accel,
            settings,
            sun,
            band_sources,
        }
    }

    /// The Stokes vector leaving the visible point `vertex` toward the camera along `omega`, in
    /// the pixel frame (image right `image_right`, docs/design.md §1.6), averaged over
    /// `settings.samples` paths; `rng` is the pixel's own stream.
    pub fn estimate(
        &self,
        vertex: &Vertex,
        omega: &Vector3<f64>,
        image_right: &Vector3<f64>,
        rng: &mut ChaCha8Rng,
    ) -> Estimate {
        let point = self.shading_point(vertex, omega);
        let frame = &point.frame;
        let to_pixel_frame = camera_frame_turn(&frame.s_axis, omega, image_right);
        let to_pixel = |s: &Stokes| to_pixel_frame.apply(s);
        let exact = self
            .open_world
            .leaving(point.material, frame, vertex.hit.temperature);
        let n = self.settings.samples.max(1);
        let sun = self.sun_integral(&point);
        // Sums of the samples' differences from the first one: the variance is then exactly zero
        // when every sample is the same (an unoccluded, fully lit or fully shadowed point).
        let (mut first, mut sum, mut sum2) = (None, Stokes::zeros(), Stokes::zeros());
        // Visibility of the disc by a few stratified shadow rays, reused cyclically: a lit or
        // shadowed point needs one answer, only penumbrae need more, and each sample still
        // carries one of them so that the standard error sees the penumbra's spread.
        let shadow_rays = n.min(SHADOW_RAYS_PER_PIXEL) as usize;
        let mut visibility = [0.0; SHADOW_RAYS_PER_PIXEL as usize];
        if sun.is_some() {
            for (s, v) in visibility.iter_mut().take(shadow_rays).enumerate() {
                let stratum = (s as f64 + rng.random::<f64>()) / shadow_rays as f64;
                *v = self.sun_visibility(vertex, [stratum, rng.random::<f64>()]);
            }
        }
        let split = self.settings.first_bounce_samples.max(1) as usize;
        let mut sampler = PixelSampler::new(n as usize, split, rng);
        for s in 0..sampler.paths() {
            sampler.start_path(s);
            let mut x = if split > 1 {
                self.split_first_bounce(&point, split, &mut sampler)
            } else {
                self.correction(&point, 0, &mut sampler)
            };
            if let Some(integral) = sun {
                x += integral * visibility[s % shadow_rays];
            }
            let x = to_pixel(&x);
            let d = x - *first.get_or_insert(x);
            sum += d;
            sum2 += d.component_mul(&d);
        }
        let shift = sum / n as f64;
        let mean = first.unwrap_or_default() + shift;
        let variance = (sum2 / n as f64 - shift.component_mul(&shift)).map(|v| v.max(0.0));
        let standard_error = if n > 1 {
            (variance / (n - 1) as f64).map(f64::sqrt)
        } else {
            Stokes::zeros()
        };
        Estimate {
            open_world: to_pixel(&exact),
            correction: mean,
            standard_error,
        }
    }

    /// One-sample estimate of the Stokes vector leaving `vertex` along `omega` at depth `depth`,
    /// in the psps frame of `omega` (s axis returned with it).
    fn leaving(
        &self,
        vertex: &Vertex,
        omega: &Vector3<f64>,
        depth: u32,
        sampler: &mut Sampler,
    ) -> (Stokes, Vector3<f64>) {
        let point = self.shading_point(vertex, omega);
        let open = self.open_leaving(&point);
        (
            self.leaving_beyond_open(&point, open, depth, sampler),
            point.frame.s_axis,
        )
    }

    /// The open-world value leaving `point` (its outgoing frame).
    fn open_leaving(&self, point: &ShadingPoint) -> Stokes {
        self.open_world
            .leaving(point.material, &point.frame, point.vertex.hit.temperature)
    }

    /// [`PathTracer::leaving`] at a prepared `point` whose open-world value is `open`: that
    /// value plus the sun and, while `depth` ≤ `bounces`, the correction.
    fn leaving_beyond_open(
        &self,
        point: &ShadingPoint,
        open: Stokes,
        depth: u32,
        sampler: &mut Sampler,
    ) -> Stokes {
        let mut s = open;
        if let Some(integral) = self.sun_integral(point) {
            let disc_point = [sampler.uniform(), sampler.uniform()];
            s += integral * self.sun_visibility(point.vertex, disc_point);
        }
        if depth <= self.settings.bounces {
            s += self.correction(point, depth, sampler);
        }
        s
    }

    /// One sample of ∫ F (S_in − L_env e₀) cosθ_i dΩ_i at `point` (depth `depth`), in the psps
    /// frame of its outgoing frame, the pBRDF sampled at the path's point for this depth
    /// ([`PixelSampler::bounce_point`], stratified over the pixel's paths).
    fn correction(&self, point: &ShadingPoint, depth: u32, sampler: &mut Sampler) -> Stokes {
        if point.outgoing.is_none() {
            return Stokes::zeros();
        }
        let Some(bounce) = self.bounce(point, sampler.bounce_point(depth)) else {
            return Stokes::zeros();
        };
        let (leaving, s_from) = self.leaving(&bounce.next, &bounce.toward_x, depth + 1, sampler);
        let [scattered] = self.scatter(point, &bounce, [&leaving], &s_from);
        scattered
    }

    /// The visible point's correction with its first bounce split into `split` lobe samples
    /// (`[render] first_bounce_samples`): the path's own sample ω₀ continues, the others end at
    /// their hit's open-world value. With f(ω, S) one sample's F (S − L_env e₀) cosθ_i / pdf,
    /// S_open the hit's open-world value and S its full one (open world, sun, deeper
    /// correction),
    ///
    ///   C = f(ω₀, S) − f(ω₀, S_open) + (1/split) Σ_i f(ω_i, S_open(ω_i)),  i = 0 … split − 1,
    ///
    /// whose expectation is E f(ω, S): the two terms at ω₀ estimate E[f(ω, S) − f(ω, S_open)],
    /// the mean over the split estimates E f(ω, S_open) (weights 1, −1 and split × 1/split: the
    /// open part counted exactly once; no linearity of f needed, so band materials keep
    /// theirs). The first bounce's integrand has the edges of what it hits (a silhouette, the
    /// far edge of a ground), where the stratified points converge faster than 1/N: split × N
    /// first-bounce points for the cost of N deeper paths.
    fn split_first_bounce(
        &self,
        point: &ShadingPoint,
        split: usize,
        sampler: &mut Sampler,
    ) -> Stokes {
        let mut open_sum = Stokes::zeros();
        let mut beyond_open = Stokes::zeros();
        if let Some(bounce) = self.bounce(point, sampler.bounce_point(0)) {
            let hit = self.shading_point(&bounce.next, &bounce.toward_x);
            let open = self.open_leaving(&hit);
            let full = self.leaving_beyond_open(&hit, open, 1, sampler);
            let [full, open] = self.scatter(point, &bounce, [&full, &open], &hit.frame.s_axis);
            beyond_open = full - open;
            open_sum = open;
        }
        for index in 1..split {
            let u = sampler.extra_first_bounce_point(index);
            if let Some(bounce) = self.bounce(point, u) {
                let hit = self.shading_point(&bounce.next, &bounce.toward_x);
                let open = self.open_leaving(&hit);
                let [open] = self.scatter(point, &bounce, [&open], &hit.frame.s_axis);
                open_sum += open;
            }
        }
        beyond_open + open_sum / split as f64
    }

    /// Draws an incident direction at `point` from the pBRDF with the uniforms `u` and traces
    /// it; `None` below the surface or when the ray escapes (the correction's integrand is zero
    /// there).
    fn bounce(&self, point: &ShadingPoint, u: [f64; 2]) -> Option<Bounce> {
        let (vertex, frame) = (point.vertex, &point.frame);
        let pbrdf = self.scene.materials[point.material].optics.sampling_pbrdf();
        let (w_i, pdf) = pbrdf.sample_incident(&point.outgoing.as_ref()?.view, u)?;
        let direction = frame.to_world(&w_i);
        // Below the true (geometric) surface: an artefact of interpolated normals, not light.
        if direction.dot(&vertex.geometric_normal) <= 0.0 {
            return None;
        }
        let origin = vertex.hit.point + vertex.geometric_normal * self.accel.offset;
        let hit = self.accel.closest_hit(&origin, &direction)?;
        let toward_x = -direction;
        Some(Bounce {
            w_i,
            pdf,
            direction,
            toward_x,
            next: Vertex::seen_from(hit, &toward_x),
        })
    }

    /// F (S_in − L_env e₀) cosθ_i / pdf at `point` for each Stokes vector in `leaving` (the
    /// light leaving the bounce's hit toward the point, in the psps frame with s axis `s_from`),
    /// in the psps frame of the point's outgoing frame. A grey material's Mueller matrix is
    /// evaluated once for all of them.
    fn scatter<const N: usize>(
        &self,
        point: &ShadingPoint,
        bounce: &Bounce,
        leaving: [&Stokes; N],
        s_from: &Vector3<f64>,
    ) -> [Stokes; N] {
        let (frame, material) = (&point.frame, point.material);
        let optics = &self.scene.materials[material].optics;
        let pbrdf = optics.sampling_pbrdf();
        let Some(Outgoing {
            view,
            scattered,
            to_frame,
        }) = &point.outgoing
        else {
            return [Stokes::zeros(); N];
        };
        let w_i = bounce.w_i;
        // Incident frame at x: k = −ω_i, s = −ê_φ(ω_i) in the local frame (docs/design.md §1.3).
        let incident = Direction::from_unit_vector(w_i);
        let s_incident = -frame.to_world(&incident.azimuthal_axis);
        let eta = rotation_between_frames(s_from, &s_incident, &bounce.toward_x);
        let environment = self.scene.environment.radiance(&bounce.direction);
        let masking = [pbrdf.masking(w_i.z), view.masking];
        let weight = w_i.z / bounce.pdf;
        match (optics, &self.band_sources[material]) {
            (MaterialOptics::Band(band), Some(sources)) => {
                let emitted = self.emitted_toward(&bounce.next, &bounce.toward_x, eta);
                let geometry = BandScattering {
                    incident: &incident,
                    scattered,
                    masking,
                };
                leaving.map(|s| {
                    let s_in = eta.apply(s);
                    let local =
                        band_scattering(band, sources, &geometry, &s_in, &emitted, environment);
                    to_frame.apply(&(local * weight))
                })
            }
            _ => {
                let mueller =
                    pbrdf.mueller_with_masking(&incident, scattered, masking[0], masking[1]);
                leaving.map(|s| {
                    let mut s_in = eta.apply(s);
                    s_in[0] -= environment;
                    to_frame.apply(&(mueller * s_in * weight))
                })
            }
        }
    }

    /// What the hit `vertex` emits toward the receiver along `toward_x` (its open-world emission,
    /// rotated by `eta` into the receiver's incident frame) and its spectrum: the hit's
    /// emissivity at each wavelength node (a band material; `None`: grey) and temperature.
    fn emitted_toward(
        &self,
        vertex: &Vertex,
        toward_x: &Vector3<f64>,
        eta: FrameTurn,
    ) -> EmittedLight {
        let frame = OutgoingFrame::new(&vertex.normal, toward_x);
        let material = self.scene.triangle_material(vertex.hit.triangle);
        let temperature = vertex.hit.temperature;
        let tables = &self.open_world.tables[material];
        let cos_theta = frame.cos_theta.max(THETA_MAX.cos());
        EmittedLight {
            radiance: self.open_world.radiance.radiance(temperature),
            emissivity: tables.emissivity_at(cos_theta, temperature),
            per_node: tables.node_emissivities(cos_theta),
            polarization: eta.apply(&Stokes::new(0.0, 1.0, 0.0, 0.0)),
        }
    }

    /// ∫_disc F_j0(ω→ω_o) cosθ dΩ L_sun = E_sun Σ w_k F_j0(ω_k→ω_o) cosθ_k, in the point's frame; `None`
    /// without a sun or where no node is above the local horizon.
    fn sun_integral(&self, point: &ShadingPoint) -> Option<Stokes> {
        let (frame, material) = (&point.frame, point.material);
        let (sun, rules) = self.sun.as_ref()?;
        if sun.direction.dot(&point.vertex.geometric_normal) <= 0.0 {
            return None;
        }
        let outgoing = point.outgoing.as_ref()?;
        let optics = &self.scene.materials[material].optics;
        let pbrdf: &Pbrdf = optics.sampling_pbrdf();
        let scattered = &outgoing.scattered;
        let masking_o = outgoing.view.masking;
        let mut sum = Stokes::zeros();
        let mut any = false;
        for (node, weight) in &rules[material].nodes {
            let w_i = frame.to_local(node);
            if w_i.z <= 0.0 {
                continue;
            }
            any = true;
            let incident = Direction::from_unit_vector(w_i);
            let masking = [pbrdf.masking(w_i.z), masking_o];
            let mueller: Mueller = match (optics, &self.band_sources[material]) {
                (MaterialOptics::Band(band), Some(sources)) => {
                    let [mixed] = band.mueller_mixtures(
                        &incident,
                        scattered,
                        masking,
                        [SpectralMix::fixed(&sources.sun)],
                    );
                    mixed
                }
                _ => pbrdf.mueller_with_masking(&incident, scattered, masking[0], masking[1]),
            };
            sum += mueller.column(0) * (weight * w_i.z);
        }
        any.then(|| outgoing.to_frame.apply(&(sum * sun.irradiance)))
    }

    /// 1 if a shadow ray from `vertex` to the disc point `[area fraction, angle fraction]`
    /// ([`Sun::disc_point`]) escapes.
    fn sun_visibility(&self, vertex: &Vertex, [stratum, angle]: [f64; 2]) -> f64 {
        let Some((sun, _)) = self.sun.as_ref() else {
            return 0.0;
        };
        let direction = sun.disc_point(stratum, angle);
        if direction.dot(&vertex.geometric_normal) <= 0.0 {
            return 0.0;
        }
        let origin = vertex.hit.point + vertex.geometric_normal * self.accel.offset;
        if self.accel.occluded(&origin, &direction) {
            0.0
        } else {
            1.0
        }
    }
}
