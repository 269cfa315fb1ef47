//! The environment as a band material's reflection tables see it (docs/design.md §1.9): its radiance
//! split over the material's wavelength nodes, L_m(u) = L(u) f_m(T_b(u)), with T_b(u) the
//! brightness temperature of the band radiance L(u) at sin(elevation) u and f_m the Planck
//! fractions of a grey source at T_b ([`WavelengthNodes::planck_fractions`]): the environment is
//! known only by its band radiance, so its spectrum is taken as grey at its brightness temperature.
//!
//! The reflection table of a band material is then Σ_m Σ_k K_mk L_m(u_k), one table fill per
//! wavelength node (~36), where a grey material needs one. But L_m(u) has few degrees of freedom:
//! the fractions change slowly with T_b, and T_b spans a few tens of kelvin over the sky and
//! ground. So it is written as
//!
//!   L_m(u) = f̄_m L(u) + Σ_r U_mr E_r(u),
//!
//! with f̄ the radiance-weighted mean fractions, and U_r, E_r the leading singular vectors of
//! the deviation D_m(u) = L(u) (f_m(u) − f̄_m) sampled at the ends of every cell of the sky's
//! [`SineTable`]. Enough of them are kept that the deviation left out is below
//! [`DEVIATION_TOLERANCE`] of the largest radiance at every sample; the fill then costs 1 + r grey
//! fills (r = 1–3 for the window sky and ground) with the kernels K⁰ = Σ_m f̄_m K_m and
//! K^r = Σ_m U_mr K_m. Because Σ_m D_m(u) = 0, every U_r with a non-zero singular value has
//! Σ_m U_mr = 0: a material whose pBRDF does not change with λ gets K⁰ = its grey kernel and
//! K^r = 0, hence the grey table (to rounding).

use crate::optics::{Band, WavelengthNodes};
use crate::scene::environment::SineTable;
use nalgebra::DMatrix;
use std::collections::HashMap;

/// The largest deviation L_m − (f̄_m L + Σ_r U_mr E_r) left out, relative to the environment's
/// largest radiance and per unit norm of a kernel over the nodes: a reflection table entry then
/// errs by less than this times its reflectance.
pub const DEVIATION_TOLERANCE: f64 = 1e-5;

/// One environment component beyond the mean: its shares over the wavelength nodes and its
/// radiance over u on the sky table's cells.
#[derive(Clone)]
pub struct SpectralComponent {
    pub shares: Vec<f64>,
    pub sky: SineTable,
}

/// The environment split over one material's wavelength nodes (module documentation).
#[derive(Clone)]
pub struct BandEnvironment {
    /// f̄_m, summing to 1: component 0 is the environment itself with these shares.
    pub mean_shares: Vec<f64>,
    pub components: Vec<SpectralComponent>,
}

impl BandEnvironment {
    /// Splits the environment sampled by `sky` (the grey reflection fill's sine table) over
    /// `nodes` of `band`.
    pub fn new(sky: &SineTable, band: &Band, nodes: &WavelengthNodes) -> BandEnvironment {
        BandEnvironment::with_tolerance(sky, band, nodes, DEVIATION_TOLERANCE)
    }

    /// [`BandEnvironment::new`] leaving out at most `tolerance` (relative, as
    /// [`DEVIATION_TOLERANCE`]).
    pub fn with_tolerance(
        sky: &SineTable,
        band: &Band,
        nodes: &WavelengthNodes,
        tolerance: f64,
    ) -> BandEnvironment {
        let samples = DistinctRadiances::of(sky);
        let fractions: Vec<Vec<f64>> = samples
            .radiance
            .iter()
            .map(|&l| {
                let t = band.brightness_temperature(l).unwrap_or(0.0);
                nodes.planck_fractions(t)
            })
            .collect();
        let total: f64 = samples.radiance.iter().sum();
        let mean_shares = if total > 0.0 {
            (0..nodes.len())
                .map(|m| {
                    let weighted: f64 = samples
                        .radiance
                        .iter()
                        .zip(&fractions)
                        .map(|(l, f)| l * f[m])
                        .sum();
                    weighted / total
                })
                .collect()
        } else {
            // A black environment: any shares (nothing is reflected).
            nodes.planck_fractions(300.0)
        };
        let deviation = DMatrix::from_fn(nodes.len(), samples.radiance.len(), |m, e| {
            samples.radiance[e] * (fractions[e][m] - mean_shares[m])
        });
        let largest = samples.radiance.iter().copied().fold(0.0, f64::max);
        let tolerance = tolerance * largest / (nodes.len() as f64).sqrt();
        let components = leading_components(&deviation, tolerance)
            .into_iter()
            .map(|shares| {
                let at = |value: f64| {
                    let e = samples.index_of(value);
                    (0..shares.len())
                        .map(|m| shares[m] * deviation[(m, e)])
                        .sum::<f64>()
                };
                let cells = sky
                    .cells()
                    .iter()
                    .map(|&[a, rise]| {
                        let start = at(a);
                        [start, at(a + rise) - start]
                    })
                    .collect();
                SpectralComponent {
                    shares,
                    sky: SineTable::from_cells(cells),
                }
            })
            .collect();
        BandEnvironment {
            mean_shares,
            components,
        }
    }

    /// The wavelength node with the largest mean share of the environment's radiance.
    pub fn brightest_node(&self) -> usize {
        (0..self.mean_shares.len())
            .rev()
            .max_by(|&a, &b| self.mean_shares[a].total_cmp(&self.mean_shares[b]))
            .unwrap_or(0)
    }

    /// The coefficients of a quantity Q_m given per wavelength node on each component:
    /// [Σ_m f̄_m Q_m, Σ_m U_m1 Q_m, …] (a kernel weight, ρ_d).
    pub fn project(&self, per_node: impl Fn(usize) -> f64) -> Vec<f64> {
        std::iter::once(&self.mean_shares)
            .chain(self.components.iter().map(|c| &c.shares))
            .map(|shares| {
                shares
                    .iter()
                    .enumerate()
                    .map(|(m, s)| s * per_node(m))
                    .sum()
            })
            .collect()
    }
}

/// The distinct radiances at the ends of a sine table's cells, with a lookup by value.
struct DistinctRadiances {
    radiance: Vec<f64>,
    index: HashMap<u64, usize>,
}

impl DistinctRadiances {
    fn of(sky: &SineTable) -> DistinctRadiances {
        let mut samples = DistinctRadiances {
            radiance: Vec::new(),
            index: HashMap::new(),
        };
        for &[a, rise] in sky.cells() {
            for value in [a, a + rise] {
                let next = samples.radiance.len();
                if let std::collections::hash_map::Entry::Vacant(slot) =
                    samples.index.entry(value.to_bits())
                {
                    slot.insert(next);
                    samples.radiance.push(value.max(0.0));
                }
            }
        }
        samples
    }

    fn index_of(&self, value: f64) -> usize {
        self.index[&value.to_bits()]
    }
}

/// The fewest left singular vectors of `deviation` (rows: wavelength nodes, columns: samples)
/// whose projection leaves every column within `tolerance` (Euclidean norm); every vector when
/// the decomposition fails to converge (then the split is exact, only slower).
fn leading_components(deviation: &DMatrix<f64>, tolerance: f64) -> Vec<Vec<f64>> {
    let rows = deviation.nrows();
    let worst =
        |residual: &DMatrix<f64>| residual.column_iter().map(|c| c.norm()).fold(0.0, f64::max);
    let mut residual = deviation.clone();
    if worst(&residual) <= tolerance {
        return Vec::new();
    }
    let Some(svd) = nalgebra::SVD::try_new(deviation.clone(), true, false, 1e-15, 10_000) else {
        return (0..rows)
            .map(|r| (0..rows).map(|m| if m == r { 1.0 } else { 0.0 }).collect())
            .collect();
    };
    let Some(u) = svd.u else {
        return Vec::new();
    };
    let mut kept = Vec::new();
    for r in 0..u.ncols() {
        let vector = u.column(r).into_owned();
        let coefficients = vector.transpose() * &residual;
        residual -= &vector * coefficients;
        kept.push(vector.iter().copied().collect());
        if worst(&residual) <= tolerance {
            break;
        }
    }
    kept
}
