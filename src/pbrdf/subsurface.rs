//! The volume-scattering terms of docs/design.md §1.10: which side of the facets reflects
//! ([`FacetSide`]), and the polarized subsurface term
//!     F_ss(ω_i→ω_r) = (ρ_s / (π Z)) · T(θ_r) · L(−η_r) D(d) L(η_i) · T(θ_i),
//! light refracted into the material through a smooth interface, scattered inside with a residual
//! polarization d referred to the scattering plane, and refracted out.
//!
//! - T(θ) is the Fresnel transmission Mueller matrix of the macro surface at cos θ, air → material
//!   (ε = N²), in the psps frame of its direction: t_s,p = 1 − R_s,p, T± = (t_s ± t_p)/2,
//!   X = √(t_s t_p); T = [[T+, T−, 0, 0], [T−, T+, 0, 0], [0, 0, X, 0], [0, 0, 0, X]]. For a
//!   dielectric t_p ≥ t_s, so the light leaves p-polarized — as thermal emission does.
//! - D(d) = diag(1, d, −d, −d_c): the polarization that survives volume scattering, with the signs
//!   of a mirror (a perfect mirror is diag(1, 1, −1, −1) in s/p frames); d_c = d unless given. A
//!   negative d_c keeps helicity, as forward multiple scattering by large grains does (sintered
//!   PTFE: d ≈ 0.03, d_c ≈ −0.02). m33 takes no part in the reflectance, so d_c does not enter Z. Like single scattering by a
//!   particle, it is referred to the scattering plane (the plane of ω_i and ω_r), not to the
//!   macro surface: L(η_i), L(−η_r) are the rotations of the facet term (§1.3) from the psps
//!   frames into the frames of that plane (whose normal is ω_i × ω_r, the facet's s axis).
//!   Multiplied out, L(−η_r) D L(η_i) = [[1,0,0,0], [0,dC,dS,0], [0,dS,−dC,0], [0,0,0,−d_c]] with
//!   C + iS = e^{i(2η_i + 2η_r)}. NIST's sintered PTFE shows why: at normal incidence its residual
//!   polarization follows cos 2φ_r, sin 2φ_r (m11 = −m22 = ±0.05 at φ_r = 0°, 90°), which a
//!   matrix fixed in the macro frames cannot give. D is realizable (Cloude) for
//!   2|d| − 1 ≤ d_c ≤ 1 ([`Subsurface::is_realizable`]); the model accepts d ∈ [0, 1] and refuses
//!   an unrealizable d_c.
//! - d may change with the scattering angle Θ between the incident beam (travelling along −ω_i)
//!   and the scattered one (ω_r), cos Θ = −ω_i·ω_r = 1 − 2cos²β: d(Θ) = d + d1 cos Θ, as single
//!   scattering by particles polarizes differently forward and backward (docs/design.md §1.10).
//!   The bounds below hold with the largest |d(Θ)|, |d| + |d1|.
//! - The interface has the material's index N, or n_sub + ik where given ([`Subsurface`]).
//! - Z = (1 − R̄) + |d|·|Ā|, R̄ = 2∫₀¹ R(μ) μ dμ, Ā = 2∫₀¹ T−(μ) μ dμ, the normalization that
//!   conserves energy: for light of intensity I_t after the interface (I_t = T+(θ_i) unpolarized)
//!   the term's directional-hemispherical reflectance is at most
//!   (ρ_s/Z)[(1 − R̄) I_t + |d| |Ā| I_t] = ρ_s I_t, since |C|, |S| ≤ 1 and the transmitted Stokes
//!   vector's polarized part is at most I_t — at most a fraction ρ_s of what the smooth interface
//!   lets in comes out.
//!
//! Reciprocity: T is symmetric, and the rotated D has the structure of the facet term's Fresnel
//! matrix between the same rotations, so F_ss obeys the facet term's Sekera relation
//! F(ω_r→ω_i) = Q F(ω_i→ω_r)ᵀ Q. With N = 1 and d = 0 every R is exactly 0, Z exactly 1 and the
//! term is (ρ_s/π) diag(1,0,0,0) bit for bit: today's ideal depolarizer (§1.3's ρ_d).

use super::terms::{Parameter, Term};
use crate::optics::{FresnelFractions, Mueller, RefractiveIndex};
use num_complex::Complex64;
use std::f64::consts::{FRAC_1_PI, PI};

/// The parameters of a subsurface lobe: ρ_s ∈ [0, 1], the fraction of the transmitted light
/// that comes back out, d ∈ [0, 1], its residual polarization, and the real index n_sub of the
/// interface it crosses (`None`: the material's n). The subsurface light meets the interface
/// everywhere, not only on the facets that make the lobe; where that interface is rougher or
/// contaminated its polarization is weaker than a smooth one of index n gives, which a separate
/// index describes (docs/design.md §1.10).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Subsurface {
    /// The model's term this lobe is ([`Term::lobe`] names its parameters).
    pub term: Term,
    pub rho_s: f64,
    pub d: f64,
    pub n_sub: Option<f64>,
    /// The circular residual polarization (D's m33 = −d_c); absent: d.
    pub d_c: Option<f64>,
    /// The residual polarization's change with the scattering angle Θ, d(Θ) = d + d1 cos Θ;
    /// absent: 0.
    pub d1: Option<f64>,
}

/// A lobe's d, n_sub, d_c or d1 given without its ρ_s (in a material file, a scene's inline
/// material or on the command line): they describe a lobe that is not there.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}", self.message(|p| p.name().to_owned()))]
pub struct LobeKeysWithoutReflectance {
    pub term: Term,
}

impl LobeKeysWithoutReflectance {
    /// "d, n_sub, d_c and d1 need rho_s: they belong to the subsurface term", with each
    /// parameter written by `name` (a key, or a flag).
    pub fn message(&self, name: impl Fn(Parameter) -> String) -> String {
        let lobe = self.term.lobe().expect("a lobe term");
        let names: Vec<String> = lobe.dependents().map(&name).collect();
        let listed = match names.split_last() {
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
            None => String::new(),
        };
        let (verb, pronoun) = if names.len() == 1 {
            ("needs", "it belongs")
        } else {
            ("need", "they belong")
        };
        format!(
            "{listed} {verb} {}: {pronoun} to the {} term",
            name(lobe.reflectance),
            self.term.name()
        )
    }
}

impl Subsurface {
    /// The lobe `term` that its keys describe (`key` gives a parameter's value where written),
    /// wherever they are written: none without ρ_s, d absent is 0, n_sub, d_c and d1 absent take
    /// their defaults (n, d, 0).
    pub fn from_keys(
        term: Term,
        key: impl Fn(Parameter) -> Option<f64>,
    ) -> Result<Option<Subsurface>, LobeKeysWithoutReflectance> {
        let Some(lobe) = term.lobe() else {
            return Ok(None);
        };
        let optional = |p: Option<Parameter>| p.and_then(&key);
        match key(lobe.reflectance) {
            Some(rho_s) => Ok(Some(Subsurface {
                term,
                rho_s,
                d: key(lobe.residual).unwrap_or(0.0),
                n_sub: optional(lobe.interface_index),
                d_c: optional(lobe.circular),
                d1: optional(lobe.residual_slope),
            })),
            None if lobe.dependents().any(|p| key(p).is_some()) => {
                Err(LobeKeysWithoutReflectance { term })
            }
            None => Ok(None),
        }
    }

    /// The lobe's values as its keys are written, in [`Parameter::ALL`] order: ρ_s and d always,
    /// n_sub, d_c and d1 where given.
    pub fn keys(&self) -> impl Iterator<Item = (Parameter, f64)> {
        let lobe = self.term.lobe().expect("a lobe term");
        [
            Some((lobe.reflectance, self.rho_s)),
            Some((lobe.residual, self.d)),
            lobe.interface_index.zip(self.n_sub),
            lobe.circular.zip(self.d_c),
            lobe.residual_slope.zip(self.d1),
        ]
        .into_iter()
        .flatten()
    }

    /// The value of `parameter`, one of the lobe's, with the defaults of absent keys filled in
    /// (n_sub = `n`, d_c = d, d1 = 0); `None` for a parameter of another term.
    pub fn value(&self, parameter: Parameter, n: f64) -> Option<f64> {
        let lobe = self.term.lobe()?;
        let p = Some(parameter);
        if parameter == lobe.reflectance {
            Some(self.rho_s)
        } else if parameter == lobe.residual {
            Some(self.d)
        } else if p == lobe.interface_index {
            Some(self.n_sub.unwrap_or(n))
        } else if p == lobe.circular {
            Some(self.circular())
        } else if p == lobe.residual_slope {
            Some(self.d1.unwrap_or(0.0))
        } else {
            None
        }
    }

    /// The largest |d(Θ)| over all scattering angles: |d| + |d1|.
    pub fn largest_residual(&self) -> f64 {
        self.d.abs() + self.d1.unwrap_or(0.0).abs()
    }

    /// d_c, or d where it is not given (the mirror-signed D of the module docs).
    pub fn circular(&self) -> f64 {
        self.d_c.unwrap_or(self.d)
    }

    /// Whether D = diag(1, d, −d, −d_c) is a sum of Jones matrices at every scattering angle:
    /// its coherency eigenvalues are (1 − d_c)/4 twice, (1 + 2d + d_c)/4 and (1 − 2d + d_c)/4,
    /// so d_c ∈ [2|d(Θ)| − 1, 1] for the largest |d(Θ)| = |d| + |d1|.
    pub fn is_realizable(&self) -> bool {
        let d_c = self.circular();
        d_c <= 1.0 && d_c >= 2.0 * self.largest_residual() - 1.0
    }
}

/// Fresnel transmission of the macro surface at one zenith angle: (T+, T−, X) of the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transmission {
    pub plus: f64,
    pub minus: f64,
    pub cross: f64,
}

impl Transmission {
    /// T(θ) at cos θ = `cos_theta` for permittivity ε = N².
    #[inline]
    pub fn at(cos_theta: f64, permittivity: Complex64) -> Transmission {
        let (rs2, rp2, _) = FresnelFractions::new(cos_theta, permittivity).reflectances_and_cross();
        let (ts, tp) = (1.0 - rs2, 1.0 - rp2);
        Transmission {
            plus: 0.5 * (ts + tp),
            minus: 0.5 * (ts - tp),
            cross: (ts * tp).max(0.0).sqrt(),
        }
    }
}

/// A subsurface term ready to evaluate: its parameters, ε = N² and the scale ρ_s/(πZ).
#[derive(Clone, Copy, Debug)]
pub(super) struct PreparedSubsurface {
    pub(super) terms: Subsurface,
    permittivity: Complex64,
    scale: f64,
}

impl PreparedSubsurface {
    pub(super) fn new(terms: Subsurface, index: RefractiveIndex) -> PreparedSubsurface {
        let n = terms.n_sub.unwrap_or(index.n);
        let permittivity = RefractiveIndex::new(n, index.k).permittivity();
        let (mean_reflectance, mean_minus) = interface_means(permittivity);
        // |d(Θ)| ≤ |d| + |d1| at every Θ: the bound of the module docs holds with it.
        let z = (1.0 - mean_reflectance) + terms.largest_residual() * mean_minus.abs();
        PreparedSubsurface {
            terms,
            permittivity,
            scale: terms.rho_s * FRAC_1_PI / z,
        }
    }

    /// T(θ) of this material's interface.
    #[inline]
    pub(super) fn transmission(&self, cos_theta: f64) -> Transmission {
        Transmission::at(cos_theta, self.permittivity)
    }

    /// The term's Mueller matrix from T(θ_i), T(θ_r), `plane` = (C, S) = (cos, sin) of
    /// 2η_i + 2η_r, the turn of the scattering plane against the psps frames, and cos Θ of the
    /// scattering angle (module docs).
    #[inline]
    pub(super) fn mueller(
        &self,
        incident: Transmission,
        scattered: Transmission,
        plane: (f64, f64),
        cos_scattering: f64,
    ) -> Mueller {
        let (i, r, k) = (incident, scattered, self.scale);
        let d = self.terms.d + self.terms.d1.unwrap_or(0.0) * cos_scattering;
        let (dc, ds) = (d * plane.0, d * plane.1);
        let mut m = Mueller::zeros();
        // T(θ_r) · [[1,0,0,0],[0,dC,dS,0],[0,dS,−dC,0],[0,0,0,−d]] · T(θ_i), multiplied out.
        m[(0, 0)] = k * (r.plus * i.plus + dc * r.minus * i.minus);
        m[(0, 1)] = k * (r.plus * i.minus + dc * r.minus * i.plus);
        m[(0, 2)] = k * ds * r.minus * i.cross;
        m[(1, 0)] = k * (r.minus * i.plus + dc * r.plus * i.minus);
        m[(1, 1)] = k * (r.minus * i.minus + dc * r.plus * i.plus);
        m[(1, 2)] = k * ds * r.plus * i.cross;
        m[(2, 0)] = k * ds * r.cross * i.minus;
        m[(2, 1)] = k * ds * r.cross * i.plus;
        m[(2, 2)] = -k * dc * r.cross * i.cross;
        m[(3, 3)] = -k * self.terms.circular() * r.cross * i.cross;
        m
    }
}

/// Gauss–Legendre nodes per panel of [`interface_means`].
const MEAN_NODES: usize = 48;

/// (R̄, Ā) = (2∫₀¹ R(μ) μ dμ, 2∫₀¹ T−(μ) μ dμ) of the interface with permittivity ε.
/// R(μ) is analytic except at μ_c = √(1 − Re ε) when Re ε < 1 (the critical angle of a material
/// optically thinner than air), where it has a square-root kink: the interval is split there and
/// each panel mapped by μ = a + (b − a) sin²(πv/2), which removes square-root end singularities,
/// so 48 nodes per panel give the means to ~1e-14.
fn interface_means(permittivity: Complex64) -> (f64, f64) {
    let critical = (1.0 - permittivity.re).max(0.0).sqrt();
    let panels: &[(f64, f64)] = if critical > 0.0 && critical < 1.0 {
        &[(0.0, critical), (critical, 1.0)]
    } else {
        &[(0.0, 1.0)]
    };
    let rule = gauss_quad::legendre::GaussLegendre::new(MEAN_NODES.try_into().expect("48 ≥ 1"));
    let (mut reflectance, mut minus) = (0.0, 0.0);
    for &(a, b) in panels {
        for &(x, w) in rule.as_node_weight_pairs().iter() {
            let v = 0.5 * (x + 1.0);
            let half_angle = 0.5 * PI * v;
            let mu = a + (b - a) * half_angle.sin().powi(2);
            let jacobian = (b - a) * 0.5 * PI * (PI * v).sin() * 0.5 * w;
            let t = Transmission::at(mu, permittivity);
            // R = (R_s + R_p)/2 = 1 − T+.
            reflectance += 2.0 * (1.0 - t.plus) * mu * jacobian;
            minus += 2.0 * t.minus * mu * jacobian;
        }
    }
    (reflectance, minus)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_matched_interface_transmits_everything_exactly() {
        let eps = RefractiveIndex::new(1.0, 0.0).permittivity();
        for cos in [1.0, 0.7, 0.3, 0.01] {
            let t = Transmission::at(cos, eps);
            assert_eq!((t.plus, t.minus, t.cross), (1.0, 0.0, 1.0));
        }
        assert_eq!(interface_means(eps), (0.0, 0.0));
    }

    /// R̄ of a dielectric against its closed form (Stern 1964 / Walton: the hemispherical
    /// reflectance of a smooth dielectric, here n = 1.5: R̄ = 0.092 …) computed by brute force.
    #[test]
    fn interface_means_match_a_brute_force_sum() {
        for (n, k) in [(1.5, 0.0), (1.35, 0.0), (2.4, 0.3), (0.7, 0.0), (0.9, 0.05)] {
            let eps = RefractiveIndex::new(n, k).permittivity();
            let (r, a) = interface_means(eps);
            // Midpoint rule on a fine grid (converges slowly but surely, kink or not).
            let steps = 400_000;
            let (mut r_ref, mut a_ref) = (0.0, 0.0);
            for s in 0..steps {
                let mu = (s as f64 + 0.5) / steps as f64;
                let t = Transmission::at(mu, eps);
                r_ref += 2.0 * (1.0 - t.plus) * mu / steps as f64;
                a_ref += 2.0 * t.minus * mu / steps as f64;
            }
            // The midpoint rule's own error at the kink of n < 1 is ~5e-9.
            assert!((r - r_ref).abs() < 2e-8, "{n} {k}: {r} vs {r_ref}");
            assert!((a - a_ref).abs() < 2e-8, "{n} {k}: {a} vs {a_ref}");
        }
        // The classic value for n = 1.5: hemispherical reflectance 0.0918 (e.g. Duntley 1942).
        let (r, _) = interface_means(RefractiveIndex::new(1.5, 0.0).permittivity());
        assert!((r - 0.0918).abs() < 5e-4, "{r}");
    }
}
