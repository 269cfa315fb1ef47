//! The numbers behind a fit report, computed once and drawn twice (PNG and SVG): every measured
//! point placed on the goniometer's plane of incidence or on an out-of-plane ring, its standard
//! deviation and normalized residual, and the chosen and competing models evaluated along each
//! plane and ring and as polarized emissivity (docs/design.md §1.3–1.4).

use crate::fit::observation_sigmas;
use crate::material::Material;
use crate::measure::MeasurementSet;
use crate::optics::{Mueller, Stokes};
use crate::pbrdf::{Direction, HemisphereQuadrature, Pbrdf};

use super::super::ReportError;

mod points;
mod residuals;
use points::{drawn_points, point_views, shown_views};
pub use residuals::{
    Residual, ResidualDensity, ResidualSummary, BIN_WIDTH, DENSITY_X_DEG, DENSITY_Y_SIGMA,
    HISTOGRAM_LIMIT,
};

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
    /// Detector zenith signed for the plane of incidence (docs/design.md §1.1): + on the specular side
    /// (φ_r = φ_i + 180°), − toward the source (φ_r = φ_i); `None` off the plane.
    pub signed_zenith: Option<f64>,
    /// Index into [`ReportData::rings`] when the point lies on an out-of-plane ring.
    pub ring: Option<usize>,
    /// φ_r − φ_i in [0°, 360°).
    pub relative_azimuth: f64,
}

/// A point the profile panels show (in the plane of incidence at an angle with curves, or on a
/// drawn ring): where it lies, its measured elements and the model.
#[derive(Clone, Debug)]
pub struct DrawnPoint {
    pub place: PointView,
    /// The measured elements by Mueller index r*4 + c, in the psps frame the point is drawn in: its
    /// own, except at the normal (θ_r = 0), where they are turned into the in-plane profile's
    /// frame (`points::in_plane_frame_at_normal`); elements that cannot be turned are `None`
    /// there.
    /// [`ReportData::residuals`] are taken before, in the row's own frame.
    pub readings: [Option<Reading>; 16],
    /// The chosen model at this geometry, in the same frame as `readings`.
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

/// ε0 and ε1 against emission angle for the chosen and the competing model.
#[derive(Clone, Debug)]
pub struct EmissivityCurves {
    pub theta_deg: Vec<f64>,
    pub chosen: Vec<Stokes>,
    pub alternative: Option<Vec<Stokes>>,
}

pub struct ReportData {
    /// Distinct incidence angles (°), ascending.
    pub incidences: Vec<f64>,
    /// The incidence angles (indices into `incidences`) drawn with model curves, ascending: all of
    /// them up to [`MAX_CURVE_INCIDENCES`], else that many chosen evenly over the measured range.
    /// Their position in this list is their colour.
    pub shown: Vec<usize>,
    /// Per incidence angle, its position in `shown` (`None` when it has no curves).
    pub slot: Vec<Option<usize>>,
    /// Off-plane points on no ring of at least [`RING_MIN_SPAN_DEG`] (a raster around specular).
    pub raster_points: usize,
    /// Off-plane points on rings left out of the profile panels (more rings than
    /// [`MAX_RINGS`], or at incidence angles without curves).
    pub unshown_ring_points: usize,
    /// Mueller indices present in the measurement, ascending.
    pub elements: Vec<usize>,
    /// The points the profile panels show, in the order of the file; the others (most of a
    /// dense scan's) appear only among the residuals.
    pub drawn: Vec<DrawnPoint>,
    /// In-plane model sweeps, one per entry of `shown` (`None` when no point of that angle lies in
    /// the plane).
    pub in_plane: Vec<Option<ModelSweep>>,
    pub rings: Vec<Ring>,
    /// The normalized residuals of every measured element, summarized for panels (g) and (h).
    pub residuals: ResidualSummary,
    pub emissivity: EmissivityCurves,
    pub chosen_label: String,
    pub alternative_label: Option<String>,
}

impl ReportData {
    /// Places every measured point of `set`, takes its residuals and evaluates the models of
    /// `material` (and of its competing fit) along the planes, rings and emission angles drawn.
    pub fn new(material: &Material, set: &MeasurementSet) -> Result<ReportData, ReportError> {
        let (chosen, alternative) = curve_sources(material)?;
        let incidences = distinct_sorted(set.points.iter().map(|p| p.theta_i_deg));
        let mut points = point_views(set, &incidences);
        let shown = representatives(&incidences, MAX_CURVE_INCIDENCES);
        let mut slot = vec![None; incidences.len()];
        for (position, &incidence) in shown.iter().enumerate() {
            slot[incidence] = Some(position);
        }
        let found = find_rings(
            &mut points,
            set,
            &incidences,
            &slot,
            &chosen,
            alternative.as_ref(),
        );
        let in_plane = in_plane_sweeps(&points, &incidences, &shown, &chosen, alternative.as_ref());
        // Every point's view is freed before the sigmas (one per observation) are taken.
        let shown_points = shown_views(points, &slot);
        // The standard deviations the fit weighted by (the file's u_ columns or the fit's
        // default noise model), so that report residuals are the ones the optimizer minimized.
        let sigmas = observation_sigmas(set)?;
        let residuals = ResidualSummary::new(set, &sigmas, &chosen)?;
        let drawn = drawn_points(shown_points, set, &sigmas, &chosen)?;
        let emissivity = emissivity_curves(&chosen, alternative.as_ref());

        Ok(ReportData {
            incidences,
            shown,
            slot,
            raster_points: found.raster_points,
            unshown_ring_points: found.unshown_points,
            elements: set.elements.clone(),
            drawn,
            in_plane,
            rings: found.rings,
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
        self.raster_points
    }
}

/// The chosen model and, when the fit recorded one, the competing distribution's best fit.
fn curve_sources(
    material: &Material,
) -> Result<(ModelCurveSource, Option<ModelCurveSource>), ReportError> {
    let chosen = ModelCurveSource {
        label: material.model.distribution().name().to_owned(),
        pbrdf: material.grey_model()?.pbrdf()?,
    };
    let alternative = match material.fit.as_ref().and_then(|f| f.alternative.as_ref()) {
        Some(alt) => Some(ModelCurveSource {
            label: alt.model.distribution.name().to_owned(),
            pbrdf: alt.model.pbrdf()?,
        }),
        None => None,
    };
    Ok((chosen, alternative))
}

/// The in-plane model sweeps of the `shown` incidence angles: `None` for an angle without a
/// point in the plane of incidence.
fn in_plane_sweeps(
    points: &[PointView],
    incidences: &[f64],
    shown: &[usize],
    chosen: &ModelCurveSource,
    alternative: Option<&ModelCurveSource>,
) -> Vec<Option<ModelSweep>> {
    let mut has_in_plane = vec![false; incidences.len()];
    for p in points.iter().filter(|p| p.signed_zenith.is_some()) {
        has_in_plane[p.incidence] = true;
    }
    shown
        .iter()
        .map(|&incidence| {
            has_in_plane[incidence]
                .then(|| in_plane_sweep(incidences[incidence], chosen, alternative))
        })
        .collect()
}

/// Most incidence angles drawn with model curves: beyond it, curves and their points are shown
/// for this many angles spread evenly over the measured range (a report draws each curve in
/// several panels, so their number must not grow with the file). Every point stays in the
/// residual panels.
pub const MAX_CURVE_INCIDENCES: usize = 8;
/// Most out-of-plane rings drawn (chosen evenly, by incidence angle then detector zenith).
pub const MAX_RINGS: usize = 18;

/// Indices of at most `limit` of the ascending `values`: all when they are few, else the one
/// nearest to each of `limit` targets evenly spaced from the first to the last.
pub fn representatives(values: &[f64], limit: usize) -> Vec<usize> {
    if values.len() <= limit {
        return (0..values.len()).collect();
    }
    let (low, high) = (values[0], values[values.len() - 1]);
    let mut chosen: Vec<usize> = (0..limit)
        .map(|i| {
            let target = low + (high - low) * i as f64 / (limit - 1).max(1) as f64;
            let at = values
                .partition_point(|&v| v < target)
                .min(values.len() - 1);
            if at > 0 && (target - values[at - 1]) <= (values[at] - target) {
                at - 1
            } else {
                at
            }
        })
        .collect();
    chosen.dedup();
    chosen
}

/// `limit` indices of `0..count` spread evenly, first and last included (all when fewer).
fn evenly(count: usize, limit: usize) -> Vec<usize> {
    if count <= limit {
        return (0..count).collect();
    }
    let mut picked: Vec<usize> = (0..limit)
        .map(|i| (i * (count - 1) + (limit - 1) / 2) / (limit - 1).max(1))
        .collect();
    picked.dedup();
    picked
}

/// A detector at the normal (θ_r = 0 to a microdegree): its φ_r is arbitrary, so it lies in
/// every plane, the plane of incidence included.
fn at_normal(theta_r_deg: f64) -> bool {
    theta_r_deg.abs() < SAME_ANGLE_DEG
}

/// Signed detector zenith when (θ_r, φ_r − φ_i) lies in the plane of incidence.
fn in_plane_zenith(theta_r_deg: f64, relative_azimuth: f64) -> Option<f64> {
    let off_specular = (relative_azimuth - 180.0).abs();
    let off_source = relative_azimuth.min(360.0 - relative_azimuth);
    if at_normal(theta_r_deg) || off_specular < SAME_ANGLE_DEG {
        Some(theta_r_deg)
    } else if off_source < SAME_ANGLE_DEG {
        Some(-theta_r_deg)
    } else {
        None
    }
}

/// φ_r − φ_i of the in-plane profile at signed detector zenith `zenith`: the specular side
/// (180°) for zenith ≥ 0, the source side (0°) below. At zenith 0 (the normal) its psps frame is
/// therefore the limit θ_r → 0⁺ along φ_i + 180° (docs/design.md §1.3).
fn in_plane_relative_azimuth(zenith: f64) -> f64 {
    if zenith >= 0.0 {
        180.0
    } else {
        0.0
    }
}

fn distinct_sorted(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut all: Vec<f64> = values.collect();
    all.sort_by(f64::total_cmp);
    all.dedup_by(|a, b| (*a - *b).abs() < SAME_ANGLE_DEG);
    all
}

/// Index of `value` in the ascending, deduplicated `sorted` (a binary search: a file can hold
/// as many distinct angles as rows).
fn position_of(sorted: &[f64], value: f64) -> usize {
    let at = sorted.partition_point(|&v| v < value - SAME_ANGLE_DEG);
    if sorted
        .get(at)
        .is_some_and(|&v| (v - value).abs() < SAME_ANGLE_DEG)
    {
        at
    } else {
        0
    }
}

/// A group of off-plane points at one (θ_i, θ_r) is drawn as a ring when it spans at least this
/// much azimuth; a small raster around specular (a few degrees of φ_r) would only pile up at 180°.
const RING_MIN_SPAN_DEG: f64 = 60.0;

/// Rings found in a measurement, and the off-plane points the profile panels do not show.
struct FoundRings {
    rings: Vec<Ring>,
    raster_points: usize,
    unshown_points: usize,
}

/// Groups the out-of-plane points by (θ_i, θ_r) into rings. A ring also claims the in-plane
/// points of the same (θ_i, θ_r), which are its φ_r − φ_i = 0° and 180° members. Rings are drawn
/// only at incidence angles with curves (`slot`), at most [`MAX_RINGS`] of them, spread evenly;
/// grouping sorts once, so it costs N log N however many rings the file has.
fn find_rings(
    points: &mut [PointView],
    set: &MeasurementSet,
    incidences: &[f64],
    slot: &[Option<usize>],
    chosen: &ModelCurveSource,
    alternative: Option<&ModelCurveSource>,
) -> FoundRings {
    let order = setting_order(points, set);
    let groups = settings(&order, points, set);
    let (candidates, raster_points) = ring_candidates(groups, points);
    let drawable: Vec<&[usize]> = candidates
        .iter()
        .copied()
        .filter(|group| slot[points[group[0]].incidence].is_some())
        .collect();
    let kept: Vec<&[usize]> = evenly(drawable.len(), MAX_RINGS)
        .into_iter()
        .map(|i| drawable[i])
        .collect();
    let off_plane_on_rings = |groups: &[&[usize]]| -> usize {
        groups
            .iter()
            .flat_map(|g| g.iter())
            .filter(|&&i| points[i].signed_zenith.is_none())
            .count()
    };
    let unshown_points = off_plane_on_rings(&candidates) - off_plane_on_rings(&kept);
    let mut rings = Vec::with_capacity(kept.len());
    for (index, group) in kept.iter().enumerate() {
        let incidence = points[group[0]].incidence;
        let theta_r_deg = set.points.row(group[0]).theta_r_deg;
        for &i in group.iter() {
            points[i].ring = Some(index);
        }
        let rank = rings
            .iter()
            .filter(|r: &&Ring| r.incidence == incidence)
            .count();
        rings.push(Ring {
            incidence,
            theta_r_deg,
            rank,
            sweep: ring_sweep(incidences[incidence], theta_r_deg, chosen, alternative),
        });
    }
    FoundRings {
        rings,
        raster_points,
        unshown_points,
    }
}

/// Indices of the points sorted by incidence angle, then detector zenith θ_r.
fn setting_order(points: &[PointView], set: &MeasurementSet) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    let theta_r = |i: usize| set.points.row(i).theta_r_deg;
    order.sort_by(|&a, &b| {
        points[a]
            .incidence
            .cmp(&points[b].incidence)
            .then(theta_r(a).total_cmp(&theta_r(b)))
    });
    order
}

/// The runs of `order` (from [`setting_order`]) of one incidence angle whose θ_r agree with the
/// run's first to a microdegree: the points of one goniometer setting (θ_i, θ_r).
fn settings<'o>(
    order: &'o [usize],
    points: &[PointView],
    set: &MeasurementSet,
) -> Vec<&'o [usize]> {
    let theta_r = |i: usize| set.points.row(i).theta_r_deg;
    let mut groups: Vec<&[usize]> = Vec::new();
    let mut start = 0;
    for end in 1..=order.len() {
        let split = end == order.len() || {
            let (first, next) = (order[start], order[end]);
            points[first].incidence != points[next].incidence
                || (theta_r(next) - theta_r(first)).abs() >= SAME_ANGLE_DEG
        };
        if split {
            groups.push(&order[start..end]);
            start = end;
        }
    }
    groups
}

/// The settings with off-plane points that span at least [`RING_MIN_SPAN_DEG`] of azimuth (the
/// rings), and the number of off-plane points in the others (rasters around specular).
fn ring_candidates<'o>(
    groups: Vec<&'o [usize]>,
    points: &[PointView],
) -> (Vec<&'o [usize]>, usize) {
    let mut raster_points = 0;
    let mut candidates: Vec<&[usize]> = Vec::new();
    for group in groups {
        let off_plane = group
            .iter()
            .filter(|&&i| points[i].signed_zenith.is_none())
            .count();
        if off_plane == 0 {
            continue;
        }
        let (low, high) = group
            .iter()
            .map(|&i| points[i].relative_azimuth)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        if high - low >= RING_MIN_SPAN_DEG {
            candidates.push(group);
        } else {
            raster_points += off_plane;
        }
    }
    (candidates, raster_points)
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
            let phi_r = in_plane_relative_azimuth(zenith);
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

#[cfg(test)]
pub(super) mod tests {
    use super::points::normal_detector_turn;
    use super::*;
    use crate::material::{AlternativeFit, ModelSpec};
    use crate::measure::MeasurementPoint;
    use crate::pbrdf::{Shadowing, SlopeDistribution};
    use crate::report::fit_report::profiles::{profile_series, Domain, Quantity};
    use crate::report::fit_report::test_records::fit_record;
    use std::collections::BTreeMap;

    fn spec(distribution: SlopeDistribution) -> ModelSpec {
        ModelSpec {
            distribution,
            shadowing: Shadowing::Smith,
            n: 1.5,
            k: 0.1,
            rho_d: 0.01,
            facet: Default::default(),
            lobe_keys: Default::default(),
            wavelength_um: 10.0,
        }
    }

    pub(super) fn material(with_alternative: bool) -> Material {
        let model = spec(SlopeDistribution::Cauchy { sigma: 0.2, q: 2.5 });
        let fit = with_alternative.then(|| {
            let alternative = AlternativeFit {
                model: spec(SlopeDistribution::Gaussian { sigma: 0.15 }),
                cost: 2.0,
                reduced_chi2: 2.0,
                aic: 1.0,
                bic: 1.0,
            };
            fit_record(serde_json::json!({ "alternative": alternative }))
        });
        Material {
            name: "test".into(),
            tool_version: "test".into(),
            model: crate::material::MaterialModel::Grey(model),
            fit,
        }
    }

    /// A set of m00 and m10 at the given (θ_i, φ_i, θ_r, φ_r), valued by `value(m)`.
    pub(super) fn set_of(
        geometry: &[(f64, f64, f64, f64)],
        value: impl Fn(&Mueller) -> [f64; 2],
        uncertainties: [Option<f64>; 2],
    ) -> MeasurementSet {
        let model = material(false).grey_model().unwrap().pbrdf().unwrap();
        let points = geometry
            .iter()
            .enumerate()
            .map(|(i, &(ti, pi, tr, pr))| {
                let m = model.mueller(
                    &Direction::from_angles(ti.to_radians(), pi.to_radians()),
                    &Direction::from_angles(tr.to_radians(), pr.to_radians()),
                );
                MeasurementPoint {
                    theta_i_deg: ti,
                    phi_i_deg: pi,
                    theta_r_deg: tr,
                    phi_r_deg: pr,
                    values: value(&m).to_vec(),
                    uncertainties: uncertainties.to_vec(),
                    line: i as u64 + 2,
                }
            })
            .collect();
        MeasurementSet {
            source: "x.csv".into(),
            sha256: String::new(),
            material: "test".into(),
            wavelength_um: 10.0,
            metadata: BTreeMap::new(),
            elements: vec![0, 4],
            points,
            merged: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// The chosen model's own values of `elements` at the given (θ_i, φ_i, θ_r, φ_r), each with a
    /// 1-σ of 1e-4 sr⁻¹.
    fn model_set(geometry: &[(f64, f64, f64, f64)], elements: &[usize]) -> MeasurementSet {
        let mut set = set_of(geometry, exact, [None, None]);
        let model = material(false).grey_model().unwrap().pbrdf().unwrap();
        let mut points = set.points.to_points();
        for p in &mut points {
            let m = model.mueller(
                &Direction::from_angles(p.theta_i_deg.to_radians(), p.phi_i_deg.to_radians()),
                &Direction::from_angles(p.theta_r_deg.to_radians(), p.phi_r_deg.to_radians()),
            );
            p.values = elements.iter().map(|&e| m[(e / 4, e % 4)]).collect();
            p.uncertainties = vec![Some(1e-4); elements.len()];
        }
        set.points = points.into_iter().collect();
        set.elements = elements.to_vec();
        set
    }

    pub(super) fn exact(m: &Mueller) -> [f64; 2] {
        [m[(0, 0)], m[(1, 0)]]
    }

    #[test]
    fn points_are_placed_in_the_plane_on_rings_or_in_a_raster() {
        let geometry = [
            (60.0, 0.0, 30.0, 180.0), // specular side of the plane
            (60.0, 10.0, 30.0, 10.0), // toward the source (φ_r = φ_i)
            (60.0, 0.0, 0.0, 90.0),   // detector at the normal: in every plane
            (60.0, 0.0, 45.0, 30.0),  // a ring spanning 120°
            (60.0, 0.0, 45.0, 90.0),
            (60.0, 0.0, 45.0, 150.0),
            (60.0, 0.0, 45.0, 180.0), // its in-plane member
            (60.0, 0.0, 58.0, 175.0), // a raster of 10° around specular: no ring
            (60.0, 0.0, 58.0, 185.0),
            (20.0, 0.0, 45.0, 200.0), // another incidence angle
        ];
        let set = set_of(&geometry, exact, [None, None]);
        let data = ReportData::new(&material(false), &set).unwrap();
        assert_eq!(data.incidences, [20.0, 60.0]);
        // The points the profiles show, in the order of the file, with their signed zenith in
        // the plane and their ring: the plane's three, the ring's three and its in-plane member;
        // not the raster (58°) nor the lone 20° point, which are only among the residuals.
        let placed: Vec<(Option<f64>, Option<usize>)> = data
            .drawn
            .iter()
            .map(|p| (p.place.signed_zenith, p.place.ring))
            .collect();
        assert_eq!(
            placed,
            [
                (Some(30.0), None),
                (Some(-30.0), None),
                (Some(0.0), None),
                (None, Some(0)),
                (None, Some(0)),
                (None, Some(0)),
                (Some(45.0), Some(0)),
            ]
        );
        // Two residuals (m00, m10) per point, each at the point's hemisphere-signed θ_r.
        let forward: Vec<f64> = data
            .residuals
            .each
            .iter()
            .step_by(2)
            .map(|r| r.forward_zenith)
            .collect();
        assert_eq!(
            forward[3..6],
            [-45.0, 45.0, 45.0],
            "90° ≤ φr−φi ≤ 270° is forward"
        );
        assert_eq!(data.rings.len(), 1);
        assert_eq!(
            (data.rings[0].incidence, data.rings[0].theta_r_deg),
            (1, 45.0)
        );
        assert_eq!(data.off_ring_points(), 3);
        // Only θi = 60° has in-plane points, so only it gets an in-plane model sweep.
        assert!(data.in_plane[0].is_none() && data.in_plane[1].is_some());
    }

    #[test]
    fn curves_go_to_a_few_angles_spread_over_the_range() {
        let few = [20.0, 40.0, 60.0];
        assert_eq!(representatives(&few, 8), [0, 1, 2]);
        let many: Vec<f64> = (0..1000).map(|i| 5.0 + 0.07 * i as f64).collect();
        let chosen = representatives(&many, 8);
        assert_eq!(chosen.len(), 8);
        assert_eq!((chosen[0], chosen[7]), (0, 999), "both ends of the range");
        for (i, &c) in chosen.iter().enumerate() {
            let target = 5.0 + 69.93 * i as f64 / 7.0;
            assert!((many[c] - target).abs() <= 0.035 + 1e-9, "{i}: {}", many[c]);
        }
        // Clustered angles: the nearest measured one to each target, never twice.
        let clustered = [10.0, 10.5, 11.0, 50.0, 80.0, 80.5, 81.0, 81.5, 82.0, 82.5];
        assert_eq!(representatives(&clustered, 8), [0, 2, 3, 4, 9]);
        assert_eq!(evenly(200, 18).len(), 18);
        assert_eq!(evenly(200, 18)[17], 199);
        assert_eq!(evenly(5, 18), [0, 1, 2, 3, 4]);
        assert_eq!(position_of(&many, 5.0 + 0.07 * 500.0), 500);
    }

    #[test]
    fn sweeps_and_emissivity_are_the_models_own_values() {
        let set = set_of(&[(30.0, 0.0, 30.0, 180.0)], exact, [None, None]);
        let material = material(true);
        let data = ReportData::new(&material, &set).unwrap();
        let sweep = data.in_plane[0].as_ref().unwrap();
        let specular = sweep
            .x
            .iter()
            .position(|&x| (x - 30.0).abs() < 1e-9)
            .unwrap();
        let at = |model: &Pbrdf| {
            model.mueller(
                &Direction::from_angles(30f64.to_radians(), 0.0),
                &Direction::from_angles(30f64.to_radians(), std::f64::consts::PI),
            )
        };
        assert_eq!(
            sweep.chosen[specular],
            at(&material.grey_model().unwrap().pbrdf().unwrap())
        );
        let alternative = material.fit.as_ref().unwrap().alternative.as_ref().unwrap();
        assert_eq!(
            sweep.alternative.as_ref().unwrap()[specular],
            at(&alternative.model.pbrdf().unwrap())
        );
        assert_eq!(data.alternative_label.as_deref(), Some("gaussian"));
        // Toward the source the detector sits at φ_r = φ_i: the retro direction at −30°.
        let retro = sweep
            .x
            .iter()
            .position(|&x| (x + 30.0).abs() < 1e-9)
            .unwrap();
        let expected = material.grey_model().unwrap().pbrdf().unwrap().mueller(
            &Direction::from_angles(30f64.to_radians(), 0.0),
            &Direction::from_angles(30f64.to_radians(), 0.0),
        );
        assert_eq!(sweep.chosen[retro], expected);

        let e = &data.emissivity;
        assert_eq!(e.theta_deg.first(), Some(&0.0));
        assert_eq!(e.theta_deg.last(), Some(&88.0));
        let direct = material
            .grey_model()
            .unwrap()
            .pbrdf()
            .unwrap()
            .emissivity(60f64.to_radians(), &HemisphereQuadrature::default());
        assert_eq!(e.chosen[30], direct);
        // Isotropic surface: emission is p-polarized (ε1 < 0) away from the normal.
        assert!(e.chosen[1..].iter().all(|s| s[1] < 0.0 && s[0] < 1.0));
    }
    /// The chosen model's in-plane curve at θ_r = 0 (the normal), for the first incidence angle.
    fn in_plane_curve_at_normal(data: &ReportData) -> Mueller {
        let sweep = data.in_plane[0].as_ref().unwrap();
        let zero = sweep.x.iter().position(|&x| x == 0.0).unwrap();
        sweep.chosen[zero]
    }

    #[test]
    fn a_detector_at_the_normal_is_drawn_in_the_in_plane_frame_whatever_its_azimuth() {
        // φ_r − φ_i = 90° (a quarter turn of the frame), 135° (m10 and m20 mix) and, with
        // φ_i ≠ 0, 230°; the in-plane profile's frame at θ_r = 0 is the limit along φ_i + 180°.
        let geometry = [
            (40.0, 0.0, 0.0, 90.0),
            (40.0, 0.0, 0.0, 135.0),
            (40.0, 20.0, 0.0, 250.0),
        ];
        let linear = [0, 1, 2, 4, 5, 6, 8, 9, 10];
        let set = model_set(&geometry, &linear);
        let data = ReportData::new(&material(false), &set).unwrap();
        let curve = in_plane_curve_at_normal(&data);
        let m00 = curve[(0, 0)];
        assert!(curve[(1, 0)].abs() > 0.05 * m00, "a polarizing model");
        assert_eq!(
            data.drawn.len(),
            geometry.len(),
            "in-plane points are drawn"
        );
        for (p, row) in data.drawn.iter().zip(&set.points) {
            assert_eq!(p.place.signed_zenith, Some(0.0));
            let measured = p.readings[0].unwrap().value;
            assert_eq!(measured, row.values[0], "m00 does not turn");
            for &e in &linear {
                let (r, c) = (e / 4, e % 4);
                let ratio = p.readings[e].unwrap().value / measured;
                let want = curve[(r, c)] / m00;
                assert!(
                    (ratio - want).abs() < 1e-12,
                    "{e} at {row:?}: {ratio} vs {want}"
                );
                let model = p.model[(r, c)] / p.model[(0, 0)];
                assert!((model - want).abs() < 1e-12, "model {e}: {model} vs {want}");
            }
            // The panels see the same: the point sits on the curve at 0.
            let (series, _) = profile_series(&data, Quantity::Ratio(4), Domain::InPlane);
            assert!(series[0]
                .points
                .iter()
                .all(|q| q.x == 0.0 && (q.value - curve[(1, 0)] / m00).abs() < 1e-12));
        }
        // Unturned, the rows disagree with the curve: m10 flips sign at 90°, and at 135° the
        // polarization sits in m20, which the in-plane model has none of.
        let raw = |point: usize, e: usize| {
            set.points.row(point).values[linear.iter().position(|&x| x == e).unwrap()]
        };
        assert!((raw(0, 4) + curve[(1, 0)]).abs() < 1e-12 * m00);
        assert!(raw(1, 4).abs() < 1e-12 * m00 && raw(1, 8).abs() > 0.05 * m00);
        assert!(curve[(2, 0)].abs() < 1e-15 * m00);
        // Residuals stay data − model in the row's own frame: zero for the model's own values.
        assert!(data.residuals.each.iter().all(|r| r.value.abs() < 1e-9));
        assert_eq!(data.residuals.count, geometry.len() * linear.len());
    }

    #[test]
    fn an_element_is_turned_only_with_the_partners_it_mixes_with() {
        // m00 and m10 without m20: at 90° m10' = −m10 needs no partner; at 135° m10' = m20,
        // which was not measured, so that row has no in-plane m10 (m00 stays).
        let set = model_set(&[(40.0, 0.0, 0.0, 90.0), (40.0, 0.0, 0.0, 135.0)], &[0, 4]);
        let data = ReportData::new(&material(false), &set).unwrap();
        let curve = in_plane_curve_at_normal(&data);
        let quarter = &data.drawn[0];
        let m10 = quarter.readings[4].unwrap();
        assert_eq!(m10.value, -set.points.row(0).values[1]);
        assert!(
            (m10.value / quarter.readings[0].unwrap().value - curve[(1, 0)] / curve[(0, 0)]).abs()
                < 1e-12
        );
        assert!((m10.sigma - 1e-4).abs() < 1e-18);
        let eighth = &data.drawn[1];
        assert_eq!(eighth.readings[4], None);
        assert_eq!(
            eighth.readings[0].map(|r| r.value),
            Some(set.points.row(1).values[0])
        );
        let (series, _) = profile_series(&data, Quantity::Ratio(4), Domain::InPlane);
        assert_eq!(
            series[0].points.len(),
            1,
            "only the row that could be turned"
        );
        let (series, _) = profile_series(&data, Quantity::M00, Domain::InPlane);
        assert_eq!(series[0].points.len(), 2);
        // Both rows keep their residuals in their own frames.
        assert_eq!(data.residuals.count, 4);
    }

    #[test]
    fn only_points_the_profiles_show_keep_their_readings() {
        // In the plane (specular side), and off it beside specular (a raster, on no ring).
        let set = model_set(
            &[(40.0, 0.0, 30.0, 180.0), (40.0, 0.0, 30.0, 170.0)],
            &[0, 4],
        );
        let data = ReportData::new(&material(false), &set).unwrap();
        assert_eq!(data.drawn.len(), 1);
        assert_eq!(data.drawn[0].place.signed_zenith, Some(30.0));
        assert_eq!(data.off_ring_points(), 1);
        assert_eq!(data.residuals.count, 4, "every row keeps its residuals");
    }

    #[test]
    fn the_frame_turn_at_the_normal_follows_the_azimuth() {
        // At k = ẑ, s = ê_φ and p = ẑ × ê_φ = (−cos φ, −sin φ, 0) = ê_(φ+90°): the s axes of
        // azimuths φ_r and φ_i + 180° differ by η = φ_i + 180° − φ_r, counted from s toward p.
        let quarter = normal_detector_turn(0.0, 90.0).angle();
        assert!((quarter - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        let turn = normal_detector_turn(20.0, 250.0).angle();
        assert!((turn - (-50f64).to_radians()).abs() < 1e-14);
        assert!(normal_detector_turn(10.0, 190.0).angle().abs() < 1e-15);
    }
}
