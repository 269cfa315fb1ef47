//! The camera between the scene's radiance and the images (docs/design.md §1.11): optics blur the
//! polarizer images ([`otf`]), the detector adds temporal noise (`render::sensor`), its fixed
//! pattern and quantization ([`detector`]), and a division-of-focal-plane array records one
//! imperfect polarizer per pixel ([`polarizer_array`]) to be demosaicked (`render::dofp`).
//! [`metrics`] compares what the camera delivers with the noise-free truth.
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

use super::dofp::{demosaic, orientation};
use super::film::polarizer;
use super::sensor::Noise;
use crate::scene::Sensor;
use detector::DetectorModel;
use metrics::CameraMetrics;
use polarizer_array::{PolarizerArray, ORIENTATIONS};
use rayon::prelude::*;

/// What the DoFP camera delivers.
pub struct DofpImages {
    /// Each pixel's recorded value at its own polarizer, row-major.
    pub mosaic: Vec<f64>,
    /// Stokes (S0, S1, S2) per pixel, demosaicked and reconstructed.
    pub stokes: Vec<[f64; 3]>,
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
        otf::filter_stokes(
            &otf::TransferFunction::new(sensor, optics),
            width,
            height,
            stokes,
        );
    }
    let noise = Noise::of_sensor(sensor);
    let detector = sensor.detector.map(|d| DetectorModel::new(sensor, d));
    let dofp = sensor.dofp.map(|d| {
        let array = PolarizerArray::new(sensor, d, width, height);
        record_dofp(&array, &noise, detector.as_ref(), stokes)
    });
    let polarizers = if noise.is_noisy() || detector.is_some() {
        record_four_images(&noise, detector.as_ref(), width, stokes)
    } else {
        Vec::new()
    };
    let metrics = truth.map(|truth| CameraMetrics::of(&truth, stokes, dofp.as_ref()));
    Recording {
        polarizers,
        dofp,
        metrics,
    }
}

/// The four-image camera: each polarizer image of each pixel with its noise and pattern; the
/// Stokes vectors re-estimated from them, S0 = ½ΣI, S1 = I0 − I90, S2 = I45 − I135 (S3 is not
/// measured by linear polarizers and is left as it is).
fn record_four_images(
    noise: &Noise,
    detector: Option<&DetectorModel>,
    width: usize,
    stokes: &mut [[f64; 4]],
) -> Vec<[f32; 4]> {
    let mut recorded = vec![[0.0f32; 4]; stokes.len()];
    stokes
        .par_chunks_mut(width)
        .zip(recorded.par_chunks_mut(width))
        .enumerate()
        .for_each(|(y, (row, row_recorded))| {
            let normals = noise.row_normals(y, width);
            let pattern = detector.map(|d| d.pattern_row(y, width));
            for (x, s) in row.iter_mut().enumerate() {
                let mut i = [0, 1, 2, 3].map(|k| {
                    polarizer(*s, ORIENTATIONS[k]) + noise.sigma_polarizer * normals[x][k]
                });
                if let (Some(d), Some(p)) = (detector, &pattern) {
                    i = [0, 1, 2, 3].map(|k| d.read(i[k], &p[x], k));
                }
                row_recorded[x] = i.map(|v| v as f32);
                *s = [
                    0.5 * (i[0] + i[1] + i[2] + i[3]),
                    i[0] - i[2],
                    i[1] - i[3],
                    s[3],
                ];
            }
        });
    recorded
}

/// The DoFP camera: every pixel's signal through its own polarizer (crosstalk included), with
/// the noise draw of that polarizer image and the pixel's pattern; then demosaicked and
/// reconstructed.
fn record_dofp(
    array: &PolarizerArray,
    noise: &Noise,
    detector: Option<&DetectorModel>,
    stokes: &[[f64; 4]],
) -> DofpImages {
    let (width, height) = array.size();
    let signals = array.signals(stokes);
    let mut mosaic = vec![0.0f64; stokes.len()];
    mosaic
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, row)| {
            let normals = noise.row_normals(y, width);
            let pattern = detector.map(|d| d.pattern_row(y, width));
            for (x, value) in row.iter_mut().enumerate() {
                let k = orientation(x, y);
                let mut v = signals[y * width + x] + noise.sigma_polarizer * normals[x][k];
                if let (Some(d), Some(p)) = (detector, &pattern) {
                    v = d.read(v, &p[x], k);
                }
                *value = v;
            }
        });
    let polarizers = demosaic(width, height, &mosaic, array.dofp.demosaic);
    DofpImages {
        stokes: array.reconstruct(&polarizers),
        mosaic,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::Band;
    use crate::scene::{Demosaic, Dofp};

    fn sensor(dofp: Dofp) -> Sensor {
        Sensor {
            band: Band::lwir(),
            netd_mk: 0.0,
            seed: 9,
            netd_reference_k: 300.0,
            optics: None,
            detector: None,
            dofp: Some(dofp),
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
        let recorded = record_four_images(&noise, None, w, &mut row);
        let mut again = vec![[5.0, 0.2, -0.1, 0.0]; w];
        record_four_images(&noise, None, w, &mut again);
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
