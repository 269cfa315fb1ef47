//! Optics primitives: Fresnel coefficients of an absorbing medium, Jones/Mueller/Stokes algebra in
//! the SCATMECH "psps" convention, and Planck band radiance. Nothing here knows about microfacets.

pub mod band_nodes;
mod brightness;
mod dispersion;
pub mod frame;
mod fresnel;
mod planck;
mod polarization;
mod realizability;

pub use band_nodes::{SpectralMix, TableMissesBand, WavelengthNodes};
pub use brightness::TemperatureLookup;
pub use dispersion::{LorentzDispersion, LorentzError, LorentzOscillator};
pub use frame::{
    camera_frame_turn, rotation_between_frames, stokes_to_camera_frame, Direction, OutgoingFrame,
};
pub use fresnel::{fresnel_amplitudes, FresnelFractions, RefractiveIndex};
pub use planck::{
    ln_spectral_radiance, spectral_radiance, valid_temperature, Band, OpticsError,
    MAX_TEMPERATURE_K, MAX_WAVELENGTH_UM, MIN_WAVELENGTH_UM, STEFAN_BOLTZMANN,
};
pub use polarization::{
    fresnel_mueller, jones_to_mueller, rotate_stokes, FrameTurn, Mueller, Stokes,
};
pub use realizability::{coherency_eigenvalues, coherency_matrix, Coherency};
