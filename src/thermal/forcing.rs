//! What drives one vertex's layer stack at one instant (docs/design.md §1.8): the front surface's
//! energy balance inputs, the back boundary and the internal heat, each checked, and their linear
//! interpolation in time within a step.

use super::layers::ThermalError;
use crate::text::number;

use crate::optics::STEFAN_BOLTZMANN;

/// Front-surface forcing of §1.8 at one instant, with the sun and sky already reduced to numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrontForcing {
    /// Absorbed solar irradiance α_s [E_dn max(0, n·s) V_sun + E_dh F_sky] (W m⁻²).
    pub absorbed_w_m2: f64,
    /// Absorbed long-wave ε [E_lw F_sky + σ T_g⁴ (1 − F_sky)] (W m⁻², already times ε).
    pub longwave_in_w_m2: f64,
    /// Thermal hemispherical emissivity ε of the surface (0…1).
    pub emissivity: f64,
    /// Convective coefficient h (W m⁻² K⁻¹).
    pub h_w_m2k: f64,
    /// Air temperature (K).
    pub air_k: f64,
}

impl FrontForcing {
    /// Net flux into the surface at surface temperature `surface_k` (W m⁻²), §1.8.
    pub fn net_flux_w_m2(&self, surface_k: f64) -> f64 {
        self.absorbed_w_m2 + self.longwave_in_w_m2
            - self.emissivity * STEFAN_BOLTZMANN * surface_k.powi(4)
            + self.h_w_m2k * (self.air_k - surface_k)
    }

    pub(super) fn lerp(&self, end: &Self, s: f64) -> Self {
        let l = |a: f64, b: f64| a + (b - a) * s;
        Self {
            absorbed_w_m2: l(self.absorbed_w_m2, end.absorbed_w_m2),
            longwave_in_w_m2: l(self.longwave_in_w_m2, end.longwave_in_w_m2),
            emissivity: l(self.emissivity, end.emissivity),
            h_w_m2k: l(self.h_w_m2k, end.h_w_m2k),
            air_k: l(self.air_k, end.air_k),
        }
    }

    pub(super) fn validate(&self) -> Result<(), ThermalError> {
        let bad = |what: &str, v: f64, rule: &str| {
            Err(ThermalError::InvalidInput(format!(
                "front forcing {what} must be {rule}, got {}",
                number(v)
            )))
        };
        if !(self.absorbed_w_m2.is_finite() && self.absorbed_w_m2 >= 0.0) {
            return bad("absorbed_w_m2", self.absorbed_w_m2, "finite and >= 0");
        }
        if !(self.longwave_in_w_m2.is_finite() && self.longwave_in_w_m2 >= 0.0) {
            return bad("longwave_in_w_m2", self.longwave_in_w_m2, "finite and >= 0");
        }
        if !(0.0..=1.0).contains(&self.emissivity) {
            return bad("emissivity", self.emissivity, "in [0, 1]");
        }
        if !(self.h_w_m2k.is_finite() && self.h_w_m2k >= 0.0) {
            return bad("h_w_m2k", self.h_w_m2k, "finite and >= 0");
        }
        if !(self.air_k.is_finite() && self.air_k > 0.0) {
            return bad("air_k", self.air_k, "positive and finite");
        }
        Ok(())
    }
}

/// Back-face boundary (§1.8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Back {
    /// No heat crosses the back face (other than the internal flux).
    Adiabatic,
    /// The back face is held at this temperature (K).
    Fixed(f64),
    /// Convection to air: coefficient h (W m⁻² K⁻¹) and the air temperature (K); `None` takes
    /// the front forcing's air temperature.
    Convective {
        /// Back convective coefficient (W m⁻² K⁻¹).
        h_w_m2k: f64,
        /// Back air temperature (K), or the front air's.
        air_k: Option<f64>,
    },
}

impl Back {
    pub(super) fn lerp(&self, end: &Self, s: f64) -> Self {
        let l = |a: f64, b: f64| a + (b - a) * s;
        match (self, end) {
            (Back::Fixed(a), Back::Fixed(b)) => Back::Fixed(l(*a, *b)),
            (
                Back::Convective {
                    h_w_m2k: ha,
                    air_k: Some(ta),
                },
                Back::Convective {
                    h_w_m2k: hb,
                    air_k: Some(tb),
                },
            ) => Back::Convective {
                h_w_m2k: l(*ha, *hb),
                air_k: Some(l(*ta, *tb)),
            },
            (
                Back::Convective {
                    h_w_m2k: ha,
                    air_k: None,
                },
                Back::Convective {
                    h_w_m2k: hb,
                    air_k: None,
                },
            ) => Back::Convective {
                h_w_m2k: l(*ha, *hb),
                air_k: None,
            },
            // A change of kind takes effect over the whole step, as the end value.
            _ => *end,
        }
    }

    pub(super) fn validate(&self) -> Result<(), ThermalError> {
        let temp_ok = |t: f64| t.is_finite() && t > 0.0;
        match *self {
            Back::Adiabatic => Ok(()),
            Back::Fixed(t) if temp_ok(t) => Ok(()),
            Back::Fixed(t) => Err(ThermalError::InvalidInput(format!(
                "back temperature must be positive and finite, got {} K",
                number(t)
            ))),
            Back::Convective { h_w_m2k, air_k } => {
                if !(h_w_m2k.is_finite() && h_w_m2k >= 0.0) {
                    return Err(ThermalError::InvalidInput(format!(
                        "back h_w_m2k must be finite and >= 0, got {}",
                        number(h_w_m2k)
                    )));
                }
                match air_k {
                    Some(t) if !temp_ok(t) => Err(ThermalError::InvalidInput(format!(
                        "back air temperature must be positive and finite, got {} K",
                        number(t)
                    ))),
                    _ => Ok(()),
                }
            }
        }
    }
}

/// Everything that drives one vertex at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Forcing {
    /// Front surface energy balance inputs.
    pub front: FrontForcing,
    /// Back boundary.
    pub back: Back,
    /// Internal heat flux entering at the back face (W m⁻²; an engine under a hood).
    pub internal_w_m2: f64,
}

impl Forcing {
    pub(super) fn lerp(&self, end: &Self, s: f64) -> Self {
        Self {
            front: self.front.lerp(&end.front, s),
            back: self.back.lerp(&end.back, s),
            internal_w_m2: self.internal_w_m2 + (end.internal_w_m2 - self.internal_w_m2) * s,
        }
    }

    pub(super) fn validate(&self) -> Result<(), ThermalError> {
        self.front.validate()?;
        self.back.validate()?;
        if !self.internal_w_m2.is_finite() {
            return Err(ThermalError::InvalidInput(format!(
                "internal_w_m2 must be finite, got {}",
                number(self.internal_w_m2)
            )));
        }
        Ok(())
    }
}
