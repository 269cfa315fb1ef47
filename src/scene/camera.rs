//! Pinhole camera: position, look-at point, up vector, vertical field of view, resolution.
//! Pixel (i, j) has its centre at (i + ½, j + ½); row 0 is the top of the image.

use nalgebra::Vector3;

/// A camera that cannot be built: the key at fault and why.
pub type CameraError = super::error::InvalidSetting;

#[derive(Clone, Debug)]
pub struct Camera {
    pub position: Vector3<f64>,
    /// Orthonormal camera frame: `right × up = −forward` (right-handed, looking along forward).
    pub forward: Vector3<f64>,
    pub right: Vector3<f64>,
    pub up: Vector3<f64>,
    pub width: u32,
    pub height: u32,
    /// tan of half the vertical and horizontal fields of view.
    pub tan_half_fov_y: f64,
    pub tan_half_fov_x: f64,
}

impl Camera {
    pub fn new(
        position: Vector3<f64>,
        look_at: Vector3<f64>,
        up_hint: Vector3<f64>,
        fov_y_deg: f64,
        width: u32,
        height: u32,
    ) -> Result<Camera, CameraError> {
        if !(position.iter().chain(look_at.iter()).chain(up_hint.iter())).all(|c| c.is_finite()) {
            return Err("camera position, look_at and up must be finite".into());
        }
        let view = look_at - position;
        if view.norm() < 1e-9 {
            return Err("camera look_at coincides with its position".into());
        }
        let forward = view.normalize();
        let right = forward.cross(&up_hint);
        if right.norm() < 1e-9 * up_hint.norm().max(1e-300) || up_hint.norm() == 0.0 {
            return Err("camera up is zero or parallel to the viewing direction".into());
        }
        let right = right.normalize();
        let up = right.cross(&forward);
        if !(fov_y_deg.is_finite() && fov_y_deg > 0.0 && fov_y_deg < 179.0) {
            return Err(format!(
                "camera fov_deg = {} must be within (0°, 179°)",
                crate::text::number(fov_y_deg)
            )
            .into());
        }
        // ~200 bytes per pixel in flight (Stokes, fragments, channels, encoded files): 8K UHD
        // stays within a few GiB.
        if width == 0 || height == 0 || width as u64 * height as u64 > 7680 * 4320 {
            return Err(format!(
                "camera resolution {width}×{height} must be at least 1×1 and at most 7680×4320 \
                 pixels in total"
            )
            .into());
        }
        let tan_half_fov_y = (0.5 * fov_y_deg.to_radians()).tan();
        Ok(Camera {
            position,
            forward,
            right,
            up,
            width,
            height,
            tan_half_fov_y,
            tan_half_fov_x: tan_half_fov_y * width as f64 / height as f64,
        })
    }

    /// Camera-space coordinates (x right, y up, z depth along forward) of a world point.
    #[inline]
    pub fn to_view(&self, p: &Vector3<f64>) -> Vector3<f64> {
        let d = p - self.position;
        Vector3::new(d.dot(&self.right), d.dot(&self.up), d.dot(&self.forward))
    }

    /// Continuous pixel coordinates (x to the right, y down) of a camera-space point with z > 0.
    #[inline]
    pub fn view_to_screen(&self, v: &Vector3<f64>) -> (f64, f64) {
        let x = 0.5 * self.width as f64 * (1.0 + v.x / (v.z * self.tan_half_fov_x));
        let y = 0.5 * self.height as f64 * (1.0 - v.y / (v.z * self.tan_half_fov_y));
        (x, y)
    }

    /// Unit world direction of the ray through pixel coordinates (x, y).
    #[inline]
    pub fn ray_direction(&self, x: f64, y: f64) -> Vector3<f64> {
        let ndc_x = 2.0 * x / self.width as f64 - 1.0;
        let ndc_y = 1.0 - 2.0 * y / self.height as f64;
        (self.forward
            + self.right * (ndc_x * self.tan_half_fov_x)
            + self.up * (ndc_y * self.tan_half_fov_y))
            .normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_and_rays_agree() {
        let cam = Camera::new(
            Vector3::new(1.0, -5.0, 2.0),
            Vector3::new(0.0, 0.0, 0.5),
            Vector3::z(),
            40.0,
            64,
            48,
        )
        .unwrap();
        assert!((cam.right.cross(&cam.up) + cam.forward).norm() < 1e-12);
        for (x, y) in [(0.5, 0.5), (32.0, 24.0), (63.5, 10.25)] {
            let p = cam.position + cam.ray_direction(x, y) * 7.3;
            let (sx, sy) = cam.view_to_screen(&cam.to_view(&p));
            assert!((sx - x).abs() < 1e-9 && (sy - y).abs() < 1e-9);
        }
        // The look-at point projects to the image centre; world up points up the image.
        let (cx, cy) = cam.view_to_screen(&cam.to_view(&Vector3::new(0.0, 0.0, 0.5)));
        assert!((cx - 32.0).abs() < 1e-9 && (cy - 24.0).abs() < 1e-9);
        let (_, above) = cam.view_to_screen(&cam.to_view(&Vector3::new(0.0, 0.0, 1.0)));
        assert!(above < cy);
    }

    #[test]
    fn bad_cameras_are_refused() {
        let p = Vector3::new(0.0, -5.0, 0.0);
        assert!(Camera::new(p, p, Vector3::z(), 40.0, 10, 10).is_err());
        assert!(Camera::new(p, Vector3::zeros(), Vector3::y(), 40.0, 10, 10).is_err());
        assert!(Camera::new(p, Vector3::zeros(), Vector3::z(), 0.0, 10, 10).is_err());
        assert!(Camera::new(p, Vector3::zeros(), Vector3::z(), 40.0, 0, 10).is_err());
    }
}
