//! Colour maps for the previews: a thermal map for apparent temperature, a diverging map for
//! S1/S2 (white at zero), a viridis-like sequential map for DoLP, and a cyclic hue wheel for AoP
//! (AoP = −90° and +90° are the same orientation and get the same colour).

/// Piecewise-linear map through (position, RGB) anchors on [0, 1], with the colours of values
/// below and above the displayed range (chosen to stand out from the map itself).
pub struct ColorMap {
    anchors: &'static [(f64, [u8; 3])],
    pub under: [u8; 3],
    pub over: [u8; 3],
}

pub const THERMAL: ColorMap = ColorMap {
    anchors: &[
        (0.0, [0, 0, 10]),
        (0.15, [40, 10, 100]),
        (0.35, [150, 20, 140]),
        (0.55, [220, 60, 40]),
        (0.75, [250, 150, 20]),
        (0.9, [255, 220, 80]),
        (1.0, [255, 255, 230]),
    ],
    under: [0, 150, 255],
    over: [0, 220, 0],
};

/// White-hot grey scale, as thermal cameras show it.
pub const GRAY: ColorMap = ColorMap {
    anchors: &[(0.0, [0, 0, 0]), (1.0, [255, 255, 255])],
    under: [0, 90, 255],
    over: [255, 40, 0],
};

pub const DIVERGING: ColorMap = ColorMap {
    anchors: &[
        (0.0, [40, 70, 170]),
        (0.25, [130, 165, 220]),
        (0.5, [245, 245, 245]),
        (0.75, [225, 130, 110]),
        (1.0, [180, 30, 40]),
    ],
    under: [0, 150, 0],
    over: [150, 255, 120],
};

pub const SEQUENTIAL: ColorMap = ColorMap {
    anchors: &[
        (0.0, [68, 1, 84]),
        (0.25, [59, 82, 139]),
        (0.5, [33, 145, 140]),
        (0.75, [94, 201, 98]),
        (1.0, [253, 231, 37]),
    ],
    under: [255, 0, 255],
    over: [255, 0, 255],
};

/// Masked pixels (AoP where the polarization is too weak to have an angle).
pub const MASKED: [u8; 3] = [128, 128, 128];

impl ColorMap {
    /// Colour at t ∈ [0, 1] (clamped; NaN maps to the low end).
    pub fn at(&self, t: f64) -> [u8; 3] {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let i = self
            .anchors
            .partition_point(|a| a.0 <= t)
            .clamp(1, self.anchors.len() - 1);
        let ((t0, c0), (t1, c1)) = (self.anchors[i - 1], self.anchors[i]);
        let f = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        [0, 1, 2].map(|k| (c0[k] as f64 + f * (c1[k] as f64 - c0[k] as f64)).round() as u8)
    }
}

/// A colour map sampled at 256 levels, for mapping millions of pixels.
pub struct Lut([[u8; 3]; 256]);

impl Lut {
    pub fn new(map: &ColorMap) -> Lut {
        Lut(std::array::from_fn(|i| map.at(i as f64 / 255.0)))
    }

    /// Colour at t ∈ [0, 1] (clamped; NaN maps to the low end), to the nearest level.
    #[inline]
    pub fn at(&self, t: f64) -> [u8; 3] {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        self.0[(t * 255.0).round() as usize]
    }
}

/// Cyclic colour for t ∈ [0, 1) with at(0) = at(1): a hue wheel at fixed saturation/lightness.
pub fn cyclic(t: f64) -> [u8; 3] {
    let hue = t.rem_euclid(1.0) * 6.0;
    let (saturation, lightness) = (0.65, 0.55);
    let chroma = (1.0 - (2.0 * lightness - 1.0f64).abs()) * saturation;
    let x = chroma * (1.0 - (hue % 2.0 - 1.0).abs());
    let (r, g, b) = match hue as u32 {
        0 => (chroma, x, 0.0),
        1 => (x, chroma, 0.0),
        2 => (0.0, chroma, x),
        3 => (0.0, x, chroma),
        4 => (x, 0.0, chroma),
        _ => (chroma, 0.0, x),
    };
    let m = lightness - chroma / 2.0;
    [r, g, b].map(|c| ((c + m) * 255.0).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_hit_their_anchors_and_clamp() {
        assert_eq!(DIVERGING.at(0.5), [245, 245, 245]);
        assert_eq!(THERMAL.at(-3.0), [0, 0, 10]);
        assert_eq!(SEQUENTIAL.at(2.0), [253, 231, 37]);
        assert_eq!(SEQUENTIAL.at(f64::NAN), [68, 1, 84]);
    }

    #[test]
    fn lookup_tables_follow_their_maps() {
        let lut = Lut::new(&DIVERGING);
        for t in [0.0, 0.3, 0.5, 0.77, 1.0] {
            let (a, b) = (lut.at(t), DIVERGING.at(t));
            assert!(
                (0..3).all(|k| (a[k] as i32 - b[k] as i32).abs() <= 2),
                "{t}"
            );
        }
        assert_eq!(lut.at(f64::NAN), DIVERGING.at(0.0));
    }

    #[test]
    fn cyclic_map_wraps() {
        assert_eq!(cyclic(0.0), cyclic(1.0));
        assert_eq!(cyclic(0.999_999), cyclic(0.0));
        assert_ne!(cyclic(0.25), cyclic(0.75));
    }
}
