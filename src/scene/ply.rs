//! PLY meshes (ASCII or binary, via `ply-rs-bw`): `vertex` elements with x, y, z, optional
//! nx, ny, nz and an optional per-vertex `temperature` (K; DESIGN §2.3), and `face` elements with
//! a `vertex_indices` (or `vertex_index`) list. A PLY has no groups: all faces form one part,
//! named `surface`.

use super::mesh::{FaceOrigin, RawFace, RawMesh};
use nalgebra::Vector3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

/// The single part of a PLY mesh.
pub const PLY_PART: &str = "surface";

pub fn parse_ply(mut bytes: &[u8]) -> Result<RawMesh, String> {
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut bytes)
        .map_err(|e| format!("not a readable PLY file: {e}"))?;
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or("the PLY file has no 'vertex' element")?;
    let faces = ply
        .payload
        .get("face")
        .ok_or("the PLY file has no 'face' element")?;

    let mut mesh = RawMesh::default();
    let part = mesh.part_index(PLY_PART);
    let has_normals = vertices
        .first()
        .is_some_and(|v| v.contains_key("nx") && v.contains_key("ny") && v.contains_key("nz"));
    let has_temperature = vertices
        .first()
        .is_some_and(|v| v.contains_key("temperature"));
    let mut temperatures = Vec::new();
    for (i, vertex) in vertices.iter().enumerate() {
        let scalar = |key: &str| -> Result<f64, String> {
            let value = vertex
                .get(key)
                .and_then(scalar_value)
                .ok_or_else(|| format!("vertex {}: no numeric property '{key}'", i + 1))?;
            if value.is_finite() {
                Ok(value)
            } else {
                Err(format!("vertex {}: property '{key}' is not finite", i + 1))
            }
        };
        mesh.positions
            .push(Vector3::new(scalar("x")?, scalar("y")?, scalar("z")?));
        if has_normals {
            mesh.normals
                .push(Vector3::new(scalar("nx")?, scalar("ny")?, scalar("nz")?));
        }
        if has_temperature {
            temperatures.push(scalar("temperature")?);
        }
    }
    if has_temperature {
        mesh.vertex_temperatures = Some(temperatures);
    }

    for (f, face) in faces.iter().enumerate() {
        let origin = FaceOrigin::Index(f + 1);
        let indices = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .and_then(list_value)
            .ok_or_else(|| format!("{origin}: no integer list 'vertex_indices'"))?;
        if indices.len() < 3 {
            return Err(format!("{origin}: a face needs at least 3 vertices"));
        }
        if let Some(bad) = indices
            .iter()
            .find(|&&v| v < 0 || v as usize >= mesh.positions.len())
        {
            return Err(format!(
                "{origin}: vertex index {bad} is out of range ({} vertices)",
                mesh.positions.len()
            ));
        }
        for i in 1..indices.len() - 1 {
            let vertices = [indices[0], indices[i], indices[i + 1]].map(|v| v as u32);
            mesh.faces.push(RawFace {
                vertices,
                normals: has_normals.then_some(vertices),
                part,
                origin,
            });
        }
    }
    if mesh.faces.is_empty() {
        return Err("the mesh has no faces".into());
    }
    Ok(mesh)
}

fn scalar_value(property: &Property) -> Option<f64> {
    Some(match *property {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

fn list_value(property: &Property) -> Option<Vec<i64>> {
    Some(match property {
        Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRIANGLE: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n\
        property float y\nproperty float z\nproperty float temperature\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n\
        0 0 0 300\n1 0 0 310\n0 1 0 320\n1 1 0 330\n4 0 1 3 2\n";

    #[test]
    fn reads_positions_temperatures_and_splits_polygons() {
        let mesh = parse_ply(TRIANGLE.as_bytes()).unwrap();
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(
            mesh.vertex_temperatures,
            Some(vec![300.0, 310.0, 320.0, 330.0])
        );
        assert_eq!(mesh.faces.len(), 2);
        assert_eq!(mesh.faces[1].vertices, [0, 3, 2]);
        assert_eq!(mesh.parts, vec![PLY_PART]);
    }

    #[test]
    fn bad_faces_and_values_are_named() {
        let out_of_range = TRIANGLE.replace("4 0 1 3 2", "3 0 1 7");
        let err = parse_ply(out_of_range.as_bytes()).unwrap_err();
        assert!(
            err.starts_with("face 1: vertex index 7 is out of range"),
            "{err}"
        );
        let nan = TRIANGLE.replace("1 0 0 310", "1 nan 0 310");
        let err = parse_ply(nan.as_bytes()).unwrap_err();
        assert!(err.contains("vertex 2") || err.contains("PLY"), "{err}");
        assert!(parse_ply(b"not a ply").is_err());
    }
}
