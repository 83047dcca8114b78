//! The path tracer's kernel (`shader_core::pt`): one invocation per pixel, the per-pixel function
//! [`pixel`] called by the `#[spirv(compute)]` entry point [`pt_render`] and by the CPU launcher.
//!
//! Bindings: 0 = [`RenderArgs`], 1 = scene words (`shader_core::pt::scene`), 2 = environment
//! (`shader_core::pt::environment`), 3 = energy LUT (`shader_core::energy`), 4 = output,
//! [`OUT_STRIDE`] floats per pixel of the launch: radiance sum RGB, albedo sum RGB, normal sum
//! XYZ, depth sum, rays traced.

use shader_core::buffer::store;
use shader_core::pt::camera::Camera;
use shader_core::pt::integrator::{render_pixel, RenderParams};
use shader_core::Vec3;
use spirv_std::glam::UVec3;
use spirv_std::spirv;

/// Output floats per pixel.
pub const OUT_STRIDE: usize = 11;

/// The launch record of [`pt_render`], shared by the host and the kernel (`#[repr(C)]`, all
/// 4-byte fields). Invocation `i` renders pixel `first_pixel + i` and writes `out[OUT_STRIDE i..]`.
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
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel in this launch.
    pub spp: u32,
    /// Index of the launch's first sample.
    pub sample_base: u32,
    /// Seed.
    pub seed: u32,
    /// Longest path in bounces.
    pub max_depth: u32,
    /// First bounce of Russian roulette.
    pub rr_depth: u32,
    /// `shader_core::pt::integrator::STRATEGY_*`.
    pub strategy: u32,
    /// `shader_core::energy::COMP_*`.
    pub compensation: u32,
    /// Per-sample radiance clamp (0 = off).
    pub clamp: f32,
    /// Next-event probability of the environment.
    pub p_env: f32,
    /// `shader_core::pt::camera::PERSPECTIVE` or `ORTHOGRAPHIC`.
    pub camera_kind: u32,
    /// Camera horizontal scale (tan(yfov/2) aspect, or xmag).
    pub camera_scale_x: f32,
    /// Camera vertical scale (tan(yfov/2), or ymag).
    pub camera_scale_y: f32,
    /// Camera origin.
    pub origin_x: f32,
    pub origin_y: f32,
    pub origin_z: f32,
    /// Camera right axis.
    pub right_x: f32,
    pub right_y: f32,
    pub right_z: f32,
    /// Camera up axis.
    pub up_x: f32,
    pub up_y: f32,
    pub up_z: f32,
    /// Camera forward axis.
    pub forward_x: f32,
    pub forward_y: f32,
    pub forward_z: f32,
}

impl RenderArgs {
    /// The integrator's parameters.
    #[inline]
    pub fn params(&self) -> RenderParams {
        RenderParams {
            width: self.width,
            height: self.height,
            spp: self.spp,
            sample_base: self.sample_base,
            seed: self.seed,
            max_depth: self.max_depth,
            rr_depth: self.rr_depth,
            strategy: self.strategy,
            compensation: self.compensation,
            clamp: self.clamp,
            p_env: self.p_env,
            camera: Camera {
                kind: self.camera_kind,
                origin: Vec3::new(self.origin_x, self.origin_y, self.origin_z),
                right: Vec3::new(self.right_x, self.right_y, self.right_z),
                up: Vec3::new(self.up_x, self.up_y, self.up_z),
                forward: Vec3::new(self.forward_x, self.forward_y, self.forward_z),
                scale_x: self.camera_scale_x,
                scale_y: self.camera_scale_y,
            },
        }
    }

    /// The record carrying `p` (launch fields zero: the launcher fills them).
    pub fn new(p: &RenderParams) -> RenderArgs {
        let c = &p.camera;
        RenderArgs {
            width: p.width,
            height: p.height,
            spp: p.spp,
            sample_base: p.sample_base,
            seed: p.seed,
            max_depth: p.max_depth,
            rr_depth: p.rr_depth,
            strategy: p.strategy,
            compensation: p.compensation,
            clamp: p.clamp,
            p_env: p.p_env,
            camera_kind: c.kind,
            camera_scale_x: c.scale_x,
            camera_scale_y: c.scale_y,
            origin_x: c.origin.x,
            origin_y: c.origin.y,
            origin_z: c.origin.z,
            right_x: c.right.x,
            right_y: c.right.y,
            right_z: c.right.z,
            up_x: c.up.x,
            up_y: c.up.y,
            up_z: c.up.z,
            forward_x: c.forward.x,
            forward_y: c.forward.y,
            forward_z: c.forward.z,
            ..RenderArgs::default()
        }
    }
}

/// Invocation `i` of a launch: renders pixel `first_pixel + i` into `out[OUT_STRIDE i..]`.
#[inline]
pub fn pixel(i: u32, args: &RenderArgs, scene: &[u32], env: &[f32], lut: &[f32], out: &mut [f32]) {
    let p = args.params();
    let s = render_pixel(scene, env, lut, &p, args.first_pixel + i);
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
