//! `#` comments that explain a material TOML to whoever opens it: a line
//! above each key of the fixed tables, with its unit and meaning, and a block above each table.
//! Tables whose keys vary (per Mueller element, per parameter) carry only their block. The
//! comments are added to the serialized document with `toml_edit`, so the values are exactly
//! what serde wrote; docs/materials.md has the longer explanations.

use crate::pbrdf::{DistributionKind, Parameter};
use std::borrow::Cow;
use toml_edit::{DocumentMut, Item, Table};

/// Above the first key of the file.
const HEADER: &str =
    "irpol material library entry: the pBRDF model (docs/design.md §1.3) and how it was fitted.\n\
Every field is explained in docs/materials.md; values are as the fit wrote them.";

const TOP: &[(&str, &str)] = &[
    (
        "name",
        "the material's name (the measurement's '# material:' line)",
    ),
    ("tool_version", "the irpol version that wrote this file"),
];

/// The comment block above each table, by its dotted path.
const TABLES: &[(&str, &str)] = &[
    (
        "model",
        "The pBRDF: F = P(θ) G M(β) / (4 cosθ cosθ_i cosθ_r) + (ρ_d/π) diag(1,0,0,0), in sr⁻¹.\n\
               The renderer and `irpol eval` read only this table.",
    ),
    (
        "fit",
        "How the model was fitted (provenance, optimizer, quality); `irpol report` and\n\
             `irpol library` read it, the renderer does not.",
    ),
    (
        "fit.fixed_parameters",
        "Parameters held fixed during the fit (--fix, or left out of --free), at these values.",
    ),
    (
        "fit.merged_sources",
        "Further measurement files of this material and wavelength fitted with `source` as\n\
                            repeat measurements (their rows follow its rows).",
    ),
    (
        "fit.source_data",
        "The fingerprint of the source's parsed data (values, not bytes): `irpol report` rebuilds\n\
         after comment or layout edits and says which rows changed otherwise.",
    ),
    (
        "fit.merged_sources.source_data",
        "The fingerprint of this file's parsed data (as [fit.source_data]).",
    ),
    (
        "fit.selection",
        "The rows of the sources that were fitted (--wavelength, --theta-i); `irpol report`\n\
         rebuilds from the same rows.",
    ),
    (
        "fit.settings",
        "What reproduces the fit besides optimizer and seed: bounds, distribution choice,\n\
                      each stage's stopping rules, robust loss, where the uncertainties came from.",
    ),
    (
        "fit.rmse",
        "Root-mean-square residual (model − measured) per Mueller element, sr⁻¹.",
    ),
    (
        "fit.uncertainty",
        "1-σ uncertainty of each free parameter, in its own unit: from the Jacobian at the\n\
                         optimum, scaled by the reduced χ².",
    ),
    (
        "fit.alternative",
        "The other slope distribution's best fit on the same data, for comparison.",
    ),
    ("fit.alternative.model", "Its model (keys as in [model])."),
    (
        "model.dispersion",
        "The Lorentz law the spectral fit used (docs/design.md §1.9): ε(ν) = eps_inf + Σ strength ν_j² /\n\
         (ν_j² − ν² − iγ_jν), ν = 1/λ, ν_j = 1/resonance_um, γ_j = damping_um/resonance_um²;\n\
         n and k above are this law at wavelength_um.",
    ),
    (
        "model.dispersion.oscillators",
        "One oscillator: resonance wavelength (µm), strength Δε, line width in wavelength (µm).",
    ),
    (
        "fit.uncertainty_per_wavelength",
        "1-σ errors of the per-wavelength parameters, one per wavelength_um (a law's n, k: from\n\
         the law's covariance); [fit.uncertainty] holds the shared ones.",
    ),
    (
        "fit.wavelengths",
        "The spectral fit at one wavelength: its points and χ² per observation.",
    ),
    (
        "fit.dispersion",
        "How n, k depend on λ (table or lorentz:N) and the AIC/BIC of the table and of a law.",
    ),
    (
        "fit.profile_bounds.*",
        "What the data allow for a parameter whose ± would mislead (undetermined, or bounded\n\
         from one side only): one-sided profile-likelihood bounds (docs/materials.md).",
    ),
];

/// The keys of `[model]` that are not model parameters (those explain themselves in
/// [`crate::pbrdf::terms`]); `distribution` lists the laws of [`DistributionKind`].
const MODEL: &[(&str, &str)] = &[
    ("facet", "which side of the facets reflects: \"external\" (relative index N, the default) or \"internal\" (1/N, inside grains)"),
    ("shadowing", "shadowing/masking G: \"none\" (G = 1), \"torrance-sparrow\" or \"smith\" (energy conserving)"),
    ("wavelength_um", "wavelength of the measurement the model was fitted to, µm"),
];

/// Every key of `[model]` with its comment.
fn model_keys() -> Vec<(&'static str, Cow<'static, str>)> {
    let laws: Vec<String> = DistributionKind::ALL
        .iter()
        .map(|kind| format!("\"{kind}\" ({})", kind.description()))
        .collect();
    let distribution = format!("facet slope distribution P(θ): {}", laws.join(" or "));
    let parameters = Parameter::ALL
        .iter()
        .map(|p| (p.name(), Cow::Borrowed(p.info().comment)));
    let others = MODEL.iter().map(|&(key, text)| (key, Cow::Borrowed(text)));
    std::iter::once(("distribution", Cow::Owned(distribution)))
        .chain(parameters)
        .chain(others)
        .collect()
}

const FIT: &[(&str, &str)] = &[
    ("source", "the measurement CSV as given to `irpol fit` (relative to where it ran)"),
    ("source_sha256", "SHA-256 of its bytes: `irpol report` refuses to rebuild from a changed file"),
    ("layout", "the instrument layout (docs/design.md §2.8) the sources were read through (--layout)"),
    ("angles", "how the sources' angles were read (--angles): radians converted to degrees, or degrees that look like radians"),
    ("points", "measured geometries (rows) used, over all source files"),
    ("elements", "Mueller elements fitted (the columns present)"),
    ("free_parameters", "parameters the fit varied (--free); the others are held at their [model] values"),
    ("optimizer", "optimizer stages: ga (seeded genetic search), nm (Nelder–Mead), lm (Levenberg–Marquardt)"),
    ("seed", "seed of the genetic stage"),
    ("iterations", "optimizer iterations over all stages"),
    ("evaluations", "model evaluations over all stages"),
    ("cost", "χ² = Σ ((model − measured)/σ)² over every element of every row (a robust loss: its sum)"),
    ("reduced_chi2", "cost / degrees_of_freedom: ≈ 1 when the model fits within the stated uncertainties"),
    ("degrees_of_freedom", "observations (points × elements) minus free parameters"),
    ("aic", "Akaike information criterion, cost + 2p (p free parameters): lower is better"),
    ("bic", "Bayesian information criterion, cost + p ln N (N observations): lower is better"),
    ("termination", "why the last optimizer stage stopped"),
    ("correlation", "correlation matrix of the free parameters, rows and columns in free_parameters order"),
    ("undetermined", "free parameters the data do not determine (no sensitivity, |ρ| > 0.999 or a huge error)"),
    ("at_bound", "free parameters resting on a bound of their search interval"),
    ("pinned", "of those, the ones at a bound other than zero: the fit does not describe its data"),
    ("model_choice", "which slope distribution was kept, by ΔAIC and ΔBIC"),
    ("convergence", "best cost after each genetic generation (the first global_iterations), then each local iteration"),
    ("global_iterations", "how many entries of convergence are genetic generations"),
];

const MERGED_SOURCE: &[(&str, &str)] = &[
    (
        "source",
        "a further measurement CSV as given to `irpol fit`",
    ),
    ("source_sha256", "SHA-256 of its bytes"),
    ("points", "its rows"),
];

const SELECTION: &[(&str, &str)] = &[
    (
        "wavelength_um",
        "the one wavelength kept of a file of several, µm",
    ),
    (
        "theta_i_deg",
        "the incidence angles kept, degrees (rows within 0.05° of one)",
    ),
];

const ALTERNATIVE: &[(&str, &str)] = &[
    ("cost", "its χ²"),
    ("reduced_chi2", "its cost / degrees of freedom"),
    ("aic", "its Akaike information criterion"),
    ("bic", "its Bayesian information criterion"),
];

const PROFILE_BOUND: &[(&str, &str)] = &[
    (
        "lower",
        "the parameter is above this (absent: the data allow the search interval's lower end)",
    ),
    (
        "upper",
        "the parameter is below this (absent: the data allow the search interval's upper end)",
    ),
    ("confidence", "the confidence of each side's bound"),
];

/// The keys of one table explained line by line.
#[derive(Clone, Copy)]
enum Keys {
    Fixed(&'static [(&'static str, &'static str)]),
    /// `[model]` and its copies: [`model_keys`].
    Model,
}

impl Keys {
    fn comments(self) -> Vec<(&'static str, Cow<'static, str>)> {
        match self {
            Keys::Fixed(keys) => keys
                .iter()
                .map(|&(key, text)| (key, Cow::Borrowed(text)))
                .collect(),
            Keys::Model => model_keys(),
        }
    }
}

/// The keys explained line by line, by table path; other tables get only their block. A path
/// ending in `.*` stands for every subtable of its parent (one per parameter).
const KEYED: &[(&str, Keys)] = &[
    ("model", Keys::Model),
    ("fit", Keys::Fixed(FIT)),
    ("fit.merged_sources", Keys::Fixed(MERGED_SOURCE)),
    ("fit.selection", Keys::Fixed(SELECTION)),
    ("fit.alternative", Keys::Fixed(ALTERNATIVE)),
    ("fit.alternative.model", Keys::Model),
    ("fit.profile_bounds.*", Keys::Fixed(PROFILE_BOUND)),
];

/// The entry of `entries` for the table at `path`: its own, or its parent's `.*` entry.
fn entry_for<'e, T>(entries: &'e [(&str, T)], path: &str) -> Option<&'e T> {
    let wildcard = path
        .rsplit_once('.')
        .map(|(parent, _)| format!("{parent}.*"));
    entries
        .iter()
        .find(|(p, _)| *p == path || Some(*p) == wildcard.as_deref())
        .map(|(_, entry)| entry)
}

/// `text` (a serialized material) with the comments added; the values are untouched.
/// `identification` lists the fitted parameters the data do not determine, with why
/// ([`super::FitRecord::identification`]): each gets a line of its own above its `[model]` key.
pub(super) fn commented(
    text: &str,
    identification: &[(String, String)],
) -> Result<String, toml_edit::TomlError> {
    let mut document: DocumentMut = text.parse()?;
    let root = document.as_table_mut();
    explain_keys(root, &Keys::Fixed(TOP).comments());
    if let Some(mut name) = root.key_mut(TOP[0].0) {
        let explained = comment_lines(TOP[0].1);
        name.leaf_decor_mut()
            .set_prefix(format!("{}\n{explained}", comment_lines(HEADER)));
    }
    decorate_tables(root, "");
    if let Some(Item::Table(model)) = root.get_mut("model") {
        mark_undetermined(model, identification);
    }
    Ok(document.to_string())
}

/// Adds `# NOT DETERMINED by the data: why` above each `[model]` key that `identification`
/// names (a spectral coordinate such as `n(0.351um)` marks its table, `n`).
fn mark_undetermined(model: &mut Table, identification: &[(String, String)]) {
    for (name, why) in identification {
        // A dispersion law's coordinates (cauchy_a, eps_inf, …) shape the n table.
        let key = match name.split('(').next().unwrap_or(name) {
            base if model.contains_key(base) => base,
            _ => "n",
        };
        if let Some(mut key) = model.key_mut(key) {
            let decor = key.leaf_decor_mut();
            let prefix = decor
                .prefix()
                .and_then(|p| p.as_str())
                .unwrap_or("")
                .to_owned();
            decor.set_prefix(format!(
                "{prefix}{}",
                comment_lines(&format!("NOT DETERMINED by the data: {name} {why}"))
            ));
        }
    }
}

/// Comments the subtables of `table` (whose dotted path is `path`) and their keys, recursively.
fn decorate_tables(table: &mut Table, path: &str) {
    for (key, item) in table.iter_mut() {
        let path = if path.is_empty() {
            key.get().to_owned()
        } else {
            format!("{path}.{}", key.get())
        };
        let tables: Vec<&mut Table> = match item {
            Item::Table(table) => vec![table],
            Item::ArrayOfTables(array) => array.iter_mut().collect(),
            _ => continue,
        };
        for (index, table) in tables.into_iter().enumerate() {
            if let (0, Some(block)) = (index, entry_for(TABLES, &path)) {
                table
                    .decor_mut()
                    .set_prefix(format!("\n{}", comment_lines(block)));
            }
            if let Some(keys) = entry_for(KEYED, &path) {
                explain_keys(table, &keys.comments());
            }
            decorate_tables(table, &path);
        }
    }
}

/// A comment line above each key of `table` that `comments` explains.
fn explain_keys(table: &mut Table, comments: &[(&str, Cow<'static, str>)]) {
    for (key, comment) in comments {
        if let Some(mut key) = table.key_mut(key) {
            key.leaf_decor_mut().set_prefix(comment_lines(comment));
        }
    }
}

/// `text` as `# ` lines, each ending in a newline.
fn comment_lines(text: &str) -> String {
    text.lines()
        .map(|line| format!("# {}\n", line.trim_start()))
        .collect()
}

#[cfg(test)]
pub(super) fn explained_keys(path: &str) -> Option<Vec<&'static str>> {
    let keys = if path.is_empty() {
        Some(Keys::Fixed(TOP))
    } else {
        entry_for(KEYED, path).copied()
    };
    keys.map(|keys| keys.comments().iter().map(|(key, _)| *key).collect())
}

#[cfg(test)]
pub(super) fn has_block(path: &str) -> bool {
    entry_for(TABLES, path).is_some()
}
