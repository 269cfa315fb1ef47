//! Sobol's sequence in the first 2 × [`STRATIFIED_DEPTHS`] dimensions, randomized per pixel
//! (module docs of [`super`]).

use super::STRATIFIED_DEPTHS;
use rand::Rng;

/// Dimensions of the sequence: two per stratified depth.
pub const DIMENSIONS: usize = 2 * STRATIFIED_DEPTHS;

/// Generator matrices of Sobol's first four dimensions as 32-bit columns (column k is the
/// direction number v_(k+1) = m_(k+1) / 2^(k+1)): van der Corput, then Joe and Kuo's primitive
/// polynomials x + 1, x² + x + 1 and x³ + x + 1 with initial m = (1), (1, 3), (1, 3, 1).
const SOBOL_MATRICES: [[u32; 32]; DIMENSIONS] = [
    sobol_matrix(0, 0, [0; 3]),
    sobol_matrix(1, 0, [1, 0, 0]),
    sobol_matrix(2, 1, [1, 3, 0]),
    sobol_matrix(3, 1, [1, 3, 1]),
];

/// The generator matrix of a primitive polynomial of `degree` s with inner coefficients
/// `inner` (a₁ … a_(s−1) as bits, a₁ the highest) and initial direction integers `initial`;
/// degree 0 is the van der Corput (identity) matrix. Bratley and Fox's recurrence:
/// m_k = 2a₁m_(k−1) ⊕ 2²a₂m_(k−2) ⊕ … ⊕ 2^s m_(k−s) ⊕ m_(k−s).
const fn sobol_matrix(degree: usize, inner: u32, initial: [u32; 3]) -> [u32; 32] {
    let mut m = [0u32; 33];
    let mut columns = [0u32; 32];
    let mut k = 1;
    while k <= 32 {
        m[k] = if degree == 0 {
            1
        } else if k <= degree {
            initial[k - 1]
        } else {
            let mut value = m[k - degree] ^ (m[k - degree] << degree);
            let mut j = 1;
            while j < degree {
                if (inner >> (degree - 1 - j)) & 1 == 1 {
                    value ^= m[k - j] << j;
                }
                j += 1;
            }
            value
        };
        columns[k - 1] = m[k] << (32 - k);
        k += 1;
    }
    columns
}

/// Point `index` of the unscrambled sequence in dimensions `first` and `first + 1`, as 32
/// fixed-point bits each. Branch-free: a column enters where its bit of the index is set, by a
/// mask (a branch on the index's bits mispredicts about every other column: with it, the
/// Mitsuba comparison's render took 5 % more CPU).
fn sobol_bits(index: u32, first: usize) -> [u32; 2] {
    let (mut bits, mut rest, mut column) = ([0u32; 2], index, 0);
    while rest != 0 {
        let mask = 0u32.wrapping_sub(rest & 1);
        bits[0] ^= SOBOL_MATRICES[first][column] & mask;
        bits[1] ^= SOBOL_MATRICES[first + 1][column] & mask;
        rest >>= 1;
        column += 1;
    }
    bits
}

/// Burley's nested scramble: a Laine–Karras-style hash applied from the most significant bit
/// down, so that each bit is flipped by a function of the seed and the bits above it only (an
/// Owen scramble's structure: boxes of the net map onto boxes).
fn nested_scramble(bits: u32, seed: u32) -> u32 {
    let mut v = bits.reverse_bits().wrapping_add(seed);
    v ^= v.wrapping_mul(0x6c50_b47c);
    v ^= v.wrapping_mul(0xb82f_1e52);
    v ^= v.wrapping_mul(0xc7af_e638);
    v ^= v.wrapping_mul(0x8d22_f6e6);
    v.reverse_bits()
}

/// One pixel's randomization of the sequence: per dimension a scramble seed and a digital shift.
#[derive(Clone, Copy, Debug)]
pub struct Randomization {
    seeds: [u32; DIMENSIONS],
    shifts: [u32; DIMENSIONS],
}

impl Randomization {
    /// A randomization drawn from `rng`.
    pub fn new(rng: &mut impl Rng) -> Randomization {
        Randomization {
            seeds: rng.random(),
            shifts: rng.random(),
        }
    }

    /// Coordinates `first` and `first + 1` of point `index`, randomized: the scrambled, shifted
    /// 32 bits of the sequence plus 20 uniform bits from `rng` below them (52 bits in all, so
    /// that the largest value, (2^52 − 1)/2^52, is exactly representable below 1).
    pub fn pair(&self, index: usize, first: usize, rng: &mut impl Rng) -> [f64; 2] {
        let bits = sobol_bits(index as u32, first);
        let below: u64 = rng.random();
        [0, 1].map(|k| {
            let d = first + k;
            let randomized = nested_scramble(bits[k], self.seeds[d]) ^ self.shifts[d];
            let low = (below >> (32 * k)) & 0xf_ffff;
            ((u64::from(randomized) << 20) | low) as f64 / (1u64 << 52) as f64
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The matrices are Sobol's: the first eight points of the four dimensions as SciPy's
    /// `qmc.Sobol(d=4, scramble=False)` lists them (in Gray-code order: its point g is point
    /// g ⊕ (g >> 1) of the natural order used here).
    #[test]
    fn the_unscrambled_sequence_is_sobols() {
        let scipy: [[f64; 4]; 8] = [
            [0.0, 0.0, 0.0, 0.0],
            [0.5, 0.5, 0.5, 0.5],
            [0.75, 0.25, 0.25, 0.25],
            [0.25, 0.75, 0.75, 0.75],
            [0.375, 0.375, 0.625, 0.875],
            [0.875, 0.875, 0.125, 0.375],
            [0.625, 0.125, 0.875, 0.625],
            [0.125, 0.625, 0.375, 0.125],
        ];
        for (g, expected) in scipy.iter().enumerate() {
            let index = (g ^ (g >> 1)) as u32;
            for (dimension, value) in expected.iter().enumerate() {
                let bits = sobol_bits(index, dimension - dimension % 2)[dimension % 2];
                let ours = bits as f64 / 4_294_967_296.0;
                assert_eq!(ours, *value, "point {g}, dimension {dimension}");
            }
        }
    }
}
