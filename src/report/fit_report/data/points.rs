//! The measured points of a fit report: where each lies, each row's elements and model in its own
//! frame (from which [`super::residuals`] takes the residuals), and what the profile
//! panels draw of the points they show (docs/design.md §1.3 for the frames).

use super::{
    at_normal, in_plane_relative_azimuth, in_plane_zenith, position_of, DrawnPoint,
    ModelCurveSource, PointView, Reading, ReportError,
};
use crate::measure::{MeasurementRow, MeasurementSet};
use crate::optics::{rotation_between_frames, FrameTurn, Mueller};
use crate::pbrdf::Direction;

/// Every measured point as the report sees it (not yet on a ring, nothing drawn yet), in the
/// order of the file.
pub(super) fn point_views(set: &MeasurementSet, incidences: &[f64]) -> Vec<PointView> {
    set.points
        .iter()
        .map(|p| {
            let relative_azimuth = relative_azimuth(&p);
            PointView {
                incidence: position_of(incidences, p.theta_i_deg),
                signed_zenith: in_plane_zenith(p.theta_r_deg, relative_azimuth),
                ring: None,
                relative_azimuth,
            }
        })
        .collect()
}

/// φ_r − φ_i of a row in [0°, 360°).
fn relative_azimuth(p: &MeasurementRow<'_>) -> f64 {
    (p.phi_r_deg - p.phi_i_deg).rem_euclid(360.0)
}

/// The detector zenith a row's residuals are drawn at: θ_r signed by hemisphere, + on the
/// forward (specular) half 90° ≤ φ_r − φ_i ≤ 270°; in the plane of incidence, its signed zenith.
pub(super) fn residual_zenith(p: MeasurementRow<'_>) -> f64 {
    let relative_azimuth = relative_azimuth(&p);
    in_plane_zenith(p.theta_r_deg, relative_azimuth).unwrap_or({
        if (90.0..=270.0).contains(&relative_azimuth) {
            p.theta_r_deg
        } else {
            -p.theta_r_deg
        }
    })
}

/// The measured elements of row `point` of `set` (standard deviations `sigmas`) and the chosen
/// model there, both in the row's own psps frame.
pub(super) fn own_frame(
    set: &MeasurementSet,
    sigmas: &[f64],
    point: usize,
    chosen: &ModelCurveSource,
) -> Result<([Option<Reading>; 16], Mueller), ReportError> {
    let p = set.points.row(point);
    let incident = checked_direction("theta_i_deg", p.theta_i_deg, p.phi_i_deg)?;
    let scattered = checked_direction("theta_r_deg", p.theta_r_deg, p.phi_r_deg)?;
    let width = set.elements.len();
    let mut readings = [None; 16];
    for (column, &element) in set.elements.iter().enumerate() {
        let (value, sigma) = (p.values[column], sigmas[point * width + column]);
        readings[element] = Some(Reading { value, sigma });
    }
    Ok((readings, chosen.pbrdf.mueller(&incident, &scattered)))
}

/// The points the profile panels show, with their row indices: in the plane of incidence at
/// an angle with curves (`slot`), or on a drawn ring. A dense scan's rows are mostly neither;
/// those appear only among the residuals, and their views need not outlive the placing.
pub(super) fn shown_views(
    points: Vec<PointView>,
    slot: &[Option<usize>],
) -> Vec<(usize, PointView)> {
    points
        .into_iter()
        .enumerate()
        .filter(|(_, view)| {
            let in_plane = slot[view.incidence].is_some() && view.signed_zenith.is_some();
            in_plane || view.ring.is_some()
        })
        .collect()
}

/// What the profile panels draw of each of the `shown` points (row index and place in `set`,
/// standard deviations `sigmas`).
pub(super) fn drawn_points(
    shown: Vec<(usize, PointView)>,
    set: &MeasurementSet,
    sigmas: &[f64],
    chosen: &ModelCurveSource,
) -> Result<Vec<DrawnPoint>, ReportError> {
    shown
        .into_iter()
        .map(|(point, place)| {
            let p = set.points.row(point);
            let (readings, model) = own_frame(set, sigmas, point, chosen)?;
            let (readings, model) = if at_normal(p.theta_r_deg) {
                in_plane_frame_at_normal(&readings, &model, p.phi_i_deg, p.phi_r_deg)
            } else {
                (readings, model)
            };
            Ok(DrawnPoint {
                place,
                readings,
                model,
            })
        })
        .collect()
}

fn checked_direction(name: &'static str, theta: f64, phi: f64) -> Result<Direction, ReportError> {
    Ok(Direction::from_degrees_checked(name, theta, phi)?)
}

/// Largest |mixing weight| of the frame turn of [`in_plane_frame_at_normal`] treated as zero:
/// the sin 2η or cos 2η of a turn within [`SAME_ANGLE_DEG`](super::SAME_ANGLE_DEG) of a multiple of 90° (sin 2e-6° ≈
/// 3.49e-8), where rounding of 90° in radians leaves ~1e-16 instead of 0.
const NEGLIGIBLE_MIXING: f64 = 3.5e-8;

/// The turn η of the outgoing psps frame of a detector at the normal from its own azimuth φ_r
/// to the in-plane profile's (φ_i + 180°, [`in_plane_relative_azimuth`]). At θ_r = 0 light leaves
/// along k = ẑ and each frame is the limit θ_r → 0⁺ along its azimuth φ (docs/design.md §1.3), with
/// s = lim unit(ẑ × k) = ê_φ = (−sin φ, cos φ, 0) ([`Direction::azimuthal_axis`]); η is the angle
/// from the row's s toward its p = k × s at which the in-plane s lies (optics::frame).
pub(super) fn normal_detector_turn(phi_i_deg: f64, phi_r_deg: f64) -> FrameTurn {
    let own = Direction::from_angles(0.0, phi_r_deg.to_radians());
    let in_plane_phi = phi_i_deg + in_plane_relative_azimuth(0.0);
    let in_plane = Direction::from_angles(0.0, in_plane_phi.to_radians());
    rotation_between_frames(&own.azimuthal_axis, &in_plane.azimuthal_axis, &own.vector)
}

/// A row measured with the detector at the normal, re-expressed in the psps frame of the
/// in-plane profile (the frame the in-plane model curves are drawn in at θ_r = 0), so that it
/// can be drawn there whatever its φ_r: M' = L(η) M with L = [`FrameTurn::mueller`] and η from
/// [`normal_detector_turn`]. Only the outgoing (row) side turns; the incident side is the scan's.
///
/// L(η) mixes rows 1 and 2 of each column (m1c' = cos2η m1c + sin2η m2c, m2c' = −sin2η m1c +
/// cos2η m2c); rows 0 and 3 stay as they are. A turned element is formed only when every
/// element it mixes in with a non-negligible weight was measured (a row with m10 but not m20
/// at φ_r − φ_i = 135° has no in-plane m10, and it is left out of the in-plane polarization
/// panels rather than drawn from half its partners); at a turn of a multiple of 90° each element
/// is its own partner (m10' = ±m10). m00 never turns. The 1-σ of a turned element is that of
/// independent errors, √(Σ (L_rj σ_jc)²). Points at the normal are never on a ring
/// ([`find_rings`](super::find_rings) skips groups without an off-plane point), so only the in-plane panels see
/// the turned values; the residual panels use the row's own frame.
fn in_plane_frame_at_normal(
    readings: &[Option<Reading>; 16],
    model: &Mueller,
    phi_i_deg: f64,
    phi_r_deg: f64,
) -> ([Option<Reading>; 16], Mueller) {
    let turn = normal_detector_turn(phi_i_deg, phi_r_deg).mueller();
    let mut turned = [None; 16];
    for (element, slot) in turned.iter_mut().enumerate() {
        let (row, column) = (element / 4, element % 4);
        let mut value = 0.0;
        let mut variance = 0.0;
        let mut complete = true;
        for partner in 0..4 {
            let weight = turn[(row, partner)];
            if weight.abs() <= NEGLIGIBLE_MIXING {
                continue;
            }
            match readings[partner * 4 + column] {
                Some(r) => {
                    value += weight * r.value;
                    variance += (weight * r.sigma).powi(2);
                }
                None => complete = false,
            }
        }
        if complete && readings[element].is_some() {
            *slot = Some(Reading {
                value,
                sigma: variance.sqrt(),
            });
        }
    }
    (turned, turn * model)
}
