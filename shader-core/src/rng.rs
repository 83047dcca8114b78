//! Random and low-discrepancy numbers from integer operations only (identical on CPU and GPU).
//!
//! Conventions: every generator here is a pure function of its integer inputs (seed, stream,
//! index, scramble), so a sequence is reproducible across runs, threads and backends. Floats
//! are `k / 2^24` for an integer `k` in [0, 2^24): always in [0, 1), never 1, exactly
//! representable.
//!
//! ```
//! use shader_core::rng::{radical_inverse_base2, u32_to_unit_f32, Pcg32};
//! // The same seed and stream give the same sequence.
//! let mut a = Pcg32::new(42, 7);
//! let mut b = Pcg32::new(42, 7);
//! let xs: Vec<u32> = (0..8).map(|_| a.next_u32()).collect();
//! let ys: Vec<u32> = (0..8).map(|_| b.next_u32()).collect();
//! assert_eq!(xs, ys);
//! // Another stream gives another sequence.
//! let mut c = Pcg32::new(42, 8);
//! assert_ne!(xs, (0..8).map(|_| c.next_u32()).collect::<Vec<u32>>());
//! // It is O'Neill's pcg32 (XSH-RR 64/32): seed 42, stream 54 gives the reference demo's output.
//! let mut r = Pcg32::new(42, 54);
//! let first: Vec<u32> = (0..6).map(|_| r.next_u32()).collect();
//! assert_eq!(first, [0xa15c02b7, 0x7b47f409, 0xba1d3330, 0x83d2f293, 0xbfa4784b, 0xcbed606e]);
//! // Unit floats are in [0, 1): the largest is 1 - 2^-24.
//! assert_eq!(u32_to_unit_f32(u32::MAX), 1.0 - 1.0 / 16_777_216.0);
//! assert_eq!(radical_inverse_base2(1), 0.5);
//! ```

use crate::ieee;

/// PCG hash of one 32-bit word (Jarzynski & Olano 2020, "Hash Functions for GPU Rendering", pcg).
#[inline]
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// A PCG32 generator (O'Neill 2014, "PCG: A Family of Simple Fast Space-Efficient Statistically
/// Good Algorithms for Random Number Generation", XSH-RR 64/32) with 64-bit state kept as two u32
/// words so it runs without the Int64 capability.
#[derive(Clone, Copy, Debug)]
pub struct Pcg32 {
    lo: u32,
    hi: u32,
    inc_lo: u32,
    inc_hi: u32,
}

/// 64-bit multiply-add on (hi, lo) pairs: a * b + c mod 2^64.
#[inline]
fn mul_add_u64(a_hi: u32, a_lo: u32, b_hi: u32, b_lo: u32, c_hi: u32, c_lo: u32) -> (u32, u32) {
    // a_lo * b_lo as a full 64-bit product from 16-bit halves.
    let (a0, a1) = (a_lo & 0xffff, a_lo >> 16);
    let (b0, b1) = (b_lo & 0xffff, b_lo >> 16);
    let p00 = a0 * b0;
    let p01 = a0 * b1;
    let p10 = a1 * b0;
    let p11 = a1 * b1;
    let mid = (p00 >> 16) + (p01 & 0xffff) + (p10 & 0xffff);
    let lo = (p00 & 0xffff) | (mid << 16);
    let hi = p11 + (p01 >> 16) + (p10 >> 16) + (mid >> 16);
    let hi = hi
        .wrapping_add(a_hi.wrapping_mul(b_lo))
        .wrapping_add(a_lo.wrapping_mul(b_hi));
    let (lo2, carry) = lo.overflowing_add(c_lo);
    let hi2 = hi.wrapping_add(c_hi).wrapping_add(carry as u32);
    (hi2, lo2)
}

impl Pcg32 {
    const MUL_HI: u32 = 0x5851_f42d;
    const MUL_LO: u32 = 0x4c95_7f2d;

    /// Seed with a sequence index (stream) and an offset, as PCG's `pcg32_srandom`.
    #[inline]
    pub fn new(seed: u32, stream: u32) -> Self {
        // inc = (stream << 1) | 1 as a 64-bit value.
        let mut r = Pcg32 { lo: 0, hi: 0, inc_lo: (stream << 1) | 1, inc_hi: stream >> 31 };
        r.next_u32();
        let (lo, c) = r.lo.overflowing_add(seed);
        r.lo = lo;
        r.hi = r.hi.wrapping_add(c as u32);
        r.next_u32();
        r
    }

    /// The next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let (old_hi, old_lo) = (self.hi, self.lo);
        let (hi, lo) = mul_add_u64(old_hi, old_lo, Self::MUL_HI, Self::MUL_LO, self.inc_hi, self.inc_lo);
        self.hi = hi;
        self.lo = lo;
        // xorshifted = ((old >> 18) ^ old) >> 27, as 32 bits.
        let s_lo = (old_lo >> 18) | (old_hi << 14);
        let s_hi = old_hi >> 18;
        let x_lo = s_lo ^ old_lo;
        let x_hi = s_hi ^ old_hi;
        let xorshifted = (x_lo >> 27) | (x_hi << 5);
        let rot = old_hi >> 27;
        xorshifted.rotate_right(rot)
    }

    /// A uniform float in [0, 1).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        u32_to_unit_f32(self.next_u32())
    }
}

/// The top 24 bits of `bits` as a float in [0, 1) (exact: every value is k / 2^24).
#[inline]
pub fn u32_to_unit_f32(bits: u32) -> f32 {
    (bits >> 8) as f32 * (ieee::div(1.0, 16_777_216.0))
}

/// Reverse the bits of a 32-bit word with shifts and masks.
#[inline]
pub fn reverse_bits(mut v: u32) -> u32 {
    v = ((v >> 1) & 0x5555_5555) | ((v & 0x5555_5555) << 1);
    v = ((v >> 2) & 0x3333_3333) | ((v & 0x3333_3333) << 2);
    v = ((v >> 4) & 0x0f0f_0f0f) | ((v & 0x0f0f_0f0f) << 4);
    v = ((v >> 8) & 0x00ff_00ff) | ((v & 0x00ff_00ff) << 8);
    (v >> 16) | (v << 16)
}

/// Van der Corput radical inverse in base 2 of `i`, in [0, 1).
#[inline]
pub fn radical_inverse_base2(i: u32) -> f32 {
    u32_to_unit_f32(reverse_bits(i))
}

/// Sobol dimension 2 (primitive polynomial x + 1, Joe & Kuo direction numbers v_0 = 2^31,
/// v_(k+1) = v_k ^ (v_k >> 1): the Pascal triangle mod 2) of index `i`, bit-reversed: bit j is
/// the XOR of the bits k of `i` with j a bit-subset of k (Lucas' theorem: C(k, j) is odd), the
/// subset-sum transform in five shift-and-mask steps instead of a loop over the bits of `i`.
#[inline]
pub fn sobol_dim2_reversed(i: u32) -> u32 {
    let mut r = i;
    r ^= (r >> 1) & 0x5555_5555;
    r ^= (r >> 2) & 0x3333_3333;
    r ^= (r >> 4) & 0x0f0f_0f0f;
    r ^= (r >> 8) & 0x00ff_00ff;
    r ^= (r >> 16) & 0x0000_ffff;
    r
}

/// The i-th point of the 2D Sobol sequence (first two dimensions; Joe & Kuo direction numbers:
/// dimension 1 is the van der Corput sequence, dimension 2 [`sobol_dim2_reversed`]), XOR-scrambled
/// by `scramble_x`, `scramble_y` (random digit scrambling).
#[inline]
pub fn sobol_2d(i: u32, scramble_x: u32, scramble_y: u32) -> (f32, f32) {
    let x = reverse_bits(i) ^ scramble_x;
    let y = reverse_bits(sobol_dim2_reversed(i)) ^ scramble_y;
    (u32_to_unit_f32(x), u32_to_unit_f32(y))
}

/// Hash-based Owen scrambling in bit-reversed order (Burley 2020, "Practical Hash-based Owen
/// Scrambling", JCGT 9(4), listing 2, after Laine & Karras 2011): a bijection of u32 in which
/// output bit k depends only on input bits 0..=k and the seed, so applied to a bit-reversed
/// value it flips each digit by a hash of the digits above it (a nested uniform scramble).
#[inline]
pub fn laine_karras_permutation(x: u32, seed: u32) -> u32 {
    let mut x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Nested uniform (Owen) scramble of a 32-bit fixed-point value or index (Burley 2020, listing 3).
#[inline]
pub fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    reverse_bits(laine_karras_permutation(reverse_bits(x), seed))
}

/// Sample `index` of a 1D Owen-scrambled Sobol (van der Corput) sequence, its index shuffled by
/// another Owen scramble (Burley 2020, section 4: "shuffled scrambled Sobol"); `seed` picks the
/// scramble, so independent seeds give independent randomized sequences.
#[inline]
pub fn sobol_owen_1d(index: u32, seed: u32) -> f32 {
    let i = nested_uniform_scramble(index, seed);
    // Dimension 1 is reverse_bits(i); its Owen scramble is reverse_bits(LK(i)).
    u32_to_unit_f32(reverse_bits(laine_karras_permutation(i, pcg_hash(seed ^ 0x5b1d_0001))))
}

/// Sample `index` of a 2D Owen-scrambled, index-shuffled Sobol sequence (dimensions 1 and 2;
/// Burley 2020, section 4); each prefix of 2^m samples is a (0, m, 2)-net for every seed.
#[inline]
pub fn sobol_owen_2d(index: u32, seed: u32) -> (f32, f32) {
    let i = nested_uniform_scramble(index, seed);
    let x = reverse_bits(laine_karras_permutation(i, pcg_hash(seed ^ 0x5b1d_0001)));
    let y = reverse_bits(laine_karras_permutation(sobol_dim2_reversed(i), pcg_hash(seed ^ 0x5b1d_0002)));
    (u32_to_unit_f32(x), u32_to_unit_f32(y))
}

/// The i-th point of the R2 sequence (Roberts 2018, plastic-constant Kronecker lattice), computed
/// in 32-bit fixed point so it is exact and identical everywhere; `offset` is a per-stream shift.
#[inline]
pub fn r2(i: u32, offset_x: u32, offset_y: u32) -> (f32, f32) {
    // 2^32 / g and 2^32 / g^2 with g = 1.32471795724474602596 (plastic number).
    let x = i.wrapping_mul(3_242_174_889).wrapping_add(offset_x);
    let y = i.wrapping_mul(2_447_445_413).wrapping_add(offset_y);
    (u32_to_unit_f32(x), u32_to_unit_f32(y))
}
