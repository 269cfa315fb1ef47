//! Mitsuba 3's "tensor file" container (docs/design.md §2.10): named, typed n-dimensional arrays
//! in one little-endian file. Hand-written: no crate reads or writes this format.
//!
//! Layout: 12 bytes `tensor_file\0`, version u8 1 and u8 0, u32 field count; per field u16 name
//! length, the name, u16 rank, u8 data type, u64 byte offset of the data, rank × u64 shape; the
//! data of each field C-ordered at its offset (8-byte aligned by the writer).
//!
//! The reader takes only the header into memory and reads a field, or a slab of one, when asked:
//! a 1 GB table is never held twice.

use std::io::{Read, Seek, SeekFrom};

/// The 12 bytes every tensor file begins with.
pub const MAGIC: &[u8; 12] = b"tensor_file\0";

/// Data types of Mitsuba's `Struct::Type` that a field may hold (the codes are Mitsuba's).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dtype {
    U8 = 1,
    I8 = 2,
    U16 = 3,
    I16 = 4,
    U32 = 5,
    I32 = 6,
    U64 = 7,
    I64 = 8,
    F16 = 9,
    F32 = 10,
    F64 = 11,
}

impl Dtype {
    fn from_code(code: u8) -> Option<Dtype> {
        use Dtype::*;
        [U8, I8, U16, I16, U32, I32, U64, I64, F16, F32, F64]
            .into_iter()
            .find(|d| *d as u8 == code)
    }

    /// Bytes per element.
    pub fn size(self) -> u64 {
        match self {
            Dtype::U8 | Dtype::I8 => 1,
            Dtype::U16 | Dtype::I16 | Dtype::F16 => 2,
            Dtype::U32 | Dtype::I32 | Dtype::F32 => 4,
            Dtype::U64 | Dtype::I64 | Dtype::F64 => 8,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Dtype::U8 => "uint8",
            Dtype::I8 => "int8",
            Dtype::U16 => "uint16",
            Dtype::I16 => "int16",
            Dtype::U32 => "uint32",
            Dtype::I32 => "int32",
            Dtype::U64 => "uint64",
            Dtype::I64 => "int64",
            Dtype::F16 => "float16",
            Dtype::F32 => "float32",
            Dtype::F64 => "float64",
        }
    }
}

/// A refused tensor file: which field (when one is to blame) and what is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{message}", field.as_ref().map(|f| format!("field '{f}': ")).unwrap_or_default())]
pub struct TensorError {
    pub field: Option<String>,
    pub message: String,
}

impl TensorError {
    pub fn file(message: impl Into<String>) -> TensorError {
        TensorError {
            field: None,
            message: message.into(),
        }
    }

    pub fn field(field: &str, message: impl Into<String>) -> TensorError {
        TensorError {
            field: Some(crate::text::shown(field)),
            message: message.into(),
        }
    }
}

/// One field's header entry.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldInfo {
    pub name: String,
    pub dtype: Dtype,
    pub offset: u64,
    pub shape: Vec<u64>,
}

impl FieldInfo {
    /// Elements in the field (the product of its shape).
    pub fn len(&self) -> u64 {
        self.shape.iter().product()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The shape as Python prints it, `(0, 22)`.
    pub fn shape_text(&self) -> String {
        shape_text(&self.shape)
    }
}

/// `(a, b, …)`, with a trailing comma for one dimension as Python writes it.
pub fn shape_text(shape: &[u64]) -> String {
    let parts: Vec<String> = shape.iter().map(u64::to_string).collect();
    match parts.len() {
        1 => format!("({},)", parts[0]),
        _ => format!("({})", parts.join(", ")),
    }
}

/// The header of a tensor file: every field's entry, checked to lie inside the file.
#[derive(Clone, Debug, PartialEq)]
pub struct TensorHeader {
    pub fields: Vec<FieldInfo>,
}

/// Most fields and most dimensions a header may declare: far above any real file, low enough
/// that a corrupt count cannot make the reader allocate gigabytes.
const MAX_FIELDS: u32 = 4096;
const MAX_RANK: u16 = 32;

impl TensorHeader {
    /// Reads and checks the header of a tensor file of `file_len` bytes.
    pub fn read(source: &mut impl Read, file_len: u64) -> Result<TensorHeader, TensorError> {
        let mut magic = [0u8; 12];
        read_exact(source, &mut magic, "the header")?;
        if &magic != MAGIC {
            return Err(TensorError::file(
                "not a Mitsuba tensor file (it does not begin with 'tensor_file\\0')",
            ));
        }
        let version = [read_u8(source)?, read_u8(source)?];
        if version != [1, 0] {
            return Err(TensorError::file(format!(
                "tensor file version {}.{} is not supported (1.0 is)",
                version[0], version[1]
            )));
        }
        let count = u32::from_le_bytes(read_array(source, "the header")?);
        if count > MAX_FIELDS {
            return Err(TensorError::file(format!(
                "the header declares {count} fields (corrupt: at most {MAX_FIELDS} are read)"
            )));
        }
        let fields = (0..count)
            .map(|_| read_field_entry(source, file_len))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(TensorHeader { fields })
    }

    pub fn field(&self, name: &str) -> Option<&FieldInfo> {
        self.fields.iter().find(|f| f.name == name)
    }
}

fn read_field_entry(source: &mut impl Read, file_len: u64) -> Result<FieldInfo, TensorError> {
    let name_len = u16::from_le_bytes(read_array(source, "a field entry")?);
    let mut name = vec![0u8; usize::from(name_len)];
    read_exact(source, &mut name, "a field name")?;
    let name = String::from_utf8_lossy(&name).into_owned();
    let rank = u16::from_le_bytes(read_array(source, "a field entry")?);
    if rank > MAX_RANK {
        return Err(TensorError::field(&name, format!("rank {rank} (corrupt)")));
    }
    let code = read_u8(source)?;
    let dtype = Dtype::from_code(code)
        .ok_or_else(|| TensorError::field(&name, format!("unknown data type code {code}")))?;
    let offset = u64::from_le_bytes(read_array(source, "a field entry")?);
    let shape = (0..rank)
        .map(|_| read_array(source, "a field shape").map(u64::from_le_bytes))
        .collect::<Result<Vec<_>, _>>()?;
    let field = FieldInfo {
        name,
        dtype,
        offset,
        shape,
    };
    let bytes = field
        .shape
        .iter()
        .try_fold(dtype.size(), |acc, &n| acc.checked_mul(n));
    match bytes.and_then(|b| b.checked_add(offset)) {
        Some(end) if end <= file_len => Ok(field),
        _ => Err(TensorError::field(
            &field.name,
            format!(
                "truncated: shape {} of {} at byte {} runs past the end of the file ({file_len} bytes)",
                field.shape_text(),
                dtype.name(),
                offset
            ),
        )),
    }
}

fn read_exact(source: &mut impl Read, buffer: &mut [u8], what: &str) -> Result<(), TensorError> {
    source.read_exact(buffer).map_err(|e| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => {
            TensorError::file(format!("truncated: the file ends inside {what}"))
        }
        _ => TensorError::file(format!("cannot read {what}: {e}")),
    })
}

fn read_array<const N: usize>(source: &mut impl Read, what: &str) -> Result<[u8; N], TensorError> {
    let mut bytes = [0u8; N];
    read_exact(source, &mut bytes, what)?;
    Ok(bytes)
}

fn read_u8(source: &mut impl Read) -> Result<u8, TensorError> {
    Ok(read_array::<1>(source, "the header")?[0])
}

/// Reads `count` elements of `field` from element `first` on, converted to f64 (the floating
/// and integer types a table may use; float16 is refused).
pub fn read_values(
    source: &mut (impl Read + Seek),
    field: &FieldInfo,
    first: u64,
    count: usize,
) -> Result<Vec<f64>, TensorError> {
    let size = field.dtype.size();
    source
        .seek(SeekFrom::Start(field.offset + first * size))
        .map_err(|e| TensorError::field(&field.name, format!("cannot seek: {e}")))?;
    let mut bytes = vec![0u8; count * size as usize];
    read_exact(source, &mut bytes, &format!("field '{}'", field.name))?;
    let convert: fn(&[u8]) -> f64 = match field.dtype {
        Dtype::F32 => |b| f64::from(f32::from_le_bytes(b.try_into().unwrap())),
        Dtype::F64 => |b| f64::from_le_bytes(b.try_into().unwrap()),
        Dtype::U8 => |b| f64::from(b[0]),
        Dtype::I8 => |b| f64::from(b[0] as i8),
        Dtype::U16 => |b| f64::from(u16::from_le_bytes(b.try_into().unwrap())),
        Dtype::I16 => |b| f64::from(i16::from_le_bytes(b.try_into().unwrap())),
        Dtype::U32 => |b| f64::from(u32::from_le_bytes(b.try_into().unwrap())),
        Dtype::I32 => |b| f64::from(i32::from_le_bytes(b.try_into().unwrap())),
        Dtype::U64 => |b| u64::from_le_bytes(b.try_into().unwrap()) as f64,
        Dtype::I64 => |b| i64::from_le_bytes(b.try_into().unwrap()) as f64,
        Dtype::F16 => {
            return Err(TensorError::field(
                &field.name,
                "float16 data is not supported (float32 or float64 is)",
            ))
        }
    };
    Ok(bytes.chunks_exact(size as usize).map(convert).collect())
}

/// A field to write: its name, shape and little-endian data bytes.
pub struct FieldData {
    pub name: String,
    pub dtype: Dtype,
    pub shape: Vec<u64>,
    pub bytes: Vec<u8>,
}

impl FieldData {
    pub fn f32(name: &str, shape: Vec<u64>, values: &[f32]) -> FieldData {
        FieldData {
            name: name.to_owned(),
            dtype: Dtype::F32,
            shape,
            bytes: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        }
    }

    pub fn u16(name: &str, shape: Vec<u64>, values: &[u16]) -> FieldData {
        FieldData {
            name: name.to_owned(),
            dtype: Dtype::U16,
            shape,
            bytes: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        }
    }
}

/// The bytes of a tensor file holding `fields`, each field's data 8-byte aligned (Mitsuba 3.9.1
/// loads such files: scripts/check_mitsuba_export.py).
pub fn tensor_file_bytes(fields: &[FieldData]) -> Vec<u8> {
    let header_len: usize = 12
        + 2
        + 4
        + fields
            .iter()
            .map(|f| 2 + f.name.len() + 2 + 1 + 8 + 8 * f.shape.len())
            .sum::<usize>();
    let mut offsets = Vec::with_capacity(fields.len());
    let mut end = header_len;
    for field in fields {
        end = end.div_ceil(8) * 8;
        offsets.push(end as u64);
        end += field.bytes.len();
    }
    let mut out = Vec::with_capacity(end);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(fields.len() as u32).to_le_bytes());
    for (field, offset) in fields.iter().zip(&offsets) {
        out.extend_from_slice(&(field.name.len() as u16).to_le_bytes());
        out.extend_from_slice(field.name.as_bytes());
        out.extend_from_slice(&(field.shape.len() as u16).to_le_bytes());
        out.push(field.dtype as u8);
        out.extend_from_slice(&offset.to_le_bytes());
        for n in &field.shape {
            out.extend_from_slice(&n.to_le_bytes());
        }
    }
    for (field, &offset) in fields.iter().zip(&offsets) {
        out.resize(offset as usize, 0);
        out.extend_from_slice(&field.bytes);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    #[test]
    fn a_written_file_reads_back_field_for_field() {
        let fields = [
            FieldData::f32("abc", vec![1, 3], &[1.0, -2.5, 3.25]),
            FieldData::u16("w", vec![2], &[8000, 12000]),
        ];
        let bytes = tensor_file_bytes(&fields);
        let mut cursor = Cursor::new(&bytes[..]);
        let header = TensorHeader::read(&mut cursor, bytes.len() as u64).unwrap();
        assert_eq!(header.fields.len(), 2);
        let abc = header.field("abc").unwrap();
        assert_eq!(abc.offset % 8, 0);
        assert_eq!(abc.shape, [1, 3]);
        assert_eq!(
            read_values(&mut cursor, abc, 0, 3).unwrap(),
            [1.0, -2.5, 3.25]
        );
        let w = header.field("w").unwrap();
        assert_eq!(read_values(&mut cursor, w, 1, 1).unwrap(), [12000.0]);
    }

    #[test]
    fn a_field_past_the_end_is_refused_naming_it() {
        let bytes = tensor_file_bytes(&[FieldData::f32("M", vec![4], &[0.0; 4])]);
        let cut = &bytes[..bytes.len() - 1];
        let error = TensorHeader::read(&mut Cursor::new(cut), cut.len() as u64).unwrap_err();
        assert_eq!(error.field.as_deref(), Some("M"));
        assert!(error.to_string().contains("truncated"), "{error}");
    }
}
