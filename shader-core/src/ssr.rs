//! Screen-space reflections: Unity HDRP's tracer and resolves, and Frostbite's stochastic SSR
//! (Stachowiak 2015), as per-pixel functions shared by the CPU backend and the SPIR-V kernels.
//!
//! * [`mat4`]: a 4x4 f32 matrix with a fixed evaluation order (cameras).
//! * [`params`]: the parameter buffer every pass reads, and the coordinate conventions.
//! * [`trace`]: G-buffer decoding, reflection rays, Hi-Z / linear / brute-force tracing.
//! * [`resolve`]: HDRP fades, colour-pyramid sampling, SSR_APPROX and neighbourhood resolves.
//! * [`specular`]: the reflection times the preintegrated FG term from the energy tables.
//! * [`stochastic`]: Frostbite-style stochastic SSR (tiles, ray list, VNDF rays, reuse, temporal).

pub mod mat4;
pub mod params;
pub mod resolve;
pub mod specular;
pub mod stochastic;
pub mod trace;
