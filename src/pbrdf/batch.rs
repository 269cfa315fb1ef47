//! The Mueller BRDF over columns of geometries in degrees (the Python `mueller`, benches): bit
//! for bit [`Pbrdf::mueller`] of each row's directions as `irpol eval` reads them, computed in
//! blocks so that the work splits into loops of independent iterations that the compiler
//! vectorizes.
//!
//! Why blocks: one geometry's evaluation is a long chain (four sines and cosines, two Smith
//! masking factors, the facet density's logarithm and exponential, the Fresnel square roots and
//! division, the frame rotations), and evaluated geometry after geometry it runs close to its
//! latency. Over a block of 64, each stage is one loop without calls or branches: the sines and
//! cosines of all directions, the masking factors of each side, then the whole Mueller matrix of
//! each pair (its elements stored column by column and copied out). Every value is computed by
//! the same operations as in the one-at-a-time path but for the slope density's logarithm
//! (inlined here, the system's there: one at a time it is 13 ns faster), so the results agree to
//! ~q |ln x| 1e-16 of m00, within 1e-12 (tested below); where a vectorized stage cannot be exact (a facet density below e^−708, a
//! model with a subsurface term) the geometry goes the one-at-a-time way. On one core of the
//! 2-core test machine (AVX-512), 1e6 random geometries of paper_paint take 29–32 ns each
//! without shadowing and 44–45 ns with the Cauchy Smith factor (88 and 147 ns with only the
//! sines, cosines and masking calls in blocks).

use super::{ModelError, Pbrdf, Shadowing};
use crate::elementary::{sin_cos_degrees_within_a_turn, within_a_turn};
use crate::optics::{Direction, Mueller};
use crate::pbrdf::ScatteringGeometry;

/// Geometries per block: large enough for the loops to amortize, small enough that a block's
/// sines, cosines and masking factors (12 × 64 values, 6 kB) stay in the L1 cache.
const BLOCK: usize = 64;

/// Four equally long columns of geometries in degrees, read as `irpol eval` reads a row:
/// θ_i ∈ [0°, 90°), θ_r ∈ (−90°, 90°) with a negative θ_r the direction across the normal
/// ([`super::fold_signed_zenith`]), finite azimuths.
#[derive(Clone, Copy, Debug)]
pub struct GeometryColumns<'a> {
    pub theta_i: &'a [f64],
    pub phi_i: &'a [f64],
    pub theta_r: &'a [f64],
    pub phi_r: &'a [f64],
}

impl GeometryColumns<'_> {
    /// The geometry count, `None` unless all four columns have it.
    pub fn count(&self) -> Option<usize> {
        let count = self.theta_i.len();
        ([self.phi_i.len(), self.theta_r.len(), self.phi_r.len()] == [count; 3]).then_some(count)
    }

    /// The directions of geometry `row`, checked as `irpol eval` checks a row.
    pub fn directions(&self, row: usize) -> Result<(Direction, Direction), ModelError> {
        Ok((
            Direction::from_degrees_checked("theta_i_deg", self.theta_i[row], self.phi_i[row])?,
            Direction::from_signed_degrees_checked(
                "theta_r_deg",
                self.theta_r[row],
                self.phi_r[row],
            )?,
        ))
    }

    /// Whether geometry `row` passes [`GeometryColumns::directions`]' checks (the same
    /// conditions, without building the directions), its four angles with θ_r folded to its
    /// unsigned form except φ_r, and whether φ_r needs [`GeometryColumns::folded_azimuth`].
    /// The fold's azimuth is left to a separate pass: its `rem_euclid` is an fmod call, which
    /// the compiler, making the fold branch free, ran for every geometry (5 % of a
    /// random-geometry evaluation, perf).
    #[inline(always)]
    fn folded(&self, row: usize) -> (bool, [f64; 4], bool) {
        let (ti, pi, tr, pr) = (
            self.theta_i[row],
            self.phi_i[row],
            self.theta_r[row],
            self.phi_r[row],
        );
        // fold_signed_zenith's condition; its folded φ_r is finite where φ_r is.
        let fold = tr < 0.0 && pr.is_finite();
        let tr = if fold { -tr } else { tr };
        // NaN fails every comparison, so each condition also refuses it.
        let valid = (0.0..90.0).contains(&ti)
            && pi.is_finite()
            && (0.0..90.0).contains(&tr)
            && pr.is_finite();
        (valid, [ti, pi, tr, pr], fold)
    }

    /// φ_r of geometry `row` as [`super::fold_signed_zenith`] folds it (for a row that
    /// [`GeometryColumns::folded`] says needs it).
    fn folded_azimuth(&self, row: usize) -> f64 {
        super::fold_signed_zenith(self.theta_r[row], self.phi_r[row]).1
    }
}

/// A block's Mueller elements, element e (row-major m00…m33) of geometry j at [e][j].
type BlockElements = [[f64; BLOCK]; 16];

/// The sines and cosines of one block's directions and their masking factors, column by column.
struct Block {
    /// θ_i, φ_i, θ_r, φ_r (degrees, reduced to one turn), then overwritten by their sines.
    sines: [[f64; BLOCK]; 4],
    cosines: [[f64; BLOCK]; 4],
    masking: [[f64; BLOCK]; 2],
}

/// The Smith masking factors G1 of one column of cosines into `out` (whole columns: a fixed
/// trip count; a stale tail is harmless).
fn masking_column(model: &Pbrdf, cosines: &[f64; BLOCK], out: &mut [f64; BLOCK]) {
    match model.cauchy_smith_table() {
        // One vectorized loop: ~6 ns per direction where the calls one at a time took 20–30.
        Some(table) => table.masking_into(cosines, out),
        None => {
            for (g1, &c) in out.iter_mut().zip(cosines) {
                *g1 = model.masking(c);
            }
        }
    }
}

impl Pbrdf {
    /// The Mueller BRDF (sr⁻¹, psps frames, row-major m00…m33) of geometries `first..` of
    /// `columns` into `out`, 16 values per geometry, as many as `out` holds: [`Pbrdf::mueller`]
    /// of [`GeometryColumns::directions`] by the same operations, but for the inlined logarithm of
    /// the slope density (within 1 ulp of the system's, which `mueller` keeps: ~1e-15 relative). The error is that of the first
    /// invalid geometry in the range; `out` is then partly written.
    pub fn mueller_columns(
        &self,
        columns: &GeometryColumns<'_>,
        first: usize,
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        let mut block = Block {
            sines: [[0.0; BLOCK]; 4],
            cosines: [[0.0; BLOCK]; 4],
            masking: [[1.0; BLOCK]; 2],
        };
        for (b, values) in out.chunks_mut(16 * BLOCK).enumerate() {
            let start = first + b * BLOCK;
            let count = values.len() / 16;
            self.fill_block(columns, start, count, &mut block)?;
            self.write_block(&block, values);
        }
        Ok(())
    }

    /// Checks geometries `start..start + count` and computes their sines, cosines and masking
    /// factors into `block` (the first `count` entries of each column).
    fn fill_block(
        &self,
        columns: &GeometryColumns<'_>,
        start: usize,
        count: usize,
        block: &mut Block,
    ) -> Result<(), ModelError> {
        let (mut valid, mut beyond_a_turn, mut any_fold) = (true, false, false);
        for j in 0..count {
            let (ok, angles, fold) = columns.folded(start + j);
            valid &= ok;
            any_fold |= fold;
            for (column, angle) in block.sines.iter_mut().zip(angles) {
                beyond_a_turn |= angle.abs() > 360.0;
                column[j] = angle;
            }
        }
        if !valid {
            for row in start..start + count {
                columns.directions(row)?;
            }
        }
        // Folded azimuths lie within [0°, 360°): `beyond_a_turn` may only overcount.
        if any_fold {
            for j in 0..count {
                if columns.folded(start + j).2 {
                    block.sines[3][j] = columns.folded_azimuth(start + j);
                }
            }
        }
        // Only where needed: in a loop the compiler evaluates fmod for every angle and selects
        // (6 % of a random-geometry evaluation, perf), though it changes only angles beyond a
        // turn, which are rare.
        if beyond_a_turn {
            for column in block.sines.iter_mut() {
                for angle in &mut column[..count] {
                    *angle = within_a_turn(*angle);
                }
            }
        }
        // Over the whole block, whatever `count`: a fixed trip count, and a stale tail is
        // harmless (never written out).
        for (sines, cosines) in block.sines.iter_mut().zip(block.cosines.iter_mut()) {
            for (s, c) in sines.iter_mut().zip(cosines.iter_mut()) {
                (*s, *c) = sin_cos_degrees_within_a_turn(*s);
            }
        }
        if self.shadowing() == Shadowing::Smith {
            let [incident, scattered] = &mut block.masking;
            masking_column(self, &block.cosines[0], incident);
            masking_column(self, &block.cosines[2], scattered);
        }
        Ok(())
    }

    /// The Mueller matrices of a filled block's first `values.len() / 16` geometries.
    fn write_block(&self, block: &Block, values: &mut [f64]) {
        if self.has_subsurface() {
            for (j, m_out) in values.chunks_exact_mut(16).enumerate() {
                let m = self
                    .block_geometry(block, j)
                    .map_or_else(Mueller::zeros, |g| {
                        self.mueller_for_geometry(&g, block.masking[0][j], block.masking[1][j])
                    });
                for (slot, value) in m_out.iter_mut().zip(m.transpose().iter()) {
                    *slot = *value;
                }
            }
            return;
        }
        let mut elements: BlockElements = [[0.0; BLOCK]; 16];
        let mut exact = [true; BLOCK];
        self.block_elements(block, &mut elements, &mut exact);
        for (j, m_out) in values.chunks_exact_mut(16).enumerate() {
            if exact[j] {
                for (slot, element) in m_out.iter_mut().zip(&elements) {
                    *slot = element[j];
                }
            } else if let Some(g) = self.block_geometry(block, j) {
                let m = self.mueller_for_geometry(&g, block.masking[0][j], block.masking[1][j]);
                for (slot, value) in m_out.iter_mut().zip(m.transpose().iter()) {
                    *slot = *value;
                }
            }
        }
    }

    /// The geometry of direction pair `j` of a filled block.
    #[inline(always)]
    fn block_geometry(&self, block: &Block, j: usize) -> Option<ScatteringGeometry> {
        let [sin_ti, sin_pi, sin_tr, sin_pr] = &block.sines;
        let [cos_ti, cos_pi, cos_tr, cos_pr] = &block.cosines;
        let incident =
            Direction::from_sines_and_cosines((sin_ti[j], cos_ti[j]), (sin_pi[j], cos_pi[j]));
        let scattered =
            Direction::from_sines_and_cosines((sin_tr[j], cos_tr[j]), (sin_pr[j], cos_pr[j]));
        ScatteringGeometry::new(&incident, &scattered)
    }

    /// The Mueller elements (row-major m00…m33) of every geometry of a filled block of a model
    /// without a subsurface term, element e of geometry j at `elements[e][j]`, and whether each
    /// is exact: one loop without calls or branches over the whole block, which the compiler
    /// vectorizes (the same operations as one at a time, so the same results), where the matrices
    /// one at a time ran at the latency of their long chains (square roots, divisions, the
    /// density's logarithm and exponential). A geometry flagged inexact (a facet density below
    /// e^−708, outside the vectorized exponential's range) is recomputed by the caller.
    fn block_elements(
        &self,
        block: &Block,
        elements: &mut BlockElements,
        exact: &mut [bool; BLOCK],
    ) {
        // One loop per shadowing kind, each with its kind a constant.
        match self.shadowing() {
            Shadowing::None => self.block_elements_with(block, elements, exact, Shadowing::None),
            Shadowing::TorranceSparrow => {
                self.block_elements_with(block, elements, exact, Shadowing::TorranceSparrow)
            }
            Shadowing::Smith => self.block_elements_with(block, elements, exact, Shadowing::Smith),
        }
    }

    /// [`Pbrdf::block_elements`] of a model whose shadowing is `shadowing`.
    #[inline(always)]
    fn block_elements_with(
        &self,
        block: &Block,
        elements: &mut BlockElements,
        exact: &mut [bool; BLOCK],
        shadowing: Shadowing,
    ) {
        for j in 0..BLOCK {
            let masking = [block.masking[0][j], block.masking[1][j]];
            let (m, in_range) = match self.block_geometry(block, j) {
                Some(g) => self.facets_and_depolarizer_in_range(&g, masking, shadowing),
                None => (Mueller::zeros(), true),
            };
            exact[j] = in_range;
            for (element, value) in elements.iter_mut().zip(m.transpose().iter()) {
                element[j] = *value;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::RefractiveIndex;
    use crate::pbrdf::{FacetSide, SlopeDistribution, Subsurface};

    fn model(shadowing: Shadowing) -> Pbrdf {
        Pbrdf::new(
            SlopeDistribution::Cauchy { sigma: 0.1, q: 1.8 },
            shadowing,
            RefractiveIndex::new(1.2, 0.2),
            0.01,
        )
        .unwrap()
    }

    /// Models that take every path of a block: each shadowing kind; a narrow Cauchy lobe with
    /// q = 100 and a narrow Gaussian, whose facet densities fall below e^−708 at moderate tilts
    /// (the geometries recomputed one at a time); the Gaussian Smith factor (its closed form,
    /// not the table); internal facets (ε = 1/N², the other branch of the Fresnel square root);
    /// a subsurface term (the one-at-a-time loop).
    fn models_of_every_path() -> Vec<Pbrdf> {
        let mut models: Vec<Pbrdf> = [
            Shadowing::None,
            Shadowing::TorranceSparrow,
            Shadowing::Smith,
        ]
        .into_iter()
        .map(model)
        .collect();
        let index = RefractiveIndex::new(1.5, 0.05);
        for distribution in [
            SlopeDistribution::Cauchy {
                sigma: 0.01,
                q: 100.0,
            },
            SlopeDistribution::Gaussian { sigma: 0.05 },
            SlopeDistribution::Gaussian { sigma: 0.4 },
        ] {
            models.push(Pbrdf::new(distribution, Shadowing::Smith, index, 0.0).unwrap());
        }
        let internal = model(Shadowing::Smith).with_volume(FacetSide::Internal, None);
        models.push(internal.unwrap());
        let subsurface = Subsurface {
            term: crate::pbrdf::Term::Subsurface,
            rho_s: 0.3,
            d: 0.2,
            n_sub: None,
            d_c: None,
            d1: None,
        };
        let with_subsurface =
            model(Shadowing::Smith).with_volume(FacetSide::External, Some(subsurface));
        models.push(with_subsurface.unwrap());
        models
    }

    /// Random geometries (several blocks and a partial one, signed θ_r, azimuths beyond a turn,
    /// runs of repeated angles) give exactly the matrices of the one-at-a-time path.
    #[test]
    fn columns_equal_mueller_to_the_bit() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = |low: f64, high: f64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            low + (high - low) * ((state >> 11) as f64 / (1u64 << 53) as f64)
        };
        let count = 3 * BLOCK + 17;
        let mut theta_i: Vec<f64> = (0..count).map(|_| uniform(0.0, 89.9)).collect();
        let phi_i: Vec<f64> = (0..count).map(|_| uniform(-800.0, 800.0)).collect();
        let theta_r: Vec<f64> = (0..count).map(|_| uniform(-89.9, 89.9)).collect();
        let phi_r: Vec<f64> = (0..count).map(|_| uniform(-800.0, 800.0)).collect();
        theta_i[10..30].fill(45.0);
        theta_i[40] = 0.0;
        let columns = GeometryColumns {
            theta_i: &theta_i,
            phi_i: &phi_i,
            theta_r: &theta_r,
            phi_r: &phi_r,
        };
        for model in models_of_every_path() {
            let mut out = vec![f64::NAN; 16 * (count - 5)];
            model.mueller_columns(&columns, 5, &mut out).unwrap();
            let mut underflows = 0;
            for (j, got) in out.chunks_exact(16).enumerate() {
                let (incident, scattered) = columns.directions(5 + j).unwrap();
                let want = model.mueller(&incident, &scattered).transpose();
                // The same operations but for the density's logarithm (inlined in the block,
                // glibc's one at a time; each within 1 ulp): relative ~q |ln x| 1e-16 of m00,
                // up to ~1e-13 where the density nears e^−708 (q = 100 here).
                let scale = want[(0, 0)].abs();
                assert!(
                    got.iter()
                        .zip(want.iter())
                        .all(|(a, b)| (a - b).abs() <= 1e-12 * scale),
                    "{model:?} row {j}: {got:?} vs {want}"
                );
                underflows += usize::from(got[0] < 1e-300);
            }
            // The narrow lobes do reach the one-at-a-time fallback.
            if model.distribution().sigma() <= 0.05 {
                assert!(underflows > 10, "{model:?}: {underflows}");
            }
        }
    }

    /// The block's own checks refuse exactly what the direction constructors refuse, and the
    /// error is the first invalid row's.
    #[test]
    fn invalid_rows_give_the_first_rows_error() {
        let specials = [
            0.0,
            -0.0,
            10.0,
            -10.0,
            89.999,
            90.0,
            -90.0,
            -89.999,
            400.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let model = model(Shadowing::Smith);
        for &ti in &specials {
            for &pi in &specials {
                for &tr in &specials {
                    for &pr in &specials {
                        let rows = [5.0, ti, 5.0];
                        let (theta_i, phi_i) = (rows, [0.0, pi, 0.0]);
                        let (theta_r, phi_r) = ([5.0, tr, 5.0], [180.0, pr, 180.0]);
                        let columns = GeometryColumns {
                            theta_i: &theta_i,
                            phi_i: &phi_i,
                            theta_r: &theta_r,
                            phi_r: &phi_r,
                        };
                        let mut out = [0.0; 48];
                        // Compared as messages: a NaN value makes equal errors unequal.
                        let got = model
                            .mueller_columns(&columns, 0, &mut out)
                            .map_err(|e| e.to_string());
                        let want = columns.directions(1).map(|_| ()).map_err(|e| e.to_string());
                        assert_eq!(got, want, "{ti} {pi} {tr} {pr}");
                        assert_eq!(columns.folded(1).0, want.is_ok(), "{ti} {pi} {tr} {pr}");
                    }
                }
            }
        }
    }
}
