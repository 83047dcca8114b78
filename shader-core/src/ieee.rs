//! Correctly rounded `f32` division and square root (IEEE 754-2019 §5.4.1, round to nearest even) built only from the operations the Vulkan spec ("Precision and Operation of SPIR-V Instructions") requires to be correctly rounded.
//!
//! Vulkan lets `OpFDiv` be off by 2.5 ULP and GLSL.std.450 `Sqrt`/`InverseSqrt` be approximate, so
//! every division and square root in this crate (and in kernels built on it) goes through [`div`] and
//! [`sqrt`] here. In the SPIR-V build they run the software routines [`div_soft`] and
//! [`sqrt_soft`]; on the CPU they are the native `divss`/`sqrtss`, which give the same bits (the
//! proof below), only faster ([`EXACT`], [`SOFT_ON_CPU`]). The software routines use only `f32` add/sub/mul (exact under round-to-nearest, no contraction:
//! the shader build decorates them `NoContraction`), comparisons, bit casts, 32-bit integer
//! arithmetic and `i32`/`u32` casts: no `OpFDiv`, no square-root instruction, no FMA, no 64-bit
//! integers.
//!
//! Method (both functions): unpack the operands into a significand in [1, 2) (denormals
//! normalised) and an exponent; approximate with a Newton iteration from a linear or bit-trick
//! seed; correct once with the residual computed by Dekker's TwoProduct (exact without FMA under
//! round-to-nearest); then decide the last bit exactly by the sign of an exact residual against the
//! rounding midpoint; finally scale by the exponent with one rounding (denormal results rounded
//! once, gradual underflow; overflow to infinity).
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
//! Proof: this crate's `ieee_exhaustive` test compares [`sqrt_soft`] with the native square
//! root on all 2^32 bit patterns and [`div_soft`] with the native `/` on structured and random
//! pairs (10^10 of them).
//!
//! ```
//! use shader_core::ieee::{div, div_soft, rsqrt, sqrt, sqrt_soft};
//! let pairs = [(1.0f32, 3.0f32), (2.0, 7.0), (-0.0, 5.0), (1.0e-40, 3.0), (3.0e38, 0.1), (1.0, 0.0)];
//! for (a, b) in pairs {
//!     let native = std::hint::black_box(a) / std::hint::black_box(b);
//!     // Same bits as the native division, on either path.
//!     assert_eq!(div(a, b).to_bits(), native.to_bits());
//!     assert_eq!(div_soft(a, b).to_bits(), native.to_bits());
//! }
//! for x in [2.0f32, 0.5, 1.0e-41, 3.0e38, -0.0, f32::INFINITY] {
//!     assert_eq!(sqrt_soft(x).to_bits(), std::hint::black_box(x).sqrt().to_bits());
//!     assert_eq!(sqrt(x).to_bits(), sqrt_soft(x).to_bits());
//! }
//! // Invalid operations give x86's default NaN; sqrt(-0) = -0.
//! assert_eq!(div_soft(0.0, 0.0).to_bits(), 0xffc0_0000);
//! assert_eq!(sqrt_soft(-1.0).to_bits(), 0xffc0_0000);
//! assert_eq!(sqrt_soft(-0.0).to_bits(), (-0.0f32).to_bits());
//! // rsqrt is two roundings: 1 / sqrt(x), not a fused reciprocal square root.
//! assert_eq!(rsqrt(2.0), div(1.0, sqrt(2.0)));
//! ```

/// The one switch: `true` (default): in the SPIR-V build [`div`] and [`sqrt`] are the software
/// routines [`div_soft`] and [`sqrt_soft`] (bit-exact on any conformant Vulkan device). `false`
/// (feature `native-div-sqrt`, for a second, faster SPIR-V build of the same kernels): they are
/// `OpFDiv` and GLSL.std.450 `Sqrt`, correctly rounded on Mesa lavapipe but only to 2.5 / ~2 ULP
/// on other drivers, so bit-exactness with the CPU is then no longer promised.
pub const EXACT: bool = !cfg!(feature = "native-div-sqrt");

/// `true`: the CPU build runs the software routines too. Off by default: x86-64 `divss` and
/// `sqrtss` give the same bits (proven by this crate's `ieee_exhaustive` test) 6-7 times
/// faster in the kernels; turning it on changes no result.
pub const SOFT_ON_CPU: bool = false;

/// Whether [`div`] and [`sqrt`] take the software path in this build.
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
/// denormals normalised.
#[inline]
fn unpack(abs_bits: u32) -> (f32, i32) {
    let mut bits = abs_bits;
    let mut bias = 127;
    if bits < MIN_NORMAL_BITS {
        bits = (f32::from_bits(bits) * pow2i(24)).to_bits(); // exact
        bias = 127 + 24;
    }
    let e = (bits >> 23) as i32 - bias;
    (f32::from_bits((bits & MANT_MASK) | ONE_BITS), e)
}

/// A magnitude (bits without sign) as the floating-point environment reads it: a denormal is
/// read as zero where the environment flushes denormals (DAZ: a device that flushes them, and the
/// CPU backend's threads then, which set FTZ/DAZ), else kept. Found by one multiplication by 2^24,
/// exact where denormals are kept; so the software routines treat a denormal operand as the
/// hardware `divss`/`sqrtss` do under the same controls, and their denormal results, made by a
/// multiplication in [`scale_rounded`], flush as the hardware's do (x86: tininess after rounding).
#[inline]
fn env_magnitude(abs_bits: u32) -> u32 {
    if abs_bits < MIN_NORMAL_BITS && (f32::from_bits(abs_bits) * pow2i(24)).to_bits() == 0 {
        0
    } else {
        abs_bits
    }
}

/// The NaN x86 returns for a NaN operand: the operand with its quiet bit set.
#[inline]
fn quiet(bits: u32) -> f32 {
    f32::from_bits(bits | QUIET_BIT)
}

/// The spacing of the f32 grid just above (`up`) and just below (`dn`) q > 0, normal.
#[inline]
fn ulps(q: f32) -> (f32, f32) {
    let up = f32::from_bits(q.to_bits() & INF_BITS) * pow2i(-23);
    let dn = if (q.to_bits() & MANT_MASK) == 0 { 0.5 * up } else { up };
    (up, dn)
}

/// q * 2^k rounded once (ties to even) for q = RN(Q) in [0.5, 2) and the sign `dir` of Q - q:
/// normal and overflowing results by exact scaling, denormal results by rounding q to the
/// denormal grid, where a tie of q is broken by `dir` (the only case where rounding q twice
/// differs from rounding Q once).
#[inline]
fn scale_rounded(q: f32, dir: i32, k: i32) -> f32 {
    if k >= -125 {
        let k = if k > 129 { 129 } else { k };
        if k > 127 {
            return (q * pow2i(127)) * pow2i(k - 127);
        }
        return q * pow2i(k);
    }
    let k = if k < -160 { -160 } else { k }; // below 2^-159 everything rounds to 0 anyway
    let hs = q * pow2i(k + 100); // exact, normal
    let r1 = hs * pow2i(-100); // one rounding onto the denormal grid
    let t = hs - (r1 * pow2i(100)); // exact: what that rounding removed (scaled by 2^100)
    let half = pow2i(-50); // half the denormal spacing 2^-149, scaled by 2^100
    if t == half && dir > 0 {
        r1 + f32::from_bits(1)
    } else if t == -half && dir < 0 {
        r1 - f32::from_bits(1)
    } else {
        r1
    }
}

/// a / b correctly rounded (round to nearest, ties to even), denormals and signed zeros
/// included; NaN rules as x86 `divss`: [`div_soft`] where [`SOFT`], else the native `/`.
#[inline]
pub fn div(a: f32, b: f32) -> f32 {
    if SOFT { div_soft(a, b) } else { a / b }
}

/// sqrt(x) correctly rounded (round to nearest even): sqrt(-0) = -0, sqrt(inf) = inf, x < 0
/// gives the default NaN, a NaN is returned quieted (x86 `sqrtss`): [`sqrt_soft`] where
/// [`SOFT`], else the native square root.
#[inline]
pub fn sqrt(x: f32) -> f32 {
    if SOFT { sqrt_soft(x) } else { native_sqrt(x) }
}

/// [`div`] by the software routine, on every target. Not inlined: rust-gpu inlines every
/// `#[inline]` function at each call site, which gave every division in a kernel its own ~200
/// instructions (the path tracer's entry point was 650 k instructions) and the drivers that much
/// more to compile; one function per module instead (the CPU calls it only in tests and probes).
#[inline(never)]
pub fn div_soft(a: f32, b: f32) -> f32 {
    let (ua, ub) = (a.to_bits(), b.to_bits());
    let sign = (ua ^ ub) & SIGN_MASK;
    let (aa, ab) = (env_magnitude(ua & ABS_MASK), env_magnitude(ub & ABS_MASK));
    // Zero (a flushed denormal included), infinite or NaN operands (kept denormals go on to the
    // general path).
    if aa == 0 || ab == 0 || aa >= INF_BITS || ab >= INF_BITS {
        if aa > INF_BITS {
            return quiet(ua);
        }
        if ab > INF_BITS {
            return quiet(ub);
        }
        if (aa == INF_BITS && ab == INF_BITS) || (aa == 0 && ab == 0) {
            return f32::from_bits(DEFAULT_NAN_BITS);
        }
        if aa == INF_BITS || ab == 0 {
            return f32::from_bits(sign | INF_BITS);
        }
        return f32::from_bits(sign); // 0 / b or a / inf
    }
    let (xa, ea) = unpack(aa);
    let (xb, eb) = unpack(ab);
    // Q = xa / xb in (1/2, 2). y ~ 1/xb: linear seed (rel. error <= 1/17), two Newton steps
    // (rel. error ~2^-16).
    let (bh, bl) = split(xb);
    let mut y = 1.411_764_7 - (0.470_588_24 * xb);
    y = y + (y * (1.0 - (xb * y)));
    y = y + (y * (1.0 - (xb * y)));
    let q0 = xa * y;
    // One correction with the TwoProduct residual: |Q - q| <= 1/2 ULP + 2^-30 ULP.
    let (p0, e0) = two_prod_split(q0, bh, bl);
    let r0 = (xa - p0) - e0;
    let mut q = q0 + (r0 * y);
    // The last bit, exactly: with |Q - q| < 1 ULP the remainder r = xa - q xb is a float and
    // 2r, u xb are exact, so comparing them places Q against the midpoints q +- u/2 (Q is never
    // a midpoint: a 24-bit quotient of 24-bit significands cannot end in a single 25th bit).
    let (p1, e1) = two_prod_split(q, bh, bl);
    let r1 = (xa - p1) - e1;
    let (up, dn) = ulps(q);
    let mut dir = 0;
    if (2.0 * r1) > (up * xb) {
        q = q + up;
        dir = -1;
    } else if (2.0 * r1) < -(dn * xb) {
        q = q - dn;
        dir = 1;
    } else if r1 > 0.0 {
        dir = 1;
    } else if r1 < 0.0 {
        dir = -1;
    }
    let m = scale_rounded(q, dir, ea - eb);
    f32::from_bits(m.to_bits() | sign)
}

/// [`sqrt`] by the software routine, on every target. Not inlined, as [`div_soft`].
#[inline(never)]
pub fn sqrt_soft(x: f32) -> f32 {
    let ux = x.to_bits();
    let ax = env_magnitude(ux & ABS_MASK);
    if ax == 0 || ux >= INF_BITS {
        if ax > INF_BITS {
            return quiet(ux);
        }
        if ax == 0 {
            return f32::from_bits(ux & SIGN_MASK); // a zero, or a denormal the environment flushed
        }
        if ux == INF_BITS {
            return x;
        }
        return f32::from_bits(DEFAULT_NAN_BITS); // x < 0
    }
    let (mut m, mut e) = unpack(ax);
    if (e & 1) != 0 {
        m = 2.0 * m; // m in [2, 4), e even
        e = e - 1;
    }
    // y ~ 1/sqrt(m): bit-trick seed (rel. error < 3.5%), two Newton steps (rel. error ~2^-16).
    let hm = 0.5 * m;
    let mut y = f32::from_bits(0x5f37_59df_u32.wrapping_sub(m.to_bits() >> 1));
    y = y * (1.5 - (hm * (y * y)));
    y = y * (1.5 - (hm * (y * y)));
    let s0 = m * y;
    // One correction with the TwoProduct residual m - s0^2.
    let (sh, sl) = split(s0);
    let (p0, e0) = two_prod_split(s0, sh, sl);
    let r0 = (m - p0) - e0;
    let mut s = s0 + (r0 * (0.5 * y));
    // The last bit, exactly. With s+ / s- the floats next to s, the midpoints satisfy
    // mid+^2 = s s+ + u^2/4 and mid-^2 = s s- + u-^2/4; m and the products lie on a grid coarser
    // than those u^2/4, so sqrt(m) > mid+ iff m > s s+, and sqrt(m) < mid- iff m <= s s-
    // (sqrt(s s-) < mid- by the AM-GM inequality). Each comparison is exact: m - p is exact
    // (Sterbenz) and compared with the TwoProduct error term.
    let s_up = f32::from_bits(s.to_bits() + 1);
    let (uh, ul) = split(s_up);
    let (pu, eu) = two_prod_split(s, uh, ul);
    if (m - pu) > eu {
        s = s_up;
    } else {
        let s_dn = f32::from_bits(s.to_bits() - 1);
        let (dh, dl) = split(s_dn);
        let (pd, ed) = two_prod_split(s, dh, dl);
        if (m - pd) <= ed {
            s = s_dn;
        }
    }
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
        let (g, w) = (div_soft(a, b), native_div(a, b));
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
            assert_eq!(sqrt_soft(x).to_bits(), black_box(x).sqrt().to_bits(), "{bits:#x}");
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
                assert_eq!(sqrt_soft(a).to_bits(), native_sqrt(black_box(a)).to_bits(), "sqrt {:#x}", a.to_bits());
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
                assert_eq!(sqrt_soft(d).to_bits(), native_sqrt(black_box(d)).to_bits(), "sqrt {:#x}", d.to_bits());
            }
        })
        .join()
        .unwrap();
    }
}
