//! A measurement's prepared data as the objective reads it: the whole of it, or some of its
//! points (a cross-validation fold) read in place instead of copied. A fold of K − 1 parts of
//! a dense scan is most of the file, and a copy of its prepared points (geometry, values and
//! 1/σ, 224 B a row of a 9-element file) was the largest thing the choice of terms held.

use super::data::{default_floor, default_sigma, ErrorSource, MeasurementData};

/// Some points of a [`MeasurementData`] as [`MeasurementData::new`] prepares a set of those
/// rows alone, without copying them: the same points in the same order, their own zenith list
/// (so that an evaluation computes the shadowing of their zeniths only) and, for the elements
/// weighed by the default noise model, that model's floor from their own largest m00.
pub(crate) struct PointSubset {
    /// The points, ascending, as positions in the whole data (a set has fewer than 2³² rows).
    points: Vec<u32>,
    /// Distinct cos θ of the subset's points, in the order [`MeasurementData::new`] lists them.
    zenith_cosines: Vec<f64>,
    /// The position in `zenith_cosines` of each of the whole data's zeniths (unused for a
    /// zenith none of the subset's points has).
    zenith_slots: Vec<u32>,
    /// The default noise model's floor of the subset.
    default_floor: f64,
}

impl PointSubset {
    /// The points `rows` (ascending) of `whole`.
    pub(crate) fn new(whole: &MeasurementData, rows: &[usize]) -> PointSubset {
        let width = whole.elements.len();
        let m00_max = rows
            .iter()
            .map(|&p| whole.values[p * width])
            .fold(0.0, f64::max);
        let mut zenith_cosines = Vec::new();
        let mut zenith_slots = vec![u32::MAX; whole.zenith_cosines.len()];
        let mut slot = |zenith: usize| {
            if zenith_slots[zenith] == u32::MAX {
                zenith_slots[zenith] = index_u32(zenith_cosines.len());
                zenith_cosines.push(whole.zenith_cosines[zenith]);
            }
        };
        for &p in rows {
            let g = &whole.geometry[p];
            slot(g.incident_zenith());
            slot(g.scattered_zenith());
        }
        PointSubset {
            points: rows.iter().map(|&p| index_u32(p)).collect(),
            zenith_cosines,
            zenith_slots,
            default_floor: default_floor(m00_max),
        }
    }

    /// The subset as the objective reads it, `whole` being the data it was taken from.
    pub(crate) fn view<'a>(&'a self, whole: &'a MeasurementData) -> DataView<'a> {
        DataView {
            whole,
            subset: Some(self),
        }
    }
}

/// `index` as a u32 (a point or zenith position; a set has fewer than 2³² rows).
fn index_u32(index: usize) -> u32 {
    u32::try_from(index).expect("a measurement has fewer than 2³² rows")
}

/// The points a fit evaluates: all of a [`MeasurementData`], or a [`PointSubset`] of it. A
/// point's position here is its position in the subset; its observations are numbered
/// point-major from there, as in a [`MeasurementData`] of the subset alone.
#[derive(Clone, Copy)]
pub(crate) struct DataView<'a> {
    pub(super) whole: &'a MeasurementData,
    subset: Option<&'a PointSubset>,
}

impl<'a> From<&'a MeasurementData> for DataView<'a> {
    fn from(whole: &'a MeasurementData) -> Self {
        DataView {
            whole,
            subset: None,
        }
    }
}

impl DataView<'_> {
    pub fn points(&self) -> usize {
        self.subset.map_or(self.whole.points(), |s| s.points.len())
    }
    /// Number of observations (points × elements): the size of the residual vector.
    pub fn observations(&self) -> usize {
        self.points() * self.element_count()
    }
    pub fn element_count(&self) -> usize {
        self.whole.element_count()
    }
    pub fn has_circular(&self) -> bool {
        self.whole.has_circular()
    }
    /// Distinct cos θ of the points' directions.
    pub fn zenith_cosines(&self) -> &[f64] {
        self.subset
            .map_or(&self.whole.zenith_cosines, |s| &s.zenith_cosines)
    }

    /// The position in the whole data of point `point`.
    #[inline]
    pub fn whole_point(&self, point: usize) -> usize {
        self.subset.map_or(point, |s| s.points[point] as usize)
    }
    /// The position in [`DataView::zenith_cosines`] of the whole data's zenith `zenith`.
    #[inline]
    pub fn zenith(&self, zenith: usize) -> usize {
        self.subset
            .map_or(zenith, |s| s.zenith_slots[zenith] as usize)
    }
    /// 1/σ of element `element` of the point whose first observation in the whole data is
    /// `start`: the whole data's, or for an element of the default noise model the subset's
    /// own, 1/σ with the subset's floor, computed as [`MeasurementData::new`] computes it.
    #[inline]
    pub fn inverse_sigma(&self, start: usize, element: usize) -> f64 {
        match self.subset {
            Some(s) if self.whole.error_sources()[element] == ErrorSource::DefaultModel => {
                1.0 / default_sigma(element, self.whole.values[start], s.default_floor)
            }
            _ => self.whole.inverse_sigma[start + element],
        }
    }

    /// Measured value and standard deviation of observation `index` (point-major), as
    /// [`MeasurementData::observation`] gives them.
    pub fn observation(&self, index: usize) -> (f64, f64) {
        let width = self.element_count();
        let start = self.whole_point(index / width) * width;
        let element = index % width;
        (
            self.whole.values[start + element],
            1.0 / self.inverse_sigma(start, element),
        )
    }

    /// Every `stride`-th point, from the first, with the same standard deviations (the default
    /// noise model's floor stays that of the data viewed) and the zenith list of those points
    /// only, so that an evaluation costs what the subsample holds.
    pub fn every_nth(&self, stride: usize) -> MeasurementData {
        let count = self.points().div_ceil(stride);
        let points = (0..self.points())
            .step_by(stride)
            .map(|p| self.whole_point(p));
        self.whole.with_points(points, count, |start, element| {
            self.inverse_sigma(start, element)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{MeasurementPoint, MeasurementSet};

    /// A fold read in place is what preparing the fold's rows alone gives: the default noise
    /// model's floor follows the fold's largest m00 (here a row with m00 = 0 sits on it), the
    /// file's uncertainties stay, the zenith list is the fold's own; its subsample too.
    #[test]
    fn a_subset_reads_as_its_rows_prepared_alone() {
        let point = |theta_i: f64, theta_r: f64, m00: f64| MeasurementPoint {
            theta_i_deg: theta_i,
            phi_i_deg: 0.0,
            theta_r_deg: theta_r,
            phi_r_deg: 180.0,
            values: vec![m00, 0.1 * m00],
            uncertainties: vec![None, Some(2e-3)],
            line: 0,
        };
        let set = MeasurementSet {
            source: "fold.csv".into(),
            sha256: String::new(),
            material: "fold".into(),
            wavelength_um: 10.0,
            metadata: Default::default(),
            elements: vec![0, 4],
            points: vec![
                point(10.0, 20.0, 4.0),
                point(30.0, 20.0, 0.0),
                point(50.0, 40.0, 0.5),
                point(10.0, 60.0, 0.25),
                point(70.0, 20.0, 0.125),
            ]
            .into_iter()
            .collect(),
            merged: Vec::new(),
            notes: Vec::new(),
        };
        let whole = MeasurementData::new(&set).unwrap();
        let rows = [1, 2, 3, 4];
        let subset = PointSubset::new(&whole, &rows);
        let fold = subset.view(&whole);
        let alone = MeasurementData::new(&super::super::subset(&set, &rows)).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let observations = |d: DataView| {
            (0..d.observations())
                .flat_map(|i| {
                    let (value, sigma) = d.observation(i);
                    [value.to_bits(), sigma.to_bits()]
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(fold.points(), rows.len());
        assert_eq!(observations(fold), observations((&alone).into()));
        assert_eq!(bits(fold.zenith_cosines()), bits(&alone.zenith_cosines));
        let zeniths = |d: DataView| {
            (0..d.points())
                .map(|p| {
                    let g = &d.whole.geometry[d.whole_point(p)];
                    (
                        d.zenith(g.incident_zenith()),
                        d.zenith(g.scattered_zenith()),
                    )
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(zeniths(fold), zeniths((&alone).into()));
        // The whole file's floor (1e-6 × 4) is not the fold's (1e-6 × 0.5).
        assert_ne!(whole.observation(2).1, fold.observation(0).1);
        // Every other point of the fold, as every other point of the rows prepared alone.
        let every_other = fold.every_nth(2);
        let alone_every_other = DataView::from(&alone).every_nth(2);
        assert_eq!(
            observations((&every_other).into()),
            observations((&alone_every_other).into())
        );
        assert_eq!(
            bits(&every_other.zenith_cosines),
            bits(&alone_every_other.zenith_cosines)
        );
    }
}
