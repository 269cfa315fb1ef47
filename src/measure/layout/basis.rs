//! SCATMECH's `xyxy` Mueller basis in the sample frame, rotated into irpol's psps
//! (docs/design.md §2.8).
//!
//! psps takes each direction's own s/p basis, s = unit(ẑ × k) for light travelling along k
//! (docs/design.md §1.3). xyxy takes, for every direction, the basis the sample's axes give it:
//! near the normal its first vector is the sample's ŷ, whatever the azimuth, where psps's s turns
//! with the azimuth. A direction of travel at azimuth α (α_r = φ_r for the scattered light,
//! α_i = φ_i + 180° for the incident light, which travels toward the surface) has its xyxy basis
//! turned from its psps basis by α about the direction of travel, in opposite senses for light
//! travelling up and down. With L(η) the Stokes rotation of docs/design.md §1.3,
//!
//!   M_psps = L(α_r) M_xyxy L(α_i)
//!
//! In SCATMECH's own geometry (source at azimuth 180°, so α_i = 0°; viewer at φ_s) this is its
//! `convert` from xyxy to psps, a rotator of φ_s on the scattered side only;
//! `scripts/check_xyxy_basis.py` compares it with SCATMECH's `Mueller(..., 'xyxy')` and
//! `'psps'` at random out-of-plane geometries. L has period 180° in α, so a signed angle folded
//! to (|θ|, φ + 180°) leaves it unchanged.

use crate::elementary::sin_cos_degrees;

/// Rotates a row-major Mueller matrix `m` from the xyxy basis into psps for the incidence
/// azimuth `phi_i_deg` and the detector azimuth `phi_r_deg` (irpol's, docs/design.md §1.1).
/// Only rows and columns 1 and 2 change: m00, m03, m30 and m33 are the same in both bases.
pub fn xyxy_to_psps(m: &mut [f64; 16], phi_i_deg: f64, phi_r_deg: f64) {
    // L(α) on the left mixes rows 1 and 2: row1' = c row1 + s row2, row2' = −s row1 + c row2.
    let (s, c) = sin_cos_degrees(2.0 * phi_r_deg);
    for column in 0..4 {
        let (a, b) = (m[4 + column], m[8 + column]);
        m[4 + column] = c * a + s * b;
        m[8 + column] = c * b - s * a;
    }
    // L(α) on the right mixes columns 1 and 2: col1' = c col1 − s col2, col2' = s col1 + c col2.
    let (s, c) = sin_cos_degrees(2.0 * (phi_i_deg + 180.0));
    for row in 0..4 {
        let (a, b) = (m[4 * row + 1], m[4 * row + 2]);
        m[4 * row + 1] = c * a - s * b;
        m[4 * row + 2] = s * a + c * b;
    }
}

/// The elements the rotation of [`xyxy_to_psps`] mixes with element `index` (row-major),
/// itself included: rows 1 and 2 mix, and so do columns 1 and 2.
pub(super) fn mixed_with(index: usize) -> Vec<usize> {
    let partners = |k: usize| {
        if k == 1 || k == 2 {
            vec![1, 2]
        } else {
            vec![k]
        }
    };
    let mut mixed = Vec::new();
    for row in partners(index / 4) {
        for column in partners(index % 4) {
            mixed.push(row * 4 + column);
        }
    }
    mixed
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> [f64; 16] {
        std::array::from_fn(|k| 1.0 + k as f64 * 0.37 - (k % 3) as f64)
    }

    #[test]
    fn in_plane_and_corner_elements_are_unchanged() {
        // Source at azimuth 180° and detector in the plane of incidence: the bases coincide.
        for phi_r in [0.0, 180.0, -180.0, 360.0] {
            let mut m = example();
            xyxy_to_psps(&mut m, 180.0, phi_r);
            assert_eq!(m, example());
        }
        let mut m = example();
        xyxy_to_psps(&mut m, 31.0, 77.0);
        for k in [0, 3, 12, 15] {
            assert_eq!(m[k], example()[k]);
        }
    }

    #[test]
    fn a_quarter_turn_of_the_detector_flips_the_linear_rows() {
        let mut m = example();
        xyxy_to_psps(&mut m, 180.0, 90.0);
        let e = example();
        for column in 0..4 {
            assert_eq!(m[4 + column], -e[4 + column]);
            assert_eq!(m[8 + column], -e[8 + column]);
        }
    }

    #[test]
    fn mixing_sets_close_rows_and_columns_one_and_two() {
        assert_eq!(mixed_with(0), vec![0]);
        assert_eq!(mixed_with(1), vec![1, 2]);
        assert_eq!(mixed_with(4), vec![4, 8]);
        assert_eq!(mixed_with(6), vec![5, 6, 9, 10]);
        assert_eq!(mixed_with(15), vec![15]);
    }
}
