//! The rows of a [`super::MeasurementSet`] stored as columns (docs/design.md §2.1): one block of
//! angles, one point-major block of Mueller values, one point-major block of the uncertainties of
//! the elements that have a `u_` column, one of line numbers. A row costs its data and nothing
//! more (no heap allocation of its own), and the values block is shared, not copied, with the
//! fit's prepared data ([`MeasurementRows::shared_values`]).

use std::sync::Arc;

use super::MeasurementPoint;

/// The data rows of a measurement set, column by column. Every row has the same number of Mueller
/// elements (the set's [`super::MeasurementSet::elements`]) and the same elements with an
/// uncertainty, because both are decided by the file's header row.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MeasurementRows {
    /// (θ_i, φ_i, θ_r, φ_r) of each row, degrees.
    angles: Vec<[f64; 4]>,
    /// Mueller values, point-major (`row * width + element`), shared with the fit.
    values: Arc<Vec<f64>>,
    /// Each element's position among a row's uncertainties, `None` for an element without one.
    uncertainty_slots: Vec<Option<usize>>,
    /// Uncertainties of the elements with a slot, point-major (`row * slots + slot`).
    uncertainties: Vec<f64>,
    /// 1-based line of each row in its file.
    lines: Vec<u64>,
}

/// One row of [`MeasurementRows`], borrowed: what [`MeasurementPoint`] owns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasurementRow<'a> {
    /// Incidence zenith angle, degrees, in [0, 90).
    pub theta_i_deg: f64,
    /// Incidence azimuth, degrees.
    pub phi_i_deg: f64,
    /// Receiver zenith angle, degrees, in [0, 90).
    pub theta_r_deg: f64,
    /// Receiver azimuth, degrees.
    pub phi_r_deg: f64,
    /// Mueller-matrix BRDF elements, sr⁻¹, aligned with the set's elements; `values[0]` is m00.
    pub values: &'a [f64],
    /// 1-based line of the row in the file.
    pub line: u64,
    uncertainties: &'a [f64],
    slots: &'a [Option<usize>],
}

impl<'a> MeasurementRow<'a> {
    /// The 1-σ uncertainty (sr⁻¹) of element `element` (a position in the set's elements), if
    /// the file has a `u_` column for it (`None` too for a position beyond the elements).
    pub fn uncertainty(&self, element: usize) -> Option<f64> {
        let slot = self.slots.get(element).copied().flatten()?;
        Some(self.uncertainties[slot])
    }

    /// The uncertainty of each element in order, `None` for those without a `u_` column.
    pub fn uncertainties(&self) -> impl ExactSizeIterator<Item = Option<f64>> + 'a {
        let own = self.uncertainties;
        self.slots.iter().map(move |slot| slot.map(|s| own[s]))
    }

    /// (θ_i, φ_i, θ_r, φ_r), degrees.
    pub fn angles(&self) -> [f64; 4] {
        [
            self.theta_i_deg,
            self.phi_i_deg,
            self.theta_r_deg,
            self.phi_r_deg,
        ]
    }

    /// The row as an owned point.
    pub fn to_point(&self) -> MeasurementPoint {
        MeasurementPoint {
            theta_i_deg: self.theta_i_deg,
            phi_i_deg: self.phi_i_deg,
            theta_r_deg: self.theta_r_deg,
            phi_r_deg: self.phi_r_deg,
            values: self.values.to_vec(),
            uncertainties: self.uncertainties().collect(),
            line: self.line,
        }
    }
}

impl MeasurementRows {
    /// No rows of `has_uncertainty.len()` elements each, those flagged in `has_uncertainty`
    /// with an uncertainty, with room for `capacity` rows.
    pub fn with_capacity(has_uncertainty: &[bool], capacity: usize) -> MeasurementRows {
        let mut count = 0;
        let uncertainty_slots: Vec<Option<usize>> = has_uncertainty
            .iter()
            .map(|&has| {
                count += usize::from(has);
                has.then(|| count - 1)
            })
            .collect();
        let width = uncertainty_slots.len();
        MeasurementRows {
            angles: Vec::with_capacity(capacity),
            values: Arc::new(Vec::with_capacity(capacity * width)),
            uncertainty_slots,
            uncertainties: Vec::with_capacity(capacity * count),
            lines: Vec::with_capacity(capacity),
        }
    }

    /// No rows, with the shape (elements, which of them have an uncertainty) of `self`.
    pub fn empty_like(&self, capacity: usize) -> MeasurementRows {
        MeasurementRows::with_capacity(&self.has_uncertainty(), capacity)
    }

    /// Appends a row: `angles` (θ_i, φ_i, θ_r, φ_r) in degrees, `values` and `uncertainties`
    /// aligned with the elements, its file `line`.
    ///
    /// # Panics
    /// If `values` or `uncertainties` is not one per element, or an uncertainty is given (or
    /// missing) for an element that has none (or has one): the shape is the header's, the same
    /// for every row.
    pub fn push(
        &mut self,
        angles: [f64; 4],
        values: &[f64],
        uncertainties: &[Option<f64>],
        line: u64,
    ) {
        let width = self.width();
        assert!(
            values.len() == width && uncertainties.len() == width,
            "a row of {} values and {} uncertainties among rows of {width} elements",
            values.len(),
            uncertainties.len()
        );
        for (slot, uncertainty) in self.uncertainty_slots.iter().zip(uncertainties) {
            assert_eq!(
                slot.is_some(),
                uncertainty.is_some(),
                "every row has uncertainties for the same elements"
            );
        }
        self.angles.push(angles);
        Arc::make_mut(&mut self.values).extend_from_slice(values);
        self.uncertainties.extend(uncertainties.iter().flatten());
        self.lines.push(line);
    }

    /// Appends an owned point ([`MeasurementRows::push`]'s panics apply).
    pub fn push_point(&mut self, point: &MeasurementPoint) {
        let angles = [
            point.theta_i_deg,
            point.phi_i_deg,
            point.theta_r_deg,
            point.phi_r_deg,
        ];
        self.push(angles, &point.values, &point.uncertainties, point.line);
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// Mueller elements per row.
    pub fn width(&self) -> usize {
        self.uncertainty_slots.len()
    }

    /// Whether each element has an uncertainty (a `u_` column), in element order.
    pub fn has_uncertainty(&self) -> Vec<bool> {
        self.uncertainty_slots.iter().map(Option::is_some).collect()
    }

    /// Row `index`.
    ///
    /// # Panics
    /// If `index` ≥ [`MeasurementRows::len`].
    pub fn row(&self, index: usize) -> MeasurementRow<'_> {
        let [theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg] = self.angles[index];
        let width = self.width();
        let own = self.uncertainties_per_row();
        MeasurementRow {
            theta_i_deg,
            phi_i_deg,
            theta_r_deg,
            phi_r_deg,
            values: &self.values[index * width..(index + 1) * width],
            line: self.lines[index],
            uncertainties: &self.uncertainties[index * own..(index + 1) * own],
            slots: &self.uncertainty_slots,
        }
    }

    /// The first row, if any.
    pub fn first(&self) -> Option<MeasurementRow<'_>> {
        (!self.is_empty()).then(|| self.row(0))
    }

    /// The rows in order.
    pub fn iter(&self) -> Rows<'_> {
        Rows {
            rows: self,
            next: 0,
            end: self.len(),
        }
    }

    /// The rows as owned points.
    pub fn to_points(&self) -> Vec<MeasurementPoint> {
        self.iter().map(|row| row.to_point()).collect()
    }

    /// (θ_i, φ_i, θ_r, φ_r) of every row, degrees.
    pub fn angles(&self) -> &[[f64; 4]] {
        &self.angles
    }

    /// Every row's Mueller values, point-major (`row * width + element`).
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The values block itself, for a reader that keeps it (the fit's prepared data) without a
    /// copy.
    pub fn shared_values(&self) -> Arc<Vec<f64>> {
        Arc::clone(&self.values)
    }

    /// The uncertainties of the elements that have one, point-major.
    pub fn uncertainty_block(&self) -> &[f64] {
        &self.uncertainties
    }

    /// Every row's file line.
    pub fn lines(&self) -> &[u64] {
        &self.lines
    }

    /// Keeps the rows for which `keep` is true, in order.
    pub fn retain(&mut self, mut keep: impl FnMut(MeasurementRow<'_>) -> bool) {
        let kept: Vec<usize> = (0..self.len()).filter(|&i| keep(self.row(i))).collect();
        if kept.len() < self.len() {
            *self = self.select(&kept);
        }
    }

    /// The rows `indices`, in the order given.
    pub fn select(&self, indices: &[usize]) -> MeasurementRows {
        let mut chosen = self.empty_like(indices.len());
        for &index in indices {
            chosen.push_row(self.row(index));
        }
        chosen
    }

    /// Appends the rows of `other`.
    ///
    /// # Panics
    /// If `other`'s rows have another shape (elements, which of them have an uncertainty).
    pub fn append(&mut self, other: &MeasurementRows) {
        assert_eq!(
            self.uncertainty_slots, other.uncertainty_slots,
            "rows of one shape"
        );
        self.angles.extend_from_slice(&other.angles);
        Arc::make_mut(&mut self.values).extend_from_slice(&other.values);
        self.uncertainties.extend_from_slice(&other.uncertainties);
        self.lines.extend_from_slice(&other.lines);
    }

    /// Gives every element of every row an uncertainty: `sigma(row)`, one per element.
    pub(crate) fn set_uncertainties(
        &mut self,
        mut sigma: impl FnMut(MeasurementRow<'_>) -> Vec<f64>,
    ) {
        let width = self.width();
        let mut block = Vec::with_capacity(self.len() * width);
        for index in 0..self.len() {
            let row_sigma = sigma(self.row(index));
            assert_eq!(row_sigma.len(), width, "one uncertainty per element");
            block.extend(row_sigma);
        }
        self.uncertainty_slots = (0..width).map(Some).collect();
        self.uncertainties = block;
    }

    /// Frees capacity beyond the rows held (after a reader reserved for more).
    pub(crate) fn shrink_to_fit(&mut self) {
        self.angles.shrink_to_fit();
        Arc::make_mut(&mut self.values).shrink_to_fit();
        self.uncertainties.shrink_to_fit();
        self.lines.shrink_to_fit();
    }

    fn push_row(&mut self, row: MeasurementRow<'_>) {
        self.angles.push(row.angles());
        Arc::make_mut(&mut self.values).extend_from_slice(row.values);
        self.uncertainties.extend_from_slice(row.uncertainties);
        self.lines.push(row.line);
    }

    fn uncertainties_per_row(&self) -> usize {
        self.uncertainty_slots.iter().flatten().count()
    }
}

impl FromIterator<MeasurementPoint> for MeasurementRows {
    /// The points as rows, their shape that of the first point ([`MeasurementRows::push`]'s
    /// panics apply to the others).
    fn from_iter<I: IntoIterator<Item = MeasurementPoint>>(points: I) -> MeasurementRows {
        let mut points = points.into_iter().peekable();
        let has_uncertainty: Vec<bool> = points
            .peek()
            .map(|p| p.uncertainties.iter().map(Option::is_some).collect())
            .unwrap_or_default();
        let mut rows = MeasurementRows::with_capacity(&has_uncertainty, points.size_hint().0);
        for point in points {
            rows.push_point(&point);
        }
        rows
    }
}

/// The rows of [`MeasurementRows`] in order ([`MeasurementRows::iter`]).
#[derive(Debug, Clone)]
pub struct Rows<'a> {
    rows: &'a MeasurementRows,
    next: usize,
    end: usize,
}

impl<'a> Iterator for Rows<'a> {
    type Item = MeasurementRow<'a>;

    fn next(&mut self) -> Option<MeasurementRow<'a>> {
        (self.next < self.end).then(|| {
            self.next += 1;
            self.rows.row(self.next - 1)
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.end - self.next, Some(self.end - self.next))
    }

    fn nth(&mut self, n: usize) -> Option<MeasurementRow<'a>> {
        self.next = self.next.saturating_add(n).min(self.end);
        self.next()
    }
}

impl DoubleEndedIterator for Rows<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        (self.next < self.end).then(|| {
            self.end -= 1;
            self.rows.row(self.end)
        })
    }
}

impl ExactSizeIterator for Rows<'_> {}

impl<'a> IntoIterator for &'a MeasurementRows {
    type Item = MeasurementRow<'a>;
    type IntoIter = Rows<'a>;

    fn into_iter(self) -> Rows<'a> {
        self.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(line: u64, m00: f64, u: Option<f64>) -> MeasurementPoint {
        MeasurementPoint {
            theta_i_deg: 10.0,
            phi_i_deg: 0.0,
            theta_r_deg: 20.0 + line as f64,
            phi_r_deg: 180.0,
            values: vec![m00, -0.5 * m00],
            uncertainties: vec![None, u],
            line,
        }
    }

    /// Rows go in as points and come out as the same points, whichever operation moved them.
    #[test]
    fn points_survive_the_columns() {
        let points: Vec<MeasurementPoint> = (0..5)
            .map(|k| point(k + 2, k as f64, Some(0.1 * k as f64 + 0.1)))
            .collect();
        let mut rows: MeasurementRows = points.iter().cloned().collect();
        assert_eq!(rows.to_points(), points);
        assert_eq!(rows.row(3).uncertainty(1), Some(0.4));
        assert_eq!(rows.row(3).uncertainty(0), None);
        assert_eq!(rows.values().len(), 10);
        assert_eq!(rows.uncertainty_block().len(), 5);
        let picked = rows.select(&[4, 1]);
        assert_eq!(
            picked.to_points(),
            vec![points[4].clone(), points[1].clone()]
        );
        rows.retain(|r| r.line % 2 == 0);
        assert_eq!(rows.lines(), [2, 4, 6]);
        let mut both = rows.clone();
        both.append(&picked);
        assert_eq!(both.len(), 5);
        assert_eq!(both.row(3).to_point(), points[4]);
    }

    /// The fit's copy of the values is the block itself; a later change to the rows leaves it
    /// as it was.
    #[test]
    fn shared_values_are_not_copied_until_the_rows_change() {
        let mut rows: MeasurementRows = (0..3).map(|k| point(k, 1.0, None)).collect();
        let shared = rows.shared_values();
        assert!(std::ptr::eq(shared.as_ptr(), rows.values().as_ptr()));
        rows.push_point(&point(9, 7.0, None));
        assert_eq!(shared.len(), 6);
        assert_eq!(rows.values().len(), 8);
    }

    #[test]
    #[should_panic(expected = "same elements")]
    fn a_row_of_another_shape_is_refused() {
        let mut rows: MeasurementRows = std::iter::once(point(1, 1.0, Some(0.1))).collect();
        rows.push_point(&point(2, 1.0, None));
    }

    /// Estimated uncertainties cover every element of every row.
    #[test]
    fn set_uncertainties_flags_every_element() {
        let mut rows: MeasurementRows = (0..2).map(|k| point(k, 2.0, None)).collect();
        rows.set_uncertainties(|r| vec![0.1 * r.values[0]; 2]);
        assert_eq!(rows.has_uncertainty(), [true, true]);
        let u: Vec<Option<f64>> = rows.row(1).uncertainties().collect();
        assert_eq!(u, [Some(0.2), Some(0.2)]);
    }
}
