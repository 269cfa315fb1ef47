//! The binary PLY payload read directly from its bytes: each element's items in header order,
//! every property decoded in place from its byte order (`from_le_bytes` / `from_be_bytes`) into
//! the mesh's own arrays, with no per-item map. Vertex properties may be of any scalar type,
//! face lists of any integer count and index types; properties irpol does not read, and
//! elements other than `vertex` and `face`, are skipped by their size.
//!
//! Every read takes its bytes through [`Bytes`], which yields `None` at the end of the payload
//! instead of indexing past it; list sizes are multiplied with checked arithmetic. The header
//! check has already bounded the element counts by the payload's length.

use super::{finite, no_numeric_property, temperature_notes, Polygon, PLY_PART, VERTEX_KEYS};
use crate::scene::mesh::{FaceOrigin, MeshError, RawMesh};
use crate::text::shown;
use nalgebra::Vector3;
use ply_rs_bw::ply::{ElementDef, Header, PropertyType, ScalarType};

/// The byte order of a binary payload.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    Little,
    Big,
}

/// A PLY scalar type (the parser's `ScalarType`, which is not `Copy`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Number {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Number {
    fn of(scalar: &ScalarType) -> Number {
        match scalar {
            ScalarType::Char => Number::I8,
            ScalarType::UChar => Number::U8,
            ScalarType::Short => Number::I16,
            ScalarType::UShort => Number::U16,
            ScalarType::Int => Number::I32,
            ScalarType::UInt => Number::U32,
            ScalarType::Float => Number::F32,
            ScalarType::Double => Number::F64,
        }
    }

    fn size(self) -> usize {
        match self {
            Number::I8 | Number::U8 => 1,
            Number::I16 | Number::U16 => 2,
            Number::I32 | Number::U32 | Number::F32 => 4,
            Number::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Number::F32 | Number::F64)
    }
}

/// How a property is laid out in each item.
#[derive(Clone, Copy, Debug)]
enum Field {
    Scalar(Number),
    List { length: Number, item: Number },
}

/// One property of an element: its name, layout, and for the vertex properties irpol reads, the
/// index of its value in [`VERTEX_KEYS`].
struct Column<'h> {
    name: &'h str,
    field: Field,
    slot: Option<usize>,
}

/// The columns of `element` in header (and payload) order.
fn columns(element: &ElementDef) -> Vec<Column<'_>> {
    element
        .properties
        .values()
        .map(|property| Column {
            name: &property.name,
            field: match &property.data_type {
                PropertyType::Scalar(scalar) => Field::Scalar(Number::of(scalar)),
                PropertyType::List(length, item) => Field::List {
                    length: Number::of(length),
                    item: Number::of(item),
                },
            },
            slot: None,
        })
        .collect()
}

/// The payload not yet read.
struct Bytes<'a> {
    rest: &'a [u8],
    order: Order,
    /// The payload's whole length, for the offsets in messages.
    total: usize,
}

/// A read that fails leaves the payload where it was, so `offset` then points at the value
/// that did not fit.
impl<'a> Bytes<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let (head, tail) = self.rest.split_at_checked(n)?;
        self.rest = tail;
        Some(head)
    }

    fn array<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, tail) = self.rest.split_first_chunk::<N>()?;
        self.rest = tail;
        Some(*head)
    }

    /// The next value of type `number`; every PLY type is exact in f64.
    fn number(&mut self, number: Number) -> Option<f64> {
        macro_rules! read {
            ($t:ty) => {{
                let raw = self.array()?;
                (match self.order {
                    Order::Little => <$t>::from_le_bytes(raw),
                    Order::Big => <$t>::from_be_bytes(raw),
                }) as f64
            }};
        }
        Some(match number {
            Number::I8 => read!(i8),
            Number::U8 => read!(u8),
            Number::I16 => read!(i16),
            Number::U16 => read!(u16),
            Number::I32 => read!(i32),
            Number::U32 => read!(u32),
            Number::F32 => read!(f32),
            Number::F64 => read!(f64),
        })
    }

    fn offset(&self) -> usize {
        self.total - self.rest.len()
    }
}

/// Where a message points: item `index` (from 0) of `element`, at `property`.
struct Place<'h> {
    element: &'h str,
    index: usize,
    property: &'h str,
}

impl Place<'_> {
    fn item(&self) -> String {
        match self.element {
            "vertex" | "face" => format!("{} {}", self.element, self.index + 1),
            other => format!("element '{}' item {}", shown(other), self.index + 1),
        }
    }

    /// The payload ends inside the property, which starts at payload byte `at`.
    fn ends_inside(&self, at: usize) -> MeshError {
        format!(
            "{}: the file ends inside property '{}' (payload byte {at}): the file is truncated, \
             or a list length or element count is wrong",
            self.item(),
            self.property,
        )
        .into()
    }
}

/// Reads a list's length and returns its items' bytes.
fn list<'a>(
    bytes: &mut Bytes<'a>,
    length: Number,
    item: Number,
    place: &Place,
) -> Result<(usize, &'a [u8]), MeshError> {
    let start = bytes.offset();
    let n = bytes
        .number(length)
        .ok_or_else(|| place.ends_inside(start))?;
    if n < 0.0 {
        return Err(format!(
            "{}: list '{}' has a negative length ({n})",
            place.item(),
            place.property
        )
        .into());
    }
    // Integer lengths of at most 32 bits: exact, and within usize.
    let n = n as usize;
    let raw = n
        .checked_mul(item.size())
        .and_then(|size| bytes.take(size))
        .ok_or_else(|| place.ends_inside(start))?;
    Ok((n, raw))
}

/// Reads the vertices, faces and other elements of a binary payload in `order`.
pub fn read_mesh(header: &Header, payload: &[u8], order: Order) -> Result<RawMesh, MeshError> {
    let vertex = header
        .elements
        .get("vertex")
        .ok_or("the PLY file has no 'vertex' element")?;
    let face = header
        .elements
        .get("face")
        .ok_or("the PLY file has no 'face' element")?;
    check_list_lengths(header)?;
    let mut mesh = RawMesh::default();
    let part = mesh.part_index(PLY_PART);
    let vertices = VertexLayout::new(vertex)?;
    let faces = FaceLayout::new(face, part, vertices.has_normals, vertex.count)?;
    if vertex.count > 0 {
        mesh.notes = temperature_notes(
            vertex.properties.keys().map(String::as_str),
            vertices.has_temperature,
        );
    }
    let mut bytes = Bytes {
        rest: payload,
        order,
        total: payload.len(),
    };
    for element in header.elements.values() {
        match element.name.as_str() {
            "vertex" => vertices.read(element.count, &mut bytes, &mut mesh)?,
            "face" => faces.read(element.count, &mut bytes, &mut mesh)?,
            _ => skip(element, &mut bytes)?,
        }
    }
    if !bytes.rest.is_empty() {
        return Err(format!(
            "{} bytes follow the items the header declares: its element counts or property \
             types do not describe the whole file",
            bytes.rest.len()
        )
        .into());
    }
    if mesh.faces.is_empty() {
        return Err("the mesh has no faces".into());
    }
    Ok(mesh)
}

/// Refuses list lengths of a floating-point type (the standard allows integers only).
fn check_list_lengths(header: &Header) -> Result<(), MeshError> {
    for element in header.elements.values() {
        for column in columns(element) {
            if let Field::List { length, .. } = column.field {
                if !length.is_integer() {
                    return Err(format!(
                        "element '{}': list '{}' has a floating-point length type; a PLY \
                         list's length must be an integer type (uchar, int, …)",
                        shown(&element.name),
                        column.name
                    )
                    .into());
                }
            }
        }
    }
    Ok(())
}

/// The vertex element's columns, with a slot for each value irpol reads.
struct VertexLayout<'h> {
    columns: Vec<Column<'h>>,
    has_normals: bool,
    has_temperature: bool,
}

impl<'h> VertexLayout<'h> {
    /// Normals when nx, ny and nz are all declared, a temperature when `temperature` is; each
    /// value read must be a scalar (checked when there are vertices, as a message about vertex 1).
    fn new(element: &'h ElementDef) -> Result<VertexLayout<'h>, MeshError> {
        let mut columns = columns(element);
        for column in &mut columns {
            column.slot = VERTEX_KEYS.iter().position(|k| *k == column.name);
        }
        let declared = |key: &str| columns.iter().any(|c| c.name == key);
        let has_normals = declared("nx") && declared("ny") && declared("nz");
        let has_temperature = declared("temperature");
        if element.count > 0 {
            for (slot, key) in VERTEX_KEYS.iter().enumerate() {
                let needed =
                    slot < 3 || (slot < 6 && has_normals) || (slot == 6 && has_temperature);
                let scalar = columns
                    .iter()
                    .any(|c| c.slot == Some(slot) && matches!(c.field, Field::Scalar(_)));
                if needed && !scalar {
                    return Err(no_numeric_property(0, key));
                }
            }
        }
        Ok(VertexLayout {
            columns,
            has_normals,
            has_temperature,
        })
    }

    /// Reads `count` vertices into `mesh`.
    fn read(&self, count: usize, bytes: &mut Bytes, mesh: &mut RawMesh) -> Result<(), MeshError> {
        mesh.positions.reserve_exact(count);
        if self.has_normals {
            mesh.normals.reserve_exact(count);
        }
        let mut temperatures = Vec::with_capacity(if self.has_temperature { count } else { 0 });
        let mut values = [0.0; VERTEX_KEYS.len()];
        for index in 0..count {
            for column in &self.columns {
                let place = || Place {
                    element: "vertex",
                    index,
                    property: column.name,
                };
                match column.field {
                    Field::Scalar(number) => {
                        let value = bytes
                            .number(number)
                            .ok_or_else(|| place().ends_inside(bytes.offset()))?;
                        if let Some(slot) = column.slot {
                            values[slot] = value;
                        }
                    }
                    Field::List { length, item } => {
                        list(bytes, length, item, &place())?;
                    }
                }
            }
            let value = |slot: usize| finite(values[slot], index, VERTEX_KEYS[slot]);
            mesh.positions
                .push(Vector3::new(value(0)?, value(1)?, value(2)?));
            if self.has_normals {
                mesh.normals
                    .push(Vector3::new(value(3)?, value(4)?, value(5)?));
            }
            if self.has_temperature {
                temperatures.push(value(6)?);
            }
        }
        if self.has_temperature {
            mesh.vertex_temperatures = Some(temperatures);
        }
        Ok(())
    }
}

/// The face element's columns and which of them holds the vertex indices.
struct FaceLayout<'h> {
    columns: Vec<Column<'h>>,
    /// The column of `vertex_indices` (else `vertex_index`) when it is an integer list.
    indices: Option<usize>,
    part: u32,
    has_normals: bool,
    vertex_count: usize,
}

impl<'h> FaceLayout<'h> {
    fn new(
        element: &'h ElementDef,
        part: u32,
        has_normals: bool,
        vertex_count: usize,
    ) -> Result<FaceLayout<'h>, MeshError> {
        let columns = columns(element);
        let named = |key: &str| columns.iter().position(|c| c.name == key);
        let indices = named("vertex_indices")
            .or_else(|| named("vertex_index"))
            .filter(|&c| matches!(columns[c].field, Field::List { item, .. } if item.is_integer()));
        if indices.is_none() && element.count > 0 {
            return Err(
                format!("{}: no integer list 'vertex_indices'", FaceOrigin::Index(1)).into(),
            );
        }
        Ok(FaceLayout {
            columns,
            indices,
            part,
            has_normals,
            vertex_count,
        })
    }

    /// Reads `count` faces into `mesh` as triangle fans.
    fn read(&self, count: usize, bytes: &mut Bytes, mesh: &mut RawMesh) -> Result<(), MeshError> {
        mesh.faces.reserve(count);
        let mut indices: Vec<i64> = Vec::new();
        for index in 0..count {
            for (c, column) in self.columns.iter().enumerate() {
                let place = || Place {
                    element: "face",
                    index,
                    property: column.name,
                };
                match column.field {
                    Field::Scalar(number) => {
                        bytes
                            .take(number.size())
                            .ok_or_else(|| place().ends_inside(bytes.offset()))?;
                    }
                    Field::List { length, item } => {
                        let (n, raw) = list(bytes, length, item, &place())?;
                        if Some(c) == self.indices {
                            let mut values = Bytes {
                                rest: raw,
                                order: bytes.order,
                                total: raw.len(),
                            };
                            indices.clear();
                            // `raw` holds exactly n items: every read succeeds.
                            indices.extend(
                                (0..n).map_while(|_| values.number(item)).map(|v| v as i64),
                            );
                        }
                    }
                }
            }
            let polygon = Polygon {
                origin: FaceOrigin::Index(index + 1),
                part: self.part,
                has_normals: self.has_normals,
                vertex_count: self.vertex_count,
            };
            polygon.push(&indices, mesh)?;
        }
        Ok(())
    }
}

/// Skips the items of an element irpol does not read.
fn skip(element: &ElementDef, bytes: &mut Bytes) -> Result<(), MeshError> {
    let columns = columns(element);
    for index in 0..element.count {
        for column in &columns {
            let place = Place {
                element: &element.name,
                index,
                property: column.name,
            };
            match column.field {
                Field::Scalar(number) => {
                    bytes
                        .take(number.size())
                        .ok_or_else(|| place.ends_inside(bytes.offset()))?;
                }
                Field::List { length, item } => {
                    list(bytes, length, item, &place)?;
                }
            }
        }
    }
    Ok(())
}
