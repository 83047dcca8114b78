//! Energy-compensation kernels (see `shader_core::energy`, docs/energy.md): the E / E' table, the
//! E_avg table and the white furnace, each a per-invocation function both backends call plus a
//! `#[spirv(compute)]` entry point.
//!
//! Every entry point is 1D with [`crate::WORKGROUP_SIZE`] threads and binds its launch record
//! (`#[repr(C)]`, 4-byte fields, `bytemuck::Pod` on the host) at binding 0: the launch fields
//! `invocations`, `groups_x` and `first` (filled by `runner::Backend::run`), then the kernel's
//! parameters. Local invocation `i = id.x + id.y * groups_x * WORKGROUP_SIZE` computes item
//! `first + i` and writes `out[stride i..]`; the CPU launcher calls the same function. The entry
//! points copy the record into the invocation once (fields read through the binding at every use
//! are slow on lavapipe).

use shader_core::ieee;
use shader_core::energy::{self, FurnaceMaterial, FurnaceSample, TableSums};
use spirv_std::glam::UVec3;
use spirv_std::spirv;

/// Furnace layout: a row of spheres, roughness 0..1 left to right, orthographic view along -z.
pub const LAYOUT_SPHERES: u32 = 0;
/// Furnace layout: the table grid, one invocation per (mu_i, r_j) cell center (n_mu x n_r).
pub const LAYOUT_GRID: u32 = 1;
/// Outputs per furnace invocation (`shader_core::energy::FurnaceSample`): albedo, mu (0 outside
/// the spheres), roughness.
pub const FURNACE_STRIDE: usize = FurnaceSample::WORDS;
/// Outputs per E / E' table cell (`shader_core::energy::TableSums`): the sums of E and E'.
pub const TABLE_STRIDE: usize = TableSums::WORDS;

/// Which samples one invocation of the table kernels sums: a launch covers chunks of `chunk`
/// samples from sample `start` on, cut at sample `end`, for every cell; item `c` (counted over the
/// whole launch) is cell `c % cells` of chunk `c / cells`, so every (cell, chunk) pair of the
/// launch runs at once and each chunk's sum is the same whichever launch computes it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct SampleChunks {
    /// First sample of the launch's first chunk.
    pub start: u32,
    /// Samples per chunk.
    pub chunk: u32,
    /// One past the last sample (the last chunk is cut there).
    pub end: u32,
}

impl SampleChunks {
    /// (cell, first sample, sample count) of item `c` over `cells` cells.
    #[inline]
    pub fn item(&self, c: u32, cells: u32) -> (u32, u32, u32) {
        let first = self.start + (c / cells) * self.chunk;
        let count = if first < self.end { min_u32(self.chunk, self.end - first) } else { 0 };
        (c % cells, first, count)
    }
}

#[inline]
fn min_u32(a: u32, b: u32) -> u32 {
    if a < b { a } else { b }
}

/// Launch record of [`energy_albedo_table`]: the sample chunks `s` of every cell of an `n_mu` x
/// `n_r` table (sequence `seq`, scrambling seed `seed`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct AlbedoTableArgs {
    pub invocations: u32,
    pub groups_x: u32,
    pub first: u32,
    pub n_mu: u32,
    pub n_r: u32,
    pub s: SampleChunks,
    pub seq: u32,
    pub seed: u32,
}

/// Launch record of [`energy_albedo_avg`]: the sample chunks `s` of every one of the `n_avg`
/// roughness cells.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct AlbedoAvgArgs {
    pub invocations: u32,
    pub groups_x: u32,
    pub first: u32,
    pub n_avg: u32,
    pub s: SampleChunks,
    pub seq: u32,
    pub seed: u32,
}

/// Launch record of [`energy_furnace`]: `layout` ([`LAYOUT_SPHERES`]: `width` x `height` pixels
/// of `rows` spheres; [`LAYOUT_GRID`]: `width` = n_mu by `rows` = n_r cell centres), `samples`
/// per pixel (sequence `seq`, seed `seed`), the compensation `mode` (`shader_core::energy::COMP_*`)
/// and the material.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct FurnaceArgs {
    pub invocations: u32,
    pub groups_x: u32,
    pub first: u32,
    pub layout: u32,
    pub width: u32,
    pub height: u32,
    pub rows: u32,
    pub samples: u32,
    pub seq: u32,
    pub seed: u32,
    pub mode: u32,
    pub metallic: f32,
    pub base: f32,
    pub min_roughness: f32,
}

/// The E / E' table, invocation `i`: the f32 sums (E, E') of item `first + i`'s samples
/// ([`SampleChunks::item`]), written to `out[2 i]`, `out[2 i + 1]`.
#[inline]
pub fn albedo_table_cell(i: u32, a: &AlbedoTableArgs, out: &mut [f32]) {
    let (cell, start, count) = a.s.item(a.first + i, a.n_mu * a.n_r);
    let (e, ep) = energy::albedo_cell_sums(cell % a.n_mu, cell / a.n_mu, a.n_mu, a.n_r, start, count, a.seq, a.seed);
    TableSums { e, e_prime: ep }.store(out, (i as usize) * TABLE_STRIDE);
}

/// E_avg, invocation `i`: the f32 sum of item `first + i`'s samples ([`SampleChunks::item`] over
/// the roughness cells), written to `out[i]`.
#[inline]
pub fn albedo_avg_cell(i: u32, a: &AlbedoAvgArgs, out: &mut [f32]) {
    let (cell, start, count) = a.s.item(a.first + i, a.n_avg);
    out[i as usize] = energy::albedo_avg_sums(cell, a.n_avg, start, count, a.seq, a.seed);
}

/// White furnace, invocation `i`: pixel (or grid cell) `first + i`'s (albedo, mu, roughness),
/// written to `out[3 i..]`. Pixels outside the spheres see the environment: albedo 1, mu 0.
#[inline]
pub fn furnace_pixel(i: u32, a: &FurnaceArgs, lut: &[f32], out: &mut [f32]) {
    let (albedo, mu, roughness) = furnace_sample(a.first + i, a, lut);
    FurnaceSample { albedo, mu, roughness }.store(out, (i as usize) * FURNACE_STRIDE);
}

/// (albedo, mu, roughness) of furnace pixel (or grid cell) `p`.
#[inline]
fn furnace_sample(p: u32, a: &FurnaceArgs, lut: &[f32]) -> (f32, f32, f32) {
    let (x, y) = (p % a.width, p / a.width);
    let (mu, roughness) = if a.layout == LAYOUT_GRID {
        (energy::table_mu(x, a.width), energy::cell_center(y, a.rows))
    } else {
        let spheres = a.rows;
        let cell = a.width / spheres;
        let k = x / cell;
        let r = if spheres > 1 { ieee::div(k as f32, (spheres - 1) as f32) } else { 0.0 };
        let px = ieee::div(2.0 * ((x - k * cell) as f32 + 0.5), cell as f32) - 1.0;
        let py = 1.0 - ieee::div(2.0 * (y as f32 + 0.5), a.height as f32);
        let rr = px * px + py * py;
        if !(rr < 1.0) || k >= spheres {
            return (1.0, 0.0, r);
        }
        let mu = ieee::sqrt(1.0 - rr);
        (if mu < energy::MU_MIN { energy::MU_MIN } else { mu }, r)
    };
    let m = FurnaceMaterial { base: a.base, metallic: a.metallic, roughness, mode: a.mode, min_roughness: a.min_roughness };
    (energy::furnace_albedo(lut, &m, mu, a.samples, a.seq, a.seed, p), mu, roughness)
}

/// Entry point of [`albedo_table_cell`].
#[spirv(compute(threads(64)))]
pub fn energy_albedo_table(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &AlbedoTableArgs,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] out: &mut [f32],
) {
    let a = *args;
    let Some(i) = crate::invocation_index(id, a.invocations, a.groups_x) else { return };
    albedo_table_cell(i, &a, out);
}

/// Entry point of [`albedo_avg_cell`].
#[spirv(compute(threads(64)))]
pub fn energy_albedo_avg(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &AlbedoAvgArgs,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] out: &mut [f32],
) {
    let a = *args;
    let Some(i) = crate::invocation_index(id, a.invocations, a.groups_x) else { return };
    albedo_avg_cell(i, &a, out);
}

/// Entry point of [`furnace_pixel`]; `lut` is the LUT buffer of `shader_core::energy`.
#[spirv(compute(threads(64)))]
pub fn energy_furnace(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &FurnaceArgs,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] lut: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] out: &mut [f32],
) {
    let a = *args;
    let Some(i) = crate::invocation_index(id, a.invocations, a.groups_x) else { return };
    furnace_pixel(i, &a, lut, out);
}

/// The host's declarations of the energy kernels (`crate::launch`).
#[cfg(not(target_arch = "spirv"))]
mod declarations {
    use super::*;
    use crate::launch::{ItemFn, Kernel};

    /// [`energy_albedo_table`]: one item's [`TABLE_STRIDE`] sums per invocation; no bindings.
    pub const ALBEDO_TABLE: Kernel<ItemFn<AlbedoTableArgs>> = Kernel {
        entry: "energy::energy_albedo_table",
        cpu: |a, _, i, out| albedo_table_cell(0, &AlbedoTableArgs { first: a.first + i, ..*a }, out),
    };

    /// [`energy_albedo_avg`]: one item's sum per invocation; no bindings.
    pub const ALBEDO_AVG: Kernel<ItemFn<AlbedoAvgArgs>> = Kernel {
        entry: "energy::energy_albedo_avg",
        cpu: |a, _, i, out| albedo_avg_cell(0, &AlbedoAvgArgs { first: a.first + i, ..*a }, out),
    };

    /// [`energy_furnace`]: one pixel's [`FURNACE_STRIDE`] values per invocation; binding: the
    /// energy LUT.
    pub const FURNACE: Kernel<ItemFn<FurnaceArgs>> = Kernel {
        entry: "energy::energy_furnace",
        cpu: |a, b, i, out| furnace_pixel(0, &FurnaceArgs { first: a.first + i, ..*a }, b.f32(0), out),
    };
}
#[cfg(not(target_arch = "spirv"))]
pub use declarations::*;
