//! One part's `thermal` keys, checked (docs/design.md §1.8, §2.4): its layer stack, back
//! boundary, surface properties, internal heat schedule and enclosure.

use super::super::config::{
    BackConfig, InternalHeatConfig, LayerMaterialConfig, PartThermalConfig,
};
use super::super::{Back, Layer, LayerMaterial, LayerStack, ThermalError};
use super::Enclosure;
use crate::optics::{valid_temperature, MAX_TEMPERATURE_K};
use crate::text::number;
use std::collections::BTreeMap;

/// One part's thermal description.
pub struct SurfaceThermal {
    pub stack: LayerStack,
    pub back: Back,
    pub solar_absorptance: f64,
    /// Thermal hemispherical emissivity (given, or the material's ε_0 of §1.4).
    pub emissivity: f64,
    /// Front convective coefficient; `None` = [`super::convection::mcadams_coefficient`].
    pub convection_w_m2k: Option<f64>,
    pub internal_heat: Schedule,
    /// Index into [`ThermalSetup::enclosures`] of the node the back face sees (its back is then
    /// `Back::Convective` with the node's temperature in place of the outside air).
    pub enclosure: Option<usize>,
    /// Fraction of the solar irradiance on the front that enters the enclosure (0 unless glazing).
    pub solar_transmittance: f64,
}

/// A quantity piecewise linear in time (s), constant beyond its first and last points.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    points: Vec<(f64, f64)>,
}

impl Schedule {
    pub fn constant(value: f64) -> Schedule {
        Schedule {
            points: vec![(0.0, value)],
        }
    }

    /// The value at `time_s`. Equal times make a step (the later point wins from then on).
    pub fn at(&self, time_s: f64) -> f64 {
        let p = &self.points;
        let after = p.partition_point(|&(t, _)| t <= time_s);
        match after {
            0 => p[0].1,
            n if n == p.len() => p[n - 1].1,
            n => {
                let ((t0, v0), (t1, v1)) = (p[n - 1], p[n]);
                v0 + (v1 - v0) * (time_s - t0) / (t1 - t0)
            }
        }
    }
}

/// A part's `thermal` key that cannot be used; messages start with the key at fault.
#[derive(Debug, thiserror::Error)]
pub enum PartThermalError {
    #[error("stack is empty: give [[layer name, thickness_m], …] front to back")]
    EmptyStack,
    #[error(
        "stack: layer '{}' is not defined in [thermal.layers] (defined: {})",
        crate::text::shown(name),
        if defined.is_empty() { "none".to_owned() } else { crate::text::shown_at_most(&defined.join(", "), 200) }
    )]
    UnknownLayer { name: String, defined: Vec<String> },
    #[error("stack: {0}")]
    Stack(ThermalError),
    #[error("{key} = {} must be within [0, 1]", number(*value))]
    Fraction { key: &'static str, value: f64 },
    #[error(
        "{key} = {} W/m²/K is outside 0…{MAX_CONVECTION_W_M2K} W/m²/K (still air ~5, forced \
         water ~1e4)",
        number(*value)
    )]
    Convection { key: &'static str, value: f64 },
    #[error(
        "back.temperature_k = {} must be within (0, {MAX_TEMPERATURE_K}] K",
        number(*temperature_k)
    )]
    BackTemperature { temperature_k: f64 },
    #[error("internal_heat_w_m2 is an empty schedule: give [[time_h, w_m2], …]")]
    EmptySchedule,
    #[error(
        "enclosure: '{}' is not defined in [thermal.enclosures] (defined: {})",
        crate::text::shown(name),
        if defined.is_empty() { "none".to_owned() } else { crate::text::shown_at_most(&defined.join(", "), 200) }
    )]
    UnknownEnclosure { name: String, defined: Vec<String> },
    #[error(
        "enclosure needs back = {{ convection_w_m2k = … }}: the coefficient between the back face \
         and the enclosed air"
    )]
    EnclosureBack,
    #[error(
        "solar_transmittance needs enclosure = \"NAME\": the sunlight through the part enters an \
         enclosure"
    )]
    TransmittanceWithoutEnclosure,
    #[error(
        "solar_absorptance + solar_transmittance = {} + {} is more than 1",
        number(*absorptance), number(*transmittance)
    )]
    AbsorbedAndTransmitted {
        absorptance: f64,
        transmittance: f64,
    },
    #[error(
        "internal_heat_w_m2 has a point [{} h, {} W/m²] outside ±{} h, ±{} W/m²",
        number(*time_h), number(*w_m2), number(MAX_SCHEDULE_H), number(MAX_INTERNAL_HEAT_W_M2)
    )]
    OutOfRangePoint { time_h: f64, w_m2: f64 },
    #[error(
        "internal_heat_w_m2: times must not decrease ({} h after {} h)",
        number(*later_h), number(*earlier_h)
    )]
    Decreasing { later_h: f64, earlier_h: f64 },
}

/// Largest convective coefficient (W m⁻² K⁻¹), front or back: forced water flow is ~1e4.
pub const MAX_CONVECTION_W_M2K: f64 = 1e5;
/// Largest |internal heat flux| (W m⁻²): a thousand times an engine under a hood.
pub const MAX_INTERNAL_HEAT_W_M2: f64 = 1e6;
/// Largest |time| of a schedule point (h): beyond any run ([`MAX_STEPS`](super::MAX_STEPS) minutes is ~4 years).
pub const MAX_SCHEDULE_H: f64 = 1e6;

/// One part's keys, checked, with its thermal `emissivity` (given, or its material's);
/// `enclosures` are the names of `[thermal.enclosures]` in order.
pub fn resolve_part(
    part: &PartThermalConfig,
    layers: &BTreeMap<String, LayerMaterialConfig>,
    enclosures: &[Enclosure],
    emissivity: f64,
) -> Result<SurfaceThermal, PartThermalError> {
    let stack = resolve_stack(&part.stack, layers)?;
    let fraction = |key: &'static str, value: f64| {
        if value.is_finite() && (0.0..=1.0).contains(&value) {
            Ok(value)
        } else {
            Err(PartThermalError::Fraction { key, value })
        }
    };
    fraction("solar_absorptance", part.solar_absorptance)?;
    fraction("emissivity", emissivity)?;
    if let Some(h) = part.convection_w_m2k {
        convection("convection_w_m2k", h)?;
    }
    let back = resolve_back(&part.back)?;
    let (enclosure, solar_transmittance) = resolve_enclosure_keys(part, &back, enclosures)?;
    Ok(SurfaceThermal {
        stack,
        back,
        solar_absorptance: part.solar_absorptance,
        emissivity,
        convection_w_m2k: part.convection_w_m2k,
        internal_heat: resolve_schedule(&part.internal_heat_w_m2)?,
        enclosure,
        solar_transmittance,
    })
}

/// A part's `enclosure` (its index) and `solar_transmittance` (0 when not given): the enclosure
/// defined, the back convective (its coefficient couples the face to the node), and the light
/// transmitted entering an enclosure and no more than what is not absorbed.
fn resolve_enclosure_keys(
    part: &PartThermalConfig,
    back: &Back,
    enclosures: &[Enclosure],
) -> Result<(Option<usize>, f64), PartThermalError> {
    let enclosure =
        match &part.enclosure {
            None => None,
            Some(name) => Some(enclosures.iter().position(|e| &e.name == name).ok_or_else(
                || PartThermalError::UnknownEnclosure {
                    name: name.clone(),
                    defined: enclosures.iter().map(|e| e.name.clone()).collect(),
                },
            )?),
        };
    if enclosure.is_some() && !matches!(back, Back::Convective { .. }) {
        return Err(PartThermalError::EnclosureBack);
    }
    let Some(transmittance) = part.solar_transmittance else {
        return Ok((enclosure, 0.0));
    };
    if !(transmittance.is_finite() && (0.0..=1.0).contains(&transmittance)) {
        return Err(PartThermalError::Fraction {
            key: "solar_transmittance",
            value: transmittance,
        });
    }
    if enclosure.is_none() {
        return Err(PartThermalError::TransmittanceWithoutEnclosure);
    }
    if part.solar_absorptance + transmittance > 1.0 {
        return Err(PartThermalError::AbsorbedAndTransmitted {
            absorptance: part.solar_absorptance,
            transmittance,
        });
    }
    Ok((enclosure, transmittance))
}

/// `[[layer name, thickness_m], …]` front to back, each name one of `layers`.
fn resolve_stack(
    entries: &[(String, f64)],
    layers: &BTreeMap<String, LayerMaterialConfig>,
) -> Result<LayerStack, PartThermalError> {
    if entries.is_empty() {
        return Err(PartThermalError::EmptyStack);
    }
    let mut stack = Vec::with_capacity(entries.len());
    for (name, thickness) in entries {
        let m = layers
            .get(name)
            .ok_or_else(|| PartThermalError::UnknownLayer {
                name: name.clone(),
                defined: layers.keys().cloned().collect(),
            })?;
        let material = LayerMaterial::new(
            name,
            m.conductivity_w_mk,
            m.density_kg_m3,
            m.heat_capacity_j_kgk,
        );
        stack.push(Layer::new(material, *thickness));
    }
    LayerStack::new(stack).map_err(PartThermalError::Stack)
}

fn resolve_back(back: &BackConfig) -> Result<Back, PartThermalError> {
    match *back {
        BackConfig::Adiabatic | BackConfig::Keyword(_) => Ok(Back::Adiabatic),
        BackConfig::Fixed(f) if valid_temperature(f.temperature_k) && f.temperature_k > 0.0 => {
            Ok(Back::Fixed(f.temperature_k))
        }
        BackConfig::Fixed(f) => Err(PartThermalError::BackTemperature {
            temperature_k: f.temperature_k,
        }),
        BackConfig::Convective(c) => Ok(Back::Convective {
            h_w_m2k: convection("back.convection_w_m2k", c.convection_w_m2k)?,
            air_k: None,
        }),
    }
}

/// A convective coefficient within 0…[`MAX_CONVECTION_W_M2K`].
fn convection(key: &'static str, value: f64) -> Result<f64, PartThermalError> {
    if (0.0..=MAX_CONVECTION_W_M2K).contains(&value) {
        Ok(value)
    } else {
        Err(PartThermalError::Convection { key, value })
    }
}

fn resolve_schedule(heat: &InternalHeatConfig) -> Result<Schedule, PartThermalError> {
    let points: Vec<(f64, f64)> = match heat {
        InternalHeatConfig::Constant(q) => vec![(0.0, *q)],
        InternalHeatConfig::Schedule(points) => {
            points.iter().map(|&(h, q)| (h * 3600.0, q)).collect()
        }
    };
    if points.is_empty() {
        return Err(PartThermalError::EmptySchedule);
    }
    if let Some((t, q)) = points
        .iter()
        .find(|(t, q)| !(t.abs() <= MAX_SCHEDULE_H * 3600.0 && q.abs() <= MAX_INTERNAL_HEAT_W_M2))
    {
        return Err(PartThermalError::OutOfRangePoint {
            time_h: t / 3600.0,
            w_m2: *q,
        });
    }
    if let Some(w) = points.windows(2).find(|w| w[1].0 < w[0].0) {
        return Err(PartThermalError::Decreasing {
            later_h: w[1].0 / 3600.0,
            earlier_h: w[0].0 / 3600.0,
        });
    }
    Ok(Schedule { points })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedules_interpolate_step_and_hold() {
        let s = resolve_schedule(&InternalHeatConfig::Schedule(vec![
            (1.0, 0.0),
            (1.0, 400.0),
            (2.0, 400.0),
            (3.0, 0.0),
        ]))
        .unwrap();
        assert_eq!(s.at(0.0), 0.0);
        assert_eq!(s.at(3599.0), 0.0);
        assert_eq!(s.at(3600.0), 400.0);
        assert_eq!(s.at(7200.0), 400.0);
        assert!((s.at(9000.0) - 200.0).abs() < 1e-12);
        assert_eq!(s.at(1e6), 0.0);
        assert_eq!(Schedule::constant(5.0).at(-3.0), 5.0);
    }

    #[test]
    fn decreasing_schedules_are_refused() {
        let e = resolve_schedule(&InternalHeatConfig::Schedule(vec![(2.0, 0.0), (1.0, 1.0)]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("must not decrease (1 h after 2 h)"), "{e}");
    }
}
