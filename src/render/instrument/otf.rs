//! Camera optics as an optical transfer function (docs/design.md §1.11): the image the detector
//! samples is the scene convolved with the band-averaged diffraction PSF of a circular aperture,
//! a Gaussian (defocus, jitter) and the pixel's square aperture. Each has a closed-form OTF, so the
//! image is filtered in the Fourier domain by their product,
//! OTF(f) = Σ_m w_m MTF_diff(|f| λ_m F#/p) · sinc(a f_x) sinc(a f_y) · exp(−2π²σ²|f|²),
//! f in cycles per pixel, p the pitch, a = √(fill factor), w_m the band's Planck-weighted shares
//! R(λ)B_λ(T_ref) at the wavelength nodes of `optics::band_nodes` (the PSF of band light is the
//! shares' mix of each wavelength's unit-energy PSF, so its OTF is the same mix of OTFs).
//! MTF_diff(x) = (2/π)(arccos x − x√(1 − x²)) for x < 1, 0 beyond (the cut-off 1/(λF#)).
//!
//! **Edges.** The image is extended by mirroring (half-sample symmetric) by a margin of
//! [`margin_px`] pixels — 32 diffraction lengths λ_max F#/p plus 4σ and the aperture, where under
//! 1 % of the Airy pattern's energy lies farther out — and by more mirroring up to a size the FFT
//! handles fast; beyond the margin the filter is periodic. A uniform image stays uniform to
//! rounding (OTF(0) = 1) and its mean is kept exactly.
//!
//! **Sampling.** The renderer's pixels are point samples; the filter treats them as samples of a
//! band-limited image (the OTF is applied up to the pixel Nyquist frequency). Detail finer than a
//! pixel that the renderer aliased stays aliased; supersample the render (a larger resolution)
//! where that matters.
//!
//! Written with `rustfft` for the transforms; the OTF is this module's own, from the formulas above.

use crate::optics::WavelengthNodes;
use crate::scene::{Optics, Sensor};
use num_complex::Complex;
use rayon::prelude::*;
use rustfft::{Fft, FftPlanner};
use std::f64::consts::PI;
use std::sync::Arc;

/// The optics' OTF over the sensor band (see the module documentation).
pub struct TransferFunction {
    optics: Optics,
    /// (λ_m F#/p, w_m): each node's diffraction scale in pixels and its share; empty without
    /// diffraction.
    diffraction: Vec<(f64, f64)>,
}

impl TransferFunction {
    /// The OTF of `sensor`'s optics, the band weighted by the Planck spectrum at the sensor's
    /// NETD reference temperature.
    pub fn new(sensor: &Sensor, optics: Optics) -> TransferFunction {
        let diffraction = optics.diffraction.map_or_else(Vec::new, |d| {
            let (lo, hi) = sensor.band.limits_um();
            let nodes = WavelengthNodes::for_table(&sensor.band, &[lo, hi])
                .expect("a table spanning the band covers it");
            let shares = nodes.planck_fractions(sensor.netd_reference_k);
            nodes
                .wavelengths_um()
                .iter()
                .zip(shares)
                .map(|(&lambda_um, w)| (lambda_um * d.f_number / d.pixel_pitch_um, w))
                .collect()
        });
        TransferFunction {
            optics,
            diffraction,
        }
    }

    /// The band-averaged diffraction MTF at radial frequency `f` (cycles per pixel).
    pub fn diffraction_mtf(&self, f: f64) -> f64 {
        if self.diffraction.is_empty() {
            return 1.0;
        }
        self.diffraction
            .iter()
            .map(|&(scale, w)| w * circular_aperture_mtf(f * scale))
            .sum()
    }

    /// OTF(f_x, f_y), frequencies in cycles per pixel (real: the PSF is real and symmetric).
    pub fn at(&self, fx: f64, fy: f64) -> f64 {
        let radial_sq = fx * fx + fy * fy;
        let a = self.optics.aperture_px;
        let sigma = self.optics.blur_sigma_px;
        self.diffraction_mtf(radial_sq.sqrt())
            * sinc(a * fx)
            * sinc(a * fy)
            * (-2.0 * PI * PI * sigma * sigma * radial_sq).exp()
    }

    /// How far (pixels) the image is mirrored before filtering.
    pub fn margin_px(&self) -> usize {
        let longest = self.diffraction.iter().map(|d| d.0).fold(0.0, f64::max);
        let reach = 32.0 * longest + 4.0 * self.optics.blur_sigma_px + self.optics.aperture_px;
        (reach.ceil() as usize + 2).min(1024)
    }
}

/// MTF of a diffraction-limited circular aperture at x = f/f_cutoff.
fn circular_aperture_mtf(x: f64) -> f64 {
    if x >= 1.0 {
        0.0
    } else {
        2.0 / PI * (x.acos() - x * (1.0 - x * x).sqrt())
    }
}

/// sin(πu)/(πu), 1 at u = 0.
fn sinc(u: f64) -> f64 {
    if u.abs() < 1e-8 {
        1.0 - (PI * u).powi(2) / 6.0
    } else {
        (PI * u).sin() / (PI * u)
    }
}

/// Index into [0, n) of position `i` of the half-sample symmetric extension (…2 1 0 | 0 1 2 … n−1 |
/// n−1 n−2 …), periodic with 2n.
fn mirrored(i: isize, n: usize) -> usize {
    let period = 2 * n as isize;
    let j = i.rem_euclid(period);
    if j < n as isize {
        j as usize
    } else {
        (period - 1 - j) as usize
    }
}

/// The smallest size ≥ n whose only prime factors are 2, 3 and 5 (fast for the FFT).
fn fast_size(n: usize) -> usize {
    (n.max(1)..)
        .find(|&m| {
            let mut m = m;
            for p in [2, 3, 5] {
                while m % p == 0 {
                    m /= p;
                }
            }
            m == 1
        })
        .expect("5-smooth numbers are unbounded")
}

/// Filters the Stokes images (row-major, `width` × `height`) by `otf`, in place.
pub fn filter_stokes(otf: &TransferFunction, width: usize, height: usize, stokes: &mut [[f64; 4]]) {
    let margin = otf.margin_px();
    let (pw, ph) = (
        fast_size(width + 2 * margin),
        fast_size(height + 2 * margin),
    );
    let transforms = Transforms::new(pw, ph);
    let gains = otf_grid(otf, pw, ph);
    // Two real images per complex one: with a real PSF, Re and Im are filtered independently.
    for pair in [(0, 1), (2, 3)] {
        let mut grid: Vec<Complex<f64>> = (0..pw * ph)
            .map(|i| {
                let x = mirrored((i % pw) as isize - margin as isize, width);
                let y = mirrored((i / pw) as isize - margin as isize, height);
                let s = stokes[y * width + x];
                Complex::new(s[pair.0], s[pair.1])
            })
            .collect();
        transforms.filter(&mut grid, &gains);
        stokes
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, s) in row.iter_mut().enumerate() {
                    let z = grid[(y + margin) * pw + x + margin];
                    s[pair.0] = z.re;
                    s[pair.1] = z.im;
                }
            });
    }
}

/// The OTF at the DFT frequencies of a `pw` × `ph` grid, in the transposed (column-major) layout
/// the 2-D transform leaves its spectrum in. The OTF is even in f_x and f_y, so it is evaluated on
/// one quadrant of frequencies (|k| ≤ n/2) and read from there.
fn otf_grid(otf: &TransferFunction, pw: usize, ph: usize) -> Vec<f64> {
    let (qw, qh) = (pw / 2 + 1, ph / 2 + 1);
    let quadrant: Vec<f64> = (0..qw * qh)
        .into_par_iter()
        .map(|i| otf.at((i / qh) as f64 / pw as f64, (i % qh) as f64 / ph as f64))
        .collect();
    // DFT index k stands for the frequency k/n or (k − n)/n, whose magnitude is min(k, n − k)/n.
    let folded = |k: usize, n: usize| k.min(n - k);
    (0..pw * ph)
        .into_par_iter()
        .map(|i| quadrant[folded(i / ph, pw) * qh + folded(i % ph, ph)])
        .collect()
}

/// Forward and inverse 1-D transforms of a `pw` × `ph` grid's rows and columns.
struct Transforms {
    pw: usize,
    ph: usize,
    rows: (Arc<dyn Fft<f64>>, Arc<dyn Fft<f64>>),
    columns: (Arc<dyn Fft<f64>>, Arc<dyn Fft<f64>>),
}

impl Transforms {
    fn new(pw: usize, ph: usize) -> Transforms {
        let mut planner = FftPlanner::new();
        Transforms {
            pw,
            ph,
            rows: (planner.plan_fft_forward(pw), planner.plan_fft_inverse(pw)),
            columns: (planner.plan_fft_forward(ph), planner.plan_fft_inverse(ph)),
        }
    }

    /// Multiplies the grid's 2-D spectrum by `gains` (transposed layout) and transforms back.
    fn filter(&self, grid: &mut Vec<Complex<f64>>, gains: &[f64]) {
        let (pw, ph) = (self.pw, self.ph);
        along_rows(grid, pw, &self.rows.0);
        let mut transposed = transpose(grid, pw, ph);
        along_rows(&mut transposed, ph, &self.columns.0);
        let scale = 1.0 / (pw * ph) as f64;
        transposed
            .par_iter_mut()
            .zip(gains)
            .for_each(|(z, &g)| *z *= g * scale);
        along_rows(&mut transposed, ph, &self.columns.1);
        *grid = transpose(&transposed, ph, pw);
        along_rows(grid, pw, &self.rows.1);
    }
}

/// The 1-D transform `fft` of every row (length `n`) of `grid`.
fn along_rows(grid: &mut [Complex<f64>], n: usize, fft: &Arc<dyn Fft<f64>>) {
    grid.par_chunks_mut(n).for_each_init(
        || vec![Complex::new(0.0, 0.0); fft.get_inplace_scratch_len()],
        |scratch, row| fft.process_with_scratch(row, scratch),
    );
}

/// The transpose of a row-major `w` × `h` grid (becomes `h` × `w`).
fn transpose(grid: &[Complex<f64>], w: usize, h: usize) -> Vec<Complex<f64>> {
    let mut out = vec![Complex::new(0.0, 0.0); w * h];
    out.par_chunks_mut(h).enumerate().for_each(|(x, column)| {
        for (y, z) in column.iter_mut().enumerate() {
            *z = grid[y * w + x];
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::instrument::ideal_sensor as sensor;
    use crate::scene::Diffraction;

    fn optics(f_number: f64, pitch: f64, fill: f64, sigma: f64) -> Optics {
        Optics {
            diffraction: Some(Diffraction {
                f_number,
                pixel_pitch_um: pitch,
            }),
            aperture_px: fill.sqrt(),
            blur_sigma_px: sigma,
        }
    }

    #[test]
    fn the_psf_integrates_to_one() {
        // ∫PSF = OTF(0): the band's Planck shares sum to one, each factor is 1 at f = 0.
        for (f, p, fill, sigma) in [
            (1.0, 17.0, 1.0, 0.0),
            (2.5, 12.0, 0.5, 0.7),
            (8.0, 5.0, 0.0, 3.0),
        ] {
            let otf = TransferFunction::new(&sensor(), optics(f, p, fill, sigma));
            assert!((otf.at(0.0, 0.0) - 1.0).abs() < 1e-12);
        }
    }

    /// J1(x) = (1/π)∫₀^π cos(τ − x sin τ) dτ (Bessel's integral; the midpoint rule converges
    /// exponentially for a periodic integrand).
    fn bessel_j1(x: f64) -> f64 {
        let n = 400;
        (0..n)
            .map(|i| {
                let tau = PI * (i as f64 + 0.5) / n as f64;
                (tau - x * tau.sin()).cos()
            })
            .sum::<f64>()
            / n as f64
    }

    #[test]
    fn the_diffraction_kernel_is_the_sampled_band_averaged_airy_pattern() {
        // At f/8 and a 17 µm pitch the cut-off 1/(λF#) is below the pixel Nyquist frequency, so the
        // filter's kernel is the continuous PSF sampled at the pixels:
        // PSF(r) = Σ w_λ π/(4s²) [2J1(πr/s)/(πr/s)]², s = λF#/p in pixels, w_λ ∝ B_λ(300 K).
        let (w, h) = (96, 96);
        let mut image = vec![[0.0; 4]; w * h];
        image[48 * w + 48] = [1.0, 0.0, 0.0, 0.0];
        let otf = TransferFunction::new(&sensor(), optics(8.0, 17.0, 0.0, 0.0));
        filter_stokes(&otf, w, h, &mut image);
        let planck = |l: f64| 1.0 / (l.powi(5) * ((1.438_776_877e-2 / (l * 300.0)).exp() - 1.0));
        let nodes = 600;
        let airy = |r: f64| {
            let (mut sum, mut total) = (0.0, 0.0);
            for i in 0..nodes {
                let lambda_um = 8.0 + 6.0 * (i as f64 + 0.5) / nodes as f64;
                let weight = planck(lambda_um * 1e-6);
                let s = lambda_um * 8.0 / 17.0;
                let v = PI * r / s;
                let amplitude = if v < 1e-9 {
                    1.0
                } else {
                    2.0 * bessel_j1(v) / v
                };
                sum += weight * PI / (4.0 * s * s) * amplitude * amplitude;
                total += weight;
            }
            sum / total
        };
        let peak = airy(0.0);
        for (dx, dy) in [(0, 0), (1, 0), (2, 1), (3, 3), (5, 0), (7, 4), (10, 2)] {
            let got = image[(48 + dy) * w + 48 + dx][0];
            let want = airy(((dx * dx + dy * dy) as f64).sqrt());
            assert!(
                (got - want).abs() < 2e-3 * peak,
                "({dx}, {dy}): {got} vs {want}"
            );
        }
    }

    #[test]
    fn mirroring_and_fast_sizes() {
        assert_eq!(
            (0..7).map(|i| mirrored(i - 2, 3)).collect::<Vec<_>>(),
            [1, 0, 0, 1, 2, 2, 1]
        );
        assert_eq!(fast_size(97), 100);
        assert_eq!(fast_size(1), 1);
        assert_eq!(fast_size(1081), 1125);
    }
}
