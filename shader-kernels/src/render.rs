//! The path tracer's kernels (`shader_core::pt`): one invocation per pixel, the per-pixel
//! functions [`pixel`] and [`gbuffer_pixel`] called by the `#[spirv(compute)]` entry points
//! [`pt_render`] and [`pt_gbuffer`] and by the CPU launcher.
//!
//! Bindings: 0 = [`RenderArgs`], 1 = scene words (`shader_core::pt::scene`), 2 = environment
//! (`shader_core::pt::environment`), 3 = energy LUT (`shader_core::energy`), 4 = output,
//! [`OUT_STRIDE`] floats per pixel of the launch: radiance sum RGB, albedo sum RGB, normal sum
//! XYZ, depth sum, rays traced. [`pt_gbuffer`] binds [`GBufferArgs`] at 0 and writes
//! [`GBUFFER_STRIDE`] floats per pixel (see [`gbuffer_pixel`]).

use shader_core::buffer::store;
use shader_core::pt::gbuffer::{self, GBufferParams};
use shader_core::pt::integrator::{render_pixel, RenderParams};
use spirv_std::glam::UVec3;
use spirv_std::spirv;

/// Output floats per pixel.
pub const OUT_STRIDE: usize = 11;

/// The launch record of [`pt_render`], shared by the host and the kernel (`#[repr(C)]`, all
/// 4-byte fields): the launch fields the launcher fills, then the integrator's parameters as
/// they are. Invocation `i` renders pixel `first_pixel + i` and writes `out[OUT_STRIDE i..]`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct RenderArgs {
    /// Invocations (pixels) in this launch.
    pub invocations: u32,
    /// Workgroups in x of the 2D dispatch.
    pub groups_x: u32,
    /// Pixel of invocation 0.
    pub first_pixel: u32,
    /// Unused (keeps the parameters 16-byte aligned in the buffer).
    pub pad: u32,
    /// The integrator's parameters.
    pub params: RenderParams,
}

impl RenderArgs {
    /// The record carrying `p` (launch fields zero: the launcher fills them).
    pub fn new(p: &RenderParams) -> RenderArgs {
        RenderArgs { params: *p, ..RenderArgs::default() }
    }
}

/// Invocation `i` of a launch: renders pixel `first_pixel + i` into `out[OUT_STRIDE i..]`.
#[inline]
pub fn pixel(i: u32, args: &RenderArgs, scene: &[u32], env: &[f32], lut: &[f32], out: &mut [f32]) {
    let s = render_pixel(scene, env, lut, &args.params, args.first_pixel + i);
    let o = i as usize * OUT_STRIDE;
    store3(out, o, s.color);
    store3(out, o + 3, s.albedo);
    store3(out, o + 6, s.normal);
    store(out, o + 9, s.depth);
    store(out, o + 10, s.rays);
}

/// Entry point of [`pixel`].
#[spirv(compute(threads(64)))]
pub fn pt_render(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &RenderArgs,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] scene: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] env: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] lut: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] out: &mut [f32],
) {
    let a = *args;
    if let Some(i) = crate::invocation_index(id, a.invocations, a.groups_x) {
        pixel(i, &a, scene, env, lut, out);
    }
}

/// Output floats per pixel of [`pt_gbuffer`].
pub const GBUFFER_STRIDE: usize = 27;

/// Offsets of [`gbuffer_pixel`]'s values in a pixel's `GBUFFER_STRIDE` floats: the G-buffer
/// ([`DEPTH`](gbuffer_out::DEPTH) .. [`DEPTH_FAR`](gbuffer_out::DEPTH_FAR), the same in every
/// launch), then the reference sums from [`ALL`](gbuffer_out::ALL) on (added over launches).
pub mod gbuffer_out {
    /// Linear view depth.
    pub const DEPTH: usize = 0;
    /// World normal XYZ.
    pub const NORMAL: usize = 1;
    /// Perceptual roughness.
    pub const ROUGHNESS: usize = 4;
    /// Metallic.
    pub const METALLIC: usize = 5;
    /// Base colour RGB.
    pub const BASE: usize = 6;
    /// 1 where reference samples were taken, else 0.
    pub const GLOSSY: usize = 9;
    /// Far depth of the texel (`shader_core::pt::gbuffer::GBufferPixel::depth_far`).
    pub const DEPTH_FAR: usize = 10;
    /// Sum of w L, all geometry (RGB); the first summed value.
    pub const ALL: usize = 11;
    /// Sum of w L, on-screen geometry (RGB).
    pub const ONSCREEN: usize = 14;
    /// Sum of w F L, all geometry (RGB).
    pub const SPECULAR_ALL: usize = 17;
    /// Sum of w F L, on-screen geometry (RGB).
    pub const SPECULAR_ONSCREEN: usize = 20;
    /// Sum of w.
    pub const WEIGHT: usize = 23;
    /// Sum of w over samples the same both ways.
    pub const WEIGHT_SAME: usize = 24;
    /// Samples taken.
    pub const SAMPLES: usize = 25;
    /// Rays traced.
    pub const RAYS: usize = 26;
}

/// The launch record of [`pt_gbuffer`]: the launch fields, then the G-buffer parameters.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct GBufferArgs {
    /// Invocations (pixels) in this launch.
    pub invocations: u32,
    /// Workgroups in x of the 2D dispatch.
    pub groups_x: u32,
    /// Pixel of invocation 0.
    pub first_pixel: u32,
    /// Unused (keeps the parameters 16-byte aligned in the buffer).
    pub pad: u32,
    /// The G-buffer parameters.
    pub params: GBufferParams,
}

impl GBufferArgs {
    /// The record carrying `p` (launch fields zero: the launcher fills them).
    pub fn new(p: &GBufferParams) -> GBufferArgs {
        GBufferArgs { params: *p, ..GBufferArgs::default() }
    }
}

/// Invocation `i`: pixel `first_pixel + i` of `shader_core::pt::gbuffer::gbuffer_pixel` into
/// `out[GBUFFER_STRIDE i..]` at the offsets of [`gbuffer_out`].
#[inline]
pub fn gbuffer_pixel(i: u32, args: &GBufferArgs, scene: &[u32], env: &[f32], lut: &[f32], out: &mut [f32]) {
    let g = gbuffer::gbuffer_pixel(scene, env, lut, &args.params, args.first_pixel + i);
    let o = i as usize * GBUFFER_STRIDE;
    use gbuffer_out as layout;
    store(out, o + layout::DEPTH, g.depth);
    store3(out, o + layout::NORMAL, g.normal);
    store(out, o + layout::ROUGHNESS, g.roughness);
    store(out, o + layout::METALLIC, g.metallic);
    store3(out, o + layout::BASE, g.base);
    store(out, o + layout::GLOSSY, g.glossy as f32);
    store(out, o + layout::DEPTH_FAR, g.depth_far);
    store3(out, o + layout::ALL, g.all);
    store3(out, o + layout::ONSCREEN, g.onscreen);
    store3(out, o + layout::SPECULAR_ALL, g.specular_all);
    store3(out, o + layout::SPECULAR_ONSCREEN, g.specular_onscreen);
    store(out, o + layout::WEIGHT, g.weight);
    store(out, o + layout::WEIGHT_SAME, g.weight_same);
    store(out, o + layout::SAMPLES, g.samples);
    store(out, o + layout::RAYS, g.rays);
}

#[inline]
fn store3(out: &mut [f32], o: usize, v: shader_core::Vec3) {
    store(out, o, v.x);
    store(out, o + 1, v.y);
    store(out, o + 2, v.z);
}

/// Entry point of [`gbuffer_pixel`].
#[spirv(compute(threads(64)))]
pub fn pt_gbuffer(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &GBufferArgs,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] scene: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] env: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] lut: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] out: &mut [f32],
) {
    let a = *args;
    if let Some(i) = crate::invocation_index(id, a.invocations, a.groups_x) {
        gbuffer_pixel(i, &a, scene, env, lut, out);
    }
}

/// The host's declarations of [`pt_render`] and [`pt_gbuffer`] (`crate::launch`). Bindings:
/// scene words, environment, energy LUT.
#[cfg(not(target_arch = "spirv"))]
mod declarations {
    use super::*;
    use crate::launch::{ItemFn, Kernel};

    /// [`pt_render`]: one pixel's [`OUT_STRIDE`] values per invocation.
    pub const PT_RENDER: Kernel<ItemFn<RenderArgs>> = Kernel {
        entry: "render::pt_render",
        cpu: |a, b, i, out| pixel(0, &RenderArgs { first_pixel: a.first_pixel + i, ..*a }, b.u32(0), b.f32(1), b.f32(2), out),
    };

    /// [`pt_gbuffer`]: one pixel's [`GBUFFER_STRIDE`] values per invocation.
    pub const PT_GBUFFER: Kernel<ItemFn<GBufferArgs>> = Kernel {
        entry: "render::pt_gbuffer",
        cpu: |a, b, i, out| gbuffer_pixel(0, &GBufferArgs { first_pixel: a.first_pixel + i, ..*a }, b.u32(0), b.f32(1), b.f32(2), out),
    };
}
#[cfg(not(target_arch = "spirv"))]
pub use declarations::*;
