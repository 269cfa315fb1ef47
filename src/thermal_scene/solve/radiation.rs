//! The front forcing's radiation terms of docs/design.md §1.8, written once for every path that
//! builds a forcing (one vertex at a time, an enclosure's members, a terrain's blocks of lanes):
//!   incident = E_dn max(0, n·s) V_sun + E_dh F_sky   (α_s of it absorbed, τ of it into an enclosure),
//!   long-wave in = ε [E_lw F_sky + σT_g⁴ (1 − F_sky)]                 with the typed ground,
//!                = ε [E_lw F_sky + σT_g⁴ (1 − n_z)/2 + σT_o⁴ blocked]  with the solved ground,
//! where "blocked" is the rest of the hemisphere, 1 − F_sky − (1 − n_z)/2, radiating at
//! `thermal.ground_temperature_k` when given (T_o), else at the solved ground's T_g.
//!
//! What is the same for every vertex at a sample is [`SampleRadiation`]; what a vertex adds is its
//! normal, its F_sky and its V_sun at that time, so a block of vertices costs a few multiply–adds
//! each.

use crate::optics::STEFAN_BOLTZMANN;
use crate::weather::WeatherSample;
use nalgebra::Vector3;

/// What is below the horizon and in the blocked part of the sky at one sample.
#[derive(Clone, Copy, Debug)]
pub(super) enum GroundEmission {
    /// The typed ground: σT_g⁴ for everything that is not sky.
    Typed { emission_w_m2: f64 },
    /// The solved ground's σT_g⁴ below the horizon, and σT_o⁴ of what blocks the sky.
    Solved { below_w_m2: f64, occluded_w_m2: f64 },
}

/// The sun, the sky and the ground at one sample, the same for every vertex.
#[derive(Clone, Copy, Debug)]
pub(super) struct SampleRadiation {
    pub sun_direction: Vector3<f64>,
    /// E_dn with the sun above the horizon, 0 below it (W m⁻²).
    pub direct_normal_w_m2: f64,
    pub diffuse_horizontal_w_m2: f64,
    pub longwave_down_w_m2: f64,
    pub ground: GroundEmission,
}

impl SampleRadiation {
    /// The sample `w` with the typed ground at `typed_ground_k`, or the solved ground at
    /// `ground_k` (what blocks the sky then at `occluded_k`, or at the ground's own temperature).
    pub fn new(
        w: &WeatherSample,
        typed_ground_k: f64,
        ground_k: Option<f64>,
        occluded_k: Option<f64>,
    ) -> SampleRadiation {
        let sigma = STEFAN_BOLTZMANN;
        let ground = match ground_k {
            None => GroundEmission::Typed {
                emission_w_m2: sigma * typed_ground_k.powi(4),
            },
            Some(g) => GroundEmission::Solved {
                below_w_m2: sigma * g.powi(4),
                occluded_w_m2: sigma * occluded_k.unwrap_or(g).powi(4),
            },
        };
        SampleRadiation {
            sun_direction: w.sun_direction,
            direct_normal_w_m2: if w.sun_direction.z > 0.0 {
                w.direct_normal_w_m2
            } else {
                0.0
            },
            diffuse_horizontal_w_m2: w.diffuse_horizontal_w_m2,
            longwave_down_w_m2: w.longwave_down_w_m2,
            ground,
        }
    }

    /// Solar irradiance on a front of unit normal `normal` (W m⁻²) before absorption, with the
    /// sun visible by the fraction `sun_visible` and the sky by `sky_view`.
    #[inline]
    pub fn incident_w_m2(&self, normal: &Vector3<f64>, sky_view: f64, sun_visible: f64) -> f64 {
        let cos_sun = normal.dot(&self.sun_direction).max(0.0);
        self.direct_normal_w_m2 * cos_sun * sun_visible + self.diffuse_horizontal_w_m2 * sky_view
    }

    /// Absorbed long-wave (W m⁻², already times ε) of a front of emissivity `emissivity`,
    /// normal z-component `normal_z` and sky view `sky_view`.
    #[inline]
    pub fn longwave_in_w_m2(&self, emissivity: f64, normal_z: f64, sky_view: f64) -> f64 {
        let sky = self.longwave_down_w_m2 * sky_view;
        match self.ground {
            GroundEmission::Typed { emission_w_m2 } => {
                emissivity * (sky + emission_w_m2 * (1.0 - sky_view))
            }
            GroundEmission::Solved {
                below_w_m2,
                occluded_w_m2,
            } => {
                let below = 0.5 * (1.0 - normal_z);
                let blocked = (1.0 - sky_view - below).max(0.0);
                emissivity * (sky + below_w_m2 * below + occluded_w_m2 * blocked)
            }
        }
    }
}

/// Where a time falls among the shadow instants: V_sun is linear between instants `i` and `j`
/// with weight `s` on `j` (a shadow edge crossing a vertex takes one shadow step).
#[derive(Clone, Copy, Debug)]
pub(super) struct ShadowInterval {
    i: usize,
    j: usize,
    s: f64,
}

impl ShadowInterval {
    /// The interval of `time_s` among `instants` shadow instants `step_s` apart.
    pub fn at(time_s: f64, step_s: f64, instants: usize) -> ShadowInterval {
        let x = time_s / step_s;
        let i = (x.floor() as usize).min(instants - 1);
        let j = (i + 1).min(instants - 1);
        let s = (x - i as f64).clamp(0.0, 1.0);
        ShadowInterval { i, j, s }
    }

    /// V_sun from a vertex's visibility at each instant.
    #[inline]
    pub fn visible(&self, lit: &[u8]) -> f64 {
        f64::from(lit[self.i]) * (1.0 - self.s) + f64::from(lit[self.j]) * self.s
    }
}
