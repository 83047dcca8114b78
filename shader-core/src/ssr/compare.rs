//! Float minimum, maximum, clamp and floor to an index with fixed NaN rules, written as
//! comparisons so the CPU and the SPIR-V pick the same operand.

/// `a < b ? a : b` (a NaN in `a` selects `b`), written with a comparison so both backends agree.
#[inline]
pub fn minf(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// `a > b ? a : b` (a NaN in `a` selects `b`).
#[inline]
pub fn maxf(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// Clamp to [lo, hi]; NaN maps to `lo`.
#[inline]
pub fn clampf(x: f32, lo: f32, hi: f32) -> f32 {
    if x >= lo {
        if x <= hi {
            x
        } else {
            hi
        }
    } else {
        lo
    }
}

/// floor(x) for x in [0, hi] as an integer, clamped to [0, hi] (NaN and negatives give 0).
#[inline]
pub fn floor_index(x: f32, hi: u32) -> u32 {
    if x >= 0.0 {
        let hf = hi as f32;
        if x < hf {
            x as u32
        } else {
            hi
        }
    } else {
        0
    }
}
