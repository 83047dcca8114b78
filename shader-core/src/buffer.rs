//! Storage-buffer element access without panicking bounds checks, for kernels with many reads
//! (a workaround for a control-flow limit of Mesa lavapipe).
//!
//! rust-gpu turns every panicking `buf[i]` into a bounds check whose failure returns from the
//! entry point. Mesa lowers each such early return by nesting the rest of the function inside
//! an `if`, and llvmpipe's gallivm keeps at most 80 nested conditions (`LP_MAX_TGSI_NESTING`):
//! past that it silently stops masking, so lanes run code their conditions exclude. [`load`] and
//! [`store`] check the index with a branch that merges instead of returning, so a kernel's
//! nesting depth no longer grows with its number of buffer accesses. Out-of-range reads give 0
//! and out-of-range writes are dropped, on the CPU and the GPU alike; callers index in range by
//! construction (the CPU-vs-GPU comparisons would show a difference otherwise).
//!
//! ```
//! use shader_core::buffer::{load, store};
//! let mut buf = [1.0f32, 2.0, 3.0];
//! assert_eq!(load(&buf, 2), 3.0);
//! assert_eq!(load(&buf, 3), 0.0); // out of range: 0, no panic
//! store(&mut buf, 0, 9.0);
//! store(&mut buf, 7, 9.0); // out of range: dropped
//! assert_eq!(buf, [9.0, 2.0, 3.0]);
//! ```

/// `buf[i]`, or 0 when `i` is out of range.
#[inline(always)]
pub fn load(buf: &[f32], i: usize) -> f32 {
    if i < buf.len() {
        // SAFETY: `i < buf.len()` was just checked.
        unsafe { *buf.get_unchecked(i) }
    } else {
        0.0
    }
}

/// `buf[i] = v`; nothing is written when `i` is out of range.
#[inline(always)]
pub fn store(buf: &mut [f32], i: usize, v: f32) {
    if i < buf.len() {
        // SAFETY: `i < buf.len()` was just checked.
        unsafe { *buf.get_unchecked_mut(i) = v }
    }
}

/// `buf[b..b + N]` as an array, with one merging range check for the N values (all zeros when
/// `b + N - 1` is out of range): a vector, texel or record in one condition instead of N.
macro_rules! load_n {
    ($(#[$doc:meta])* $name:ident, $n:literal, [$($k:literal),*]) => {
        $(#[$doc])*
        #[inline(always)]
        pub fn $name(buf: &[f32], b: usize) -> [f32; $n] {
            if buf.len() >= $n && b <= buf.len() - $n {
                // SAFETY: `b + N - 1 < buf.len()` was just checked (without overflow).
                unsafe { [$(*buf.get_unchecked(b + $k)),*] }
            } else {
                [0.0; $n]
            }
        }
    };
}

load_n!(
    /// `[buf[b], buf[b + 1]]`, one merging range check (zeros past the end).
    load2, 2, [0, 1]
);
load_n!(
    /// `[buf[b], buf[b + 1], buf[b + 2]]`, one merging range check (zeros past the end): an RGB
    /// texel or a vector.
    load3, 3, [0, 1, 2]
);
load_n!(
    /// `buf[b..b + 4]`, one merging range check (zeros past the end).
    load4, 4, [0, 1, 2, 3]
);
load_n!(
    /// `buf[b..b + 8]`, one merging range check (zeros past the end): a ray record.
    load8, 8, [0, 1, 2, 3, 4, 5, 6, 7]
);

/// `buf[o..o + 3] = v` (each write dropped when out of range, as [`store`]).
#[inline(always)]
pub fn store_vec3(buf: &mut [f32], o: usize, v: crate::vector::Vec3) {
    store(buf, o, v.x);
    store(buf, o + 1, v.y);
    store(buf, o + 2, v.z);
}

/// `buf[o..o + 3]` as a vector ([`load3`]).
#[inline(always)]
pub fn load_vec3(buf: &[f32], o: usize) -> crate::vector::Vec3 {
    let [x, y, z] = load3(buf, o);
    crate::vector::Vec3::new(x, y, z)
}

/// `buf[i]` of a word buffer, or 0 when `i` is out of range (the merging check of [`load`]).
#[inline(always)]
pub fn load_u32(buf: &[u32], i: usize) -> u32 {
    if i < buf.len() {
        // SAFETY: `i < buf.len()` was just checked.
        unsafe { *buf.get_unchecked(i) }
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_range_reads_and_writes_and_out_of_range_is_inert() {
        let mut b = [1.0f32, 2.0, 3.0];
        assert_eq!(load(&b, 1), 2.0);
        assert_eq!(load(&b, 3), 0.0);
        store(&mut b, 2, 7.0);
        store(&mut b, 9, 8.0);
        assert_eq!(b, [1.0, 2.0, 7.0]);
        assert_eq!(load3(&b, 0), [1.0, 2.0, 7.0]);
        // One element past the end: the whole triple reads as zeros.
        assert_eq!(load3(&b, 1), [0.0; 3]);
        let r = [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
        assert_eq!(load8(&r, 1), [2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
        assert_eq!(load8(&r, 2), [0.0; 8]);
        assert_eq!(load8(&r, usize::MAX - 3), [0.0; 8]);
        assert_eq!(load8(&r[..7], 0), [0.0; 8]);
        assert_eq!(load3(&r[..2], 0), [0.0; 3]);
        assert_eq!(load2(&r, 7), [8.0, 9.0]);
        assert_eq!(load2(&r, 8), [0.0; 2]);
        assert_eq!(load4(&r, 5), [6.0, 7.0, 8.0, 9.0]);
        assert_eq!(load4(&r, 6), [0.0; 4]);
    }
}
