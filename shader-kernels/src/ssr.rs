//! Screen-space reflection passes (see `shader_core::ssr`): one compute entry point per pass and,
//! for each, the per-invocation function (below, or `shader_core::ssr::stochastic`'s list
//! functions) that maps invocation `i` to its pixel, texel, tile or list entry and computes it: the
//! entry point calls it after checking the invocation range, the host's CPU backend calls the same
//! function for every invocation, so nothing on the host re-derives the mapping.
//!
//! Every entry point but [`sssr_scan`] is 1D with [`crate::WORKGROUP_SIZE`] threads; `args` is its
//! [`PassArgs`] record (a uniform buffer, as `consts`); invocation
//! `i = id.x + id.y * groups_x * WORKGROUP_SIZE`;
//! `consts` holds the [`SsrParams`] record (`shader_core::ssr::params`) as it is, in a uniform
//! buffer (its layout is std140's: 4-byte scalars, then 16-byte-aligned matrices of 16-byte rows),
//! read into the invocation once by [`params`].

use shader_core::buffer::store;
use shader_core::ssr::params::{SsrParams, MODE_UNSET, MODE_WORDS};
use shader_core::ssr::hits;
use shader_core::ssr::resolve::{self, HIT_STRIDE, OUT_STRIDE};
use shader_core::ssr::specular;
use shader_core::ssr::stochastic;
use shader_core::ssr::trace::{self, RAY_STRIDE};
use spirv_std::glam::UVec3;
use spirv_std::arch::workgroup_memory_barrier_with_group_sync;
use spirv_std::spirv;

/// An SSR dispatch's own arguments (`#[repr(C)]`, four `u32`: std140), bound as a uniform buffer
/// at binding 0: its invocation count, its groups in x, and the pass's one argument (the pyramid
/// level, the resolve shape; unused elsewhere). The list passes dispatched indirectly bind the
/// scan's dispatch record (`stochastic::dispatch_record`), whose first words are the same.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct PassArgs {
    /// Invocations of the dispatch (those at or past it return at once).
    pub invocations: u32,
    /// Workgroups in x of the 2D dispatch ([`crate::invocation_index`]).
    pub groups_x: u32,
    /// The pass's argument: mip level (pyramids), neighbourhood shape (HDRP resolve).
    pub arg: u32,
    /// The pass's second argument: the column the scans sum; unused elsewhere.
    pub pad: u32,
}

/// The invocation index of an SSR dispatch with its arguments (`args[id.z]`, indexed by z for
/// the reason [`params`] gives), or `None` past the end of the work.
#[inline]
fn pass(id: UVec3, args: &[PassArgs; 1]) -> Option<(u32, PassArgs)> {
    let a = args[id.z as usize];
    crate::invocation_index(id, a.invocations, a.groups_x).map(|i| (i, a))
}

/// The dispatch's parameter record: `consts[id.z]` (every SSR dispatch is one layer deep, so
/// z = 0 and `consts` holds one record). Why a uniform buffer, and why indexed by z, on llvmpipe
/// (Mesa 22.3; `host bench storage` measures the first point):
/// * it reads a storage buffer one lane at a time in a loop with two branches per lane, at an
///   address every lane shares too (a ~30-field record cost the SSR passes up to 40 % of their
///   time); a uniform buffer's field is one load per 8 lanes;
/// * it specializes a kernel on up to four uniform-buffer fields read at constant offsets (those
///   that decide branches and loops) by compiling it again with their values at every dispatch
///   (5-10 ms each at 128x128); an offset that depends on the dispatch is not one it inlines.
///
/// The CPU launcher passes the record itself; nothing else differs.
///
/// `modes` are the entry point's specialization constants 0..[`MODE_WORDS`] (their default,
/// [`MODE_UNSET`], leaves a field to the record): the GPU backend compiles each pipeline with
/// the record's own mode words ([`SsrParams::modes`]), so the driver sees them as constants and
/// drops the code of the paths they exclude. Mesa 22.3's llvmpipe runs both sides of every branch
/// with the inactive lanes masked and inlines at most four uniform-buffer values; before the
/// modes were pinned the stochastic resolve ran the colour-pyramid sample of the other colour
/// mode for every ray it read (the floor scene's resolve 354 ms, with that path removed by hand
/// 163 ms, Mesa 22.3, 1920x1080).
#[inline]
fn params(id: UVec3, consts: &[SsrParams; 1], modes: [u32; MODE_WORDS]) -> SsrParams {
    consts[id.z as usize].with_modes(modes)
}

// The specialization constants' default in the entry points' attributes is this literal.
const _: () = assert!(MODE_UNSET == 4294967295);

/// Tile classification, invocation `i` (tile `i`, row-major 8x8 tiles): its record (class, rays,
/// eligible pixels, valid pixels) as u32 bits at `tiles[ob..]`.
#[inline]
pub fn classify(p: &SsrParams, gbuf: &[f32], i: u32, tiles: &mut [f32], ob: usize) {
    let tiles_x = (p.width + stochastic::TILE - 1) / stochastic::TILE;
    let (class, rays, eligible, valid) = stochastic::classify_tile(p, gbuf, i % tiles_x, i / tiles_x);
    store(tiles, ob, f32::from_bits(class));
    store(tiles, ob + 1, f32::from_bits(rays));
    store(tiles, ob + 2, f32::from_bits(eligible));
    store(tiles, ob + 3, f32::from_bits(valid));
}

/// List emission, invocation `i` (tile `i`): its rays and eligible pixels into the two lists.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn emit(p: &SsrParams, gbuf: &[f32], ray_offsets: &[f32], pixel_offsets: &[f32], i: u32, list: &mut [f32], pixels: &mut [f32]) {
    let tiles_x = (p.width + stochastic::TILE - 1) / stochastic::TILE;
    stochastic::emit_tile(p, gbuf, ray_offsets, pixel_offsets, i % tiles_x, i / tiles_x, list, pixels);
}

/// HDRP's pixel list, invocation `i` (tile `i`): the tile's valid pixels into the list.
#[inline]
pub fn hdrp_emit(p: &SsrParams, gbuf: &[f32], offsets: &[f32], i: u32, pixels: &mut [f32]) {
    let tiles_x = (p.width + stochastic::TILE - 1) / stochastic::TILE;
    stochastic::emit_valid_tile(p, gbuf, offsets, i % tiles_x, i / tiles_x, pixels);
}

/// Where a list pass's invocation writes its record: at its slot of the pass's output (the GPU:
/// one buffer over every slot, `at_slot`), or at the start of `out`, a record of its own (the
/// CPU launcher, which stores it at the returned slot).
#[inline]
fn dest(slot: u32, stride: usize, at_slot: bool) -> usize {
    if at_slot {
        (slot as usize) * stride
    } else {
        0
    }
}

/// HDRP tracing, invocation `k` (entry `k` of the valid-pixel list): the pixel's ray record (see
/// [`dest`]); returns its slot (the pixel).
#[inline]
pub fn hdrp_trace(p: &SsrParams, gbuf: &[f32], depth_pyr: &[f32], pixels: &[f32], k: u32, rays: &mut [f32], at_slot: bool) -> u32 {
    let (q, x, y) = stochastic::list_pixel(p, pixels, k);
    trace::hdrp_trace_pixel(p, gbuf, depth_pyr, x, y, rays, dest(q, RAY_STRIDE, at_slot));
    q
}

/// HDRP's hit records, invocation `k` (entry `k` of the valid-pixel list; one ray per pixel):
/// the record of the pixel's ray (see [`dest`]); returns its slot.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn hdrp_hits(p: &SsrParams, gbuf: &[f32], color_pyr: &[f32], rays: &[f32], pixels: &[f32], k: u32, hits_out: &mut [f32], at_slot: bool) -> u32 {
    let (q, _, _) = stochastic::list_pixel(p, pixels, k);
    hits::hit_record_slot(p, gbuf, color_pyr, rays, q, hits_out, dest(q, HIT_STRIDE, at_slot));
    q
}

/// `SSR_APPROX`, invocation `k` (entry `k` of the valid-pixel list): the pixel's reflection (see
/// [`dest`]); returns the pixel.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn hdrp_reproject(p: &SsrParams, gbuf: &[f32], color_pyr: &[f32], rays: &[f32], pixels: &[f32], k: u32, out: &mut [f32], at_slot: bool) -> u32 {
    let (q, x, y) = stochastic::list_pixel(p, pixels, k);
    resolve::hdrp_reproject_approx(p, gbuf, color_pyr, rays, x, y, out, dest(q, OUT_STRIDE, at_slot));
    q
}

/// HDRP's neighbourhood resolve of shape `shape`, invocation `k` (entry `k` of the valid-pixel
/// list): the pixel's reflection (see [`dest`]); returns the pixel.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn hdrp_resolve(p: &SsrParams, gbuf: &[f32], color_pyr: &[f32], rays: &[f32], hits_in: &[f32], shape: u32, pixels: &[f32], k: u32, out: &mut [f32], at_slot: bool) -> u32 {
    let (q, x, y) = stochastic::list_pixel(p, pixels, k);
    resolve::hdrp_resolve_neighborhood(p, gbuf, color_pyr, rays, hits_in, shape, x, y, out, dest(q, OUT_STRIDE, at_slot));
    q
}

/// Stochastic tracing, invocation `k` (entry `k` of the ray list): the ray's record (see
/// [`dest`]); returns its slot.
#[inline]
pub fn sssr_trace_entry(p: &SsrParams, gbuf: &[f32], depth_pyr: &[f32], list: &[f32], k: u32, rays: &mut [f32], at_slot: bool) -> u32 {
    let slot = stochastic::list_slot(p, list, k);
    stochastic::trace_list_entry(p, gbuf, depth_pyr, list, k, rays, dest(slot, RAY_STRIDE, at_slot));
    slot
}

/// Stochastic hit records, invocation `k` (entry `k` of the ray list): the ray's hit record (see
/// [`dest`]); returns its slot.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn sssr_hits_entry(p: &SsrParams, gbuf: &[f32], color_pyr: &[f32], rays: &[f32], list: &[f32], k: u32, hits_out: &mut [f32], at_slot: bool) -> u32 {
    let slot = stochastic::list_slot(p, list, k);
    hits::hit_record_slot(p, gbuf, color_pyr, rays, slot, hits_out, dest(slot, HIT_STRIDE, at_slot));
    slot
}

/// Stochastic resolve, invocation `k` (entry `k` of the eligible-pixel list): the pixel's
/// reflection (see [`dest`]); returns the pixel.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn sssr_resolve_entry(p: &SsrParams, gbuf: &[f32], color_pyr: &[f32], rays: &[f32], hits_in: &[f32], pixels: &[f32], k: u32, out: &mut [f32], at_slot: bool) -> u32 {
    let (q, x, y) = stochastic::list_pixel(p, pixels, k);
    stochastic::resolve_pixel(p, gbuf, color_pyr, rays, hits_in, x, y, out, dest(q, OUT_STRIDE, at_slot));
    q
}

/// Reflection hit distance, invocation `k` (entry `k` of the eligible-pixel list): the pixel's
/// distance (see [`dest`]); returns the pixel.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn sssr_hit_distance_entry(p: &SsrParams, gbuf: &[f32], rays: &[f32], hits_in: &[f32], pixels: &[f32], k: u32, out: &mut [f32], at_slot: bool) -> u32 {
    let (q, x, y) = stochastic::list_pixel(p, pixels, k);
    store(out, dest(q, 1, at_slot), stochastic::hit_distance_pixel(p, gbuf, rays, hits_in, x, y));
    q
}

/// Temporal accumulation, invocation `i` (pixel `i`): its history texel at `out[ob..]`.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn temporal(p: &SsrParams, gbuf: &[f32], prev_gbuf: &[f32], hit_distance: &[f32], current: &[f32], history: &[f32], i: u32, out: &mut [f32], ob: usize) {
    stochastic::temporal_pixel(p, gbuf, prev_gbuf, hit_distance, current, history, i % p.width, i / p.width, out, ob);
}

/// Specular term, invocation `i` (pixel `i`): its value at `out[ob..]`.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn specular_term(p: &SsrParams, gbuf: &[f32], base_color: &[f32], lut: &[f32], reflection: &[f32], i: u32, out: &mut [f32], ob: usize) {
    specular::specular_pixel(p, gbuf, base_color, lut, reflection, i % p.width, i / p.width, out, ob);
}

/// Max-device-depth pyramid: mips `arg` and `arg + 1` (`arg` = 0, 2, 4, ...), invocation `i` =
/// block `i` of [`trace::hiz_block`] (the pass with `arg` 0 also converts mip 0 and the far-depth
/// layer from linear to device depth).
#[spirv(compute(threads(64)))]
pub fn ssr_hiz_downsample(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] pyr: &mut [f32],
) {
    let Some((i, a)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    trace::hiz_block(&p, pyr, a.arg, i).store(pyr);
}

/// Colour pyramid: mips `arg` and `arg + 1` (`arg` = 1, 3, 5, ...) of `pyr` (RGB), invocation `i`
/// = block `i` of [`resolve::color_block`].
#[spirv(compute(threads(64)))]
pub fn ssr_color_downsample(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] pyr: &mut [f32],
) {
    let Some((i, a)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    resolve::color_block(&p, pyr, a.arg, i).store(pyr);
}

/// HDRP's pixel list: each tile writes its pixels with a valid surface into the list from its
/// offset (the scan of the tiles' `stochastic::TILE_VALID` column).
#[spirv(compute(threads(64)))]
pub fn ssr_hdrp_emit(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] offsets: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] pixels: &mut [f32],
) {
    let Some((i, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    hdrp_emit(&p, gbuf, offsets, i, pixels);
}

/// HDRP tracing over the valid-pixel list: one mirror ray (or, with `FLAG_STOCHASTIC`, one GGX
/// ray) per listed pixel, Hi-Z / linear / brute force per `consts`; `rays` zero-initialized
/// (pixels without a surface to trace keep an invalid record).
#[spirv(compute(threads(64)))]
pub fn ssr_hdrp_trace(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] depth_pyr: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] pixels: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] rays: &mut [f32],
) {
    let Some((k, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    hdrp_trace(&p, gbuf, depth_pyr, pixels, k, rays, true);
}

/// Hit records (`shader_core::ssr::hits`): one invocation per ray slot (pixels x samples per
/// pixel), every slot; the oracle of the list passes' records.
#[spirv(compute(threads(64)))]
pub fn ssr_ray_hits(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] color_pyr: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] rays: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] hits: &mut [f32],
) {
    let Some((i, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    hits::hit_record_slot(&p, gbuf, color_pyr, rays, i, hits, (i as usize) * HIT_STRIDE);
}

/// HDRP's hit records over the valid-pixel list (one ray per pixel: the slot is the pixel);
/// `hits` zero-initialized, as every slot without a hitting ray is.
#[spirv(compute(threads(64)))]
pub fn ssr_hdrp_hits(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] color_pyr: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] rays: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] pixels: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] hits: &mut [f32],
) {
    let Some((k, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    hdrp_hits(&p, gbuf, color_pyr, rays, pixels, k, hits, true);
}

/// HDRP reprojection, `SSR_APPROX`, over the valid-pixel list: the pixel's own ray only (`out`
/// zero-initialized: every other pixel reflects nothing).
#[spirv(compute(threads(64)))]
#[allow(clippy::too_many_arguments)]
pub fn ssr_hdrp_reproject(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] color_pyr: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] rays: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] pixels: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] out: &mut [f32],
) {
    let Some((k, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    hdrp_reproject(&p, gbuf, color_pyr, rays, pixels, k, out, true);
}

/// HDRP's neighbourhood resolve (`arg` = shape: `resolve::NEIGHBORHOOD_3X3` or
/// `NEIGHBORHOOD_CROSS5`) over the valid-pixel list, from the hit records of [`ssr_hdrp_hits`]
/// (`out` zero-initialized). Its own entry point, apart from `SSR_APPROX`'s: on a device that
/// predicates branches (llvmpipe) one kernel holding both would run both.
#[spirv(compute(threads(64)))]
#[allow(clippy::too_many_arguments)]
pub fn ssr_hdrp_resolve(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] color_pyr: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] rays: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] hits: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] pixels: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] out: &mut [f32],
) {
    let Some((k, a)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    hdrp_resolve(&p, gbuf, color_pyr, rays, hits, a.arg, pixels, k, out, true);
}

/// Tile classification (both pipelines): one invocation per 8x8 tile writes (class, rays,
/// eligible pixels, valid pixels) as u32 bits.
#[spirv(compute(threads(64)))]
pub fn sssr_classify(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] tiles: &mut [f32],
) {
    let Some((i, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    classify(&p, gbuf, i, tiles, (i as usize) * stochastic::TILE_STRIDE);
}

/// Stochastic SSR, compaction step 2: each tile writes its rays (pixel, sample | mode << 8) into
/// the ray list from its offset and its eligible pixels into the pixel list from theirs.
#[spirv(compute(threads(64)))]
#[allow(clippy::too_many_arguments)]
pub fn sssr_emit(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] ray_offsets: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] pixel_offsets: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] list: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] pixels: &mut [f32],
) {
    let Some((i, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    emit(&p, gbuf, ray_offsets, pixel_offsets, i, list, pixels);
}

/// Stochastic SSR, tracing over the compacted ray list: entry k's record goes to its slot
/// (`stochastic::list_slot`) of `rays` (zero-initialized: slots without a ray stay invalid).
#[spirv(compute(threads(64)))]
pub fn sssr_trace(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] depth_pyr: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] list: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] rays: &mut [f32],
) {
    let Some((k, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    sssr_trace_entry(&p, gbuf, depth_pyr, list, k, rays, true);
}

/// Stochastic SSR, hit records over the compacted ray list (dispatched like [`sssr_trace`]):
/// entry k's record goes to its slot of `hits` (zero-initialized: slots without a ray stay
/// zero, as [`ssr_ray_hits`] writes them).
#[spirv(compute(threads(64)))]
pub fn sssr_hits(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] color_pyr: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] rays: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] list: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] hits: &mut [f32],
) {
    let Some((k, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    sssr_hits_entry(&p, gbuf, color_pyr, rays, list, k, hits, true);
}

/// Stochastic SSR, BRDF-weighted ratio-estimator resolve over the compacted list of eligible
/// pixels (`out` zero-initialized: every other pixel reflects nothing); `hits` from
/// [`sssr_hits`].
#[spirv(compute(threads(64)))]
#[allow(clippy::too_many_arguments)]
pub fn sssr_resolve(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] color_pyr: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] rays: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] hits: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] pixels: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] out: &mut [f32],
) {
    let Some((k, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    sssr_resolve_entry(&p, gbuf, color_pyr, rays, hits, pixels, k, out, true);
}

/// Stochastic SSR, temporal accumulation (one invocation per pixel; history stride 5): hit-based
/// or surface reprojection, depth/normal history rejection against the previous G-buffer.
#[spirv(compute(threads(64)))]
pub fn sssr_temporal(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] prev_gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] hit_distance: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] current: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] history: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 7)] out: &mut [f32],
) {
    let Some((i, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    temporal(&p, gbuf, prev_gbuf, hit_distance, current, history, i, out, (i as usize) * stochastic::HISTORY_STRIDE);
}

/// Stochastic SSR, reflection hit distance (the temporal pass's virtual-image input) over the
/// list of eligible pixels (`out` zero-initialized: the other pixels traced no ray), from the
/// hit records of [`sssr_hits`].
#[spirv(compute(threads(64)))]
#[allow(clippy::too_many_arguments)]
pub fn sssr_hit_distance(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] rays: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] hits: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] pixels: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] out: &mut [f32],
) {
    let Some((k, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    sssr_hit_distance_entry(&p, gbuf, rays, hits, pixels, k, out, true);
}

/// Specular term: the reflection (4 values per pixel) times the preintegrated FG term looked up
/// in the energy tables `lut` (`shader_core::energy` layout), with f0 from base colour (3 per
/// pixel) and metalness.
#[spirv(compute(threads(64)))]
pub fn ssr_specular(
    #[spirv(global_invocation_id)] id: UVec3,
    #[spirv(uniform, descriptor_set = 0, binding = 0)] args: &[PassArgs; 1],
    #[spirv(uniform, descriptor_set = 0, binding = 1)] consts: &[SsrParams; 1],
    #[spirv(spec_constant(id = 0, default = 4294967295))] modes: [u32; MODE_WORDS],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] gbuf: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] base_color: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 4)] lut: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 5)] reflection: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 6)] out: &mut [f32],
) {
    let Some((i, _)) = pass(id, args) else { return };
    let p = params(id, consts, modes);
    specular_term(&p, gbuf, base_color, lut, reflection, i, out, (i as usize) * specular::SPECULAR_STRIDE);
}

/// Stochastic SSR, compaction step 1: the exclusive prefix sum of one count column of the tiles
/// (`args[3]`: `stochastic::TILE_RAYS`, `TILE_ELIGIBLE` or `TILE_VALID`) by one workgroup of 64
/// lanes: each lane sums its segment of the tiles (`stochastic::scan_segment`), a Hillis-Steele
/// scan in workgroup memory of the 64 segment totals, each lane writes its segment's offsets;
/// and the trace pass's dispatch record (`stochastic::dispatch_record`: ray count, then the
/// indirect-dispatch groups) of the pass launched over that list. Integer sums: the same offsets
/// as the CPU's sequential `prefix_sum_tiles`. `args[2]` = tile count.
#[spirv(compute(threads(64)))]
pub fn sssr_scan(
    #[spirv(local_invocation_index)] lane: u32,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] tiles: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] offsets: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] dispatch: &mut [u32],
    #[spirv(workgroup)] shared: &mut [u32; stochastic::SCAN_SHARED],
) {
    let n = args[2];
    let column = args[3] as usize;
    let lanes = stochastic::SCAN_LANES;
    let (first, end) = stochastic::scan_segment(n, lane);
    let own = stochastic::segment_total(tiles, column, first, end);
    shared[lane as usize] = own;
    workgroup_memory_barrier_with_group_sync();
    let mut src: usize = 0;
    let mut d: u32 = 1;
    while d < lanes {
        let v = stochastic::scan_lane_inclusive(shared, src, lane, d);
        let dst = (lanes as usize) - src;
        shared[dst + lane as usize] = v;
        workgroup_memory_barrier_with_group_sync();
        src = dst;
        d *= 2;
    }
    let inclusive = shared[src + lane as usize];
    let total = shared[src + (lanes - 1) as usize];
    stochastic::segment_offsets(tiles, column, first, end, inclusive - own, offsets);
    if lane == 0 {
        stochastic::store_scan_total(offsets, dispatch, n, Some(total), crate::WORKGROUP_SIZE);
    }
}

/// The host's declarations of the SSR passes (`crate::launch`). Every pass but the scans binds
/// the [`SsrParams`] record first (binding 1 of the entry point, [`Bindings::record`] 0), then
/// the buffers in the entry point's order; the scans bind the tiles alone.
#[cfg(not(target_arch = "spirv"))]
mod declarations {
    use super::*;
    use crate::launch::{Bindings, BlockFns, ItemFn, Kernel, ListFn, SerialFn};
    use shader_core::ssr::params::MipBlock;
    use shader_core::Vec3;

    /// The parameter record of an SSR launch.
    #[inline]
    fn p<'a>(b: &Bindings<'a>) -> &'a SsrParams {
        b.record(0)
    }

    /// [`ssr_hiz_downsample`]: mips `arg` and `arg + 1` of the depth pyramid, in place.
    pub const HIZ_DOWNSAMPLE: Kernel<BlockFns<PassArgs, MipBlock<f32>>> = Kernel {
        entry: "ssr::ssr_hiz_downsample",
        cpu: BlockFns { block: |a, b, pyr, i| trace::hiz_block(p(b), pyr, a.arg, i), store: |w, pyr| w.store(pyr) },
    };

    /// [`ssr_color_downsample`]: mips `arg` and `arg + 1` of the colour pyramid, in place.
    pub const COLOR_DOWNSAMPLE: Kernel<BlockFns<PassArgs, MipBlock<Vec3>>> = Kernel {
        entry: "ssr::ssr_color_downsample",
        cpu: BlockFns { block: |a, b, pyr, i| resolve::color_block(p(b), pyr, a.arg, i), store: |w, pyr| w.store(pyr) },
    };

    /// [`ssr_hdrp_emit`]: bindings G-buffer, tile offsets; output the pixel list.
    pub const HDRP_EMIT: Kernel<SerialFn<PassArgs>> = Kernel {
        entry: "ssr::ssr_hdrp_emit",
        cpu: |_, b, i, outs| hdrp_emit(p(b), b.f32(1), b.f32(2), i, outs[0]),
    };

    /// [`ssr_hdrp_trace`]: bindings G-buffer, depth pyramid, pixel list.
    pub const HDRP_TRACE: Kernel<ListFn<PassArgs>> = Kernel {
        entry: "ssr::ssr_hdrp_trace",
        cpu: |_, b, k, o| hdrp_trace(p(b), b.f32(1), b.f32(2), b.f32(3), k, o, false),
    };

    /// [`ssr_ray_hits`]: bindings G-buffer, colour pyramid, rays.
    pub const RAY_HITS: Kernel<ItemFn<PassArgs>> = Kernel {
        entry: "ssr::ssr_ray_hits",
        cpu: |_, b, i, o| hits::hit_record_slot(p(b), b.f32(1), b.f32(2), b.f32(3), i, o, 0),
    };

    /// [`ssr_hdrp_hits`]: bindings G-buffer, colour pyramid, rays, pixel list.
    pub const HDRP_HITS: Kernel<ListFn<PassArgs>> = Kernel {
        entry: "ssr::ssr_hdrp_hits",
        cpu: |_, b, k, o| hdrp_hits(p(b), b.f32(1), b.f32(2), b.f32(3), b.f32(4), k, o, false),
    };

    /// [`ssr_hdrp_reproject`]: bindings G-buffer, colour pyramid, rays, pixel list.
    pub const HDRP_REPROJECT: Kernel<ListFn<PassArgs>> = Kernel {
        entry: "ssr::ssr_hdrp_reproject",
        cpu: |_, b, k, o| hdrp_reproject(p(b), b.f32(1), b.f32(2), b.f32(3), b.f32(4), k, o, false),
    };

    /// [`ssr_hdrp_resolve`] (`arg`: the shape): bindings G-buffer, colour pyramid, rays, hits,
    /// pixel list.
    pub const HDRP_RESOLVE: Kernel<ListFn<PassArgs>> = Kernel {
        entry: "ssr::ssr_hdrp_resolve",
        cpu: |a, b, k, o| hdrp_resolve(p(b), b.f32(1), b.f32(2), b.f32(3), b.f32(4), a.arg, b.f32(5), k, o, false),
    };

    /// [`sssr_classify`]: binding G-buffer.
    pub const SSSR_CLASSIFY: Kernel<ItemFn<PassArgs>> = Kernel {
        entry: "ssr::sssr_classify",
        cpu: |_, b, i, o| classify(p(b), b.f32(1), i, o, 0),
    };

    /// [`sssr_emit`]: bindings G-buffer, ray offsets, pixel offsets; outputs the ray list and
    /// the pixel list.
    pub const SSSR_EMIT: Kernel<SerialFn<PassArgs>> = Kernel {
        entry: "ssr::sssr_emit",
        cpu: |_, b, i, outs| {
            if let [list, pixels] = outs {
                emit(p(b), b.f32(1), b.f32(2), b.f32(3), i, list, pixels)
            }
        },
    };

    /// [`sssr_trace`]: bindings G-buffer, depth pyramid, ray list.
    pub const SSSR_TRACE: Kernel<ListFn<PassArgs>> = Kernel {
        entry: "ssr::sssr_trace",
        cpu: |_, b, k, o| sssr_trace_entry(p(b), b.f32(1), b.f32(2), b.f32(3), k, o, false),
    };

    /// [`sssr_hits`]: bindings G-buffer, colour pyramid, rays, ray list.
    pub const SSSR_HITS: Kernel<ListFn<PassArgs>> = Kernel {
        entry: "ssr::sssr_hits",
        cpu: |_, b, k, o| sssr_hits_entry(p(b), b.f32(1), b.f32(2), b.f32(3), b.f32(4), k, o, false),
    };

    /// [`sssr_resolve`]: bindings G-buffer, colour pyramid, rays, hits, pixel list.
    pub const SSSR_RESOLVE: Kernel<ListFn<PassArgs>> = Kernel {
        entry: "ssr::sssr_resolve",
        cpu: |_, b, k, o| sssr_resolve_entry(p(b), b.f32(1), b.f32(2), b.f32(3), b.f32(4), b.f32(5), k, o, false),
    };

    /// [`sssr_hit_distance`]: bindings G-buffer, rays, hits, pixel list.
    pub const SSSR_HIT_DISTANCE: Kernel<ListFn<PassArgs>> = Kernel {
        entry: "ssr::sssr_hit_distance",
        cpu: |_, b, k, o| sssr_hit_distance_entry(p(b), b.f32(1), b.f32(2), b.f32(3), b.f32(4), k, o, false),
    };

    /// [`sssr_temporal`]: bindings G-buffer, previous G-buffer, hit distance, current
    /// reflection, history.
    pub const SSSR_TEMPORAL: Kernel<ItemFn<PassArgs>> = Kernel {
        entry: "ssr::sssr_temporal",
        cpu: |_, b, i, o| temporal(p(b), b.f32(1), b.f32(2), b.f32(3), b.f32(4), b.f32(5), i, o, 0),
    };

    /// [`ssr_specular`]: bindings G-buffer, base colour, energy LUT, reflection.
    pub const SPECULAR: Kernel<ItemFn<PassArgs>> = Kernel {
        entry: "ssr::ssr_specular",
        cpu: |_, b, i, o| specular_term(p(b), b.f32(1), b.f32(2), b.f32(3), b.f32(4), i, o, 0),
    };

    /// The scans' CPU form: the sequential prefix sum of column `pad` over `arg` tiles (binding:
    /// the tiles) and the dispatch record (as f32 bits) of the pass launched over the list.
    const SCAN_CPU: SerialFn<PassArgs> = |a, b, _, outs| {
        if let [offsets, dispatch] = outs {
            stochastic::prefix_sum_tiles(b.f32(0), a.arg, a.pad as usize, offsets);
            let rec = stochastic::dispatch_record(offsets[a.arg as usize].to_bits(), crate::WORKGROUP_SIZE);
            for (d, r) in dispatch.iter_mut().zip(rec) {
                *d = f32::from_bits(r);
            }
        }
    };

    /// [`sssr_scan`], one workgroup.
    pub const SSSR_SCAN: Kernel<SerialFn<PassArgs>> = Kernel { entry: "ssr::sssr_scan", cpu: SCAN_CPU };

    /// `ssr_subgroup::sssr_scan_subgroup` (the subgroup module), one workgroup.
    pub const SSSR_SCAN_SUBGROUP: Kernel<SerialFn<PassArgs>> = Kernel { entry: "ssr_subgroup::sssr_scan_subgroup", cpu: SCAN_CPU };
}
#[cfg(not(target_arch = "spirv"))]
pub use declarations::*;
