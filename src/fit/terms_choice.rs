//! What choosing a model's terms found ([`super::cross_validation`]): each candidate's scores,
//! whether it is physically admissible, and which one was kept by which rule — the record a fit's
//! outcome carries and the table `irpol fit` prints.

use crate::pbrdf::{DistributionKind, ModelTerms};

/// One candidate set of terms as the choice saw it.
#[derive(Clone, Debug, PartialEq)]
pub struct TermsScore {
    pub terms: ModelTerms,
    /// The distribution the candidate's own comparison kept.
    pub distribution: DistributionKind,
    pub free_parameters: usize,
    pub reduced_chi2: f64,
    pub aic: f64,
    /// Σ r² and the number of held-out observations of each fold, when folds were asked for.
    pub folds: Vec<(f64, usize)>,
    /// Why the fitted model is not physically admissible ([`super::admissible`]); `None`: it is.
    pub inadmissible: Option<String>,
}

impl TermsScore {
    /// Mean squared normalized residual over every held-out observation.
    pub fn cv_score(&self) -> Option<f64> {
        let total: f64 = self.folds.iter().map(|f| f.0).sum();
        let count: usize = self.folds.iter().map(|f| f.1).sum();
        (count > 0).then(|| total / count as f64)
    }

    /// The standard error of [`TermsScore::cv_score`]: the spread of the folds' own scores
    /// over √K.
    pub fn cv_standard_error(&self) -> Option<f64> {
        let k = self.folds.len();
        if k < 2 {
            return None;
        }
        let scores: Vec<f64> = self.folds.iter().map(|f| f.0 / f.1.max(1) as f64).collect();
        let mean = scores.iter().sum::<f64>() / k as f64;
        let variance = scores.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (k - 1) as f64;
        Some((variance / k as f64).sqrt())
    }

    /// The scores of several measurements of one material (its wavelengths) as one: χ², AIC
    /// and the folds' residuals added up, the distribution and admissibility of the first.
    pub fn combined(parts: &[TermsScore], inadmissible: Option<String>) -> TermsScore {
        let first = &parts[0];
        let folds = (0..first.folds.len())
            .map(|f| {
                let sum = parts.iter().map(|p| p.folds[f].0).sum();
                (sum, parts.iter().map(|p| p.folds[f].1).sum())
            })
            .collect();
        TermsScore {
            terms: first.terms,
            distribution: first.distribution,
            free_parameters: parts.iter().map(|p| p.free_parameters).sum(),
            reduced_chi2: parts.iter().map(|p| p.reduced_chi2).sum::<f64>() / parts.len() as f64,
            aic: parts.iter().map(|p| p.aic).sum(),
            folds,
            inadmissible,
        }
    }
}

/// The candidates' scores and which one was kept.
#[derive(Clone, Debug, PartialEq)]
pub struct TermsChoice {
    pub scores: Vec<TermsScore>,
    /// Index into `scores` of the kept candidate.
    pub chosen: usize,
    /// K, when the choice was made by K-fold cross-validation.
    pub folds: Option<usize>,
    /// (rows compared, rows measured) when the candidates were compared on every n-th row of a
    /// dense set and the kept terms then fitted to every row ([`super::cross_validation`]).
    pub sampled: Option<(usize, usize)>,
}

impl TermsChoice {
    /// Index of the candidate with the lowest AIC.
    pub fn best_by_aic(&self) -> usize {
        lowest(self.scores.iter().map(|s| s.aic))
    }

    /// One line per candidate, the kept one marked: `terms  distribution  χ²_ν  AIC  CV
    /// (± its standard error)  admissible`.
    pub fn table(&self) -> String {
        let mut lines = vec![format!(
            "  {:<22} {:<9} {:>3} {:>10} {:>12} {:>18}  {}",
            "terms", "slopes", "p", "χ²/dof", "AIC", "CV χ²/obs", "admissible"
        )];
        for (i, s) in self.scores.iter().enumerate() {
            let cv = match (s.cv_score(), s.cv_standard_error()) {
                (Some(v), Some(e)) => format!("{v:.4} ± {e:.4}"),
                (Some(v), None) => format!("{v:.4}"),
                _ => "—".to_owned(),
            };
            let mark = if i == self.chosen { "*" } else { " " };
            let admissible = s
                .inadmissible
                .as_ref()
                .map_or("yes".to_owned(), |why| format!("no: {why}"));
            lines.push(format!(
                "{mark} {:<22} {:<9} {:>3} {:>10.4} {:>12.1} {:>18}  {admissible}",
                s.terms.to_string(),
                s.distribution.to_string(),
                s.free_parameters,
                s.reduced_chi2,
                s.aic,
                cv
            ));
        }
        lines.push(self.rule());
        lines.join("\n")
    }

    /// How the kept candidate was chosen, one line.
    fn rule(&self) -> String {
        let admissible = self.scores.iter().any(|s| s.inadmissible.is_none());
        let among = if admissible {
            "among the admissible sets"
        } else {
            "no set is admissible: kept the best of all, which is not physical"
        };
        let rule = match self.folds {
            Some(k) => format!(
                "  kept: the fewest parameters whose {k}-fold CV score is within one standard \
                 error of the best, {among}"
            ),
            None => format!("  kept: the lowest AIC, {among}"),
        };
        match self.sample_clause() {
            Some(clause) => format!("{rule}\n  {clause}"),
            None => rule,
        }
    }

    /// How the candidates' rows were sampled, when they were.
    fn sample_clause(&self) -> Option<String> {
        let (compared, measured) = self.sampled?;
        Some(format!(
            "scores from every n-th row, {compared} of the {measured} rows; the kept terms then \
             fitted to every row"
        ))
    }

    /// Adds to `material`'s fit settings that its terms were chosen on a subsample of its rows,
    /// when they were: the record says how the fit was made.
    pub(super) fn note_sample(&self, material: &mut crate::material::Material) {
        let (Some(clause), Some(record)) = (self.sample_clause(), material.fit.as_mut()) else {
            return;
        };
        if let Some(setting) = record.settings.get_mut("terms_choice") {
            setting.push_str(&format!("; {clause}"));
        }
    }

    /// Index of the candidate to keep: by cross-validation when folds were taken (the
    /// one-standard-error rule: the fewest parameters whose score is within one standard error
    /// of the best, so that a bigger model must predict better than the folds' scatter), else
    /// by AIC; among the admissible candidates when there are any.
    pub(super) fn choose(scores: &[TermsScore], cross_validated: bool) -> usize {
        let admissible: Vec<usize> = (0..scores.len())
            .filter(|&i| scores[i].inadmissible.is_none())
            .collect();
        let pool = if admissible.is_empty() {
            (0..scores.len()).collect()
        } else {
            admissible
        };
        if !cross_validated {
            return pool[lowest(pool.iter().map(|&i| scores[i].aic))];
        }
        let score = |i: usize| scores[i].cv_score().unwrap_or(f64::INFINITY);
        let best = pool[lowest(pool.iter().map(|&i| score(i)))];
        let threshold = score(best) + scores[best].cv_standard_error().unwrap_or(0.0);
        pool.into_iter()
            .filter(|&i| score(i) <= threshold)
            .min_by(|&a, &b| {
                let key = |i: usize| (scores[i].free_parameters, score(i));
                key(a)
                    .partial_cmp(&key(b))
                    .unwrap_or(std::cmp::Ordering::Equal)
            })
            .unwrap_or(best)
    }
}

pub(super) fn lowest(values: impl Iterator<Item = f64>) -> usize {
    values
        .enumerate()
        .fold(
            (0, f64::INFINITY),
            |best, (i, v)| {
                if v < best.1 {
                    (i, v)
                } else {
                    best
                }
            },
        )
        .0
}
