//! Facet slope distributions (docs/design.md §1.2) and their Smith Λ functions (docs/design.md §1.3).

use super::limits::{within, MAX_Q, MAX_SIGMA, MIN_SIGMA};
use super::terms::Parameter;
use super::ModelError;
use crate::elementary::{inline_exp, inline_ln};
use serde::{Deserialize, Serialize};
use statrs::function::{beta::beta_reg, erf::erfc, gamma::ln_gamma};
use std::f64::consts::PI;
use std::fmt;

mod cauchy_table;

pub(crate) use cauchy_table::{CauchySmithTable, HalfBetaRatio};

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
