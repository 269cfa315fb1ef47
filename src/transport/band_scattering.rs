//! A band material's scattering of light from a surface hit (docs/design.md §1.9): each source
//! (the hit's emission, what the hit reflects, the environment a correction replaces, the sun)
//! weighted over the material's wavelength nodes by its own spectrum. Used by the path
//! integrator ([`super::path`]).

use crate::emitter::SUN_TEMPERATURE_K;
use crate::optics::band_nodes::{BrightnessGrid, FractionsByRadiance};
use crate::optics::{Direction, SpectralMix, Stokes};
use crate::pbrdf::BandPbrdf;

/// The spectral shares of the sources a band material scatters (docs/design.md §1.9, module docs).
pub(super) struct BandSources {
    /// Planck fractions of a grey source by its band radiance (a surface hit, the environment).
    pub(super) by_radiance: FractionsByRadiance,
    /// Planck fractions of the sun: a 5772 K blackbody through the band.
    pub(super) sun: Vec<f64>,
}

/// Light emitted by a surface hit, in the receiver's incident frame (the path integrator's
/// `emitted_toward`).
pub(super) struct EmittedLight {
    /// L_bb(T) of the hit.
    pub(super) radiance: f64,
    /// Its (ε0, ε1) toward the receiver (band-integrated for a band material).
    pub(super) emissivity: [f64; 2],
    /// (ε0, ε1) of a band material at each wavelength node; `None` for a grey one.
    pub(super) per_node: Option<Vec<[f64; 2]>>,
    /// The unit linear polarization (0, 1, 0, 0) of the hit's outgoing frame, rotated into the
    /// receiver's incident frame: the hit emits L (ε0 e₀ + ε1 u).
    pub(super) polarization: Stokes,
}

/// Where a band material scatters: the incident and scattered directions (local frame) and the
/// shadowing factors of both.
pub(super) struct BandScattering<'a> {
    pub(super) incident: &'a Direction,
    pub(super) scattered: &'a Direction,
    pub(super) masking: [f64; 2],
}

/// One sample of F (S_in − L_env e₀) at a band material (docs/design.md §1.9), S_in the light from a
/// surface hit, each part with its own spectrum over the wavelength nodes m:
/// - what the hit emits, L_bb(T) (ε0 e₀ + ε1 u) with u its polarization: node by node
///   p_m(T) (ε0_m e₀ + ε1_m u), p the Planck shares at the hit's temperature and ε_m its
///   emissivity at λ_m (constant for a grey hit);
/// - what it reflects, S_in less its emission, taken as a uniform grey source at the
///   brightness temperature T_s of (that light / the hit's mean reflectance) reflected by the
///   hit (Kirchhoff: a uniform source L_s is reflected as L_s ((1 − ε0_m) e₀ − ε1_m u)), with
///   L_s such that its S0 is exact; the polarization the model misses keeps the shares f(T_s);
/// - the environment it replaces, grey at its brightness temperature.
pub(super) fn band_scattering(
    band: &BandPbrdf,
    sources: &BandSources,
    at: &BandScattering,
    s_in: &Stokes,
    emitted: &EmittedLight,
    environment: f64,
) -> Stokes {
    let nodes = band.nodes().len();
    let per_node = emitted.per_node.as_ref().filter(|e| e.len() == nodes);
    let emissivity = |m: usize| per_node.map_or(emitted.emissivity, |e| e[m]);
    let [e0, e1] = emitted.emissivity;
    let hit = emitted.radiance;
    let unpolarized = Stokes::new(1.0, 0.0, 0.0, 0.0);
    let reflected = s_in - (unpolarized * e0 + emitted.polarization * e1) * hit;
    let source = sources.by_radiance.at(reflected[0] / (1.0 - e0).max(1e-9));
    let reflectance: f64 = (0..nodes)
        .map(|m| source.weight(m) * (1.0 - emissivity(m)[0]))
        .sum();
    let source_radiance = if reflectance > 1e-12 {
        reflected[0] / reflectance
    } else {
        0.0
    };
    let planck = sources.by_radiance.at(hit);
    let (mut along_e0, mut along_u) = (vec![0.0; nodes], vec![0.0; nodes]);
    let mut modelled_u = 0.0;
    for m in 0..nodes {
        let [em0, em1] = emissivity(m);
        let (p, f) = (planck.weight(m), source.weight(m));
        along_e0[m] = p * em0 * hit + f * (1.0 - em0) * source_radiance;
        along_u[m] = p * em1 * hit - f * em1 * source_radiance;
        modelled_u -= f * em1 * source_radiance;
    }
    // What the uniform-source model leaves out of the reflected light (its S0 is exact).
    let unmodelled = reflected - unpolarized * reflected[0] - emitted.polarization * modelled_u;
    let [mueller_e0, mueller_u, mueller_rest, mueller_environment] = band.mueller_mixtures(
        at.incident,
        at.scattered,
        at.masking,
        [
            SpectralMix::fixed(&along_e0),
            SpectralMix::fixed(&along_u),
            source,
            sources.by_radiance.at(environment),
        ],
    );
    mueller_e0.column(0).into_owned() + mueller_u * emitted.polarization + mueller_rest * unmodelled
        - mueller_environment.column(0) * environment
}

impl BandSources {
    pub(super) fn new(band: &BandPbrdf, grid: &BrightnessGrid) -> BandSources {
        BandSources {
            by_radiance: FractionsByRadiance::new(band.nodes(), grid),
            sun: band.nodes().planck_fractions(SUN_TEMPERATURE_K),
        }
    }
}
