//! Stochastic screen-space reflections (Stachowiak 2015, "Stochastic Screen-Space Reflections",
//! SIGGRAPH Advances): 8x8 tile classification, a compacted ray list (deterministic prefix sum),
//! sparse GGX-VNDF rays (1, 2 or 4 per 2x2 quad; Hi-Z for smooth, linear march for rough), the
//! BRDF-weighted ratio-estimator resolve over a neighbourhood, filtered importance sampling from
//! the colour pyramid, and temporal accumulation with history clamping.

use super::params::{SsrParams, FLAG_FIS, FLAG_REUSE, TRACE_HIZ, TRACE_LINEAR_CROSSING};
use super::resolve::{
    edge_of_screen_fade, hit_position, lambda_cos, load_ray, log2_approx, perceptual_roughness_fade, reproject_hit,
    sample_color, OUT_STRIDE,
};
use super::trace::{clampf, load_surface, maxf, minf, reflect, trace_and_store, store_no_ray, Surface, RAY_STRIDE};
use crate::ndf;
use crate::rng;
use crate::vector::Vec3;
use spirv_std::num_traits::Float;

/// Tile edge in pixels.
pub const TILE: u32 = 8;
/// Tile classes.
pub const TILE_SKIP: u32 = 0;
pub const TILE_HIZ: u32 = 1;
pub const TILE_LINEAR: u32 = 2;
pub const TILE_MIXED: u32 = 3;
/// Floats per tile record: class, rays, eligible pixels (bits), unused.
pub const TILE_STRIDE: usize = 4;
/// Words per ray-list entry: pixel index, sample | (trace mode << 8).
pub const LIST_STRIDE: usize = 2;
/// Floats per history texel: r, g, b (premultiplied), opacity, accumulated frame count.
pub const HISTORY_STRIDE: usize = 5;
/// Perceptual roughness below which a pixel is a mirror: one deterministic ray, traced at every
/// pixel (never reused across pixels: its lobe is a Dirac).
pub const MIRROR_ROUGHNESS: f32 = 0.03;

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

/// Classify tile (tx, ty): (class, rays to trace, eligible pixels). A tile with no eligible
/// pixel (sky, too rough, faded out, back-facing) is skipped.
pub fn classify_tile(p: &SsrParams, gbuf: &[f32], tx: u32, ty: u32) -> (u32, u32, u32) {
    let mut rays = 0;
    let mut eligible_px = 0;
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
    (class, rays, eligible_px)
}

/// Exclusive prefix sum of the tiles' ray counts, in tile order (one invocation; identical on
/// both backends): `offsets[t]` for each of `n` tiles and the total at `offsets[n]`.
pub fn prefix_sum_tiles(tiles: &[f32], n: u32, offsets: &mut [f32]) {
    let mut sum: u32 = 0;
    let mut t: u32 = 0;
    while t < n {
        offsets[t as usize] = f32::from_bits(sum);
        sum += tiles[(t as usize) * TILE_STRIDE + 1].to_bits();
        t += 1;
    }
    offsets[n as usize] = f32::from_bits(sum);
}

/// Write tile (tx, ty)'s rays into the list from its offset: pixels in row order within the
/// tile, samples in order.
pub fn emit_tile_rays(p: &SsrParams, gbuf: &[f32], offsets: &[f32], tx: u32, ty: u32, list: &mut [f32]) {
    let tiles_x = (p.width + TILE - 1) / TILE;
    let mut k = offsets[(ty * tiles_x + tx) as usize].to_bits();
    let mut j = 0;
    while j < TILE {
        let y = ty * TILE + j;
        let mut i = 0;
        while i < TILE {
            let x = tx * TILE + i;
            if x < p.width && y < p.height {
                let s = load_surface(p, gbuf, x, y);
                if eligible(p, &s) && traces(p, x, y, s.perceptual_roughness) {
                    let mode = trace_mode_for(p, s.perceptual_roughness);
                    let mut smp = 0;
                    while smp < p.samples_per_pixel {
                        list[(k as usize) * LIST_STRIDE] = f32::from_bits(y * p.width + x);
                        list[(k as usize) * LIST_STRIDE + 1] = f32::from_bits(smp | (mode << 8));
                        k += 1;
                        smp += 1;
                    }
                }
            }
            i += 1;
        }
        j += 1;
    }
}

/// An orthonormal tangent frame (t, b) around unit n (Duff et al. 2017, "Building an Orthonormal
/// Basis, Revisited", listing 3), with the sign chosen by comparison.
#[inline]
pub fn tangent_frame(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bb = Vec3::new(b, s + n.y * n.y * a, -n.y);
    (t, bb)
}

/// A uniform point of the unit disk by rejection from the square (integer PCG stream; no
/// transcendentals, so both backends draw the same point). At most 16 tries, then the centre.
#[inline]
pub fn disk_point(rng: &mut rng::Pcg32) -> (f32, f32) {
    let mut k = 0;
    while k < 16 {
        let x = rng.next_f32() * 2.0 - 1.0;
        let y = rng.next_f32() * 2.0 - 1.0;
        if x * x + y * y < 1.0 {
            return (x, y);
        }
        k += 1;
    }
    (0.0, 0.0)
}

/// GGX VNDF sample (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", listing 1)
/// for isotropic `alpha` in the local frame (v.z > 0), from a uniform disk point (d1, d2) (the
/// polar map of listing 1 replaced by a disk point; same distribution). Returns the normal.
pub fn sample_vndf_disk(v: Vec3, alpha: f32, d1: f32, d2: f32) -> Vec3 {
    let vh = Vec3::new(alpha * v.x, alpha * v.y, v.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / Float::sqrt(lensq) } else { Vec3::new(1.0, 0.0, 0.0) };
    let t2 = vh.cross(t1);
    let s = 0.5 * (1.0 + vh.z);
    let h = 1.0 - d1 * d1;
    let h = if h > 0.0 { Float::sqrt(h) } else { 0.0 };
    let p2 = (1.0 - s) * h + s * d2;
    let pz2 = 1.0 - d1 * d1 - p2 * p2;
    let pz = if pz2 > 0.0 { Float::sqrt(pz2) } else { 0.0 };
    let nh = t1 * d1 + t2 * p2 + vh * pz;
    let nz = if nh.z > 0.0 { nh.z } else { 0.0 };
    Vec3::new(alpha * nh.x, alpha * nh.y, nz).normalize()
}

/// GGX D for a half vector at cosine `c` to the normal (isotropic; Heitz 2014 eq. 85 through
/// [`ndf::ggx_d`]).
#[inline]
pub fn ggx_d_cos(c: f32, alpha: f32) -> f32 {
    let s2 = 1.0 - c * c;
    let s = if s2 > 0.0 { Float::sqrt(s2) } else { 0.0 };
    ndf::ggx_d(Vec3::new(s, 0.0, c), alpha, alpha)
}

/// Solid-angle pdf of the reflected direction of a VNDF-sampled normal: G1(v) D(h) / (4 n.v)
/// (Heitz 2018 eq. 2 times the reflection Jacobian 1 / (4 v.h)).
#[inline]
pub fn vndf_reflection_pdf(nv: f32, nh: f32, alpha: f32) -> f32 {
    let g1 = 1.0 / (1.0 + lambda_cos(nv, alpha));
    g1 * ggx_d_cos(nh, alpha) / (4.0 * nv)
}

/// The ray of sample `smp` of pixel (x, y): mirror for mirror pixels (pdf 0 marks a Dirac),
/// otherwise a VNDF sample with its radial coordinate truncated by `sample_bias` (Stachowiak's
/// importance-sampling bias: u1 in [0, 1 - bias]); directions below the surface are resampled
/// (up to 4 tries). Returns (direction, pdf).
pub fn sample_ray(p: &SsrParams, s: &Surface, x: u32, y: u32, smp: u32) -> (Vec3, f32) {
    if s.perceptual_roughness < MIRROR_ROUGHNESS {
        return (reflect(s.v, s.n), 0.0);
    }
    let alpha = s.perceptual_roughness * s.perceptual_roughness;
    let seed = rng::pcg_hash((y * p.width + x) ^ rng::pcg_hash(p.frame * 16 + smp));
    let mut r = rng::Pcg32::new(seed, smp);
    let (t, b) = tangent_frame(s.n);
    let vl = Vec3::new(s.v.dot(t), s.v.dot(b), s.v.dot(s.n));
    let shrink = Float::sqrt(1.0 - clampf(p.sample_bias, 0.0, 0.999));
    let mut tries = 0;
    let mut l = reflect(s.v, s.n);
    let mut pdf = 0.0;
    while tries < 4 {
        let (d1, d2) = disk_point(&mut r);
        let m = sample_vndf_disk(vl, alpha, d1 * shrink, d2 * shrink);
        let mw = t * m.x + b * m.y + s.n * m.z;
        let cand = reflect(s.v, mw);
        if cand.dot(s.n) > 0.0 {
            l = cand;
            pdf = vndf_reflection_pdf(vl.z, m.z, alpha);
            break;
        }
        tries += 1;
    }
    (l, pdf)
}

/// Trace ray-list entry `k` (pixel, sample, mode) and store its record at
/// `out[ob..ob + RAY_STRIDE]`.
pub fn trace_list_entry(p: &SsrParams, gbuf: &[f32], pyr: &[f32], list: &[f32], k: u32, out: &mut [f32], ob: usize) {
    let pixel = list[(k as usize) * LIST_STRIDE].to_bits();
    let word = list[(k as usize) * LIST_STRIDE + 1].to_bits();
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

#[inline]
fn store4(out: &mut [f32], ob: usize, c: Vec3, a: f32) {
    out[ob] = c.x;
    out[ob + 1] = c.y;
    out[ob + 2] = c.z;
    out[ob + 3] = a;
}

/// The BRDF-weighted ratio-estimator resolve of pixel (x, y) (Stachowiak 2015, "ray reuse"):
/// over the rays of the (2r+1)^2 neighbourhood (or only its own with reuse off),
/// sum(L_k w_k) / sum(w_k) with w_k = f(v, l_k) cos / pdf_k = D(h) G2(v, l) / (4 n.v) / pdf_k
/// (F = 1; l_k from this pixel to the neighbour's hit; a missed ray keeps its direction and
/// contributes weight with zero radiance and opacity). Radiance comes from the previous colour
/// pyramid at the reprojected hit, at mip 0 or, with filtered importance sampling, at the mip of
/// the ray's cone footprint. Mirror pixels use their own ray only. Premultiplied by the
/// roughness fade.
pub fn resolve_pixel(p: &SsrParams, gbuf: &[f32], color: &[f32], rays: &[f32], x: u32, y: u32, out: &mut [f32], ob: usize) {
    let s = load_surface(p, gbuf, x, y);
    if !eligible(p, &s) {
        store4(out, ob, Vec3::ZERO, 0.0);
        return;
    }
    let spp = p.samples_per_pixel;
    let mirror = s.perceptual_roughness < MIRROR_ROUGHNESS;
    let alpha = s.perceptual_roughness * s.perceptual_roughness;
    let nv = s.n.dot(s.v);
    let radius: i32 = if mirror || p.flags & FLAG_REUSE == 0 { 0 } else { p.resolve_radius as i32 };
    let window = (2 * radius + 1) * (2 * radius + 1);
    // Expected rays in the window, for the filtered-importance-sampling cone.
    let rays_in_window = maxf(1.0, window as f32 * spp as f32 * p.rays_per_quad as f32 * 0.25);
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
                    let r = load_ray(rays, ((q * spp + k) as usize) * RAY_STRIDE);
                    k += 1;
                    if !r.valid {
                        continue;
                    }
                    let l = if r.hit { (hit_position(p, gbuf, r.hx, r.hy) - s.pos).normalize_or_zero() } else { r.dir };
                    let nl = s.n.dot(l);
                    if !(nl > 0.0) {
                        continue;
                    }
                    let w = if mirror {
                        1.0
                    } else {
                        if !(r.pdf > 0.0) {
                            continue;
                        }
                        let h = (s.v + l).normalize_or_zero();
                        let g2 = 1.0 / (1.0 + lambda_cos(nv, alpha) + lambda_cos(nl, alpha));
                        ggx_d_cos(s.n.dot(h), alpha) * g2 / (4.0 * nv) / r.pdf
                    };
                    if !(w > 0.0 && w < f32::INFINITY) {
                        continue;
                    }
                    if r.hit {
                        let (u, v) = reproject_hit(p, gbuf, r.hx, r.hy);
                        let a = edge_of_screen_fade(u, v, p.edge_fade_rcp_length);
                        let mut mip = 0.0;
                        if p.flags & FLAG_FIS != 0 && !mirror {
                            // Cone of solid angle 1 / (pdf N): half-angle tangent ~ sqrt(omega / pi);
                            // footprint diameter in pixels at the hit's screen distance. Written as
                            // (1/pi) / (pdf N): the form (1 / (pdf N)) * (1/pi) rounded differently
                            // on lavapipe (1 ULP in 0.2% of pixels; see docs/ssr.md).
                            let tan_half = Float::sqrt(core::f32::consts::FRAC_1_PI / (r.pdf * rays_in_window));
                            let ddx = r.hx - s.origin.x;
                            let ddy = r.hy - s.origin.y;
                            let dist_px = Float::sqrt(ddx * ddx + ddy * ddy);
                            mip = maxf(0.0, log2_approx(2.0 * dist_px * tan_half));
                        }
                        let c = sample_color(p, color, u, v, mip);
                        acc = acc + c * (a * w);
                        acc_a += a * w;
                    }
                    acc_w += w;
                }
            }
            dx += 1;
        }
        dy += 1;
    }
    if !(acc_w > 0.0) {
        store4(out, ob, Vec3::ZERO, 0.0);
        return;
    }
    let fade = perceptual_roughness_fade(s.perceptual_roughness, p.roughness_fade_rcp_length, p.roughness_fade_end_times_rcp_length);
    let k = fade / acc_w;
    store4(out, ob, acc * k, acc_a * k);
}

/// Temporal accumulation of pixel (x, y): the history is fetched at the pixel's previous position
/// (UV minus its motion vector; nearest texel), clamped to the min/max box of the current
/// resolve's 3x3 neighbourhood (history rejection), and blended with weight
/// max(1 / (n + 1), temporal_alpha); off-screen or empty history restarts at the current value.
pub fn temporal_pixel(p: &SsrParams, gbuf: &[f32], current: &[f32], history: &[f32], x: u32, y: u32, out: &mut [f32], ob: usize) {
    let i = (y * p.width + x) as usize;
    let cb = i * OUT_STRIDE;
    let cur = Vec3::new(current[cb], current[cb + 1], current[cb + 2]);
    let cur_a = current[cb + 3];
    let mv_u = gbuf[i * super::trace::GBUF_STRIDE + 6];
    let mv_v = gbuf[i * super::trace::GBUF_STRIDE + 7];
    let pu = (x as f32 + 0.5) / p.width as f32 - mv_u;
    let pv = (y as f32 + 0.5) / p.height as f32 - mv_v;
    let fresh = |out: &mut [f32]| {
        out[ob] = cur.x;
        out[ob + 1] = cur.y;
        out[ob + 2] = cur.z;
        out[ob + 3] = cur_a;
        out[ob + 4] = 1.0;
    };
    if !(pu >= 0.0 && pu < 1.0 && pv >= 0.0 && pv < 1.0) {
        fresh(out);
        return;
    }
    let hx = super::trace::floor_index(pu * p.width as f32, p.width - 1);
    let hy = super::trace::floor_index(pv * p.height as f32, p.height - 1);
    let hb = ((hy * p.width + hx) as usize) * HISTORY_STRIDE;
    let n = history[hb + 4];
    if !(n >= 1.0) {
        fresh(out);
        return;
    }
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
                let c = Vec3::new(current[b], current[b + 1], current[b + 2]);
                lo = Vec3::new(minf(lo.x, c.x), minf(lo.y, c.y), minf(lo.z, c.z));
                hi = Vec3::new(maxf(hi.x, c.x), maxf(hi.y, c.y), maxf(hi.z, c.z));
                lo_a = minf(lo_a, current[b + 3]);
                hi_a = maxf(hi_a, current[b + 3]);
            }
            dx += 1;
        }
        dy += 1;
    }
    let h = Vec3::new(
        clampf(history[hb], lo.x, hi.x),
        clampf(history[hb + 1], lo.y, hi.y),
        clampf(history[hb + 2], lo.z, hi.z),
    );
    let ha = clampf(history[hb + 3], lo_a, hi_a);
    let n1 = n + 1.0;
    let w = maxf(1.0 / n1, p.temporal_alpha);
    out[ob] = h.x + (cur.x - h.x) * w;
    out[ob + 1] = h.y + (cur.y - h.y) * w;
    out[ob + 2] = h.z + (cur.z - h.z) * w;
    out[ob + 3] = ha + (cur_a - ha) * w;
    out[ob + 4] = minf(n1, 1024.0);
}
