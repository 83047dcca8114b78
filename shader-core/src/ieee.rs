//! Correctly rounded `f32` division and square root (IEEE 754-2019 §5.4.1, round to nearest even) on any conformant Vulkan device: the device's own instruction as a seed, then an exact correction from the operations Vulkan requires to be correctly rounded.
//!
//! Vulkan lets `OpFDiv` be off by 2.5 ULP and GLSL.std.450 `Sqrt`/`InverseSqrt` be approximate, so
//! every division and square root in this crate (and in kernels built on it) goes through [`div`] and
//! [`sqrt`] here. In the SPIR-V build they run [`div_exact`] and [`sqrt_exact`]; on the CPU they
//! are the native `divss`/`sqrtss`, which give the same bits (the proof below), only faster
//! ([`EXACT`], [`SOFT_ON_CPU`]).
//!
//! Method (both functions, [`div_with_seed`] and [`sqrt_with_seed`] say why each step is exact):
//! unpack the operands into significands in [1, 2) (denormals normalised) and an exponent; take
//! the device's division or square root of the significands as a seed ([`div_seed`],
//! [`sqrt_seed`]: the only inexact instructions, each in a function of its own whose name says
//! `seed`), whose error Vulkan bounds (2.5 ULP; the square root's as 1 / InverseSqrt); correct it
//! once with a residual computed by Dekker's TwoProduct (exact without FMA under
//! round-to-nearest) and a rough reciprocal, which leaves it within an ULP; decide the last bit
//! exactly by the sign of an exact residual against the rounding midpoint; finally scale by the
//! exponent with one rounding (denormal results rounded once, gradual underflow; overflow to
//! infinity). Everything else is `f32` add/sub/mul (no contraction: the shader build decorates
//! them `NoContraction`), comparisons, bit casts and 32-bit integer arithmetic: no FMA, no 64-bit
//! integers, no loop. The rare cases (special operands, denormal results) have branches of their
//! own, which a driver skips when no lane takes them (GPUs, Mesa 23 and later); the choices
//! inside the common path are selects.
//!
//! Denormals follow the floating-point environment: kept where it keeps them; where it flushes
//! them (a GPU measured to flush, and then the CPU backend's threads with FTZ/DAZ set), a denormal
//! operand reads as a zero of its sign and a denormal quotient flushes to zero, as `divss` and
//! `sqrtss` do under FTZ/DAZ (checked on the CPU under those controls by this module's tests).
//!
//! Special values reproduce x86-64 SSE (`divss`, `sqrtss`) bit for bit, so the CPU results are
//! the same as the native operators: a NaN operand is returned quieted (the first one for `div`),
//! an invalid operation (0/0, inf/inf, sqrt of a negative number) gives the default NaN
//! `0xffc0_0000`, and signed zeros and infinities follow IEEE 754.
//!
//! Proof: this crate's `ieee_exhaustive` test compares [`sqrt_exact`] with the native square
//! root on all 2^32 bit patterns and [`div_exact`] with the native `/` on structured and random
//! pairs, and runs the corrections with seeds perturbed to every value the Vulkan bounds allow
//! (and an ULP beyond): all 2^24 square-root significands, 10^10 division pairs in the documented
//! run (docs/exactness.md), a seeded sample of each in every test run.
//!
//! ```
//! use shader_core::ieee::{div, div_exact, rsqrt, sqrt, sqrt_exact};
//! let pairs = [(1.0f32, 3.0f32), (2.0, 7.0), (-0.0, 5.0), (1.0e-40, 3.0), (3.0e38, 0.1), (1.0, 0.0)];
//! for (a, b) in pairs {
//!     let native = std::hint::black_box(a) / std::hint::black_box(b);
//!     // Same bits as the native division, on either path.
//!     assert_eq!(div(a, b).to_bits(), native.to_bits());
//!     assert_eq!(div_exact(a, b).to_bits(), native.to_bits());
//! }
//! for x in [2.0f32, 0.5, 1.0e-41, 3.0e38, -0.0, f32::INFINITY] {
//!     assert_eq!(sqrt_exact(x).to_bits(), std::hint::black_box(x).sqrt().to_bits());
//!     assert_eq!(sqrt(x).to_bits(), sqrt_exact(x).to_bits());
//! }
//! // Invalid operations give x86's default NaN; sqrt(-0) = -0.
//! assert_eq!(div_exact(0.0, 0.0).to_bits(), 0xffc0_0000);
//! assert_eq!(sqrt_exact(-1.0).to_bits(), 0xffc0_0000);
//! assert_eq!(sqrt_exact(-0.0).to_bits(), (-0.0f32).to_bits());
//! // rsqrt is two roundings: 1 / sqrt(x), not a fused reciprocal square root.
//! assert_eq!(rsqrt(2.0), div(1.0, sqrt(2.0)));
//! ```

/// The one switch: `true` (default): in the SPIR-V build [`div`] and [`sqrt`] are the corrected
/// routines [`div_exact`] and [`sqrt_exact`] (bit-exact on any conformant Vulkan device). `false`
/// (feature `native-div-sqrt`, for a second SPIR-V build of the same kernels): they are the bare
/// `OpFDiv` and GLSL.std.450 `Sqrt`, correctly rounded on Mesa lavapipe but only to 2.5 / ~2 ULP
/// on other drivers, so bit-exactness with the CPU is then no longer promised.
pub const EXACT: bool = !cfg!(feature = "native-div-sqrt");

/// `true`: the CPU build runs the corrected routines too. Off by default: x86-64 `divss` and
/// `sqrtss` are correctly rounded and give the same bits (proven by this crate's
/// `ieee_exhaustive` test) several times faster in the kernels; turning it on changes no result.
pub const SOFT_ON_CPU: bool = false;

/// Whether [`div`] and [`sqrt`] take the corrected routines in this build.
pub const SOFT: bool = EXACT && (cfg!(target_arch = "spirv") || SOFT_ON_CPU);

const SIGN_MASK: u32 = 0x8000_0000;
const ABS_MASK: u32 = 0x7fff_ffff;
const MANT_MASK: u32 = 0x007f_ffff;
const INF_BITS: u32 = 0x7f80_0000;
const MIN_NORMAL_BITS: u32 = 0x0080_0000;
const ONE_BITS: u32 = 0x3f80_0000;
/// The quiet bit of a binary32 NaN.
const QUIET_BIT: u32 = 0x0040_0000;
/// x86's default NaN ("real indefinite") returned by invalid operations.
const DEFAULT_NAN_BITS: u32 = 0xffc0_0000;

/// `a` where `c`, else `b`: both already computed, so the branch holds no work and drivers
/// turn it into one select (NIR's peephole select, LLVM's `select`).
#[inline]
fn pick<T>(c: bool, a: T, b: T) -> T {
    if c { a } else { b }
}

/// 2^k for k in [-126, 127], built from its bits.
#[inline]
fn pow2i(k: i32) -> f32 {
    f32::from_bits(((k + 127) as u32) << 23)
}

/// Veltkamp split into two halves of at most 12 significant bits each (|a| < 2^115); the one
/// home of the split, used by [`crate::math`]'s double-f32 arithmetic too.
#[inline]
pub(crate) fn split(a: f32) -> (f32, f32) {
    let c = 4097.0 * a;
    let hi = c - (c - a);
    (hi, a - hi)
}

/// Dekker's TwoProduct without FMA, with `b` already split: p + e == a * b exactly when no
/// under/overflow occurs (here all operands lie in [0.5, 4)).
#[inline]
fn two_prod_split(a: f32, bh: f32, bl: f32) -> (f32, f32) {
    let p = a * (bh + bl);
    let (ah, al) = split(a);
    let e = (((ah * bh) - p) + (ah * bl) + (al * bh)) + (al * bl);
    (p, e)
}

/// Significand in [1, 2) and unbiased exponent of a finite nonzero magnitude (bits without sign),
/// denormals normalised (by an exact multiplication by 2^24).
#[inline]
fn unpack(abs_bits: u32) -> (f32, i32) {
    let denormal = abs_bits < MIN_NORMAL_BITS;
    let bits = pick(denormal, (f32::from_bits(abs_bits) * pow2i(24)).to_bits(), abs_bits);
    let e = (bits >> 23) as i32 - pick(denormal, 127 + 24, 127);
    (f32::from_bits((bits & MANT_MASK) | ONE_BITS), e)
}

/// A magnitude (bits without sign) as the floating-point environment reads it: a denormal is
/// read as zero where the environment flushes denormals (DAZ: a device that flushes them, and the
/// CPU backend's threads then, which set FTZ/DAZ), else kept. Found by one multiplication by 2^24,
/// exact where denormals are kept; so the routines treat a denormal operand as the hardware
/// `divss`/`sqrtss` do under the same controls, and their denormal results, made by a
/// multiplication in [`scale_rounded`], flush as the hardware's do (x86: tininess after rounding).
#[inline]
fn env_magnitude(abs_bits: u32) -> u32 {
    let flushed = (abs_bits < MIN_NORMAL_BITS) & ((f32::from_bits(abs_bits) * pow2i(24)).to_bits() == 0);
    pick(flushed, 0, abs_bits)
}

/// The spacing of the f32 grid just above (`up`) and just below (`dn`) q > 0, normal.
#[inline]
fn ulps(q: f32) -> (f32, f32) {
    let up = f32::from_bits(q.to_bits() & INF_BITS) * pow2i(-23);
    let dn = pick((q.to_bits() & MANT_MASK) == 0, 0.5 * up, up);
    (up, dn)
}

/// q * 2^k rounded once (ties to even) for q = RN(Q) in [0.5, 2) and `dir`, a float of the sign of Q - q:
/// normal and overflowing results by exact scaling in two steps (the second rounds only on
/// overflow), denormal results by rounding q to the denormal grid, where a tie of q is broken by
/// `dir` (the only case where rounding q twice differs from rounding Q once).
#[inline]
fn scale_rounded(q: f32, dir: f32, k: i32) -> f32 {
    if k >= -125 {
        // Normal or overflowing: k in [-125, 129] after the clamp (above 129 everything
        // overflows), in two exact steps of which only the second may round (to infinity).
        let k = if k > 129 { 129 } else { k };
        let k1 = k >> 1;
        return (q * pow2i(k1)) * pow2i(k - k1);
    }
    // Denormal: below 2^-159 everything rounds to 0 anyway.
    let k = if k < -160 { -160 } else { k };
    let hs = q * pow2i(k + 100); // exact, normal
    let r1 = hs * pow2i(-100); // one rounding onto the denormal grid
    let t = hs - (r1 * pow2i(100)); // exact: what that rounding removed (scaled by 2^100)
    let half = pow2i(-50); // half the denormal spacing 2^-149, scaled by 2^100
    let tiny = f32::from_bits(1);
    pick((t == half) & (dir > 0.0), r1 + tiny, pick((t == -half) & (dir < 0.0), r1 - tiny, r1))
}

/// a / b correctly rounded (round to nearest, ties to even), denormals and signed zeros
/// included; NaN rules as x86 `divss`: [`div_exact`] where [`SOFT`], else the native `/`.
#[inline]
pub fn div(a: f32, b: f32) -> f32 {
    if SOFT { div_exact(a, b) } else { a / b }
}

/// sqrt(x) correctly rounded (round to nearest even): sqrt(-0) = -0, sqrt(inf) = inf, x < 0
/// gives the default NaN, a NaN is returned quieted (x86 `sqrtss`): [`sqrt_exact`] where
/// [`SOFT`], else the native square root.
#[inline]
pub fn sqrt(x: f32) -> f32 {
    if SOFT { sqrt_exact(x) } else { native_sqrt(x) }
}

/// The seed of [`div_exact`]: the device's own division (one `OpFDiv` in SPIR-V), called only
/// with `a`, `b` in [1, 2), where Vulkan bounds its error by 2.5 ULP. The only inexact
/// instruction of the exact build's division: its own function (never inlined; the SPIR-V
/// check looks for it by name), its result read only by the correction in [`div_with_seed`].
#[inline(never)]
pub fn div_seed(a: f32, b: f32) -> f32 {
    a / b
}

/// The seed of [`sqrt_exact`]: the device's own square root (GLSL.std.450 `Sqrt`), called only
/// with `m` in [1, 4), where Vulkan bounds it as 1 / InverseSqrt (2 ULP, then a 2.5-ULP
/// division). Its own function, as [`div_seed`].
#[inline(never)]
pub fn sqrt_seed(m: f32) -> f32 {
    native_sqrt(m)
}

/// [`div`] by seed and exact correction, on every target: [`div_with_seed`] with [`div_seed`].
/// Not inlined: one function per module rather than its ~100 instructions at every division
/// (the path tracer's entry point was 650 k instructions when it was inlined).
#[inline(never)]
pub fn div_exact(a: f32, b: f32) -> f32 {
    div_with_seed(a, b, div_seed)
}

/// [`sqrt`] by seed and exact correction, on every target: [`sqrt_with_seed`] with
/// [`sqrt_seed`]. Not inlined, as [`div_exact`].
#[inline(never)]
pub fn sqrt_exact(x: f32) -> f32 {
    sqrt_with_seed(x, sqrt_seed)
}

/// a / b correctly rounded from `seed(xa, xb)`, any approximation of xa / xb within 3.5 ULP of
/// it, for the significands xa, xb in [1, 2) of the operands (the proof runs this with seeds
/// perturbed to every such value: `ieee_exhaustive`).
///
/// Why it is exact: with Q = xa / xb in (1/2, 2) and q0 = seed, |Q - q0| <= 3.5 ULP. The
/// residual r0 = xa - q0 xb is computed with Dekker's TwoProduct (xa - p0 exact by Sterbenz) to a
/// relative 2^-24, and q = q0 + r0 y with y = 24/17 - 8/17 xb (|y xb - 1| <= 1/17) leaves
/// |Q - q| <= 3.5/17 ULP + 1/2 ULP < 1 ULP. Then the remainder r1 = xa - q xb is a float
/// (|r1| < 2 ULP(q) on the grid of ULP(q) ULP(xb): 24 bits) and TwoProduct gives it exactly, so
/// comparing 2 r1 with u xb (u the spacing above or below q, both exact) places Q against the
/// midpoints q +- u/2 (Q is never a midpoint: a 24-bit quotient of 24-bit significands cannot end
/// in a single 25th bit). The sign of the remainder left after that step is the direction
/// [`scale_rounded`] needs for a denormal result.
#[inline]
pub fn div_with_seed(a: f32, b: f32, seed: impl Fn(f32, f32) -> f32) -> f32 {
    let (ua, ub) = (a.to_bits(), b.to_bits());
    let sign = (ua ^ ub) & SIGN_MASK;
    let (aa, ab) = (env_magnitude(ua & ABS_MASK), env_magnitude(ub & ABS_MASK));
    // Zero (a flushed denormal included), infinite or NaN operands: x86's results. Kept
    // denormals go on to the general path.
    if (aa == 0) | (ab == 0) | (aa >= INF_BITS) | (ab >= INF_BITS) {
        let invalid = ((aa == INF_BITS) & (ab == INF_BITS)) | ((aa == 0) & (ab == 0));
        return f32::from_bits(pick(
            aa > INF_BITS,
            ua | QUIET_BIT,
            pick(ab > INF_BITS, ub | QUIET_BIT, pick(invalid, DEFAULT_NAN_BITS, pick((aa == INF_BITS) | (ab == 0), sign | INF_BITS, sign))),
        ));
    }
    let (xa, ea) = unpack(aa);
    let (xb, eb) = unpack(ab);
    let q0 = seed(xa, xb);
    let y = 1.411_764_7 - (0.470_588_24 * xb);
    let (bh, bl) = split(xb);
    let (p0, e0) = two_prod_split(q0, bh, bl);
    let r0 = (xa - p0) - e0;
    let q = q0 + (r0 * y);
    let (p1, e1) = two_prod_split(q, bh, bl);
    let r1 = (xa - p1) - e1;
    let (up, dn) = ulps(q);
    let above = (2.0 * r1) > (up * xb);
    let below = (2.0 * r1) < -(dn * xb);
    let step = pick(above, up, pick(below, -dn, 0.0));
    let q = q + step;
    // The sign of Q - q for the chosen q: the remainder less the step's share, whose rounding
    // keeps its sign (all terms are far above the underflow threshold).
    let dir = r1 - (step * xb);
    let m = scale_rounded(q, dir, ea - eb);
    f32::from_bits(m.to_bits() | sign)
}

/// sqrt(x) correctly rounded from `seed(m)`, any approximation of sqrt(m) within 8 ULP of it, for
/// m in [1, 4) the significand of x scaled to an even exponent (the proof runs this with seeds
/// perturbed to every such value, on all 2^24 values of m: `ieee_exhaustive`).
///
/// Why it is exact: with S = sqrt(m) in [1, 2) and s0 = seed, |S - s0| <= 8 ULP. The residual
/// r0 = m - s0^2 (TwoProduct; m - p0 exact by Sterbenz) and y, the bit-trick estimate of
/// 1/sqrt(m) (|y S - 1| < 0.035), give s = s0 + r0 y / 2 with |S - s| <= 8 * 0.035 ULP + 1/2 ULP
/// < 1 ULP, so sqrt(m) is s or a neighbour. With s+ / s- the floats next to s, the midpoints
/// satisfy mid+^2 = s s+ + u^2/4 and mid-^2 = s s- + u-^2/4; m and the products lie on a grid
/// coarser than those u^2/4, so sqrt(m) > mid+ iff m > s s+, and sqrt(m) < mid- iff m <= s s-
/// (sqrt(s s-) < mid- by the AM-GM inequality). Each comparison is exact: m - p is exact
/// (Sterbenz) and compared with the TwoProduct error term.
#[inline]
pub fn sqrt_with_seed(x: f32, seed: impl Fn(f32) -> f32) -> f32 {
    let ux = x.to_bits();
    let ax = env_magnitude(ux & ABS_MASK);
    // x < 0 and NaN have ux >= INF_BITS, as +inf does.
    if (ax == 0) | (ux >= INF_BITS) {
        return f32::from_bits(pick(
            ax > INF_BITS,
            ux | QUIET_BIT,
            // A zero or a denormal the environment flushed keeps its sign; +inf stays; x < 0 is invalid.
            pick(ax == 0, ux & SIGN_MASK, pick(ux == INF_BITS, ux, DEFAULT_NAN_BITS)),
        ));
    }
    let (m, e) = unpack(ax);
    let odd = (e & 1) != 0;
    let m = pick(odd, 2.0 * m, m); // m in [1, 4), e even
    let e = e - (odd as i32);
    let s0 = seed(m);
    let y = f32::from_bits(0x5f37_59df_u32.wrapping_sub(m.to_bits() >> 1));
    let (sh, sl) = split(s0);
    let (p0, e0) = two_prod_split(s0, sh, sl);
    let r0 = (m - p0) - e0;
    let s = s0 + (r0 * (0.5 * y));
    let s_up = f32::from_bits(s.to_bits() + 1);
    let (uh, ul) = split(s_up);
    let (pu, eu) = two_prod_split(s, uh, ul);
    let s_dn = f32::from_bits(s.to_bits() - 1);
    let (dh, dl) = split(s_dn);
    let (pd, ed) = two_prod_split(s, dh, dl);
    let s = pick((m - pu) > eu, s_up, pick((m - pd) <= ed, s_dn, s));
    s * pow2i(e >> 1) // exact: the result is normal
}

/// Make the calling CPU thread flush denormals as a GPU measured to flush them does: x86-64
/// MXCSR.FTZ (bit 15, denormal results to zero) and MXCSR.DAZ (bit 6, denormal operands read as
/// zero), the environment the CPU backend's threads then run in and the software routines above
/// follow. No effect on other CPUs; not part of the SPIR-V build.
#[cfg(not(target_arch = "spirv"))]
pub fn flush_denormals_on_this_thread() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: ldmxcsr/stmxcsr only change this thread's SSE rounding/denormal controls.
    unsafe {
        let mut csr: u32 = 0;
        core::arch::asm!("stmxcsr [{}]", in(reg) &mut csr, options(nostack));
        csr |= (1 << 15) | (1 << 6);
        core::arch::asm!("ldmxcsr [{}]", in(reg) &csr, options(nostack));
    }
}

/// 1 / sqrt(x) as two correctly rounded operations ([`div`] of 1 by [`sqrt`]).
#[inline]
pub fn rsqrt(x: f32) -> f32 {
    div(1.0, sqrt(x))
}

/// The platform square root (`sqrtss` on the CPU, GLSL.std.450 `Sqrt` in SPIR-V).
#[inline]
fn native_sqrt(x: f32) -> f32 {
    use spirv_std::num_traits::Float;
    Float::sqrt(x)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use core::hint::black_box;

    fn native_div(a: f32, b: f32) -> f32 {
        black_box(a) / black_box(b)
    }

    fn check_div(a: f32, b: f32) {
        let (g, w) = (div_exact(a, b), native_div(a, b));
        assert_eq!(g.to_bits(), w.to_bits(), "{a:e} ({:#x}) / {b:e} ({:#x}): got {g:e} want {w:e}", a.to_bits(), b.to_bits());
    }

    #[test]
    fn div_special_values() {
        let vals = [
            0.0, -0.0, 1.0, -1.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, -f32::NAN,
            f32::from_bits(0x7f80_0001), f32::from_bits(0xff80_1234), f32::from_bits(1),
            f32::from_bits(0x807f_ffff), f32::MIN_POSITIVE, f32::MAX, -f32::MAX, 3.0, 1e-40, 7e37,
        ];
        for &a in &vals {
            for &b in &vals {
                check_div(a, b);
            }
        }
    }

    #[test]
    fn sqrt_special_values() {
        for bits in [0u32, 0x8000_0000, 0x7f80_0000, 0xff80_0000, 0x7fc0_0000, 0xffc0_0000, 0x7f80_0001, 0xff80_0001, 1, 0x8000_0001, 0xbf80_0000, 0x3f80_0000, 0x7f7f_ffff] {
            let x = f32::from_bits(bits);
            assert_eq!(sqrt_exact(x).to_bits(), black_box(x).sqrt().to_bits(), "{bits:#x}");
            assert_eq!(sqrt(x).to_bits(), black_box(x).sqrt().to_bits(), "{bits:#x}");
        }
    }

    #[test]
    fn div_near_one_and_powers_of_two() {
        for i in 0..4096u32 {
            for j in 0..64u32 {
                let a = f32::from_bits(0x3f80_0000 - 2048 + i);
                let b = f32::from_bits(0x3f80_0000 - 32 + j);
                check_div(a, b);
                check_div(b, a);
                check_div(a * pow2i(-100), b * pow2i(30));
                check_div(a * pow2i(100), b * pow2i(-30));
            }
        }
    }

    /// Under FTZ/DAZ (set on this test's own thread) the software routines give the bits of
    /// `divss`/`sqrtss` under the same controls: denormal operands read as signed zeros, denormal
    /// quotients flush to zero. This is what a GPU that flushes denormals runs against a CPU
    /// backend whose threads flush too.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn soft_routines_follow_ftz_daz_like_the_hardware() {
        std::thread::spawn(|| {
            flush_denormals_on_this_thread();
            assert_eq!(native_div(f32::from_bits(1), 1.0).to_bits(), 0, "FTZ/DAZ not in effect");
            let mut vals = std::vec::Vec::new();
            for bits in [0u32, 1, 2, 0x0000_1234, 0x003f_ffff, 0x0040_0000, 0x007f_ffff, 0x0080_0000, 0x0080_0001, 0x3f80_0000, 0x3fc0_0000, 0x4b80_0000, 0x7f7f_ffff, 0x7f80_0000, 0x7fc0_0000] {
                vals.push(f32::from_bits(bits));
                vals.push(f32::from_bits(bits | SIGN_MASK));
            }
            for &a in &vals {
                for &b in &vals {
                    check_div(a, b);
                }
                assert_eq!(sqrt_exact(a).to_bits(), native_sqrt(black_box(a)).to_bits(), "sqrt {:#x}", a.to_bits());
            }
            // Quotients around the bottom of the normal range (tiny before or after rounding,
            // ties on the denormal grid), and denormal operands of every magnitude.
            let mut x = 0x2545_f491_4f6c_dd1du64;
            let mut next = || {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                x as u32
            };
            for _ in 0..200_000 {
                let (r1, r2) = (next(), next());
                let a = f32::from_bits(0x3f80_0000 | (r1 & MANT_MASK) | (r1 & SIGN_MASK));
                // b in [2^125, 2^128): a / b lands in [2^-128, 2^-124]
                let b = f32::from_bits(((252 + (r2 >> 30) % 3) << 23) | (r2 & MANT_MASK));
                check_div(a, b);
                check_div(f32::from_bits(r1 & 0x807f_ffff), f32::from_bits(r2 & 0x7fff_ffff));
                check_div(f32::from_bits(r2 & 0x7fff_ffff), f32::from_bits(r1 & 0x807f_ffff));
                let d = f32::from_bits(r1 & 0x807f_ffff);
                assert_eq!(sqrt_exact(d).to_bits(), native_sqrt(black_box(d)).to_bits(), "sqrt {:#x}", d.to_bits());
            }
        })
        .join()
        .unwrap();
    }
}
