//! Running the SSR passes on a backend: the CPU backend calls the kernels' per-invocation
//! functions natively (rayon over pixels), the GPU backend dispatches the SPIR-V entry points of
//! `shader_kernels::ssr`. Every pass is timed (CPU: wall clock; GPU: timestamp queries).

use super::gbuffer::GBuffer;
use runner::gpu::groups_2d;
use runner::timing::{Timing, TimingSource};
use runner::{Backend, Kernel, Launch};
use shader_kernels::launch::{ItemFn, ListFn};
use shader_kernels::ssr::PassArgs;
use anyhow::{Context, Result};
use shader_core::ssr::params::{self, mip_size, SsrParams};
use shader_core::ssr::resolve::{self, COLOR_STRIDE, HIT_STRIDE, OUT_STRIDE};
use shader_core::ssr::specular::SPECULAR_STRIDE;
use shader_core::ssr::stochastic;
use shader_core::ssr::trace::RAY_STRIDE;
use shader_kernels::ssr as kern;

/// How rays are traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceMode {
    /// HDRP's hierarchical traversal of the depth pyramid (max device depth per cell).
    HiZ,
    /// A linear march with this many steps.
    Linear(u32),
    /// Every pixel along the ray (the oracle).
    BruteForce,
}

impl TraceMode {
    pub fn label(&self) -> String {
        match self {
            TraceMode::HiZ => "hiz".into(),
            TraceMode::Linear(n) => format!("linear{n}"),
            TraceMode::BruteForce => "brute".into(),
        }
    }
}

/// HDRP's resolve after tracing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HdrpResolve {
    /// `SSR_APPROX`: colour pyramid at mip lerp(0, maxMip, perceptualRoughness).
    Approx,
    /// 3x3 neighbourhood weighted by GetSSRSampleWeight.
    Block3x3,
    /// 5-tap cross weighted by GetSSRSampleWeight.
    Cross5,
}

impl HdrpResolve {
    pub fn label(&self) -> &'static str {
        match self {
            HdrpResolve::Approx => "approx",
            HdrpResolve::Block3x3 => "3x3",
            HdrpResolve::Cross5 => "cross5",
        }
    }
    /// The neighbourhood shape (`resolve::NEIGHBORHOOD_*`) of the neighbourhood resolves.
    fn shape(&self) -> Option<u32> {
        match self {
            HdrpResolve::Approx => None,
            HdrpResolve::Block3x3 => Some(resolve::NEIGHBORHOOD_3X3),
            HdrpResolve::Cross5 => Some(resolve::NEIGHBORHOOD_CROSS5),
        }
    }
}

/// Settings shared by both pipelines (HDRP's volume parameters and defaults where it has them).
#[derive(Clone, Debug)]
pub struct SsrSettings {
    /// Object thickness relative to its depth (HDRP default 0.01).
    pub thickness: f32,
    /// Screen edge fade length in [-1, 1] clip units (HDRP default 0.1).
    pub screen_fade: f32,
    /// Pixels smoother than this are traced: perceptual roughness <= 1 - min_smoothness
    /// (HDRP default 0.9; the scenes here use 0.4 to study glossy reflections).
    pub min_smoothness: f32,
    /// The roughness fade starts at perceptual roughness 1 - smoothness_fade_start (HDRP 0.9).
    pub smoothness_fade_start: f32,
    /// Hi-Z iteration limit (HDRP quality presets 16 / 32 / 64 "max ray steps").
    pub hiz_max_iterations: u32,
    /// Highest depth-pyramid mip the Hi-Z tracer climbs to (clamped to the pyramid).
    pub hiz_max_mip: u32,
    /// Reject hits on surfaces facing away from the ray.
    pub backface_reject: bool,
    /// Use the G-buffer's far depth, when it has one, as the end of the mip-0 slab (the slab
    /// ends where the texel's visible surface does; `shader_core::ssr::trace::slab_base`);
    /// otherwise, or without one, HDRP's constant slab of `thickness`.
    pub far_depth: bool,
    /// With the far depth: the thinnest mip-0 slab, relative to the surface depth.
    pub min_thickness: f32,
    pub frame: u32,
    /// The GGX visible-normal sampler of the stochastic rays (HDRP's non-approximate resolves and SSSR).
    pub sampler: VndfSampler,
}

/// Tile classification statistics.
#[derive(Clone, Debug, Default)]
pub struct TileStats {
    pub tiles: usize,
    pub skipped: usize,
    pub rays: usize,
    pub eligible_pixels: usize,
    /// Class per tile (`stochastic::TILE_*`), row-major.
    pub classes: Vec<u32>,
}

/// The visible-normal sampler of `shader_core::vndf` used for GGX rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VndfSampler {
    /// Heitz 2018 ellipsoid (projected-disk) sampling; bias truncates u1 (disk radius^2).
    Heitz,
    /// Dupuy & Benyoub 2023 spherical caps; bias truncates u2 (cap height).
    Caps,
    /// Eto & Tokuyoshi 2023 bounded caps (fewer rays below the horizon); bias truncates u2.
    Bounded,
}

impl VndfSampler {
    pub const ALL: [VndfSampler; 3] = [VndfSampler::Heitz, VndfSampler::Caps, VndfSampler::Bounded];
    pub fn label(&self) -> &'static str {
        match self {
            VndfSampler::Heitz => "heitz",
            VndfSampler::Caps => "caps",
            VndfSampler::Bounded => "bounded",
        }
    }
    /// The `SAMPLER` parameter value.
    pub fn id(&self) -> u32 {
        match self {
            VndfSampler::Heitz => params::SAMPLER_HEITZ,
            VndfSampler::Caps => params::SAMPLER_CAPS,
            VndfSampler::Bounded => params::SAMPLER_BOUNDED,
        }
    }
}

impl Default for SsrSettings {
    fn default() -> Self {
        SsrSettings {
            thickness: 0.01,
            screen_fade: 0.1,
            min_smoothness: 0.4,
            smoothness_fade_start: 0.5,
            hiz_max_iterations: 64,
            hiz_max_mip: 16,
            backface_reject: true,
            far_depth: true,
            min_thickness: MIN_THICKNESS,
            frame: 0,
            sampler: VndfSampler::Heitz,
        }
    }
}

/// Default [`SsrSettings::min_thickness`].
pub const MIN_THICKNESS: f32 = 0.001;

/// Number of levels of a full pyramid over w x h (down to 1x1).
pub fn mip_levels(w: u32, h: u32) -> u32 {
    let mut l = 1;
    while mip_size(w, l - 1) > 1 || mip_size(h, l - 1) > 1 {
        l += 1;
    }
    l
}

/// Texels in a full pyramid.
pub fn pyramid_texels(w: u32, h: u32) -> usize {
    (0..mip_levels(w, h)).map(|l| (mip_size(w, l) * mip_size(h, l)) as usize).sum()
}

/// The depth-pyramid buffer before its passes run: level 0 = the first width x height values of
/// `depth` (linear depth, > 0, +inf for the sky) and, where `p` has a far-depth layer, the next
/// width x height values at [`SsrParams::far_depth_offset`] (after the last mip). The first
/// pass converts both to device depth ([`depth_pyramid_passes`]). Depths that are NaN or <= 0
/// are refused (`GBuffer::validate` refuses them too): the pyramid of maxima of device depth
/// equals the device depth of the minimum linear depth only where near / z decreases with z.
pub fn depth_pyramid_init(p: &SsrParams, depth: &[f32]) -> Result<Vec<f32>> {
    let n = (p.width * p.height) as usize;
    let total = pyramid_texels(p.width, p.height);
    let far = p.far_depth_offset as usize;
    if far == 0 {
        anyhow::ensure!(depth.len() == n || depth.len() == 2 * n, "depth has {} values, expected {n}", depth.len());
    } else {
        anyhow::ensure!(far == total, "far-depth offset {far} is not the pyramid's size {total}");
        anyhow::ensure!(depth.len() == 2 * n, "depth has {} values, expected {} (depth and far depth)", depth.len(), 2 * n);
    }
    if let Some(i) = depth[..n].iter().position(|z| !(*z > 0.0)) {
        anyhow::bail!("depth must be > 0 (linear view depth, +inf for the sky), got {} at pixel ({}, {})", depth[i], i % p.width as usize, i / p.width as usize);
    }
    // Pages touched now: the CPU passes that fill the coarser mips time their kernel only.
    let mut pyr = runner::cpu::touched_zeros(if far == 0 { total } else { total + n });
    pyr[..n].copy_from_slice(&depth[..n]);
    if far != 0 {
        pyr[total..].copy_from_slice(&depth[n..]);
    }
    Ok(pyr)
}

/// The depth-pyramid passes as (level, invocations): each writes mips `level` and `level + 1`
/// (`level` = 0, 2, 4, ...) with one invocation per texel of mip `level + 1`
/// (`shader_core::ssr::trace::hiz_block`); the first also converts the depth (and the far-depth
/// layer, with as many invocations again) from linear to device depth.
pub fn depth_pyramid_passes(p: &SsrParams) -> Vec<(u32, usize)> {
    let layers = if p.far_depth_offset != 0 { 2 } else { 1 };
    pyramid_passes(p, 0).into_iter().map(|(l, n)| (l, if l == 0 { n * layers } else { n })).collect()
}

/// The colour-pyramid passes as (level, invocations): each writes mips `level` and `level + 1`
/// (`level` = 1, 3, 5, ...; mip 0 is the frame) with one invocation per texel of mip `level + 1`
/// (`shader_core::ssr::resolve::color_block`).
pub fn color_pyramid_passes(p: &SsrParams) -> Vec<(u32, usize)> {
    pyramid_passes(p, 1)
}

/// Passes writing mips `first..p.mip_count` two at a time: (lower mip, texels of the mip above it).
fn pyramid_passes(p: &SsrParams, first: u32) -> Vec<(u32, usize)> {
    (first..p.mip_count).step_by(2).map(|l| (l, (mip_size(p.width, l + 1) * mip_size(p.height, l + 1)) as usize)).collect()
}

/// The parameters for `gb` and `s` (pipeline-specific values are set by the caller).
pub fn build_params(gb: &GBuffer, s: &SsrSettings) -> Result<SsrParams> {
    let (w, h) = (gb.width as u32, gb.height as u32);
    // HDRP: roughnessFadeEnd = 1 - minSmoothness, roughnessFadeStart = 1 - smoothnessFadeStart.
    let fade_end = 1.0 - s.min_smoothness;
    let fade_start = 1.0 - s.smoothness_fade_start;
    let fade_len = fade_end - fade_start;
    let (rcp, end_rcp) = if fade_len != 0.0 { (1.0 / fade_len, fade_end * (1.0 / fade_len)) } else { (0.0, 1.0) };
    let levels = mip_levels(w, h);
    // The far-depth layer follows the pyramid's mips in the depth-pyramid buffer.
    let far = gb.depth_far.is_some() && s.far_depth;
    Ok(SsrParams {
        width: w,
        height: h,
        near: gb.camera.near,
        thickness_scale: 1.0 / (1.0 + s.thickness),
        thickness_bias: 0.0,
        edge_fade_rcp_length: (1.0 / s.screen_fade).min(f32::MAX),
        roughness_fade_rcp_length: rcp,
        roughness_fade_end_times_rcp_length: end_rcp,
        roughness_fade_end: fade_end,
        hiz_max_iterations: s.hiz_max_iterations,
        depth_max_mip: s.hiz_max_mip.min(levels - 1),
        linear_steps: 32,
        trace_mode: params::TRACE_HIZ,
        color_max_mip: levels - 1,
        frame: s.frame,
        flags: if s.backface_reject { params::FLAG_BACKFACE_REJECT } else { 0 },
        hiz_roughness_cut: 0.2,
        rough_linear_steps: 16,
        samples_per_pixel: 1,
        rays_per_quad: 4,
        sample_bias: 0.0,
        resolve_radius: 1,
        temporal_alpha: 0.1,
        mip_count: levels,
        sampler: s.sampler.id(),
        history_depth_tolerance: 0.05,
        history_normal_cos: 0.9,
        temporal_reprojection: params::REPROJECT_HIT,
        history_roughness_tolerance: 0.05,
        far_depth_offset: if far { pyramid_texels(w, h) as u32 } else { 0 },
        min_thickness_scale: 1.0 / (1.0 + s.min_thickness),
        pad: 0,
        view: gb.camera.view(),
        proj: gb.camera.proj(gb.width, gb.height),
        inv_view: gb.camera.inv_view()?,
        prev_proj: gb.previous_camera.proj(gb.width, gb.height),
        prev_inv_view: gb.previous_camera.inv_view()?,
    })
}

/// Ray slots of a frame: pixels x samples per pixel (the ray and hit records' length in records).
pub(crate) fn ray_slots(p: &SsrParams) -> usize {
    (p.width * p.height * p.samples_per_pixel) as usize
}

/// Fail unless `v` holds `stride` values for each of the frame's ray slots; `what` names the
/// records ("ray", "hit") in the message.
pub(crate) fn ensure_slot_records(p: &SsrParams, what: &str, v: &[f32], stride: usize) -> Result<()> {
    let want = ray_slots(p) * stride;
    anyhow::ensure!(v.len() == want, "{what} records have {} values, expected {want}", v.len());
    Ok(())
}

/// Fail unless `v` is a colour pyramid of the frame (RGB texels of every mip).
pub(crate) fn ensure_color_pyramid(p: &SsrParams, v: &[f32]) -> Result<()> {
    let want = pyramid_texels(p.width, p.height) * COLOR_STRIDE;
    anyhow::ensure!(v.len() == want, "colour pyramid has {} values, expected {want} ({}x{} RGB and its mips)", v.len(), p.width, p.height);
    Ok(())
}

/// One pass's time.
#[derive(Clone, Debug)]
pub struct PassTime {
    pub name: String,
    pub seconds: f64,
    pub source: TimingSource,
}

/// Runs passes on one backend and records their times.
pub struct Runner<'a> {
    pub backend: &'a Backend,
    pub times: Vec<PassTime>,
}

/// HDRP's passes over a pixel list ([`Runner::hdrp_pixels`]): one ray per pixel (its slot is
/// the pixel), and a list of at most every pixel, each inside the frame.
fn ensure_hdrp_pixels(p: &SsrParams, pixels: &[f32]) -> Result<()> {
    anyhow::ensure!(p.samples_per_pixel == 1, "HDRP traces one ray per pixel, the parameters ask for {}", p.samples_per_pixel);
    let n = p.width * p.height;
    anyhow::ensure!(pixels.len() <= n as usize, "the pixel list has {} entries for a {}x{} frame", pixels.len(), p.width, p.height);
    if let Some(k) = pixels.iter().position(|q| q.to_bits() >= n) {
        anyhow::bail!("pixel list entry {k} names pixel {} outside the {}x{} frame", pixels[k].to_bits(), p.width, p.height);
    }
    Ok(())
}

fn bytes(v: &[f32]) -> &[u8] {
    bytemuck::cast_slice(v)
}

/// The argument record of a 1D pass over `count` invocations ([count, groups in x, `extra`...,
/// zero-padded to the four words of `shader_kernels::ssr::PassArgs`) and its 2D workgroup grid.
pub(crate) fn pass_args(count: u32, extra: &[u32]) -> (Vec<u32>, (u32, u32)) {
    let (gx, gy) = groups_2d(count.div_ceil(shader_kernels::WORKGROUP_SIZE));
    let mut args = vec![count, gx];
    args.extend_from_slice(extra);
    // At least the four words of the kernels' uniform `PassArgs` record.
    args.resize(args.len().max(std::mem::size_of::<shader_kernels::ssr::PassArgs>() / 4), 0);
    (args, (gx, gy))
}

impl<'a> Runner<'a> {
    pub fn new(backend: &'a Backend) -> Self {
        Runner { backend, times: Vec::new() }
    }

    pub(crate) fn record(&mut self, name: &str, t: Timing) {
        if let Some(p) = self.times.iter_mut().find(|p| p.name == name) {
            p.seconds += t.seconds;
            if p.source != t.source {
                p.source = TimingSource::WallClock;
            }
        } else {
            self.times.push(PassTime { name: name.into(), seconds: t.seconds, source: t.source });
        }
    }

    /// Total seconds over every recorded pass.
    pub fn total_seconds(&self) -> f64 {
        self.times.iter().map(|p| p.seconds).sum()
    }

    /// Launch an SSR pass named `name` (its time is recorded under that name): `run` gets the
    /// backend and the launch (argument record with the pass's argument `arg`, then the
    /// parameter record `consts` and `inputs`, the pipeline specialized on `consts`' modes).
    pub(crate) fn pass<R>(&mut self, name: &str, consts: &SsrParams, arg: u32, inputs: &[&[f32]], run: impl FnOnce(&Backend, Launch<'_, PassArgs>) -> Result<(R, Timing)>) -> Result<R> {
        let modes = consts.modes();
        let mut bufs: Vec<&[u8]> = vec![bytemuck::bytes_of(consts)];
        bufs.extend(inputs.iter().map(|v| bytes(v)));
        let launch = Launch::new(PassArgs { arg, ..PassArgs::default() }, &bufs).with_spec(&modes);
        let (r, t) = run(self.backend, launch).with_context(|| format!("SSR pass {name}"))?;
        self.record(name, t);
        Ok(r)
    }

    /// A pass over a list of `count` entries into a zeroed buffer of `slots` records of
    /// `stride` floats (`Backend::run_list`). An empty list runs nothing: every slot stays zero.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn list_pass(&mut self, name: &str, kernel: &Kernel<ListFn<PassArgs>>, count: usize, slots: usize, stride: usize, arg: u32, consts: &SsrParams, inputs: &[&[f32]]) -> Result<Vec<f32>> {
        if count == 0 {
            return Ok(vec![0.0; slots * stride]);
        }
        self.pass(name, consts, arg, inputs, |b, l| b.run_list(kernel, l, count, slots, stride))
    }

    /// A pass of one invocation per record of `stride` floats, `count` records
    /// (`Backend::run`).
    pub(crate) fn item_pass(&mut self, name: &str, kernel: &Kernel<ItemFn<PassArgs>>, count: usize, stride: usize, consts: &SsrParams, inputs: &[&[f32]]) -> Result<Vec<f32>> {
        self.pass(name, consts, 0, inputs, |b, l| b.run(kernel, l, count, stride))
    }

    /// The max-device-depth pyramid of `depth` (level 0 = its device depth), all levels packed, followed by
    /// the far-depth layer where the parameters have one (`depth` is then
    /// [`GBuffer::depth_layers`]: the depth, then the far depth).
    pub fn depth_pyramid(&mut self, consts: &SsrParams, depth: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let mut pyr = depth_pyramid_init(&p, depth)?;
        for (level, n) in depth_pyramid_passes(&p) {
            pyr = self.pass("depth pyramid", consts, level, &[], |b, l| b.run_in_place(&kern::HIZ_DOWNSAMPLE, l, n, pyr))?;
        }
        Ok(pyr)
    }

    /// The colour pyramid (RGB, 2x2 box filter per level).
    pub fn color_pyramid(&mut self, consts: &SsrParams, color: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let total = pyramid_texels(p.width, p.height) * COLOR_STRIDE;
        anyhow::ensure!(color.len() == (p.width * p.height) as usize * COLOR_STRIDE, "colour has {} values, expected {} ({}x{} RGB)", color.len(), (p.width * p.height) as usize * COLOR_STRIDE, p.width, p.height);
        let mut pyr = runner::cpu::touched_zeros(total);
        pyr[..color.len()].copy_from_slice(color);
        for (level, n) in color_pyramid_passes(&p) {
            pyr = self.pass("color pyramid", consts, level, &[], |b, l| b.run_in_place(&kern::COLOR_DOWNSAMPLE, l, n, pyr))?;
        }
        Ok(pyr)
    }

    /// HDRP's valid-pixel list: tile classification, the scan of its `TILE_VALID` column and
    /// the list of pixels with a valid surface (tile order, row order within a tile), which
    /// HDRP's trace, hit-record and resolve passes are launched over (the other pixels trace
    /// no ray and reflect nothing).
    pub fn hdrp_pixels(&mut self, consts: &SsrParams, gbuf: &[f32]) -> Result<Vec<f32>> {
        let tiles = self.sssr_classify(consts, gbuf)?;
        let (offsets, _) = self.sssr_scan(&tiles, stochastic::TILE_VALID)?;
        self.hdrp_emit(consts, gbuf, &offsets)
    }

    /// HDRP's pixel list from the tile offsets `offsets` (n + 1 words, the scan of `TILE_VALID`).
    pub fn hdrp_emit(&mut self, consts: &SsrParams, gbuf: &[f32], offsets: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let n = (p.width.div_ceil(stochastic::TILE) * p.height.div_ceil(stochastic::TILE)) as usize;
        anyhow::ensure!(offsets.len() == n + 1, "offsets have {} words, expected {} ({n} tiles and the total)", offsets.len(), n + 1);
        let count = offsets[n].to_bits() as usize;
        anyhow::ensure!(count <= (p.width * p.height) as usize, "the scan counts {count} valid pixels in a {}x{} frame", p.width, p.height);
        let mut outs = self.pass("compact", consts, 0, &[gbuf, offsets], |b, l| b.run_serial(&kern::HDRP_EMIT, l, n, &[count.max(1)]))?;
        let mut pixels = outs.remove(0);
        pixels.truncate(count);
        Ok(pixels)
    }

    /// HDRP tracing pass over the pixel list `pixels` ([`Runner::hdrp_pixels`]): a ray record
    /// per pixel, zero (no ray) for the pixels not in the list.
    pub fn hdrp_trace(&mut self, consts: &SsrParams, gbuf: &[f32], depth_pyr: &[f32], pixels: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let n = (p.width * p.height) as usize;
        ensure_hdrp_pixels(&p, pixels)?;
        self.list_pass("trace", &kern::HDRP_TRACE, pixels.len(), n, RAY_STRIDE, 0, consts, &[gbuf, depth_pyr, pixels])
    }

    /// Hit records of every ray slot (`HIT_STRIDE` floats per slot, pixels x samples per pixel,
    /// in the ray records' order; `shader_core::ssr::hits`): what the neighbourhood resolves
    /// need of each hitting ray (colours from the colour pyramid `color_pyr`), computed once per ray.
    pub fn ray_hits(&mut self, consts: &SsrParams, gbuf: &[f32], color_pyr: &[f32], rays: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let slots = ray_slots(&p);
        ensure_slot_records(&p, "ray", rays, RAY_STRIDE)?;
        ensure_color_pyramid(&p, color_pyr)?;
        self.item_pass("hits", &kern::RAY_HITS, slots, HIT_STRIDE, consts, &[gbuf, color_pyr, rays])
    }

    /// HDRP reprojection / resolve pass over the pixel list `pixels` (the one the rays were
    /// traced over): (rgb premultiplied, opacity) per pixel, zero for the pixels not in the list.
    /// `SSR_APPROX` reads each pixel's own ray (`ssr_hdrp_reproject`); the neighbourhood
    /// resolves (`ssr_hdrp_resolve`) first compute the hit records of the listed pixels' rays
    /// (`ssr_hdrp_hits`, its own pass, "hits").
    pub fn hdrp_reproject(&mut self, consts: &SsrParams, gbuf: &[f32], color_pyr: &[f32], rays: &[f32], pixels: &[f32], mode: HdrpResolve) -> Result<Vec<f32>> {
        let p = *consts;
        let n = (p.width * p.height) as usize;
        ensure_slot_records(&p, "ray", rays, RAY_STRIDE)?;
        ensure_hdrp_pixels(&p, pixels)?;
        ensure_color_pyramid(&p, color_pyr)?;
        let count = pixels.len();
        let Some(shape) = mode.shape() else {
            return self.list_pass("resolve", &kern::HDRP_REPROJECT, count, n, OUT_STRIDE, 0, consts, &[gbuf, color_pyr, rays, pixels]);
        };
        let hits = self.list_pass("hits", &kern::HDRP_HITS, count, n, HIT_STRIDE, 0, consts, &[gbuf, color_pyr, rays, pixels])?;
        self.list_pass("resolve", &kern::HDRP_RESOLVE, count, n, OUT_STRIDE, shape, consts, &[gbuf, color_pyr, rays, &hits, pixels])
    }

    /// The specular term: `reflection` (4 values per pixel, premultiplied) times the
    /// preintegrated FG term from the energy tables `lut` (`energy::Tables::lut_buffer`),
    /// f0 = mix(0.04, base colour, metalness). 4 values per pixel (RGB, opacity).
    pub fn specular(&mut self, consts: &SsrParams, gbuf: &[f32], base_color: &[f32], lut: &[f32], reflection: &[f32]) -> Result<Vec<f32>> {
        let p = *consts;
        let n = (p.width * p.height) as usize;
        anyhow::ensure!(base_color.len() == 3 * n, "base colour has {} values, expected {}", base_color.len(), 3 * n);
        anyhow::ensure!(reflection.len() == 4 * n, "reflection has {} values, expected {}", reflection.len(), 4 * n);
        self.item_pass("specular", &kern::SPECULAR, n, SPECULAR_STRIDE, consts, &[gbuf, base_color, lut, reflection])
    }
}

/// Everything one HDRP run produces.
#[derive(Clone, Debug)]
pub struct SsrResult {
    pub width: usize,
    pub height: usize,
    pub depth_pyramid: Vec<f32>,
    pub color_pyramid: Vec<f32>,
    /// Ray records (`RAY_STRIDE` per pixel, or per pixel and sample for SSSR).
    pub rays: Vec<f32>,
    /// Premultiplied (rgb, opacity) per pixel.
    pub reflection: Vec<f32>,
    pub times: Vec<PassTime>,
    /// Extra outputs of the stochastic pipeline (tile classes etc.).
    pub tiles: Option<TileStats>,
    /// The reflection of the frame before the last, for multi-frame runs (temporal stability).
    pub previous_reflection: Option<Vec<f32>>,
}

/// Run HDRP's SSR (trace + reprojection/resolve) on `gb`.
pub fn run_hdrp(backend: &Backend, gb: &GBuffer, s: &SsrSettings, trace_mode: TraceMode, resolve_mode: HdrpResolve) -> Result<SsrResult> {
    let mut consts = build_params(gb, s)?;
    match trace_mode {
        TraceMode::HiZ => consts.trace_mode = params::TRACE_HIZ,
        TraceMode::Linear(n) => {
            consts.trace_mode = params::TRACE_LINEAR;
            consts.linear_steps = n;
        }
        TraceMode::BruteForce => consts.trace_mode = params::TRACE_BRUTE_FORCE,
    }
    if resolve_mode != HdrpResolve::Approx {
        // HDRP's non-approximate mode traces GGX-sampled rays (one per pixel).
        consts.flags |= params::FLAG_STOCHASTIC;
    }
    let gbuf = gb.packed();
    let mut r = Runner::new(backend);
    let depth_pyramid = r.depth_pyramid(&consts, &gb.depth_layers())?;
    let color_pyramid = r.color_pyramid(&consts, &gb.color)?;
    let pixels = r.hdrp_pixels(&consts, &gbuf)?;
    let rays = r.hdrp_trace(&consts, &gbuf, &depth_pyramid, &pixels)?;
    let reflection = r.hdrp_reproject(&consts, &gbuf, &color_pyramid, &rays, &pixels, resolve_mode)?;
    Ok(SsrResult {
        width: gb.width,
        height: gb.height,
        depth_pyramid,
        color_pyramid,
        rays,
        reflection,
        times: r.times,
        tiles: None,
        previous_reflection: None,
    })
}
