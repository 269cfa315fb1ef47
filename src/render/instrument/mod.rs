//! The camera between the scene's radiance and the images (docs/design.md §1.11): optics blur the
//! polarizer images ([`otf`]), the detector adds temporal noise (`render::detector_noise`), its fixed
//! pattern and quantization ([`detector`]), and a division-of-focal-plane array records one
//! imperfect polarizer per pixel ([`polarizer_array`]) to be demosaicked (`render::dofp`).
//! [`metrics`] compares what the camera delivers with the noise-free truth; [`slanted_edge`]
//! measures an image's MTF.
//!
//! Two cameras are simulated from the same optics and detector: the four-image polarimeter whose
//! Stokes images are the render's S0–S3 (each pixel sees all four polarizer images, each with its
//! own noise and pattern), and, with `[sensor.dofp]`, the DoFP camera whose mosaic and demosaicked
//! images are written beside them. Both draw the same noise, so they differ only by the array.
//! With every setting at its default the four-image camera is today's: the Stokes images are
//! untouched without noise, and noisy exactly as before with it.

pub mod detector;
pub mod metrics;
pub mod otf;
pub mod polarizer_array;
pub mod slanted_edge;

use super::detector_noise::Noise;
use super::dofp::{demosaic, orientation};
use super::film::polarizer;
use crate::scene::Sensor;
use detector::{DetectorModel, PixelPattern};
use metrics::CameraMetrics;
use polarizer_array::{PolarizerArray, ORIENTATIONS};
use rayon::prelude::*;

/// What the DoFP camera delivers.
pub struct DofpImages {
    /// Each pixel's recorded value at its own polarizer, row-major.
    pub mosaic: Vec<f64>,
    /// Stokes (S0, S1, S2) per pixel, demosaicked and reconstructed.
    pub stokes: Vec<[f64; 3]>,
    /// (S0, S1, S2) of the noise-free radiance before the optics, what `stokes` estimates.
    pub truth: Vec<[f64; 3]>,
}

/// The camera's records of one render.
#[derive(Default)]
pub struct Recording {
    /// The four polarizer images per pixel as recorded (noise, pattern, quantization); empty when
    /// the camera records them exactly (no noise and an ideal detector).
    pub polarizers: Vec<[f32; 4]>,
    pub dofp: Option<DofpImages>,
    /// Reconstruction quality against the noise-free truth; `None` for the ideal camera.
    pub metrics: Option<CameraMetrics>,
}

/// Whether `sensor` is the ideal camera of point samples and perfect polarizers.
fn is_ideal(sensor: &Sensor) -> bool {
    sensor.netd_mk == 0.0 && sensor.optics.is_none() && sensor.detector.is_none()
}

/// Records the rendered radiance `stokes` (row-major, `width` × `height`) through `sensor`'s
/// camera, leaving in `stokes` what the four-image camera reconstructs.
pub fn record(sensor: &Sensor, width: usize, height: usize, stokes: &mut [[f64; 4]]) -> Recording {
    let measured = !is_ideal(sensor) || sensor.dofp.is_some();
    let truth = measured.then(|| stokes.to_vec());
    if let Some(optics) = sensor.optics {
        let otf = otf::TransferFunction::new(sensor, optics);
        otf::filter_stokes(&otf, width, height, stokes);
    }
    let detector = Detection {
        noise: Noise::of_sensor(sensor),
        pattern: sensor.detector.map(|d| DetectorModel::new(sensor, d)),
    };
    let array = sensor
        .dofp
        .map(|d| PolarizerArray::new(sensor, d, width, height));
    // Every pixel's signal through its own polarizer, from the radiance before any noise.
    let signals = array.as_ref().map(|a| a.signals(stokes));
    let four_images = detector.noise.is_noisy() || detector.pattern.is_some();
    let (polarizers, mosaic) =
        record_rows(&detector, signals.as_deref(), four_images, width, stokes);
    let dofp = array.map(|array| {
        let polarizers = demosaic(width, height, &mosaic, array.dofp.demosaic);
        DofpImages {
            stokes: array.reconstruct(&polarizers),
            mosaic,
            truth: Vec::new(),
        }
    });
    let metrics = truth
        .as_ref()
        .map(|truth| CameraMetrics::of(truth, stokes, dofp.as_ref()));
    let dofp = dofp.map(|d| DofpImages {
        truth: truth.iter().flatten().map(|s| [s[0], s[1], s[2]]).collect(),
        ..d
    });
    Recording {
        polarizers,
        dofp,
        metrics,
    }
}

/// The detector: temporal noise and, optionally, its fixed pattern and quantizer.
struct Detection {
    noise: Noise,
    pattern: Option<DetectorModel>,
}

impl Detection {
    /// What polarizer image `k` of pixel `x` in a row reads for `signal`, given the row's noise
    /// draws and pattern.
    #[inline]
    fn read(
        &self,
        signal: f64,
        normals: &[f64; 4],
        pattern: Option<&PixelPattern>,
        k: usize,
    ) -> f64 {
        let value = signal + self.noise.sigma_polarizer * normals[k];
        match (&self.pattern, pattern) {
            (Some(d), Some(p)) => d.read(value, p, k),
            _ => value,
        }
    }
}

/// Both cameras, row by row with one set of noise draws and one pattern per row:
/// - the four-image camera (when `four_images`): each polarizer image of each pixel with its noise
///   and pattern, returned per pixel; the Stokes vectors in `stokes` re-estimated from them,
///   S0 = ½ΣI, S1 = I0 − I90, S2 = I45 − I135 (S3 is not measured by linear polarizers and is
///   left as it is);
/// - the DoFP camera (with `signals`): each pixel's signal through its own polarizer with the
///   noise draw and pattern of that polarizer image, returned as the mosaic.
fn record_rows(
    detector: &Detection,
    signals: Option<&[f64]>,
    four_images: bool,
    width: usize,
    stokes: &mut [[f64; 4]],
) -> (Vec<[f32; 4]>, Vec<f64>) {
    let rows: Vec<(Vec<[f32; 4]>, Vec<f64>)> = stokes
        .par_chunks_mut(width)
        .enumerate()
        .map(|(y, row)| {
            let normals = detector.noise.row_normals(y, width);
            let pattern = detector.pattern.as_ref().map(|d| d.pattern_row(y, width));
            let pixel_pattern = |x: usize| pattern.as_ref().map(|p| &p[x]);
            let raw: Vec<f64> = match signals {
                None => Vec::new(),
                Some(signals) => (0..width)
                    .map(|x| {
                        let (signal, k) = (signals[y * width + x], orientation(x, y));
                        detector.read(signal, &normals[x], pixel_pattern(x), k)
                    })
                    .collect(),
            };
            if !four_images {
                return (Vec::new(), raw);
            }
            let recorded = row
                .iter_mut()
                .enumerate()
                .map(|(x, s)| {
                    let i = [0, 1, 2, 3].map(|k| {
                        let ideal = polarizer(*s, ORIENTATIONS[k]);
                        detector.read(ideal, &normals[x], pixel_pattern(x), k)
                    });
                    *s = [
                        0.5 * (i[0] + i[1] + i[2] + i[3]),
                        i[0] - i[2],
                        i[1] - i[3],
                        s[3],
                    ];
                    i.map(|v| v as f32)
                })
                .collect();
            (recorded, raw)
        })
        .collect();
    let (recorded, mosaic): (Vec<_>, Vec<_>) = rows.into_iter().unzip();
    (recorded.concat(), mosaic.concat())
}

/// An LWIR sensor with the ideal camera and no noise, referred to 300 K, for the camera's tests.
#[cfg(test)]
pub(crate) fn ideal_sensor() -> Sensor {
    Sensor {
        band: crate::optics::Band::lwir(),
        netd_mk: 0.0,
        seed: 9,
        netd_reference_k: 300.0,
        optics: None,
        detector: None,
        dofp: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Demosaic, Dofp};

    fn sensor(dofp: Dofp) -> Sensor {
        Sensor {
            dofp: Some(dofp),
            ..ideal_sensor()
        }
    }

    fn array(extinction_ratio: f64, sigma_deg: f64, crosstalk: f64, calibrated: bool) -> Dofp {
        Dofp {
            diattenuation: (extinction_ratio - 1.0) / (extinction_ratio + 1.0),
            orientation_sigma_deg: sigma_deg,
            crosstalk,
            demosaic: Demosaic::Bilinear,
            calibrated,
        }
    }

    fn dofp_of(sensor: &Sensor, w: usize, h: usize, stokes: &[[f64; 4]]) -> Vec<[f64; 3]> {
        let mut copy = stokes.to_vec();
        record(sensor, w, h, &mut copy).dofp.unwrap().stokes
    }

    #[test]
    fn a_perfect_array_demosaicks_a_linear_field_exactly() {
        let (w, h) = (12, 10);
        let truth: Vec<[f64; 4]> = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f64, (p / w) as f64);
                [
                    10.0 + 0.3 * x + 0.1 * y,
                    0.5 - 0.02 * x + 0.03 * y,
                    -0.2 + 0.01 * x,
                    0.0,
                ]
            })
            .collect();
        let perfect = Dofp {
            diattenuation: 1.0,
            ..array(10.0, 0.0, 0.0, true)
        };
        let got = dofp_of(&sensor(perfect), w, h, &truth);
        // Exact between lattice samples (to rounding), not beyond the last one.
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let (s, t) = (got[y * w + x], truth[y * w + x]);
                for j in 0..3 {
                    assert!((s[j] - t[j]).abs() < 1e-9, "({x},{y}) S{j}");
                }
            }
        }
    }

    #[test]
    fn extinction_ratio_reads_as_diattenuation_unless_calibrated() {
        // A uniform, fully p-polarized field (S1 = S0): uncalibrated the camera reads DoLP = D.
        let (w, h) = (8, 6);
        let field = vec![[2.0, 2.0, 0.0, 0.0]; w * h];
        let d = 9.0 / 11.0;
        for s in dofp_of(&sensor(array(10.0, 0.0, 0.0, false)), w, h, &field) {
            let dolp = s[1].hypot(s[2]) / s[0];
            assert!((dolp - d).abs() < 1e-9, "{dolp}");
        }
        for s in dofp_of(&sensor(array(10.0, 0.0, 0.0, true)), w, h, &field) {
            let dolp = s[1].hypot(s[2]) / s[0];
            assert!((dolp - 1.0).abs() < 1e-9, "{dolp}");
        }
    }

    #[test]
    fn calibration_undoes_orientation_errors_and_crosstalk_on_a_uniform_field() {
        let (w, h) = (10, 8);
        let field = vec![[3.0, 0.8, -1.1, 0.0]; w * h];
        let flawed = array(20.0, 3.0, 0.05, false);
        let uncalibrated = dofp_of(&sensor(flawed), w, h, &field);
        let calibrated = dofp_of(
            &sensor(Dofp {
                calibrated: true,
                ..flawed
            }),
            w,
            h,
            &field,
        );
        let truth = field[0];
        let worst = |v: &[[f64; 3]]| {
            v.iter()
                .flat_map(|s| (0..3).map(move |j| (s[j] - truth[j]).abs()))
                .fold(0.0, f64::max)
        };
        assert!(
            worst(&uncalibrated) > 0.05,
            "the flaws show: {}",
            worst(&uncalibrated)
        );
        assert!(worst(&calibrated) < 1e-9, "{}", worst(&calibrated));
    }

    #[test]
    fn crosstalk_keeps_an_unpolarized_field_uniform() {
        let (w, h) = (7, 5);
        let field = vec![[4.0, 0.0, 0.0, 0.0]; w * h];
        let mut copy = field.clone();
        let recording = record(&sensor(array(1e9, 0.0, 0.2, false)), w, h, &mut copy);
        for v in recording.dofp.unwrap().mosaic {
            assert!((v - 2.0).abs() < 1e-12);
        }
    }

    #[test]
    fn noise_has_the_stated_spread_and_is_reproducible() {
        let noise = Noise {
            sigma_polarizer: 0.01,
            seed: 7,
        };
        let (w, n) = (20_000, 20_000.0);
        let mut row = vec![[5.0, 0.2, -0.1, 0.0]; w];
        let detector = Detection {
            noise,
            pattern: None,
        };
        let (recorded, _) = record_rows(&detector, None, true, w, &mut row);
        let mut again = vec![[5.0, 0.2, -0.1, 0.0]; w];
        record_rows(&detector, None, true, w, &mut again);
        assert_eq!(row, again);
        // The Stokes vectors are the re-estimate from the recorded polarizer images.
        for (s, i) in row.iter().zip(&recorded).take(100) {
            let i = i.map(f64::from);
            assert!((s[0] - 0.5 * (i[0] + i[1] + i[2] + i[3])).abs() < 1e-5);
            assert!((s[1] - (i[0] - i[2])).abs() < 1e-5 && (s[2] - (i[1] - i[3])).abs() < 1e-5);
        }
        let spread = |v: &[f64], mean: f64| {
            (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
        };
        // Each recorded image has its own noise: I0's spread is σ_I, not that of ½(S0 + S1).
        let i0: Vec<f64> = recorded.iter().map(|i| i[0] as f64).collect();
        assert!((spread(&i0, i0.iter().sum::<f64>() / n) / 0.01 - 1.0).abs() < 0.03);
        // S0 = ½ Σ of four: σ(S0) = σ_I; S1 = I0 − I90: σ(S1) = √2 σ_I.
        let s0: Vec<f64> = row.iter().map(|s| s[0]).collect();
        let s1: Vec<f64> = row.iter().map(|s| s[1]).collect();
        assert!((s0.iter().sum::<f64>() / n - 5.0).abs() < 3e-4);
        assert!((spread(&s0, 5.0) / 0.01 - 1.0).abs() < 0.03);
        assert!((spread(&s1, 0.2) / (0.01 * 2f64.sqrt()) - 1.0).abs() < 0.03);
    }
}
