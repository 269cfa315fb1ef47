//! The optional atmospheric path between the surface and the camera:
//! S_sensor = τ S + L_path δ_j0 with τ and L_path of the scene's [`Atmosphere`] at the pixel's range
//! (docs/design.md §1.5, §1.12).

use crate::scene::Atmosphere;

/// Atmospheric transmission and path emission for one pixel at `range` metres: the Stokes
/// vector `s` seen through the path, and its standard error `error` scaled by τ (the path
/// itself is exact).
#[inline]
pub fn through_atmosphere(
    s: [f64; 4],
    error: [f64; 4],
    range: f64,
    atmosphere: &Atmosphere,
) -> ([f64; 4], [f64; 4]) {
    let (tau, path_radiance) = atmosphere.along(range);
    (
        [
            tau * s[0] + path_radiance,
            tau * s[1],
            tau * s[2],
            tau * s[3],
        ],
        error.map(|e| e * tau),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atmosphere_blends_toward_path_radiance() {
        let band = crate::optics::Band::lwir();
        let atm = Atmosphere::extinction(1e-3, 280.0, &band);
        let (s, e) = through_atmosphere([10.0, 1.0, -1.0, 0.5], [0.1; 4], 1000.0, &atm);
        let tau = (-1.0f64).exp();
        let path = band.radiance(280.0);
        assert!((s[0] - (10.0 * tau + path * (1.0 - tau))).abs() < 1e-12);
        assert!(e.iter().all(|e| (e - 0.1 * tau).abs() < 1e-15));
        assert!((s[1] - tau).abs() < 1e-12 && (s[2] + tau).abs() < 1e-12);
        assert!((s[3] - 0.5 * tau).abs() < 1e-12);
    }
}
