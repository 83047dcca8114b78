//! The per-ray hit records (`shader_core::ssr::hits`) change where the resolves' per-ray work is
//! done, not what it computes: both neighbourhood resolves are compared, to the bit, with the
//! per-(pixel, ray) evaluation they replaced, and the stochastic hit distance with its per-ray form (written out below from the same shader-core
//! functions, so a hit record holding the wrong field, the wrong pixel's pdf or a stale value
//! fails). CPU only: the CPU-vs-GPU comparison of the records and resolves is in ssr_sssr.rs,
//! ssr_hdrp.rs and ssr_gltf.rs.

use host::ssr::pipeline::{build_params, HdrpResolve, Runner};
use host::ssr::sssr::{sssr_params, SssrSettings};
use host::ssr::{scene, SsrSettings};
use host::Backend;
use shader_core::ieee;
use shader_core::ssr::params::{SsrParams, FLAG_FIS, FLAG_RAY_COLOR, FLAG_REUSE, FLAG_STOCHASTIC};
use shader_core::ssr::resolve::{
    edge_of_screen_fade, hit_position, lambda_cos, load_ray, log2_approx, perceptual_roughness_fade, reproject_hit, sample_color,
    ssr_sample_weight, OUT_STRIDE,
};
use shader_core::ssr::stochastic::{eligible, ray_pdf_at_hit, ray_weight, MIRROR_ROUGHNESS};
use shader_core::ssr::trace::{load_surface, RAY_STRIDE};
use shader_core::vector::Vec3;
use std::cell::Cell;

const W: usize = 96;
const H: usize = 72;

/// (rgb, opacity) from the ratio sums, as the resolves store them.
fn finish(p: &SsrParams, rough: f32, acc: Vec3, acc_a: f32, acc_w: f32) -> [f32; 4] {
    if !(acc_w > 0.0) {
        return [0.0; 4];
    }
    let k = ieee::div(perceptual_roughness_fade(rough, p.roughness_fade_rcp_length, p.roughness_fade_end_times_rcp_length), acc_w);
    let c = acc * k;
    [c.x, c.y, c.z, acc_a * k]
}

/// The reflection hit distance of pixel (x, y) with each ray's hit position and pdf evaluated
/// here, as the hit-distance pass did before it read the hit records.
fn hit_distance_per_ray(p: &SsrParams, gbuf: &[f32], rays: &[f32], x: u32, y: u32) -> f32 {
    let s = load_surface(p, gbuf, x, y);
    if !s.valid {
        return 0.0;
    }
    let spp = p.samples_per_pixel;
    let mirror = s.perceptual_roughness < MIRROR_ROUGHNESS;
    let alpha = s.perceptual_roughness * s.perceptual_roughness;
    let nv = s.n.dot(s.v);
    let q = y * p.width + x;
    let (mut acc_d, mut acc_w) = (0.0f32, 0.0f32);
    for k in 0..spp {
        let r = load_ray(rays, ((q * spp + k) as usize) * RAY_STRIDE);
        if r.valid && r.hit {
            let hp = hit_position(p, gbuf, r.hx, r.hy);
            let d = hp - s.pos;
            let len = ieee::sqrt(d.dot(d));
            let l = if len > 0.0 { d / len } else { Vec3::ZERO };
            let w = ray_weight(&s, alpha, nv, lambda_cos(nv, alpha), mirror, l, ray_pdf_at_hit(p, &s, hp, r.pdf));
            acc_d += w * len;
            acc_w += w;
        }
    }
    if acc_w > 0.0 { ieee::div(acc_d, acc_w) } else { 0.0 }
}

/// The stochastic resolve of pixel (x, y) with every per-ray quantity evaluated per pair;
/// `mips` counts the gathered hitting rays sampled at mip 0 and above it (the two ways
/// `resolve::hit_color` takes).
fn sssr_pixel_per_pair(p: &SsrParams, gbuf: &[f32], color: &[f32], rays: &[f32], x: u32, y: u32, mips: &Cell<[usize; 2]>) -> [f32; 4] {
    let s = load_surface(p, gbuf, x, y);
    if !eligible(p, &s) {
        return [0.0; 4];
    }
    let spp = p.samples_per_pixel;
    let mirror = s.perceptual_roughness < MIRROR_ROUGHNESS;
    let alpha = s.perceptual_roughness * s.perceptual_roughness;
    let nv = s.n.dot(s.v);
    let radius: i32 = if mirror || p.flags & FLAG_REUSE == 0 { 0 } else { p.resolve_radius as i32 };
    let window = (2 * radius + 1) * (2 * radius + 1);
    let rays_in_window = (window as f32 * spp as f32 * p.rays_per_quad as f32 * 0.25).max(1.0);
    let (mut acc, mut acc_a, mut acc_w) = (Vec3::ZERO, 0.0f32, 0.0f32);
    for dy in -radius..=radius {
        for dx in -radius..=radius {
            let (qx, qy) = (x as i32 + dx, y as i32 + dy);
            if qx < 0 || qy < 0 || qx as u32 >= p.width || qy as u32 >= p.height {
                continue;
            }
            let q = qy as u32 * p.width + qx as u32;
            let sq = load_surface(p, gbuf, qx as u32, qy as u32);
            for k in 0..spp {
                let r = load_ray(rays, ((q * spp + k) as usize) * RAY_STRIDE);
                if !r.valid {
                    continue;
                }
                let (l, pdf) = if r.hit {
                    let hp = hit_position(p, gbuf, r.hx, r.hy);
                    ((hp - s.pos).normalize_or_zero(), ray_pdf_at_hit(p, &sq, hp, r.pdf))
                } else {
                    (r.dir, r.pdf)
                };
                let w = ray_weight(&s, alpha, nv, lambda_cos(nv, alpha), mirror, l, pdf);
                if !(w > 0.0) {
                    continue;
                }
                if r.hit {
                    let (u, v) = reproject_hit(p, gbuf, r.hx, r.hy);
                    let a = edge_of_screen_fade(u, v, p.edge_fade_rcp_length);
                    // The footprint is seen from the resolving pixel, or with FLAG_RAY_COLOR from
                    // the ray's own pixel.
                    let ray_color = p.flags & FLAG_RAY_COLOR != 0;
                    let (from, from_mirror) = if ray_color { (sq.origin, sq.perceptual_roughness < MIRROR_ROUGHNESS) } else { (s.origin, mirror) };
                    let mut mip = 0.0;
                    if p.flags & FLAG_FIS != 0 && !from_mirror {
                        let tan_half = ieee::sqrt(ieee::div(core::f32::consts::FRAC_1_PI, r.pdf * rays_in_window));
                        let (ddx, ddy) = (r.hx - from.x, r.hy - from.y);
                        mip = log2_approx(2.0 * ieee::sqrt(ddx * ddx + ddy * ddy) * tan_half).max(0.0);
                    }
                    acc = acc + sample_color(p, color, u, v, mip) * (a * w);
                    acc_a += a * w;
                    let mut m = mips.get();
                    m[(mip > 0.0) as usize] += 1;
                    mips.set(m);
                }
                acc_w += w;
            }
        }
    }
    finish(p, s.perceptual_roughness, acc, acc_a, acc_w)
}

/// HDRP's 3x3 neighbourhood resolve of pixel (x, y), per pair.
fn hdrp_pixel_per_pair(p: &SsrParams, gbuf: &[f32], color: &[f32], rays: &[f32], x: u32, y: u32) -> [f32; 4] {
    let s = load_surface(p, gbuf, x, y);
    if !s.valid {
        return [0.0; 4];
    }
    let alpha = s.perceptual_roughness * s.perceptual_roughness;
    let (mut acc, mut acc_a, mut acc_w) = (Vec3::ZERO, 0.0f32, 0.0f32);
    for dy in -1i32..=1 {
        for dx in -1i32..=1 {
            let (qx, qy) = (x as i32 + dx, y as i32 + dy);
            if qx < 0 || qy < 0 || qx as u32 >= p.width || qy as u32 >= p.height {
                continue;
            }
            let r = load_ray(rays, ((qy as u32 * p.width + qx as u32) as usize) * RAY_STRIDE);
            if !r.valid {
                continue;
            }
            let l = if r.hit { (hit_position(p, gbuf, r.hx, r.hy) - s.pos).normalize_or_zero() } else { r.dir };
            let w = ssr_sample_weight(s.n, s.v, l, alpha);
            if !(w > 0.0) {
                continue;
            }
            if r.hit {
                let (u, v) = reproject_hit(p, gbuf, r.hx, r.hy);
                let a = edge_of_screen_fade(u, v, p.edge_fade_rcp_length);
                acc = acc + sample_color(p, color, u, v, 0.0) * (a * w);
                acc_a += a * w;
            }
            acc_w += w;
        }
    }
    finish(p, s.perceptual_roughness, acc, acc_a, acc_w)
}

fn assert_same(tag: &str, got: &[f32], want: impl Fn(u32, u32) -> [f32; 4]) -> usize {
    let mut lit = 0;
    for (i, o) in got.chunks_exact(OUT_STRIDE).enumerate() {
        let (x, y) = ((i % W) as u32, (i / W) as u32);
        let w = want(x, y);
        for c in 0..4 {
            assert_eq!(o[c].to_bits(), w[c].to_bits(), "{tag}: pixel ({x}, {y}) channel {c}: {} vs per-pair {}", o[c], w[c]);
        }
        lit += (w[3] > 0.0) as usize;
    }
    lit
}

#[test]
fn neighbourhood_resolves_equal_their_per_pair_form_to_the_bit() {
    let d = SssrSettings::default();
    for (name, t, fade_band) in [
        ("floor", SssrSettings { rays_per_quad: 4, samples_per_pixel: 1, ..d.clone() }, false),
        ("floor", SssrSettings { rays_per_quad: 1, samples_per_pixel: 4, ..d.clone() }, false),
        ("animated", SssrSettings { rays_per_quad: 2, samples_per_pixel: 1, fis: false, ..d.clone() }, false),
        ("hallway", SssrSettings { rays_per_quad: 4, samples_per_pixel: 1, reuse: false, ..d.clone() }, false),
        ("floor", SssrSettings { rays_per_quad: 4, samples_per_pixel: 1, ray_color: false, ..d.clone() }, false),
        // The scenes' glossy surfaces are smoother than the roughness fade's start (perceptual
        // 0.5): this run moves them into the band, where both resolves scale by the fade.
        ("floor", SssrSettings { rays_per_quad: 4, samples_per_pixel: 1, ..d.clone() }, true),
    ] {
        let mut g = scene(name).unwrap().render_gbuffer(W, H, 4);
        if fade_band {
            for r in g.roughness.iter_mut().filter(|r| **r >= 0.03) {
                *r = (0.5 + *r).min(0.85);
            }
        }
        let gbuf = g.packed();
        let tag = format!("{name} SSSR rpq {} spp {} reuse {} fis {} ray colour {} fade band {fade_band}", t.rays_per_quad, t.samples_per_pixel, t.reuse, t.fis, t.ray_color);
        let consts = sssr_params(&g, &SsrSettings { frame: 2, ..SsrSettings::default() }, &t).unwrap();
        let p = consts;
        let mut c = Runner::new(&Backend::Cpu);
        let f = c.sssr_frame_passes(&consts, &gbuf, &g.depth_layers(), &g.color).unwrap();
        let mips = Cell::new([0usize; 2]);
        let lit = assert_same(&tag, &f.reflection, |x, y| sssr_pixel_per_pair(&p, &gbuf, &f.color_pyramid, &f.rays, x, y, &mips));
        assert!(lit > W * H / 10, "{tag}: only {lit} pixels reflect anything: the comparison would prove little");
        let faded = (0..W * H)
            .filter(|&i| f.reflection[i * 4 + 3] != 0.0)
            .filter(|&i| {
                let fade = perceptual_roughness_fade(g.roughness[i], p.roughness_fade_rcp_length, p.roughness_fade_end_times_rcp_length);
                fade > 0.0 && fade < 1.0
            })
            .count();
        assert!(!fade_band || faded > 200, "{tag}: only {faded} reflecting pixels inside the roughness fade");
        // Every way a colour is gathered is compared: without filtered importance sampling the
        // hit record's mip-0 colour, with it the lookup at mip 0 and the trilinear one above it.
        let [at_0, above_0] = mips.get();
        // (The fade-band run reflects on fewer pixels: its rough rays hit less often.)
        let min_rays = if fade_band { 300 } else { 1000 };
        assert!(at_0 > min_rays, "{tag}: only {at_0} rays gathered at mip 0");
        if t.fis && t.reuse {
            assert!(above_0 > min_rays, "{tag}: only {above_0} rays gathered above mip 0");
        }
        // The hit distance (over the pixel list, from the hit records) against its per-ray form.
        let hd = c.sssr_hit_distance(&consts, &gbuf, &f.rays, &f.hits, &f.pixels).unwrap();
        let mut hit = 0;
        for (i, d) in hd.iter().enumerate() {
            let (x, y) = ((i % W) as u32, (i / W) as u32);
            let want = hit_distance_per_ray(&p, &gbuf, &f.rays, x, y);
            assert_eq!(d.to_bits(), want.to_bits(), "{tag}: hit distance at ({x}, {y}): {d} vs per-ray {want}");
            hit += (want > 0.0) as usize;
        }
        assert!(hit > W * H / 20, "{tag}: only {hit} pixels have a hit distance");

        // HDRP's 3x3 resolve on GGX-sampled rays of the same G-buffer.
        let mut consts = build_params(&g, &SsrSettings::default()).unwrap();
        consts.flags |= FLAG_STOCHASTIC;
        let p = consts;
        let dp = c.depth_pyramid(&consts, &g.depth_layers()).unwrap();
        let cp = c.color_pyramid(&consts, &g.color).unwrap();
        let pixels = c.hdrp_pixels(&consts, &gbuf).unwrap();
        let rays = c.hdrp_trace(&consts, &gbuf, &dp, &pixels).unwrap();
        let out = c.hdrp_reproject(&consts, &gbuf, &cp, &rays, &pixels, HdrpResolve::Block3x3).unwrap();
        let lit = assert_same(&format!("{name} HDRP 3x3"), &out, |x, y| hdrp_pixel_per_pair(&p, &gbuf, &cp, &rays, x, y));
        assert!(lit > W * H / 10, "{name} HDRP: only {lit} pixels reflect anything");
    }
}
