//! A shader crate of one's own on top of `shader-core`: a GGX specular lobe, its compute entry
//! point, and the same function called natively.
//!
//! `cargo xtask build-shaders` (or `cargo xtask build-shaders --only user-shader`) compiles this
//! crate with rust-gpu and the project's post-processing (no `spirv-opt`, `NoContraction` on every
//! float operation, `SignedZeroInfNanPreserve`) into `examples/user-shader/user-shader.spv.gz`, with
//! its manifest `user-shader.json` (source hash of `shader-core` and this crate).
//! `tests/tests/user_shader.rs` loads that module with the runner (`GpuContext::add_spirv`),
//! dispatches [`ggx_specular_kernel`] and checks that every output has the same bits as
//! [`ggx_specular_row`] called natively.
//!
//! Only the entry point is GPU specific: on other targets the `spirv` attribute is inert and the
//! crate is an ordinary `no_std` library.
#![no_std]

use shader_core::buffer::{load, store};
use shader_core::{fresnel, ieee, masking, ndf, Vec3};
use spirv_std::glam::UVec3;
use spirv_std::spirv;

/// Threads per workgroup of [`ggx_specular_kernel`] (its `threads(64)`).
pub const WORKGROUP_SIZE: u32 = 64;

/// Values per input row: `wo_x, wo_y, wo_z, wi_x, wi_y, wi_z, alpha_x, alpha_y, f0`.
pub const INPUTS: usize = 9;

/// Name of the entry point in the SPIR-V module.
pub const ENTRY_POINT: &str = "ggx_specular_kernel";

/// The GGX specular lobe (Walter et al. 2007, "Microfacet Models for Refraction through Rough
/// Surfaces", eq. 20; the glTF 2.0 specular BRDF):
/// f = D(wm) G2(wo, wi) F(wo.wm) / (4 cos(theta_o) cos(theta_i)), wm = normalize(wo + wi), with
/// anisotropic GGX D ([`ndf::ggx_d`]), height-correlated Smith G2
/// ([`masking::ggx_g2_height_correlated`]) and Schlick's Fresnel with F90 = 1
/// ([`fresnel::schlick`]).
///
/// Conventions: local shading frame (normal = +z), `wo` and `wi` unit vectors pointing away from
/// the surface; the value has no cosine factor (multiply by `wi.z` for the reflected radiance).
/// 0 when either direction is at or below the horizon (z <= 0). NaN for NaN input or an invalid
/// roughness (alpha < 0, NaN or infinite, as `shader-core`'s NDFs).
///
/// ```
/// use shader_core::Vec3;
/// // Mirror configuration at normal incidence: f = D(n) F0 / 4 = F0 / (4 pi alpha^2).
/// let alpha = 0.5f32;
/// let f = user_shader::ggx_specular(Vec3::Z, Vec3::Z, alpha, alpha, 0.04);
/// assert!((f - 0.04 / (4.0 * core::f32::consts::PI * alpha * alpha)).abs() < 1e-7);
/// assert_eq!(user_shader::ggx_specular(Vec3::Z, Vec3::new(1.0, 0.0, 0.0), alpha, alpha, 0.04), 0.0);
/// ```
#[inline]
pub fn ggx_specular(wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32, f0: f32) -> f32 {
    let cos_o = wo.z;
    let cos_i = wi.z;
    if cos_o <= 0.0 || cos_i <= 0.0 {
        return 0.0;
    }
    let wm = (wo + wi).normalize();
    let d = ndf::ggx_d(wm, alpha_x, alpha_y);
    let g = masking::ggx_g2_height_correlated(wo, wi, alpha_x, alpha_y);
    let f = fresnel::schlick(wo.dot(wm), f0, 1.0);
    ieee::div(d * g * f, 4.0 * (cos_o * cos_i))
}

/// [`ggx_specular`] of row `i` of `input` ([`INPUTS`] values per row): the per-invocation function
/// that the entry point and a native caller share. Rows past the end of `input` read zeros.
#[inline]
pub fn ggx_specular_row(input: &[f32], i: usize) -> f32 {
    let b = i * INPUTS;
    let wo = Vec3::new(load(input, b), load(input, b + 1), load(input, b + 2));
    let wi = Vec3::new(load(input, b + 3), load(input, b + 4), load(input, b + 5));
    ggx_specular(wo, wi, load(input, b + 6), load(input, b + 7), load(input, b + 8))
}

/// Compute entry point: `output[i] = ggx_specular_row(input, i)` for every row `i < args[0]`.
///
/// Bindings (descriptor set 0): 0 = `args` `[rows, groups in x]` (`u32`), 1 = `input` (rows of
/// [`INPUTS`] `f32`), 2 = `output` (one `f32` per row). Dispatched as 2D groups of
/// [`WORKGROUP_SIZE`] threads, at most 65535 groups in x: row `i = id.x + id.y * groups_x * 64`.
#[spirv(compute(threads(64)))]
pub fn ggx_specular_kernel(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] input: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] output: &mut [f32],
) {
    let i = id.x + id.y * args[1] * WORKGROUP_SIZE;
    if i < args[0] {
        store(output, i as usize, ggx_specular_row(input, i as usize));
    }
}

/// The CPU version of a dispatch: `output[i] = ggx_specular_row(input, i)` for every row.
pub fn ggx_specular_rows(input: &[f32], output: &mut [f32]) {
    let mut i = 0;
    while i < output.len() {
        output[i] = ggx_specular_row(input, i);
        i += 1;
    }
}
