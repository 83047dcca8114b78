//! The constants every SSR pass reads: one [`SsrParams`] record (`#[repr(C)]`, 4-byte fields,
//! a `bytemuck::Pod` on the host), written by the host and bound as it is by every kernel, so the
//! layout is the struct's and both backends read the same fields.
//!
//! Conventions:
//! * View space: x right, y up, +z forward; linear depth = view z > 0; sky = +inf depth.
//! * Projection: reverse-Z infinite perspective, rows (P00, 0, P02, 0), (0, P11, P12, 0),
//!   (0, 0, 0, near), (0, 0, 1, 0); device depth d = near / z (1 at the near plane, 0 at infinity).
//! * Screen space: pixel (i, j) covers [i, i+1) x [j, j+1), row 0 at the top; UV = screen / size.
//! * Motion vectors: UV(current) - UV(previous), in UV units (HDRP's convention).
//!
//! ```
//! use shader_core::ssr::mat4::Mat4;
//! use shader_core::ssr::params::{mip_size, SsrParams, FLAG_REUSE};
//! let p = SsrParams { width: 640, height: 360, near: 0.1, flags: FLAG_REUSE, view: Mat4::IDENTITY, ..SsrParams::default() };
//! assert_eq!((p.width, p.height, p.near, p.flags), (640, 360, 0.1, FLAG_REUSE));
//! // The record the kernels bind: 32 scalar words, then five row-major matrices.
//! assert_eq!(core::mem::size_of::<SsrParams>(), 4 * (32 + 5 * 16));
//! // Mip sizes round up and never reach 0.
//! assert_eq!((mip_size(640, 1), mip_size(5, 1), mip_size(5, 9)), (320, 3, 1));
//! ```

use super::mat4::Mat4;

/// Trace mode ([`SsrParams::trace_mode`]): HDRP's hierarchical-Z march over the depth pyramid.
pub const TRACE_HIZ: u32 = 0;
/// Trace mode: a fixed number of linear steps in screen space ([`SsrParams::linear_steps`]).
pub const TRACE_LINEAR: u32 = 1;
/// Trace mode: every pixel along the ray (reference tracer; slow).
pub const TRACE_BRUTE_FORCE: u32 = 2;
/// Linear march that also accepts a surface crossed between two steps (the stochastic
/// pipeline's cheap tracer for rough rays).
pub const TRACE_LINEAR_CROSSING: u32 = 3;

/// GGX visible-normal samplers of `shader_core::vndf` for the stochastic rays
/// ([`SsrParams::sampler`]). Importance-sampling bias truncates the u that maps to the lobe's radial/height
/// coordinate: u1 for Heitz (disk radius r = sqrt(u1)), u2 for the spherical caps and the
/// bounded caps (cap height z = (1 - u2)(1 + b) - b; their u1 is the azimuth).
pub const SAMPLER_HEITZ: u32 = 0;
/// Sampler: Dupuy & Benyoub 2023 spherical caps ([`crate::vndf::sample_vndf_caps`]).
pub const SAMPLER_CAPS: u32 = 1;
/// Sampler: Eto & Tokuyoshi 2023 bounded VNDF ([`crate::vndf::sample_vndf_bounded`]).
pub const SAMPLER_BOUNDED: u32 = 2;

/// Temporal reprojection of the reflection history ([`SsrParams::temporal_reprojection`]): through
/// the surface's motion vector, or through the reflected hit's virtual image.
pub const REPROJECT_SURFACE: u32 = 0;
/// Reprojection through the reflected hit point's virtual image.
pub const REPROJECT_HIT: u32 = 1;

/// Flag bit: reject hits on surfaces facing away from the ray (HDRP's back-face rejection).
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
/// Stochastic resolve with filtered importance sampling: each hitting ray's colour is fetched
/// once, by the hits pass, at the cone footprint seen from the ray's own pixel, and every pixel
/// that reuses the ray reads it (FidelityFX SSSR stores a radiance per ray alike); otherwise each
/// (pixel, ray) pair samples the colour pyramid at the footprint seen from the resolving pixel.
pub const FLAG_RAY_COLOR: u32 = 32;

/// The parameters of every SSR pass, bound as they are (`#[repr(C)]`, 4-byte fields: no padding
/// between them; `pad` keeps the matrices 16-byte aligned).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct SsrParams {
    /// Render-target width in pixels.
    pub width: u32,
    /// Render-target height in pixels.
    pub height: u32,
    /// Near-plane distance (view-space units, > 0) of the reverse-Z projection: device depth = near / z.
    pub near: f32,
    /// Object thickness assumed behind the depth buffer, as a multiple of the surface depth (HDRP's
    /// `_SsrThicknessScale`): a ray hits when it is behind the surface by less than
    /// `depth * thickness_scale + thickness_bias`.
    pub thickness_scale: f32,
    /// Constant part of the assumed thickness (HDRP's `_SsrThicknessBias`), linear-depth units.
    pub thickness_bias: f32,
    /// 1 / width of the screen-edge fade, in UV units (HDRP's `_SsrEdgeFadeRcpLength`).
    pub edge_fade_rcp_length: f32,
    /// 1 / length of the perceptual-roughness fade (HDRP's `_SsrRoughnessFadeRcpLength`).
    pub roughness_fade_rcp_length: f32,
    /// Fade end times 1 / fade length (HDRP's `_SsrRoughnessFadeEndTimesRcpLength`).
    pub roughness_fade_end_times_rcp_length: f32,
    /// Perceptual roughness above which no ray is traced (the fade reaches 0).
    pub roughness_fade_end: f32,
    /// Largest number of Hi-Z march iterations per ray.
    pub hiz_max_iterations: u32,
    /// Coarsest level of the depth (Hi-Z) pyramid the tracer may use.
    pub depth_max_mip: u32,
    /// Number of steps of the linear tracers.
    pub linear_steps: u32,
    /// Tracer: [`TRACE_HIZ`], [`TRACE_LINEAR`], [`TRACE_BRUTE_FORCE`] or [`TRACE_LINEAR_CROSSING`].
    pub trace_mode: u32,
    /// Coarsest level of the colour pyramid the resolve samples.
    pub color_max_mip: u32,
    /// Frame index: seeds the per-pixel random numbers and rotates the rays-per-quad pattern.
    pub frame: u32,
    /// `FLAG_*` bits ([`FLAG_BACKFACE_REJECT`], [`FLAG_STOCHASTIC`], [`FLAG_FIS`], [`FLAG_REUSE`],
    /// [`FLAG_SAMPLED_PDF`]).
    pub flags: u32,
    /// Stochastic pipeline: perceptual roughness below which a tile's rays use Hi-Z tracing (rougher
    /// ones the cheap linear tracer).
    pub hiz_roughness_cut: f32,
    /// Number of steps of [`TRACE_LINEAR_CROSSING`] (the rough rays' tracer).
    pub rough_linear_steps: u32,
    /// Stochastic rays per traced pixel.
    pub samples_per_pixel: u32,
    /// Traced pixels per 2x2 quad: 4 (all), 2 (checkerboard, alternating per frame) or 1 (one per
    /// quad, rotating per frame); the others reuse their neighbours' rays.
    pub rays_per_quad: u32,
    /// Importance-sampling bias in [0, 0.999]: the fraction of the lobe's tail cut from the sampled u
    /// (0 = unbiased).
    pub sample_bias: f32,
    /// Neighbourhood radius in pixels of the ray-reuse resolve (0: own rays only).
    pub resolve_radius: u32,
    /// Smallest weight of the current frame in the temporal accumulation (exponential moving average).
    pub temporal_alpha: f32,
    /// Number of levels of the depth and colour pyramids (level 0 included).
    pub mip_count: u32,
    /// Ray sampler: [`SAMPLER_HEITZ`], [`SAMPLER_CAPS`] or [`SAMPLER_BOUNDED`].
    pub sampler: u32,
    /// History rejection: largest relative difference of linear depth between the pixel and its
    /// reprojected history texel (0 or less: no depth test).
    pub history_depth_tolerance: f32,
    /// History rejection: smallest cosine between the pixel's normal and the history texel's
    /// (-1 or less: no normal test).
    pub history_normal_cos: f32,
    /// History reprojection: [`REPROJECT_SURFACE`] or [`REPROJECT_HIT`].
    pub temporal_reprojection: u32,
    /// History rejection: largest difference of perceptual roughness between the pixel and the
    /// history texel's surface (negative: no roughness test).
    pub history_roughness_tolerance: f32,
    /// Texel offset, in the depth-pyramid buffer, of the far-depth layer appended after the
    /// pyramid's mips (width x height linear depths: the farthest depth the surface seen at each
    /// pixel reaches, visibly, within one pixel of its centre; `+inf` for the sky); 0 when there is
    /// none (then every level uses the constant slab of `thickness_scale`, HDRP's rule). See
    /// [`crate::ssr::trace::slab_base`].
    pub far_depth_offset: u32,
    /// With a far-depth layer: the device-depth scale of the thinnest slab a mip-0 texel gets,
    /// 1 / (1 + min_thickness) (HDRP's form of `thickness_scale`), so surfaces seen face-on (far
    /// depth = depth) keep a slab against rounding; 1 gives no minimum.
    pub min_thickness_scale: f32,
    /// Unused.
    pub pad: u32,
    /// World-to-view transform of the current frame.
    pub view: Mat4,
    /// View-to-clip projection of the current frame (reverse-Z infinite perspective).
    pub proj: Mat4,
    /// View-to-world transform of the current frame (the inverse of `view`).
    pub inv_view: Mat4,
    /// The previous frame's camera (history rejection reconstructs its positions).
    pub prev_proj: Mat4,
    /// The previous frame's view-to-world transform.
    pub prev_inv_view: Mat4,
}

/// Number of [`SsrParams`] fields that choose code paths for a whole dispatch (the mode words:
/// [`SsrParams::modes`]), which a GPU pipeline pins as specialization constants 0..
pub const MODE_WORDS: usize = 5;

/// A mode word the pipeline does not pin: the field is read from the record (the kernels'
/// specialization constants default to it).
pub const MODE_UNSET: u32 = u32::MAX;

impl SsrParams {
    /// The mode words: [`SsrParams::flags`], [`SsrParams::sampler`], [`SsrParams::trace_mode`],
    /// [`SsrParams::temporal_reprojection`] and [`SsrParams::rays_per_quad`], the fields whose
    /// value chooses which code a dispatch runs rather than what it computes. The GPU backend
    /// compiles each SSR pipeline with them as specialization constants, so the driver removes
    /// the paths a dispatch never takes (a driver that runs both sides of a branch with lanes
    /// masked, as Mesa 22.3's llvmpipe does, would otherwise pay for them on every invocation).
    #[inline]
    pub fn modes(&self) -> [u32; MODE_WORDS] {
        [self.flags, self.sampler, self.trace_mode, self.temporal_reprojection, self.rays_per_quad]
    }

    /// This record with its mode fields replaced by `modes` ([`SsrParams::modes`]' order), each
    /// one that is not [`MODE_UNSET`]: how a kernel reads the record under its pipeline's
    /// specialization constants. `p.with_modes(p.modes()) == p`.
    #[inline]
    pub fn with_modes(mut self, modes: [u32; MODE_WORDS]) -> SsrParams {
        let pick = |pinned: u32, field: u32| if pinned == MODE_UNSET { field } else { pinned };
        self.flags = pick(modes[0], self.flags);
        self.sampler = pick(modes[1], self.sampler);
        self.trace_mode = pick(modes[2], self.trace_mode);
        self.temporal_reprojection = pick(modes[3], self.temporal_reprojection);
        self.rays_per_quad = pick(modes[4], self.rays_per_quad);
        self
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

/// The columns (or rows) 2x and 2x + 1 of a mip `n` texels wide under column x of the mip above
/// it, the second repeating the first past the edge of an odd size: every texel of a mip lies
/// under exactly one texel of the next.
#[inline]
pub fn mip_children(x: u32, n: u32) -> (u32, u32) {
    let x0 = 2 * x;
    (x0, if x0 + 1 < n { x0 + 1 } else { x0 })
}

/// What one invocation of a pyramid pass writes: the 2x2 texels of mip `level` under one texel of
/// mip `level + 1` (texels (x0, y0), (x1, y0), (x0, y1), (x1, y1) of [`mip_children`]; an index
/// repeats at the far edge of an odd size) and, where the pyramid has mip `level + 1`, that
/// texel, computed from them. A pass so writes two mips per dispatch with one invocation per
/// texel of the coarser one (`trace::hiz_block`, `resolve::color_block`).
#[derive(Clone, Copy, Debug, Default)]
pub struct MipBlock<T> {
    /// Texel indices (in texels of the pyramid buffer) of the block in mip `level`.
    pub texels: [u32; 4],
    /// Their values.
    pub values: [T; 4],
    /// The texel of mip `level + 1` above the block and its value, if that mip exists.
    pub above: Option<(u32, T)>,
}

/// The block of mip `level` (`w` x `h` texels at texel offset `base`) under texel `k` (row-major)
/// of mip `level + 1`: the four texel indices and their (x, y).
#[inline]
pub fn mip_block_texels(w: u32, h: u32, base: u32, k: u32) -> ([u32; 4], [(u32, u32); 4]) {
    let w_above = mip_size(w, 1);
    let (x0, x1) = mip_children(k % w_above, w);
    let (y0, y1) = mip_children(k / w_above, h);
    let xy = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)];
    ([base + y0 * w + x0, base + y0 * w + x1, base + y1 * w + x0, base + y1 * w + x1], xy)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mode_words_pin_their_own_fields_and_nothing_else() {
        let p = SsrParams { flags: 5, sampler: 2, trace_mode: 3, temporal_reprojection: 1, rays_per_quad: 2, width: 7, frame: 9, ..SsrParams::default() };
        assert_eq!(p.modes(), [5, 2, 3, 1, 2]);
        assert_eq!(p.with_modes(p.modes()), p);
        assert_eq!(p.with_modes([MODE_UNSET; MODE_WORDS]), p);
        // Each word sets its field alone.
        let q = p.with_modes([40, MODE_UNSET, MODE_UNSET, MODE_UNSET, MODE_UNSET]);
        assert_eq!(q, SsrParams { flags: 40, ..p });
        let q = p.with_modes([MODE_UNSET, 1, 0, 0, 4]);
        assert_eq!(q, SsrParams { sampler: 1, trace_mode: 0, temporal_reprojection: 0, rays_per_quad: 4, ..p });
        assert_eq!(q.modes(), [5, 1, 0, 0, 4]);
    }
}
