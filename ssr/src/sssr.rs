//! Stochastic screen-space reflections (Stachowiak 2015) on the host: the pass sequence
//! classify -> prefix sums -> emit (ray and pixel lists) -> trace and hit records (over the ray
//! list) -> resolve (over the pixel list) -> temporal,
//! on either backend, and the multi-frame driver for temporal accumulation.

use super::gbuffer::GBuffer;
pub use super::pipeline::TileStats;
use super::pipeline::{build_params, color_pyramid_passes, depth_pyramid_init, depth_pyramid_passes, ensure_color_pyramid, ensure_slot_records, pass_args, pyramid_texels, ray_slots, Runner, SsrResult, SsrSettings};
use super::scene::Scene;
use runner::{Backend, Kernel, Launch};
use shader_kernels::launch::SerialFn;
use shader_kernels::ssr::PassArgs;
use runner::gpu::{ChainBuffer, ChainDispatch, ChainPass};
use anyhow::{Context, Result};
use shader_core::ssr::params::{SsrParams, FLAG_FIS, FLAG_RAY_COLOR, FLAG_REUSE, FLAG_SAMPLED_PDF, FLAG_STOCHASTIC, REPROJECT_HIT, REPROJECT_SURFACE};
use shader_core::ssr::resolve::{COLOR_STRIDE, HIT_STRIDE, OUT_STRIDE};
use shader_core::ssr::stochastic::{self, HISTORY_STRIDE, LIST_STRIDE, TILE, TILE_SKIP, TILE_STRIDE};
use shader_core::ssr::trace::RAY_STRIDE;
use shader_kernels::ssr as kern;

/// Stochastic SSR settings.
#[derive(Clone, Debug)]
pub struct SssrSettings {
    /// Rays per 2x2 quad: 1, 2 or 4.
    pub rays_per_quad: u32,
    /// Rays per tracing pixel: 1..=8.
    pub samples_per_pixel: u32,
    /// Resolve with the neighbours' rays (ray reuse).
    pub reuse: bool,
    /// Neighbourhood radius of the resolve (1 = 3x3).
    pub resolve_radius: u32,
    /// Frames of temporal accumulation ending at the requested frame (1 = none).
    pub temporal_frames: u32,
    /// Minimum temporal blend weight.
    pub temporal_alpha: f32,
    /// Importance-sampling bias (truncated radial u).
    pub sample_bias: f32,
    /// Perceptual roughness from which rays use the linear march (Stachowiak's cheap tracer for
    /// rough rays; default 1 = Hi-Z for every ray: at 0.2 the 16-step march's missed hits were the
    /// largest part of the non-mirror error, docs/ssr.md).
    pub hiz_roughness_cut: f32,
    /// Steps of that linear march.
    pub rough_linear_steps: u32,
    /// Filtered importance sampling from the colour pyramid.
    pub fis: bool,
    /// Weight rays with the pdf stored at sampling time (Stachowiak's form) instead of the
    /// generating pixel's pdf at the reconstructed hit direction.
    pub sampled_pdf: bool,
    /// With filtered importance sampling: fetch each ray's colour once, at the footprint seen
    /// from its own pixel, for every pixel that reuses it (`FLAG_RAY_COLOR`; the default), instead
    /// of at each resolving pixel's footprint (false). Without filtered importance sampling every
    /// colour is the mip-0 one and this changes nothing.
    pub ray_color: bool,
    /// How the temporal pass reprojects the history.
    pub reprojection: Reprojection,
    /// Depth/normal history rejection (the neighbourhood clamp is always on).
    pub history_rejection: bool,
}

/// Temporal reprojection of the reflection history.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reprojection {
    /// Through the virtual image of the reflected hit (falls back to the surface's motion).
    Hit,
    /// Through the surface's motion vector.
    Surface,
}

impl Reprojection {
    pub const ALL: [Reprojection; 2] = [Reprojection::Hit, Reprojection::Surface];
    pub fn label(self) -> &'static str {
        match self {
            Reprojection::Hit => "hit",
            Reprojection::Surface => "surface",
        }
    }
}

impl Default for SssrSettings {
    fn default() -> Self {
        SssrSettings {
            rays_per_quad: 4,
            samples_per_pixel: 1,
            reuse: true,
            resolve_radius: 1,
            temporal_frames: 1,
            temporal_alpha: 0.1,
            sample_bias: 0.1,
            hiz_roughness_cut: 1.0,
            rough_linear_steps: 16,
            fis: true,
            sampled_pdf: false,
            ray_color: true,
            reprojection: Reprojection::Hit,
            history_rejection: true,
        }
    }
}

/// The parameters of a stochastic run.
pub fn sssr_params(gb: &GBuffer, s: &SsrSettings, t: &SssrSettings) -> Result<SsrParams> {
    let mut c = build_params(gb, s)?;
    if !matches!(t.rays_per_quad, 1 | 2 | 4) {
        anyhow::bail!("rays per quad must be 1, 2 or 4 (got {})", t.rays_per_quad);
    }
    if !(1..=8).contains(&t.samples_per_pixel) {
        anyhow::bail!("samples per pixel must be in 1..=8 (got {})", t.samples_per_pixel);
    }
    c.rays_per_quad = t.rays_per_quad;
    c.samples_per_pixel = t.samples_per_pixel;
    c.resolve_radius = t.resolve_radius;
    c.rough_linear_steps = t.rough_linear_steps;
    c.sample_bias = t.sample_bias;
    c.hiz_roughness_cut = t.hiz_roughness_cut;
    c.temporal_alpha = t.temporal_alpha;
    c.temporal_reprojection = match t.reprojection {
        Reprojection::Hit => REPROJECT_HIT,
        Reprojection::Surface => REPROJECT_SURFACE,
    };
    if !t.history_rejection {
        c.history_depth_tolerance = 0.0;
        c.history_normal_cos = -1.0;
        c.history_roughness_tolerance = -1.0;
    }
    c.flags |= FLAG_STOCHASTIC;
    if t.reuse {
        c.flags |= FLAG_REUSE;
    }
    if t.fis {
        c.flags |= FLAG_FIS;
    }
    if t.sampled_pdf {
        c.flags |= FLAG_SAMPLED_PDF;
    }
    if t.fis && t.ray_color {
        c.flags |= FLAG_RAY_COLOR;
    }
    Ok(c)
}

impl Runner<'_> {
    /// Tile classification: `TILE_STRIDE` words per tile.
    pub fn sssr_classify(&mut self, consts: &SsrParams, gbuf: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let (tx, ty) = (p.width.div_ceil(TILE), p.height.div_ceil(TILE));
        let n = (tx * ty) as usize;
        self.item_pass("classify", &kern::SSSR_CLASSIFY, n, TILE_STRIDE, consts, &[gbuf])
    }

    /// Prefix sum of one count column of the tiles (`stochastic::TILE_RAYS`, `TILE_ELIGIBLE`
    /// or `TILE_VALID`; n + 1 words, the last the total): sequential on the CPU, the parallel
    /// `sssr_scan` on the GPU.
    pub fn sssr_prefix(&mut self, tiles: &[f32], column: usize) -> Result<Vec<f32>> {
        Ok(self.sssr_scan(tiles, column)?.0)
    }

    /// The parallel scan of column `column` (`sssr_scan`: one workgroup, workgroup memory): tile
    /// offsets plus total (n + 1 words) and the dispatch record (`stochastic::DISPATCH_WORDS`) of
    /// the pass launched over that list. On the CPU: the sequential prefix sum and the same record.
    pub fn sssr_scan(&mut self, tiles: &[f32], column: usize) -> Result<(Vec<f32>, Vec<u32>)> {
        self.sssr_scan_with(tiles, column, ScanKernel::Auto)
    }

    /// [`Runner::sssr_scan`] with a chosen GPU kernel (the CPU ignores the choice).
    pub fn sssr_scan_with(&mut self, tiles: &[f32], column: usize, kernel: ScanKernel) -> Result<(Vec<f32>, Vec<u32>)> {
        anyhow::ensure!(
            column == stochastic::TILE_RAYS || column == stochastic::TILE_ELIGIBLE || column == stochastic::TILE_VALID,
            "scan column {column} is not a count column"
        );
        let n = tiles.len() / TILE_STRIDE;
        let scan = kernel.kernel(self.backend)?;
        let args = PassArgs { arg: n as u32, pad: column as u32, ..PassArgs::default() };
        let (mut outs, t) = self
            .backend
            .run_serial(scan, Launch::new(args, &[bytemuck::cast_slice(tiles)]), 1, &[n + 1, stochastic::DISPATCH_WORDS])
            .context("SSR pass compact (scan)")?;
        self.record("compact", t);
        let rec: Vec<u32> = outs.pop().expect("two outputs").iter().map(|d| d.to_bits()).collect();
        check_dispatch_record(&rec, scan.entry)?;
        Ok((outs.pop().expect("two outputs"), rec))
    }

    /// One stochastic frame without the temporal pass: depth and colour pyramids,
    /// classification, the two scans (rays, eligible pixels), the two lists, tracing and hit
    /// records over the ray list, and the resolve over the pixel list. On the GPU every pass runs
    /// in one command buffer with no host round trip: each scan writes the dispatch record of the
    /// passes launched over its list, which are dispatched indirectly from it (the lists are
    /// allocated for every pixel; only the scans' totals are used). On the CPU: the same passes
    /// one after the other, over the same lists.
    pub fn sssr_frame_passes(&mut self, consts: &SsrParams, gbuf: &[f32], depth: &[f32], color: &[f32]) -> Result<FramePasses> {
        let p = *consts;
        let (tx, ty) = (p.width.div_ceil(TILE), p.height.div_ceil(TILE));
        let n = (tx * ty) as usize;
        let pixels = (p.width * p.height) as usize;
        let slots = ray_slots(&p);
        // One command buffer is what only a GPU has; the CPU runs the passes one by one.
        let Some(g) = self.backend.gpu() else {
            return self.sssr_frame_passes_separately(consts, gbuf, depth, color);
        };
        let args_for = |count: usize, extra: &[u32]| pass_args(count as u32, extra).0;
        let direct = |count: usize| {
            let (gx, gy) = pass_args(count as u32, &[]).1;
            ChainDispatch::Direct(gx, gy, 1)
        };
        let indirect = |buffer: usize| ChainDispatch::Indirect { buffer, offset_bytes: (stochastic::INDIRECT_OFFSET * 4) as u64 };
        // Argument records: per pyramid level, tiles, the two scans.
        let depth_levels = depth_pyramid_passes(&p);
        let levels = color_pyramid_passes(&p);
        let level_args: Vec<Vec<u32>> = depth_levels.iter().chain(&levels).map(|&(l, cnt)| args_for(cnt, &[l])).collect();
        let tile_args = args_for(n, &[]);
        let ray_scan_args = scan_pass_args(n, stochastic::TILE_RAYS);
        let pixel_scan_args = scan_pass_args(n, stochastic::TILE_ELIGIBLE);
        let total = pyramid_texels(p.width, p.height);
        let depth_init = depth_pyramid_init(&p, depth)?;
        let mut color_init = vec![0.0f32; total * COLOR_STRIDE];
        color_init[..color.len()].copy_from_slice(color);
        // Output buffers start zeroed (wgpu's guarantee): ray slots, hit records and pixels the
        // list passes do not reach stay zero, as the CPU path leaves them.
        let mut bufs = vec![
            ChainBuffer::Input(bytemuck::bytes_of(consts)),
            ChainBuffer::Input(bytemuck::cast_slice(gbuf)),
            ChainBuffer::Input(bytemuck::cast_slice(&tile_args)),
            ChainBuffer::Input(bytemuck::cast_slice(&ray_scan_args)),
            ChainBuffer::Input(bytemuck::cast_slice(&pixel_scan_args)),
            chain_out(depth_init.len() * 4, Some(bytemuck::cast_slice(&depth_init))),
            chain_out(total * COLOR_STRIDE * 4, Some(bytemuck::cast_slice(&color_init))),
            chain_out(n * TILE_STRIDE * 4, None),
            chain_out((n + 1) * 4, None),
            chain_out(stochastic::DISPATCH_WORDS * 4, None),
            chain_out((n + 1) * 4, None),
            chain_out(stochastic::DISPATCH_WORDS * 4, None),
            chain_out(slots.max(1) * LIST_STRIDE * 4, None),
            chain_out(pixels.max(1) * 4, None),
            chain_out(slots * RAY_STRIDE * 4, None),
            chain_out(slots * HIT_STRIDE * 4, None),
            chain_out(pixels * OUT_STRIDE * 4, None),
        ];
        let (consts_b, gbuf_b, tile_b, ray_scan_b, pixel_scan_b) = (0, 1, 2, 3, 4);
        let (depth_b, color_b, tiles_b) = (5, 6, 7);
        let (ray_offsets_b, ray_dispatch_b, pixel_offsets_b, pixel_dispatch_b) = (8, 9, 10, 11);
        let (list_b, plist_b, rays_b, hits_b, refl_b) = (12, 13, 14, 15, 16);
        let first_level_arg = bufs.len();
        bufs.extend(level_args.iter().map(|a| ChainBuffer::Input(bytemuck::cast_slice(a))));
        let scan_entry = ScanKernel::Auto.kernel(self.backend)?.entry;
        let modes = consts.modes();
        let mut passes = Vec::new();
        let mut names = Vec::new();
        for (k, &(_, cnt)) in depth_levels.iter().enumerate() {
            passes.push(ChainPass { entry: kern::HIZ_DOWNSAMPLE.entry, spec: &modes, reads: vec![first_level_arg + k, consts_b], writes: vec![depth_b], dispatch: direct(cnt) });
            names.push("depth pyramid");
        }
        for (k, &(_, cnt)) in levels.iter().enumerate() {
            let arg = first_level_arg + depth_levels.len() + k;
            passes.push(ChainPass { entry: kern::COLOR_DOWNSAMPLE.entry, spec: &modes, reads: vec![arg, consts_b], writes: vec![color_b], dispatch: direct(cnt) });
            names.push("color pyramid");
        }
        passes.push(ChainPass { entry: kern::SSSR_CLASSIFY.entry, spec: &modes, reads: vec![tile_b, consts_b, gbuf_b], writes: vec![tiles_b], dispatch: direct(n) });
        names.push("classify");
        for (args_b, offsets_b, dispatch_b) in [(ray_scan_b, ray_offsets_b, ray_dispatch_b), (pixel_scan_b, pixel_offsets_b, pixel_dispatch_b)] {
            passes.push(ChainPass { entry: scan_entry, spec: &[], reads: vec![args_b, tiles_b], writes: vec![offsets_b, dispatch_b], dispatch: ChainDispatch::Direct(1, 1, 1) });
            names.push("compact");
        }
        passes.push(ChainPass {
            entry: kern::SSSR_EMIT.entry,
            spec: &modes,
            reads: vec![tile_b, consts_b, gbuf_b, ray_offsets_b, pixel_offsets_b],
            writes: vec![list_b, plist_b],
            dispatch: direct(n),
        });
        names.push("compact");
        passes.push(ChainPass {
            entry: kern::SSSR_TRACE.entry,
            spec: &modes,
            reads: vec![ray_dispatch_b, consts_b, gbuf_b, depth_b, list_b],
            writes: vec![rays_b],
            dispatch: indirect(ray_dispatch_b),
        });
        names.push("trace");
        passes.push(ChainPass {
            entry: kern::SSSR_HITS.entry,
            spec: &modes,
            reads: vec![ray_dispatch_b, consts_b, gbuf_b, color_b, rays_b, list_b],
            writes: vec![hits_b],
            dispatch: indirect(ray_dispatch_b),
        });
        names.push("hits");
        passes.push(ChainPass {
            entry: kern::SSSR_RESOLVE.entry,
            spec: &modes,
            reads: vec![pixel_dispatch_b, consts_b, gbuf_b, color_b, rays_b, hits_b, plist_b],
            writes: vec![refl_b],
            dispatch: indirect(pixel_dispatch_b),
        });
        names.push("resolve");
        let (mut res, times) = g.dispatch_chain(&bufs, &passes).context("GPU stochastic SSR frame")?;
        for (name, t) in names.iter().zip(times) {
            self.record(name, t);
        }
        for b in [ray_dispatch_b, pixel_dispatch_b] {
            let rec: Vec<u32> = bytemuck::cast_slice(&res[b].take().unwrap()).to_vec();
            check_dispatch_record(&rec, scan_entry)?;
        }
        let mut take = |i: usize| -> Vec<f32> { bytemuck::cast_slice(&res[i].take().unwrap()).to_vec() };
        let offsets = take(ray_offsets_b);
        let pixel_offsets = take(pixel_offsets_b);
        let count = offsets[n].to_bits() as usize;
        let pixel_count = pixel_offsets[n].to_bits() as usize;
        let mut list = take(list_b);
        list.truncate(count * LIST_STRIDE);
        let mut pixel_list = take(plist_b);
        pixel_list.truncate(pixel_count);
        Ok(FramePasses {
            depth_pyramid: take(depth_b),
            color_pyramid: take(color_b),
            tiles: take(tiles_b),
            offsets,
            pixel_offsets,
            list,
            count,
            pixels: pixel_list,
            rays: take(rays_b),
            hits: take(hits_b),
            reflection: take(refl_b),
        })
    }

    /// [`Runner::sssr_frame_passes`] with every pass submitted (and, on the GPU, read back) on its
    /// own: the CPU backend's path, and the GPU comparison point of `host bench ssr-wall`.
    pub fn sssr_frame_passes_separately(&mut self, consts: &SsrParams, gbuf: &[f32], depth: &[f32], color: &[f32]) -> Result<FramePasses> {
        let depth_pyramid = self.depth_pyramid(consts, depth)?;
        let color_pyramid = self.color_pyramid(consts, color)?;
        let tiles = self.sssr_classify(consts, gbuf)?;
        let offsets = self.sssr_prefix(&tiles, stochastic::TILE_RAYS)?;
        let pixel_offsets = self.sssr_prefix(&tiles, stochastic::TILE_ELIGIBLE)?;
        let (list, pixels) = self.sssr_emit(consts, gbuf, &offsets, &pixel_offsets)?;
        let rays = self.sssr_trace(consts, gbuf, &depth_pyramid, &list)?;
        let hits = self.sssr_hits(consts, gbuf, &color_pyramid, &rays, &list)?;
        let reflection = self.sssr_resolve(consts, gbuf, &color_pyramid, &rays, &hits, &pixels)?;
        let count = list.len() / LIST_STRIDE;
        Ok(FramePasses { depth_pyramid, color_pyramid, tiles, offsets, pixel_offsets, list, count, pixels, rays, hits, reflection })
    }

    /// The compacted ray list (`LIST_STRIDE` words per ray, `ray_offsets`' total entries) and
    /// eligible-pixel list (one word per pixel, `pixel_offsets`' total), from the two scans.
    pub fn sssr_emit(&mut self, consts: &SsrParams, gbuf: &[f32], ray_offsets: &[f32], pixel_offsets: &[f32]) -> Result<(Vec<f32>, Vec<f32>)> {
        let p = *consts;
        let (tx, ty) = (p.width.div_ceil(TILE), p.height.div_ceil(TILE));
        let n = (tx * ty) as usize;
        anyhow::ensure!(ray_offsets.len() == n + 1 && pixel_offsets.len() == n + 1, "offsets have {} and {} words, expected {} ({n} tiles and the total)", ray_offsets.len(), pixel_offsets.len(), n + 1);
        let rays = ray_offsets[n].to_bits() as usize;
        let eligible = pixel_offsets[n].to_bits() as usize;
        let mut outs = self.pass("compact", consts, 0, &[gbuf, ray_offsets, pixel_offsets], |b, l| b.run_serial(&kern::SSSR_EMIT, l, n, &[rays.max(1) * LIST_STRIDE, eligible.max(1)]))?;
        let mut pixels = outs.pop().expect("two outputs");
        let mut list = outs.pop().expect("two outputs");
        list.truncate(rays * LIST_STRIDE);
        pixels.truncate(eligible);
        Ok((list, pixels))
    }

    /// Trace the ray list (`LIST_STRIDE` words per entry); records land at their slots (pixel *
    /// samples + sample), the other slots are zero (no ray).
    pub fn sssr_trace(&mut self, consts: &SsrParams, gbuf: &[f32], depth_pyr: &[f32], list: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let slots = ray_slots(&p);
        self.list_pass("trace", &kern::SSSR_TRACE, list.len() / LIST_STRIDE, slots, RAY_STRIDE, 0, consts, &[gbuf, depth_pyr, list])
    }

    /// Hit records of the rays of the list (`HIT_STRIDE` per slot, `shader_core::ssr::hits`;
    /// colours from the colour pyramid `color_pyr`), computed once per ray for the resolve; slots
    /// without a ray are zero (as [`Runner::ray_hits`] writes them).
    pub fn sssr_hits(&mut self, consts: &SsrParams, gbuf: &[f32], color_pyr: &[f32], rays: &[f32], list: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let slots = ray_slots(&p);
        ensure_slot_records(&p, "ray", rays, RAY_STRIDE)?;
        ensure_color_pyramid(&p, color_pyr)?;
        self.list_pass("hits", &kern::SSSR_HITS, list.len() / LIST_STRIDE, slots, HIT_STRIDE, 0, consts, &[gbuf, color_pyr, rays, list])
    }

    /// The ratio-estimator resolve of the eligible pixels `pixels` (from [`Runner::sssr_emit`]),
    /// with the hit records of [`Runner::sssr_hits`]; every other pixel is zero.
    pub fn sssr_resolve(&mut self, consts: &SsrParams, gbuf: &[f32], color_pyr: &[f32], rays: &[f32], hits: &[f32], pixels: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let n = (p.width * p.height) as usize;
        ensure_color_pyramid(&p, color_pyr)?;
        ensure_slot_records(&p, "hit", hits, HIT_STRIDE)?;
        self.list_pass("resolve", &kern::SSSR_RESOLVE, pixels.len(), n, OUT_STRIDE, 0, consts, &[gbuf, color_pyr, rays, hits, pixels])
    }

    /// Reflection hit distance per pixel over the eligible pixels `pixels` (from
    /// [`Runner::sssr_emit`]), from the hit records `hits` ([`Runner::sssr_hits`]); 0 where no own
    /// ray hit and at every other pixel.
    pub fn sssr_hit_distance(&mut self, consts: &SsrParams, gbuf: &[f32], rays: &[f32], hits: &[f32], pixels: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let n = (p.width * p.height) as usize;
        ensure_slot_records(&p, "hit", hits, HIT_STRIDE)?;
        self.list_pass("temporal", &kern::SSSR_HIT_DISTANCE, pixels.len(), n, 1, 0, consts, &[gbuf, rays, hits, pixels])
    }

    /// Temporal accumulation: new history (`HISTORY_STRIDE` per pixel). `prev_gbuf` is the packed
    /// G-buffer of the frame the history belongs to, `hit_distance` this frame's
    /// [`Runner::sssr_hit_distance`].
    #[allow(clippy::too_many_arguments)]
    pub fn sssr_temporal(&mut self, consts: &SsrParams, gbuf: &[f32], prev_gbuf: &[f32], hit_distance: &[f32], current: &[f32], history: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let n = (p.width * p.height) as usize;
        anyhow::ensure!(prev_gbuf.len() == gbuf.len(), "previous G-buffer has {} values, expected {}", prev_gbuf.len(), gbuf.len());
        self.item_pass("temporal", &kern::SSSR_TEMPORAL, n, HISTORY_STRIDE, consts, &[gbuf, prev_gbuf, hit_distance, current, history])
    }
}

/// The GPU kernel of the ray-list scan.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScanKernel {
    /// Subgroup scan where the adapter has subgroups, else workgroup memory.
    Auto,
    /// Hillis-Steele in workgroup memory (`ssr::sssr_scan`), on every adapter.
    Workgroup,
    /// Subgroup inclusive adds (`ssr_subgroup::sssr_scan_subgroup`); an error without subgroups.
    Subgroup,
}

impl ScanKernel {
    /// The kernel this choice runs on `backend` (the CPU backend runs the sequential prefix sum
    /// whatever the choice: both kernels declare it).
    fn kernel(self, backend: &Backend) -> Result<&'static Kernel<SerialFn<PassArgs>>> {
        let (wg, sg) = (&kern::SSSR_SCAN, &kern::SSSR_SCAN_SUBGROUP);
        let Some(g) = backend.gpu() else { return Ok(wg) };
        match self {
            ScanKernel::Auto => Ok(if g.has_subgroups() { sg } else { wg }),
            ScanKernel::Workgroup => Ok(wg),
            ScanKernel::Subgroup if g.has_subgroups() => Ok(sg),
            ScanKernel::Subgroup => anyhow::bail!("the subgroup scan needs an adapter with subgroup operations and SPIR-V passthrough; {} has none", g.info.name),
        }
    }
}

/// A scan's dispatch record must hold a ray count; the subgroup kernel writes `u32::MAX` where the
/// device's subgroups do not tile the 64-lane workgroup.
fn check_dispatch_record(rec: &[u32], entry: &str) -> Result<()> {
    if rec.first() == Some(&u32::MAX) {
        anyhow::bail!("{entry}: the device's subgroups do not tile a 64-lane workgroup; set HOST_NO_SUBGROUPS=1 to use the workgroup-memory scan");
    }
    Ok(())
}

/// The scan's argument record: one workgroup ([1, 1]), then the tile count and the column scanned.
fn scan_pass_args(tiles: usize, column: usize) -> Vec<u32> {
    pass_args(1, &[tiles as u32, column as u32]).0
}

/// A chain buffer the passes write and the host reads back.
fn chain_out(size: usize, init: Option<&[u8]>) -> ChainBuffer<'_> {
    ChainBuffer::Output { size, init, read_back: true }
}

/// What [`Runner::sssr_frame_passes`] returns.
#[derive(Clone, Debug)]
pub struct FramePasses {
    /// Max-device-depth pyramid, all levels packed.
    pub depth_pyramid: Vec<f32>,
    /// Colour pyramid (RGB), all levels packed.
    pub color_pyramid: Vec<f32>,
    /// `TILE_STRIDE` words per tile.
    pub tiles: Vec<f32>,
    /// Exclusive ray-list offsets per tile and the total (u32 bits).
    pub offsets: Vec<f32>,
    /// Exclusive pixel-list offsets per tile and the total (u32 bits).
    pub pixel_offsets: Vec<f32>,
    /// The `count` ray-list entries (`LIST_STRIDE` words each).
    pub list: Vec<f32>,
    pub count: usize,
    /// The eligible pixels (index bits), tile by tile, the resolve's launch list.
    pub pixels: Vec<f32>,
    /// Ray records at pixel * samples + sample.
    pub rays: Vec<f32>,
    /// Hit records at the same slots.
    pub hits: Vec<f32>,
    /// The resolve (`OUT_STRIDE` per pixel).
    pub reflection: Vec<f32>,
}

/// The lists and hit records of a stochastic frame, which its temporal pass reads.
pub struct FrameLists {
    /// The ray list (`LIST_STRIDE` words per ray).
    pub list: Vec<f32>,
    /// The eligible pixels.
    pub pixels: Vec<f32>,
    /// Hit records per ray slot.
    pub hits: Vec<f32>,
}

/// One frame of stochastic SSR on `gb` (no temporal pass). Returns the result, its lists and its
/// hit records.
pub fn sssr_frame(backend: &Backend, gb: &GBuffer, s: &SsrSettings, t: &SssrSettings) -> Result<(SsrResult, FrameLists)> {
    let consts = sssr_params(gb, s, t)?;
    let gbuf = gb.packed();
    let mut r = Runner::new(backend);
    let FramePasses { depth_pyramid, color_pyramid, tiles, list, count, pixels, rays, hits, reflection, .. } =
        r.sssr_frame_passes(&consts, &gbuf, &gb.depth_layers(), &gb.color)?;
    let n_tiles = tiles.len() / TILE_STRIDE;
    let classes: Vec<u32> = tiles.chunks_exact(TILE_STRIDE).map(|c| c[0].to_bits()).collect();
    let stats = TileStats {
        tiles: n_tiles,
        skipped: classes.iter().filter(|&&c| c == TILE_SKIP).count(),
        rays: count,
        eligible_pixels: tiles.chunks_exact(TILE_STRIDE).map(|c| c[2].to_bits() as usize).sum(),
        classes,
    };
    Ok((
        SsrResult {
            width: gb.width,
            height: gb.height,
            depth_pyramid,
            color_pyramid,
            rays,
            reflection,
            times: r.times,
            tiles: Some(stats),
            previous_reflection: None,
        },
        FrameLists { list, pixels, hits },
    ))
}

/// Stochastic SSR at `frame`, with `frames` frames of temporal accumulation ending there (the
/// earlier frames are rendered from `scene` when given, else `gb` is reused with new random
/// numbers). Times are those of the last frame (temporal pass included).
pub fn run_sssr(
    backend: &Backend,
    source: Option<&dyn FrameSource>,
    gb: &GBuffer,
    s: &SsrSettings,
    t: &SssrSettings,
    frame: u32,
    frames: u32,
) -> Result<SsrResult> {
    let frames = frames.max(1);
    let mut history: Option<Vec<f32>> = None;
    let mut prev_gbuf: Option<Vec<f32>> = None;
    let mut last: Option<SsrResult> = None;
    for k in 0..frames {
        let f = (frame + k + 1).saturating_sub(frames);
        let g_owned;
        let g = match source {
            Some(src) if k + 1 < frames => match src.gbuffer(gb.width, gb.height, f)? {
                Some(g) => {
                    g_owned = g;
                    &g_owned
                }
                None => gb,
            },
            _ => gb,
        };
        let mut ss = s.clone();
        // Random numbers vary per frame even when the camera does not.
        ss.frame = frame.wrapping_mul(1024).wrapping_add(k);
        let (mut res, lists) = sssr_frame(backend, g, &ss, t)?;
        if frames > 1 {
            let consts = sssr_params(g, &ss, t)?;
            let n = g.width * g.height;
            let hist = history.take().unwrap_or_else(|| vec![0.0; n * HISTORY_STRIDE]);
            let packed = g.packed();
            let prev = prev_gbuf.take().unwrap_or_else(|| packed.clone());
            let mut r = Runner::new(backend);
            // The hit distance is read only by hit-based reprojection.
            let dist = match t.reprojection {
                Reprojection::Hit => r.sssr_hit_distance(&consts, &packed, &res.rays, &lists.hits, &lists.pixels)?,
                Reprojection::Surface => vec![0.0; n],
            };
            let out = r.sssr_temporal(&consts, &packed, &prev, &dist, &res.reflection, &hist)?;
            prev_gbuf = Some(packed);
            res.times.extend(r.times);
            res.reflection = out.chunks_exact(HISTORY_STRIDE).flat_map(|c| [c[0], c[1], c[2], c[3]]).collect();
            history = Some(out);
        }
        res.previous_reflection = last.take().map(|l| l.reflection);
        last = Some(res);
    }
    Ok(last.expect("at least one frame"))
}

/// Where a temporal run gets the G-buffers of the frames before the last (the last is the
/// G-buffer passed to [`run_sssr`]).
pub trait FrameSource {
    /// The G-buffer of frame `f` at `width` x `height`, or `None` to reuse the last frame's (a
    /// static camera over a static scene).
    fn gbuffer(&self, width: usize, height: usize, f: u32) -> Result<Option<GBuffer>>;
}

impl FrameSource for Scene {
    /// Animated built-in scenes render frame `f`; static ones reuse the last frame.
    fn gbuffer(&self, width: usize, height: usize, f: u32) -> Result<Option<GBuffer>> {
        Ok(self.animated().then(|| self.render_gbuffer(width, height, f)))
    }
}

/// Stored G-buffers of frames `first ..`: for G-buffers exported along a camera path
/// (`host render --gbuffer --orbit`).
pub struct FrameSequence {
    /// Frame number of `frames[0]`.
    pub first: u32,
    pub frames: Vec<GBuffer>,
}

impl FrameSource for FrameSequence {
    /// The stored frame `f`; frames outside the sequence reuse the last frame (none is
    /// invented); a stored frame of another size is an error.
    fn gbuffer(&self, width: usize, height: usize, f: u32) -> Result<Option<GBuffer>> {
        let Some(g) = f.checked_sub(self.first).and_then(|i| self.frames.get(i as usize)) else { return Ok(None) };
        stored_frame(g, width, height, f)
    }
}

/// One stored view for every frame before the last: a static camera held before a camera cut.
pub struct StaticView<'a>(pub &'a GBuffer);

impl FrameSource for StaticView<'_> {
    fn gbuffer(&self, width: usize, height: usize, f: u32) -> Result<Option<GBuffer>> {
        stored_frame(self.0, width, height, f)
    }
}

/// A stored frame `f` for a `width` x `height` run; another size is an error.
fn stored_frame(g: &GBuffer, width: usize, height: usize, f: u32) -> Result<Option<GBuffer>> {
    if g.width != width || g.height != height {
        anyhow::bail!("stored frame {f} is {}x{}, the run is {width}x{height}", g.width, g.height);
    }
    Ok(Some(g.clone()))
}

/// The ray-list order is a pure function of the G-buffer: a CPU reference for tests.
pub fn expected_list(gb: &GBuffer, s: &SsrSettings, t: &SssrSettings) -> Result<Vec<(u32, u32)>> {
    let consts = sssr_params(gb, s, t)?;
    let p = consts;
    let gbuf = gb.packed();
    let (tx, ty) = (p.width.div_ceil(TILE), p.height.div_ceil(TILE));
    let mut v = Vec::new();
    for t in 0..tx * ty {
        let (bx, by) = (t % tx, t / tx);
        for j in 0..TILE {
            for i in 0..TILE {
                let (x, y) = (bx * TILE + i, by * TILE + j);
                if x >= p.width || y >= p.height {
                    continue;
                }
                let surf = shader_core::ssr::trace::load_surface(&p, &gbuf, x, y);
                if stochastic::eligible(&p, &surf) && stochastic::traces(&p, x, y, surf.perceptual_roughness) {
                    for smp in 0..p.samples_per_pixel {
                        v.push((y * p.width + x, smp));
                    }
                }
            }
        }
    }
    Ok(v)
}
