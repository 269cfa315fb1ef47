//! Wavefront OBJ: `v`, `vn`, `f` (any of `v`, `v/vt`, `v//vn`, `v/vt/vn`, negative indices
//! relative to the end), `g`/`o` start a part (docs/design.md §2.3: groups are parts). Polygons are split
//! into triangle fans. Texture and material statements are accepted and ignored; anything else is
//! refused so that a corrupt file is not half-read. Errors read `line N: what is wrong`.
//!
//! Own reader rather than a crate because part boundaries must keep the file's vertex indices (the
//! raw mesh is the file's topology; shading splits vertices per part) and every error must name
//! its line: `tobj` re-indexes vertices per model and its `LoadError`
//! variants (`PositionParseError`, `FaceParseError`, …) carry no line or column.

use super::mesh::{FaceOrigin, MeshError, RawFace, RawMesh};
use crate::text::shown;
use nalgebra::Vector3;
use std::fmt::Write as _;

/// Statements that carry nothing the renderer uses.
const IGNORED: &[&str] = &["vt", "vp", "s", "usemtl", "mtllib", "l", "p"];

pub fn parse_obj(text: &str) -> Result<RawMesh, MeshError> {
    let mut mesh = RawMesh::default();
    let mut part: Option<u32> = None;
    for (number, line) in text.lines().enumerate() {
        let line_no = number + 1;
        let content = line.split('#').next().unwrap_or("").trim();
        let mut fields = content.split_whitespace();
        let Some(keyword) = fields.next() else {
            continue;
        };
        let at = |error: MeshError| MeshError::Line {
            line: line_no,
            message: error.to_string(),
        };
        match keyword {
            "v" => {
                let numbers = parse_numbers(fields).map_err(at)?;
                // x y z, optionally w (3+1) or a vertex colour (3+3).
                if !matches!(numbers.len(), 3 | 4 | 6) {
                    return Err(at(format!(
                        "a vertex needs 3 coordinates, got {}",
                        numbers.len()
                    )
                    .into()));
                }
                let v = Vector3::new(numbers[0], numbers[1], numbers[2]);
                if !v.iter().all(|c| c.is_finite()) {
                    return Err(at(format!(
                        "vertex {} has a non-finite coordinate",
                        mesh.positions.len() + 1
                    )
                    .into()));
                }
                mesh.positions.push(v);
            }
            "vn" => {
                let numbers = parse_numbers(fields).map_err(at)?;
                if numbers.len() != 3 || !numbers.iter().all(|c| c.is_finite()) {
                    return Err(at("a normal needs 3 finite components".into()));
                }
                mesh.normals
                    .push(Vector3::new(numbers[0], numbers[1], numbers[2]));
            }
            "f" => {
                let part = *part.get_or_insert_with(|| mesh.part_index("default"));
                push_face(&mut mesh, fields, part, line_no).map_err(at)?;
            }
            "g" | "o" => {
                let name = fields.collect::<Vec<_>>().join(" ");
                check_part_name(&name).map_err(at)?;
                let name = if name.is_empty() { "default" } else { &name };
                part = Some(mesh.part_index(name));
            }
            other if IGNORED.contains(&other) => {}
            other => {
                return Err(at(
                    format!("unsupported OBJ statement '{}'", shown(other)).into()
                ))
            }
        }
    }
    if mesh.faces.is_empty() {
        return Err("the mesh has no faces".into());
    }
    Ok(mesh)
}

/// Splits an `f` statement's polygon into a triangle fan of part `part`.
fn push_face<'a>(
    mesh: &mut RawMesh,
    fields: impl Iterator<Item = &'a str>,
    part: u32,
    line_no: usize,
) -> Result<(), MeshError> {
    let corners = fields
        .map(|field| parse_corner(field, mesh))
        .collect::<Result<Vec<_>, _>>()?;
    if corners.len() < 3 {
        return Err(format!("a face needs at least 3 vertices, got {}", corners.len()).into());
    }
    let with_normals = corners.iter().filter(|c| c.1.is_some()).count();
    if with_normals != 0 && with_normals != corners.len() {
        return Err("some corners of the face have normals and some do not".into());
    }
    for i in 1..corners.len() - 1 {
        let picked = [corners[0], corners[i], corners[i + 1]];
        mesh.faces.push(RawFace {
            vertices: picked.map(|c| c.0),
            normals: (with_normals > 0).then(|| picked.map(|c| c.1.unwrap_or(0))),
            part,
            origin: FaceOrigin::Line(line_no),
        });
    }
    Ok(())
}

/// Longest group name accepted: part names reach the scene file's part tables and messages.
const MAX_PART_NAME_CHARS: usize = 256;

/// A group name must be text a scene file can name: no control characters, not a whole line of
/// binary junk.
fn check_part_name(name: &str) -> Result<(), MeshError> {
    if name.chars().any(char::is_control) {
        return Err(format!("group name '{}' contains a control character", shown(name)).into());
    }
    if name.chars().count() > MAX_PART_NAME_CHARS {
        return Err(format!(
            "group name '{}' is longer than {MAX_PART_NAME_CHARS} characters",
            shown(name)
        )
        .into());
    }
    Ok(())
}

fn parse_numbers<'a>(fields: impl Iterator<Item = &'a str>) -> Result<Vec<f64>, MeshError> {
    fields
        .map(|f| {
            f.parse::<f64>()
                .map_err(|_| MeshError::from(format!("'{}' is not a number", shown(f))))
        })
        .collect()
}

/// One `f` corner: (0-based vertex index, 0-based normal index if any).
fn parse_corner(field: &str, mesh: &RawMesh) -> Result<(u32, Option<u32>), MeshError> {
    let mut pieces = field.split('/');
    let vertex = resolve_index(pieces.next().unwrap_or(""), mesh.positions.len(), "vertex")?;
    let _texture = pieces.next();
    let normal = match pieces.next() {
        Some(text) if !text.is_empty() => Some(resolve_index(text, mesh.normals.len(), "normal")?),
        _ => None,
    };
    Ok((vertex, normal))
}

/// OBJ indices are 1-based; negative ones count back from the last element defined so far.
fn resolve_index(text: &str, defined: usize, what: &str) -> Result<u32, MeshError> {
    let index: i64 = text
        .parse()
        .map_err(|_| MeshError::from(format!("'{}' is not a {what} index", shown(text))))?;
    let resolved = if index > 0 {
        index - 1
    } else {
        defined as i64 + index
    };
    if index == 0 || resolved < 0 || resolved >= defined as i64 {
        return Err(
            format!("{what} index {index} is out of range ({defined} defined so far)").into(),
        );
    }
    Ok(resolved as u32)
}

/// OBJ text of a mesh: vertices, then faces grouped by part (`g name`). Normals are not written;
/// the reader recomputes them with its crease angle.
pub fn format_obj(mesh: &RawMesh, header: &str) -> String {
    let mut out = String::new();
    for line in header.lines() {
        let _ = writeln!(out, "# {line}");
    }
    for p in &mesh.positions {
        let _ = writeln!(out, "v {:.5} {:.5} {:.5}", p.x, p.y, p.z);
    }
    for (index, name) in mesh.parts.iter().enumerate() {
        let _ = writeln!(out, "g {name}");
        for face in mesh.faces.iter().filter(|f| f.part as usize == index) {
            let [a, b, c] = face.vertices.map(|v| v + 1);
            let _ = writeln!(out, "f {a} {b} {c}");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_become_parts_and_quads_become_fans() {
        let text = "# a box lid\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\n\
                    g lid\nf 1 2 3 4\ng tip\nf -4 -3 5\n";
        let mesh = parse_obj(text).unwrap();
        assert_eq!(mesh.parts, vec!["lid", "tip"]);
        assert_eq!(mesh.faces.len(), 3);
        assert_eq!(mesh.faces[0].vertices, [0, 1, 2]);
        assert_eq!(mesh.faces[1].vertices, [0, 2, 3]);
        assert_eq!(mesh.faces[2].vertices, [1, 2, 4]);
        assert_eq!(mesh.faces[2].part, 1);
        assert_eq!(mesh.faces[2].origin, FaceOrigin::Line(10));
    }

    #[test]
    fn normals_and_texture_coordinates_are_read() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3//1\n";
        let mesh = parse_obj(text).unwrap();
        assert_eq!(mesh.faces[0].normals, Some([0, 0, 0]));
        assert_eq!(mesh.parts, vec!["default"]);
    }

    #[test]
    fn bad_files_name_the_line() {
        let cases = [
            (
                "v 0 0 0\nv 1 0 nan\n",
                "line 2: vertex 2 has a non-finite coordinate",
            ),
            (
                "v 0 0 0\nv 1 0 0\nf 1 2 3\n",
                "line 3: vertex index 3 is out of range",
            ),
            ("v 0 0\n", "line 1: a vertex needs 3 coordinates"),
            ("v 0 0 x\n", "line 1: 'x' is not a number"),
            (
                "v 0 0 0\nbogus 1\n",
                "line 2: unsupported OBJ statement 'bogus'",
            ),
            ("v 0 0 0\n", "the mesh has no faces"),
            (
                "v 0 0 0\n\u{1b}[2J 1\n",
                "line 2: unsupported OBJ statement '\\u{1b}[2J'",
            ),
            (
                "g a\u{7}b\n",
                "line 1: group name 'a\\u{7}b' contains a control",
            ),
        ];
        for (text, expected) in cases {
            let err = parse_obj(text).unwrap_err().to_string();
            assert!(
                err.starts_with(expected),
                "{err:?} should start with {expected:?}"
            );
        }
    }

    #[test]
    fn written_meshes_read_back() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\ng a\nf 1 2 3\ng b\nf 3 2 4\n";
        let mesh = parse_obj(text).unwrap();
        let again = parse_obj(&format_obj(&mesh, "test")).unwrap();
        assert_eq!(again.parts, mesh.parts);
        assert_eq!(again.positions, mesh.positions);
        let faces = |m: &RawMesh| {
            m.faces
                .iter()
                .map(|f| (f.vertices, f.part))
                .collect::<Vec<_>>()
        };
        assert_eq!(faces(&again), faces(&mesh));
    }
}
