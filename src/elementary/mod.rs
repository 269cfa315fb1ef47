//! Elementary functions inlined into the physics' hot paths, where the system libm's opaque
//! calls dominated the cost: e^y and ln x for the slope density and the Smith Λ table, and sin/cos of
//! angles in degrees for the direction tables built from measurement and evaluation columns; and
//! the seeded Gaussian deviates of the detector noise and the procedural terrain.
//! Each file says why no crate serves and how its accuracy is tested.

mod degrees;
mod exponential;
mod logarithm;
mod random;

pub use degrees::sin_cos_degrees;
pub(crate) use degrees::{sin_cos_degrees_within_a_turn, within_a_turn};
pub(crate) use exponential::{exp_within_range, inline_exp};
pub(crate) use logarithm::{inline_ln, ln_of_normal};
pub(crate) use random::standard_normal;

/// a·b + c, fused where the target has the instruction (x86-64 with FMA, as `.cargo/config.toml`
/// builds on any recent CPU; aarch64 always). On x86 without it, `mul_add` would be a libm call
/// (43 ns per first-column BRDF); unfused it is 34 ns, and the 1-ulp bound holds either way (the
/// reduction's k·HI is exact; the test passes in both builds).
#[inline(always)]
pub(crate) fn multiply_add(a: f64, b: f64, c: f64) -> f64 {
    if cfg!(all(
        any(target_arch = "x86", target_arch = "x86_64"),
        not(target_feature = "fma")
    )) {
        a * b + c
    } else {
        a.mul_add(b, c)
    }
}
