//! The path tracer's kernel (`shader_core::pt`): one invocation per pixel, the per-pixel function
//! [`pixel`] called by the `#[spirv(compute)]` entry point [`pt_render`] and by the CPU launcher.
//!
//! Bindings: 0 = [`RenderArgs`], 1 = scene words (`shader_core::pt::scene`), 2 = environment
//! (`shader_core::pt::environment`), 3 = energy LUT (`shader_core::energy`), 4 = output,
//! [`OUT_STRIDE`] floats per pixel of the launch: radiance sum RGB, albedo sum RGB, normal sum
//! XYZ, depth sum, rays traced.

use shader_core::buffer::store;
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
    store(out, o, s.color.x);
    store(out, o + 1, s.color.y);
    store(out, o + 2, s.color.z);
    store(out, o + 3, s.albedo.x);
    store(out, o + 4, s.albedo.y);
    store(out, o + 5, s.albedo.z);
    store(out, o + 6, s.normal.x);
    store(out, o + 7, s.normal.y);
    store(out, o + 8, s.normal.z);
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
