//! Convective heat transfer between a surface and the air (docs/design.md §1.8).

/// McAdams' forced-convection coefficient of a surface in wind of `wind_m_s` (m s⁻¹):
/// h = 5.7 + 3.8 v W m⁻² K⁻¹, the front-surface default when a part gives no `convection_w_m2k`.
#[inline]
pub fn mcadams_coefficient(wind_m_s: f64) -> f64 {
    5.7 + 3.8 * wind_m_s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mcadams_is_its_closed_form() {
        assert_eq!(mcadams_coefficient(0.0), 5.7);
        for v in [0.5, 2.0, 7.25] {
            assert!((mcadams_coefficient(v) - (5.7 + 3.8 * v)).abs() < 1e-12);
        }
        // The slope is 3.8 W m⁻² K⁻¹ per m s⁻¹.
        assert!((mcadams_coefficient(3.0) - mcadams_coefficient(2.0) - 3.8).abs() < 1e-12);
    }
}
