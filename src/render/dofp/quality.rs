//! Image quality against a known truth.

/// Peak signal-to-noise ratio of `estimate` against `truth` in dB: 10 log10(peak² / MSE), the peak
/// being the truth's largest |value| (so a signed channel such as S1 has a meaningful peak).
/// `f64::INFINITY` for an exact estimate (including an all-zero truth estimated exactly),
/// `-f64::INFINITY` for an all-zero truth estimated inexactly, `NaN` for empty or unequal-length
/// inputs, where no ratio exists.
pub fn psnr(truth: &[f64], estimate: &[f64]) -> f64 {
    if truth.is_empty() || truth.len() != estimate.len() {
        return f64::NAN;
    }
    let mse = truth
        .iter()
        .zip(estimate)
        .map(|(t, e)| (t - e) * (t - e))
        .sum::<f64>()
        / truth.len() as f64;
    if mse == 0.0 {
        return f64::INFINITY;
    }
    let peak = truth.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    10.0 * (peak * peak / mse).log10()
}

#[cfg(test)]
mod tests {
    use super::psnr;

    #[test]
    fn psnr_follows_its_definition() {
        // Peak 2 (the largest |value|, here negative), MSE = (0.1² + 0.2²) / 2 = 0.025.
        let p = psnr(&[1.0, -2.0], &[1.1, -1.8]);
        assert!((p - 10.0 * (4.0f64 / 0.025).log10()).abs() < 1e-12, "{p}");
        assert_eq!(psnr(&[1.0, 2.0], &[1.0, 2.0]), f64::INFINITY);
        assert!(psnr(&[], &[]).is_nan());
        assert!(psnr(&[1.0], &[1.0, 2.0]).is_nan());
    }
}
