//! The path tracer's sample generator (PBRT-v4 section 8.3 `Sampler`: `Get1D`, `Get2D` over
//! consecutive dimensions of one pixel sample). Two kinds, chosen by `RenderParams::sampler`:
//!
//! - [`SAMPLER_SOBOL`]: padded Owen-scrambled Sobol (PBRT-v4 section 8.7, `PaddedSobolSampler`,
//!   with Burley 2020's hash-based Owen scrambling, [`rng::sobol_owen_2d`]): every 1D or 2D
//!   dimension draws the pixel sample's point of its own randomized Sobol sequence, the index
//!   shuffled and the values scrambled by a hash of (seed, pixel, dimension). Each 2^m prefix of a
//!   dimension's points over a pixel's samples is stratified (a (0, m, 2)-net), so the error of a
//!   smooth integrand falls faster than spp^-1/2; each sample alone is uniform (unbiased).
//! - [`SAMPLER_PCG`]: independent uniform numbers, one PCG32 stream per pixel sample
//!   ([`sample_rng`]), the 1D and 2D draws taken from the stream in order.
//!
//! Both are integer-only: the same (seed, pixel, sample index) gives the same numbers on every
//! backend, whatever the launch split.
//!
//! ```
//! use shader_core::pt::sampler::{Sampler, SAMPLER_PCG, SAMPLER_SOBOL};
//! // The same (kind, seed, pixel, sample) gives the same numbers.
//! let (mut a, mut b) = (Sampler::new(SAMPLER_SOBOL, 7, 42, 3), Sampler::new(SAMPLER_SOBOL, 7, 42, 3));
//! assert_eq!(a.next_2d(), b.next_2d());
//! assert_eq!(a.next_1d(), b.next_1d());
//! // The 4 samples of one dimension split [0, 1) into 4 strata.
//! let mut cells: Vec<u32> = (0..4).map(|s| (Sampler::new(SAMPLER_SOBOL, 7, 42, s).next_1d() * 4.0) as u32).collect();
//! cells.sort();
//! assert_eq!(cells, [0, 1, 2, 3]);
//! // PCG draws the pixel sample's stream in order.
//! let mut p = Sampler::new(SAMPLER_PCG, 7, 42, 3);
//! let mut r = shader_core::pt::sampler::sample_rng(7, 42, 3);
//! assert_eq!(p.next_2d(), (r.next_f32(), r.next_f32()));
//! ```

use crate::rng::{self, pcg_hash, Pcg32};

/// Independent PCG32 numbers per pixel sample.
pub const SAMPLER_PCG: u32 = 0;
/// Padded Owen-scrambled Sobol.
pub const SAMPLER_SOBOL: u32 = 1;

/// The PCG32 stream of sample `s` of pixel `pixel`.
#[inline]
pub fn sample_rng(seed: u32, pixel: u32, s: u32) -> Pcg32 {
    Pcg32::new(pcg_hash(seed ^ pcg_hash(s)), pixel)
}

/// The random numbers of one pixel sample, drawn dimension after dimension.
#[derive(Clone, Copy, Debug)]
pub struct Sampler {
    kind: u32,
    /// Hash of (seed, pixel): the Sobol scrambles' key.
    key: u32,
    /// The sample's index within its pixel.
    index: u32,
    /// The next dimension (Sobol).
    dim: u32,
    rng: Pcg32,
}

impl Sampler {
    /// The sampler of sample `index` of pixel `pixel` of a render with seed `seed`.
    #[inline]
    pub fn new(kind: u32, seed: u32, pixel: u32, index: u32) -> Sampler {
        Sampler { kind, key: pcg_hash(seed ^ pcg_hash(pixel ^ 0x9e37_79b9)), index, dim: 0, rng: sample_rng(seed, pixel, index) }
    }

    /// The scramble seed of the next dimension.
    #[inline]
    fn dimension_seed(&mut self) -> u32 {
        let s = pcg_hash(self.key ^ pcg_hash(self.dim));
        self.dim += 1;
        s
    }

    /// One number in [0, 1).
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        if self.kind == SAMPLER_SOBOL {
            let s = self.dimension_seed();
            rng::sobol_owen_1d(self.index, s)
        } else {
            self.rng.next_f32()
        }
    }

    /// Two numbers in [0, 1), stratified together (Sobol).
    #[inline]
    pub fn next_2d(&mut self) -> (f32, f32) {
        if self.kind == SAMPLER_SOBOL {
            let s = self.dimension_seed();
            rng::sobol_owen_2d(self.index, s)
        } else {
            let u0 = self.rng.next_f32();
            (u0, self.rng.next_f32())
        }
    }
}
