//! PLY meshes (ASCII or binary): `vertex` elements with x, y, z, optional nx, ny, nz and an
//! optional per-vertex `temperature` (K; docs/design.md §2.3), and `face` elements with a
//! `vertex_indices` (or `vertex_index`) list. A PLY has no groups: all faces form one part,
//! named `surface`.
//!
//! The header is read by `ply-rs-bw` (its grammar knows every type name and alias, comments and
//! `obj_info`) and checked before the payload: each element's count must fit in the bytes that
//! follow the header (every item takes at least its fixed-size properties in binary, a digit and
//! a separator per property in ASCII) and stay within [`MAX_PLY_ITEMS`], so a few hundred bytes
//! declaring 4 294 967 295 faces are refused before anything is reserved.
//!
//! Binary payloads are then read directly from the bytes ([`binary`]): the parser keeps every
//! item as a map of named properties, a few hundred bytes and several allocations each, which
//! made a million-triangle file take a second and 0.9 GB. ASCII payloads stay with the parser:
//! they are small (a mesh of millions of triangles is not written as text) and its tokenizer
//! handles the text forms a direct reader would have to repeat.

mod binary;

use super::mesh::{FaceOrigin, MeshError, RawFace, RawMesh};
use crate::text::{shown, shown_at_most};
use nalgebra::Vector3;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    DefaultElement, ElementDef, Encoding, Header, Property, PropertyType, ScalarType,
};

/// The single part of a PLY mesh.
pub const PLY_PART: &str = "surface";

/// Most items (vertices, faces, or items of any other element) a PLY element may declare. The
/// parser behind ASCII files keeps every item as a map of named properties, a few hundred bytes
/// each, so this keeps a mesh's memory to a few GB; 10 million triangles is far beyond what a
/// scene of this renderer needs.
pub const MAX_PLY_ITEMS: usize = 10_000_000;

/// Characters of the parser's own message kept in ours (it quotes whole input lines).
const PARSER_MESSAGE_CHARS: usize = 160;

/// The vertex properties irpol reads, in the order their values are checked.
const VERTEX_KEYS: [&str; 7] = ["x", "y", "z", "nx", "ny", "nz", "temperature"];

/// Reads a PLY file: binary payloads directly, ASCII ones through the parser.
pub fn parse_ply(bytes: &[u8]) -> Result<RawMesh, MeshError> {
    let (header, reader) = read_header_checked(bytes)?;
    let payload = reader.get_ref();
    match header.encoding {
        Encoding::Ascii => mesh_through_parser(&header, reader),
        Encoding::BinaryLittleEndian => binary::read_mesh(&header, payload, binary::Order::Little),
        Encoding::BinaryBigEndian => binary::read_mesh(&header, payload, binary::Order::Big),
    }
}

/// [`parse_ply`] with the payload read item by item through the parser whatever the encoding,
/// as every file was before the direct binary reader: kept so that the benchmark
/// (`benches/mesh.rs`) and the tests compare the two readers on the same files.
#[doc(hidden)]
pub fn parse_ply_through_parser(bytes: &[u8]) -> Result<RawMesh, MeshError> {
    let (header, reader) = read_header_checked(bytes)?;
    mesh_through_parser(&header, reader)
}

fn mesh_through_parser(header: &Header, mut reader: Reader<&[u8]>) -> Result<RawMesh, MeshError> {
    let payload = Parser::<DefaultElement>::new()
        .read_payload(&mut reader, header)
        .map_err(|e| unreadable(&e))?;
    let vertices = payload
        .get("vertex")
        .ok_or("the PLY file has no 'vertex' element")?;
    let faces = payload
        .get("face")
        .ok_or("the PLY file has no 'face' element")?;

    let mut mesh = RawMesh::default();
    let part = mesh.part_index(PLY_PART);
    let has_normals = read_vertices(vertices, &mut mesh)?;
    read_faces(faces, part, has_normals, &mut mesh)?;
    if mesh.faces.is_empty() {
        return Err("the mesh has no faces".into());
    }
    Ok(mesh)
}

/// The `vertex` element's positions, and normals and temperatures where every vertex has them;
/// returns whether it has normals.
fn read_vertices(vertices: &[DefaultElement], mesh: &mut RawMesh) -> Result<bool, MeshError> {
    let has_normals = vertices
        .first()
        .is_some_and(|v| v.contains_key("nx") && v.contains_key("ny") && v.contains_key("nz"));
    let has_temperature = vertices
        .first()
        .is_some_and(|v| v.contains_key("temperature"));
    if let Some(first) = vertices.first() {
        mesh.notes = temperature_notes(first.keys().map(String::as_str), has_temperature);
    }
    let mut temperatures = Vec::new();
    for (i, vertex) in vertices.iter().enumerate() {
        let scalar = |key: &str| -> Result<f64, MeshError> {
            let value = vertex
                .get(key)
                .and_then(scalar_value)
                .ok_or_else(|| no_numeric_property(i, key))?;
            finite(value, i, key)
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

    Ok(has_normals)
}

/// The notes for vertex properties named like a temperature (`names` in header order) when
/// the vertices have no `temperature` itself.
fn temperature_notes<'a>(
    names: impl Iterator<Item = &'a str>,
    has_temperature: bool,
) -> Vec<String> {
    names
        .filter(|k| looks_like_temperature(k) && !has_temperature)
        .map(|k| {
            format!(
                "vertex property '{k}' looks like a temperature but is ignored: irpol \
                 reads per-vertex temperatures (K) only from a property named 'temperature'"
            )
        })
        .collect()
}

/// Vertex `i` (from 0) lacks scalar property `key`.
fn no_numeric_property(i: usize, key: &str) -> MeshError {
    format!("vertex {}: no numeric property '{key}'", i + 1).into()
}

/// `value` of property `key` of vertex `i` (from 0), refused unless finite.
fn finite(value: f64, i: usize, key: &str) -> Result<f64, MeshError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("vertex {}: property '{key}' is not finite", i + 1).into())
    }
}

/// The `face` element's polygons, split into triangle fans of part `part`.
fn read_faces(
    faces: &[DefaultElement],
    part: u32,
    has_normals: bool,
    mesh: &mut RawMesh,
) -> Result<(), MeshError> {
    let vertex_count = mesh.positions.len();
    for (f, face) in faces.iter().enumerate() {
        let origin = FaceOrigin::Index(f + 1);
        let indices = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .and_then(list_value)
            .ok_or_else(|| format!("{origin}: no integer list 'vertex_indices'"))?;
        let polygon = Polygon {
            origin,
            part,
            has_normals,
            vertex_count,
        };
        polygon.push(&indices, mesh)?;
    }
    Ok(())
}

/// One face of a PLY and what its triangles need.
struct Polygon {
    origin: FaceOrigin,
    part: u32,
    has_normals: bool,
    /// Vertices the file declares: indices must be below.
    vertex_count: usize,
}

impl Polygon {
    /// Checks the face's vertex `indices` and appends it as a triangle fan.
    fn push(&self, indices: &[i64], mesh: &mut RawMesh) -> Result<(), MeshError> {
        let origin = self.origin;
        if indices.len() < 3 {
            return Err(format!("{origin}: a face needs at least 3 vertices").into());
        }
        if let Some(bad) = indices
            .iter()
            .find(|&&v| v < 0 || v as u64 >= self.vertex_count as u64)
        {
            return Err(format!(
                "{origin}: vertex index {bad} is out of range ({} vertices)",
                self.vertex_count
            )
            .into());
        }
        for i in 1..indices.len() - 1 {
            let vertices = [indices[0], indices[i], indices[i + 1]].map(|v| v as u32);
            mesh.faces.push(RawFace {
                vertices,
                normals: self.has_normals.then_some(vertices),
                part: self.part,
                origin,
            });
        }
        Ok(())
    }
}

/// Reads and checks the header ([`check_unique_declarations`], [`check_header`]); returns it
/// with the reader at the payload (the parser numbers payload lines from the header's).
fn read_header_checked(bytes: &[u8]) -> Result<(Header, Reader<&[u8]>), MeshError> {
    check_unique_declarations(bytes)?;
    let parser = Parser::<DefaultElement>::new();
    let mut reader = Reader::new(bytes);
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| unreadable(&e))?;
    // The reader advances through the slice, so what it still holds is the payload.
    check_header(&header, reader.get_ref().len())?;
    Ok((header, reader))
}

fn unreadable(e: &dyn std::fmt::Display) -> MeshError {
    MeshError::from(format!(
        "not a readable PLY file: {}",
        shown_at_most(&e.to_string(), PARSER_MESSAGE_CHARS)
    ))
}

/// Refuses an element declared twice, or a property declared twice in one element. The parser
/// keys both by name, so a second declaration would silently replace the first while the payload
/// still holds values for both: the items would be read misaligned.
fn check_unique_declarations(bytes: &[u8]) -> Result<(), MeshError> {
    let mut elements: Vec<(&[u8], usize)> = Vec::new();
    let mut properties: Vec<(&[u8], usize)> = Vec::new();
    for (index, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let words: Vec<&[u8]> = line
            .split(u8::is_ascii_whitespace)
            .filter(|w| !w.is_empty())
            .collect();
        let (first, name) = match words.as_slice() {
            [b"end_header", ..] => break,
            [b"element", name, ..] => (None, *name),
            [b"property", b"list", _, _, name, ..] | [b"property", _, name, ..] => {
                (elements.last().map(|e| e.0), *name)
            }
            _ => continue,
        };
        let line = index + 1;
        let (seen, what) = match first {
            None => {
                properties.clear();
                (&mut elements, "element".to_owned())
            }
            Some(element) => (
                &mut properties,
                format!(
                    "element '{}': property",
                    shown(&String::from_utf8_lossy(element))
                ),
            ),
        };
        if let Some((_, earlier)) = seen.iter().find(|(n, _)| *n == name) {
            return Err(format!(
                "header line {line}: {what} '{}' is declared twice (first on line {earlier}); \
                 remove one declaration",
                shown(&String::from_utf8_lossy(name))
            )
            .into());
        }
        seen.push((name, line));
    }
    Ok(())
}

/// Refuses versions other than 1.0 (the only PLY standard) and element counts that the payload's
/// `payload_bytes` cannot hold or that exceed [`MAX_PLY_ITEMS`].
fn check_header(header: &Header, payload_bytes: usize) -> Result<(), MeshError> {
    let version = header.version;
    if (version.major, version.minor) != (1, 0) {
        return Err(format!("PLY version {version} is not supported (only 1.0 exists)").into());
    }
    let mut needed: u128 = 0;
    for element in header.elements.values() {
        let name = shown(&element.name);
        if element.count > MAX_PLY_ITEMS {
            return Err(format!(
                "element '{name}' declares {} items; at most {MAX_PLY_ITEMS} are read",
                element.count
            )
            .into());
        }
        let per_item = least_item_bytes(element, header.encoding);
        if per_item == 0 && element.count > 0 {
            return Err(format!(
                "element '{name}' declares {} items but no properties",
                element.count
            )
            .into());
        }
        needed += element.count as u128 * per_item as u128;
    }
    // An ASCII file may end without its last line break.
    let slack = u128::from(header.encoding == Encoding::Ascii);
    if needed > payload_bytes as u128 + slack {
        return Err(format!(
            "the header declares items that need at least {needed} bytes, but only \
             {payload_bytes} bytes follow it (a truncated file or a wrong element count)"
        )
        .into());
    }
    Ok(())
}

/// The fewest bytes one item of `element` takes: its fixed-size scalars and list counts in binary
/// (a list may be empty); in ASCII one digit and one separator or line break per property.
fn least_item_bytes(element: &ElementDef, encoding: Encoding) -> usize {
    element
        .properties
        .values()
        .map(|property| match (encoding, &property.data_type) {
            (Encoding::Ascii, _) => 2,
            (_, PropertyType::Scalar(scalar) | PropertyType::List(scalar, _)) => {
                scalar_bytes(scalar)
            }
        })
        .sum()
}

fn scalar_bytes(scalar: &ScalarType) -> usize {
    match scalar {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// A vertex property name a user likely meant as the temperature (`temp`, `Temperature`,
/// `temperature_k`, `T`, …), other than the exact `temperature` irpol reads.
fn looks_like_temperature(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    name != "temperature"
        && (lower.starts_with("temp") || lower == "t" || lower == "t_k" || lower == "kelvin")
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

    #[test]
    fn temperature_like_properties_are_noted() {
        let text = TRIANGLE.replace("property float temperature", "property float Temperature");
        let mesh = parse_ply(text.as_bytes()).unwrap();
        assert!(mesh.vertex_temperatures.is_none());
        assert_eq!(mesh.notes.len(), 1);
        assert!(
            mesh.notes[0].contains("'Temperature' looks like a temperature"),
            "{:?}",
            mesh.notes
        );
        assert!(parse_ply(TRIANGLE.as_bytes()).unwrap().notes.is_empty());
    }

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
        let err = parse_ply(out_of_range.as_bytes()).unwrap_err().to_string();
        assert!(
            err.starts_with("face 1: vertex index 7 is out of range"),
            "{err}"
        );
        let nan = TRIANGLE.replace("1 0 0 310", "1 nan 0 310");
        let err = parse_ply(nan.as_bytes()).unwrap_err().to_string();
        assert!(err.contains("vertex 2") || err.contains("PLY"), "{err}");
        assert!(parse_ply(b"not a ply").is_err());
    }

    #[test]
    fn counts_the_payload_cannot_hold_are_refused_before_reading() {
        let header = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
            property float y\nproperty float z\nelement face 4294967295\n\
            property list uchar int vertex_indices\nend_header\n";
        let mut bytes = header.as_bytes().to_vec();
        bytes.extend(std::iter::repeat_n(0u8, 36 + 13));
        let err = parse_ply(&bytes).unwrap_err().to_string();
        assert!(err.contains("at most 10000000"), "{err}");
        let declared = header.replace("4294967295", "1000");
        let mut bytes = declared.as_bytes().to_vec();
        bytes.extend(std::iter::repeat_n(0u8, 36 + 13));
        let err = parse_ply(&bytes).unwrap_err().to_string();
        assert!(err.contains("only 49 bytes follow"), "{err}");
        let empty_element =
            TRIANGLE.replace("element face 1\n", "element junk 5\nelement face 1\n");
        let err = parse_ply(empty_element.as_bytes()).unwrap_err().to_string();
        assert!(
            err.contains("'junk' declares 5 items but no properties"),
            "{err}"
        );
    }

    #[test]
    fn only_version_1_0_is_read_and_a_missing_last_line_break_is_fine() {
        let err = parse_ply(TRIANGLE.replace("ascii 1.0", "ascii 7.5").as_bytes())
            .unwrap_err()
            .to_string();
        assert!(err.contains("PLY version 7.5 is not supported"), "{err}");
        let unterminated = TRIANGLE.trim_end();
        assert_eq!(parse_ply(unterminated.as_bytes()).unwrap().faces.len(), 2);
    }

    #[test]
    fn parser_messages_are_one_short_line() {
        let bad = TRIANGLE.replace(
            "0 0 0 300",
            &format!("0 0 \u{1b}[31m{} 300", "9".repeat(5000)),
        );
        let err = parse_ply(bad.as_bytes()).unwrap_err().to_string();
        assert!(
            !err.contains('\u{1b}') && !err.contains('\n') && err.len() < 400,
            "{err}"
        );
    }
}
