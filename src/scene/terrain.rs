//! A procedural terrain tile (docs/scenes.md, `shape = { kind = "terrain", … }`): a Gaussian random
//! heightfield with a chosen roughness spectrum, synthesized by FFT so that clutter needs no file.
//!
//! **Spectral synthesis.** On the periodic nx × ny grid of the tile (period = its size), the height
//! is h = Re F⁻¹[√W(k) ξ(k)] with ξ complex white Gaussian noise and W the isotropic power
//! spectral density of the chosen correlation model (ℓ the correlation length, H the Hurst
//! exponent):
//!   Gaussian   C(r) ∝ exp(−r²/ℓ²)                W(k) ∝ exp(−k²ℓ²/4);
//!   von Kármán C(r) ∝ (r/ℓ)^H K_H(r/ℓ)           W(k) ∝ (1 + k²ℓ²)^−(H+1)
//! (the 2-D Fourier pairs; H → 1/2 is the exponential correlation, small H the self-affine,
//! fractal terrain of real landscapes below ℓ). The realization is scaled so that its own rms
//! height is exactly `rms_height_m` and its mean is 0. The slopes come from the same spectrum,
//! ∂h/∂x = Re F⁻¹[i k_x √W ξ] (the Nyquist row and column dropped, where i k is not real-valued on
//! the grid), so the normals are the exact normals of the band-limited surface, as the sphere's are
//! of the sphere. The tile is periodic: its opposite edges have equal heights and normals, so
//! tiles placed side by side join without a seam.
//!
//! A 2-D FFT is two passes of `rustfft`'s 1-D transforms (rows, then columns); the crate has no
//! n-dimensional transform.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;
use std::f64::consts::PI;

/// The roughness spectrum of a terrain tile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TerrainSpectrum {
    /// Root-mean-square height (m), exactly that of the realization.
    pub rms_height_m: f64,
    /// Correlation length ℓ (m).
    pub correlation_length_m: f64,
    /// Hurst exponent H of a von Kármán spectrum; `None` for a Gaussian one.
    pub hurst: Option<f64>,
    pub seed: u64,
}

impl TerrainSpectrum {
    /// W(k) up to a constant (see the module docs).
    fn power(&self, k: f64) -> f64 {
        let kl2 = (k * self.correlation_length_m).powi(2);
        match self.hurst {
            None => (-kl2 / 4.0).exp(),
            Some(h) => (1.0 + kl2).powf(-(h + 1.0)),
        }
    }
}

/// Heights and slopes on the periodic grid, row-major `[j * nx + i]` for cell corner (i, j).
pub struct Heightfield {
    pub height: Vec<f64>,
    pub slope_x: Vec<f64>,
    pub slope_y: Vec<f64>,
}

/// The heightfield of an `size[0]` × `size[1]` tile sampled at `nx` × `ny` grid points with
/// spacing size/n (one period; see the module docs).
pub fn synthesize(size: [f64; 2], [nx, ny]: [usize; 2], spectrum: &TerrainSpectrum) -> Heightfield {
    let mut rng = ChaCha8Rng::seed_from_u64(spectrum.seed);
    let wavenumber = |m: usize, n: usize, length: f64| {
        // FFT order: 0, 1, …, n/2, −(n/2 − 1), …, −1 cycles per period.
        let cycles = if m <= n / 2 {
            m as f64
        } else {
            m as f64 - n as f64
        };
        2.0 * PI * cycles / length
    };
    let mut amplitude = vec![Complex::new(0.0, 0.0); nx * ny];
    for j in 0..ny {
        let ky = wavenumber(j, ny, size[1]);
        for i in 0..nx {
            let kx = wavenumber(i, nx, size[0]);
            let root = spectrum.power((kx * kx + ky * ky).sqrt()).sqrt();
            let xi = Complex::new(
                crate::elementary::standard_normal(&mut rng),
                crate::elementary::standard_normal(&mut rng),
            );
            amplitude[j * nx + i] = xi * root;
        }
    }
    amplitude[0] = Complex::new(0.0, 0.0); // zero mean
    let derivative = |axis: usize| {
        let mut field = amplitude.clone();
        for j in 0..ny {
            for i in 0..nx {
                let (m, n, length) = if axis == 0 {
                    (i, nx, size[0])
                } else {
                    (j, ny, size[1])
                };
                let nyquist = n % 2 == 0 && m == n / 2;
                let k = if nyquist {
                    0.0
                } else {
                    wavenumber(m, n, length)
                };
                field[j * nx + i] *= Complex::new(0.0, k);
            }
        }
        inverse_2d(field, nx, ny)
    };
    let slope_x = derivative(0);
    let slope_y = derivative(1);
    let height = inverse_2d(amplitude, nx, ny);
    let rms = (height.iter().map(|h| h * h).sum::<f64>() / height.len() as f64).sqrt();
    let scale = if rms > 0.0 {
        spectrum.rms_height_m / rms
    } else {
        0.0
    };
    let scaled = |v: Vec<f64>| v.into_iter().map(|x| x * scale).collect();
    Heightfield {
        height: scaled(height),
        slope_x: scaled(slope_x),
        slope_y: scaled(slope_y),
    }
}

/// Re F⁻¹ of a row-major nx × ny field (unnormalized: the scale is fixed afterwards).
fn inverse_2d(mut field: Vec<Complex<f64>>, nx: usize, ny: usize) -> Vec<f64> {
    let mut planner = FftPlanner::new();
    planner.plan_fft_inverse(nx).process(&mut field);
    let column_fft = planner.plan_fft_inverse(ny);
    let mut column = vec![Complex::new(0.0, 0.0); ny];
    for i in 0..nx {
        for j in 0..ny {
            column[j] = field[j * nx + i];
        }
        column_fft.process(&mut column);
        for j in 0..ny {
            field[j * nx + i] = column[j];
        }
    }
    field.into_iter().map(|c| c.re).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gaussian(rms: f64, correlation: f64, seed: u64) -> TerrainSpectrum {
        TerrainSpectrum {
            rms_height_m: rms,
            correlation_length_m: correlation,
            hurst: None,
            seed,
        }
    }

    /// Normalized autocorrelation of the heights at a lag of `lag` grid steps along x.
    fn correlation_at(field: &Heightfield, nx: usize, lag: usize) -> f64 {
        let h = &field.height;
        let c: f64 = (0..h.len())
            .map(|p| {
                let (i, j) = (p % nx, p / nx);
                h[p] * h[j * nx + (i + lag) % nx]
            })
            .sum();
        let c0: f64 = h.iter().map(|v| v * v).sum();
        c / c0
    }

    #[test]
    fn the_realization_has_the_asked_rms_and_the_gaussian_correlation() {
        // 256 × 256 grids of a 64 m tile (0.25 m cells), ℓ = 2 m: ~1000 correlation areas each,
        // so one realization's correlation at lag ℓ scatters by ~0.03 about exp(−1) = 0.368;
        // the mean of eight seeds is within 0.03 (3σ) of it, where a wrong law is off by tenths.
        let count = 8.0;
        let (mut at_l, mut at_2l) = (0.0, 0.0);
        for seed in 1..=8 {
            let field = synthesize([64.0, 64.0], [256, 256], &gaussian(0.3, 2.0, seed));
            let n = field.height.len() as f64;
            let mean = field.height.iter().sum::<f64>() / n;
            let rms = (field.height.iter().map(|h| h * h).sum::<f64>() / n).sqrt();
            assert!(
                mean.abs() < 1e-12 && (rms - 0.3).abs() < 1e-12,
                "{mean} {rms}"
            );
            at_l += correlation_at(&field, 256, 8) / count;
            at_2l += correlation_at(&field, 256, 16) / count;
            // Gaussian correlation exp(−r²/ℓ²): rms slope per axis √2 h/ℓ.
            let slope_rms = (field.slope_x.iter().map(|s| s * s).sum::<f64>() / n).sqrt();
            let expected = 2f64.sqrt() * 0.3 / 2.0;
            assert!(
                (slope_rms / expected - 1.0).abs() < 0.05,
                "{slope_rms} vs {expected}"
            );
        }
        assert!((at_l - (-1.0f64).exp()).abs() < 0.03, "C(ℓ)/C(0) = {at_l}");
        assert!(
            (at_2l - (-4.0f64).exp()).abs() < 0.03,
            "C(2ℓ)/C(0) = {at_2l}"
        );
    }

    #[test]
    fn slopes_are_the_derivatives_of_the_heights() {
        // ℓ = 16 cells: the central difference of the heights agrees with the spectral slope to
        // O((Δ/ℓ)²) of the rms slope (measured: 1.25 % at the worst of 16 384 points; a wrong
        // sign, axis or scale is off by the whole slope).
        let (size, n) = (32.0, 128);
        let field = synthesize([size, size], [n, n], &gaussian(0.2, 4.0, 3));
        let step = size / n as f64;
        let mut worst: f64 = 0.0;
        for j in 0..n {
            for i in 0..n {
                let h = |i: usize, j: usize| field.height[(j % n) * n + i % n];
                let dx = (h(i + 1, j) - h(i + n - 1, j)) / (2.0 * step);
                let dy = (h(i, j + 1) - h(i, j + n - 1)) / (2.0 * step);
                worst = worst
                    .max((dx - field.slope_x[j * n + i]).abs())
                    .max((dy - field.slope_y[j * n + i]).abs());
            }
        }
        let slope_rms = 2f64.sqrt() * 0.2 / 4.0;
        assert!(worst < 0.02 * slope_rms, "worst {worst} of {slope_rms}");
    }

    #[test]
    fn the_seed_decides_the_tile_and_von_karman_is_rougher_at_short_range() {
        let a = synthesize([16.0, 8.0], [64, 32], &gaussian(0.1, 1.0, 1));
        let b = synthesize([16.0, 8.0], [64, 32], &gaussian(0.1, 1.0, 1));
        let c = synthesize([16.0, 8.0], [64, 32], &gaussian(0.1, 1.0, 2));
        assert_eq!(a.height, b.height);
        assert_ne!(a.height, c.height);
        // Same rms and ℓ: a fractal (H = 0.3) surface decorrelates faster at one cell's lag.
        let fractal = TerrainSpectrum {
            hurst: Some(0.3),
            ..gaussian(0.1, 1.0, 1)
        };
        let f = synthesize([16.0, 8.0], [64, 32], &fractal);
        assert!(correlation_at(&f, 64, 1) < correlation_at(&a, 64, 1) - 0.05);
    }
}
