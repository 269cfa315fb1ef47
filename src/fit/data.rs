//! A measurement prepared for fast repeated model evaluation: the model-independent scattering
//! geometry of every point built once, the per-direction shadowing factors shared between points
//! with the same zenith angle, and one standard deviation per observation (the weights of the
//! least-squares objective).

use crate::measure::{MeasurementRow, MeasurementSet, MUELLER_ELEMENT_NAMES};
use crate::pbrdf::{Direction, ScatteringGeometry};
use std::collections::HashMap;
use std::sync::Arc;

use super::FitError;

/// Default noise model when a file has no `u_` column for an element: a relative 3 % on m00 and
/// 1 % of m00 on every other element, the typical performance of a rotating-retarder Mueller
/// polarimeter (the polarization elements' error scales with the signal, not with themselves).
pub const DEFAULT_M00_RELATIVE_ERROR: f64 = 0.03;
/// See [`DEFAULT_M00_RELATIVE_ERROR`].
pub const DEFAULT_OTHER_ERROR_PER_M00: f64 = 0.01;
/// Floor of a default standard deviation, relative to the largest m00 of the file, so that a
/// point with m00 = 0 does not get an infinite weight.
const DEFAULT_ERROR_FLOOR: f64 = 1e-6;

/// Where a standard deviation came from, per element of the set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorSource {
    /// The file's `u_` column.
    File,
    /// The default noise model ([`DEFAULT_M00_RELATIVE_ERROR`]).
    DefaultModel,
}

/// One measured geometry, and its zenith angles' positions in
/// [`MeasurementData::zenith_cosines`] (u32: 72 B a point, not 80; a set of 2³¹ rows would not
/// fit in memory anyway).
#[derive(Clone, Copy, Debug)]
pub(crate) struct PreparedGeometry {
    pub scattering: ScatteringGeometry,
    incident_zenith: u32,
    scattered_zenith: u32,
}

impl PreparedGeometry {
    /// Position of cos θ_i in [`MeasurementData::zenith_cosines`].
    pub fn incident_zenith(&self) -> usize {
        self.incident_zenith as usize
    }
    /// Position of cos θ_r in [`MeasurementData::zenith_cosines`].
    pub fn scattered_zenith(&self) -> usize {
        self.scattered_zenith as usize
    }
}

/// The measurement in the form the objective consumes.
#[derive(Clone, Debug)]
pub struct MeasurementData {
    pub(crate) geometry: Vec<PreparedGeometry>,
    /// Distinct cos θ of all incident and scattered directions.
    pub(crate) zenith_cosines: Vec<f64>,
    /// Mueller (row, column) of each element present.
    pub(crate) elements: Vec<(usize, usize)>,
    /// Measured values, point-major (`point * elements.len() + element`): for the data of a
    /// whole set, the set's own values block ([`crate::measure::MeasurementRows::shared_values`]),
    /// not a copy.
    pub(crate) values: Arc<Vec<f64>>,
    /// 1 / standard deviation, aligned with `values`.
    pub(crate) inverse_sigma: Vec<f64>,
    error_sources: Vec<ErrorSource>,
}

impl MeasurementData {
    /// The set's data prepared, after checking every row; the values are the set's own block,
    /// shared, so the prepared data adds only the geometry and 1/σ.
    pub fn new(set: &MeasurementSet) -> Result<MeasurementData, FitError> {
        let width = set.elements.len();
        let mut geometry = Vec::with_capacity(set.points.len());
        let mut inverse_sigma = Vec::with_capacity(set.points.len() * width);
        let zeniths = visit_observations(
            set,
            |g| geometry.push(g),
            |_, sigma| inverse_sigma.push(1.0 / sigma),
        )?;
        Ok(MeasurementData {
            geometry,
            zenith_cosines: zeniths.cosines,
            elements: set.elements.iter().map(|&e| (e / 4, e % 4)).collect(),
            values: set.points.shared_values(),
            inverse_sigma,
            error_sources: error_sources(set),
        })
    }

    pub fn points(&self) -> usize {
        self.geometry.len()
    }
    /// Number of observations (points × elements): the size of the residual vector.
    pub fn observations(&self) -> usize {
        self.values.len()
    }
    /// Whether any element of the fourth row or column (circular polarization) is measured:
    /// they carry Im(r_s* r_p), which is odd in k, so k = 0 is then not a stationary point.
    pub fn has_circular(&self) -> bool {
        self.elements
            .iter()
            .any(|&(row, column)| row == 3 || column == 3)
    }
    /// Number of distinct zenith angles (shadowing factors per model evaluation).
    pub fn zenith_count(&self) -> usize {
        self.zenith_cosines.len()
    }
    pub fn element_count(&self) -> usize {
        self.elements.len()
    }
    /// Where each element's standard deviations came from, aligned with the set's elements.
    pub fn error_sources(&self) -> &[ErrorSource] {
        &self.error_sources
    }
    /// Measured value and standard deviation of observation `index` (point-major).
    pub fn observation(&self, index: usize) -> (f64, f64) {
        (self.values[index], 1.0 / self.inverse_sigma[index])
    }

    /// The points `points` (`count` of them, ascending) with the reciprocal standard deviation
    /// `inverse_sigma(start, element)` of each element of the point whose first observation is
    /// `start`, and the zenith list of those points only (a subsample,
    /// [`super::data_view::DataView::every_nth`]).
    pub(super) fn with_points(
        &self,
        points: impl Iterator<Item = usize>,
        count: usize,
        inverse_sigma: impl Fn(usize, usize) -> f64,
    ) -> MeasurementData {
        let width = self.elements.len();
        let mut zeniths = DistinctCosines::default();
        let mut geometry = Vec::with_capacity(count);
        let mut values = Vec::with_capacity(count * width);
        let mut inverse_sigmas = Vec::with_capacity(count * width);
        for point in points {
            let g = &self.geometry[point];
            geometry.push(PreparedGeometry {
                scattering: g.scattering,
                incident_zenith: zeniths.index(self.zenith_cosines[g.incident_zenith()]),
                scattered_zenith: zeniths.index(self.zenith_cosines[g.scattered_zenith()]),
            });
            let start = point * width;
            values.extend_from_slice(&self.values[start..start + width]);
            inverse_sigmas.extend((0..width).map(|element| inverse_sigma(start, element)));
        }
        MeasurementData {
            geometry,
            zenith_cosines: zeniths.cosines,
            elements: self.elements.clone(),
            values: Arc::new(values),
            inverse_sigma: inverse_sigmas,
            error_sources: self.error_sources.clone(),
        }
    }
}

/// The standard deviation of every observation of `set`, point-major, as the fit weighs it
/// (exactly what [`MeasurementData::observation`] returns, 1/(1/σ)), after the same checks as
/// [`MeasurementData::new`]; without the prepared geometry, for a caller that needs only the
/// weights (the fit report: a third of the memory of the prepared data).
pub fn observation_sigmas(set: &MeasurementSet) -> Result<Vec<f64>, FitError> {
    let mut sigmas = Vec::with_capacity(set.points.len() * set.elements.len());
    visit_observations(set, |_| {}, |_, sigma| sigmas.push(1.0 / (1.0 / sigma)))?;
    Ok(sigmas)
}

/// Checks every point of `set` and hands its prepared geometry to `geometry` and each of its
/// observations, value and standard deviation, to `observation`; returns the distinct zenith
/// cosines the geometries index.
fn visit_observations(
    set: &MeasurementSet,
    mut geometry: impl FnMut(PreparedGeometry),
    mut observation: impl FnMut(f64, f64),
) -> Result<DistinctCosines, FitError> {
    check_elements(set)?;
    let m00_max = set.points.iter().map(|p| p.values[0]).fold(0.0, f64::max);
    let floor = default_floor(m00_max);
    let mut zeniths = DistinctCosines::default();
    for point in &set.points {
        let at_line = |what: String| refusal(set, format!("line {}: {what}", point.line));
        geometry(prepare_geometry(point, &mut zeniths, &at_line)?);
        let m00 = point.values[0];
        for (column, (&value, uncertainty)) in
            point.values.iter().zip(point.uncertainties()).enumerate()
        {
            let sigma = uncertainty.unwrap_or_else(|| default_sigma(column, m00, floor));
            if !(value.is_finite() && sigma.is_finite() && sigma > 0.0) {
                return Err(at_line(format!(
                    "{} = {value} ± {sigma} is not a usable observation",
                    MUELLER_ELEMENT_NAMES[set.elements[column]]
                )));
            }
            observation(value, sigma);
        }
    }
    Ok(zeniths)
}

/// The default noise model's standard deviation of element `column` (0: m00) of a point whose
/// m00 is `m00`, at least `floor`.
pub(super) fn default_sigma(column: usize, m00: f64, floor: f64) -> f64 {
    let relative = if column == 0 {
        DEFAULT_M00_RELATIVE_ERROR
    } else {
        DEFAULT_OTHER_ERROR_PER_M00
    };
    (relative * m00).max(floor)
}

/// The default noise model's floor for a set whose largest m00 is `m00_max`.
pub(super) fn default_floor(m00_max: f64) -> f64 {
    DEFAULT_ERROR_FLOOR * m00_max.max(f64::MIN_POSITIVE)
}

/// The refusal of `set` for `message`.
fn refusal(set: &MeasurementSet, message: String) -> FitError {
    FitError::Measurement {
        file: set.source.clone(),
        message,
    }
}

/// Refuses a set without rows, without m00 first, with an index outside the 4×4 matrix, or with
/// rows of another number of values than it has elements.
fn check_elements(set: &MeasurementSet) -> Result<(), FitError> {
    if set.points.is_empty() {
        return Err(refusal(set, "the file has no data rows".into()));
    }
    let (width, values) = (set.elements.len(), set.points.width());
    if values != width {
        return Err(refusal(
            set,
            format!("rows of {values} values for {width} elements"),
        ));
    }
    if set.elements.first() != Some(&0) {
        return Err(refusal(
            set,
            "the set has no m00 (it must come first)".into(),
        ));
    }
    if let Some(&e) = set.elements.iter().find(|&&e| e >= 16) {
        return Err(refusal(
            set,
            format!("Mueller index {e} is not an element of a 4×4 matrix"),
        ));
    }
    Ok(())
}

/// Distinct zenith cosines, found by hash: a goniometer export can have as many distinct
/// angles as rows, and a linear search per row made 2e5 such rows take 20 s.
#[derive(Default)]
struct DistinctCosines {
    cosines: Vec<f64>,
    positions: HashMap<u64, u32>,
}

impl DistinctCosines {
    /// Position of `cos` in the list, added if new.
    fn index(&mut self, cos: f64) -> u32 {
        // == on floats: +0 and −0 are one key (the cosines are finite).
        let key = if cos == 0.0 { 0 } else { cos.to_bits() };
        let cosines = &mut self.cosines;
        *self.positions.entry(key).or_insert_with(|| {
            cosines.push(cos);
            u32::try_from(cosines.len() - 1).expect("fewer than 2³² distinct zenith angles")
        })
    }
}

/// The scattering geometry of `point`, its zenith cosines entered in `zeniths`; `at_line` makes
/// the refusal of an invalid direction.
fn prepare_geometry(
    point: MeasurementRow<'_>,
    zeniths: &mut DistinctCosines,
    at_line: &impl Fn(String) -> FitError,
) -> Result<PreparedGeometry, FitError> {
    let incident =
        Direction::from_degrees_checked("theta_i_deg", point.theta_i_deg, point.phi_i_deg)
            .map_err(|e| at_line(e.to_string()))?;
    let scattered =
        Direction::from_degrees_checked("theta_r_deg", point.theta_r_deg, point.phi_r_deg)
            .map_err(|e| at_line(e.to_string()))?;
    let scattering = ScatteringGeometry::new(&incident, &scattered)
        .ok_or_else(|| at_line("a direction lies on the horizon".into()))?;
    Ok(PreparedGeometry {
        scattering,
        incident_zenith: zeniths.index(scattering.cos_incident()),
        scattered_zenith: zeniths.index(scattering.cos_scattered()),
    })
}

/// Where each element's standard deviations come from: the same for every row, decided by the
/// file's `u_` columns.
fn error_sources(set: &MeasurementSet) -> Vec<ErrorSource> {
    set.points
        .has_uncertainty()
        .into_iter()
        .map(|has| match has {
            true => ErrorSource::File,
            false => ErrorSource::DefaultModel,
        })
        .collect()
}
