//! The numbers behind a fit report, computed once and drawn twice (PNG and SVG): every measured
//! point placed on the goniometer's plane of incidence or on an out-of-plane ring, its standard
//! deviation and normalized residual, and the chosen and competing models evaluated along each
//! plane and ring and as polarized emissivity (DESIGN §1.3–1.4).

use crate::material::Material;
use crate::measure::MeasurementSet;
use crate::optics::{Mueller, Stokes};
use crate::pbrdf::{Direction, HemisphereQuadrature, Pbrdf};

use super::super::ReportError;

/// The fit's default noise model where a file has no `u_` column: 3 % of m00 on m00 and 1 % of m00
/// on every other element (a rotating-retarder polarimeter), floored at 1e-6 of the largest m00 so
/// that a zero reading keeps a finite weight. Mirrors `fit::data` so that report residuals are the
/// ones the optimizer minimized.
pub const DEFAULT_M00_RELATIVE_ERROR: f64 = 0.03;
pub const DEFAULT_OTHER_ERROR_PER_M00: f64 = 0.01;
const DEFAULT_ERROR_FLOOR: f64 = 1e-6;

/// Two angles are the same goniometer setting when they agree to a microdegree.
const SAME_ANGLE_DEG: f64 = 1e-6;

/// A model drawn in the report: the chosen fit or the competing distribution's best fit.
pub struct ModelCurveSource {
    pub label: String,
    pub pbrdf: Pbrdf,
}

/// One measured element: value and 1-σ (sr⁻¹).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    pub value: f64,
    pub sigma: f64,
}

/// A measured geometry as the report sees it.
#[derive(Clone, Debug)]
pub struct PointView {
    /// Index into [`ReportData::incidences`].
    pub incidence: usize,
    /// Detector zenith signed for the plane of incidence (DESIGN §1.1): + on the specular side
    /// (φ_r = φ_i + 180°), − toward the source (φ_r = φ_i); `None` off the plane.
    pub signed_zenith: Option<f64>,
    /// Index into [`ReportData::rings`] when the point lies on an out-of-plane ring.
    pub ring: Option<usize>,
    /// φ_r − φ_i in [0°, 360°).
    pub relative_azimuth: f64,
    /// θ_r signed by hemisphere: + when the detector is on the forward (specular) half,
    /// cos(φ_r − φ_i) < 0. Equals `signed_zenith` in the plane.
    pub forward_zenith: f64,
    /// The measured elements by Mueller index r*4 + c.
    pub readings: [Option<Reading>; 16],
    /// The chosen model at this geometry.
    pub model: Mueller,
}

/// A model evaluated along a one-parameter sweep of geometry (detector zenith or azimuth).
#[derive(Clone, Debug)]
pub struct ModelSweep {
    pub x: Vec<f64>,
    pub chosen: Vec<Mueller>,
    pub alternative: Option<Vec<Mueller>>,
}

/// Points of one incidence angle and one detector zenith off the plane of incidence.
#[derive(Clone, Debug)]
pub struct Ring {
    pub incidence: usize,
    pub theta_r_deg: f64,
    /// Position among the rings of the same incidence angle (for the marker shape).
    pub rank: usize,
    /// The models against φ_r − φ_i over 0…360°.
    pub sweep: ModelSweep,
}

/// One normalized residual (data − model)/σ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Residual {
    pub forward_zenith: f64,
    pub element: usize,
    pub value: f64,
}

/// ε0 and ε1 against emission angle for the chosen and the competing model.
#[derive(Clone, Debug)]
pub struct EmissivityCurves {
    pub theta_deg: Vec<f64>,
    pub chosen: Vec<Stokes>,
    pub alternative: Option<Vec<Stokes>>,
}

pub struct ReportData {
    /// Distinct incidence angles (°), ascending: the colour key of every panel.
    pub incidences: Vec<f64>,
    /// Mueller indices present in the measurement, ascending.
    pub elements: Vec<usize>,
    pub points: Vec<PointView>,
    /// In-plane model sweeps, one per incidence angle (`None` when no point of that angle lies in
    /// the plane).
    pub in_plane: Vec<Option<ModelSweep>>,
    pub rings: Vec<Ring>,
    pub residuals: Vec<Residual>,
    pub emissivity: EmissivityCurves,
    pub chosen_label: String,
    pub alternative_label: Option<String>,
}

impl ReportData {
    pub fn new(material: &Material, set: &MeasurementSet) -> Result<ReportData, ReportError> {
        let chosen = ModelCurveSource {
            label: material.model.distribution.name().to_owned(),
            pbrdf: material.pbrdf()?,
        };
        let alternative = match material.fit.as_ref().and_then(|f| f.alternative.as_ref()) {
            Some(alt) => Some(ModelCurveSource {
                label: alt.model.distribution.name().to_owned(),
                pbrdf: alt.model.pbrdf()?,
            }),
            None => None,
        };

        let incidences = distinct_sorted(set.points.iter().map(|p| p.theta_i_deg));
        let m00_max = set.points.iter().map(|p| p.values[0]).fold(0.0, f64::max);
        let floor = DEFAULT_ERROR_FLOOR * m00_max.max(f64::MIN_POSITIVE);

        let mut points = Vec::with_capacity(set.points.len());
        for p in &set.points {
            let incident = checked_direction("theta_i_deg", p.theta_i_deg, p.phi_i_deg)?;
            let scattered = checked_direction("theta_r_deg", p.theta_r_deg, p.phi_r_deg)?;
            let relative_azimuth = (p.phi_r_deg - p.phi_i_deg).rem_euclid(360.0);
            let signed_zenith = in_plane_zenith(p.theta_r_deg, relative_azimuth);
            let forward_zenith = signed_zenith.unwrap_or_else(|| {
                if relative_azimuth.to_radians().cos() < 0.0 {
                    p.theta_r_deg
                } else {
                    -p.theta_r_deg
                }
            });
            let mut readings = [None; 16];
            for (column, &element) in set.elements.iter().enumerate() {
                let value = p.values[column];
                let sigma = p.uncertainties[column].unwrap_or(if element == 0 {
                    (DEFAULT_M00_RELATIVE_ERROR * p.values[0]).max(floor)
                } else {
                    (DEFAULT_OTHER_ERROR_PER_M00 * p.values[0]).max(floor)
                });
                readings[element] = Some(Reading { value, sigma });
            }
            points.push(PointView {
                incidence: position_of(&incidences, p.theta_i_deg),
                signed_zenith,
                ring: None,
                relative_azimuth,
                forward_zenith,
                readings,
                model: chosen.pbrdf.mueller(&incident, &scattered),
            });
        }

        let rings = find_rings(&mut points, set, &incidences, &chosen, alternative.as_ref());
        let in_plane = incidences
            .iter()
            .enumerate()
            .map(|(group, &theta_i)| {
                points
                    .iter()
                    .any(|p| p.incidence == group && p.signed_zenith.is_some())
                    .then(|| in_plane_sweep(theta_i, &chosen, alternative.as_ref()))
            })
            .collect();
        let residuals = points
            .iter()
            .flat_map(|p| {
                p.readings.iter().enumerate().filter_map(|(element, r)| {
                    r.map(|r| Residual {
                        forward_zenith: p.forward_zenith,
                        element,
                        value: (r.value - p.model[(element / 4, element % 4)]) / r.sigma,
                    })
                })
            })
            .collect();
        let emissivity = emissivity_curves(&chosen, alternative.as_ref());

        Ok(ReportData {
            incidences,
            elements: set.elements.clone(),
            points,
            in_plane,
            rings,
            residuals,
            emissivity,
            chosen_label: chosen.label,
            alternative_label: alternative.map(|a| a.label),
        })
    }

    pub fn has_element(&self, element: usize) -> bool {
        self.elements.contains(&element)
    }

    /// Off-plane points that lie on no ring (a raster around specular): they appear only among
    /// the residuals.
    pub fn off_ring_points(&self) -> usize {
        self.points
            .iter()
            .filter(|p| p.signed_zenith.is_none() && p.ring.is_none())
            .count()
    }
}

fn checked_direction(name: &'static str, theta: f64, phi: f64) -> Result<Direction, ReportError> {
    Ok(Direction::from_degrees_checked(name, theta, phi)?)
}

/// Signed detector zenith when (θ_r, φ_r − φ_i) lies in the plane of incidence.
fn in_plane_zenith(theta_r_deg: f64, relative_azimuth: f64) -> Option<f64> {
    let off_specular = (relative_azimuth - 180.0).abs();
    let off_source = relative_azimuth.min(360.0 - relative_azimuth);
    if theta_r_deg.abs() < SAME_ANGLE_DEG || off_specular < SAME_ANGLE_DEG {
        Some(theta_r_deg)
    } else if off_source < SAME_ANGLE_DEG {
        Some(-theta_r_deg)
    } else {
        None
    }
}

fn distinct_sorted(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut all: Vec<f64> = values.collect();
    all.sort_by(f64::total_cmp);
    all.dedup_by(|a, b| (*a - *b).abs() < SAME_ANGLE_DEG);
    all
}

fn position_of(sorted: &[f64], value: f64) -> usize {
    sorted
        .iter()
        .position(|&v| (v - value).abs() < SAME_ANGLE_DEG)
        .unwrap_or(0)
}

/// A group of off-plane points at one (θ_i, θ_r) is drawn as a ring when it spans at least this
/// much azimuth; a small raster around specular (a few degrees of φ_r) would only pile up at 180°.
const RING_MIN_SPAN_DEG: f64 = 60.0;

/// Groups the out-of-plane points by (θ_i, θ_r) into rings. A ring also claims the in-plane
/// points of the same (θ_i, θ_r), which are its φ_r − φ_i = 0° and 180° members.
fn find_rings(
    points: &mut [PointView],
    set: &MeasurementSet,
    incidences: &[f64],
    chosen: &ModelCurveSource,
    alternative: Option<&ModelCurveSource>,
) -> Vec<Ring> {
    let same_group = |view: &PointView, theta_r: f64, key: (usize, f64)| {
        view.incidence == key.0 && (theta_r - key.1).abs() < SAME_ANGLE_DEG
    };
    let mut keys: Vec<(usize, f64)> = Vec::new();
    for (view, p) in points.iter().zip(&set.points) {
        if view.signed_zenith.is_none()
            && !keys.iter().any(|&key| same_group(view, p.theta_r_deg, key))
        {
            keys.push((view.incidence, p.theta_r_deg));
        }
    }
    keys.retain(|&key| {
        let azimuths = points
            .iter()
            .zip(&set.points)
            .filter(|(view, p)| same_group(view, p.theta_r_deg, key))
            .map(|(view, _)| view.relative_azimuth);
        let (low, high) = azimuths.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        high - low >= RING_MIN_SPAN_DEG
    });
    keys.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    for (view, p) in points.iter_mut().zip(&set.points) {
        view.ring = keys
            .iter()
            .position(|&key| same_group(view, p.theta_r_deg, key));
    }
    keys.iter()
        .enumerate()
        .map(|(index, &(incidence, theta_r_deg))| Ring {
            incidence,
            theta_r_deg,
            rank: keys[..index]
                .iter()
                .filter(|&&(i, _)| i == incidence)
                .count(),
            sweep: ring_sweep(incidences[incidence], theta_r_deg, chosen, alternative),
        })
        .collect()
}

/// Detector zeniths for an in-plane curve: every 0.5° to ±89.5°, and every 0.05° within 3° of
/// specular so that a narrow lobe (σ ≈ 0.03) is drawn at its true height.
fn in_plane_grid(theta_i_deg: f64) -> Vec<f64> {
    let coarse = (-179..=179).map(|i| i as f64 * 0.5);
    let fine = (-60..=60)
        .map(|i| theta_i_deg + i as f64 * 0.05)
        .filter(|x| *x < 89.5);
    distinct_sorted(coarse.chain(fine))
}

/// Relative azimuths for a ring: every 1°, and every 0.1° within 5° of the specular direction.
fn ring_grid() -> Vec<f64> {
    let coarse = (0..=360).map(f64::from);
    let fine = (-50..=50).map(|i| 180.0 + i as f64 * 0.1);
    distinct_sorted(coarse.chain(fine))
}

fn sweep(
    x: Vec<f64>,
    geometry: impl Fn(f64) -> (Direction, Direction),
    chosen: &ModelCurveSource,
    alternative: Option<&ModelCurveSource>,
) -> ModelSweep {
    let evaluate = |model: &Pbrdf| -> Vec<Mueller> {
        x.iter()
            .map(|&x| {
                let (incident, scattered) = geometry(x);
                model.mueller(&incident, &scattered)
            })
            .collect()
    };
    ModelSweep {
        chosen: evaluate(&chosen.pbrdf),
        alternative: alternative.map(|a| evaluate(&a.pbrdf)),
        x,
    }
}

fn in_plane_sweep(
    theta_i_deg: f64,
    chosen: &ModelCurveSource,
    alternative: Option<&ModelCurveSource>,
) -> ModelSweep {
    let incident = Direction::from_angles(theta_i_deg.to_radians(), 0.0);
    sweep(
        in_plane_grid(theta_i_deg),
        |zenith| {
            let phi_r = if zenith >= 0.0 { 180f64 } else { 0.0 };
            let scattered = Direction::from_angles(zenith.abs().to_radians(), phi_r.to_radians());
            (incident, scattered)
        },
        chosen,
        alternative,
    )
}

fn ring_sweep(
    theta_i_deg: f64,
    theta_r_deg: f64,
    chosen: &ModelCurveSource,
    alternative: Option<&ModelCurveSource>,
) -> ModelSweep {
    let incident = Direction::from_angles(theta_i_deg.to_radians(), 0.0);
    sweep(
        ring_grid(),
        |azimuth| {
            let scattered = Direction::from_angles(theta_r_deg.to_radians(), azimuth.to_radians());
            (incident, scattered)
        },
        chosen,
        alternative,
    )
}

/// Emission angles 0…88° every 2° (the hemispherical quadrature is accurate to 1e-5 there).
fn emissivity_curves(
    chosen: &ModelCurveSource,
    alternative: Option<&ModelCurveSource>,
) -> EmissivityCurves {
    let theta_deg: Vec<f64> = (0..=44).map(|i| 2.0 * i as f64).collect();
    let radians: Vec<f64> = theta_deg.iter().map(|t| t.to_radians()).collect();
    let quadrature = HemisphereQuadrature::default();
    EmissivityCurves {
        chosen: chosen.pbrdf.emissivity_table(&radians, &quadrature),
        alternative: alternative.map(|a| a.pbrdf.emissivity_table(&radians, &quadrature)),
        theta_deg,
    }
}
