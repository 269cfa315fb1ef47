//! `[sensor]` and its sub-tables (docs/design.md §1.11, §2.3): the band, the NETD, and the camera
//! between the scene and the Stokes images — optics, detector and the division-of-focal-plane
//! polarizer array — checked here, applied by `render::instrument`. Every default is the ideal camera
//! (point samples, perfect polarizers, no fixed pattern), which renders today's images bit for bit.

use super::config::{DetectorConfig, DofpConfig, OpticsConfig, SceneConfig};
use super::error::InvalidSetting;
use super::SceneError;
use crate::optics::{valid_temperature, Band, MAX_TEMPERATURE_K};
use crate::text::number;
use std::path::Path;

#[derive(Clone, Debug)]
pub struct Sensor {
    pub band: Band,
    pub netd_mk: f64,
    pub seed: u64,
    pub netd_reference_k: f64,
    /// The lens and pixel aperture; `None` = point samples.
    pub optics: Option<Optics>,
    /// Fixed-pattern noise and quantization; `None` = an ideal detector.
    pub detector: Option<Detector>,
    /// Write the division-of-focal-plane mosaic and its demosaicked Stokes images too.
    pub dofp: Option<Dofp>,
}

/// `[sensor.optics]`, checked: MTF = MTF_diffraction · |sinc(a f_x) sinc(a f_y)| · exp(−2π²σ²f²)
/// with f in cycles per pixel and a = √fill_factor (docs/design.md §1.11).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Optics {
    /// f-number and pixel pitch (µm) of the diffraction-limited lens; `None` = no diffraction.
    pub diffraction: Option<Diffraction>,
    /// Side of the pixel's square aperture in pixels, √(fill factor); 0 = point samples.
    pub aperture_px: f64,
    pub blur_sigma_px: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffraction {
    pub f_number: f64,
    pub pixel_pitch_um: f64,
}

/// `[sensor.detector]`, checked. Offsets are radiances of a polarizer image, σ_o = ½ · offset ·
/// dL_bb/dT at the NETD reference (the NETD's own conversion, `render::detector_noise`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detector {
    pub fpn_gain_sigma: f64,
    pub fpn_offset_mk: f64,
    /// 0 = no quantization.
    pub bits: u32,
    pub range_k: (f64, f64),
}

/// `[sensor.dofp]`, checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dofp {
    /// D = (ER − 1)/(ER + 1) of every pixel's polarizer; 1 for a perfect one.
    pub diattenuation: f64,
    pub orientation_sigma_deg: f64,
    pub crosstalk: f64,
    pub demosaic: Demosaic,
    pub calibrated: bool,
}

/// How the three missing polarizer images of each pixel are interpolated (`render::dofp`, the
/// scene key `[sensor.dofp] demosaic`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Demosaic {
    /// Each orientation's lattice bilinearly interpolated (the baseline; the default).
    #[default]
    Bilinear,
    /// Newton's polynomial interpolation in the polarization-difference domain with an edge
    /// classifier (Li, Zhao, Pan & Kong 2019).
    Newton,
    /// Guided-filter residual interpolation (after Ahmed et al. 2017).
    Residual,
}

impl Demosaic {
    pub const ALL: [Demosaic; 3] = [Demosaic::Bilinear, Demosaic::Newton, Demosaic::Residual];

    /// The scene key's value.
    pub fn name(self) -> &'static str {
        match self {
            Demosaic::Bilinear => "bilinear",
            Demosaic::Newton => "newton",
            Demosaic::Residual => "residual",
        }
    }

    pub fn from_name(name: &str) -> Option<Demosaic> {
        Demosaic::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// `[sensor]`: the band, NETD and its reference temperature (default the air's), and the camera.
pub(super) fn resolve_sensor(path: &Path, config: &SceneConfig) -> Result<Sensor, SceneError> {
    let fail = |message: String| SceneError::new(path, message);
    let s = &config.sensor;
    let band = Band::new(
        s.band_um[0],
        s.band_um[1],
        s.response
            .as_ref()
            .map(|r| r.iter().map(|&[w, v]| (w, v)).collect()),
    )
    .map_err(|e| fail(format!("sensor: {e}")))?;
    let netd_reference_k = s
        .netd_reference_k
        .unwrap_or(config.environment.air_temperature_k);
    if !(s.netd_mk.is_finite() && s.netd_mk >= 0.0) {
        return Err(fail(format!(
            "sensor.netd_mk = {} must be ≥ 0",
            number(s.netd_mk)
        )));
    }
    // An explicit reference is checked here; the default (the air) by the environment.
    if s.netd_reference_k.is_some()
        && !(valid_temperature(netd_reference_k) && netd_reference_k > 0.0)
    {
        return Err(fail(format!(
            "sensor.netd_reference_k = {} must be within (0, {MAX_TEMPERATURE_K}] K",
            number(netd_reference_k)
        )));
    }
    Ok(Sensor {
        band,
        netd_mk: s.netd_mk,
        seed: s.seed,
        netd_reference_k,
        optics: s
            .optics
            .as_ref()
            .map(resolve_optics)
            .transpose()
            .map_err(|e: InvalidSetting| fail(e.0))?,
        detector: s
            .detector
            .as_ref()
            .map(resolve_detector)
            .transpose()
            .map_err(|e: InvalidSetting| fail(e.0))?,
        dofp: s
            .dofp
            .as_ref()
            .map(resolve_dofp)
            .transpose()
            .map_err(|e: InvalidSetting| fail(e.0))?,
    })
}

/// A value that must be finite and within [lo, hi]; the message names the key.
fn within(key: &str, value: f64, lo: f64, hi: f64) -> Result<f64, InvalidSetting> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(format!(
            "{key} = {} must be within [{}, {}]",
            number(value),
            number(lo),
            number(hi)
        )
        .into())
    }
}

fn resolve_optics(o: &OpticsConfig) -> Result<Optics, InvalidSetting> {
    let diffraction = match (o.f_number, o.pixel_pitch_um) {
        (None, None) => None,
        (Some(f_number), Some(pitch)) => Some(Diffraction {
            f_number: within("sensor.optics.f_number", f_number, 0.1, 1000.0)?,
            pixel_pitch_um: within("sensor.optics.pixel_pitch_um", pitch, 0.1, 1000.0)?,
        }),
        (Some(_), None) => {
            return Err(
                "sensor.optics.f_number needs pixel_pitch_um (µm), the scale of the \
                        diffraction pattern in pixels"
                    .into(),
            )
        }
        (None, Some(_)) => {
            return Err(
                "sensor.optics.pixel_pitch_um is only used with f_number; add \
                        f_number or remove it"
                    .into(),
            )
        }
    };
    let fill = within("sensor.optics.fill_factor", o.fill_factor, 0.0, 1.0)?;
    Ok(Optics {
        diffraction,
        aperture_px: fill.sqrt(),
        blur_sigma_px: within("sensor.optics.blur_sigma_px", o.blur_sigma_px, 0.0, 100.0)?,
    })
}

fn resolve_detector(d: &DetectorConfig) -> Result<Detector, InvalidSetting> {
    let [lo, hi] = d.range_k;
    if !(valid_temperature(lo) && valid_temperature(hi) && lo < hi) {
        return Err(format!(
            "sensor.detector.range_k = [{}, {}] must be two temperatures within [0, \
             {MAX_TEMPERATURE_K}] K, the first below the second",
            number(lo),
            number(hi)
        )
        .into());
    }
    if d.bits > 32 {
        return Err(format!(
            "sensor.detector.bits = {} must be within [0, 32] (0 = no quantization)",
            d.bits
        )
        .into());
    }
    Ok(Detector {
        fpn_gain_sigma: within("sensor.detector.fpn_gain_sigma", d.fpn_gain_sigma, 0.0, 1.0)?,
        fpn_offset_mk: within("sensor.detector.fpn_offset_mk", d.fpn_offset_mk, 0.0, 1e6)?,
        bits: d.bits,
        range_k: (lo, hi),
    })
}

fn resolve_dofp(d: &DofpConfig) -> Result<Dofp, InvalidSetting> {
    let diattenuation = match d.extinction_ratio {
        None => 1.0,
        Some(er) if er == f64::INFINITY => 1.0,
        Some(er) if er.is_finite() && er >= 1.0 => (er - 1.0) / (er + 1.0),
        Some(er) => {
            return Err(format!(
                "sensor.dofp.extinction_ratio = {} must be ≥ 1 (a polarizer passes its own \
                 orientation best; inf = perfect)",
                number(er)
            )
            .into())
        }
    };
    let demosaic = Demosaic::from_name(&d.demosaic).ok_or_else(|| {
        InvalidSetting(format!(
            "sensor.dofp.demosaic = \"{}\" is not a method irpol knows; use \"bilinear\", \
             \"newton\" or \"residual\"",
            crate::text::shown(&d.demosaic)
        ))
    })?;
    Ok(Dofp {
        diattenuation,
        orientation_sigma_deg: within(
            "sensor.dofp.orientation_sigma_deg",
            d.orientation_sigma_deg,
            0.0,
            45.0,
        )?,
        // Four neighbours each take this fraction: at most all of the pixel's signal.
        crosstalk: within("sensor.dofp.crosstalk", d.crosstalk, 0.0, 0.25)?,
        demosaic,
        calibrated: d.calibrated,
    })
}
