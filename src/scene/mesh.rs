//! Triangle meshes: what a file holds ([`RawMesh`]: positions, optional normals, triangles tagged
//! with a part, optional per-vertex temperatures) and what the renderer draws ([`ShadedMesh`]:
//! world-space shading vertices, each with one normal and one temperature).
//!
//! Temperatures follow the paper's §4, a temperature per part turned into a temperature per
//! vertex and interpolated over triangles, with one departure: a vertex shared by several parts
//! is split per part and each copy keeps its own part's temperature (the paper averages them,
//! which moved a part's typed temperature at its edges: a box's top at 315 K beside 300 K sides
//! was drawn at ~310 K).

use nalgebra::{Rotation3, Vector3};
use rustc_hash::FxHashMap;

/// What is wrong with a mesh: its file's content (an OBJ statement, a PLY header or element) or
/// its geometry once placed in the world.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("an OBJ file must be UTF-8 text")]
    NotUtf8,
    #[error("unknown mesh format: the file name must end in .obj or .ply")]
    UnknownFormat,
    /// An OBJ statement (`line` from 1).
    #[error("line {line}: {message}")]
    Line { line: usize, message: String },
    #[error("{0}")]
    Content(String),
}

impl From<String> for MeshError {
    fn from(message: String) -> Self {
        MeshError::Content(message)
    }
}

impl From<&str> for MeshError {
    fn from(message: &str) -> Self {
        MeshError::Content(message.to_owned())
    }
}

/// Where a face came from in its file, for error messages ("line 12", "face 7").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaceOrigin {
    Line(usize),
    Index(usize),
}

impl std::fmt::Display for FaceOrigin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FaceOrigin::Line(line) => write!(f, "line {line}"),
            FaceOrigin::Index(index) => write!(f, "face {index}"),
        }
    }
}

#[derive(Clone, Debug)]
pub struct RawFace {
    pub vertices: [u32; 3],
    /// Indices into [`RawMesh::normals`] (OBJ `f v//vn`), when the file gives them.
    pub normals: Option<[u32; 3]>,
    pub part: u32,
    pub origin: FaceOrigin,
}

/// A mesh as read from a file or generated, in object coordinates.
#[derive(Clone, Debug, Default)]
pub struct RawMesh {
    pub positions: Vec<Vector3<f64>>,
    pub normals: Vec<Vector3<f64>>,
    pub faces: Vec<RawFace>,
    /// Part names (OBJ groups); `RawFace::part` indexes this.
    pub parts: Vec<String>,
    /// Per-vertex temperatures (PLY property `temperature`, K).
    pub vertex_temperatures: Option<Vec<f64>>,
    /// What the reader noticed but did not refuse (a property that looks like a temperature
    /// under another name), for the scene's warnings.
    pub notes: Vec<String>,
}

impl RawMesh {
    /// Index of part `name`, appended if new.
    pub fn part_index(&mut self, name: &str) -> u32 {
        match self.parts.iter().position(|p| p == name) {
            Some(i) => i as u32,
            None => {
                self.parts.push(name.to_owned());
                (self.parts.len() - 1) as u32
            }
        }
    }

    /// Index of part `name`, if the mesh has it.
    pub fn part_index_of(&self, name: &str) -> Option<u32> {
        self.parts.iter().position(|p| p == name).map(|i| i as u32)
    }

    /// Names of the parts that own at least one face.
    pub fn used_parts(&self) -> Vec<&str> {
        let mut used = vec![false; self.parts.len()];
        for face in &self.faces {
            used[face.part as usize] = true;
        }
        self.parts
            .iter()
            .zip(used)
            .filter(|(_, u)| *u)
            .map(|(p, _)| p.as_str())
            .collect()
    }
}

/// Similarity transform applied to an object: scale, then rotations about x, y, z (degrees), then
/// translation.
#[derive(Clone, Copy, Debug)]
pub struct Transform {
    pub scale: f64,
    pub rotation: Rotation3<f64>,
    pub translation: Vector3<f64>,
}

impl Transform {
    pub fn new(scale: f64, rotate_deg: [f64; 3], translate: [f64; 3]) -> Transform {
        let [rx, ry, rz] = rotate_deg.map(f64::to_radians);
        let rotation = Rotation3::from_axis_angle(&Vector3::z_axis(), rz)
            * Rotation3::from_axis_angle(&Vector3::y_axis(), ry)
            * Rotation3::from_axis_angle(&Vector3::x_axis(), rx);
        Transform {
            scale,
            rotation,
            translation: Vector3::from(translate),
        }
    }

    pub fn point(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * (p * self.scale) + self.translation
    }

    /// Normals transform with the rotation alone (uniform scale keeps them perpendicular).
    pub fn normal(&self, n: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * n
    }
}

/// The renderer's mesh: shading vertices (a position, a unit normal and a temperature each) and
/// triangles over them, every triangle tagged with a surface (an object part and its material).
#[derive(Clone, Debug, Default)]
pub struct ShadedMesh {
    pub positions: Vec<Vector3<f64>>,
    pub normals: Vec<Vector3<f64>>,
    pub temperatures: Vec<f64>,
    pub triangles: Vec<[u32; 3]>,
    pub triangle_surface: Vec<u32>,
}

/// A point on a triangle of a [`ShadedMesh`], with its interpolated attributes.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    pub triangle: usize,
    /// (b0, b1, b2), b0 = 1 − b1 − b2.
    pub barycentric: [f64; 3],
    pub point: Vector3<f64>,
    /// Interpolated shading normal, unit length.
    pub normal: Vector3<f64>,
    /// (p1 − p0) × (p2 − p0): the winding's normal, not normalized.
    pub geometric_normal: Vector3<f64>,
    pub temperature: f64,
}

impl ShadedMesh {
    /// The point of triangle `t` at barycentric coordinates (1 − b1 − b2, b1, b2) with its
    /// interpolated normal and temperature (per-vertex values interpolated, paper §4).
    #[inline]
    pub fn interpolate(&self, t: usize, b1: f64, b2: f64) -> SurfaceHit {
        let [i0, i1, i2] = self.triangles[t].map(|v| v as usize);
        let b0 = 1.0 - b1 - b2;
        let p = &self.positions;
        let n = &self.normals;
        let temperature = &self.temperatures;
        SurfaceHit {
            triangle: t,
            barycentric: [b0, b1, b2],
            point: p[i0] * b0 + p[i1] * b1 + p[i2] * b2,
            normal: (n[i0] * b0 + n[i1] * b1 + n[i2] * b2).normalize(),
            geometric_normal: (p[i1] - p[i0]).cross(&(p[i2] - p[i0])),
            temperature: temperature[i0] * b0 + temperature[i1] * b1 + temperature[i2] * b2,
        }
    }

    /// Appends `other`, offsetting its vertex indices.
    pub fn append(&mut self, other: ShadedMesh) {
        let offset = self.positions.len() as u32;
        self.positions.extend(other.positions);
        self.normals.extend(other.normals);
        self.temperatures.extend(other.temperatures);
        self.triangles
            .extend(other.triangles.into_iter().map(|t| t.map(|i| i + offset)));
        self.triangle_surface.extend(other.triangle_surface);
    }
}

/// What one object needs to turn its raw mesh into shading vertices.
pub struct ObjectShading<'a> {
    pub transform: Transform,
    /// Faces whose normals differ by less than this are smoothed together (no `vn` in the file).
    pub crease_angle_deg: f64,
    /// Per raw part: the temperature (K) when the mesh has no per-vertex temperatures.
    pub part_temperature: &'a [Option<f64>],
    /// Per raw part: the scene surface index stored in [`ShadedMesh::triangle_surface`].
    pub part_surface: &'a [u32],
}

/// Transforms, checks and converts a raw mesh. Errors name the face or vertex ("line 12: …").
/// Shades `raw` for rendering; the second value says which degenerate faces were skipped.
pub fn shade_mesh(
    raw: &RawMesh,
    setup: &ObjectShading,
) -> Result<(ShadedMesh, Option<String>), MeshError> {
    let positions: Vec<Vector3<f64>> = raw
        .positions
        .iter()
        .map(|p| setup.transform.point(p))
        .collect();
    if let Some(i) = positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(format!("vertex {} has a non-finite coordinate", i + 1).into());
    }
    let (kept, skipped) = without_degenerate_faces(raw, &positions)?;
    let raw = &kept;
    let face_normals: Vec<Vector3<f64>> = raw
        .faces
        .iter()
        .map(|f| area_normal(f, &positions))
        .collect();
    let temperature = VertexTemperatures::of(raw, setup.part_temperature)?;
    let corner_normals = corner_normals(raw, setup, &face_normals)?;

    // One shading vertex per distinct (position, part, normal): creases and part boundaries split
    // vertices so that each side keeps its own normal and material.
    let mut mesh = ShadedMesh::default();
    // Keyed by integers, so a fast non-cryptographic hash (no key here comes from an adversary
    // who could force collisions), sized for one shading vertex per mesh vertex: on a 5 M-triangle
    // terrain SipHash and rehashing were ~10 % of loading the scene.
    let mut index_of: FxHashMap<(u32, u32, [u64; 3]), u32> =
        FxHashMap::with_capacity_and_hasher(raw.positions.len(), Default::default());
    for (face, normals) in raw.faces.iter().zip(&corner_normals) {
        let mut triangle = [0u32; 3];
        for corner in 0..3 {
            let v = face.vertices[corner];
            let n = normals[corner];
            let key = (v, face.part, [n.x.to_bits(), n.y.to_bits(), n.z.to_bits()]);
            triangle[corner] = *index_of.entry(key).or_insert_with(|| {
                mesh.positions.push(positions[v as usize]);
                mesh.normals.push(n);
                mesh.temperatures.push(temperature.at(v, face.part));
                (mesh.positions.len() - 1) as u32
            });
        }
        mesh.triangles.push(triangle);
        mesh.triangle_surface
            .push(setup.part_surface[face.part as usize]);
    }
    Ok((mesh, skipped))
}

/// The cross product of a face's edges: its normal with length 2·area.
fn area_normal(face: &RawFace, positions: &[Vector3<f64>]) -> Vector3<f64> {
    let [a, b, c] = face.vertices.map(|i| positions[i as usize]);
    (b - a).cross(&(c - a))
}

/// Faces kept to those with an area (one degenerate face in a scanned mesh is
/// common and should not reject the whole mesh), and a warning naming the skipped ones. Refused
/// only when no face remains.
fn without_degenerate_faces(
    raw: &RawMesh,
    positions: &[Vector3<f64>],
) -> Result<(RawMesh, Option<String>), MeshError> {
    // Positions are finite here (checked by the caller), so the cross products are too.
    let extent = bounding_diagonal(positions);
    // Relative to the mesh size, so that millimetre and kilometre meshes are judged alike.
    let min_double_area = 1e-12 * extent * extent;
    let degenerate = |face: &RawFace| {
        let [a, b, c] = face.vertices;
        a == b || b == c || a == c || area_normal(face, positions).norm() <= min_double_area
    };
    let (skipped, faces): (Vec<RawFace>, Vec<RawFace>) =
        raw.faces.iter().cloned().partition(|f| degenerate(f));
    let describe = |f: &RawFace| format!("{} (part '{}')", f.origin, raw.parts[f.part as usize]);
    if faces.is_empty() && !skipped.is_empty() {
        return Err(format!(
            "every triangle is degenerate (zero area), e.g. {}",
            describe(&skipped[0])
        )
        .into());
    }
    let warning = (!skipped.is_empty()).then(|| {
        let shown: Vec<String> = skipped.iter().take(5).map(describe).collect();
        let more = if skipped.len() > 5 { ", …" } else { "" };
        format!(
            "skipped {} degenerate (zero-area) triangle(s): {}{more}",
            skipped.len(),
            shown.join(", ")
        )
    });
    Ok((
        RawMesh {
            faces,
            ..raw.clone()
        },
        warning,
    ))
}

/// Diagonal of the bounding box of `positions` (m); 0 for none.
pub fn bounding_diagonal(positions: &[Vector3<f64>]) -> f64 {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in positions {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    if positions.is_empty() {
        0.0
    } else {
        (hi - lo).norm()
    }
}

/// The temperature of each shading vertex: the file's per raw vertex, or its part's own (shading
/// vertices are split per part, so a vertex shared by parts has a copy at each one's temperature).
enum VertexTemperatures<'a> {
    File(&'a [f64]),
    Part(&'a [Option<f64>]),
}

impl<'a> VertexTemperatures<'a> {
    /// Refused: a file temperature out of range, or a part with faces and no temperature.
    fn of(
        raw: &'a RawMesh,
        part_temperature: &'a [Option<f64>],
    ) -> Result<VertexTemperatures<'a>, MeshError> {
        if let Some(temperatures) = &raw.vertex_temperatures {
            if let Some(i) = temperatures
                .iter()
                .position(|t| !super::valid_temperature(*t))
            {
                return Err(format!(
                    "vertex {} has temperature {} K: temperatures must be within [0, {}] K",
                    i + 1,
                    crate::text::number(temperatures[i]),
                    super::MAX_TEMPERATURE_K
                )
                .into());
            }
            return Ok(VertexTemperatures::File(temperatures));
        }
        if let Some(face) = raw
            .faces
            .iter()
            .find(|f| part_temperature[f.part as usize].is_none())
        {
            return Err(format!(
                "part '{}' has no temperature (set temperature_k on the object or the part)",
                raw.parts[face.part as usize]
            )
            .into());
        }
        Ok(VertexTemperatures::Part(part_temperature))
    }

    /// The temperature of raw vertex `v` on a face of `part`.
    fn at(&self, v: u32, part: u32) -> f64 {
        match self {
            VertexTemperatures::File(t) => t[v as usize],
            VertexTemperatures::Part(t) => t[part as usize].unwrap_or(0.0),
        }
    }
}

/// Unit normal at each face corner: the file's normals when given, otherwise the area-weighted
/// average of the same part's faces around the vertex that bend by less than the crease angle.
fn corner_normals(
    raw: &RawMesh,
    setup: &ObjectShading,
    face_normals: &[Vector3<f64>],
) -> Result<Vec<[Vector3<f64>; 3]>, MeshError> {
    let mut faces_at: Vec<Vec<u32>> = vec![Vec::new(); raw.positions.len()];
    for (f, face) in raw.faces.iter().enumerate() {
        if face.normals.is_none() {
            for &v in &face.vertices {
                faces_at[v as usize].push(f as u32);
            }
        }
    }
    let cos_crease = setup.crease_angle_deg.to_radians().cos();
    raw.faces
        .iter()
        .enumerate()
        .map(|(f, face)| {
            let own = face_normals[f].normalize();
            let mut corners = [Vector3::zeros(); 3];
            for corner in 0..3 {
                corners[corner] = match face.normals {
                    Some(indices) => {
                        let n = setup
                            .transform
                            .normal(&raw.normals[indices[corner] as usize]);
                        let length = n.norm();
                        if !(length > 1e-12 && length.is_finite()) {
                            return Err(format!(
                                "{}: vertex normal {} is zero or not finite",
                                face.origin,
                                indices[corner] + 1
                            )
                            .into());
                        }
                        n / length
                    }
                    None => {
                        let mut sum = Vector3::zeros();
                        for &g in &faces_at[face.vertices[corner] as usize] {
                            let other = &face_normals[g as usize];
                            if raw.faces[g as usize].part == face.part
                                && other.normalize().dot(&own) >= cos_crease
                            {
                                sum += other;
                            }
                        }
                        sum.normalize()
                    }
                };
            }
            Ok(corners)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_with_two_parts() -> RawMesh {
        // Two triangles sharing the edge (1, 2), each its own part.
        let mut raw = RawMesh {
            positions: vec![
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0),
                Vector3::new(1.0, 1.0, 0.0),
            ],
            ..RawMesh::default()
        };
        let a = raw.part_index("a");
        let b = raw.part_index("b");
        raw.faces = vec![
            RawFace {
                vertices: [0, 1, 2],
                normals: None,
                part: a,
                origin: FaceOrigin::Index(1),
            },
            RawFace {
                vertices: [2, 1, 3],
                normals: None,
                part: b,
                origin: FaceOrigin::Index(2),
            },
        ];
        raw
    }

    fn shading<'a>(temps: &'a [Option<f64>], surfaces: &'a [u32]) -> ObjectShading<'a> {
        ObjectShading {
            transform: Transform::new(1.0, [0.0; 3], [0.0; 3]),
            crease_angle_deg: 35.0,
            part_temperature: temps,
            part_surface: surfaces,
        }
    }

    #[test]
    fn shared_vertices_keep_each_part_temperature() {
        let raw = square_with_two_parts();
        let temps = [Some(300.0), Some(320.0)];
        let (mesh, _) = shade_mesh(&raw, &shading(&temps, &[0, 1])).unwrap();
        // Vertices 1 and 2 are split per part, each copy at its own part's temperature.
        assert_eq!(mesh.positions.len(), 6);
        let t_of = |p: Vector3<f64>| {
            mesh.positions
                .iter()
                .zip(&mesh.temperatures)
                .filter(|(q, _)| (*q - p).norm() < 1e-12)
                .map(|(_, t)| *t)
                .collect::<Vec<_>>()
        };
        assert_eq!(t_of(Vector3::new(1.0, 0.0, 0.0)), vec![300.0, 320.0]);
        assert_eq!(t_of(Vector3::new(0.0, 1.0, 0.0)), vec![300.0, 320.0]);
        assert_eq!(t_of(Vector3::new(0.0, 0.0, 0.0)), vec![300.0]);
        assert_eq!(t_of(Vector3::new(1.0, 1.0, 0.0)), vec![320.0]);
        assert_eq!(mesh.triangle_surface, vec![0, 1]);
        assert!(mesh
            .normals
            .iter()
            .all(|n| (n - Vector3::z()).norm() < 1e-12));
    }

    #[test]
    fn transform_scales_rotates_then_translates() {
        let t = Transform::new(2.0, [0.0, 0.0, 90.0], [1.0, 0.0, 0.0]);
        let p = t.point(&Vector3::new(1.0, 0.0, 0.0));
        assert!((p - Vector3::new(1.0, 2.0, 0.0)).norm() < 1e-12);
        let n = t.normal(&Vector3::new(1.0, 0.0, 0.0));
        assert!((n - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn degenerate_faces_are_skipped_and_non_finite_geometry_is_refused() {
        let mut raw = square_with_two_parts();
        raw.positions[3] = Vector3::new(0.5, 0.5, 0.0); // on the shared edge: zero area
        let temps = [Some(300.0), Some(320.0)];
        let (mesh, warning) = shade_mesh(&raw, &shading(&temps, &[0, 1])).unwrap();
        assert_eq!(mesh.triangles.len(), 1);
        let warning = warning.unwrap();
        assert!(
            warning.contains("skipped 1 degenerate") && warning.contains("face 2 (part 'b')"),
            "{warning}"
        );
        raw.faces.remove(0);
        let err = shade_mesh(&raw, &shading(&temps, &[0, 1]))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("every triangle is degenerate") && err.contains("'b'"),
            "{err}"
        );
        raw.positions[3] = Vector3::new(f64::NAN, 0.5, 0.0);
        let err = shade_mesh(&raw, &shading(&temps, &[0, 1]))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("vertex 4") && err.contains("non-finite"),
            "{err}"
        );
    }

    #[test]
    fn a_part_without_temperature_is_named() {
        let raw = square_with_two_parts();
        let err = shade_mesh(&raw, &shading(&[Some(1.0), None], &[0, 1]))
            .unwrap_err()
            .to_string();
        assert!(err.contains("part 'b' has no temperature"), "{err}");
    }

    #[test]
    fn creases_split_normals_and_smooth_faces_share_them() {
        // A roof ridge: two faces meeting at 20° are smoothed, at 90° they are not.
        for (angle_deg, smoothed) in [(20.0f64, true), (90.0, false)] {
            let half = (angle_deg / 2.0).to_radians();
            let mut raw = RawMesh {
                positions: vec![
                    Vector3::new(0.0, 0.0, 0.0),
                    Vector3::new(0.0, 1.0, 0.0),
                    Vector3::new(half.cos(), 0.0, -half.sin()),
                    Vector3::new(-half.cos(), 0.0, -half.sin()),
                ],
                ..RawMesh::default()
            };
            let p = raw.part_index("roof");
            raw.faces = vec![
                RawFace {
                    vertices: [0, 2, 1],
                    normals: None,
                    part: p,
                    origin: FaceOrigin::Index(1),
                },
                RawFace {
                    vertices: [0, 1, 3],
                    normals: None,
                    part: p,
                    origin: FaceOrigin::Index(2),
                },
            ];
            let (mesh, _) = shade_mesh(&raw, &shading(&[Some(1.0)], &[0])).unwrap();
            let distinct = if smoothed { 4 } else { 6 };
            assert_eq!(mesh.positions.len(), distinct, "angle {angle_deg}");
            if smoothed {
                let ridge = mesh.triangles[0][0] as usize;
                assert!((mesh.normals[ridge] - Vector3::z()).norm() < 1e-12);
            }
        }
    }
}
