//! Planck band radiance over a sensor band with an optional spectral response, and its inverse
//! (apparent / brightness temperature). CODATA 2018 exact constants (docs/design.md §1.5).

use crate::text::number;
use gauss_quad::legendre::GaussLegendre;
use std::num::NonZeroUsize;

const PLANCK_H: f64 = 6.626_070_15e-34; // J s
const SPEED_OF_LIGHT: f64 = 299_792_458.0; // m/s
const BOLTZMANN_K: f64 = 1.380_649e-23; // J/K
/// First radiation constant for radiance, 2hc² (W m²/sr).
const C1L: f64 = 2.0 * PLANCK_H * SPEED_OF_LIGHT * SPEED_OF_LIGHT;
/// Second radiation constant hc/k (m K).
const C2: f64 = PLANCK_H * SPEED_OF_LIGHT / BOLTZMANN_K;

/// Gauss–Legendre points per panel and the widest panel (µm). Planck's law is analytic over the
/// band, so 8 points on ≤ 0.5 µm panels are exact to ~1e-15 relative; panels also break at every
/// response-table knot, where the piecewise-linear response has a kink.
const POINTS_PER_PANEL: usize = 8;
const MAX_PANEL_UM: f64 = 0.5;

/// Shortest wavelength irpol accepts anywhere (sensor bands, materials, measurements): the near
/// ultraviolet, far below any thermal-infrared use.
pub const MIN_WAVELENGTH_UM: f64 = 0.1;
/// Longest wavelength accepted: the far infrared's end. It also bounds a band's quadrature to
/// 2000 panels (an 8 µm–1 km band asked for 2·10⁹).
pub const MAX_WAVELENGTH_UM: f64 = 1000.0;

/// The hottest temperature a scene or a weather file may give (K): far above any thermal scene,
/// and low enough that band radiances and their statistics stay finite (1e308 K overflowed them
/// to NaN).
pub const MAX_TEMPERATURE_K: f64 = 1e4;

/// Stefan–Boltzmann constant σ (W m⁻² K⁻⁴), CODATA 2018: the thermal model's emission and the
/// weather's long-wave sky formulas share it.
pub const STEFAN_BOLTZMANN: f64 = 5.670_374_419e-8;

/// Whether `t` is a temperature a scene may hold: finite, in [0, [`MAX_TEMPERATURE_K`]].
pub fn valid_temperature(t: f64) -> bool {
    t.is_finite() && (0.0..=MAX_TEMPERATURE_K).contains(&t)
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum OpticsError {
    #[error("sensor band {}–{} µm is invalid: need 0.1 ≤ lower < upper ≤ 1000 µm", number(*.lo_um), number(*.hi_um))]
    InvalidBand { lo_um: f64, hi_um: f64 },
    #[error("spectral response table is invalid: {0}")]
    InvalidResponse(String),
    #[error(
        "radiance {} W·m⁻²·sr⁻¹ has no temperature: it must be finite and ≥ 0",
        crate::text::number(*.0)
    )]
    InvalidRadiance(f64),
}

/// A sensor band: wavelength limits and a spectral response R(λ) (piecewise linear between table
/// knots, 0 outside the table; R ≡ 1 when no table is given). Radiance is ∫ R(λ) B_λ(T) dλ.
#[derive(Clone, Debug)]
pub struct Band {
    lo_um: f64,
    hi_um: f64,
    /// Quadrature nodes (wavelength in m) and weights (dλ in m, times R(λ)).
    nodes: Vec<(f64, f64)>,
    /// The response table (µm, R), `None` for R ≡ 1.
    response: Option<Vec<(f64, f64)>>,
}

impl Band {
    /// The default LWIR band, 8–14 µm with a flat response.
    pub fn lwir() -> Band {
        Band::new(8.0, 14.0, None).expect("8–14 µm is a valid band")
    }

    /// A band [lo_um, hi_um] with an optional response table of (wavelength µm, response ≥ 0),
    /// wavelengths strictly increasing.
    pub fn new(
        lo_um: f64,
        hi_um: f64,
        response: Option<Vec<(f64, f64)>>,
    ) -> Result<Band, OpticsError> {
        let inside =
            |um: f64| um.is_finite() && (MIN_WAVELENGTH_UM..=MAX_WAVELENGTH_UM).contains(&um);
        if !(inside(lo_um) && inside(hi_um) && lo_um < hi_um) {
            return Err(OpticsError::InvalidBand { lo_um, hi_um });
        }
        if let Some(table) = &response {
            validate_response(table)?;
        }
        let mut knots = vec![lo_um, hi_um];
        if let Some(table) = &response {
            knots.extend(
                table
                    .iter()
                    .map(|&(w, _)| w)
                    .filter(|&w| w > lo_um && w < hi_um),
            );
        }
        knots.sort_by(f64::total_cmp);
        let rule = GaussLegendre::new(NonZeroUsize::new(POINTS_PER_PANEL).expect("non-zero"));
        let mut nodes = Vec::new();
        for window in knots.windows(2) {
            let (a, b) = (window[0], window[1]);
            let panels = ((b - a) / MAX_PANEL_UM).ceil().max(1.0) as usize;
            let width = (b - a) / panels as f64;
            for panel in 0..panels {
                let start = a + panel as f64 * width;
                for &(x, w) in rule.as_node_weight_pairs() {
                    let lambda_um = start + 0.5 * width * (x + 1.0);
                    let r = response
                        .as_ref()
                        .map_or(1.0, |t| interpolate_response(t, lambda_um));
                    nodes.push((lambda_um * 1e-6, 0.5 * width * 1e-6 * w * r));
                }
            }
        }
        if nodes.iter().all(|&(_, w)| w == 0.0) {
            return Err(OpticsError::InvalidResponse(format!(
                "the response is zero everywhere in {}–{} µm",
                number(lo_um),
                number(hi_um)
            )));
        }
        Ok(Band {
            lo_um,
            hi_um,
            nodes,
            response,
        })
    }

    pub fn limits_um(&self) -> (f64, f64) {
        (self.lo_um, self.hi_um)
    }

    /// The spectral response R(λ) at `wavelength_um`: 1 without a table, else linear between
    /// its rows and 0 outside them (and outside the band).
    pub fn response_at(&self, wavelength_um: f64) -> f64 {
        if !(self.lo_um..=self.hi_um).contains(&wavelength_um) {
            return 0.0;
        }
        self.response
            .as_ref()
            .map_or(1.0, |table| interpolate_response(table, wavelength_um))
    }

    /// Where R(λ) has a kink inside the band (its table's rows, µm, ascending): a quadrature
    /// over the band must break its panels there.
    pub fn response_knots_um(&self) -> Vec<f64> {
        self.response.as_ref().map_or(Vec::new(), |table| {
            table
                .iter()
                .map(|&(w, _)| w)
                .filter(|&w| w > self.lo_um && w < self.hi_um)
                .collect()
        })
    }

    /// Band radiance L_bb(T) = ∫ R(λ) 2hc²/λ⁵ / (exp(hc/(λkT)) − 1) dλ in W·m⁻²·sr⁻¹; 0 at T ≤ 0.
    pub fn radiance(&self, temperature_k: f64) -> f64 {
        if temperature_k <= 0.0 {
            return 0.0;
        }
        self.nodes
            .iter()
            .map(|&(lambda, weight)| weight * spectral_radiance(lambda, temperature_k))
            .sum()
    }

    /// dL_bb/dT in W·m⁻²·sr⁻¹·K⁻¹ (for NETD → radiance noise and Newton's method).
    pub fn radiance_derivative(&self, temperature_k: f64) -> f64 {
        if temperature_k <= 0.0 {
            return 0.0;
        }
        self.nodes
            .iter()
            .map(|&(lambda, weight)| {
                let x = C2 / (lambda * temperature_k);
                // d/dT [C1L λ⁻⁵ / (eˣ − 1)] = B_λ · x eˣ / ((eˣ − 1) T) = B_λ x / ((1 − e⁻ˣ) T):
                // the second form stays finite where eˣ overflows (B_λ → 0 at a few kelvin).
                weight * spectral_radiance(lambda, temperature_k) * x
                    / ((1.0 - (-x).exp()) * temperature_k)
            })
            .sum()
    }

    /// Brightness (apparent) temperature: the T with L_bb(T) = radiance. Safeguarded Newton on a
    /// bracket, converged to 1e-13 relative.
    pub fn brightness_temperature(&self, radiance: f64) -> Result<f64, OpticsError> {
        if !radiance.is_finite() || radiance < 0.0 {
            return Err(OpticsError::InvalidRadiance(radiance));
        }
        if radiance == 0.0 {
            return Ok(0.0);
        }
        let (mut lo, mut hi) = (1.0f64, 300.0f64);
        let mut radiance_lo = self.radiance(lo);
        while radiance_lo > radiance {
            lo *= 0.5;
            if lo < 1e-3 {
                return Ok(lo);
            }
            radiance_lo = self.radiance(lo);
        }
        let mut radiance_hi = self.radiance(hi);
        while radiance_hi < radiance {
            hi *= 2.0;
            if hi > 1e7 {
                return Err(OpticsError::InvalidRadiance(radiance));
            }
            radiance_hi = self.radiance(hi);
        }
        // ln L is close to linear in 1/T (Wien: L ∝ e^(−c/T) in a narrow band), so the start is
        // the secant of ln L against 1/T through the bracket's ends, and Newton runs on ln L as a
        // function of 1/T: two or three steps even where L spans hundreds of decades (it took
        // about eight in T from the bracket's midpoint); bisection keeps it inside the bracket.
        let target = radiance.ln();
        let (ln_lo, ln_hi) = (radiance_lo.max(f64::MIN_POSITIVE).ln(), radiance_hi.ln());
        let secant = 1.0 / lo + (target - ln_lo) / (ln_hi - ln_lo) * (1.0 / hi - 1.0 / lo);
        let mut t = if secant.is_finite() && secant > 0.0 {
            (1.0 / secant).clamp(lo, hi)
        } else {
            0.5 * (lo + hi)
        };
        for _ in 0..200 {
            let value = self.radiance(t);
            let residual = value.ln() - target;
            if residual > 0.0 {
                hi = t;
            } else {
                lo = t;
            }
            // d ln L / d(1/T) = −T² L'(T)/L.
            let slope = -t * t * self.radiance_derivative(t) / value;
            let newton = 1.0 / (1.0 / t - residual / slope);
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if (next - t).abs() <= 1e-13 * t {
                return Ok(next);
            }
            t = next;
        }
        Ok(t)
    }
}

/// Spectral radiance B_λ(T) in W·m⁻²·sr⁻¹·m⁻¹ at wavelength λ in metres.
pub fn spectral_radiance(lambda_m: f64, temperature_k: f64) -> f64 {
    C1L / lambda_m.powi(5) / (C2 / (lambda_m * temperature_k)).exp_m1()
}

/// ln B_λ(T) (B_λ in W·m⁻²·sr⁻¹·m⁻¹, λ in metres), finite for any T > 0: where B_λ itself
/// underflows (x = hc/(λkT) beyond ~700, a few kelvin in the infrared) its logarithm is still
/// −x + …, which ratios of spectral radiances at one temperature need.
pub fn ln_spectral_radiance(lambda_m: f64, temperature_k: f64) -> f64 {
    let x = C2 / (lambda_m * temperature_k);
    // ln(eˣ − 1) = x + ln(1 − e⁻ˣ) without overflow; below x = 1 the direct form is exact.
    let ln_expm1 = if x > 1.0 {
        x + (-(-x).exp()).ln_1p()
    } else {
        x.exp_m1().ln()
    };
    C1L.ln() - 5.0 * lambda_m.ln() - ln_expm1
}

fn validate_response(table: &[(f64, f64)]) -> Result<(), OpticsError> {
    if table.len() < 2 {
        return Err(OpticsError::InvalidResponse(
            "needs at least two (wavelength, response) rows".into(),
        ));
    }
    for (i, &(w, r)) in table.iter().enumerate() {
        if !(w.is_finite() && w > 0.0 && r.is_finite() && r >= 0.0) {
            return Err(OpticsError::InvalidResponse(format!(
                "row {}: ({} µm, {}) needs a positive wavelength and a finite response ≥ 0",
                i + 1,
                number(w),
                number(r)
            )));
        }
        if i > 0 && w <= table[i - 1].0 {
            return Err(OpticsError::InvalidResponse(format!(
                "row {}: wavelengths must increase ({} µm after {} µm)",
                i + 1,
                number(w),
                number(table[i - 1].0)
            )));
        }
    }
    Ok(())
}

/// Piecewise-linear response, zero outside the table.
fn interpolate_response(table: &[(f64, f64)], lambda_um: f64) -> f64 {
    let first = table[0];
    let last = table[table.len() - 1];
    if lambda_um < first.0 || lambda_um > last.0 {
        return 0.0;
    }
    let upper = table
        .partition_point(|&(w, _)| w < lambda_um)
        .clamp(1, table.len() - 1);
    let (w0, r0) = table[upper - 1];
    let (w1, r1) = table[upper];
    r0 + (r1 - r0) * (lambda_um - w0) / (w1 - w0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lwir_band_radiance_matches_reference_values() {
        let band = Band::lwir();
        // Reference band radiances (CODATA 2018, R = 1).
        assert!(
            (band.radiance(300.0) - 54.93346).abs() < 5e-5,
            "{}",
            band.radiance(300.0)
        );
        assert!(
            (band.radiance(283.15) - 41.89118).abs() < 5e-5,
            "{}",
            band.radiance(283.15)
        );
    }

    #[test]
    fn whole_spectrum_integral_tends_to_stefan_boltzmann() {
        // ∫0^∞ B_λ dλ = σT⁴/π; 0.5–1000 µm holds all but ~1e-6 of it at 1000 K.
        let band = Band::new(0.5, 1000.0, None).unwrap();
        let t = 1000.0;
        let sigma_sb = 5.670_374_419e-8;
        let rel = band.radiance(t) / (sigma_sb * t.powi(4) / std::f64::consts::PI) - 1.0;
        assert!(rel.abs() < 2e-5, "relative error {rel}");
    }

    #[test]
    fn brightness_temperature_inverts_radiance() {
        let band = Band::lwir();
        for t in [
            2.0, 5.0, 37.0, 150.0, 283.15, 300.0, 301.7, 1500.0, 6000.0, 2e5,
        ] {
            let back = band.brightness_temperature(band.radiance(t)).unwrap();
            assert!((back - t).abs() < 1e-12 * t, "{t} → {back}");
        }
        assert_eq!(band.brightness_temperature(0.0), Ok(0.0));
        assert!(band.brightness_temperature(f64::NAN).is_err());
        assert!(band.brightness_temperature(-1.0).is_err());
    }

    #[test]
    fn derivative_matches_finite_difference() {
        let band = Band::lwir();
        let fd = (band.radiance(300.001) - band.radiance(299.999)) / 0.002;
        assert!((band.radiance_derivative(300.0) / fd - 1.0).abs() < 1e-7);
    }

    #[test]
    fn response_table_weights_the_band() {
        // A flat response of 0.5 halves the radiance; a triangle is integrated exactly.
        let half = Band::new(8.0, 14.0, Some(vec![(7.0, 0.5), (15.0, 0.5)])).unwrap();
        let full = Band::lwir();
        assert!((half.radiance(300.0) / full.radiance(300.0) - 0.5).abs() < 1e-13);
        let tri = Band::new(8.0, 14.0, Some(vec![(8.0, 0.0), (11.0, 1.0), (14.0, 0.0)])).unwrap();
        assert!(
            tri.radiance(300.0) < full.radiance(300.0)
                && tri.radiance(300.0) > 0.3 * full.radiance(300.0)
        );
    }

    #[test]
    fn log_spectral_radiance_matches_and_stays_finite() {
        for (lambda, t) in [(10e-6, 300.0), (8e-6, 5772.0), (14e-6, 50.0), (12e-6, 4.0)] {
            let direct = spectral_radiance(lambda, t).ln();
            let log = ln_spectral_radiance(lambda, t);
            assert!(
                (log - direct).abs() < 1e-12 * direct.abs().max(1.0),
                "{lambda} {t}"
            );
        }
        // B_λ underflows to 0 at 0.01 K; its logarithm does not.
        assert_eq!(spectral_radiance(10e-6, 0.01), 0.0);
        assert!(ln_spectral_radiance(10e-6, 0.01).is_finite());
    }

    #[test]
    fn bad_bands_are_refused() {
        assert!(Band::new(14.0, 8.0, None).is_err());
        assert!(Band::new(0.0, 8.0, None).is_err());
        assert!(Band::new(8.0, f64::NAN, None).is_err());
        // The documented range: 0.1–1000 µm, an 8 µm–1 km band is refused before any allocation.
        assert!(Band::new(8.0, 1e9, None).is_err());
        assert!(Band::new(1e-300, 14.0, None).is_err());
        assert!(Band::new(0.1, 1000.0, None).is_ok());
        assert!(Band::new(8.0, 14.0, Some(vec![(9.0, 1.0)])).is_err());
        assert!(Band::new(8.0, 14.0, Some(vec![(9.0, 1.0), (9.0, 1.0)])).is_err());
        assert!(Band::new(8.0, 14.0, Some(vec![(15.0, 1.0), (16.0, 1.0)])).is_err());
    }
}
