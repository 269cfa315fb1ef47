//! ln x inlined into the BRDF's hot paths and into loops that the compiler vectorizes (the slope
//! density and the Smith masking factors of a block of geometries, src/pbrdf/batch.rs): glibc's
//! `log` is an opaque call, which keeps a loop scalar and spills every live register around it. This is fdlibm's algorithm (Sun's `e_log.c`, also
//! musl's and the `libm` crate's former one), without its branches: x = 2^k m with m in
//! [√½, √2) by integer arithmetic on the bits, f = m − 1, s = f/(2 + f), and
//! ln m = f − f²/2 + s (f²/2 + R(s²)) with fdlibm's degree-14 minimax polynomial R (its own
//! bound: |error of R| < 2^−58.45). fdlibm states an error below 1 ulp; the tests check that
//! against the system `ln` over millions of arguments. No maintained crate offers an inlinable
//! double-precision logarithm (the `libm` crate's is an out-of-line call).

use super::multiply_add;

/// ln 2 = HI + LO, HI with its low 32 bits zero so that k·HI is exact for |k| < 2^20 (fdlibm's
/// constants, written in their shortest round-trip form).
const LN2_HI: f64 = 0.6931471803691238;
const LN2_LO: f64 = 1.9082149292705877e-10;
/// fdlibm's coefficients of R(z) = Lg1 z + Lg2 z² + … + Lg7 z⁷, z = s².
const LG: [f64; 7] = [
    0.6666666666666735,
    0.3999999999940942,
    0.2857142874366239,
    0.22222198432149784,
    0.1818357216161805,
    0.15313837699209373,
    0.14798198605116586,
];

/// ln x for any x, within 1 ulp, without a call or a branch (selects only, so that a loop over
/// it vectorizes): [`ln_of_normal`] where x is positive, normal and finite; subnormals scaled
/// into the normal range first (as fdlibm does); −∞ at ±0, ∞ at ∞, NaN below 0 and at NaN.
#[inline(always)]
pub(crate) fn inline_ln(x: f64) -> f64 {
    // 2^54 and 54 ln 2: a subnormal times 2^54 is normal.
    const TWO_TO_54: f64 = 18014398509481984.0;
    // The argument is selected, not the result: one reduction and polynomial instead of two
    // (selecting between two whole evaluations cost 10–20 ns of every scalar BRDF call).
    let subnormal = x > 0.0 && x < f64::MIN_POSITIVE;
    let (scaled, extra) = if subnormal {
        (x * TWO_TO_54, -54.0)
    } else {
        (x, 0.0)
    };
    let ln = ln_with_exponent(scaled, extra);
    let special = if x == 0.0 {
        f64::NEG_INFINITY
    } else if x == f64::INFINITY {
        f64::INFINITY
    } else {
        f64::NAN
    };
    if x > 0.0 && x < f64::INFINITY {
        ln
    } else {
        special
    }
}

/// ln x for a positive, normal, finite x, within 1 ulp; branch free (a loop over it vectorizes).
/// Other arguments give a finite but meaningless value: a caller selects it away.
#[inline(always)]
pub(crate) fn ln_of_normal(x: f64) -> f64 {
    ln_with_exponent(x, 0.0)
}

/// ln(x 2^extra) for a positive, normal, finite x and an integer `extra` (fdlibm's k offset).
#[inline(always)]
fn ln_with_exponent(x: f64, extra: f64) -> f64 {
    // Adding (1 − 0x3fe6a09e) to the high word carries into the exponent exactly when the
    // mantissa is at least √2 ≈ 0x3ff6a09e…, so k counts the halvings that bring m below √2.
    const SHIFT: u64 = (0x3ff0_0000 - 0x3fe6_a09e) << 32;
    let bits = x.to_bits().wrapping_add(SHIFT);
    let k = ((bits >> 52) as i64 - 0x3ff) as f64 + extra;
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) + (0x3fe6_a09e << 32));
    let f = m - 1.0;
    let half_f2 = 0.5 * f * f;
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    // Odd and even coefficients as two chains (fdlibm's split), half the latency of one.
    let odd = z * multiply_add(
        w,
        multiply_add(w, multiply_add(w, LG[6], LG[4]), LG[2]),
        LG[0],
    );
    let even = w * multiply_add(w, multiply_add(w, LG[5], LG[3]), LG[1]);
    let r = odd + even;
    k * LN2_HI - ((half_f2 - (s * (half_f2 + r) + k * LN2_LO)) - f)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(got: f64, want: f64) -> f64 {
        if got == want {
            return 0.0;
        }
        (got - want).abs() / (want.abs() * f64::EPSILON).max(f64::MIN_POSITIVE)
    }

    /// Within 1 ulp of the system ln (itself within ~0.5 ulp, so 1.5 between them) over the
    /// whole normal range, densely around 1 (where ln x is small and the cancellation is) and
    /// across the √2 seam of the reduction.
    #[test]
    fn agrees_with_the_system_ln() {
        let mut worst: f64 = 0.0;
        let mut check = |x: f64| {
            let error = ulps(inline_ln(x), x.ln());
            worst = worst.max(error);
            assert!(
                error <= 1.5,
                "ln {x:e}: {} vs {} ({error} ulp)",
                inline_ln(x),
                x.ln()
            );
        };
        // Log-uniform over the normal range.
        for step in 0..=2_000_000 {
            let exponent = -1021.9 + 2045.8 * step as f64 / 2e6;
            check(2f64.powf(exponent));
        }
        // Uniform over the ranges the BRDF uses: (0, 1] (the masking's x) and [1, 10⁴] (the
        // slope density's 1 + tan²θ/a), and near 1.
        for step in 1..=1_000_000 {
            let t = step as f64 / 1e6;
            check(t);
            check(1.0 + 1e4 * t);
            check(1.0 + 1e-3 * (t - 0.5));
        }
        for seam in [std::f64::consts::SQRT_2, std::f64::consts::FRAC_1_SQRT_2] {
            let mut x = seam;
            for _ in 0..1000 {
                check(x);
                check(f64::from_bits(
                    seam.to_bits() - (x.to_bits() - seam.to_bits()),
                ));
                x = f64::from_bits(x.to_bits() + 1);
            }
        }
        for exact in [1.0, 2.0, 0.5, 1024.0, f64::MIN_POSITIVE, f64::MAX] {
            check(exact);
        }
        assert_eq!(inline_ln(1.0), 0.0);
        assert!(worst > 0.0, "the comparison must see rounding differences");
    }

    #[test]
    fn special_arguments_and_subnormals() {
        assert_eq!(inline_ln(0.0), f64::NEG_INFINITY);
        assert_eq!(inline_ln(-0.0), f64::NEG_INFINITY);
        assert_eq!(inline_ln(f64::INFINITY), f64::INFINITY);
        assert!(inline_ln(-1.0).is_nan());
        assert!(inline_ln(f64::NEG_INFINITY).is_nan());
        assert!(inline_ln(f64::NAN).is_nan());
        for x in [
            5e-324,
            1e-320,
            3e-310,
            f64::MIN_POSITIVE * (1.0 - f64::EPSILON),
        ] {
            assert!(ulps(inline_ln(x), x.ln()) <= 1.0, "ln {x:e}");
        }
    }
}
