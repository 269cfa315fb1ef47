//! The binary PLY reader: files written here from known arrays (random layouts of both byte
//! orders, every scalar type and alias, extra properties and elements) are read back exactly by
//! `parse_ply` and by the parser path it replaced for binary payloads, and damaged files are
//! refused with a message naming the item, never a panic.

use crate::mesh_support;

use irpol::scene::mesh::{FaceOrigin, RawMesh};
use irpol::scene::ply::{parse_ply, parse_ply_through_parser};
use mesh_support::GridPly;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A PLY scalar type, with its two names.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

const TYPES: [Ty; 8] = [
    Ty::I8,
    Ty::U8,
    Ty::I16,
    Ty::U16,
    Ty::I32,
    Ty::U32,
    Ty::F32,
    Ty::F64,
];
const INTEGERS: [Ty; 6] = [Ty::I8, Ty::U8, Ty::I16, Ty::U16, Ty::I32, Ty::U32];

impl Ty {
    fn name(self, alias: bool) -> &'static str {
        let [plain, sized] = match self {
            Ty::I8 => ["char", "int8"],
            Ty::U8 => ["uchar", "uint8"],
            Ty::I16 => ["short", "int16"],
            Ty::U16 => ["ushort", "uint16"],
            Ty::I32 => ["int", "int32"],
            Ty::U32 => ["uint", "uint32"],
            Ty::F32 => ["float", "float32"],
            Ty::F64 => ["double", "float64"],
        };
        if alias {
            sized
        } else {
            plain
        }
    }

    /// Appends `v` (exactly representable in the type) in the byte order.
    fn put(self, v: f64, big: bool, out: &mut Vec<u8>) {
        macro_rules! put {
            ($t:ty) => {{
                let x = v as $t;
                assert_eq!(x as f64, v, "{v} is not a {self:?}");
                out.extend_from_slice(&if big {
                    x.to_be_bytes()
                } else {
                    x.to_le_bytes()
                });
            }};
        }
        match self {
            Ty::I8 => put!(i8),
            Ty::U8 => put!(u8),
            Ty::I16 => put!(i16),
            Ty::U16 => put!(u16),
            Ty::I32 => put!(i32),
            Ty::U32 => put!(u32),
            Ty::F32 => put!(f32),
            Ty::F64 => put!(f64),
        }
    }

    /// A random value the type holds exactly.
    fn sample(self, rng: &mut ChaCha8Rng) -> f64 {
        match self {
            Ty::I8 => rng.random_range(-128..=127) as f64,
            Ty::U8 => rng.random_range(0..=255) as f64,
            Ty::I16 => rng.random_range(-32768..=32767) as f64,
            Ty::U16 => rng.random_range(0..=65535) as f64,
            Ty::I32 => rng.random_range(i32::MIN..=i32::MAX) as f64,
            Ty::U32 => rng.random_range(0..=u32::MAX) as f64,
            Ty::F32 => (rng.random_range(-1e3..1e3f64) as f32) as f64,
            Ty::F64 => rng.random_range(-1e6..1e6),
        }
    }

    /// The largest value of an integer type (for vertex indices and list lengths).
    fn max(self) -> f64 {
        match self {
            Ty::I8 => 127.0,
            Ty::U8 => 255.0,
            Ty::I16 => 32767.0,
            Ty::U16 => 65535.0,
            _ => 1e9,
        }
    }
}

fn pick<T: Copy>(rng: &mut ChaCha8Rng, from: &[T]) -> T {
    from[rng.random_range(0..from.len())]
}

/// What a random file must read as.
#[derive(Default)]
struct Expected {
    positions: Vec<[f64; 3]>,
    normals: Option<Vec<[f64; 3]>>,
    temperatures: Option<Vec<f64>>,
    /// Triangles and the face (from 1) each comes from.
    triangles: Vec<([u32; 3], usize)>,
}

/// A property of a random element: read by irpol (`Some(slot)` into the vertex values) or not.
enum Prop {
    Scalar(String, Ty, Option<usize>),
    List(String, Ty, Ty),
}

/// Writes `name`'s declaration and returns it.
fn declare(header: &mut String, prop: &Prop, rng: &mut ChaCha8Rng) {
    let alias = rng.random_bool(0.5);
    match prop {
        Prop::Scalar(name, ty, _) => {
            header.push_str(&format!("property {} {name}\n", ty.name(alias)))
        }
        Prop::List(name, length, item) => header.push_str(&format!(
            "property list {} {} {name}\n",
            length.name(alias),
            item.name(alias)
        )),
    }
}

/// Appends a random list of `item`s with a length of type `length` (at most 4 items).
fn put_random_list(length: Ty, item: Ty, big: bool, rng: &mut ChaCha8Rng, out: &mut Vec<u8>) {
    let n = rng.random_range(0..=4);
    length.put(n as f64, big, out);
    for _ in 0..n {
        item.put(item.sample(rng), big, out);
    }
}

/// An element irpol skips, with fixed-size and list properties.
fn extra_element(name: &str, big: bool, rng: &mut ChaCha8Rng) -> (String, Vec<u8>) {
    let count = rng.random_range(0..6);
    let mut header = format!("element {name} {count}\n");
    let props: Vec<Prop> = (0..rng.random_range(1..4))
        .map(|p| {
            if rng.random_bool(0.5) {
                Prop::Scalar(format!("s{p}"), pick(rng, &TYPES), None)
            } else {
                Prop::List(format!("l{p}"), pick(rng, &INTEGERS), pick(rng, &TYPES))
            }
        })
        .collect();
    props.iter().for_each(|p| declare(&mut header, p, rng));
    let mut out = Vec::new();
    for _ in 0..count {
        for prop in &props {
            match prop {
                Prop::Scalar(_, ty, _) => ty.put(ty.sample(rng), big, &mut out),
                Prop::List(_, length, item) => put_random_list(*length, *item, big, rng, &mut out),
            }
        }
    }
    (header, out)
}

/// The vertex element: x, y, z, maybe normals and a temperature, each of a random type, among
/// extra scalar and list properties.
fn vertex_element(big: bool, rng: &mut ChaCha8Rng, expected: &mut Expected) -> (String, Vec<u8>) {
    let count = rng.random_range(3..100);
    let normals = rng.random_bool(0.5);
    let temperature = rng.random_bool(0.5);
    let keys = ["x", "y", "z", "nx", "ny", "nz", "temperature"];
    let mut props: Vec<Prop> = (0..7)
        .filter(|&slot| slot < 3 || (slot < 6 && normals) || (slot == 6 && temperature))
        .map(|slot| Prop::Scalar(keys[slot].to_owned(), pick(rng, &TYPES), Some(slot)))
        .collect();
    for extra in 0..rng.random_range(0..3) {
        let at = rng.random_range(0..=props.len());
        let prop = if rng.random_bool(0.5) {
            Prop::Scalar(format!("red{extra}"), pick(rng, &TYPES), None)
        } else {
            Prop::List(
                format!("tags{extra}"),
                pick(rng, &INTEGERS),
                pick(rng, &TYPES),
            )
        };
        props.insert(at, prop);
    }
    let mut header = format!("element vertex {count}\n");
    props.iter().for_each(|p| declare(&mut header, p, rng));
    let mut out = Vec::new();
    let mut values = vec![[0.0; 7]; count];
    for value in values.iter_mut() {
        for prop in &props {
            match prop {
                Prop::Scalar(_, ty, slot) => {
                    let v = ty.sample(rng);
                    if let Some(slot) = slot {
                        value[*slot] = v;
                    }
                    ty.put(v, big, &mut out);
                }
                Prop::List(_, length, item) => put_random_list(*length, *item, big, rng, &mut out),
            }
        }
    }
    expected.positions = values.iter().map(|v| [v[0], v[1], v[2]]).collect();
    expected.normals = normals.then(|| values.iter().map(|v| [v[3], v[4], v[5]]).collect());
    expected.temperatures = temperature.then(|| values.iter().map(|v| v[6]).collect());
    (header, out)
}

/// The face element: polygons of 3–6 vertices in a list of random integer types, among extra
/// properties.
fn face_element(
    vertices: usize,
    big: bool,
    rng: &mut ChaCha8Rng,
    expected: &mut Expected,
) -> (String, Vec<u8>) {
    let count = rng.random_range(1..40);
    let length = pick(rng, &INTEGERS);
    let index = pick(
        rng,
        &INTEGERS
            .into_iter()
            .filter(|t| t.max() >= vertices as f64)
            .collect::<Vec<_>>(),
    );
    let name = if rng.random_bool(0.8) {
        "vertex_indices"
    } else {
        "vertex_index"
    };
    let mut props = vec![Prop::List(name.to_owned(), length, index)];
    if rng.random_bool(0.5) {
        props.insert(0, Prop::Scalar("flags".into(), pick(rng, &TYPES), None));
    }
    if rng.random_bool(0.5) {
        props.push(Prop::List("texcoord".into(), pick(rng, &INTEGERS), Ty::F32));
    }
    let mut header = format!("element face {count}\n");
    props.iter().for_each(|p| declare(&mut header, p, rng));
    let mut out = Vec::new();
    for face in 1..=count {
        for prop in &props {
            match prop {
                Prop::Scalar(_, ty, _) => ty.put(ty.sample(rng), big, &mut out),
                Prop::List(n, length, index) if n == name => {
                    let polygon: Vec<u32> = (0..rng.random_range(3..=6))
                        .map(|_| rng.random_range(0..vertices as u32))
                        .collect();
                    length.put(polygon.len() as f64, big, &mut out);
                    polygon
                        .iter()
                        .for_each(|&v| index.put(v as f64, big, &mut out));
                    for i in 1..polygon.len() - 1 {
                        expected
                            .triangles
                            .push(([polygon[0], polygon[i], polygon[i + 1]], face));
                    }
                }
                Prop::List(_, length, item) => put_random_list(*length, *item, big, rng, &mut out),
            }
        }
    }
    (header, out)
}

/// A random binary PLY and what it holds.
fn random_file(seed: u64) -> (Vec<u8>, Expected) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let big = rng.random_bool(0.5);
    let mut expected = Expected::default();
    let vertex = vertex_element(big, &mut rng, &mut expected);
    let face = face_element(expected.positions.len(), big, &mut rng, &mut expected);
    let mut elements = vec![vertex, face];
    if rng.random_bool(0.3) {
        elements.swap(0, 1);
    }
    for name in ["material", "edge"] {
        if rng.random_bool(0.5) {
            let at = rng.random_range(0..=elements.len());
            elements.insert(at, extra_element(name, big, &mut rng));
        }
    }
    let order = if big { "big" } else { "little" };
    let mut header = format!("ply\nformat binary_{order}_endian 1.0\ncomment seed {seed}\n");
    elements.iter().for_each(|(h, _)| header.push_str(h));
    header.push_str("end_header\n");
    let mut bytes = header.into_bytes();
    elements
        .iter()
        .for_each(|(_, p)| bytes.extend_from_slice(p));
    (bytes, expected)
}

fn assert_holds(mesh: &RawMesh, expected: &Expected, what: &str) {
    let triples =
        |v: &[nalgebra::Vector3<f64>]| v.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>();
    assert_eq!(triples(&mesh.positions), expected.positions, "{what}");
    assert_eq!(
        triples(&mesh.normals),
        expected.normals.clone().unwrap_or_default(),
        "{what}"
    );
    assert_eq!(mesh.vertex_temperatures, expected.temperatures, "{what}");
    let faces: Vec<([u32; 3], usize)> = mesh
        .faces
        .iter()
        .map(|f| {
            let FaceOrigin::Index(face) = f.origin else {
                panic!("{what}: a PLY face has a line")
            };
            assert_eq!(f.normals.is_some(), expected.normals.is_some(), "{what}");
            (f.vertices, face)
        })
        .collect();
    assert_eq!(faces, expected.triangles, "{what}");
    assert_eq!(mesh.parts, ["surface"], "{what}");
    assert!(mesh.notes.is_empty(), "{what}: {:?}", mesh.notes);
}

#[test]
fn random_binary_layouts_read_as_written_by_both_readers() {
    let mut orders = [0, 0];
    for seed in 0..300 {
        let (bytes, expected) = random_file(seed);
        orders[usize::from(bytes.starts_with(b"ply\nformat binary_big"))] += 1;
        let what = format!("seed {seed}");
        assert_holds(&parse_ply(&bytes).unwrap(), &expected, &what);
        let through_parser = parse_ply_through_parser(&bytes).unwrap();
        assert_holds(&through_parser, &expected, &format!("{what}, parser"));
    }
    assert!(orders.iter().all(|&n| n > 100), "{orders:?}");
}

#[test]
fn a_grid_reads_the_same_in_both_byte_orders() {
    let little = GridPly {
        cells: 20,
        big_endian: false,
        normals: true,
        temperature: true,
    };
    let big = GridPly {
        big_endian: true,
        ..little
    };
    let [a, b] = [little, big].map(|grid| parse_ply(&grid.bytes()).unwrap());
    assert_eq!(a.positions, b.positions);
    assert_eq!(a.vertex_temperatures, b.vertex_temperatures);
    assert_eq!(a.faces.len(), 800);
    for (t, face) in a.faces.iter().enumerate() {
        assert_eq!(face.vertices, little.face(t));
        assert_eq!(face.vertices, b.faces[t].vertices);
    }
    let (p, _, temperature) = little.vertex(57);
    assert_eq!(a.positions[57], nalgebra::Vector3::from(p.map(f64::from)));
    assert_eq!(a.vertex_temperatures.unwrap()[57], temperature as f64);
}

/// A little-endian file of 4 float vertices (the fourth with `y` given) and faces given as
/// (uchar length, int indices), then `tail` bytes.
fn square(y: f32, faces: &[&[i32]], tail: &[u8]) -> Vec<u8> {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n\
         property float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        faces.len()
    )
    .into_bytes();
    for p in [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, y, 0.0],
    ] {
        p.iter()
            .for_each(|c: &f32| bytes.extend_from_slice(&c.to_le_bytes()));
    }
    for face in faces {
        bytes.push(face.len() as u8);
        face.iter()
            .for_each(|v| bytes.extend_from_slice(&v.to_le_bytes()));
    }
    bytes.extend_from_slice(tail);
    bytes
}

/// `bytes` with `from` replaced by `to` in the header only (a binary payload is not text).
fn edit_header(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    assert!(header.contains(from), "{from}");
    let mut edited = header.replace(from, to).into_bytes();
    edited.extend_from_slice(&bytes[end..]);
    edited
}

fn error(bytes: &[u8]) -> String {
    parse_ply(bytes).unwrap_err().to_string()
}

#[test]
fn damaged_payloads_are_refused_with_the_item_named() {
    assert_eq!(
        parse_ply(&square(1.0, &[&[0, 1, 2, 3]], &[]))
            .unwrap()
            .faces
            .len(),
        2
    );
    // Cut inside the second face's list (the header check still passes: 13 bytes are the least).
    let whole = square(1.0, &[&[0, 1, 2], &[0, 2, 3, 1]], &[]);
    assert_eq!(
        error(&whole[..whole.len() - 6]),
        "face 2: the file ends inside property 'vertex_indices' (payload byte 61): the file is \
         truncated, or a list length or element count is wrong"
    );
    assert_eq!(
        error(&square(1.0, &[&[0, 1, 2], &[0, 2, 9]], &[])),
        "face 2: vertex index 9 is out of range (4 vertices)"
    );
    assert_eq!(
        error(&square(1.0, &[&[0, -1, 2]], &[])),
        "face 1: vertex index -1 is out of range (4 vertices)"
    );
    assert_eq!(
        error(&square(f32::NAN, &[&[0, 1, 2]], &[])),
        "vertex 4: property 'y' is not finite"
    );
    assert_eq!(
        error(&square(f32::INFINITY, &[&[0, 1, 2]], &[])),
        "vertex 4: property 'y' is not finite"
    );
    for short in [&[][..], &[0], &[0, 1]] {
        assert_eq!(
            error(&square(1.0, &[&[0, 1, 2], short], &[])),
            "face 2: a face needs at least 3 vertices"
        );
    }
    assert_eq!(
        error(&square(1.0, &[&[0, 1, 2]], b"\n\0\0")),
        "3 bytes follow the items the header declares: its element counts or property types \
         do not describe the whole file"
    );
}

#[test]
fn huge_and_negative_list_lengths_are_refused_without_reserving() {
    // A length of 4 294 967 295 indices in a 12-byte payload.
    let header = "ply\nformat binary_big_endian 1.0\nelement vertex 0\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\nproperty list uint uint vertex_indices\n\
        end_header\n";
    let mut bytes = header.as_bytes().to_vec();
    bytes.extend_from_slice(&u32::MAX.to_be_bytes());
    bytes.extend_from_slice(&[0; 8]);
    assert_eq!(
        error(&bytes),
        "face 1: the file ends inside property 'vertex_indices' (payload byte 0): the file is \
         truncated, or a list length or element count is wrong"
    );
    let signed = header.replace("list uint uint", "list int uint");
    let mut bytes = signed.as_bytes().to_vec();
    bytes.extend_from_slice(&(-3i32).to_be_bytes());
    assert_eq!(
        error(&bytes),
        "face 1: list 'vertex_indices' has a negative length (-3)"
    );
    // In an element irpol skips, the item is named by its element.
    let skipped = "ply\nformat binary_little_endian 1.0\nelement edge 2\nproperty list short int \
        corners\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n\
        element face 0\nproperty list uchar int vertex_indices\nend_header\n";
    let mut bytes = skipped.as_bytes().to_vec();
    bytes.extend_from_slice(&[0, 0, 0xff, 0x7f]);
    assert_eq!(
        error(&bytes),
        "element 'edge' item 2: the file ends inside property 'corners' (payload byte 2): the \
         file is truncated, or a list length or element count is wrong"
    );
    let mut float_length = skipped
        .replace("list short int", "list float int")
        .into_bytes();
    float_length.extend_from_slice(&[0; 8]);
    assert_eq!(
        error(&float_length),
        "element 'edge': list 'corners' has a floating-point length type; a PLY list's length \
         must be an integer type (uchar, int, …)"
    );
}

#[test]
fn properties_irpol_cannot_read_are_named() {
    let good = square(1.0, &[&[0, 1, 2]], &[]);
    let as_list = edit_header(&good, "property float x\n", "property list uchar float x\n");
    // The payload no longer matches, but the layout is refused first.
    assert_eq!(error(&as_list), "vertex 1: no numeric property 'x'");
    let float_indices = edit_header(&good, "list uchar int", "list uchar float");
    assert_eq!(
        error(&float_indices),
        "face 1: no integer list 'vertex_indices'"
    );
    let renamed = edit_header(&good, "property float y", "property float temp");
    assert_eq!(error(&renamed), "vertex 1: no numeric property 'y'");
    let no_faces = edit_header(&good, "element face 1", "element face 0");
    assert_eq!(
        error(&no_faces[..no_faces.len() - 13]),
        "the mesh has no faces"
    );
}

#[test]
fn temperature_like_properties_are_noted_in_binary_files() {
    let mut bytes = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nproperty double Temp\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n"
        .as_bytes()
        .to_vec();
    for (i, p) in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        .iter()
        .enumerate()
    {
        p.iter()
            .for_each(|c| bytes.extend_from_slice(&c.to_le_bytes()));
        bytes.extend_from_slice(&(300.0 + i as f64).to_le_bytes());
    }
    bytes.push(3);
    [0i32, 1, 2]
        .iter()
        .for_each(|v| bytes.extend_from_slice(&v.to_le_bytes()));
    let mesh = parse_ply(&bytes).unwrap();
    assert!(mesh.vertex_temperatures.is_none());
    assert_eq!(mesh.notes.len(), 1);
    assert!(mesh.notes[0].starts_with("vertex property 'Temp' looks like a temperature"));
    assert_eq!(mesh.notes, parse_ply_through_parser(&bytes).unwrap().notes);
}

/// What `irpol thermal` writes (`surface_*.ply`, through ply-rs-bw's writer) reads back: the
/// direct reader refuses trailing bytes, so the writer must add none.
#[test]
fn files_written_by_ply_rs_bw_read_back() {
    use ply_rs_bw::ply::{
        Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyDef, PropertyType,
        ScalarType,
    };
    for encoding in [Encoding::BinaryLittleEndian, Encoding::BinaryBigEndian] {
        let mut ply = Ply::<DefaultElement>::new();
        ply.header.encoding = encoding;
        ply.header.comments.push("a triangle".into());
        let mut vertex = ElementDef::new("vertex".into());
        for name in ["x", "y", "z", "temperature"] {
            vertex.properties.add(PropertyDef::new(
                name.into(),
                PropertyType::Scalar(ScalarType::Float),
            ));
        }
        ply.header.elements.add(vertex);
        let mut face = ElementDef::new("face".into());
        face.properties.add(PropertyDef::new(
            "vertex_indices".into(),
            PropertyType::List(ScalarType::UChar, ScalarType::Int),
        ));
        ply.header.elements.add(face);
        let vertices = [
            [0.0, 0.0, 0.0, 290.5],
            [1.0, 0.0, 0.0, 300.0],
            [0.0, 2.0, 0.0, 310.25],
        ]
        .iter()
        .map(|values| {
            let mut e = DefaultElement::new();
            for (name, v) in ["x", "y", "z", "temperature"].iter().zip(values) {
                e.insert((*name).into(), Property::Float(*v));
            }
            e
        })
        .collect();
        let mut triangle = DefaultElement::new();
        triangle.insert("vertex_indices".into(), Property::ListInt(vec![0, 1, 2]));
        ply.payload.insert("vertex".into(), vertices);
        ply.payload.insert("face".into(), vec![triangle]);
        let mut bytes = Vec::new();
        ply_rs_bw::writer::Writer::new()
            .write_ply(&mut bytes, &mut ply)
            .unwrap();
        let mesh = parse_ply(&bytes).unwrap();
        assert_eq!(mesh.vertex_temperatures, Some(vec![290.5, 300.0, 310.25]));
        assert_eq!(mesh.positions[2].y, 2.0);
        assert_eq!(mesh.faces[0].vertices, [0, 1, 2]);
    }
}
