//! Checked construction of local directions from user angles (degrees). The frame itself lives in
//! `optics::frame`.

use super::ModelError;
use crate::optics::Direction;

impl Direction {
    /// From zenith and azimuth in degrees, refusing zenith outside [0°, 90°) and non-finite values.
    pub fn from_degrees_checked(
        name: &'static str,
        theta_deg: f64,
        phi_deg: f64,
    ) -> Result<Direction, ModelError> {
        if !(theta_deg.is_finite() && (0.0..90.0).contains(&theta_deg)) {
            return Err(ModelError::Zenith {
                name,
                value: theta_deg,
            });
        }
        if !phi_deg.is_finite() {
            return Err(ModelError::Azimuth {
                name,
                value: phi_deg,
            });
        }
        Ok(Direction::from_degrees(theta_deg, phi_deg))
    }

    /// A detector direction from a signed zenith angle (in-plane scans are written −80…80°):
    /// within (−90°, 90°), a negative θ is read as [`fold_signed_zenith`] reads it.
    pub fn from_signed_degrees_checked(
        name: &'static str,
        theta_deg: f64,
        phi_deg: f64,
    ) -> Result<Direction, ModelError> {
        if !(theta_deg > -90.0 && theta_deg < 90.0) {
            return Err(ModelError::DetectorZenith {
                name,
                value: theta_deg,
            });
        }
        // A non-finite azimuth is refused below as given (folded, it would read NaN).
        let (theta, phi) = if phi_deg.is_finite() {
            fold_signed_zenith(theta_deg, phi_deg)
        } else {
            (theta_deg.abs(), phi_deg)
        };
        Direction::from_degrees_checked(name, theta, phi)
    }
}

/// A signed zenith angle as a direction above the surface: θ < 0 is the direction on the other
/// side of the normal, (|θ|, φ + 180°), with φ then wrapped into [0°, 360°) so that (−30°, 180°)
/// is exactly (30°, 0°). A θ ≥ 0 (−0 included) is returned unchanged.
pub fn fold_signed_zenith(theta_deg: f64, phi_deg: f64) -> (f64, f64) {
    if theta_deg < 0.0 {
        (-theta_deg, (phi_deg + 180.0).rem_euclid(360.0))
    } else {
        (theta_deg, phi_deg)
    }
}

/// What a reader of signed detector angles tells the user (once per file or command, not per
/// row), if any of its `rows` had θ_r < 0: `place` names the file or the flag.
pub fn signed_zenith_note(place: &str, rows: usize) -> Option<String> {
    let counted = crate::text::counted(rows, "row");
    (rows > 0).then(|| format!("{place}: {counted} with θ_r < 0 read as (|θ_r|, φ_r + 180°)"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checked_angles_refuse_out_of_range() {
        assert!(Direction::from_degrees_checked("theta_i", 90.0, 0.0).is_err());
        assert!(Direction::from_degrees_checked("theta_i", -1.0, 0.0).is_err());
        assert!(Direction::from_degrees_checked("theta_i", f64::NAN, 0.0).is_err());
        assert!(Direction::from_degrees_checked("phi_i", 10.0, f64::INFINITY).is_err());
        assert!(Direction::from_degrees_checked("theta_i", 89.9, -720.0).is_ok());
    }

    #[test]
    fn a_negative_zenith_is_the_direction_across_the_normal() {
        assert_eq!(fold_signed_zenith(-30.0, 180.0), (30.0, 0.0));
        assert_eq!(fold_signed_zenith(-30.0, 0.0), (30.0, 180.0));
        assert_eq!(fold_signed_zenith(-80.0, 270.0), (80.0, 90.0));
        assert_eq!(fold_signed_zenith(30.0, 400.0), (30.0, 400.0));
        let signed = Direction::from_signed_degrees_checked("theta_r", -30.0, 180.0).unwrap();
        let unsigned = Direction::from_degrees_checked("theta_r", 30.0, 0.0).unwrap();
        assert_eq!(signed, unsigned);
        for bad in [-90.0, 90.0, f64::NAN] {
            let error = Direction::from_signed_degrees_checked("theta_r", bad, 0.0).unwrap_err();
            assert!(error.to_string().contains("(−90°, 90°)"), "{error}");
        }
    }
}
