//! Screen-space reflections: Unity HDRP's tracer and resolves, and Frostbite's stochastic SSR
//! (Stachowiak 2015), as per-pixel functions shared by the CPU backend and the SPIR-V kernels.
//!
//! * [`mat4`]: a 4x4 f32 matrix with a fixed evaluation order (cameras).
//! * [`params`]: the parameter record every pass reads, and the coordinate conventions.
//! * [`layout`]: the layouts of the buffers the passes share, and the decoded G-buffer texel.
//! * [`compare`]: float min / max / clamp / floor to an index with fixed NaN rules.
//! * [`sampling`]: reflection rays of a pixel (mirror, or GGX visible-normal samples).
//! * [`trace`]: G-buffer decoding, reflection rays, Hi-Z / linear / brute-force tracing.
//! * [`resolve`]: HDRP fades, colour-pyramid sampling, SSR_APPROX and neighbourhood resolves.
//! * [`hits`]: per-ray hit records the neighbourhood resolves read (computed once per ray).
//! * [`specular`]: the reflection times the preintegrated FG term from the energy tables.
//! * [`stochastic`]: Frostbite-style stochastic SSR (tiles, ray list, VNDF rays, reuse, temporal).
//!
//! Every pass is a function of one pixel (or tile) reading flat `f32` buffers (G-buffer, depth and
//! colour pyramids, ray records) laid out as the `*_STRIDE` constants of [`layout`] (and of
//! [`stochastic`] for its tile and ray lists) describe, with the parameters of
//! [`params::SsrParams`]; the conventions (view space, reverse-Z projection, screen space) are
//! listed in [`params`].
//!
//! ```
//! use shader_core::ssr::{params::SsrParams, trace::GBUF_STRIDE, resolve::OUT_STRIDE};
//! assert_eq!((core::mem::size_of::<SsrParams>(), GBUF_STRIDE, OUT_STRIDE), (448, 8, 4));
//! ```

pub mod compare;
pub mod hits;
pub mod layout;
pub mod mat4;
pub mod params;
pub mod resolve;
pub mod sampling;
pub mod specular;
pub mod stochastic;
pub mod trace;
