//! Stochastic screen-space reflections (Stachowiak 2015, "Stochastic Screen-Space Reflections",
//! SIGGRAPH Advances): 8x8 tile classification, a compacted ray list (deterministic prefix sum),
//! sparse GGX-VNDF rays (1, 2 or 4 per 2x2 quad; Hi-Z for smooth, linear march for rough), the
//! BRDF-weighted ratio-estimator resolve over a neighbourhood, filtered importance sampling from
//! the colour pyramid, and temporal accumulation with history clamping.
//!
//! ```
//! use shader_core::ssr::stochastic::dispatch_record;
//! // The dispatch record: [rays, groups in x, indirect (x, y, 1)].
//! assert_eq!(dispatch_record(130, 64), [130, 3, 3, 1, 1]);
//! ```

use crate::dispatch::groups_2d;
use crate::ieee;
use super::params::{SsrParams, FLAG_FIS, FLAG_RAY_COLOR, FLAG_REUSE, FLAG_SAMPLED_PDF, REPROJECT_HIT, TRACE_HIZ, TRACE_LINEAR_CROSSING};
use super::compare::{clampf, maxf, minf};
use super::layout::{gbuf, info, Surface, HIT_FADE, HIT_STRIDE, HIT_TAN_HALF, OUT_STRIDE, RAY_INFO, RAY_PDF, RAY_STRIDE};
use super::resolve::{hit_color, lambda_cos, load_hit_pos_pdf, log2_approx, perceptual_roughness_fade, store as resolve_store, store_resolved, stored_hit_color};
pub use super::sampling::{reflection_pdf, sample_ray, sample_reflection, MIRROR_ROUGHNESS};
use crate::frame::orthonormal_basis;
use super::trace::{load_surface, trace_and_store, store_no_ray};
use crate::buffer::{load, load2, load4, store};
use crate::ndf;
use crate::vector::Vec3;

/// Tile edge in pixels.
pub const TILE: u32 = 8;
/// Tile class: no eligible pixel, nothing traced.
pub const TILE_SKIP: u32 = 0;
/// Tile class: every traced pixel uses the Hi-Z tracer (all smoother than the Hi-Z cut).
pub const TILE_HIZ: u32 = 1;
/// Tile class: every traced pixel uses the linear crossing tracer (all rougher than the cut).
pub const TILE_LINEAR: u32 = 2;
/// Tile class: both tracers occur in the tile.
pub const TILE_MIXED: u32 = 3;
/// Floats per tile record: class, rays, eligible pixels, valid pixels (bits).
pub const TILE_STRIDE: usize = 4;
/// Column of a tile record holding its ray count (scanned into the ray list's offsets).
pub const TILE_RAYS: usize = 1;
/// Column of a tile record holding its eligible-pixel count (scanned into the pixel list's offsets).
pub const TILE_ELIGIBLE: usize = 2;
/// Column of a tile record holding its count of pixels with a valid surface
/// ([`Surface::valid`]: the pixels HDRP traces; scanned into HDRP's pixel list's offsets).
pub const TILE_VALID: usize = 3;
/// Words per ray-list entry: pixel index, sample | (trace mode << 8).
pub const LIST_STRIDE: usize = 2;
/// Floats per history texel: r, g, b (premultiplied), opacity, accumulated frame count.
pub const HISTORY_STRIDE: usize = 5;

/// Does pixel (x, y) trace rays this frame? Mirror pixels always; others by the quad pattern:
/// 4 rays per 2x2 quad = every pixel, 2 = a checkerboard, 1 = one pixel per quad, each
/// alternating with the frame index.
#[inline]
pub fn traces(p: &SsrParams, x: u32, y: u32, perceptual_roughness: f32) -> bool {
    if perceptual_roughness < MIRROR_ROUGHNESS {
        return true;
    }
    let q = (x & 1) + 2 * (y & 1);
    if p.rays_per_quad >= 4 {
        true
    } else if p.rays_per_quad == 2 {
        ((x + y + p.frame) & 1) == 0
    } else {
        let order = p.frame & 3;
        let pick = if order == 0 { 0 } else if order == 1 { 3 } else if order == 2 { 1 } else { 2 };
        q == pick
    }
}

/// Does pixel (x, y) need SSR at all: valid geometry, smoother than the cut-off and not fully
/// faded by the roughness fade?
#[inline]
pub fn eligible(p: &SsrParams, s: &Surface) -> bool {
    s.valid
        && perceptual_roughness_fade(s.perceptual_roughness, p.roughness_fade_rcp_length, p.roughness_fade_end_times_rcp_length) > 0.0
}

/// The tracer for a pixel: Hi-Z below the roughness cut, the cheap linear march (with the
/// crossing test) above it.
#[inline]
pub fn trace_mode_for(p: &SsrParams, perceptual_roughness: f32) -> u32 {
    if perceptual_roughness < p.hiz_roughness_cut {
        TRACE_HIZ
    } else {
        TRACE_LINEAR_CROSSING
    }
}

/// Classify tile (tx, ty): (class, rays to trace, eligible pixels, pixels with a valid surface).
/// A tile with no eligible pixel (sky, too rough, faded out, back-facing) is skipped by the
/// stochastic passes; HDRP traces every valid pixel (including those faded out exactly at the
/// fade end, whose rays its neighbourhood resolves still read).
pub fn classify_tile(p: &SsrParams, gbuf: &[f32], tx: u32, ty: u32) -> (u32, u32, u32, u32) {
    let mut rays = 0;
    let mut eligible_px = 0;
    let mut valid_px = 0;
    let mut smooth = 0;
    let mut rough = 0;
    let mut j = 0;
    while j < TILE {
        let y = ty * TILE + j;
        let mut i = 0;
        while i < TILE {
            let x = tx * TILE + i;
            if x < p.width && y < p.height {
                let s = load_surface(p, gbuf, x, y);
                if s.valid {
                    valid_px += 1;
                }
                if eligible(p, &s) {
                    eligible_px += 1;
                    if traces(p, x, y, s.perceptual_roughness) {
                        rays += p.samples_per_pixel;
                        if trace_mode_for(p, s.perceptual_roughness) == TRACE_HIZ {
                            smooth += 1;
                        } else {
                            rough += 1;
                        }
                    }
                }
            }
            i += 1;
        }
        j += 1;
    }
    let class = if eligible_px == 0 {
        TILE_SKIP
    } else if rough == 0 {
        TILE_HIZ
    } else if smooth == 0 {
        TILE_LINEAR
    } else {
        TILE_MIXED
    };
    (class, rays, eligible_px, valid_px)
}

/// Exclusive prefix sum of one count column of the tiles ([`TILE_RAYS`], [`TILE_ELIGIBLE`] or [`TILE_VALID`]), in
/// tile order (the CPU backend's compaction step; the GPU's parallel `sssr_scan` must give the
/// same): `offsets[t]` for each of `n` tiles and the total at `offsets[n]`.
pub fn prefix_sum_tiles(tiles: &[f32], n: u32, column: usize, offsets: &mut [f32]) {
    let total = segment_offsets(tiles, column, 0, n, 0, offsets);
    offsets[n as usize] = f32::from_bits(total);
}

/// Lanes of the parallel scan's workgroup: the tiles are cut into `SCAN_LANES` segments.
pub const SCAN_LANES: u32 = 64;

/// Workgroup memory of the scan: two halves of `SCAN_LANES` words (ping-pong).
pub const SCAN_SHARED: usize = 2 * SCAN_LANES as usize;

/// Tiles `[first, end)` of lane `lane` in the parallel scan of `n` tiles: `SCAN_LANES`
/// consecutive segments of ceil(n / `SCAN_LANES`) tiles, the last ones short or empty (a
/// reduce-then-scan: each lane sums its segment, one scan of the 64 segment totals, each lane
/// writes its segment's offsets from its total's exclusive prefix; Blelloch 1990, "Prefix sums
/// and their applications", section 1.3).
#[inline]
pub fn scan_segment(n: u32, lane: u32) -> (u32, u32) {
    let per = (n + SCAN_LANES - 1) / SCAN_LANES;
    let first = if lane * per < n { lane * per } else { n };
    let end = if first + per < n { first + per } else { n };
    (first, end)
}

/// Sum of column `column` over tiles `[first, end)`.
#[inline]
pub fn segment_total(tiles: &[f32], column: usize, first: u32, end: u32) -> u32 {
    let mut sum: u32 = 0;
    let mut t = first;
    while t < end {
        sum += load(tiles, (t as usize) * TILE_STRIDE + column).to_bits();
        t += 1;
    }
    sum
}

/// Write the exclusive offsets of tiles `[first, end)`, counting from `base`, into `offsets[t]`;
/// returns `base` plus the segment's total.
#[inline]
pub fn segment_offsets(tiles: &[f32], column: usize, first: u32, end: u32, base: u32, offsets: &mut [f32]) -> u32 {
    let mut sum = base;
    let mut t = first;
    while t < end {
        store(offsets, t as usize, f32::from_bits(sum));
        sum += load(tiles, (t as usize) * TILE_STRIDE + column).to_bits();
        t += 1;
    }
    sum
}

/// Words of the trace pass's dispatch record written by the scan: [rays, groups in x, then the
/// indirect dispatch (groups x, groups y, 1)] (`INDIRECT_OFFSET` words in).
pub const DISPATCH_WORDS: usize = 5;
/// Word offset of the (x, y, z) indirect-dispatch arguments inside the dispatch record.
pub const INDIRECT_OFFSET: usize = 2;

/// One Hillis-Steele step of an inclusive scan over `SCAN_LANES` values in `shared[src..]`
/// (Hillis & Steele 1986): lane's value plus the value `d` lanes before it (0 before lane 0).
/// The kernel runs log2(64) steps, ping-ponging between two halves of workgroup memory.
#[inline]
pub fn scan_lane_inclusive(shared: &[u32; SCAN_SHARED], src: usize, lane: u32, d: u32) -> u32 {
    let own = shared[src + lane as usize];
    if lane >= d {
        own + shared[src + (lane - d) as usize]
    } else {
        own
    }
}

/// Write the scan's result: the total at `offsets[n]` and the trace pass's dispatch record. The
/// subgroup scan passes `rays = None` when its subgroups do not tile the workgroup: the record's
/// ray count is then `u32::MAX` (the host reports it) and `offsets[n]` is left alone.
#[inline]
pub fn store_scan_total(offsets: &mut [f32], dispatch: &mut [u32], n: u32, rays: Option<u32>, workgroup: u32) {
    let rec = match rays {
        Some(r) => {
            offsets[n as usize] = f32::from_bits(r);
            dispatch_record(r, workgroup)
        }
        None => [u32::MAX, 0, 0, 0, 0],
    };
    let mut k = 0;
    while k < DISPATCH_WORDS {
        dispatch[k] = rec[k];
        k += 1;
    }
}

/// The trace pass's dispatch record for `rays` list entries (see [`DISPATCH_WORDS`]).
#[inline]
pub fn dispatch_record(rays: u32, workgroup: u32) -> [u32; DISPATCH_WORDS] {
    let (gx, gy) = groups_2d((rays + workgroup - 1) / workgroup);
    [rays, gx, gx, gy, 1]
}

/// Write tile (tx, ty)'s rays into the ray list from its offset in `ray_offsets` (pixels in row
/// order within the tile, samples in order) and its eligible pixels into the pixel list from its
/// offset in `pixel_offsets` (row order): the two compacted lists the trace, hit-record and
/// resolve passes are launched over.
#[allow(clippy::too_many_arguments)]
pub fn emit_tile(p: &SsrParams, gbuf: &[f32], ray_offsets: &[f32], pixel_offsets: &[f32], tx: u32, ty: u32, list: &mut [f32], pixels: &mut [f32]) {
    let tiles_x = (p.width + TILE - 1) / TILE;
    let t = (ty * tiles_x + tx) as usize;
    let mut k = load(ray_offsets, t).to_bits();
    let mut kp = load(pixel_offsets, t).to_bits();
    // A tile with nothing to emit (its offsets equal the next tile's) skips its 64 surfaces; on a
    // device that runs 8 tiles in lockstep the loop is skipped when all 8 are empty.
    if load(ray_offsets, t + 1).to_bits() == k && load(pixel_offsets, t + 1).to_bits() == kp {
        return;
    }
    let mut j = 0;
    while j < TILE {
        let y = ty * TILE + j;
        let mut i = 0;
        while i < TILE {
            let x = tx * TILE + i;
            if x < p.width && y < p.height {
                let s = load_surface(p, gbuf, x, y);
                if eligible(p, &s) {
                    store(pixels, kp as usize, f32::from_bits(y * p.width + x));
                    kp += 1;
                    if traces(p, x, y, s.perceptual_roughness) {
                        let mode = trace_mode_for(p, s.perceptual_roughness);
                        let mut smp = 0;
                        while smp < p.samples_per_pixel {
                            store(list, (k as usize) * LIST_STRIDE, f32::from_bits(y * p.width + x));
                            store(list, (k as usize) * LIST_STRIDE + 1, f32::from_bits(smp | (mode << 8)));
                            k += 1;
                            smp += 1;
                        }
                    }
                }
            }
            i += 1;
        }
        j += 1;
    }
}

/// Write tile (tx, ty)'s pixels with a valid surface ([`TILE_VALID`]) into a pixel list from
/// its offset in `offsets` (row order within the tile): the list HDRP's trace, hit-record and
/// resolve passes are launched over.
pub fn emit_valid_tile(p: &SsrParams, gbuf: &[f32], offsets: &[f32], tx: u32, ty: u32, pixels: &mut [f32]) {
    let tiles_x = (p.width + TILE - 1) / TILE;
    let t = (ty * tiles_x + tx) as usize;
    let mut k = load(offsets, t).to_bits();
    // An empty tile skips its 64 surfaces (see [`emit_tile`]).
    if load(offsets, t + 1).to_bits() == k {
        return;
    }
    let mut j = 0;
    while j < TILE {
        let y = ty * TILE + j;
        let mut i = 0;
        while i < TILE {
            let x = tx * TILE + i;
            if x < p.width && y < p.height && load_surface(p, gbuf, x, y).valid {
                store(pixels, k as usize, f32::from_bits(y * p.width + x));
                k += 1;
            }
            i += 1;
        }
        j += 1;
    }
}

/// The ray slot (pixel * samples per pixel + sample, the ray records' order) of ray-list entry `k`.
#[inline]
pub fn list_slot(p: &SsrParams, list: &[f32], k: u32) -> u32 {
    let pixel = load(list, (k as usize) * LIST_STRIDE).to_bits();
    let smp = load(list, (k as usize) * LIST_STRIDE + 1).to_bits() & 0xff;
    pixel * p.samples_per_pixel + smp
}

/// Pixel-list entry `k`: (pixel index, x, y).
#[inline]
pub fn list_pixel(p: &SsrParams, pixels: &[f32], k: u32) -> (u32, u32, u32) {
    let q = load(pixels, k as usize).to_bits();
    (q, q % p.width, q / p.width)
}

/// GGX D for a half vector at cosine `c` to the normal (isotropic; Heitz 2014 eq. 85 through
/// [`ndf::ggx_d`]).
#[inline]
pub fn ggx_d_cos(c: f32, alpha: f32) -> f32 {
    let s2 = 1.0 - c * c;
    let s = if s2 > 0.0 { ieee::sqrt(s2) } else { 0.0 };
    ndf::ggx_d(Vec3::new(s, 0.0, c), alpha, alpha)
}

/// Trace ray-list entry `k` (pixel, sample, mode) and store its record at
/// `out[ob..ob + RAY_STRIDE]`.
pub fn trace_list_entry(p: &SsrParams, gbuf: &[f32], pyr: &[f32], list: &[f32], k: u32, out: &mut [f32], ob: usize) {
    let pixel = load(list, (k as usize) * LIST_STRIDE).to_bits();
    let word = load(list, (k as usize) * LIST_STRIDE + 1).to_bits();
    let smp = word & 0xff;
    let mode = word >> 8;
    let (x, y) = (pixel % p.width, pixel / p.width);
    let s = load_surface(p, gbuf, x, y);
    if !s.valid {
        store_no_ray(out, ob);
        return;
    }
    let (l, pdf) = sample_ray(p, &s, x, y, smp);
    let steps = if mode == TRACE_LINEAR_CROSSING { p.rough_linear_steps } else { p.linear_steps };
    trace_and_store(p, gbuf, pyr, &s, x, y, l, pdf, mode, steps, out, ob);
}

/// Expected rays in a non-mirror pixel's resolve window (its (2r+1)^2 pixels times their rays),
/// the N of the filtered-importance-sampling cone; the same for every pixel of a frame.
#[inline]
pub fn fis_rays_in_window(p: &SsrParams) -> f32 {
    let radius = if p.flags & FLAG_REUSE == 0 { 0 } else { p.resolve_radius };
    let window = (2 * radius + 1) * (2 * radius + 1);
    maxf(1.0, window as f32 * p.samples_per_pixel as f32 * p.rays_per_quad as f32 * 0.25)
}

/// The colour pyramid mip of filtered importance sampling for a ray hitting pixel centre (hx,
/// hy) seen from pixel centre `origin` (screen units): log2 of the cone footprint's diameter in
/// pixels, 2 |hit - origin| tan_half ([`fis_tan_half`]), clamped below at 0.
#[inline]
pub fn fis_mip(origin: Vec3, hx: f32, hy: f32, tan_half: f32) -> f32 {
    let ddx = hx - origin.x;
    let ddy = hy - origin.y;
    let dist_px = ieee::sqrt(ddx * ddx + ddy * ddy);
    maxf(0.0, log2_approx(2.0 * dist_px * tan_half))
}

/// Filtered importance sampling (Stachowiak 2015, after Krivanek & Colbert 2008): a ray drawn
/// with density `pdf` stands for a cone of solid angle 1 / (pdf N), N = [`fis_rays_in_window`];
/// its half-angle tangent ~ sqrt(omega / pi). Written as (1/pi) / (pdf N): the form
/// (1 / (pdf N)) * (1/pi) rounded differently on lavapipe (1 ULP in 0.2% of pixels; see
/// docs/ssr.md).
#[inline]
pub fn fis_tan_half(pdf: f32, rays_in_window: f32) -> f32 {
    ieee::sqrt(ieee::div(core::f32::consts::FRAC_1_PI, pdf * rays_in_window))
}

#[inline]
/// The BRDF-weighted ratio-estimator resolve of pixel (x, y) (Stachowiak 2015, "ray reuse"):
/// over the rays of the (2r+1)^2 neighbourhood (or only its own with reuse off),
/// sum(L_k w_k) / sum(w_k) with w_k = f(v, l_k) cos / pdf_k = D(h) G2(v, l) / (4 n.v) / pdf_k
/// (F = 1; l_k from this pixel to the neighbour's hit; a missed ray keeps its direction and
/// contributes weight with zero radiance and opacity). Radiance comes from the previous colour
/// pyramid at the reprojected hit, at mip 0 or, with filtered importance sampling, at the mip of
/// the ray's cone footprint. Mirror pixels use their own ray only. Premultiplied by the
/// roughness fade. What depends on the ray alone (hit position, pdf_k at it, reprojection, edge
/// fade, cone) comes from its hit record in `hits` ([`super::hits`]).
#[allow(clippy::too_many_arguments)]
pub fn resolve_pixel(p: &SsrParams, gbuf: &[f32], color: &[f32], rays: &[f32], hits: &[f32], x: u32, y: u32, out: &mut [f32], ob: usize) {
    let s = load_surface(p, gbuf, x, y);
    if !eligible(p, &s) {
        resolve_store(out, ob, Vec3::ZERO, 0.0);
        return;
    }
    let spp = p.samples_per_pixel;
    let mirror = s.perceptual_roughness < MIRROR_ROUGHNESS;
    let alpha = s.perceptual_roughness * s.perceptual_roughness;
    let nv = s.n.dot(s.v);
    let lambda_v = lambda_cos(nv, alpha);
    let radius: i32 = if mirror || p.flags & FLAG_REUSE == 0 { 0 } else { p.resolve_radius as i32 };
    let fis = p.flags & FLAG_FIS != 0 && !mirror;
    let ray_color = p.flags & FLAG_RAY_COLOR != 0;
    let mut acc = Vec3::ZERO;
    let mut acc_a = 0.0;
    let mut acc_w = 0.0;
    let mut dy = -radius;
    while dy <= radius {
        let mut dx = -radius;
        while dx <= radius {
            let qx = x as i32 + dx;
            let qy = y as i32 + dy;
            if qx >= 0 && qy >= 0 && (qx as u32) < p.width && (qy as u32) < p.height {
                let q = qy as u32 * p.width + qx as u32;
                let mut k = 0;
                while k < spp {
                    // Only what this ray's case needs is read: a miss its pdf and direction, a hit
                    // its hit record's position and pdf, then (if it weighs anything) its fade,
                    // cone and colour (`hit_color`: the record's own mip-0 sample where the mip is 0).
                    let slot = (q * spp + k) as usize;
                    let rb = slot * RAY_STRIDE;
                    let hb = slot * HIT_STRIDE;
                    let bits = load(rays, rb + RAY_INFO).to_bits();
                    k += 1;
                    if bits & info::VALID == 0 {
                        continue;
                    }
                    let hit = bits & info::HIT != 0;
                    let (l, pdf) = if hit {
                        let (pos, pdf) = load_hit_pos_pdf(hits, hb);
                        ((pos - s.pos).normalize_or_zero(), pdf)
                    } else {
                        let [pdf, dx, dy, dz] = load4(rays, rb + RAY_PDF);
                        (Vec3::new(dx, dy, dz), pdf)
                    };
                    let w = ray_weight(&s, alpha, nv, lambda_v, mirror, l, pdf);
                    if !(w > 0.0) {
                        continue;
                    }
                    if hit {
                        let c = if ray_color {
                            stored_hit_color(hits, hb)
                        } else {
                            let mut mip = 0.0;
                            if fis {
                                let [hx, hy] = load2(rays, rb);
                                mip = fis_mip(s.origin, hx, hy, load(hits, hb + HIT_TAN_HALF));
                            }
                            hit_color(p, color, hits, hb, mip)
                        };
                        let fade = load(hits, hb + HIT_FADE);
                        acc = acc + c * (fade * w);
                        acc_a += fade * w;
                    }
                    acc_w += w;
                }
            }
            dx += 1;
        }
        dy += 1;
    }
    store_resolved(p, &s, acc, acc_a, acc_w, out, ob);
}

/// The density a ray's hit was drawn with, for the resolve's weights: the generating pixel `sq`'s
/// sampler density ([`reflection_pdf`]) at the direction from `sq` to the hit point `hit` as the
/// resolve reconstructs it (pixel centre at its G-buffer depth), so that for a pixel's own ray
/// f / pdf is evaluated at one direction (G2 / G1, Heitz 2018 eq. 19) instead of D(h) at the
/// reconstructed direction over D(h) at the sampled one. With `FLAG_SAMPLED_PDF` (or for a
/// mirror or invalid `sq`), the pdf stored at sampling time, `stored`.
#[inline]
pub fn ray_pdf_at_hit(p: &SsrParams, sq: &Surface, hit: Vec3, stored: f32) -> f32 {
    if p.flags & FLAG_SAMPLED_PDF != 0 || !sq.valid || sq.perceptual_roughness < MIRROR_ROUGHNESS {
        return stored;
    }
    let lq = (hit - sq.pos).normalize_or_zero();
    let (t, b) = orthonormal_basis(sq.n);
    let wi = Vec3::new(sq.v.dot(t), sq.v.dot(b), sq.v.dot(sq.n));
    let wo = Vec3::new(lq.dot(t), lq.dot(b), lq.dot(sq.n));
    let alpha_q = sq.perceptual_roughness * sq.perceptual_roughness;
    reflection_pdf(p.sampler, wi, wo, alpha_q)
}

/// The BRDF weight of one ray in the resolve of surface `s` (Stachowiak 2015 ratio estimator):
/// f(v, l) cos / pdf = D(h) G2(v, l) / (4 n.v) / pdf with F = 1, 1 for mirror pixels; 0 when the
/// ray cannot contribute (l below the surface, no pdf, non-finite weight). `nv` = n.v and
/// `lambda_v` = Lambda(n.v) of `s`, computed once per pixel by the caller.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn ray_weight(s: &Surface, alpha: f32, nv: f32, lambda_v: f32, mirror: bool, l: Vec3, pdf: f32) -> f32 {
    let nl = s.n.dot(l);
    if !(nl > 0.0) {
        return 0.0;
    }
    if mirror {
        return 1.0;
    }
    if !(pdf > 0.0) {
        return 0.0;
    }
    let h = (s.v + l).normalize_or_zero();
    let g2 = crate::masking::g2_height_correlated_from_lambda(lambda_v, lambda_cos(nl, alpha));
    let w = ieee::div(ieee::div(ggx_d_cos(s.n.dot(h), alpha) * g2, 4.0 * nv), pdf);
    if w > 0.0 && w < f32::INFINITY {
        w
    } else {
        0.0
    }
}

/// Reflection hit distance of pixel (x, y): the [`ray_weight`]-weighted mean of |hit - pos| over
/// the pixel's own hitting rays (the neighbours' rays may see other objects at other distances,
/// which measurably blurred moving reflections), with each ray's hit position and pdf read from
/// its hit record (`super::hits`); 0 when none hits or the pixel traced no ray.
pub fn reflection_hit_distance(p: &SsrParams, rays: &[f32], hits: &[f32], s: &Surface, x: u32, y: u32) -> f32 {
    let spp = p.samples_per_pixel;
    let mirror = s.perceptual_roughness < MIRROR_ROUGHNESS;
    let alpha = s.perceptual_roughness * s.perceptual_roughness;
    let nv = s.n.dot(s.v);
    let lambda_v = lambda_cos(nv, alpha);
    let q = y * p.width + x;
    let mut acc_d = 0.0;
    let mut acc_w = 0.0;
    let mut k = 0;
    while k < spp {
        let slot = (q * spp + k) as usize;
        let bits = load(rays, slot * RAY_STRIDE + RAY_INFO).to_bits();
        k += 1;
        if bits & info::VALID != 0 && bits & info::HIT != 0 {
            let (pos, pdf) = load_hit_pos_pdf(hits, slot * HIT_STRIDE);
            let d = pos - s.pos;
            let len = ieee::sqrt(d.dot(d));
            let l = if len > 0.0 { d / len } else { Vec3::ZERO };
            let w = ray_weight(s, alpha, nv, lambda_v, mirror, l, pdf);
            acc_d += w * len;
            acc_w += w;
        }
    }
    if acc_w > 0.0 {
        ieee::div(acc_d, acc_w)
    } else {
        0.0
    }
}

/// The hit-distance pass for pixel (x, y): [`reflection_hit_distance`] for valid surfaces, else 0.
pub fn hit_distance_pixel(p: &SsrParams, gbuf: &[f32], rays: &[f32], hits: &[f32], x: u32, y: u32) -> f32 {
    let s = load_surface(p, gbuf, x, y);
    if s.valid {
        reflection_hit_distance(p, rays, hits, &s, x, y)
    } else {
        0.0
    }
}

/// Previous-frame UV of the reflection seen at surface `s` whose reflected rays travel `dist`:
/// the virtual image of the hit, `dist` beyond the surface along the eye ray (a planar mirror's
/// image; Stachowiak 2015 temporal reprojection, "reflection motion vectors"), through the
/// previous camera.
#[inline]
pub fn virtual_image_uv(p: &SsrParams, s: &Surface, dist: f32) -> (f32, f32) {
    let len = ieee::sqrt(s.pos.dot(s.pos));
    let virt = s.pos + s.pos * (ieee::div(dist, len));
    let world = p.inv_view.transform_point(virt);
    // World to the previous view through the rigid inverse of prev_inv_view = [R | t]:
    // R^T (world - t) (the columns of R dotted with world - t).
    let m = &p.prev_inv_view;
    let d = Vec3::new(world.x - m.r0.w, world.y - m.r1.w, world.z - m.r2.w);
    let vp = Vec3::new(
        m.r0.x * d.x + m.r1.x * d.y + m.r2.x * d.z,
        m.r0.y * d.x + m.r1.y * d.y + m.r2.y * d.z,
        m.r0.z * d.x + m.r1.z * d.y + m.r2.z * d.z,
    );
    let c = p.prev_proj.transform_point4(vp);
    if c.w > 0.0 {
        (ieee::div(c.x, c.w) * 0.5 + 0.5, 0.5 - ieee::div(c.y, c.w) * 0.5)
    } else {
        (-1.0, -1.0)
    }
}

/// [`history_texel`]'s answer when there is no usable history.
pub const NO_HISTORY: u32 = u32::MAX;

/// History texel of previous-frame UV (u, v) if it holds history that describes the same
/// surface: on screen, accumulated (n >= 1) and, with rejection on, the previous frame's surface
/// there lies on the current pixel's tangent plane (|n.(P_prev - P)| <= history_depth_tolerance *
/// depth, world space) with a normal within history_normal_cos and a perceptual roughness within
/// history_roughness_tolerance of `rough`; otherwise [`NO_HISTORY`]. Written without early
/// returns (every test evaluated, the texel index clamped), since llvmpipe nests the code after
/// each return (see `crate::buffer`).
#[allow(clippy::too_many_arguments)]
pub fn history_texel(p: &SsrParams, prev_gbuf: &[f32], history: &[f32], n_world: Vec3, p_world: Vec3, depth: f32, rough: f32, u: f32, v: f32) -> u32 {
    let on_screen = u >= 0.0 && u < 1.0 && v >= 0.0 && v < 1.0;
    let hx = super::trace::floor_index(u * p.width as f32, p.width - 1);
    let hy = super::trace::floor_index(v * p.height as f32, p.height - 1);
    let t = hy * p.width + hx;
    let accumulated = load(history, (t as usize) * HISTORY_STRIDE + 4) >= 1.0;
    let gb = (t as usize) * super::trace::GBUF_STRIDE;
    let zp = load(prev_gbuf, gb);
    let np = Vec3::new(load(prev_gbuf, gb + gbuf::NORMAL), load(prev_gbuf, gb + gbuf::NORMAL + 1), load(prev_gbuf, gb + gbuf::NORMAL + 2));
    let rp = load(prev_gbuf, gb + gbuf::ROUGHNESS);
    let rough_ok = !(p.history_roughness_tolerance >= 0.0) || (rp - rough).abs() <= p.history_roughness_tolerance;
    let normal_ok = !(p.history_normal_cos > -1.0) || np.dot(n_world) >= p.history_normal_cos;
    let zp_ok = zp > 0.0 && zp < f32::INFINITY;
    let z = if zp_ok { zp } else { 1.0 };
    let ndc_x = ieee::div(hx as f32 + 0.5, p.width as f32) * 2.0 - 1.0;
    let ndc_y = 1.0 - ieee::div(hy as f32 + 0.5, p.height as f32) * 2.0;
    let vp = Vec3::new(ieee::div((ndc_x - p.prev_proj.r0.z) * z, p.prev_proj.r0.x), ieee::div((ndc_y - p.prev_proj.r1.z) * z, p.prev_proj.r1.y), z);
    let wp = p.prev_inv_view.transform_point(vp);
    let plane = n_world.dot(wp - p_world);
    let depth_ok = !(p.history_depth_tolerance > 0.0) || (zp_ok && plane.abs() <= p.history_depth_tolerance * depth);
    if on_screen && accumulated && rough_ok && normal_ok && depth_ok {
        t
    } else {
        NO_HISTORY
    }
}

/// Temporal accumulation of pixel (x, y): the history is fetched (nearest texel) at the
/// reflection's previous position - with `REPROJECT_HIT`, the virtual image of the reflected hit
/// ([`virtual_image_uv`], hit distance `hit_distance[pixel]` from [`hit_distance_pixel`]) and, if that texel is
/// rejected or the pixel's rays missed, the surface's (UV minus its motion vector); with
/// `REPROJECT_SURFACE` only the latter. A texel is used if [`history_texel`] accepts it (depth /
/// normal / roughness disocclusion test). The history is clamped to the min/max box of the current
/// resolve's 3x3 neighbourhood and blended with weight max(1 / (n + 1), temporal_alpha); without
/// usable history (or on sky) the pixel restarts at the current value.
#[allow(clippy::too_many_arguments)]
pub fn temporal_pixel(
    p: &SsrParams,
    gbuf: &[f32],
    prev_gbuf: &[f32],
    hit_distance: &[f32],
    current: &[f32],
    history: &[f32],
    x: u32,
    y: u32,
    out: &mut [f32],
    ob: usize,
) {
    let i = (y * p.width + x) as usize;
    let cb = i * OUT_STRIDE;
    let cur = Vec3::new(load(current, cb), load(current, cb + 1), load(current, cb + 2));
    let cur_a = load(current, cb + 3);
    let gi = i * super::trace::GBUF_STRIDE;
    let s = load_surface(p, gbuf, x, y);
    let z = load(gbuf, gi);
    let geometry = z > 0.0 && z < f32::INFINITY;
    let n_world = Vec3::new(load(gbuf, gi + gbuf::NORMAL), load(gbuf, gi + gbuf::NORMAL + 1), load(gbuf, gi + gbuf::NORMAL + 2));
    let p_world = p.inv_view.transform_point(s.pos);
    // Both candidates are evaluated unconditionally and selected afterwards (straight-line code).
    // The hit distance comes from its own pass ([`hit_distance_pixel`]), which keeps this
    // kernel's control-flow nesting low on llvmpipe (see `crate::buffer`); buffer accesses here go
    // through `load` / `store` for the same reason.
    let dist = if p.temporal_reprojection == REPROJECT_HIT { load(hit_distance, i) } else { 0.0 };
    let (hu, hv) = virtual_image_uv(p, &s, dist);
    let th = history_texel(p, prev_gbuf, history, n_world, p_world, s.pos.z, s.perceptual_roughness, hu, hv);
    let pu = ieee::div(x as f32 + 0.5, p.width as f32) - load(gbuf, gi + 6);
    let pv = ieee::div(y as f32 + 0.5, p.height as f32) - load(gbuf, gi + 7);
    let ts = history_texel(p, prev_gbuf, history, n_world, p_world, s.pos.z, s.perceptual_roughness, pu, pv);
    let use_hit = p.temporal_reprojection == REPROJECT_HIT && s.valid && dist > 0.0 && th != NO_HISTORY;
    let found = geometry && (use_hit || ts != NO_HISTORY);
    let t = if use_hit { th } else { ts };
    if !found {
        store(out, ob, cur.x);
        store(out, ob + 1, cur.y);
        store(out, ob + 2, cur.z);
        store(out, ob + 3, cur_a);
        store(out, ob + 4, 1.0);
        return;
    }
    let hb = (t as usize) * HISTORY_STRIDE;
    let n = load(history, hb + 4);
    // Neighbourhood box of the current frame.
    let mut lo = cur;
    let mut hi = cur;
    let mut lo_a = cur_a;
    let mut hi_a = cur_a;
    let mut dy: i32 = -1;
    while dy <= 1 {
        let mut dx: i32 = -1;
        while dx <= 1 {
            let qx = x as i32 + dx;
            let qy = y as i32 + dy;
            if qx >= 0 && qy >= 0 && (qx as u32) < p.width && (qy as u32) < p.height {
                let b = ((qy as u32 * p.width + qx as u32) as usize) * OUT_STRIDE;
                let c = Vec3::new(load(current, b), load(current, b + 1), load(current, b + 2));
                lo = Vec3::new(minf(lo.x, c.x), minf(lo.y, c.y), minf(lo.z, c.z));
                hi = Vec3::new(maxf(hi.x, c.x), maxf(hi.y, c.y), maxf(hi.z, c.z));
                lo_a = minf(lo_a, load(current, b + 3));
                hi_a = maxf(hi_a, load(current, b + 3));
            }
            dx += 1;
        }
        dy += 1;
    }
    let h = Vec3::new(
        clampf(load(history, hb), lo.x, hi.x),
        clampf(load(history, hb + 1), lo.y, hi.y),
        clampf(load(history, hb + 2), lo.z, hi.z),
    );
    let ha = clampf(load(history, hb + 3), lo_a, hi_a);
    let n1 = n + 1.0;
    let w = maxf(ieee::div(1.0, n1), p.temporal_alpha);
    store(out, ob, h.x + (cur.x - h.x) * w);
    store(out, ob + 1, h.y + (cur.y - h.y) * w);
    store(out, ob + 2, h.z + (cur.z - h.z) * w);
    store(out, ob + 3, ha + (cur_a - ha) * w);
    store(out, ob + 4, minf(n1, 1024.0));
}
