//! The `.pbsdf` table of Mitsuba 3's `measured_polarized` plugin (docs/design.md §2.10): a
//! tensor file ([`super::tensor_file`]) with the fields `phi_d`, `theta_d`, `theta_h` (float32,
//! shape (1, N), radians, increasing), `wvls` (uint16 nm, shape (N_λ,)) and `M` (float32,
//! (N_φd, N_θd, N_θh, N_λ, 4, 4), the BRDF in sr⁻¹ without the cosine, in the table's frames of
//! [`super::convention`]).
//!
//! [`PbsdfTable`] is a whole table in memory (what `export` builds and writes); [`PbsdfFile`]
//! is an opened file whose header and grids are checked and whose `M` is read one φ_d slab at a
//! time, so a large measured table is never copied whole.

use super::tensor_file::{
    read_values, shape_text, tensor_file_bytes, Dtype, FieldData, FieldInfo, TensorError,
    TensorHeader,
};
use crate::optics::Mueller;
use std::fs::File;
use std::io::{BufReader, Read, Seek};
use std::path::Path;

/// The grid of a table: φ_d, θ_d, θ_h nodes in radians, each strictly increasing.
#[derive(Clone, Debug, PartialEq)]
pub struct PbsdfGrid {
    pub phi_d: Vec<f64>,
    pub theta_d: Vec<f64>,
    pub theta_h: Vec<f64>,
}

impl PbsdfGrid {
    /// (N_φd, N_θd, N_θh).
    pub fn counts(&self) -> [usize; 3] {
        [self.phi_d.len(), self.theta_d.len(), self.theta_h.len()]
    }

    /// Nodes in the grid.
    pub fn nodes(&self) -> usize {
        self.counts().iter().product()
    }
}

/// A whole table in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct PbsdfTable {
    pub grid: PbsdfGrid,
    /// Wavelengths, nm (Mitsuba stores them as uint16).
    pub wavelengths_nm: Vec<u16>,
    /// `M` in C order, f32 as stored.
    pub values: Vec<f32>,
}

impl PbsdfTable {
    /// Index of the first of the 16 values of node (φ_d, θ_d, θ_h) at wavelength `l`.
    pub fn offset(&self, phi: usize, theta_d: usize, theta_h: usize, l: usize) -> usize {
        let [_, n_d, n_h] = self.grid.counts();
        (((phi * n_d + theta_d) * n_h + theta_h) * self.wavelengths_nm.len() + l) * 16
    }

    /// The stored matrix at a node (table frames), row i column j at M[…, i, j].
    pub fn matrix(&self, phi: usize, theta_d: usize, theta_h: usize, l: usize) -> Mueller {
        let at = self.offset(phi, theta_d, theta_h, l);
        Mueller::from_fn(|i, j| f64::from(self.values[at + i * 4 + j]))
    }

    /// The tensor-file bytes Mitsuba loads.
    pub fn to_bytes(&self) -> Vec<u8> {
        let row = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
        let [n_p, n_d, n_h] = self.grid.counts().map(|n| n as u64);
        let n_l = self.wavelengths_nm.len() as u64;
        tensor_file_bytes(&[
            FieldData::f32("phi_d", vec![1, n_p], &row(&self.grid.phi_d)),
            FieldData::f32("theta_d", vec![1, n_d], &row(&self.grid.theta_d)),
            FieldData::f32("theta_h", vec![1, n_h], &row(&self.grid.theta_h)),
            FieldData::u16("wvls", vec![n_l], &self.wavelengths_nm),
            FieldData::f32("M", vec![n_p, n_d, n_h, n_l, 4, 4], &self.values),
        ])
    }
}

/// An opened table: checked header and grids; `M` read on demand.
pub struct PbsdfFile<R> {
    source: R,
    pub grid: PbsdfGrid,
    /// Wavelengths, nm, as stored (any numeric type is accepted on reading).
    pub wavelengths_nm: Vec<f64>,
    m: FieldInfo,
}

impl PbsdfFile<BufReader<File>> {
    /// Opens and checks a table file; I/O failures are reported as the whole file's.
    pub fn open(path: &Path) -> Result<Self, TensorError> {
        let file = File::open(path).map_err(|e| TensorError::file(format!("cannot open: {e}")))?;
        let len = file
            .metadata()
            .map_err(|e| TensorError::file(format!("cannot read: {e}")))?
            .len();
        PbsdfFile::from_reader(BufReader::new(file), len)
    }
}

/// Whether `bytes` begin a tensor file (the first 12 bytes are its magic).
pub fn is_tensor_file(bytes: &[u8]) -> bool {
    bytes.starts_with(super::tensor_file::MAGIC)
}

impl<R: Read + Seek> PbsdfFile<R> {
    /// Reads and checks the header, the grids and the wavelengths of a table of `len` bytes.
    pub fn from_reader(mut source: R, len: u64) -> Result<Self, TensorError> {
        let header = TensorHeader::read(&mut source, len)?;
        let field = |name: &str| {
            header.field(name).cloned().ok_or_else(|| {
                TensorError::field(
                    name,
                    "missing (a measured_polarized table holds phi_d, theta_d, theta_h, wvls and M)",
                )
            })
        };
        let (phi, td, th, wl, m) = (
            field("phi_d")?,
            field("theta_d")?,
            field("theta_h")?,
            field("wvls")?,
            field("M")?,
        );
        let grid = PbsdfGrid {
            // Any turn is a direction; a [0, 2π] table (which Mitsuba clamps) still reads.
            phi_d: read_angles(&mut source, &phi, std::f64::consts::TAU)?,
            theta_d: read_angles(&mut source, &td, std::f64::consts::FRAC_PI_2)?,
            theta_h: read_angles(&mut source, &th, std::f64::consts::FRAC_PI_2)?,
        };
        let wavelengths_nm = read_wavelengths(&mut source, &wl)?;
        check_m_shape(&m, &grid, wavelengths_nm.len())?;
        Ok(PbsdfFile {
            source,
            grid,
            wavelengths_nm,
            m,
        })
    }

    /// Values per φ_d slab: N_θd N_θh N_λ 16.
    pub fn slab_len(&self) -> usize {
        self.grid.theta_d.len() * self.grid.theta_h.len() * self.wavelengths_nm.len() * 16
    }

    /// `M` at one φ_d node, C order (θ_d, θ_h, λ, 4, 4).
    pub fn slab(&mut self, phi: usize) -> Result<Vec<f64>, TensorError> {
        let len = self.slab_len();
        read_values(&mut self.source, &self.m, (phi * len) as u64, len)
    }

    /// The whole table in memory (for tables known to be small, and tests); wavelengths must be
    /// whole nanometres in 0..=65535 as Mitsuba writes them.
    pub fn read_table(mut self) -> Result<PbsdfTable, TensorError> {
        let mut values = Vec::with_capacity(self.grid.phi_d.len() * self.slab_len());
        for phi in 0..self.grid.phi_d.len() {
            values.extend(self.slab(phi)?.into_iter().map(|v| v as f32));
        }
        let wavelengths_nm = self
            .wavelengths_nm
            .iter()
            .map(|&w| {
                (w.fract() == 0.0 && (0.0..=65535.0).contains(&w))
                    .then_some(w as u16)
                    .ok_or_else(|| TensorError::field("wvls", format!("{w} is not a uint16 nm")))
            })
            .collect::<Result<_, _>>()?;
        Ok(PbsdfTable {
            grid: self.grid,
            wavelengths_nm,
            values,
        })
    }
}

/// Slack on the angle ranges: float32 π is 8.7e-8 above π.
const ANGLE_SLACK: f64 = 1e-5;

/// An angle field: shape (1, N) or (N,), N ≥ 2, float, finite, strictly increasing, within
/// [0, π/2] for θ and [−2π, 2π] for φ_d (`limit` the upper end; φ_d is −limit to limit).
fn read_angles(
    source: &mut (impl Read + Seek),
    field: &FieldInfo,
    limit: f64,
) -> Result<Vec<f64>, TensorError> {
    let refuse = |message: String| TensorError::field(&field.name, message);
    let count = match field.shape[..] {
        [n] | [1, n] => n,
        _ => 0,
    };
    if count < 2 || !matches!(field.dtype, Dtype::F32 | Dtype::F64) {
        return Err(refuse(format!(
            "shape {} of {}: expected float32 angles of shape (1, N) with N ≥ 2 (the plugin \
             interpolates between nodes)",
            field.shape_text(),
            field.dtype.name()
        )));
    }
    let values = read_values(source, field, 0, count as usize)?;
    let lower = if limit > 2.0 { -limit } else { 0.0 };
    if let Some(bad) = values
        .iter()
        .find(|v| !(**v >= lower - ANGLE_SLACK && **v <= limit + ANGLE_SLACK))
    {
        return Err(refuse(format!(
            "{bad} rad is outside [{lower:.6}, {limit:.6}]"
        )));
    }
    if let Some(i) = (1..values.len()).find(|&i| values[i] <= values[i - 1]) {
        return Err(refuse(format!(
            "not strictly increasing: node {i} ({}) after {}",
            values[i],
            values[i - 1]
        )));
    }
    Ok(values)
}

/// `wvls`: shape (N_λ,) (or (1, N_λ)), N_λ ≥ 1, positive finite nanometres.
fn read_wavelengths(
    source: &mut (impl Read + Seek),
    field: &FieldInfo,
) -> Result<Vec<f64>, TensorError> {
    let count = match field.shape[..] {
        [n] | [1, n] => n,
        _ => 0,
    };
    if count == 0 {
        return Err(TensorError::field(
            "wvls",
            format!(
                "shape {}: no wavelengths (expected shape (N,), N ≥ 1, in nm)",
                field.shape_text()
            ),
        ));
    }
    let values = read_values(source, field, 0, count as usize)?;
    match values.iter().find(|w| !(w.is_finite() && **w > 0.0)) {
        Some(bad) => Err(TensorError::field(
            "wvls",
            format!("{bad} is not a positive wavelength in nm"),
        )),
        None => Ok(values),
    }
}

fn check_m_shape(m: &FieldInfo, grid: &PbsdfGrid, wavelengths: usize) -> Result<(), TensorError> {
    let [p, d, h] = grid.counts().map(|n| n as u64);
    let expected = [p, d, h, wavelengths as u64, 4, 4];
    if m.shape != expected {
        return Err(TensorError::field(
            "M",
            format!(
                "shape {} disagrees with the grids: phi_d, theta_d, theta_h and wvls make {}",
                m.shape_text(),
                shape_text(&expected)
            ),
        ));
    }
    if !matches!(m.dtype, Dtype::F32 | Dtype::F64) {
        return Err(TensorError::field(
            "M",
            format!("{} values: expected float32", m.dtype.name()),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn small_table() -> PbsdfTable {
        let grid = PbsdfGrid {
            phi_d: vec![-std::f64::consts::PI, 0.0, std::f64::consts::PI],
            theta_d: vec![0.0, 0.7, std::f64::consts::FRAC_PI_2],
            theta_h: vec![0.0, std::f64::consts::FRAC_PI_2],
        };
        let n = grid.nodes() * 2 * 16;
        PbsdfTable {
            grid,
            wavelengths_nm: vec![8000, 12000],
            values: (0..n).map(|i| i as f32 * 0.25 - 3.0).collect(),
        }
    }

    fn open(bytes: &[u8]) -> Result<PbsdfFile<Cursor<&[u8]>>, TensorError> {
        PbsdfFile::from_reader(Cursor::new(bytes), bytes.len() as u64)
    }

    /// Written then read, every field is the same to the bit (the angles through float32).
    #[test]
    fn a_written_table_reads_back_exactly() {
        let table = small_table();
        let bytes = table.to_bytes();
        let back = open(&bytes).unwrap().read_table().unwrap();
        assert_eq!(back.values, table.values);
        assert_eq!(back.wavelengths_nm, table.wavelengths_nm);
        let f32_of = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<_>>();
        assert_eq!(f32_of(&back.grid.phi_d), f32_of(&table.grid.phi_d));
        assert_eq!(f32_of(&back.grid.theta_h), f32_of(&table.grid.theta_h));
        assert_eq!(back.matrix(2, 1, 1, 1), table.matrix(2, 1, 1, 1));
    }

    fn with_field(replace: &str, field: FieldData) -> Vec<u8> {
        let t = small_table();
        let row = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
        let mut fields = vec![
            FieldData::f32("phi_d", vec![1, 3], &row(&t.grid.phi_d)),
            FieldData::f32("theta_d", vec![1, 3], &row(&t.grid.theta_d)),
            FieldData::f32("theta_h", vec![1, 2], &row(&t.grid.theta_h)),
            FieldData::u16("wvls", vec![2], &t.wavelengths_nm),
            FieldData::f32("M", vec![3, 3, 2, 2, 4, 4], &t.values),
        ];
        fields.retain(|f| f.name != replace);
        fields.push(field);
        tensor_file_bytes(&fields)
    }

    fn refusal(bytes: &[u8]) -> String {
        open(bytes).err().expect("refused").to_string()
    }

    #[test]
    fn bad_tables_are_refused_naming_the_field() {
        // Mitsuba's own spectralon_lowres.pbsdf has empty angle fields.
        let empty = with_field("phi_d", FieldData::f32("phi_d", vec![0, 22], &[]));
        let message = refusal(&empty);
        assert!(
            message.starts_with("field 'phi_d': shape (0, 22)"),
            "{message}"
        );
        let no_wvls = with_field("wvls", FieldData::u16("wvls", vec![0], &[]));
        assert!(refusal(&no_wvls).starts_with("field 'wvls': shape (0,): no wavelengths"));
        let m = with_field(
            "M",
            FieldData::f32("M", vec![3, 3, 3, 2, 4, 4], &[0.0; 1152]),
        );
        let message = refusal(&m);
        assert!(
            message.contains("'M': shape (3, 3, 3, 2, 4, 4) disagrees with the grids")
                && message.contains("make (3, 3, 2, 2, 4, 4)"),
            "{message}"
        );
        let unsorted = with_field(
            "theta_h",
            FieldData::f32("theta_h", vec![1, 2], &[1.0, 0.5]),
        );
        assert!(refusal(&unsorted).contains("'theta_h': not strictly increasing"));
        let mut wrong_magic = small_table().to_bytes();
        wrong_magic[0] = b'T';
        assert!(refusal(&wrong_magic).contains("not a Mitsuba tensor file"));
        let whole = small_table().to_bytes();
        let cut = &whole[..whole.len() - 4];
        assert!(refusal(cut).starts_with("field 'M': truncated"));
        assert!(refusal(&whole[..20]).contains("truncated: the file ends inside"));
        for message in [refusal(&empty), refusal(cut), refusal(&m)] {
            assert!(!message.contains('\n'));
        }
    }
}
