//! Float helpers for error bounds: γₙ and one-ulp steps.

/// Machine epsilon for `f32` rounding: half an ULP of 1.0.
const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// Bound on the relative error of `n` chained `f32` operations (Higham's γₙ, as in pbrt).
#[inline]
pub fn gamma(n: i32) -> f32 {
    let n = n as f32 * MACHINE_EPSILON;
    n / (1.0 - n)
}

/// The smallest `f32` strictly greater than `v` (identity for +∞ and NaN).
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 || v.is_nan() {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The largest `f32` strictly less than `v` (identity for −∞ and NaN).
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 || v.is_nan() {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}
