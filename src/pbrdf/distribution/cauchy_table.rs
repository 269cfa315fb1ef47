//! Tabulated forms of the Student-t (Cauchy-family) tail integrals, for callers that evaluate
//! one model at many directions: the Cauchy Smith Λ ([`CauchySmithTable`]) and the regularized
//! incomplete beta ratio it and the visible-slope sampler share ([`HalfBetaRatio`]).

use super::PreparedDistribution;

use crate::elementary::{exp_within_range, ln_of_normal, multiply_add};
use statrs::function::beta::beta_reg;

impl PreparedDistribution {
    /// [`PreparedDistribution::smith_lambda`] of a Cauchy distribution as a table, for quadratures
    /// that need Λ at thousands of angles; `None` for the Gaussian, whose Λ is cheap.
    pub(crate) fn smith_lambda_table(&self) -> Option<CauchySmithTable> {
        match *self {
            PreparedDistribution::Cauchy {
                a,
                q,
                smith_prefactor,
                ..
            } if q > 1.5 => Some(CauchySmithTable::new(a, q, smith_prefactor)),
            _ => None,
        }
    }
}

/// The Cauchy Smith Λ for callers that evaluate one model at many directions (renderers,
/// quadratures, `irpol eval`, the Python `mueller`): the exact form needs an incomplete beta
/// function (~0.2 µs) per direction. With μ = cot θ, s = μ/√(a + μ²) ∈ [0, 1] and
/// x = 1 − s² = a/(a + μ²), docs/design.md §1.3's Λ = Γ(q−½)√a/(Γ(q−1)√π (2q−3) μ) (1 + μ²/a)^(3/2−q)
/// − ½ I_x(q−1, ½) is, since (1 + μ²/a)^(3/2−q) = x^(q−1)/√x and √a/(μ√x) = 1/s,
///     Λ = x^(q−1) [K/s − φ(s)/2],  K = Γ(q−½)/(Γ(q−1)√π (2q−3)),  φ(s) = I_x(q−1, ½)/x^(q−1).
/// φ is [`HalfBetaRatio`] with p = q − 1, evaluated as its per-interval polynomials
/// ([`HalfBetaRatio::interval_polynomials`]), and the power x^(q−1) as e^((q−1) ln x) with the
/// inlined, branch-free logarithm and exponential, so that a loop over directions vectorizes
/// ([`CauchySmithTable::masking_into`]). G1 = 1/(1+Λ) then agrees with the incomplete-beta form
/// to its own rounding error: within 1e-14 relative for q ≤ 4 and 2e-13 up to q = 100, at every
/// σ and down to grazing angles (cos θ = 1e-7; test below; the bound asked of it is 1e-12;
/// 4-point interpolation on the same grid was 3e-13 at q = 1.8 and 2e-9 at q = 60).
#[derive(Clone, Debug)]
pub(crate) struct CauchySmithTable {
    a: f64,
    q: f64,
    k: f64,
    phi: HalfBetaRatio,
    /// φ's grid interval count N, and φ on each interval [j/N, (j+1)/N] as a polynomial in
    /// sN − j ∈ [0, 1].
    intervals: f64,
    pieces: Vec<[f64; 6]>,
}

impl CauchySmithTable {
    fn new(a: f64, q: f64, smith_prefactor: f64) -> CauchySmithTable {
        // lim x→0 I_x(q−1, ½)/x^(q−1) = 1/((q−1) B(q−1, ½)) = Γ(q−½)/(Γ(q−1)√π (q−1)).
        let phi = HalfBetaRatio::new(q - 1.0, smith_prefactor / (q - 1.0));
        let pieces = phi.interval_polynomials();
        CauchySmithTable {
            a,
            q,
            k: smith_prefactor / (2.0 * q - 3.0),
            phi,
            intervals: pieces.len() as f64,
            pieces,
        }
    }

    /// Smith's G1(θ) = 1/(1 + Λ(θ)) for a direction with cos θ = `cos_theta` ∈ [0, 1]. With
    /// Λ = x^(q−1) [K/s − φ(s)/2] multiplied through by s,
    ///     G1 = s / (s + x^(q−1) (K − s φ(s)/2)),
    /// which needs two divisions where Λ and then 1/(1 + Λ) needed four. At s = 0 (grazing) it
    /// is 0, Λ's pole; at normal incidence 1. Branch free: [`CauchySmithTable::masking_into`]
    /// runs it over a block of directions as one vectorized loop, with the same results.
    #[inline(always)]
    pub(crate) fn masking(&self, cos_theta: f64) -> f64 {
        let cos2 = cos_theta * cos_theta;
        let sin2 = (1.0 - cos2).max(0.0);
        let a_sin2 = self.a * sin2;
        let denominator = a_sin2 + cos2;
        // One division for s and x: 1/√d = √d/d (divisions are most of the cost).
        let inverse = 1.0 / denominator;
        let s = cos_theta * (denominator.sqrt() * inverse);
        // x ≥ a sin²θ is normal wherever sin θ ≠ 0 (a ≥ 2e-8, sin²θ ≥ 1e-16), as the
        // logarithm's fast form needs; at sin θ = 0 the result is selected away below.
        let x = a_sin2 * inverse;
        // x^(q−1) = e^((q−1) ln x); below e^−707 it is negligible against s (then ≈ 1), and the
        // clamp keeps the exponential in its fast range. The relative error of the power,
        // ~(q−1)|ln x| 1e-16, matters only where x^(q−1) is itself negligible against s.
        let power = exp_within_range(((self.q - 1.0) * ln_of_normal(x)).max(-707.0));
        let tail = power * (self.k - 0.5 * s * self.phi_at(s));
        let g1 = s / (s + tail);
        if sin2 == 0.0 {
            1.0
        } else {
            g1
        }
    }

    /// [`CauchySmithTable::masking`] of each cosine into `out` (as many as the shorter holds).
    /// One loop of independent iterations without calls or branches: the compiler vectorizes it
    /// (a bulk Mueller evaluation of random geometries needs two factors per geometry, and one
    /// call at a time they were a third of its cost).
    #[inline]
    pub(crate) fn masking_into(&self, cosines: &[f64], out: &mut [f64]) {
        for (g1, &c) in out.iter_mut().zip(cosines) {
            *g1 = self.masking(c);
        }
    }

    /// φ(s) from the polynomial of s's grid interval (the last one at s = 1). The lookup cannot
    /// miss; `get` with a default rather than indexing keeps a panic branch out of the
    /// vectorized loop (a masked load instead).
    #[inline(always)]
    fn phi_at(&self, s: f64) -> f64 {
        // 2^52: adding it to an integer below 2^52 puts the integer in the low bits.
        const INTEGER_BITS: f64 = 4503599627370496.0;
        let u = s * self.intervals;
        let j_float = u.floor().min(self.intervals - 1.0);
        // j from its float by the bits rather than `as usize`, whose saturating conversion does
        // not vectorize (it was done lane by lane).
        let j = ((j_float + INTEGER_BITS).to_bits() - INTEGER_BITS.to_bits()) as usize;
        let t = u - j_float;
        let [c0, c1, c2, c3, c4, c5] = self.pieces.get(j).copied().unwrap_or_default();
        let t2 = t * t;
        // Even and odd halves as two chains of multiply–adds.
        let even = multiply_add(t2, multiply_add(t2, c4, c2), c0);
        let odd = multiply_add(t2, multiply_add(t2, c5, c3), c1);
        multiply_add(t, odd, even)
    }

    /// φ(s) = I_x(q−1, ½)/x^(q−1) at x = 1 − s²: also the tail of the Cauchy law's slope
    /// marginal, ½ φ x^(q−1) beyond |X| = s/√x (the visible-slope sampler's x).
    pub(crate) fn tail_ratio(&self, s: f64) -> f64 {
        self.phi.at(s)
    }
}

/// φ_p(s) = I_x(p, ½)/x^p with x = 1 − s², s ∈ [0, 1]: the regularized incomplete beta function
/// that Student-t tails need (the Cauchy Smith Λ with p = q − 1, the visible-slope sampler's
/// conditional slope with p = q − ½), with its x^p behaviour at x → 0 divided out. What is left is
/// analytic in s on [0, 1] (the (1 − x)^½ = s behaviour at x → 1 is analytic in s), so it is
/// tabulated on a uniform grid in s (from statrs' incomplete beta, ~0.2 µs a call) and
/// interpolated by 6-point Lagrange polynomials (~10 ns).
#[derive(Clone, Debug)]
pub(crate) struct HalfBetaRatio {
    /// φ_p(j/N) for j = 0..=N.
    phi: Vec<f64>,
}

impl HalfBetaRatio {
    /// The table for exponent `p`; `limit_at_one` = 1/(p B(p, ½)), φ_p's value at s = 1 (x = 0).
    pub(crate) fn new(p: f64, limit_at_one: f64) -> HalfBetaRatio {
        // φ varies faster as p grows (the lobe nears a Gaussian); 512 intervals keep the
        // interpolation error at rounding level up to p ≈ 31, beyond that the grid grows with p.
        let intervals = 512.max((16.0 * (p + 1.0)).ceil() as usize);
        let phi = (0..=intervals)
            .map(|j| {
                let s = j as f64 / intervals as f64;
                let x = 1.0 - s * s;
                if j == intervals {
                    limit_at_one
                } else {
                    beta_reg(p, 0.5, x) / x.powf(p)
                }
            })
            .collect();
        HalfBetaRatio { phi }
    }

    /// φ_p on each grid interval [j/N, (j+1)/N], j = 0..N, as the coefficients c_0…c_5 of
    /// Σ c_d τ^d in τ = sN − j ∈ [0, 1]: the interpolant of [`HalfBetaRatio::at`] on the same 6
    /// nodes, expanded once, so that an evaluation is a lookup and five multiply–adds. The
    /// Lagrange basis polynomials have small integer coefficients (exact in floating point);
    /// the expansion agrees with `at` to a few ulps (test below).
    pub(crate) fn interval_polynomials(&self) -> Vec<[f64; 6]> {
        let intervals = self.phi.len() - 1;
        (0..intervals)
            .map(|j| {
                let first = j.saturating_sub(2).min(intervals - 5);
                // Node m (0..6) lies at τ = m − shift.
                let shift = (j - first) as f64;
                let mut coefficients = [0.0; 6];
                for (node, value) in self.phi[first..first + 6].iter().enumerate() {
                    // ℓ_node(τ) = Π_{m≠node} (τ − (m − shift)) / (node − m), degree ascending.
                    let mut basis = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
                    let mut denominator = 1.0;
                    for m in (0..6).filter(|&m| m != node) {
                        let root = m as f64 - shift;
                        for d in (0..6).rev() {
                            let lower = if d > 0 { basis[d - 1] } else { 0.0 };
                            basis[d] = lower - root * basis[d];
                        }
                        denominator *= node as f64 - m as f64;
                    }
                    for (c, b) in coefficients.iter_mut().zip(basis) {
                        *c += value * b / denominator;
                    }
                }
                coefficients
            })
            .collect()
    }

    /// φ_p(s) from the 6 grid points around s (one-sided at the ends of [0, 1]).
    #[inline]
    pub(crate) fn at(&self, s: f64) -> f64 {
        let intervals = self.phi.len() - 1;
        let u = s * intervals as f64;
        let first = (u as usize).saturating_sub(2).min(intervals - 5);
        let t = u - first as f64;
        let f = &self.phi[first..first + 6];
        // Lagrange basis on the nodes t = 0, …, 5: ℓ_j(t) = Π_{m≠j} (t − m)/(j − m), the
        // denominators Π_{m≠j} (j − m) being −120, 24, −12, 12, −24, 120 (as reciprocals: a
        // division by a constant stays a division).
        const INVERSE_DENOMINATORS: [f64; 6] = [
            -1.0 / 120.0,
            1.0 / 24.0,
            -1.0 / 12.0,
            1.0 / 12.0,
            -1.0 / 24.0,
            1.0 / 120.0,
        ];
        let d = [t, t - 1.0, t - 2.0, t - 3.0, t - 4.0, t - 5.0];
        let (d01, d23, d45) = (d[0] * d[1], d[2] * d[3], d[4] * d[5]);
        let products = [
            d[1] * d23 * d45,
            d[0] * d23 * d45,
            d01 * d[3] * d45,
            d01 * d[2] * d45,
            d01 * d23 * d[5],
            d01 * d23 * d[4],
        ];
        // Written out: as an iterator sum the closure stayed a call, a fifth of a car render.
        products[0] * INVERSE_DENOMINATORS[0] * f[0]
            + products[1] * INVERSE_DENOMINATORS[1] * f[1]
            + products[2] * INVERSE_DENOMINATORS[2] * f[2]
            + products[3] * INVERSE_DENOMINATORS[3] * f[3]
            + products[4] * INVERSE_DENOMINATORS[4] * f[4]
            + products[5] * INVERSE_DENOMINATORS[5] * f[5]
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::limits::{MAX_Q, MAX_SIGMA, MIN_SIGMA};
    use super::super::SlopeDistribution;
    use super::*;
    use statrs::function::gamma::ln_gamma;

    /// The per-interval polynomials reproduce the 6-point interpolation they expand, on each
    /// interval and at its ends, for the smallest and largest exponents the models use.
    #[test]
    fn interval_polynomials_expand_the_interpolation() {
        for p in [0.5 + 1e-9, 0.8, 3.0, 30.0, MAX_Q - 1.0] {
            let ratio = HalfBetaRatio::new(p, 1.0 / (p * beta(p, 0.5)));
            let pieces = ratio.interval_polynomials();
            let n = pieces.len();
            for (j, c) in pieces.iter().enumerate() {
                for t in [0.0, 0.173, 0.5, 0.861, 1.0] {
                    let s = (j as f64 + t) / n as f64;
                    let expanded = c.iter().rev().fold(0.0, |acc, &c| acc * t + c);
                    let interpolated = ratio.at(s);
                    assert!(
                        (expanded - interpolated).abs() <= 4e-15 * interpolated.abs(),
                        "p={p} s={s}: {expanded} vs {interpolated}"
                    );
                }
            }
        }
    }

    /// The beta function B(a, b), for the test's limits.
    fn beta(a: f64, b: f64) -> f64 {
        (ln_gamma(a) + ln_gamma(b) - ln_gamma(a + b)).exp()
    }

    /// G1 of the table against the incomplete-beta form over the model's whole q range (q just
    /// above 3/2, where Λ's prefactor diverges, to 100) and σ range, from normal incidence to
    /// 0.000004° from grazing. The bound asked of the table is 1e-12 relative; it holds to the
    /// incomplete-beta form's own rounding error.
    #[test]
    fn tabulated_cauchy_lambda_matches_the_incomplete_beta_form() {
        for q in [1.5 + 1e-6, 1.52, 1.8, 2.5, 4.0, 10.0, 30.0, 60.0, MAX_Q] {
            for sigma in [MIN_SIGMA, 0.02, 0.1, 0.5, 3.0, MAX_SIGMA] {
                let prepared = SlopeDistribution::Cauchy { sigma, q }.prepare();
                let table = prepared.smith_lambda_table().unwrap();
                // The incomplete-beta form's own rounding error (the difference of two nearly
                // equal terms at large q, the power's (q−1)|ln x| 1e-16 at grazing angles) is
                // the floor: ~5e-15 at q ≤ 4, 1e-13 at q = 100.
                let bound = if q <= 4.0 { 1e-14 } else { 2e-13 };
                let grazing = (1..=40).map(|i| 1e-7 * i as f64);
                let cosines = (1..=4000).map(|i| (i as f64 / 4000.0).powi(2));
                for c in grazing.chain(cosines) {
                    // θ from 0.01° to 90° (the square: denser toward grazing where Λ grows), and
                    // within 0.0023° of grazing.
                    let exact = 1.0 / (1.0 + prepared.smith_lambda(c));
                    let tabulated = table.masking(c);
                    assert!(
                        (exact - tabulated).abs() <= bound * exact,
                        "q={q} σ={sigma} cosθ={c}: {exact} vs {tabulated}"
                    );
                }
                assert_eq!(table.masking(1.0), 1.0);
                assert_eq!(table.masking(0.0), 0.0);
            }
        }
        assert!(SlopeDistribution::Gaussian { sigma: 0.1 }
            .prepare()
            .smith_lambda_table()
            .is_none());
    }
}
