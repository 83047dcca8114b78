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
    if let Some(i) = crate::invocation_index(id, args.invocations, args.groups_x) {
        pixel(i, args, scene, env, lut, out);
    }
}

/// Output floats per pixel of [`pt_gbuffer`].
pub const GBUFFER_STRIDE: usize = 27;

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
/// `out[GBUFFER_STRIDE i..]`: depth, normal XYZ, roughness, metallic, base RGB, glossy (0/1),
/// far depth, then the reference sums all RGB, on-screen RGB, specular all RGB, specular on-screen RGB,
/// weight, same-both-ways weight, samples, rays.
#[inline]
pub fn gbuffer_pixel(i: u32, args: &GBufferArgs, scene: &[u32], env: &[f32], lut: &[f32], out: &mut [f32]) {
    let g = gbuffer::gbuffer_pixel(scene, env, lut, &args.params, args.first_pixel + i);
    let o = i as usize * GBUFFER_STRIDE;
    store(out, o, g.depth);
    store3(out, o + 1, g.normal);
    store(out, o + 4, g.roughness);
    store(out, o + 5, g.metallic);
    store3(out, o + 6, g.base);
    store(out, o + 9, g.glossy as f32);
    store(out, o + 10, g.depth_far);
    store3(out, o + 11, g.all);
    store3(out, o + 14, g.onscreen);
    store3(out, o + 17, g.specular_all);
    store3(out, o + 20, g.specular_onscreen);
    store(out, o + 23, g.weight);
    store(out, o + 24, g.weight_same);
    store(out, o + 25, g.samples);
    store(out, o + 26, g.rays);
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
    if let Some(i) = crate::invocation_index(id, args.invocations, args.groups_x) {
        gbuffer_pixel(i, args, scene, env, lut, out);
    }
}
