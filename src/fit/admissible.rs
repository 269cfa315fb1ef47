//! Whether a fitted model is physically admissible (docs/design.md §1.10, "Physically
//! admissible by default"): its index means a material's index, it conserves energy at every
//! incidence and wavelength, and its Mueller matrices are realizable. The default fit keeps the
//! best admissible set of terms; a forced one that is not admissible is said so.

use super::energy::{largest_reflectance, ENERGY_TOLERANCE};
use crate::material::ModelSpec;
use crate::optics::{coherency_eigenvalues, Mueller};
use crate::text::{number, significant};

/// k at or above which a material absorbs strongly enough for its n to fall below 1 nearby: by
/// Kramers–Kronig, Re ε < 1 lies on the short-wavelength side of a strong absorption band
/// (silicate glass at 8–8.5 µm: n 0.52–0.59 with k 0.54–1.28). Where a material absorbs less
/// at every wavelength it was fitted at, an n below 1 is a stand-in for a term the model lacks
/// (a volume scatterer fitted with facets and an ideal depolarizer ends at n ≈ 0.7).
pub const STRONG_ABSORPTION_K: f64 = 0.5;

/// Relative rounding allowed in a model matrix's smallest coherency eigenvalue.
const REALIZABILITY_ROUNDING: f64 = 1e-9;

/// Why `models` (one per wavelength of one material, with their Mueller matrices at the
/// measured geometries) are not admissible, or `None` when they are.
pub fn why_inadmissible(models: &[&ModelSpec], muellers: &[&[Mueller]]) -> Option<String> {
    why_inadmissible_where(models, |j| {
        muellers
            .get(j)
            .and_then(|rows| rows.iter().position(unrealizable))
    })
}

/// [`why_inadmissible`] with the first row whose model matrix is not realizable
/// ([`unrealizable`]) of each model `j` given by `first_unrealizable(j)`, for a caller that
/// finds it without holding every matrix (a dense scan's are 128 B a row).
pub(super) fn why_inadmissible_where(
    models: &[&ModelSpec],
    first_unrealizable: impl Fn(usize) -> Option<usize>,
) -> Option<String> {
    index_problem(models)
        .or_else(|| energy_problem(models))
        .or_else(|| realizability_problem(models, first_unrealizable))
}

/// Whether a model matrix's coherency matrix has a negative eigenvalue (Cloude), beyond
/// rounding.
pub(super) fn unrealizable(matrix: &Mueller) -> bool {
    coherency_eigenvalues(matrix)[0] < -REALIZABILITY_ROUNDING * matrix.norm()
}

/// n < 1 without strong absorption anywhere in the material's wavelengths.
fn index_problem(models: &[&ModelSpec]) -> Option<String> {
    let absorbs = models.iter().any(|m| m.k >= STRONG_ABSORPTION_K);
    let low = models
        .iter()
        .filter(|m| m.n < 1.0)
        .min_by(|a, b| a.n.total_cmp(&b.n))?;
    (!absorbs).then(|| {
        format!(
            "n = {} < 1 at {} µm without an absorption band (k < {STRONG_ABSORPTION_K})",
            significant(low.n, 4),
            number(low.wavelength_um)
        )
    })
}

/// A hemispherical reflectance above 1 + [`ENERGY_TOLERANCE`] at some incidence.
fn energy_problem(models: &[&ModelSpec]) -> Option<String> {
    models.iter().find_map(|m| {
        let (reflectance, theta_deg) = largest_reflectance(&m.pbrdf().ok()?);
        (reflectance > 1.0 + ENERGY_TOLERANCE).then(|| {
            format!(
                "reflects {} at θ_i = {}° ({} µm)",
                significant(reflectance, 4),
                number(theta_deg),
                number(m.wavelength_um)
            )
        })
    })
}

/// A model matrix whose coherency matrix has a negative eigenvalue (Cloude), the first row of
/// model `j` with one being `first_unrealizable(j)`.
fn realizability_problem(
    models: &[&ModelSpec],
    first_unrealizable: impl Fn(usize) -> Option<usize>,
) -> Option<String> {
    models.iter().enumerate().find_map(|(j, m)| {
        let row = first_unrealizable(j)?;
        Some(format!(
            "model matrix not realizable at row {} ({} µm)",
            row + 1,
            number(m.wavelength_um)
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pbrdf::{FacetSide, Shadowing, SlopeDistribution};

    fn model(n: f64, k: f64, rho_d: f64) -> ModelSpec {
        ModelSpec {
            distribution: SlopeDistribution::Cauchy { sigma: 0.4, q: 2.0 },
            shadowing: Shadowing::Smith,
            n,
            k,
            rho_d,
            facet: FacetSide::External,
            lobe_keys: Default::default(),
            wavelength_um: 1.064,
        }
    }

    #[test]
    fn an_index_below_one_needs_an_absorption_band() {
        // PTFE fitted with facets and an ideal depolarizer (measured at 0.351 µm: 0.661 + 0.413i).
        let stand_in = model(0.661, 0.413, 0.0);
        let why = why_inadmissible(&[&stand_in], &[&[]]).unwrap();
        assert!(why.starts_with("n = 0.661"), "{why}");
        assert!(
            why.contains(" < 1 at 1.064 µm without an absorption band"),
            "{why}"
        );
        // Silicate glass at 8 µm, beside its band.
        let glass = model(0.518, 0.544, 0.0);
        assert_eq!(why_inadmissible(&[&glass], &[&[]]), None);
        // A spectral material: the band at one wavelength admits n < 1 at another.
        let beside = model(0.8, 0.1, 0.0);
        assert_eq!(why_inadmissible(&[&beside, &glass], &[&[], &[]]), None);
    }

    #[test]
    fn energy_above_one_and_unrealizable_matrices_are_named() {
        let bright = model(1.5, 0.0, 1.0);
        let why = why_inadmissible(&[&bright], &[&[]]).unwrap();
        assert!(why.starts_with("reflects 1.0"), "{why}");
        let fine = model(1.5, 0.0, 0.2);
        assert_eq!(why_inadmissible(&[&fine], &[&[]]), None);
        // diag(1, 1, 1, −1) is a mirror's matrix in the wrong handedness: not realizable.
        let mut wrong = Mueller::identity();
        wrong[(3, 3)] = -1.0;
        let why = why_inadmissible(&[&fine], &[&[Mueller::identity(), wrong]]).unwrap();
        assert_eq!(why, "model matrix not realizable at row 2 (1.064 µm)");
    }
}
