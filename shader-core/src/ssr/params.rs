//! The constants every SSR pass reads: one f32 buffer (`SsrParams::LEN` values; integers stored
//! as their bits), written by the host and read identically by both backends.
//!
//! Conventions (documented in docs/ssr.md):
//! * View space: x right, y up, +z forward; linear depth = view z > 0; sky = +inf depth.
//! * Projection: reverse-Z infinite perspective, rows (P00, 0, P02, 0), (0, P11, P12, 0),
//!   (0, 0, 0, near), (0, 0, 1, 0); device depth d = near / z (1 at the near plane, 0 at infinity).
//! * Screen space: pixel (i, j) covers [i, i+1) x [j, j+1), row 0 at the top; UV = screen / size.
//! * Motion vectors: UV(current) - UV(previous), in UV units (HDRP's convention).

use super::mat4::Mat4;

/// Index of each value in the parameter buffer.
pub mod idx {
    pub const WIDTH: usize = 0;
    pub const HEIGHT: usize = 1;
    pub const NEAR: usize = 2;
    pub const THICKNESS_SCALE: usize = 3;
    pub const THICKNESS_BIAS: usize = 4;
    pub const EDGE_FADE_RCP_LENGTH: usize = 5;
    pub const ROUGHNESS_FADE_RCP_LENGTH: usize = 6;
    pub const ROUGHNESS_FADE_END_TIMES_RCP_LENGTH: usize = 7;
    pub const ROUGHNESS_FADE_END: usize = 8;
    pub const HIZ_MAX_ITERATIONS: usize = 9;
    pub const DEPTH_MAX_MIP: usize = 10;
    pub const LINEAR_STEPS: usize = 11;
    pub const TRACE_MODE: usize = 12;
    pub const COLOR_MAX_MIP: usize = 13;
    pub const FRAME: usize = 14;
    pub const FLAGS: usize = 15;
    pub const HIZ_ROUGHNESS_CUT: usize = 16;
    pub const ROUGH_LINEAR_STEPS: usize = 17;
    pub const SAMPLES_PER_PIXEL: usize = 18;
    pub const RAYS_PER_QUAD: usize = 19;
    pub const SAMPLE_BIAS: usize = 20;
    pub const RESOLVE_RADIUS: usize = 21;
    pub const TEMPORAL_ALPHA: usize = 22;
    pub const MIP_COUNT: usize = 23;
    pub const SAMPLER: usize = 24;
    pub const HISTORY_DEPTH_TOLERANCE: usize = 25;
    pub const HISTORY_NORMAL_COS: usize = 26;
    pub const TEMPORAL_REPROJECTION: usize = 27;
    pub const HISTORY_ROUGHNESS_TOLERANCE: usize = 28;
    pub const VIEW: usize = 32;
    pub const PROJ: usize = 48;
    pub const INV_VIEW: usize = 64;
    pub const PREV_PROJ: usize = 80;
    pub const PREV_INV_VIEW: usize = 96;
    pub const LEN: usize = 112;
}

/// Trace modes.
pub const TRACE_HIZ: u32 = 0;
pub const TRACE_LINEAR: u32 = 1;
pub const TRACE_BRUTE_FORCE: u32 = 2;
/// Linear march that also accepts a surface crossed between two steps (the stochastic
/// pipeline's cheap tracer for rough rays).
pub const TRACE_LINEAR_CROSSING: u32 = 3;

/// GGX visible-normal samplers of `shader_core::vndf` for the stochastic rays (the `SAMPLER`
/// value). Importance-sampling bias truncates the u that maps to the lobe's radial/height
/// coordinate: u1 for Heitz (disk radius r = sqrt(u1)), u2 for the spherical caps and the
/// bounded caps (cap height z = (1 - u2)(1 + b) - b; their u1 is the azimuth).
pub const SAMPLER_HEITZ: u32 = 0;
pub const SAMPLER_CAPS: u32 = 1;
pub const SAMPLER_BOUNDED: u32 = 2;

/// Temporal reprojection of the reflection history (the `TEMPORAL_REPROJECTION` value): through
/// the surface's motion vector, or through the reflected hit's virtual image.
pub const REPROJECT_SURFACE: u32 = 0;
pub const REPROJECT_HIT: u32 = 1;

/// Flag bits.
pub const FLAG_BACKFACE_REJECT: u32 = 1;
/// Stochastic pass: sample rays from the GGX VNDF (otherwise mirror rays).
pub const FLAG_STOCHASTIC: u32 = 2;
/// Resolve: filtered importance sampling from the colour pyramid.
pub const FLAG_FIS: u32 = 4;
/// Resolve: reuse neighbours' rays (otherwise only the pixel's own rays).
pub const FLAG_REUSE: u32 = 8;
/// Stochastic resolve: weight rays with the pdf stored at sampling time (Stachowiak's form)
/// instead of the generating pixel's pdf at the reconstructed hit direction.
pub const FLAG_SAMPLED_PDF: u32 = 16;

/// The decoded parameters.
#[derive(Clone, Copy, Debug)]
pub struct SsrParams {
    pub width: u32,
    pub height: u32,
    pub near: f32,
    pub thickness_scale: f32,
    pub thickness_bias: f32,
    pub edge_fade_rcp_length: f32,
    pub roughness_fade_rcp_length: f32,
    pub roughness_fade_end_times_rcp_length: f32,
    pub roughness_fade_end: f32,
    pub hiz_max_iterations: u32,
    pub depth_max_mip: u32,
    pub linear_steps: u32,
    pub trace_mode: u32,
    pub color_max_mip: u32,
    pub frame: u32,
    pub flags: u32,
    pub hiz_roughness_cut: f32,
    pub rough_linear_steps: u32,
    pub samples_per_pixel: u32,
    pub rays_per_quad: u32,
    pub sample_bias: f32,
    pub resolve_radius: u32,
    pub temporal_alpha: f32,
    pub mip_count: u32,
    pub sampler: u32,
    /// History rejection: largest relative difference of linear depth between the pixel and its
    /// reprojected history texel (0 or less: no depth test).
    pub history_depth_tolerance: f32,
    /// History rejection: smallest cosine between the pixel's normal and the history texel's
    /// (-1 or less: no normal test).
    pub history_normal_cos: f32,
    pub temporal_reprojection: u32,
    /// History rejection: largest difference of perceptual roughness between the pixel and the
    /// history texel's surface (negative: no roughness test).
    pub history_roughness_tolerance: f32,
    pub view: Mat4,
    pub proj: Mat4,
    pub inv_view: Mat4,
    /// The previous frame's camera (history rejection reconstructs its positions).
    pub prev_proj: Mat4,
    pub prev_inv_view: Mat4,
}

#[inline]
fn u(buf: &[f32], i: usize) -> u32 {
    buf[i].to_bits()
}

impl SsrParams {
    /// Decode the parameter buffer.
    #[inline]
    pub fn load(b: &[f32]) -> SsrParams {
        SsrParams {
            width: u(b, idx::WIDTH),
            height: u(b, idx::HEIGHT),
            near: b[idx::NEAR],
            thickness_scale: b[idx::THICKNESS_SCALE],
            thickness_bias: b[idx::THICKNESS_BIAS],
            edge_fade_rcp_length: b[idx::EDGE_FADE_RCP_LENGTH],
            roughness_fade_rcp_length: b[idx::ROUGHNESS_FADE_RCP_LENGTH],
            roughness_fade_end_times_rcp_length: b[idx::ROUGHNESS_FADE_END_TIMES_RCP_LENGTH],
            roughness_fade_end: b[idx::ROUGHNESS_FADE_END],
            hiz_max_iterations: u(b, idx::HIZ_MAX_ITERATIONS),
            depth_max_mip: u(b, idx::DEPTH_MAX_MIP),
            linear_steps: u(b, idx::LINEAR_STEPS),
            trace_mode: u(b, idx::TRACE_MODE),
            color_max_mip: u(b, idx::COLOR_MAX_MIP),
            frame: u(b, idx::FRAME),
            flags: u(b, idx::FLAGS),
            hiz_roughness_cut: b[idx::HIZ_ROUGHNESS_CUT],
            rough_linear_steps: u(b, idx::ROUGH_LINEAR_STEPS),
            samples_per_pixel: u(b, idx::SAMPLES_PER_PIXEL),
            rays_per_quad: u(b, idx::RAYS_PER_QUAD),
            sample_bias: b[idx::SAMPLE_BIAS],
            resolve_radius: u(b, idx::RESOLVE_RADIUS),
            temporal_alpha: b[idx::TEMPORAL_ALPHA],
            mip_count: u(b, idx::MIP_COUNT),
            sampler: u(b, idx::SAMPLER),
            history_depth_tolerance: b[idx::HISTORY_DEPTH_TOLERANCE],
            history_normal_cos: b[idx::HISTORY_NORMAL_COS],
            temporal_reprojection: u(b, idx::TEMPORAL_REPROJECTION),
            history_roughness_tolerance: b[idx::HISTORY_ROUGHNESS_TOLERANCE],
            view: Mat4::load(b, idx::VIEW),
            proj: Mat4::load(b, idx::PROJ),
            inv_view: Mat4::load(b, idx::INV_VIEW),
            prev_proj: Mat4::load(b, idx::PREV_PROJ),
            prev_inv_view: Mat4::load(b, idx::PREV_INV_VIEW),
        }
    }
}

/// Width of mip `level` of a pyramid whose level 0 is `w` wide: ceil(w / 2^level), at least 1.
#[inline]
pub fn mip_size(w: u32, level: u32) -> u32 {
    let s = (w + (1 << level) - 1) >> level;
    if s == 0 {
        1
    } else {
        s
    }
}
