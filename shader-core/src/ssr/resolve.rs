//! Turning ray hits into reflected radiance: HDRP's fades, colour-pyramid sampling, the
//! `SSR_APPROX` reprojection and the neighbourhood resolves weighted by `GetSSRSampleWeight`.
//!
//! Output texels are premultiplied: (rgb * opacity, opacity); a consumer composites
//! `rgb + (1 - opacity) * fallback` (a reflection probe or the sky).
//!
//! ```
//! use shader_core::ssr::resolve::{remap10, smoothstep01};
//! // HDRP's Remap10: 1 before the fade starts, 0 past its end, linear between.
//! // A fade from 0.6 to 0.8: rcp_length = 1 / 0.2 = 5, end * rcp_length = 4.
//! assert_eq!(remap10(0.5, 5.0, 4.0), 1.0);
//! assert_eq!(remap10(0.7, 5.0, 4.0), 4.0 - 0.7 * 5.0);
//! assert_eq!(remap10(0.9, 5.0, 4.0), 0.0);
//! assert_eq!((smoothstep01(0.0), smoothstep01(0.5), smoothstep01(1.0)), (0.0, 0.5, 1.0));
//! ```

use crate::ieee;
use super::params::{mip_block_texels, mip_children, mip_size, MipBlock, SsrParams, FLAG_FIS, FLAG_RAY_COLOR};
use super::compare::clampf;
use super::layout::{gbuf, info, Surface, GBUF_STRIDE, RAY_INFO, RAY_PDF, RAY_STRIDE};
pub use super::layout::{COLOR_STRIDE, HIT_COLOR, HIT_FADE, HIT_PDF, HIT_STRIDE, HIT_TAN_HALF, HIT_UV, OUT_STRIDE};
use super::trace::{load_surface, view_position};
use crate::buffer::{load, load2, load3, load4, load8};
use crate::masking;
use crate::vector::Vec3;
use spirv_std::num_traits::Float;

/// HDRP `Remap10(x, rcpLength, endTimesRcpLength)` = saturate(end*rcp - x*rcp): 1 below the fade
/// start, 0 past its end.
#[inline]
pub fn remap10(x: f32, rcp_length: f32, end_times_rcp_length: f32) -> f32 {
    clampf(end_times_rcp_length - x * rcp_length, 0.0, 1.0)
}

/// `Smoothstep01(x) = x x (3 - 2 x)` (x in [0, 1]).
#[inline]
pub fn smoothstep01(x: f32) -> f32 {
    x * x * (3.0 - 2.0 * x)
}

/// HDRP `PerceptualRoughnessFade` = Smoothstep01(Remap10(r, rcpLength, endTimesRcpLength)).
#[inline]
pub fn perceptual_roughness_fade(r: f32, rcp_length: f32, end_times_rcp_length: f32) -> f32 {
    smoothstep01(remap10(r, rcp_length, end_times_rcp_length))
}

/// HDRP `EdgeOfScreenFade(coordNDC, fadeRcpLength)`: coordinates in [0, 1] mapped to [-1, 1],
/// each axis faded over the last 1/fadeRcpLength of it; 0 outside the screen.
#[inline]
pub fn edge_of_screen_fade(u: f32, v: f32, fade_rcp_length: f32) -> f32 {
    let cx = (u * 2.0 - 1.0).abs();
    let cy = (v * 2.0 - 1.0).abs();
    let tx = remap10(cx, fade_rcp_length, fade_rcp_length);
    let ty = remap10(cy, fade_rcp_length, fade_rcp_length);
    smoothstep01(tx) * smoothstep01(ty)
}

/// Smith GGX Lambda for a direction at cosine `c` to the normal, isotropic roughness alpha
/// (Heitz 2014 eq. 86 through [`masking::ggx_lambda`]).
#[inline]
pub fn lambda_cos(c: f32, alpha: f32) -> f32 {
    let s2 = 1.0 - c * c;
    let s = if s2 > 0.0 { ieee::sqrt(s2) } else { 0.0 };
    masking::ggx_lambda(Vec3::new(s, 0.0, c), alpha, alpha)
}

/// HDRP `GetSSRSampleWeight(V, L, roughness)` = (1 + Lambda(V)) / (1 + Lambda(V) + Lambda(L)):
/// the BRDF value over the VNDF pdf with F = 1 (height-correlated Smith G2 / G1). 0 when L is
/// below the surface (n.l <= 0); `alpha` is the GGX roughness (perceptual squared).
#[inline]
pub fn ssr_sample_weight(n: Vec3, v: Vec3, l: Vec3, alpha: f32) -> f32 {
    ssr_sample_weight_lv(n, l, alpha, lambda_cos(n.dot(v), alpha) + 1.0)
}

/// [`ssr_sample_weight`] with the receiver's `1 + Lambda(V)` computed once by the caller (the
/// same value, so the same bits).
#[inline]
pub fn ssr_sample_weight_lv(n: Vec3, l: Vec3, alpha: f32, lambda_v_plus_one: f32) -> f32 {
    let nl = n.dot(l);
    if !(nl > 0.0) {
        return 0.0;
    }
    let lambda_l = lambda_cos(nl, alpha);
    ieee::div(lambda_v_plus_one, lambda_v_plus_one + lambda_l)
}

/// `a + (b - a) t`.
#[inline]
pub fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

#[inline]
fn lerp3(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    Vec3::new(lerp(a.x, b.x, t), lerp(a.y, b.y, t), lerp(a.z, b.z, t))
}

#[inline]
fn clamp_i(x: i32, hi: u32) -> u32 {
    if x < 0 {
        0
    } else if x as u32 > hi {
        hi
    } else {
        x as u32
    }
}

#[inline]
fn texel(p: &SsrParams, pyr: &[f32], off: u32, w: u32, x: u32, y: u32) -> Vec3 {
    let _ = p;
    let [r, g, b] = load3(pyr, ((off + y * w + x) as usize) * COLOR_STRIDE);
    Vec3::new(r, g, b)
}

/// Bilinear sample of colour pyramid level `level` at (u, v) in [0, 1] (clamped), clamp-to-edge.
pub fn sample_color_level(p: &SsrParams, pyr: &[f32], u: f32, v: f32, level: u32) -> Vec3 {
    sample_color_mip(p, pyr, u, v, super::trace::p_mip_offset(p, level), mip_size(p.width, level), mip_size(p.height, level))
}

/// [`sample_color_level`] of the mip at texel offset `off`, `w` x `h` texels.
#[inline]
fn sample_color_mip(p: &SsrParams, pyr: &[f32], u: f32, v: f32, off: u32, w: u32, h: u32) -> Vec3 {
    let tx = clampf(u, 0.0, 1.0) * w as f32 - 0.5;
    let ty = clampf(v, 0.0, 1.0) * h as f32 - 0.5;
    let fx0 = Float::floor(tx);
    let fy0 = Float::floor(ty);
    let fx = tx - fx0;
    let fy = ty - fy0;
    let ix = fx0 as i32;
    let iy = fy0 as i32;
    let x0 = clamp_i(ix, w - 1);
    let x1 = clamp_i(ix + 1, w - 1);
    let y0 = clamp_i(iy, h - 1);
    let y1 = clamp_i(iy + 1, h - 1);
    let top = lerp3(texel(p, pyr, off, w, x0, y0), texel(p, pyr, off, w, x1, y0), fx);
    let bottom = lerp3(texel(p, pyr, off, w, x0, y1), texel(p, pyr, off, w, x1, y1), fx);
    lerp3(top, bottom, fy)
}

/// Trilinear sample of the colour pyramid at fractional mip `mip` (clamped to [0, color_max_mip]).
pub fn sample_color(p: &SsrParams, pyr: &[f32], u: f32, v: f32, mip: f32) -> Vec3 {
    let m = clampf(mip, 0.0, p.color_max_mip as f32);
    let l0f = Float::floor(m);
    let l0 = l0f as u32;
    let f = m - l0f;
    // Mip l0 + 1 follows mip l0 in the buffer: one offset sum serves both.
    let (off0, w0, h0) = (super::trace::p_mip_offset(p, l0), mip_size(p.width, l0), mip_size(p.height, l0));
    let c0 = sample_color_mip(p, pyr, u, v, off0, w0, h0);
    if f > 0.0 && l0 < p.color_max_mip {
        let c1 = sample_color_mip(p, pyr, u, v, off0 + w0 * h0, mip_size(w0, 1), mip_size(h0, 1));
        lerp3(c0, c1, f)
    } else {
        c0
    }
}

/// One texel of colour mip `level` (>= 1): the box average of the (up to) 2x2 texels of the level
/// below it covers (edge texels repeated for odd sizes, [`mip_children`]), [`color_box`].
pub fn color_downsample_texel(p: &SsrParams, pyr: &[f32], level: u32, x: u32, y: u32) -> Vec3 {
    color_children_box(p, pyr, super::trace::p_mip_offset(p, level - 1), mip_size(p.width, level - 1), mip_size(p.height, level - 1), x, y)
}

/// [`color_downsample_texel`] with the mip below given as its texel offset and size.
#[inline]
fn color_children_box(p: &SsrParams, pyr: &[f32], off: u32, pw: u32, ph: u32, x: u32, y: u32) -> Vec3 {
    let (x0, x1) = mip_children(x, pw);
    let (y0, y1) = mip_children(y, ph);
    let a = texel(p, pyr, off, pw, x0, y0);
    let b = texel(p, pyr, off, pw, x1, y0);
    let c = texel(p, pyr, off, pw, x0, y1);
    let d = texel(p, pyr, off, pw, x1, y1);
    color_box(a, b, c, d)
}

/// The box average of a 2x2 block (texels (x0, y0), (x1, y0), (x0, y1), (x1, y1)), summed as
/// ((a + b) + (c + d)) * 0.25: the one order every colour-pyramid texel uses.
#[inline]
pub fn color_box(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> Vec3 {
    ((a + b) + (c + d)) * 0.25
}

impl MipBlock<Vec3> {
    /// Write the block into the colour pyramid (RGB, [`COLOR_STRIDE`] values per texel).
    #[inline]
    pub fn store(&self, pyr: &mut [f32]) {
        store_rgb(pyr, self.texels[0], self.values[0]);
        store_rgb(pyr, self.texels[1], self.values[1]);
        store_rgb(pyr, self.texels[2], self.values[2]);
        store_rgb(pyr, self.texels[3], self.values[3]);
        if let Some((j, v)) = self.above {
            store_rgb(pyr, j, v);
        }
    }
}

#[inline]
fn store_rgb(pyr: &mut [f32], texel: u32, c: Vec3) {
    let b = (texel as usize) * COLOR_STRIDE;
    crate::buffer::store(pyr, b, c.x);
    crate::buffer::store(pyr, b + 1, c.y);
    crate::buffer::store(pyr, b + 2, c.z);
}

/// A pass of the colour pyramid, invocation `k`: mips `level` and `level + 1` in one step
/// ([`MipBlock`]; the passes are `level` = 1, 3, 5, ...; mip 0 is the frame), each texel
/// [`color_downsample_texel`] of the mip below and the one above their [`color_box`]. Each
/// invocation reads only the mip below, so the invocations of a pass are independent.
pub fn color_block(p: &SsrParams, pyr: &[f32], level: u32, k: u32) -> MipBlock<Vec3> {
    let w = mip_size(p.width, level);
    let h = mip_size(p.height, level);
    let base = super::trace::p_mip_offset(p, level);
    let (texels, xy) = mip_block_texels(w, h, base, k);
    let (below, pw, ph) = (super::trace::p_mip_offset(p, level - 1), mip_size(p.width, level - 1), mip_size(p.height, level - 1));
    let values = [
        color_children_box(p, pyr, below, pw, ph, xy[0].0, xy[0].1),
        color_children_box(p, pyr, below, pw, ph, xy[1].0, xy[1].1),
        color_children_box(p, pyr, below, pw, ph, xy[2].0, xy[2].1),
        color_children_box(p, pyr, below, pw, ph, xy[3].0, xy[3].1),
    ];
    let above = if level + 1 < p.mip_count { Some((base + w * h + k, color_box(values[0], values[1], values[2], values[3]))) } else { None };
    MipBlock { texels, values, above }
}

/// A decoded ray record.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayRecord {
    /// A ray was traced for this record ([`super::trace::info::VALID`]).
    pub valid: bool,
    /// The ray hit a surface ([`super::trace::info::HIT`]).
    pub hit: bool,
    /// Hit pixel centre (screen units).
    pub hx: f32,
    /// Hit pixel centre, y (screen units, row 0 at the top).
    pub hy: f32,
    /// Solid-angle density the ray was sampled with (0 for mirror rays).
    pub pdf: f32,
    /// Ray direction (view space, unit).
    pub dir: Vec3,
}

/// Whether the ray record at `rays[b..]` is a valid ray that hit, and its hit pixel centre (x,
/// y): the first four words of [`load_ray`], all `SSR_APPROX` reads.
#[inline]
pub fn load_ray_hit(rays: &[f32], b: usize) -> (bool, f32, f32) {
    let [hx, hy, _, info_bits] = load4(rays, b);
    let bits = info_bits.to_bits();
    (bits & info::VALID != 0 && bits & info::HIT != 0, hx, hy)
}

/// Decode the ray record at `rays[b..]` (all zeros, an invalid ray, if it lies past the end).
#[inline]
pub fn load_ray(rays: &[f32], b: usize) -> RayRecord {
    let [hx, hy, _, info_bits, pdf, dx, dy, dz] = load8(rays, b);
    let bits = info_bits.to_bits();
    RayRecord { valid: bits & info::VALID != 0, hit: bits & info::HIT != 0, hx, hy, pdf, dir: Vec3::new(dx, dy, dz) }
}

/// Hit position and pdf of the hit record at `hits[b..]` (the part every resolve weight needs;
/// zeros past the end).
#[inline]
pub fn load_hit_pos_pdf(hits: &[f32], b: usize) -> (Vec3, f32) {
    let [x, y, z, pdf] = load4(hits, b);
    (Vec3::new(x, y, z), pdf)
}

/// Does the hits pass store each ray's colour ([`HIT_COLOR`])? When the frame's resolves gather
/// at mip 0 only (HDRP's resolves; the stochastic one without filtered importance sampling; the
/// ray's mip-0 colour, which replaces 12 texel values per (pixel, ray) pair by 3 per pair and 12
/// per ray), and with [`FLAG_RAY_COLOR`] (the colour at the ray's own footprint,
/// `super::stochastic::fis_mip`). With filtered importance sampling at each resolving pixel's
/// footprint most rays of a 1080p frame gather above mip 0 and a record's mip-0 colour would cost
/// the hits pass more than it saves: the slots stay zero.
#[inline]
pub fn hit_colors_stored(p: &SsrParams) -> bool {
    p.flags & FLAG_FIS == 0 || p.flags & FLAG_RAY_COLOR != 0
}

/// Does a resolve read a hit record's previous-frame UV ([`HIT_UV`]) and cone ([`HIT_TAN_HALF`])?
/// Only the stochastic resolve with filtered importance sampling at each resolving pixel's
/// footprint (without [`FLAG_RAY_COLOR`]) samples the colour pyramid per (pixel, ray) pair; every
/// other resolve takes the colour the hits pass stored ([`hit_colors_stored`]), so the hits pass
/// leaves these three words zero.
#[inline]
pub fn hit_footprints_stored(p: &SsrParams) -> bool {
    p.flags & FLAG_FIS != 0 && p.flags & FLAG_RAY_COLOR == 0
}

/// The colour stored in the hit record at `hits[hb..]` ([`HIT_COLOR`]).
#[inline]
pub fn stored_hit_color(hits: &[f32], hb: usize) -> Vec3 {
    let [r, g, b] = load3(hits, hb + HIT_COLOR);
    Vec3::new(r, g, b)
}

/// The colour a resolve gathers for the hitting ray whose record is at `hits[hb..]`, at colour
/// mip `mip`: [`sample_color`] at the record's (u, v). Where the mip clamps to 0 and the record
/// holds its mip-0 sample ([`hit_colors_stored`] without [`FLAG_RAY_COLOR`]; the hits pass
/// computed it with the same function), that sample, read as 3 values instead of 12 texel values.
#[inline]
pub fn hit_color(p: &SsrParams, color: &[f32], hits: &[f32], hb: usize, mip: f32) -> Vec3 {
    if p.flags & FLAG_FIS == 0 && clampf(mip, 0.0, p.color_max_mip as f32) == 0.0 {
        stored_hit_color(hits, hb)
    } else {
        let [u, v] = load2(hits, hb + HIT_UV);
        sample_color(p, color, u, v, mip)
    }
}

/// The hit pixel's previous-frame UV (its UV minus the motion vector stored at the hit pixel).
#[inline]
pub fn reproject_hit(p: &SsrParams, gbuf: &[f32], hx: f32, hy: f32) -> (f32, f32) {
    let x = hx as u32;
    let y = hy as u32;
    let b = ((y * p.width + x) as usize) * GBUF_STRIDE;
    let u = ieee::div(hx, p.width as f32) - load(gbuf, b + gbuf::MOTION);
    let v = ieee::div(hy, p.height as f32) - load(gbuf, b + gbuf::MOTION + 1);
    (u, v)
}

/// View-space position of a hit pixel (its centre at the G-buffer's linear depth).
#[inline]
pub fn hit_position(p: &SsrParams, gbuf: &[f32], hx: f32, hy: f32) -> Vec3 {
    let x = hx as u32;
    let y = hy as u32;
    let z = load(gbuf, ((y * p.width + x) as usize) * GBUF_STRIDE);
    view_position(p, hx, hy, z)
}

#[inline]
pub(crate) fn store(out: &mut [f32], ob: usize, c: Vec3, a: f32) {
    crate::buffer::store(out, ob, c.x);
    crate::buffer::store(out, ob + 1, c.y);
    crate::buffer::store(out, ob + 2, c.z);
    crate::buffer::store(out, ob + 3, a);
}

/// A weighted neighbourhood resolve's output: (sum of weighted colour, of weighted opacity) over
/// the sum of weights, premultiplied by the perceptual-roughness fade of surface `s`; zero when
/// no weight was gathered.
#[inline]
pub(crate) fn store_resolved(p: &SsrParams, s: &Surface, acc: Vec3, acc_a: f32, acc_w: f32, out: &mut [f32], ob: usize) {
    if !(acc_w > 0.0) {
        store(out, ob, Vec3::ZERO, 0.0);
        return;
    }
    let fade = perceptual_roughness_fade(s.perceptual_roughness, p.roughness_fade_rcp_length, p.roughness_fade_end_times_rcp_length);
    let k = ieee::div(fade, acc_w);
    store(out, ob, acc * k, acc_a * k);
}

/// HDRP reprojection with `SSR_APPROX`: the hit is reprojected through the motion vectors, the
/// previous frame's colour pyramid is sampled at mip lerp(0, maxMip, perceptualRoughness), and
/// the result is premultiplied by opacity = EdgeOfScreenFade(prevUV) * PerceptualRoughnessFade.
#[allow(clippy::too_many_arguments)]
pub fn hdrp_reproject_approx(
    p: &SsrParams,
    gbuf: &[f32],
    color: &[f32],
    rays: &[f32],
    x: u32,
    y: u32,
    out: &mut [f32],
    ob: usize,
) {
    let i = (y * p.width + x) as usize;
    let (hit, hx, hy) = load_ray_hit(rays, i * RAY_STRIDE);
    if !hit {
        store(out, ob, Vec3::ZERO, 0.0);
        return;
    }
    let rough = load(gbuf, i * GBUF_STRIDE + gbuf::ROUGHNESS);
    let (u, v) = reproject_hit(p, gbuf, hx, hy);
    let opacity = edge_of_screen_fade(u, v, p.edge_fade_rcp_length)
        * perceptual_roughness_fade(rough, p.roughness_fade_rcp_length, p.roughness_fade_end_times_rcp_length);
    let mip = lerp(0.0, p.color_max_mip as f32, rough);
    let c = sample_color(p, color, u, v, mip);
    store(out, ob, c * opacity, opacity);
}

/// Neighbourhood shape of [`hdrp_resolve_neighborhood`]: the 3x3 block around the pixel.
pub const NEIGHBORHOOD_3X3: u32 = 0;
/// Neighbourhood shape: the pixel and its four edge neighbours.
pub const NEIGHBORHOOD_CROSS5: u32 = 1;

/// Accumulate one neighbour's ray into the ratio sums for surface `s` (`lambda_v_plus_one` =
/// 1 + Lambda(V) of `s`); a hitting ray's position, reprojection and fade come from its hit record.
#[inline]
#[allow(clippy::too_many_arguments)]
fn accumulate_neighbor(
    p: &SsrParams,
    color: &[f32],
    rays: &[f32],
    hits: &[f32],
    s: &Surface,
    alpha: f32,
    lambda_v_plus_one: f32,
    q: usize,
    acc: &mut Vec3,
    acc_a: &mut f32,
    acc_w: &mut f32,
) {
    let rb = q * RAY_STRIDE;
    let bits = load(rays, rb + RAY_INFO).to_bits();
    if bits & info::VALID == 0 {
        return;
    }
    let hit = bits & info::HIT != 0;
    let hb = q * HIT_STRIDE;
    let l = if hit {
        (load_hit_pos_pdf(hits, hb).0 - s.pos).normalize_or_zero()
    } else {
        let [dx, dy, dz] = load3(rays, rb + RAY_PDF + 1);
        Vec3::new(dx, dy, dz)
    };
    let w = ssr_sample_weight_lv(s.n, l, alpha, lambda_v_plus_one);
    if !(w > 0.0) {
        return;
    }
    if hit {
        let c = hit_color(p, color, hits, hb, 0.0);
        let fade = load(hits, hb + HIT_FADE);
        *acc = *acc + c * (fade * w);
        *acc_a += fade * w;
    }
    *acc_w += w;
}

/// HDRP's non-approximate reprojection: the rays of a neighbourhood of the pixel (3x3 block, or
/// the 5-tap cross: centre and its 4 edge neighbours) weighted by `GetSSRSampleWeight(V, L, alpha)`
/// with L from this pixel to each neighbour's hit (a missed ray keeps its own direction and
/// contributes weight with zero colour and opacity); colour at mip 0 times the hit's edge fade;
/// the weighted average times this pixel's roughness fade. `hits` holds the rays' hit records
/// ([`HIT_STRIDE`], from [`super::hits`]).
#[allow(clippy::too_many_arguments)]
pub fn hdrp_resolve_neighborhood(
    p: &SsrParams,
    gbuf: &[f32],
    color: &[f32],
    rays: &[f32],
    hits: &[f32],
    shape: u32,
    x: u32,
    y: u32,
    out: &mut [f32],
    ob: usize,
) {
    let s = load_surface(p, gbuf, x, y);
    if !s.valid {
        store(out, ob, Vec3::ZERO, 0.0);
        return;
    }
    let alpha = s.perceptual_roughness * s.perceptual_roughness;
    let lambda_v_plus_one = lambda_cos(s.n.dot(s.v), alpha) + 1.0;
    let mut acc = Vec3::ZERO;
    let mut acc_a = 0.0;
    let mut acc_w = 0.0;
    let mut dy: i32 = -1;
    while dy <= 1 {
        let mut dx: i32 = -1;
        while dx <= 1 {
            let in_shape = shape == NEIGHBORHOOD_3X3 || dx == 0 || dy == 0;
            let qx = x as i32 + dx;
            let qy = y as i32 + dy;
            if in_shape && qx >= 0 && qy >= 0 && (qx as u32) < p.width && (qy as u32) < p.height {
                let q = (qy as u32 * p.width + qx as u32) as usize;
                accumulate_neighbor(p, color, rays, hits, &s, alpha, lambda_v_plus_one, q, &mut acc, &mut acc_a, &mut acc_w);
            }
            dx += 1;
        }
        dy += 1;
    }
    store_resolved(p, &s, acc, acc_a, acc_w, out, ob);
}

/// log2(x) for x > 0 by the float's exponent plus its mantissa read linearly (exact operations
/// only; at most 0.086 below the true log2; powers of two exact). 0 for x <= 0 or NaN.
#[inline]
pub fn log2_approx(x: f32) -> f32 {
    if !(x > 0.0) {
        return 0.0;
    }
    if x == f32::INFINITY {
        return 128.0;
    }
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32 - 127;
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    e as f32 + (m - 1.0)
}

