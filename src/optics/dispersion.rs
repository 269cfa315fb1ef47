//! A parametric dispersion law for the complex index over wavelength (docs/design.md §1.9): a sum of
//! Lorentz oscillators on a constant background,
//!
//!   ε(ν) = ε_∞ + Σ_j Δε_j ν_j² / (ν_j² − ν² − i γ_j ν),
//!
//! with ν = 1/λ the wavenumber (µm⁻¹), ν_j = 1/λ_j at each oscillator's resonance wavelength λ_j,
//! and γ_j = w_j / λ_j² its damping, w_j the line width written as a wavelength (µm) at the
//! resonance (so that the three parameters of an oscillator are all read off a spectrum plot in
//! µm). Causal, hence Kramers–Kronig consistent, for ε_∞ ≥ 1, Δε_j > 0, γ_j > 0; Im ε > 0 (k > 0)
//! everywhere in the exp(−iωt) convention. N = √ε, principal branch (Re N ≥ 0, Im N ≥ 0).

use super::RefractiveIndex;
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// Why a Lorentz law is not physical.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LorentzError {
    #[error("eps_inf = {} must be ≥ 1", crate::text::number(*.0))]
    EpsInf(f64),
    #[error("a Lorentz dispersion needs at least one oscillator")]
    NoOscillator,
    /// `oscillator` counts from 1.
    #[error(
        "oscillator {oscillator}: {name} = {} must be positive",
        crate::text::number(*value)
    )]
    Oscillator {
        oscillator: usize,
        name: &'static str,
        value: f64,
    },
}

/// One Lorentz oscillator (a resonance of the lattice, e.g. silicate's Si–O stretch near 9.3 µm).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LorentzOscillator {
    /// Resonance wavelength λ_j, µm.
    pub resonance_um: f64,
    /// Oscillator strength Δε_j (dimensionless): the static permittivity it adds.
    pub strength: f64,
    /// Line width w_j written as a wavelength at the resonance, µm (damping γ_j = w_j/λ_j²).
    pub damping_um: f64,
}

/// ε_∞ plus Lorentz oscillators.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LorentzDispersion {
    /// High-frequency (electronic) permittivity ε_∞.
    pub eps_inf: f64,
    pub oscillators: Vec<LorentzOscillator>,
}

impl LorentzDispersion {
    /// The relative permittivity ε at `wavelength_um`.
    pub fn permittivity(&self, wavelength_um: f64) -> Complex64 {
        let nu = 1.0 / wavelength_um;
        self.oscillators
            .iter()
            .fold(Complex64::new(self.eps_inf, 0.0), |eps, o| {
                let nu0 = 1.0 / o.resonance_um;
                let gamma = o.damping_um * nu0 * nu0;
                let denominator = Complex64::new(nu0 * nu0 - nu * nu, -gamma * nu);
                eps + o.strength * nu0 * nu0 / denominator
            })
    }

    /// N = n + ik = √ε at `wavelength_um` (principal branch: k ≥ 0 when Im ε ≥ 0).
    pub fn index(&self, wavelength_um: f64) -> RefractiveIndex {
        let n = self.permittivity(wavelength_um).sqrt();
        RefractiveIndex::new(n.re, n.im)
    }

    /// Why the law is not physical, if it is not: ε_∞ ≥ 1 and each oscillator's resonance,
    /// strength and width positive and finite.
    pub fn validate(&self) -> Result<(), LorentzError> {
        if !(self.eps_inf.is_finite() && self.eps_inf >= 1.0) {
            return Err(LorentzError::EpsInf(self.eps_inf));
        }
        if self.oscillators.is_empty() {
            return Err(LorentzError::NoOscillator);
        }
        for (j, o) in self.oscillators.iter().enumerate() {
            for (name, value) in [
                ("resonance_um", o.resonance_um),
                ("strength", o.strength),
                ("damping_um", o.damping_um),
            ] {
                if !(value.is_finite() && value > 0.0) {
                    return Err(LorentzError::Oscillator {
                        oscillator: j + 1,
                        name,
                        value,
                    });
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn silicate() -> LorentzDispersion {
        LorentzDispersion {
            eps_inf: 2.1,
            oscillators: vec![LorentzOscillator {
                resonance_um: 9.3,
                strength: 0.8,
                damping_um: 0.744,
            }],
        }
    }

    /// Closed forms: far from the resonance on the long side ε → ε_∞ + Δε (static), on the short
    /// side ε → ε_∞; at the resonance ε = ε_∞ + i Δε ν₀/γ (purely the damping term).
    #[test]
    fn limits_and_resonance_follow_the_oscillator_formula() {
        let law = silicate();
        let static_eps = law.permittivity(1e6);
        assert!((static_eps.re - 2.9).abs() < 1e-9 && static_eps.im.abs() < 1e-6);
        let optical = law.permittivity(1e-3);
        assert!((optical.re - 2.1).abs() < 1e-3 && optical.im.abs() < 1e-3);
        let at = law.permittivity(9.3);
        let nu0 = 1.0 / 9.3;
        let gamma = 0.744 * nu0 * nu0;
        assert!((at.re - 2.1).abs() < 1e-12);
        assert!((at.im - 0.8 * nu0 / gamma).abs() < 1e-12);
        // Below 1 on the short side of the band (the reststrahlen edge), absorbing near it.
        let n8 = law.index(8.0);
        assert!(n8.n < 1.0 && n8.k > 0.3, "{n8:?}");
        let n = law.index(11.5);
        let eps = law.permittivity(11.5);
        assert!((Complex64::new(n.n, n.k).powi(2) - eps).norm() < 1e-12);
    }

    #[test]
    fn unphysical_laws_are_refused() {
        let mut law = silicate();
        assert!(law.validate().is_ok());
        law.oscillators[0].damping_um = 0.0;
        assert!(law
            .validate()
            .unwrap_err()
            .to_string()
            .contains("damping_um"));
        law = silicate();
        law.eps_inf = 0.5;
        assert!(law.validate().unwrap_err().to_string().contains("eps_inf"));
    }
}
