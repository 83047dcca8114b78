//! Energy-compensation kernels (see `shader_core::energy`, docs/energy.md): the E / E' table, the
//! E_avg table and the white furnace, each a per-invocation function both backends call plus a
//! `#[spirv(compute)]` entry point.
//!
//! Every entry point is 1D with [`crate::WORKGROUP_SIZE`] threads; `args[0]` = invocations,
//! `args[1]` = groups in x; invocation `i = id.x + id.y * groups_x * WORKGROUP_SIZE`.

use shader_core::ieee;
use crate::invocation;
use shader_core::energy::{self, FurnaceMaterial};
use spirv_std::glam::UVec3;
use spirv_std::spirv;

/// Words of the furnace `args` buffer.
pub const FURNACE_ARGS: usize = 14;
/// Furnace layout: a row of spheres, roughness 0..1 left to right, orthographic view along -z.
pub const LAYOUT_SPHERES: u32 = 0;
/// Furnace layout: the table grid, one invocation per (mu_i, r_j) cell center (n_mu x n_r).
pub const LAYOUT_GRID: u32 = 1;
/// Outputs per furnace invocation: albedo, mu (0 outside the spheres), roughness.
pub const FURNACE_STRIDE: usize = 3;

/// E / E' table chunk: `args` = [cells, groups_x, n_mu, n_r, start, count, seq, seed]; the f32
/// sums (E, E') of samples [start, start + count) of cell i (written to out[2 i], out[2 i + 1]).
#[inline]
pub fn albedo_table_cell(i: u32, args: &[u32]) -> (f32, f32) {
    let (n_mu, n_r) = (args[2], args[3]);
    energy::albedo_cell_sums(i % n_mu, i / n_mu, n_mu, n_r, args[4], args[5], args[6], args[7])
}

/// E_avg chunk: `args` = [n_avg, groups_x, n_avg, start, count, seq, seed]; the f32 sum of samples
/// [start, start + count) of roughness cell j (written to out[j]).
#[inline]
pub fn albedo_avg_cell(j: u32, args: &[u32]) -> f32 {
    energy::albedo_avg_sums(j, args[2], args[3], args[4], args[5], args[6])
}

/// White furnace, one pixel (or grid cell): `args` = [invocations, groups_x, layout, width,
/// height, spheres (LAYOUT_SPHERES) or n_r (LAYOUT_GRID), samples, seq, seed, mode, metallic
/// bits, base bits, min-roughness bits, 0]; returns (albedo, mu, roughness), written to
/// out[3 i..]. Pixels outside the spheres see the environment: albedo 1, mu 0.
#[inline]
pub fn furnace_pixel(i: u32, args: &[u32], lut: &[f32]) -> (f32, f32, f32) {
    let layout = args[2];
    let width = args[3];
    let (x, y) = (i % width, i / width);
    let (mu, roughness) = if layout == LAYOUT_GRID {
        (energy::table_mu(x, width), energy::cell_center(y, args[5]))
    } else {
        let spheres = args[5];
        let cell = width / spheres;
        let k = x / cell;
        let r = if spheres > 1 { ieee::div(k as f32, (spheres - 1) as f32) } else { 0.0 };
        let px = ieee::div(2.0 * ((x - k * cell) as f32 + 0.5), cell as f32) - 1.0;
        let py = 1.0 - ieee::div(2.0 * (y as f32 + 0.5), args[4] as f32);
        let rr = px * px + py * py;
        if !(rr < 1.0) || k >= spheres {
            return (1.0, 0.0, r);
        }
        let mu = ieee::sqrt(1.0 - rr);
        (if mu < energy::MU_MIN { energy::MU_MIN } else { mu }, r)
    };
    let m = FurnaceMaterial {
        base: f32::from_bits(args[11]),
        metallic: f32::from_bits(args[10]),
        roughness,
        mode: args[9],
        min_roughness: f32::from_bits(args[12]),
    };
    (energy::furnace_albedo(lut, &m, mu, args[6], args[7], args[8], i), mu, roughness)
}


/// Entry point of [`albedo_table_cell`].
#[spirv(compute(threads(64)))]
pub fn energy_albedo_table(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] out: &mut [f32],
) {
    let Some(i) = invocation(id, args) else { return };
    let (e, ep) = albedo_table_cell(i, args);
    out[(2 * i) as usize] = e;
    out[(2 * i + 1) as usize] = ep;
}

/// Entry point of [`albedo_avg_cell`].
#[spirv(compute(threads(64)))]
pub fn energy_albedo_avg(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] out: &mut [f32],
) {
    let Some(j) = invocation(id, args) else { return };
    out[j as usize] = albedo_avg_cell(j, args);
}

/// Entry point of [`furnace_pixel`]; `lut` is the LUT buffer of `shader_core::energy`.
#[spirv(compute(threads(64)))]
pub fn energy_furnace(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] lut: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [f32],
) {
    let Some(i) = invocation(id, args) else { return };
    let (a, mu, r) = furnace_pixel(i, args, lut);
    let o = (i as usize) * FURNACE_STRIDE;
    out[o] = a;
    out[o + 1] = mu;
    out[o + 2] = r;
}
