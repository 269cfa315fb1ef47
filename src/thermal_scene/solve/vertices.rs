//! Which shading vertices the thermal run solves and what each sees: the vertices of parts with a
//! stack (those of upright terrain tiles apart, as fields), their sky view and sun visibility at
//! the shadow instants, and their grouping into identical forcing histories.

use super::super::exposure::{sky_view_factors, sun_visibility, Occluders, VertexFrame};
use super::field::FieldVertices;
use super::radiation::ShadowInterval;
use super::{weather_at, ThermalRunError, DAY_S};
use crate::progress::Progress;
use crate::scene::mesh::ShadedMesh;
use crate::scene::Scene;
use crate::thermal::setup::ThermalSetup;
use nalgebra::Vector3;
use std::borrow::Cow;
use std::collections::HashMap;

/// One distinct forcing history: the first vertex that has it stands for all.
#[derive(Hash, PartialEq, Eq)]
struct HistoryKey {
    surface: u32,
    normal: [u64; 3],
    sky_view: u64,
    initial_k: u64,
    lit: Vec<u8>,
}

/// The shading vertices the model computes, and what each sees.
pub(super) struct ThermalVertices {
    /// Shading vertex index of each thermal vertex.
    pub(super) index: Vec<usize>,
    /// Surface (part) of each thermal vertex.
    pub(super) surface: Vec<u32>,
    pub(super) sky_view: Vec<f64>,
    /// V_sun per thermal vertex and shadow instant, row-major.
    pub(super) lit: Vec<u8>,
    /// Shadow instants per vertex.
    pub(super) shadows: usize,
}

impl ThermalVertices {
    /// The vertices of parts with a stack, with their sky view and sun visibility traced, and
    /// apart from them the vertices of upright terrain tiles, solved as fields (see `field`).
    pub(super) fn trace(
        scene: &Scene,
        setup: &ThermalSetup,
        occluders: &Occluders,
        progress: &dyn Progress,
    ) -> Result<(ThermalVertices, Vec<FieldVertices>), ThermalRunError> {
        let mesh = &scene.mesh;
        let all_surfaces = vertex_surfaces(scene);
        let mut fields = field_sets(scene, setup);
        let mut index = Vec::new();
        let mut frames = Vec::new();
        for (v, &surface) in all_surfaces.iter().enumerate() {
            if setup.surfaces[surface as usize].is_none() {
                continue;
            }
            let grid = grid_point_of(scene, surface, &mesh.positions[v]);
            let field = grid.and_then(|(h, g)| {
                let field = fields.iter_mut().find(|f| f.heightfield == h)?;
                Some((field, g))
            });
            if let Some((field, g)) = field {
                field.vertex.push(v);
                field.grid.push(g);
                continue;
            }
            index.push(v);
            frames.push(VertexFrame {
                position: mesh.positions[v],
                normal: mesh.normals[v],
                grid,
            });
        }
        progress.begin("sky view and shadows", 2);
        let sky_view = sky_view_factors(occluders, &frames);
        progress.advance(1);
        let sun = shadow_instants(setup)
            .iter()
            .map(|&t| weather_at(setup, t).map(|w| w.sun_direction))
            .collect::<Result<Vec<_>, _>>()?;
        let lit = sun_visibility(occluders, &frames, &sun);
        progress.advance(1);
        progress.end();
        let vertices = ThermalVertices {
            surface: index.iter().map(|&v| all_surfaces[v]).collect(),
            index,
            sky_view,
            lit,
            shadows: sun.len(),
        };
        fields.retain(|f| !f.vertex.is_empty());
        Ok((vertices, fields))
    }

    fn lit(&self, i: usize) -> &[u8] {
        &self.lit[i * self.shadows..(i + 1) * self.shadows]
    }

    /// What thermal vertex `i` sees.
    pub(super) fn exposure(&self, i: usize, mesh: &ShadedMesh) -> Exposure<'_> {
        Exposure {
            normal: mesh.normals[self.index[i]],
            sky_view: self.sky_view[i],
            lit: self.lit(i),
        }
    }

    /// Each thermal vertex's history class, and one representative vertex per class.
    pub(super) fn group(&self, mesh: &ShadedMesh) -> (Vec<usize>, Vec<usize>) {
        let mut class_of: HashMap<HistoryKey, usize> = HashMap::new();
        let mut representatives = Vec::new();
        let class = (0..self.index.len())
            .map(|i| {
                let v = self.index[i];
                let n = mesh.normals[v];
                let key = HistoryKey {
                    surface: self.surface[i],
                    normal: [n.x.to_bits(), n.y.to_bits(), n.z.to_bits()],
                    sky_view: self.sky_view[i].to_bits(),
                    initial_k: mesh.temperatures[v].to_bits(),
                    lit: self.lit(i).to_vec(),
                };
                *class_of.entry(key).or_insert_with(|| {
                    representatives.push(i);
                    representatives.len() - 1
                })
            })
            .collect();
        (class, representatives)
    }
}

/// An empty field for every upright terrain tile whose part has a stack outside any enclosure
/// (an enclosure's members are marched with their air node, one at a time).
pub(super) fn field_sets(scene: &Scene, setup: &ThermalSetup) -> Vec<FieldVertices> {
    (scene.heightfields.iter().enumerate())
        .filter(|(_, hf)| {
            let model = setup.surfaces[hf.surface as usize].as_ref();
            model.is_some_and(|m| m.enclosure.is_none())
        })
        .map(|(heightfield, hf)| FieldVertices {
            heightfield,
            surface: hf.surface,
            vertex: Vec::new(),
            grid: Vec::new(),
        })
        .collect()
}

/// (heightfield, grid point) of a vertex of `surface` at `position`, when it is a point of an
/// upright terrain tile.
fn grid_point_of(scene: &Scene, surface: u32, position: &Vector3<f64>) -> Option<(usize, usize)> {
    let h = (scene.heightfields.iter()).position(|hf| hf.surface == surface)?;
    Some((h, scene.heightfields[h].grid_point(position)?))
}

/// The triangles that rays must test: all but the upright terrain tiles' (their horizon maps
/// answer for them).
pub(super) fn occluding_mesh(scene: &Scene) -> Cow<'_, ShadedMesh> {
    if scene.heightfields.is_empty() {
        return Cow::Borrowed(&scene.mesh);
    }
    let terrain = |s: u32| scene.heightfields.iter().any(|hf| hf.surface == s);
    let mesh = &scene.mesh;
    let mut kept = ShadedMesh::default();
    let mut new_index = vec![u32::MAX; mesh.positions.len()];
    for (triangle, &s) in mesh.triangles.iter().zip(&mesh.triangle_surface) {
        if terrain(s) {
            continue;
        }
        let corners = triangle.map(|v| {
            let slot = &mut new_index[v as usize];
            if *slot == u32::MAX {
                *slot = kept.positions.len() as u32;
                kept.positions.push(mesh.positions[v as usize]);
                kept.normals.push(mesh.normals[v as usize]);
                kept.temperatures.push(mesh.temperatures[v as usize]);
            }
            *slot
        });
        kept.triangles.push(corners);
        kept.triangle_surface.push(s);
    }
    Cow::Owned(kept)
}

/// The surface (object part) of every shading vertex (a shading vertex belongs to one part).
pub fn vertex_surfaces(scene: &Scene) -> Vec<u32> {
    let mut surface = vec![0u32; scene.mesh.positions.len()];
    for (triangle, &s) in scene
        .mesh
        .triangles
        .iter()
        .zip(&scene.mesh.triangle_surface)
    {
        for &v in triangle {
            surface[v as usize] = s;
        }
    }
    surface
}

/// The end of the sampled time: the run's, or the spun-up first day's if longer.
pub(super) fn sampled_end(setup: &ThermalSetup) -> f64 {
    if setup.spinup_days > 0 {
        setup.duration_s.max(DAY_S)
    } else {
        setup.duration_s
    }
}

/// How many [`shadow_instants`] there are.
pub(super) fn shadow_instants_count(setup: &ThermalSetup) -> usize {
    (sampled_end(setup) / setup.shadow_step_s).ceil() as usize + 1
}

/// Shadow instants 0, step, 2·step, … through the end of the run (and of the spin-up day).
pub(super) fn shadow_instants(setup: &ThermalSetup) -> Vec<f64> {
    let end = sampled_end(setup);
    (0..shadow_instants_count(setup))
        .map(|i| (i as f64 * setup.shadow_step_s).min(end))
        .collect()
}

/// What one vertex sees.
pub(super) struct Exposure<'a> {
    pub(super) normal: nalgebra::Vector3<f64>,
    pub(super) sky_view: f64,
    /// V_sun at each shadow instant.
    pub(super) lit: &'a [u8],
}

impl Exposure<'_> {
    /// V_sun at `time_s`, linear between shadow instants.
    pub(super) fn sun_visible(&self, time_s: f64, step_s: f64) -> f64 {
        ShadowInterval::at(time_s, step_s, self.lit.len()).visible(self.lit)
    }
}
