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
        Ok(Direction::from_angles(
            theta_deg.to_radians(),
            phi_deg.to_radians(),
        ))
    }
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
}
