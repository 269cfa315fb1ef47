//! Facet slope distributions (docs/design.md §1.2) and their Smith Λ functions (docs/design.md §1.3).

use super::limits::{within, MAX_Q, MAX_SIGMA, MIN_SIGMA};
use super::terms::Parameter;
use super::ModelError;
use crate::elementary::{exp_within_range, inline_exp, inline_ln, ln_of_normal, multiply_add};
use serde::{Deserialize, Serialize};
use statrs::function::{beta::beta_reg, erf::erfc, gamma::ln_gamma};
use std::f64::consts::PI;
use std::fmt;

/// Distribution of facet slopes m = tan θ, normalized over the hemisphere (∫ P(θ) dΩ = 1).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "distribution", rename_all = "lowercase")]
pub enum SlopeDistribution {
    /// Cauchy / Student-t (Wellems 2006; Ma et al. eq. 3), a = 2σ², q > 1:
    /// P(θ) = (q−1) a^(q−1) / (π cos³θ (tan²θ + a)^q). q = 2 is GGX with α = √2σ; q → ∞ Gaussian.
    Cauchy { sigma: f64, q: f64 },
    /// Gaussian slopes (Priest–Germer, Torrance–Sparrow): P(θ) = exp(−tan²θ/(2σ²)) / (2πσ² cos³θ).
    /// SCATMECH's slope parameter s and Beckmann's α equal √2σ.
    Gaussian { sigma: f64 },
}

impl SlopeDistribution {
    pub fn sigma(&self) -> f64 {
        match *self {
            SlopeDistribution::Cauchy { sigma, .. } | SlopeDistribution::Gaussian { sigma } => {
                sigma
            }
        }
    }

    /// The family of the distribution, without its parameters.
    pub fn kind(&self) -> DistributionKind {
        match self {
            SlopeDistribution::Cauchy { .. } => DistributionKind::Cauchy,
            SlopeDistribution::Gaussian { .. } => DistributionKind::Gaussian,
        }
    }

    pub fn name(&self) -> &'static str {
        self.kind().name()
    }

    /// The value of one of the distribution's [`DistributionKind::parameters`]; `None` for any
    /// other parameter.
    pub fn parameter(&self, parameter: Parameter) -> Option<f64> {
        match (*self, parameter) {
            (SlopeDistribution::Cauchy { sigma, .. }, Parameter::Sigma)
            | (SlopeDistribution::Gaussian { sigma }, Parameter::Sigma) => Some(sigma),
            (SlopeDistribution::Cauchy { q, .. }, Parameter::Q) => Some(q),
            _ => None,
        }
    }

    /// The slope m = tan θ below which a fraction `p` of the facets lie: the inverse CDFs of
    /// docs/design.md §1.2, tan²θ = a((1 − p)^(1/(1−q)) − 1) (Cauchy, a = 2σ²), −2σ² ln(1 − p) (Gaussian).
    pub fn slope_quantile(&self, p: f64) -> f64 {
        let tan2 = match *self {
            SlopeDistribution::Cauchy { sigma, q } => {
                2.0 * sigma * sigma * ((1.0 - p).powf(1.0 / (1.0 - q)) - 1.0)
            }
            SlopeDistribution::Gaussian { sigma } => -2.0 * sigma * sigma * (1.0 - p).ln(),
        };
        tan2.max(0.0).sqrt()
    }

    /// Refuses parameters outside the ranges of [`super::limits`].
    pub fn validate(&self) -> Result<(), ModelError> {
        let sigma = self.sigma();
        if !within(sigma, MIN_SIGMA, MAX_SIGMA) {
            return Err(ModelError::Sigma(sigma));
        }
        if let SlopeDistribution::Cauchy { q, .. } = *self {
            if !(within(q, 1.0, MAX_Q) && q > 1.0) {
                return Err(ModelError::Q(q));
            }
        }
        Ok(())
    }

    /// Precomputes the normalization and Smith constants; call only on a validated distribution.
    pub(crate) fn prepare(&self) -> PreparedDistribution {
        match *self {
            SlopeDistribution::Cauchy { sigma, q } => {
                let a = 2.0 * sigma * sigma;
                PreparedDistribution::Cauchy {
                    a,
                    inverse_a: 1.0 / a,
                    q,
                    norm: (q - 1.0) / (PI * a),
                    // Γ(q−½)/(Γ(q−1)√π); only meaningful (and only used) for q > 3/2.
                    smith_prefactor: if q > 1.5 {
                        (ln_gamma(q - 0.5) - ln_gamma(q - 1.0)).exp() / PI.sqrt()
                    } else {
                        f64::NAN
                    },
                }
            }
            SlopeDistribution::Gaussian { sigma } => PreparedDistribution::Gaussian {
                inv_two_sigma2: 0.5 / (sigma * sigma),
                norm: 1.0 / (2.0 * PI * sigma * sigma),
                inv_sqrt2_sigma: 1.0 / (2.0f64.sqrt() * sigma),
            },
        }
    }
}

/// A slope distribution family without its parameters: the one vocabulary of distribution names
/// (material files, scene files, the command line, fits and reports all parse and print them
/// here). A new slope law is a variant here, its arms in [`SlopeDistribution`], and its
/// parameters in [`super::terms`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DistributionKind {
    Cauchy,
    Gaussian,
}

/// Why a distribution name or a distribution's parameters are refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DistributionError {
    #[error(
        "unknown distribution '{}': use {names}",
        crate::text::shown(.0),
        names = DistributionKind::names()
    )]
    Unknown(String),
    #[error("the {0} distribution needs q")]
    NeedsQ(DistributionKind),
    #[error(
        "q applies to the {} distribution only",
        DistributionKind::names_with(Parameter::Q)
    )]
    StrayQ(DistributionKind),
}

impl DistributionKind {
    /// Every family, in the order fits try them (the first wins a tie of equal complexity).
    pub const ALL: [DistributionKind; 2] = [DistributionKind::Cauchy, DistributionKind::Gaussian];

    /// The name in files and on the command line (serde writes the same, lowercased).
    pub fn name(&self) -> &'static str {
        match self {
            DistributionKind::Cauchy => "cauchy",
            DistributionKind::Gaussian => "gaussian",
        }
    }

    /// Who the law is known by, for the material file's comment.
    pub fn description(&self) -> &'static str {
        match self {
            DistributionKind::Cauchy => "Student-t, Wellems 2006",
            DistributionKind::Gaussian => "Beckmann",
        }
    }

    /// The slope parameters of the family, in canonical order.
    pub fn parameters(&self) -> &'static [Parameter] {
        match self {
            DistributionKind::Cauchy => &[Parameter::Sigma, Parameter::Q],
            DistributionKind::Gaussian => &[Parameter::Sigma],
        }
    }

    /// Parses a name of [`DistributionKind::name`] (surrounding blanks ignored).
    pub fn parse(text: &str) -> Result<DistributionKind, DistributionError> {
        let name = text.trim();
        DistributionKind::ALL
            .into_iter()
            .find(|kind| kind.name() == name)
            .ok_or_else(|| DistributionError::Unknown(text.to_owned()))
    }

    /// "cauchy or gaussian": every name, for messages and help.
    pub fn names() -> String {
        Self::listed(DistributionKind::ALL.iter())
    }

    /// The names of the families that have `parameter` ("cauchy" for q).
    fn names_with(parameter: Parameter) -> String {
        Self::listed(
            DistributionKind::ALL
                .iter()
                .filter(|kind| kind.parameters().contains(&parameter)),
        )
    }

    fn listed<'a>(kinds: impl Iterator<Item = &'a DistributionKind>) -> String {
        kinds
            .map(|kind| kind.name())
            .collect::<Vec<_>>()
            .join(" or ")
    }

    /// Whether `parameter` belongs to this family's model: every parameter but the slope
    /// parameters of the other families (q is Cauchy-only).
    pub fn has(&self, parameter: Parameter) -> bool {
        self.parameters().contains(&parameter)
            || !DistributionKind::ALL
                .iter()
                .any(|kind| kind.parameters().contains(&parameter))
    }

    /// The first other family (the alternative of a model comparison between two).
    pub fn other(&self) -> DistributionKind {
        DistributionKind::ALL
            .into_iter()
            .find(|kind| kind != self)
            .expect("there is more than one family")
    }

    /// The distribution of this family with σ and q, refused when q is missing for a family
    /// that has it or given for one that has not.
    pub fn with(self, sigma: f64, q: Option<f64>) -> Result<SlopeDistribution, DistributionError> {
        match (self.has(Parameter::Q), q) {
            (true, None) => Err(DistributionError::NeedsQ(self)),
            (false, Some(_)) => Err(DistributionError::StrayQ(self)),
            (_, q) => Ok(self.with_parameters(|p| match p {
                Parameter::Q => q.unwrap_or(f64::NAN),
                _ => sigma,
            })),
        }
    }

    /// The distribution of this family with each of its [`DistributionKind::parameters`] taken
    /// from `value` (e.g. a fit's full parameter vector).
    pub fn with_parameters(self, value: impl Fn(Parameter) -> f64) -> SlopeDistribution {
        let sigma = value(Parameter::Sigma);
        match self {
            DistributionKind::Cauchy => SlopeDistribution::Cauchy {
                sigma,
                q: value(Parameter::Q),
            },
            DistributionKind::Gaussian => SlopeDistribution::Gaussian { sigma },
        }
    }
}

impl fmt::Display for DistributionKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for DistributionKind {
    type Err = DistributionError;

    fn from_str(text: &str) -> Result<DistributionKind, DistributionError> {
        DistributionKind::parse(text)
    }
}

/// [`DistributionKind::parse`] as a function: what scene files, material files and the command
/// line call to read a distribution name.
pub fn parse_distribution(text: &str) -> Result<DistributionKind, DistributionError> {
    DistributionKind::parse(text)
}

/// The distribution named `name` with σ and q ([`DistributionKind::with`]): a model written as
/// a name and its parameters (e.g. a scene's inline material) in one call.
pub fn slope_distribution(
    name: &str,
    sigma: f64,
    q: Option<f64>,
) -> Result<SlopeDistribution, DistributionError> {
    parse_distribution(name)?.with(sigma, q)
}

/// A validated distribution with its constants computed once.
#[derive(Clone, Copy, Debug)]
pub(crate) enum PreparedDistribution {
    Cauchy {
        a: f64,
        inverse_a: f64,
        q: f64,
        /// (q − 1)/(π a): p(m) = norm (1 + m²/a)^(−q).
        norm: f64,
        smith_prefactor: f64,
    },
    Gaussian {
        inv_two_sigma2: f64,
        norm: f64,
        inv_sqrt2_sigma: f64,
    },
}

impl PreparedDistribution {
    /// Slope-space density p(m) at |m|² = `slope2` (∫ p d²m = 1).
    #[inline]
    pub(crate) fn slope_pdf(&self, slope2: f64) -> f64 {
        let (exponent, norm) = self.slope_pdf_exponent_and_factor::<false>(slope2);
        norm * inline_exp(exponent)
    }

    /// (E, c) with p(m) = c e^E at |m|² = `slope2`; `INLINE_LN` selects the logarithm (below).
    #[inline]
    fn slope_pdf_exponent_and_factor<const INLINE_LN: bool>(&self, slope2: f64) -> (f64, f64) {
        match *self {
            PreparedDistribution::Cauchy {
                inverse_a, q, norm, ..
            } => {
                // (q−1)a^(q−1)/π (m² + a)^(−q) as (q−1)/(πa) (1 + m²/a)^(−q): neither factor
                // under- or overflows for small a and large q (a^(q−1) alone underflows to 0 at
                // σ = 1e-5, q = 40). exp(−q ln x) rather than powf: glibc's correctly rounded
                // pow took half of a BRDF evaluation; the relative error is ~q |ln x| 1e-16.
                // Which logarithm: in a vectorized block loop (src/pbrdf/batch.rs) the inlined
                // one, as glibc's, an opaque call, keeps the loop scalar and spills its registers
                // (5 % of a random-geometry Mueller evaluation, perf); one evaluation at a time
                // glibc's, 13 ns faster there (criterion: 4×4 Mueller 52 against 65 ns). Both are
                // within 1 ulp, so the two paths agree to ~q |ln x| 1e-16 relative.
                let x = 1.0 + slope2 * inverse_a;
                let ln = if INLINE_LN { inline_ln(x) } else { x.ln() };
                (-q * ln, norm)
            }
            PreparedDistribution::Gaussian {
                inv_two_sigma2,
                norm,
                ..
            } => (-slope2 * inv_two_sigma2, norm),
        }
    }

    /// The microfacet normal distribution D(θ) = P(θ)/cosθ = p(tanθ)/cos⁴θ of a facet tilted by
    /// θ, from tan²θ (P is the paper's eq. 3 density per solid angle; ∫ D cosθ dΩ = 1), as
    /// (E, c) with D = c e^E. The BRDF multiplies its other factors into c while the exponent is
    /// computed, so that the exponential is the last factor on its chain.
    #[inline]
    pub(crate) fn normal_distribution_exponent_and_factor<const INLINE_LN: bool>(
        &self,
        tan2_theta: f64,
    ) -> (f64, f64) {
        let (exponent, norm) = self.slope_pdf_exponent_and_factor::<INLINE_LN>(tan2_theta);
        let inverse_cos2 = 1.0 + tan2_theta;
        (exponent, norm * inverse_cos2 * inverse_cos2)
    }

    /// Smith Λ(θ) for a direction at zenith angle θ, μ = cot θ (docs/design.md §1.3).
    pub(crate) fn smith_lambda(&self, cos_theta: f64) -> f64 {
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        if sin_theta == 0.0 {
            return 0.0;
        }
        let mu = cos_theta / sin_theta;
        match *self {
            PreparedDistribution::Gaussian {
                inv_sqrt2_sigma, ..
            } => {
                let x = mu * inv_sqrt2_sigma;
                if x > 26.0 {
                    return 0.0; // erfc(26) < 1e-295: Λ underflows
                }
                // ½(erf x − 1) + e^(−x²)/(2√π x), with erfc to keep absolute accuracy at large x.
                0.5 * ((-x * x).exp() / (PI.sqrt() * x) - erfc(x))
            }
            PreparedDistribution::Cauchy {
                a,
                q,
                smith_prefactor,
                ..
            } => {
                let mu2 = mu * mu;
                smith_prefactor * a.sqrt() / ((2.0 * q - 3.0) * mu) * (1.0 + mu2 / a).powf(1.5 - q)
                    - 0.5 * beta_reg(q - 1.0, 0.5, a / (a + mu2))
            }
        }
    }

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

    /// A slope scale of the distribution (≈ σ), for laying out quadrature panels.
    pub(crate) fn slope_scale(&self) -> f64 {
        match *self {
            PreparedDistribution::Cauchy { a, .. } => (0.5 * a).sqrt(),
            PreparedDistribution::Gaussian { inv_two_sigma2, .. } => (0.5 / inv_two_sigma2).sqrt(),
        }
    }

    /// Slope magnitude beyond which the distribution holds < 1e-17 of its mass (∞ for the
    /// heavy-tailed Cauchy, whose tail matters at grazing angles).
    pub(crate) fn slope_cutoff(&self) -> f64 {
        match *self {
            PreparedDistribution::Cauchy { .. } => f64::INFINITY,
            // Mass beyond u is exp(−u²/(2σ²)); e^−40 ≈ 4e-18.
            PreparedDistribution::Gaussian { inv_two_sigma2, .. } => (40.0 / inv_two_sigma2).sqrt(),
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
    use super::*;
    use gauss_quad::legendre::GaussLegendre;

    #[test]
    fn kinds_name_parse_and_build_their_distributions() {
        for kind in DistributionKind::ALL {
            assert_eq!(DistributionKind::parse(kind.name()), Ok(kind));
            assert_eq!(parse_distribution(&format!(" {kind} ")), Ok(kind));
            // serde reads and writes the same names.
            let json = serde_json::to_string(&kind).unwrap();
            assert_eq!(json, format!("\"{}\"", kind.name()));
            let q = kind.has(Parameter::Q).then_some(2.5);
            let distribution = kind.with(0.1, q).unwrap();
            assert_eq!(
                (distribution.kind(), distribution.name()),
                (kind, kind.name())
            );
        }
        let message = |e: DistributionError| e.to_string();
        assert_eq!(
            message(DistributionKind::parse("beckmann").unwrap_err()),
            "unknown distribution 'beckmann': use cauchy or gaussian"
        );
        assert_eq!(
            message(DistributionKind::Cauchy.with(0.1, None).unwrap_err()),
            "the cauchy distribution needs q"
        );
        assert_eq!(
            message(DistributionKind::Gaussian.with(0.1, Some(2.0)).unwrap_err()),
            "q applies to the cauchy distribution only"
        );
        assert!(!DistributionKind::Gaussian.has(Parameter::Q));
        assert!(DistributionKind::Gaussian.has(Parameter::RhoD));
        assert_eq!(DistributionKind::Cauchy.other(), DistributionKind::Gaussian);
    }

    fn gl(n: usize) -> GaussLegendre {
        GaussLegendre::new(n.try_into().unwrap())
    }

    /// ∫ p(m) d²m over the plane by polar quadrature with u = s/(1−s) on [0, 1).
    fn total_mass(dist: &PreparedDistribution) -> f64 {
        let rule = gl(400);
        2.0 * PI
            * rule.integrate(0.0, 1.0, |s| {
                let u = s / (1.0 - s);
                dist.slope_pdf(u * u) * u / ((1.0 - s) * (1.0 - s))
            })
    }

    #[test]
    fn distributions_are_normalized() {
        for dist in [
            SlopeDistribution::Cauchy { sigma: 0.1, q: 1.8 },
            SlopeDistribution::Cauchy { sigma: 0.3, q: 4.0 },
            SlopeDistribution::Gaussian { sigma: 0.2 },
        ] {
            let mass = total_mass(&dist.prepare());
            assert!((mass - 1.0).abs() < 1e-6, "{dist:?}: {mass}");
        }
    }

    #[test]
    fn cauchy_with_q_2_is_ggx() {
        // GGX D(h) = α² / (π cos⁴θ (α² + tan²θ)²) with α = √2σ.
        let sigma = 0.23;
        let alpha2 = 2.0 * sigma * sigma;
        let dist = SlopeDistribution::Cauchy { sigma, q: 2.0 }.prepare();
        for deg in [0.0f64, 10.0, 35.0, 70.0] {
            let c = deg.to_radians().cos();
            let tan2 = (1.0 - c * c) / (c * c);
            let ggx = alpha2 / (PI * c.powi(4) * (alpha2 + tan2).powi(2));
            let (exponent, factor) = dist.normal_distribution_exponent_and_factor::<false>(tan2);
            assert!((factor * exponent.exp() / ggx - 1.0).abs() < 1e-13);
        }
    }

    /// Narrow, nearly Gaussian Cauchy lobes: a^(q−1) alone underflows at σ = 1e-5, q = 40, but
    /// the density must stay finite and exact, p(m) = (q−1)/(πa) (1 + m²/a)^(−q).
    #[test]
    fn narrow_heavy_exponent_density_stays_finite() {
        let (sigma, q) = (1e-5, 40.0);
        let a = 2.0 * sigma * sigma;
        let dist = SlopeDistribution::Cauchy { sigma, q }.prepare();
        for m in [0.0, sigma, 5.0 * sigma] {
            let expect = (q - 1.0) / (PI * a) * (1.0 + m * m / a).powf(-q);
            let got = dist.slope_pdf(m * m);
            assert!(
                (got / expect - 1.0).abs() < 1e-13,
                "m={m}: {got} vs {expect}"
            );
        }
    }

    /// ∫_0^∞ f by Gauss–Legendre on panels doubling in width from scale/16 (heavy tails welcome).
    fn integrate_to_infinity(f: impl Fn(f64) -> f64, scale: f64) -> f64 {
        let rule = gl(16);
        let (mut start, mut width, mut total) = (0.0, scale / 16.0, 0.0);
        for _ in 0..60 {
            total += rule.integrate(start, start + width, &f);
            start += width;
            width *= 2.0;
        }
        total
    }

    /// Smith Λ from its definition, Λ(μ) = (1/μ) ∫_μ^∞ (x − μ) p_x(x) dx, with the marginal slope
    /// density p_x(x) = ∫ p(x, y) dy computed numerically too.
    fn lambda_by_quadrature(dist: &PreparedDistribution, mu: f64) -> f64 {
        let scale = dist.slope_scale();
        let marginal =
            |x: f64| 2.0 * integrate_to_infinity(|y| dist.slope_pdf(x * x + y * y), scale);
        integrate_to_infinity(|t| t * marginal(mu + t), scale) / mu
    }

    #[test]
    fn smith_lambda_matches_its_definition() {
        for dist in [
            SlopeDistribution::Gaussian { sigma: 0.25 },
            SlopeDistribution::Cauchy { sigma: 0.2, q: 2.0 },
            SlopeDistribution::Cauchy {
                sigma: 0.15,
                q: 1.8,
            },
            SlopeDistribution::Cauchy { sigma: 0.3, q: 3.5 },
        ] {
            let prepared = dist.prepare();
            for deg in [20.0f64, 60.0, 80.0, 88.0] {
                let c = deg.to_radians().cos();
                let mu = c / (1.0 - c * c).sqrt();
                let closed = prepared.smith_lambda(c);
                let numeric = lambda_by_quadrature(&prepared, mu);
                assert!(
                    (closed - numeric).abs() < 1e-9 * numeric + 1e-15,
                    "{dist:?} θ={deg}: closed {closed} numeric {numeric}"
                );
            }
        }
    }

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

    #[test]
    fn cauchy_q2_lambda_has_the_ggx_closed_form() {
        let sigma = 0.2;
        let dist = SlopeDistribution::Cauchy { sigma, q: 2.0 }.prepare();
        for deg in [5.0f64, 45.0, 85.0] {
            let theta = deg.to_radians();
            let expect = 0.5 * ((1.0 + 2.0 * sigma * sigma * theta.tan().powi(2)).sqrt() - 1.0);
            assert!((dist.smith_lambda(theta.cos()) - expect).abs() < 1e-13);
        }
        assert_eq!(dist.smith_lambda(1.0), 0.0);
    }

    #[test]
    fn slope_quantiles_invert_the_distributions() {
        // Cauchy q = 2 is GGX: P(m < x) = x²/(x² + a); Gaussian: 1 − exp(−x²/(2σ²)).
        let x = SlopeDistribution::Cauchy { sigma: 0.2, q: 2.0 }.slope_quantile(0.9);
        assert!((x * x / (x * x + 0.08) - 0.9).abs() < 1e-12);
        let x = SlopeDistribution::Gaussian { sigma: 0.2 }.slope_quantile(0.5);
        assert!((1.0 - (-x * x / 0.08).exp() - 0.5).abs() < 1e-12);
    }

    #[test]
    fn invalid_parameters_are_refused() {
        assert_eq!(
            SlopeDistribution::Gaussian { sigma: 0.0 }.validate(),
            Err(ModelError::Sigma(0.0))
        );
        assert!(SlopeDistribution::Gaussian { sigma: f64::NAN }
            .validate()
            .is_err());
        assert_eq!(
            SlopeDistribution::Cauchy { sigma: 0.1, q: 1.0 }.validate(),
            Err(ModelError::Q(1.0))
        );
        assert!(SlopeDistribution::Cauchy {
            sigma: -0.1,
            q: 2.0
        }
        .validate()
        .is_err());
        assert!(SlopeDistribution::Cauchy {
            sigma: 0.1,
            q: f64::INFINITY
        }
        .validate()
        .is_err());
        // The documented limits: inclusive ends pass, a step beyond fails.
        for (sigma, q, ok) in [
            (MIN_SIGMA, MAX_Q, true),
            (MAX_SIGMA, 1.0 + 1e-9, true),
            (1e-300, 2.0, false),
            (MAX_SIGMA * 1.01, 2.0, false),
            (0.2, 1e308, false),
            (0.2, MAX_Q * 1.01, false),
        ] {
            let result = SlopeDistribution::Cauchy { sigma, q }.validate();
            assert_eq!(result.is_ok(), ok, "σ = {sigma}, q = {q}: {result:?}");
        }
    }
}
