//! The air between the camera and a surface (docs/design.md §1.5, §1.12, §2.9): over a path of
//! `range` metres the camera sees S_sensor = τ(r) S + L_path(r) δ_j0 (the path emits unpolarized
//! light). [`Atmosphere`] is that path, whichever way the scene gives it:
//!
//! - **Extinction** (`extinction_per_km`): a grey Beer–Lambert slab, τ = exp(−βr) and
//!   L_path = (1 − τ) L_bb(T_path), L_bb the band radiance of the sensor.
//! - **Table** (`table = "path.csv"`): rows of a radiative-transfer code (MODTRAN, libRadtran,
//!   LOWTRAN) read by [`table`], band-integrated or spectral. A spectral table is integrated over
//!   the sensor band at each tabulated range *before* anything is interpolated in range, because a
//!   band transmittance is not exponential in range (each wavelength decays at its own rate):
//!   τ_band(r_j) = ∫R τ(λ, r_j) B_λ(T_ref) dλ / ∫R B_λ(T_ref) dλ, the share of a blackbody at
//!   T_ref that the path lets through, with T_ref the sensor's NETD reference temperature (the
//!   air's by default: the scene's typical temperature); L_band(r_j) = ∫R L_λ(λ, r_j) dλ, the
//!   band radiance exactly as `optics::Band::radiance` defines it. Both use the wavelength nodes
//!   of band rendering ([`WavelengthNodes`], split at every table wavelength and response knot),
//!   with τ and L_λ linear in λ between the table's wavelengths, so L_band is the exact integral
//!   of that interpolant (R·L_λ is quadratic on each piece, four Gauss points integrate it).
//!
//! **Between ranges** τ is log-linear (ln τ linear in r: exact for an exponential) and the path
//! radiance linear in τ, L = L_j + (τ − τ_j)/(τ_j+1 − τ_j) (L_j+1 − L_j): exact for a homogeneous
//! stretch, where L_path = (1 − τ) B, and monotone between the rows like a linear interpolation
//! in range (it falls back to linear in range where τ does not change). Where a row has τ = 0,
//! τ is linear in range in the intervals next to it (ln 0 has no line). Below the first range the
//! table is continued to (r = 0, τ = 1, L = 0); beyond the last range τ and L are the last row's
//! (the scene warns when objects reach beyond it).

pub mod table;

use crate::optics::{Band, WavelengthNodes};
use std::sync::Arc;
pub use table::{read_table, AtmosphereTable, AtmosphereTableError, TableRows};

/// The atmospheric path of a scene: τ(r) and L_path(r) over range r (metres).
#[derive(Clone, Debug)]
pub struct Atmosphere {
    path: Path,
}

#[derive(Clone, Debug)]
enum Path {
    /// τ = exp(−β r), L_path = (1 − τ) L_bb(T).
    Extinction {
        extinction_per_m: f64,
        temperature_k: f64,
        /// L_bb(T) over the sensor band.
        blackbody: f64,
    },
    /// A radiative-transfer table, band-integrated over the sensor band.
    Table {
        table: Arc<AtmosphereTable>,
        rows: BandRows,
    },
}

/// What `summary.json` says of the atmosphere.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AtmosphereSummary {
    /// `"extinction"` or `"table"`.
    pub kind: &'static str,
    /// The table file (as the scene names it, relative to the scene's folder).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub table: Option<String>,
    /// The table's `# source:` line(s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// The table's `# geometry:` line(s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub geometry: Option<String>,
}

impl Atmosphere {
    /// The grey slab of `extinction_per_km`: β in 1/m, the path's temperature, the sensor band.
    pub fn extinction(extinction_per_m: f64, temperature_k: f64, band: &Band) -> Atmosphere {
        Atmosphere {
            path: Path::Extinction {
                extinction_per_m,
                temperature_k,
                blackbody: band.radiance(temperature_k),
            },
        }
    }

    /// A table over `band`; a spectral table is weighted by a blackbody at `reference_k` (the
    /// NETD reference) and refused when it does not cover the band.
    pub fn from_table(
        table: Arc<AtmosphereTable>,
        band: &Band,
        reference_k: f64,
    ) -> Result<Atmosphere, AtmosphereTableError> {
        let rows = table.band_rows(band, reference_k)?;
        Ok(Atmosphere {
            path: Path::Table { table, rows },
        })
    }

    /// (τ, L_path) at `range` metres.
    #[inline]
    pub fn along(&self, range: f64) -> (f64, f64) {
        match &self.path {
            Path::Extinction {
                extinction_per_m,
                blackbody,
                ..
            } => {
                let tau = (-extinction_per_m * range).exp();
                (tau, (1.0 - tau) * blackbody)
            }
            Path::Table { rows, .. } => rows.at(range),
        }
    }

    /// τ over `range` metres.
    pub fn transmittance(&self, range: f64) -> f64 {
        self.along(range).0
    }

    /// The path's own radiance (W·m⁻²·sr⁻¹, band-integrated) over `range` metres.
    pub fn path_radiance(&self, range: f64) -> f64 {
        self.along(range).1
    }

    /// The path at another path temperature (a thermal run's air at an instant): an extinction
    /// path re-evaluated; a table keeps its own radiances.
    pub fn with_path_temperature(&self, temperature_k: f64, band: &Band) -> Atmosphere {
        match &self.path {
            Path::Extinction {
                extinction_per_m, ..
            } => Atmosphere::extinction(*extinction_per_m, temperature_k, band),
            Path::Table { .. } => self.clone(),
        }
    }

    /// The path with a spectral table weighted at another reference temperature (the NETD
    /// reference of a thermal run's instant); other paths are unchanged.
    pub fn with_reference_temperature(&self, reference_k: f64, band: &Band) -> Atmosphere {
        match &self.path {
            Path::Table { table, .. } if matches!(table.rows, TableRows::Spectral(_)) => {
                // The band was covered at load; the same band is covered now.
                Atmosphere::from_table(table.clone(), band, reference_k)
                    .unwrap_or_else(|_| self.clone())
            }
            _ => self.clone(),
        }
    }

    /// The path's temperature of an extinction path.
    pub fn temperature_k(&self) -> Option<f64> {
        match &self.path {
            Path::Extinction { temperature_k, .. } => Some(*temperature_k),
            Path::Table { .. } => None,
        }
    }

    /// The longest range of a table (m): beyond it the last row holds.
    pub fn last_range_m(&self) -> Option<f64> {
        match &self.path {
            Path::Extinction { .. } => None,
            Path::Table { rows, .. } => rows.ranges_m.last().copied(),
        }
    }

    /// The table file, if the path is a table.
    pub fn table_file(&self) -> Option<&std::path::Path> {
        match &self.path {
            Path::Extinction { .. } => None,
            Path::Table { table, .. } => Some(&table.file),
        }
    }

    /// What `summary.json` reports.
    pub fn summary(&self) -> AtmosphereSummary {
        match &self.path {
            Path::Extinction { .. } => AtmosphereSummary {
                kind: "extinction",
                table: None,
                source: None,
                geometry: None,
            },
            Path::Table { table, .. } => AtmosphereSummary {
                kind: "table",
                table: Some(table.file.display().to_string()),
                source: table.source.clone(),
                geometry: table.geometry.clone(),
            },
        }
    }
}

/// A path band-integrated at each range (ascending, the first 0), ready to interpolate.
#[derive(Clone, Debug, PartialEq)]
pub struct BandRows {
    ranges_m: Vec<f64>,
    transmittance: Vec<f64>,
    path_radiance: Vec<f64>,
}

impl BandRows {
    /// Rows at strictly ascending ranges ≥ 0 (checked by the reader); a first range above 0 gets
    /// the row (0, τ = 1, L = 0) before it.
    pub fn new(ranges_m: Vec<f64>, transmittance: Vec<f64>, path_radiance: Vec<f64>) -> BandRows {
        let mut rows = BandRows {
            ranges_m: Vec::with_capacity(ranges_m.len() + 1),
            transmittance: Vec::with_capacity(ranges_m.len() + 1),
            path_radiance: Vec::with_capacity(ranges_m.len() + 1),
        };
        if ranges_m.first().is_some_and(|&r| r > 0.0) {
            rows.ranges_m.push(0.0);
            rows.transmittance.push(1.0);
            rows.path_radiance.push(0.0);
        }
        rows.ranges_m.extend(ranges_m);
        rows.transmittance.extend(transmittance);
        rows.path_radiance.extend(path_radiance);
        rows
    }

    /// The tabulated ranges (m), with the added row at 0 if any.
    pub fn ranges_m(&self) -> &[f64] {
        &self.ranges_m
    }

    /// τ at each tabulated range.
    pub fn transmittance(&self) -> &[f64] {
        &self.transmittance
    }

    /// L_path at each tabulated range (W·m⁻²·sr⁻¹).
    pub fn path_radiance(&self) -> &[f64] {
        &self.path_radiance
    }

    /// (τ, L_path) at `range` (module documentation: log-linear τ, L linear in τ, clamped).
    pub fn at(&self, range: f64) -> (f64, f64) {
        let last = self.ranges_m.len() - 1;
        let upper = self.ranges_m.partition_point(|&r| r <= range);
        if upper > last {
            return (self.transmittance[last], self.path_radiance[last]);
        }
        if upper == 0 {
            return (self.transmittance[0], self.path_radiance[0]);
        }
        let i = upper - 1;
        let t = (range - self.ranges_m[i]) / (self.ranges_m[i + 1] - self.ranges_m[i]);
        let (tau_a, tau_b) = (self.transmittance[i], self.transmittance[i + 1]);
        let ratio = tau_b / tau_a;
        let (tau, share) = if tau_a > 0.0 && tau_b > 0.0 && !(1e-300..1e300).contains(&ratio) {
            // A subnormal or tiny τ next to a large one: the ratio (or e^d) leaves f64.
            log_linear_wide(tau_a, tau_b, t)
        } else if tau_a > 0.0 && tau_b > 0.0 {
            let d = ratio.ln();
            // (τ − τ_a)/(τ_b − τ_a) = (e^(t d) − 1)/(e^d − 1), without the cancellation of
            // the difference where τ hardly changes; t where it does not change at all.
            let share = if d == 0.0 {
                t
            } else {
                (t * d).exp_m1() / d.exp_m1()
            };
            (tau_a * (t * d).exp(), share)
        } else {
            (tau_a + t * (tau_b - tau_a), t)
        };
        let (l_a, l_b) = (self.path_radiance[i], self.path_radiance[i + 1]);
        (tau, l_a + share * (l_b - l_a))
    }
}

/// τ log-linear between `tau_a` and `tau_b` (both > 0) at fraction `t`, and the share
/// (τ − τ_a)/(τ_b − τ_a), for pairs whose ratio leaves f64's range (τ = 1e-310 beside 0.5
/// made e^d infinite and the pixels NaN): the logarithms taken apart, and for a rising τ the
/// share's exponentials divided by e^d first.
fn log_linear_wide(tau_a: f64, tau_b: f64, t: f64) -> (f64, f64) {
    let (ln_a, ln_b) = (tau_a.ln(), tau_b.ln());
    let d = ln_b - ln_a;
    let tau = (ln_a + t * d).exp();
    let share = if d < 0.0 {
        (t * d).exp_m1() / d.exp_m1()
    } else {
        (((t - 1.0) * d).exp() - (-d).exp()) / -(-d).exp_m1()
    };
    (tau, share.clamp(0.0, 1.0))
}

/// Band rows of a spectral table: at each range, τ weighted by R(λ) B_λ(`reference_k`) and L_λ
/// integrated with R(λ), τ and L_λ linear in λ between the table's wavelengths `wavelengths_um`
/// (ascending); `transmittance[w][j]`, `radiance_per_um[w][j]` at wavelength w and range j.
pub fn integrate_spectral(
    band: &Band,
    reference_k: f64,
    wavelengths_um: &[f64],
    ranges_m: &[f64],
    transmittance: &[Vec<f64>],
    radiance_per_um: &[Vec<f64>],
) -> Result<BandRows, crate::optics::TableMissesBand> {
    let nodes = WavelengthNodes::for_table(band, wavelengths_um)?;
    let fractions = nodes.planck_fractions(reference_k);
    let mut tau = vec![0.0; ranges_m.len()];
    let mut radiance = vec![0.0; ranges_m.len()];
    for ((&lambda, &weight_m), &fraction) in nodes
        .wavelengths_um()
        .iter()
        .zip(nodes.weights_m())
        .zip(&fractions)
    {
        // The table's interval holding the node (the nodes lie inside the table).
        let upper = wavelengths_um
            .partition_point(|&w| w <= lambda)
            .clamp(1, wavelengths_um.len() - 1);
        let (a, b) = (upper - 1, upper);
        let t = (lambda - wavelengths_um[a]) / (wavelengths_um[b] - wavelengths_um[a]);
        for j in 0..ranges_m.len() {
            let tau_j = transmittance[a][j] + t * (transmittance[b][j] - transmittance[a][j]);
            let l_j = radiance_per_um[a][j] + t * (radiance_per_um[b][j] - radiance_per_um[a][j]);
            tau[j] += fraction * tau_j;
            // L_λ per µm, weights in metres: 1e6 µm per m.
            radiance[j] += weight_m * l_j * 1e6;
        }
    }
    // Rounding may carry a weighted mean of values in [0, 1] a hair outside.
    let tau = tau.into_iter().map(|v| v.clamp(0.0, 1.0)).collect();
    Ok(BandRows::new(ranges_m.to_vec(), tau, radiance))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(ranges: &[f64], tau: &[f64], l: &[f64]) -> BandRows {
        BandRows::new(ranges.to_vec(), tau.to_vec(), l.to_vec())
    }

    #[test]
    fn an_exponential_table_is_reproduced_between_its_rows() {
        let (beta, blackbody): (f64, f64) = (2e-3, 7.5);
        let ranges = [100.0, 400.0, 1000.0];
        let tau: Vec<f64> = ranges.iter().map(|r| (-beta * r).exp()).collect();
        let l: Vec<f64> = tau.iter().map(|t| (1.0 - t) * blackbody).collect();
        let table = rows(&ranges, &tau, &l);
        assert_eq!(table.ranges_m()[0], 0.0);
        for r in [0.0, 1.0, 50.0, 100.0, 250.0, 999.0] {
            let (t, p) = table.at(r);
            let expected = (-beta * r).exp();
            assert!((t - expected).abs() < 1e-15, "{r}: {t} vs {expected}");
            assert!((p - (1.0 - expected) * blackbody).abs() < 1e-13, "{r}: {p}");
        }
        // Beyond the last row: the last row.
        assert_eq!(table.at(5000.0), (tau[2], l[2]));
    }

    #[test]
    fn zero_transmittance_rows_interpolate_without_nan() {
        let table = rows(&[0.0, 10.0, 20.0], &[1.0, 0.0, 0.0], &[0.0, 5.0, 5.0]);
        let (t, p) = table.at(5.0);
        assert_eq!((t, p), (0.5, 2.5));
        assert_eq!(table.at(15.0), (0.0, 5.0));
        assert_eq!(table.at(10.0), (0.0, 5.0));
    }

    /// Subnormal and tiny transmittances beside ordinary ones (issue 42: 1e-310 made NaN
    /// pixels): finite, within the rows' bounds, the endpoints reproduced.
    #[test]
    fn subnormal_transmittances_interpolate_finitely() {
        for tiny in [1e-310, 5e-324, 1e-300, 1e-200] {
            let table = rows(&[0.0, 10.0, 20.0], &[1.0, tiny, 0.5], &[0.0, 5.0, 2.0]);
            for k in 0..=40 {
                let r = k as f64 * 0.5;
                let (t, p) = table.at(r);
                assert!(t.is_finite() && p.is_finite(), "{tiny} at {r}: {t}, {p}");
                assert!((0.0..=1.0).contains(&t), "{tiny} at {r}: τ {t}");
                assert!((0.0..=5.0).contains(&p), "{tiny} at {r}: L {p}");
            }
            assert_eq!(table.at(20.0), (0.5, 2.0));
            let (t, p) = table.at(10.0);
            assert!(
                (t - tiny).abs() <= tiny * 1e-9 + 1e-321 && (p - 5.0).abs() < 1e-12,
                "{t} {p}"
            );
            // Log-linear: halfway between τ and 0.5 lies √(0.5 τ).
            let (t, _) = table.at(15.0);
            let expected = 0.5f64.sqrt() * tiny.sqrt();
            assert!(
                (t - expected).abs() <= expected * 1e-9,
                "{tiny}: {t} vs {expected}"
            );
        }
    }

    #[test]
    fn constant_transmittance_keeps_the_radiance_linear_in_range() {
        let table = rows(&[0.0, 10.0], &[0.5, 0.5], &[1.0, 3.0]);
        assert_eq!(table.at(5.0), (0.5, 2.0));
        // A hair of change: no cancellation, the share stays ≈ t.
        let table = rows(&[0.0, 10.0], &[0.5, 0.5 * (1.0 + 1e-15)], &[1.0, 3.0]);
        assert!((table.at(5.0).1 - 2.0).abs() < 1e-12);
    }
}
