//! Floating-point error bounds and ulp stepping used by robust intersection and ray spawning.

/// Unit roundoff of `f32` (half an ulp of 1.0).
pub const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// Conservative bound `n·ε / (1 - n·ε)` on the relative error of `n` chained f32 operations
/// (Higham's γₙ, as used by pbrt).
#[inline]
#[must_use]
pub const fn gamma(n: i32) -> f32 {
    let ne = n as f32 * MACHINE_EPSILON;
    ne / (1.0 - ne)
}

/// The smallest `f32` strictly greater than `v` (identity for +∞ and NaN).
#[inline]
#[must_use]
pub fn next_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 || v.is_nan() {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The largest `f32` strictly smaller than `v` (identity for -∞ and NaN).
#[inline]
#[must_use]
pub fn next_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 || v.is_nan() {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_up_and_down_step_one_ulp() {
        assert_eq!(next_up(1.0), 1.0 + f32::EPSILON);
        assert_eq!(next_down(1.0), 1.0 - f32::EPSILON / 2.0);
        assert_eq!(next_up(0.0), f32::from_bits(1));
        assert_eq!(next_up(-0.0), f32::from_bits(1));
        assert_eq!(next_down(0.0), -f32::from_bits(1));
        assert_eq!(next_up(-1.0), -1.0 + f32::EPSILON / 2.0);
        assert_eq!(next_up(f32::INFINITY), f32::INFINITY);
        assert_eq!(next_down(f32::NEG_INFINITY), f32::NEG_INFINITY);
        assert_eq!(next_up(f32::MAX), f32::INFINITY);
    }

    #[test]
    fn gamma_grows_with_n() {
        assert!(gamma(3) > gamma(2));
        assert!((gamma(1) - MACHINE_EPSILON).abs() < 1e-12);
    }
}
