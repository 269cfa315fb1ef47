//! Wavelength nodes for band rendering (docs/design.md §1.9): the sensor signal of a material whose n, k
//! and ρ_d are tables over wavelength is S_j = ∫ R(λ) [reflected + ε_j(λ) B_λ(T)] dλ, and this
//! module chooses the λ_m and weights w_m of Σ_m w_m (…)(λ_m) that stand for the integral.
//!
//! **The choice.** The band is split at every table wavelength inside it (n, k, ρ_d are linear
//! between table nodes, so the pBRDF is smooth on each piece and has a kink at each node), at every
//! knot of the sensor's response table (R is piecewise linear) and into pieces at most
//! [`MAX_PIECE_UM`] wide (the Planck curvature across a coarse table); each piece gets
//! [`POINTS_PER_PIECE`] Gauss–Legendre nodes, w_m = R(λ_m) × (its Gauss weight × half the piece
//! width, in metres). Measured on the shipped silicate glass (nine nodes 8–14 µm across its
//! reststrahlen band, Cauchy σ = 0.06, q = 2.8, Smith), band emissivity at θ = 0…89° and
//! T = 250–350 K against 2000 nodes: 3 points per piece err by ≤ 1.6e-6 (relative to ε_0), 4 by
//! ≤ 3.3e-8, 2 by 8e-5, 1 by 4.5e-3; narrower pieces change nothing there (the table's own pieces
//! are ≤ 1.5 µm). Four points keep a 300-fold margin on the 1e-5 the renderer promises.
//!
//! **Planck fractions.** A grey source (a blackbody's spectrum scaled to a band radiance, docs/design.md
//! §1.9's stand-in for an environment known only by its band radiance) at brightness temperature
//! T puts the fraction f_m(T) = w_m B_λm(T) / Σ_m' w_m' B_λm'(T) of its band radiance at node m;
//! Σ_m f_m = 1 to rounding, so a material whose pBRDF does not change with λ is band-integrated
//! to its grey value. [`WavelengthNodes::planck_fractions`] evaluates them in the log domain
//! (finite down to a few kelvin, where B_λ underflows) and takes the limits at T → 0 (all at the
//! longest wavelength) and T → ∞ (Rayleigh–Jeans, ∝ w_m λ_m⁻⁴).

use super::planck::{ln_spectral_radiance, Band};
use crate::text::number;
use gauss_quad::legendre::GaussLegendre;
use std::num::NonZeroUsize;

/// Gauss–Legendre nodes on each piece of the band (see the module documentation for why four).
pub const POINTS_PER_PIECE: usize = 4;
/// The widest piece (µm): a two-row table 8–14 µm is still integrated on 1 µm pieces.
pub const MAX_PIECE_UM: f64 = 1.0;
/// Piece breaks closer than this (µm) are one (the tables' own resolution, docs/design.md §1.9).
const SAME_BREAK_UM: f64 = 1e-6;
/// Below this temperature (K) the fractions are those of the limit T → 0.
const COLDEST_K: f64 = 1e-3;

/// A material's wavelength table does not reach over the whole sensor band.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error(
    "its table covers {}–{} µm, not the whole sensor band {}–{} µm (band rendering needs n, k over the band)",
    number(.table_um.0), number(.table_um.1), number(.band_um.0), number(.band_um.1)
)]
pub struct TableMissesBand {
    pub table_um: (f64, f64),
    pub band_um: (f64, f64),
}

/// The wavelength nodes λ_m (µm) and weights w_m (R(λ) dλ in metres) of one material's table over
/// one band, in ascending wavelength.
#[derive(Clone, Debug, PartialEq)]
pub struct WavelengthNodes {
    wavelength_um: Vec<f64>,
    weight_m: Vec<f64>,
}

impl WavelengthNodes {
    /// The nodes for a table with ascending wavelengths `table_um` over `band`; refused when the
    /// table does not span the band's limits.
    pub fn for_table(band: &Band, table_um: &[f64]) -> Result<WavelengthNodes, TableMissesBand> {
        WavelengthNodes::for_tables(band, &[table_um])
    }

    /// The nodes shared by several tables (a scene's spectral materials): the band is split at
    /// every wavelength of every table (breaks closer than 1e-6 µm are one), so each material is
    /// smooth on each piece and the materials can exchange light node by node. Refused when a
    /// table does not span the band (the first such).
    pub fn for_tables(
        band: &Band,
        tables_um: &[&[f64]],
    ) -> Result<WavelengthNodes, TableMissesBand> {
        let (lo, hi) = band.limits_um();
        for table_um in tables_um {
            let (first, last) = match table_um {
                [first, .., last] => (*first, *last),
                [only] => (*only, *only),
                [] => (f64::NAN, f64::NAN),
            };
            if !(first <= lo && last >= hi) {
                return Err(TableMissesBand {
                    table_um: (first, last),
                    band_um: (lo, hi),
                });
            }
        }
        let mut breaks = vec![lo, hi];
        for table_um in tables_um {
            breaks.extend(table_um.iter().copied().filter(|&w| w > lo && w < hi));
        }
        breaks.extend(band.response_knots_um());
        breaks.sort_by(f64::total_cmp);
        breaks.dedup_by(|a, b| *a - *b < SAME_BREAK_UM);
        Ok(WavelengthNodes::on_pieces(band, &breaks))
    }

    /// [`POINTS_PER_PIECE`] Gauss–Legendre nodes on each piece between `breaks` (ascending),
    /// pieces wider than [`MAX_PIECE_UM`] split evenly.
    fn on_pieces(band: &Band, breaks: &[f64]) -> WavelengthNodes {
        let rule = GaussLegendre::new(NonZeroUsize::new(POINTS_PER_PIECE).expect("non-zero"));
        let mut nodes = WavelengthNodes {
            wavelength_um: Vec::new(),
            weight_m: Vec::new(),
        };
        for pair in breaks.windows(2) {
            let pieces = ((pair[1] - pair[0]) / MAX_PIECE_UM).ceil().max(1.0) as usize;
            let width = (pair[1] - pair[0]) / pieces as f64;
            for piece in 0..pieces {
                let start = pair[0] + piece as f64 * width;
                for &(x, w) in rule.as_node_weight_pairs() {
                    let lambda = start + 0.5 * width * (x + 1.0);
                    nodes.wavelength_um.push(lambda);
                    nodes
                        .weight_m
                        .push(band.response_at(lambda) * 0.5 * width * 1e-6 * w);
                }
            }
        }
        nodes
    }

    pub fn len(&self) -> usize {
        self.wavelength_um.len()
    }

    pub fn is_empty(&self) -> bool {
        self.wavelength_um.is_empty()
    }

    /// The node wavelengths, µm, ascending.
    pub fn wavelengths_um(&self) -> &[f64] {
        &self.wavelength_um
    }

    /// The weights R(λ_m) × dλ (m).
    pub fn weights_m(&self) -> &[f64] {
        &self.weight_m
    }

    /// f_m(T) = w_m B_λm(T) / Σ w B (module documentation): the share of a grey source's band
    /// radiance at each node. T = ∞ gives the Rayleigh–Jeans shares, T ≤ 1 mK those of T → 0.
    pub fn planck_fractions(&self, temperature_k: f64) -> Vec<f64> {
        let logs: Vec<f64> = if temperature_k.is_infinite() {
            // B_λ → 2ckT/λ⁴: the T factor cancels in the ratio.
            self.nodes()
                .map(|(lambda_um, w)| w.ln() - 4.0 * lambda_um.ln())
                .collect()
        } else {
            let t = temperature_k.max(COLDEST_K);
            self.nodes()
                .map(|(lambda_um, w)| w.ln() + ln_spectral_radiance(lambda_um * 1e-6, t))
                .collect()
        };
        // Shares by the log-sum-exp: exact ratios where every B_λ underflows.
        let largest = logs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let shares: Vec<f64> = logs.iter().map(|l| (l - largest).exp()).collect();
        let total: f64 = shares.iter().sum();
        shares.iter().map(|s| s / total).collect()
    }

    fn nodes(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.wavelength_um
            .iter()
            .copied()
            .zip(self.weight_m.iter().copied())
    }
}

/// Weights over a material's wavelength nodes, e.g. the Planck fractions of a source, possibly
/// interpolated between two tabulated rows: `weight(m) = (1 − t) lower[m] + t upper[m]`.
#[derive(Clone, Copy, Debug)]
pub struct SpectralMix<'a> {
    lower: &'a [f64],
    upper: &'a [f64],
    t: f64,
}

impl<'a> SpectralMix<'a> {
    /// Fixed weights (one row).
    pub fn fixed(weights: &'a [f64]) -> SpectralMix<'a> {
        SpectralMix {
            lower: weights,
            upper: weights,
            t: 0.0,
        }
    }

    /// The weight of node m.
    #[inline]
    pub fn weight(&self, m: usize) -> f64 {
        let lower = self.lower[m];
        lower + self.t * (self.upper[m] - lower)
    }

    pub fn len(&self) -> usize {
        self.lower.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lower.is_empty()
    }
}

/// Brightness temperatures of band radiance on a grid uniform in v = L/(L + L_ref) ∈ [0, 1]
/// (L_ref the band radiance at 300 K): every radiance from 0 to ∞ (a sun glint) has a cell, and
/// 300 K sits at v = ½ with ~0.6 K per cell. Built once per band (one Newton solve per node) and
/// shared by every material's [`FractionsByRadiance`].
#[derive(Clone, Debug)]
pub struct BrightnessGrid {
    reference: f64,
    temperatures: Vec<f64>,
}

/// Cells of [`BrightnessGrid`] over v ∈ [0, 1].
const BRIGHTNESS_CELLS: usize = 512;

impl BrightnessGrid {
    pub fn new(band: &Band) -> BrightnessGrid {
        let reference = band.radiance(300.0);
        let temperatures = (0..=BRIGHTNESS_CELLS)
            .map(|i| {
                let v = i as f64 / BRIGHTNESS_CELLS as f64;
                if i == BRIGHTNESS_CELLS {
                    return f64::INFINITY;
                }
                band.brightness_temperature(reference * v / (1.0 - v))
                    .unwrap_or(0.0)
            })
            .collect();
        BrightnessGrid {
            reference,
            temperatures,
        }
    }

    /// Cell index and fraction of radiance `radiance` (negative values read as 0).
    #[inline]
    fn locate(&self, radiance: f64) -> (usize, f64) {
        let l = radiance.max(0.0);
        let x = l / (l + self.reference) * BRIGHTNESS_CELLS as f64;
        let i = (x as usize).min(BRIGHTNESS_CELLS - 1);
        (i, (x - i as f64).min(1.0))
    }
}

/// The Planck fractions of a grey source as a function of its band radiance, for the Monte Carlo
/// parts (docs/design.md §1.7, §1.9): the rows f(T_b) at the nodes of a [`BrightnessGrid`], interpolated
/// linearly (so the weights still sum to 1).
#[derive(Clone, Debug)]
pub struct FractionsByRadiance {
    grid: BrightnessGrid,
    /// Row i holds f_m(T_i), m = 0..nodes.
    rows: Vec<f64>,
    nodes: usize,
}

impl FractionsByRadiance {
    pub fn new(nodes: &WavelengthNodes, grid: &BrightnessGrid) -> FractionsByRadiance {
        let rows = grid
            .temperatures
            .iter()
            .flat_map(|&t| nodes.planck_fractions(t))
            .collect();
        FractionsByRadiance {
            grid: grid.clone(),
            rows,
            nodes: nodes.len(),
        }
    }

    /// The fractions of a grey source of band radiance `radiance`.
    #[inline]
    pub fn at(&self, radiance: f64) -> SpectralMix<'_> {
        let (i, t) = self.grid.locate(radiance);
        let m = self.nodes;
        SpectralMix {
            lower: &self.rows[i * m..(i + 1) * m],
            upper: &self.rows[(i + 1) * m..(i + 2) * m],
            t,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SILICATE_UM: [f64; 9] = [8.0, 8.5, 9.0, 9.5, 10.0, 10.6, 11.5, 12.5, 14.0];

    #[test]
    fn nodes_integrate_the_band_radiance() {
        // Σ w_m B_λm(T) is the band radiance: Planck's law is smooth on every piece.
        for (band, table) in [
            (Band::lwir(), SILICATE_UM.to_vec()),
            (Band::lwir(), vec![7.0, 15.0]),
            (
                Band::new(8.0, 14.0, Some(vec![(8.0, 0.2), (10.3, 1.0), (14.0, 0.5)])).unwrap(),
                vec![8.0, 14.0],
            ),
        ] {
            let nodes = WavelengthNodes::for_table(&band, &table).unwrap();
            for t in [200.0, 300.0, 5772.0] {
                let sum: f64 = nodes
                    .nodes()
                    .map(|(l, w)| w * super::super::spectral_radiance(l * 1e-6, t))
                    .sum();
                let exact = band.radiance(t);
                assert!(
                    (sum / exact - 1.0).abs() < 1e-9,
                    "{table:?} {t}: {sum} {exact}"
                );
            }
        }
    }

    #[test]
    fn pieces_break_at_table_nodes() {
        let nodes = WavelengthNodes::for_table(&Band::lwir(), &SILICATE_UM).unwrap();
        // Eight pieces (the last, 12.5–14 µm, in two): nine times four nodes.
        assert_eq!(nodes.len(), 9 * POINTS_PER_PIECE);
        let w = nodes.wavelengths_um();
        assert!(w.windows(2).all(|p| p[0] < p[1]) && w[0] > 8.0 && w[w.len() - 1] < 14.0);
        for &node in &SILICATE_UM[1..8] {
            let below = w.iter().filter(|&&x| x < node).count();
            assert_eq!(below % POINTS_PER_PIECE, 0, "a piece straddles {node}");
        }
    }

    #[test]
    fn a_table_short_of_the_band_is_refused() {
        let err = WavelengthNodes::for_table(&Band::new(7.5, 14.0, None).unwrap(), &SILICATE_UM)
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "its table covers 8–14 µm, not the whole sensor band 7.5–14 µm (band rendering needs \
             n, k over the band)"
        );
    }

    #[test]
    fn fractions_sum_to_one_and_have_their_limits() {
        let nodes = WavelengthNodes::for_table(&Band::lwir(), &SILICATE_UM).unwrap();
        for t in [0.0, 0.5, 20.0, 300.0, 5772.0, f64::INFINITY] {
            let f = nodes.planck_fractions(t);
            let sum: f64 = f.iter().sum();
            assert!((sum - 1.0).abs() < 1e-15, "{t}: {sum}");
            assert!(f.iter().all(|x| x.is_finite() && *x >= 0.0));
        }
        let cold = nodes.planck_fractions(0.0);
        // Wien: the colder, the redder; at T → 0 all at the longest wavelength.
        assert!((cold[cold.len() - 1] - 1.0).abs() < 1e-12, "{cold:?}");
        // At 300 K the direct ratio agrees.
        let f = nodes.planck_fractions(300.0);
        let direct: Vec<f64> = nodes
            .nodes()
            .map(|(l, w)| w * super::super::spectral_radiance(l * 1e-6, 300.0))
            .collect();
        let total: f64 = direct.iter().sum();
        for (a, b) in f.iter().zip(&direct) {
            assert!((a - b / total).abs() < 1e-15);
        }
        // Rayleigh–Jeans is the limit of hot sources.
        let hot = nodes.planck_fractions(1e9);
        let limit = nodes.planck_fractions(f64::INFINITY);
        assert!(hot
            .iter()
            .zip(&limit)
            .all(|(a, b)| (a - b).abs() < 1e-5 * b));
    }

    #[test]
    fn fractions_by_radiance_follow_the_brightness_temperature() {
        let band = Band::lwir();
        let nodes = WavelengthNodes::for_table(&band, &SILICATE_UM).unwrap();
        let table = FractionsByRadiance::new(&nodes, &BrightnessGrid::new(&band));
        for t in [230.0, 271.3, 300.0, 333.3, 400.0] {
            let mix = table.at(band.radiance(t));
            let exact = nodes.planck_fractions(t);
            let sum: f64 = (0..nodes.len()).map(|m| mix.weight(m)).sum();
            assert!((sum - 1.0).abs() < 1e-14);
            for (m, e) in exact.iter().enumerate() {
                assert!((mix.weight(m) - e).abs() < 2e-5 * e, "{t} K node {m}");
            }
        }
    }
}
