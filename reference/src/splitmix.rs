//! SplitMix64 (Steele, Lea & Flood 2014, "Fast Splittable Pseudorandom Number Generators",
//! OOPSLA; the finalizer of Java's `SplittableRandom`): the reproducible inputs of the test
//! suites, one generator for all of them.
//!
//! ```
//! use reference::splitmix::SplitMix64;
//! let mut r = SplitMix64(0);
//! assert_eq!(r.next_u64(), 0xe220_a839_7b1d_cdaf);
//! assert_eq!(SplitMix64::mix(0), 0xe220_a839_7b1d_cdaf);
//! assert!((0.0..1.0).contains(&r.next_f32()));
//! ```

/// The generator's state (a 64-bit counter stepped by the golden-ratio increment).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// The first output of the stream with state `z`: a stateless hash of `z`.
    #[inline]
    pub fn mix(z: u64) -> u64 {
        SplitMix64(z).next_u64()
    }

    /// A uniform f32 in [0, 1) from the top 24 bits of the next output.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / 16_777_216.0)
    }
}
