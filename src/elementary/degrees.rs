//! sin and cos of angles given in degrees (Julia's `sind`/`cosd`, C23's `sinpi` idea), for the
//! direction tables that `irpol eval`, the fit and the Python `mueller` build from degree columns.
//!
//! Two reasons not to convert to radians and call `f64::sin_cos`. Accuracy: reducing degrees by
//! quarter turns is exact in floating point, so sin 180° = cos 90° = 0 exactly (through radians
//! they come out as 1.2e-16 and 6.1e-17). Speed: glibc's `sincos` is an opaque call (~13 ns, with
//! its own radian range reduction); four of them per geometry were 28 % of a bulk Mueller
//! evaluation of random geometries. After the exact reduction the argument is within ±45°
//! (|x| ≤ π/4), where the Taylor series themselves, with their exact 1/n! coefficients, are
//! accurate to far below an ulp at degree 17 (sin) and 18 (cos): the first omitted terms are
//! (π/4)¹⁹/19! = 8e-20 and (π/4)²⁰/20! = 3e-21. No maintained crate offers inlinable
//! degree-argument trigonometry.

use super::multiply_add;

/// (sin x°, cos x°) for a finite `x_deg`; within 1 ulp of the correctly rounded values (test
/// below), and exact at multiples of 90°.
#[inline]
pub fn sin_cos_degrees(x_deg: f64) -> (f64, f64) {
    sin_cos_degrees_within_a_turn(within_a_turn(x_deg))
}

/// `x_deg` reduced to at most one turn in magnitude (unchanged when it already is), as
/// [`sin_cos_degrees`] reduces it: a batch reduces a block of angles with this branch first, so
/// that its loop over [`sin_cos_degrees_within_a_turn`] has no call and vectorizes.
#[inline(always)]
pub(crate) fn within_a_turn(x_deg: f64) -> f64 {
    // fmod is exact; it only keeps the quarter count below small multiples (x − 90k is exact
    // whenever 90k is an integer no larger than 2|x|, as both are multiples of ulp(x)).
    if x_deg.abs() > 360.0 {
        x_deg % 360.0
    } else {
        x_deg
    }
}

/// [`sin_cos_degrees`] of an angle with |x| ≤ 360° (of [`within_a_turn`]): branch free, the same
/// operations and so the same results.
#[inline(always)]
pub(crate) fn sin_cos_degrees_within_a_turn(x: f64) -> (f64, f64) {
    let quarter_turns = (x / 90.0).round_ties_even();
    let reduced = x - 90.0 * quarter_turns; // exact, within ±45°
    let (s, c) = sin_cos_within_an_eighth_turn(reduced.to_radians());
    // Quarter turn q = 0, 1, 2, 3 gives (s, c), (c, −s), (−s, −c), (−c, s): selected with bit
    // masks rather than a branch, which random azimuths would mispredict three times in four.
    let q = (quarter_turns as i64) as u64;
    let swap = 0u64.wrapping_sub(q & 1);
    let (s_bits, c_bits) = (s.to_bits(), c.to_bits());
    let first = (s_bits & !swap) | (c_bits & swap);
    let second = (c_bits & !swap) | (s_bits & swap);
    let sin_sign = (q >> 1 & 1) << 63;
    let cos_sign = ((q + 1) >> 1 & 1) << 63;
    (
        f64::from_bits(first ^ sin_sign),
        f64::from_bits(second ^ cos_sign),
    )
}

/// Taylor series of sin and cos for |x| ≤ π/4 (see the module note), in Horner form in x².
#[inline(always)]
fn sin_cos_within_an_eighth_turn(x: f64) -> (f64, f64) {
    const SIN: [f64; 8] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5040.0,
        1.0 / 362880.0,
        -1.0 / 39916800.0,
        1.0 / 6227020800.0,
        -1.0 / 1307674368000.0,
        1.0 / 355687428096000.0,
    ];
    const COS: [f64; 9] = [
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40320.0,
        -1.0 / 3628800.0,
        1.0 / 479001600.0,
        -1.0 / 87178291200.0,
        1.0 / 20922789888000.0,
        -1.0 / 6402373705728000.0,
    ];
    let x2 = x * x;
    // sin x = x + x³ (−1/6 + x² (1/120 − …)), cos x = 1 + x² (−1/2 + …): the leading term added
    // last keeps the rounding of the small tail from reaching the result's last bit.
    (
        multiply_add(x * x2, polynomial(&SIN, x2), x),
        multiply_add(x2, polynomial(&COS, x2), 1.0),
    )
}

/// Σ c_j y^j as E(y²) + y O(y²) (even and odd coefficients, each by Horner's rule with fused
/// multiply–adds): two independent chains of half the length, as the latency of one long chain
/// was the cost of the function.
#[inline(always)]
fn polynomial(coefficients: &[f64], y: f64) -> f64 {
    let y2 = y * y;
    let horner = |start: usize| {
        coefficients
            .iter()
            .skip(start)
            .step_by(2)
            .rev()
            .fold(0.0, |acc, &c| multiply_add(acc, y2, c))
    };
    multiply_add(y, horner(1), horner(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn multiples_of_90_degrees_are_exact() {
        for (deg, expect) in [
            (0.0, (0.0, 1.0)),
            (90.0, (1.0, 0.0)),
            (180.0, (0.0, -1.0)),
            (270.0, (-1.0, 0.0)),
            (-90.0, (-1.0, 0.0)),
            (720.0, (0.0, 1.0)),
            (-450.0, (-1.0, 0.0)),
        ] {
            let (s, c) = sin_cos_degrees(deg);
            assert_eq!((s + 0.0, c + 0.0), expect, "{deg}°"); // + 0.0: −0 equals 0
        }
        let (s, c) = sin_cos_degrees(30.0);
        assert!((s - 0.5).abs() <= f64::EPSILON * 0.5);
        assert!((c - 0.75f64.sqrt()).abs() <= f64::EPSILON * 0.5);
    }

    /// Against the radian `sin_cos` of the angle reduced exactly into (−180°, 180°] (so that the
    /// radian argument's own rounding, ulp(π) = 4.4e-16, bounds the comparison) over ±1000°.
    #[test]
    fn agrees_with_the_radian_functions() {
        for j in -200_000..=200_000 {
            let deg = j as f64 * 0.005_000_37;
            let (s, c) = sin_cos_degrees(deg);
            let reduced = deg - 360.0 * (deg / 360.0).round(); // exact
            let (rs, rc) = reduced.to_radians().sin_cos();
            let bound = if reduced.abs() <= 45.0 {
                2.3e-16
            } else {
                4.5e-16
            };
            assert!((s - rs).abs() <= bound, "sin {deg}°: {s} vs {rs}");
            assert!((c - rc).abs() <= bound, "cos {deg}°: {c} vs {rc}");
            assert!((s * s + c * c - 1.0).abs() <= 4.5e-16, "{deg}°");
        }
        let (s, c) = sin_cos_degrees(1e-300);
        assert_eq!((s, c), (1e-300f64.to_radians(), 1.0));
        let (s, c) = sin_cos_degrees(1e17); // 10¹⁷ ≡ 280 (mod 360)
        let (rs, rc) = 280f64.to_radians().sin_cos();
        assert!((s - rs).abs() < 1e-15 && (c - rc).abs() < 1e-15);
    }
}
