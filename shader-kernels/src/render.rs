//! The path tracer's kernels (`shader_core::pt`): one invocation per pixel, the per-pixel
//! functions [`pixel`] and [`gbuffer_pixel`] called by the `#[spirv(compute)]` entry points
//! [`pt_render`] and [`pt_gbuffer`] and by the CPU launcher.
//!
//! Bindings: 0 = [`RenderArgs`], 1 = scene words (`shader_core::pt::scene`), 2 = environment
//! (`shader_core::pt::environment`), 3 = energy LUT (`shader_core::energy`), 4 = pixel list
//! (read when [`RenderArgs::pixel_list`] is 1: adaptive sampling launches only the pixels still
//! sampled), 5 = output, [`OUT_STRIDE`] floats per invocation: radiance sum RGB, albedo sum RGB,
//! normal sum XYZ, depth sum, rays traced. [`pt_gbuffer`] binds [`GBufferArgs`] at 0, no pixel
//! list, and writes [`GBUFFER_STRIDE`] floats per pixel (see [`gbuffer_pixel`]) at 4.

use shader_core::pt::gbuffer::{self, GBufferParams, GBufferPixel};
use shader_core::pt::integrator::{render_pixel, PixelSums, RenderParams};
use spirv_std::glam::UVec3;
use spirv_std::spirv;

/// Output floats per pixel (`shader_core::pt::integrator::PixelSums`).
pub const OUT_STRIDE: usize = PixelSums::WORDS;

/// The launch record of [`pt_render`], shared by the host and the kernel (`#[repr(C)]`, all
/// 4-byte fields): the launch fields the launcher fills, then the integrator's parameters as
/// they are. Invocation `i` renders pixel `first_pixel + i` (or, with `pixel_list` 1, pixel
/// `pixels[first_pixel + i]`) and writes `out[OUT_STRIDE i..]`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct RenderArgs {
    /// Invocations (pixels) in this launch.
    pub invocations: u32,
    /// Workgroups in x of the 2D dispatch.
    pub groups_x: u32,
    /// Pixel of invocation 0 (with `pixel_list` 1: the list entry of invocation 0).
    pub first_pixel: u32,
    /// 0: invocations render consecutive pixels; 1: they render the pixels the list names.
    pub pixel_list: u32,
    /// The integrator's parameters.
    pub params: RenderParams,
}

impl RenderArgs {
    /// The record carrying `p` (launch fields zero: the launcher fills them).
    pub fn new(p: &RenderParams) -> RenderArgs {
        RenderArgs { params: *p, ..RenderArgs::default() }
    }
}

/// Invocation `i` of a launch: renders pixel `first_pixel + i` (or `pixels[first_pixel + i]`
/// with a pixel list) into `out[OUT_STRIDE i..]`.
#[inline]
pub fn pixel(i: u32, args: &RenderArgs, scene: &[u32], env: &[f32], lut: &[f32], pixels: &[u32], out: &mut [f32]) {
    let k = args.first_pixel + i;
    let px = if args.pixel_list != 0 { shader_core::buffer::load_u32(pixels, k as usize) } else { k };
    render_pixel(scene, env, lut, &args.params, px).store(out, i as usize * OUT_STRIDE);
}

/// Entry point of [`pixel`].
#[spirv(compute(threads(64)))]
pub fn pt_render(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &RenderArgs,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] scene: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] env: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] lut: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] pixels: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] out: &mut [f32],
) {
    let a = *args;
    if let Some(i) = crate::invocation_index(id, a.invocations, a.groups_x) {
        pixel(i, &a, scene, env, lut, pixels, out);
    }
}

/// Output floats per pixel of [`pt_gbuffer`] (`shader_core::pt::gbuffer::GBufferPixel`).
pub const GBUFFER_STRIDE: usize = GBufferPixel::WORDS;

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
/// `out[GBUFFER_STRIDE i..]` (`GBufferPixel::store`).
#[inline]
pub fn gbuffer_pixel(i: u32, args: &GBufferArgs, scene: &[u32], env: &[f32], lut: &[f32], out: &mut [f32]) {
    gbuffer::gbuffer_pixel(scene, env, lut, &args.params, args.first_pixel + i).store(out, i as usize * GBUFFER_STRIDE);
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
/// scene words, environment, energy LUT (and [`pt_render`]'s pixel list).
#[cfg(not(target_arch = "spirv"))]
mod declarations {
    use super::*;
    use crate::launch::{ItemFn, Kernel};

    /// [`pt_render`]: one pixel's [`OUT_STRIDE`] values per invocation.
    pub const PT_RENDER: Kernel<ItemFn<RenderArgs>> = Kernel {
        entry: "render::pt_render",
        cpu: |a, b, i, out| pixel(0, &RenderArgs { first_pixel: a.first_pixel + i, ..*a }, b.u32(0), b.f32(1), b.f32(2), b.u32(3), out),
    };

    /// [`pt_gbuffer`]: one pixel's [`GBUFFER_STRIDE`] values per invocation.
    pub const PT_GBUFFER: Kernel<ItemFn<GBufferArgs>> = Kernel {
        entry: "render::pt_gbuffer",
        cpu: |a, b, i, out| gbuffer_pixel(0, &GBufferArgs { first_pixel: a.first_pixel + i, ..*a }, b.u32(0), b.f32(1), b.f32(2), out),
    };
}
#[cfg(not(target_arch = "spirv"))]
pub use declarations::*;
