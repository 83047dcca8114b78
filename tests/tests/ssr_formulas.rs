//! The SSR passes' formulas against independent f64 forms of their equations, on the CPU: the
//! stochastic resolve's ray weight f cos / pdf = D(h) G2(v, l) / (4 n.v) / pdf (Stachowiak 2015's
//! ratio estimator; Heitz 2018 eq. 19), HDRP's `GetSSRSampleWeight` = G2 / G1 = (1 + Lambda(v)) /
//! (1 + Lambda(v) + Lambda(l)), the colour pyramid's bilinear and trilinear samples, the filtered-
//! importance-sampling cone and mip, HDRP's edge-of-screen fade and `SSR_APPROX` resolve, the
//! hit's virtual image for temporal reprojection, and the temporal blend (history clamped to the
//! current 3x3 box, weight max(1 / (n + 1), alpha)). The CPU-vs-GPU comparisons cannot catch a
//! wrong formula (both backends run the same one) and the error-against-reference tests only
//! bound whole pipelines; each test here fails when its formula is changed (`cargo xtask mutants`,
//! docs/DEVELOPING.md "Formula tests and mutants").

use host::microfacet_ref as r64;
use host::ssr::pipeline::pyramid_texels;
use host::ssr::sssr::{sssr_params, SssrSettings};
use host::ssr::{scene, SsrSettings};
use shader_core::ssr::params::{mip_size, SsrParams, FLAG_REUSE};
use shader_core::ssr::resolve::{edge_of_screen_fade, hdrp_reproject_approx, lambda_cos, log2_approx, sample_color, sample_color_level, ssr_sample_weight, COLOR_STRIDE, OUT_STRIDE};
use shader_core::ssr::mat4::Mat4;
use shader_core::ssr::stochastic::{fis_mip, fis_rays_in_window, fis_tan_half, ray_weight, temporal_pixel, virtual_image_uv, HISTORY_STRIDE};
use shader_core::ssr::trace::{info, load_surface, p_mip_offset, Surface, GBUF_STRIDE, RAY_INFO, RAY_STRIDE};
use shader_core::vector::Vec3;

/// SplitMix64: reproducible inputs without a dependency.
struct Rng(reference::splitmix::SplitMix64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0.next_u64()
    }
    /// Uniform in [lo, hi).
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }
    /// A unit vector, uniform on the sphere.
    fn unit(&mut self) -> Vec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32)
    }
}

fn d64(a: Vec3) -> [f64; 3] {
    [f64::from(a.x), f64::from(a.y), f64::from(a.z)]
}

/// A surface at the origin with normal `n`, eye direction `v` and perceptual roughness `r`.
fn surface(n: Vec3, v: Vec3, r: f32) -> Surface {
    Surface { valid: true, pos: Vec3::ZERO, n, v, perceptual_roughness: r, origin: Vec3::ZERO }
}

/// Random (n, v, l) with n.v >= 0.05 (the resolve's surfaces face the eye) and l anywhere.
fn configuration(rng: &mut Rng) -> (Vec3, Vec3, Vec3) {
    loop {
        let n = rng.unit();
        let v = rng.unit();
        if n.dot(v) >= 0.05 {
            return (n, v, rng.unit());
        }
    }
}

/// `stochastic::ray_weight` = D(h) G2(v, l) / (4 n.v) / pdf for non-mirror surfaces (0 below the
/// surface), 1 above it for mirror ones, over 200,000 random configurations and densities; f64
/// reference from `reference::microfacet` on the same (f32) vectors.
#[test]
fn stochastic_ray_weight_is_brdf_cos_over_pdf() {
    let mut rng = Rng(reference::splitmix::SplitMix64(1));
    let (mut above, mut worst) = (0, 0.0f64);
    for _ in 0..200_000 {
        let (n, v, l) = configuration(&mut rng);
        let r = rng.range(0.2, 1.0) as f32;
        let alpha = r * r;
        let pdf = 10f64.powf(rng.range(-2.0, 3.0)) as f32;
        let s = surface(n, v, r);
        let nv = n.dot(v);
        let w = ray_weight(&s, alpha, nv, lambda_cos(nv, alpha), false, l, pdf);
        let mirror = ray_weight(&s, alpha, nv, lambda_cos(nv, alpha), true, l, pdf);
        // The cosines as the kernel computes them (f32 dot products), the rest in f64: the test
        // checks the formula, not the conditioning of a dot product near 0.
        let (n64, v64, l64) = (d64(n), d64(v), d64(l));
        let nl = f64::from(n.dot(l));
        if nl <= 0.0 {
            assert_eq!((w, mirror), (0.0, 0.0), "below the surface: n.l = {nl}");
            continue;
        }
        assert_eq!(mirror, 1.0, "a mirror surface weighs its ray 1 above the surface");
        let a = f64::from(alpha);
        let h = r64::normalize([v64[0] + l64[0], v64[1] + l64[1], v64[2] + l64[2]]);
        let nv64 = f64::from(nv);
        let g2 = r64::g2_height_correlated(r64::ggx_lambda_cos(nv64, a), r64::ggx_lambda_cos(nl, a));
        let want = r64::ggx_d_cos(r64::dot(n64, h), a) * g2 / (4.0 * nv64) / f64::from(pdf);
        let rel = (f64::from(w) - want).abs() / want;
        assert!(rel < 1e-3, "n {n:?} v {v:?} l {l:?} r {r} pdf {pdf}: weight {w}, f64 {want} (rel {rel:.2e})");
        worst = worst.max(rel);
        above += 1;
    }
    eprintln!("ray weight: {above} configurations above the surface, worst relative error {worst:.2e}");
    assert!(above > 50_000);
}

/// HDRP `GetSSRSampleWeight` = (1 + Lambda(v)) / (1 + Lambda(v) + Lambda(l)) (height-correlated
/// G2 over G1), 0 below the surface, against the f64 Lambda of the kernel's cosines.
#[test]
fn hdrp_sample_weight_is_g2_over_g1() {
    let mut rng = Rng(reference::splitmix::SplitMix64(2));
    let mut worst = 0.0f64;
    for _ in 0..200_000 {
        let (n, v, l) = configuration(&mut rng);
        let alpha = rng.range(0.0004, 1.0) as f32;
        let w = ssr_sample_weight(n, v, l, alpha);
        let (nv, nl) = (f64::from(n.dot(v)), f64::from(n.dot(l)));
        if nl <= 0.0 {
            assert_eq!(w, 0.0, "below the surface: n.l = {nl}");
            continue;
        }
        let a = f64::from(alpha);
        let lv = r64::ggx_lambda_cos(nv, a);
        let want = (1.0 + lv) / (1.0 + lv + r64::ggx_lambda_cos(nl, a));
        let err = (f64::from(w) - want).abs();
        assert!(err < 1e-5, "n {n:?} v {v:?} l {l:?} alpha {alpha}: weight {w}, f64 {want}");
        worst = worst.max(err);
    }
    eprintln!("GetSSRSampleWeight: worst absolute error {worst:.2e}");
}

/// Parameters of a small frame of the floor scene (static camera).
fn params(w: usize, h: usize) -> (SsrParams, Vec<f32>) {
    let g = scene("floor").unwrap().render_gbuffer(w, h, 0);
    (sssr_params(&g, &SsrSettings::default(), &SssrSettings::default()).unwrap(), g.packed())
}

/// A colour pyramid whose mip `level` holds `f(level, x, y)` at texel (x, y).
fn pyramid(p: &SsrParams, f: impl Fn(u32, f64, f64) -> [f64; 3]) -> Vec<f32> {
    let mut pyr = vec![0.0f32; pyramid_texels(p.width, p.height) * COLOR_STRIDE];
    for level in 0..=p.color_max_mip {
        let (w, h, off) = (mip_size(p.width, level), mip_size(p.height, level), p_mip_offset(p, level));
        for y in 0..h {
            for x in 0..w {
                let c = f(level, f64::from(x), f64::from(y));
                let b = ((off + y * w + x) as usize) * COLOR_STRIDE;
                for k in 0..3 {
                    pyr[b + k] = c[k] as f32;
                }
            }
        }
    }
    pyr
}

/// Bilinear interpolation reproduces a linear function of the texel coordinates exactly: sampled
/// at (u, v), each mip gives the function at (u w - 1/2, v h - 1/2) (inside the texel centres;
/// clamp-to-edge beyond them). Each channel slopes differently in x and y, so a swapped or
/// reversed interpolation weight shows.
#[test]
fn colour_samples_are_bilinear_in_the_texel_coordinates() {
    let (p, _) = params(80, 60);
    assert!(p.color_max_mip >= 3);
    let linear = |x: f64, y: f64| [0.1 + 0.02 * x + 0.005 * y, 0.3 + 0.001 * x + 0.03 * y, 1.0 - 0.01 * x + 0.004 * y];
    let pyr = pyramid(&p, |level, x, y| {
        let c = linear(x, y);
        [c[0] + f64::from(level), c[1], c[2]]
    });
    let mut rng = Rng(reference::splitmix::SplitMix64(3));
    let mut worst = 0.0f64;
    for _ in 0..20_000 {
        let level = (rng.next() % u64::from(p.color_max_mip + 1)) as u32;
        let (w, h) = (f64::from(mip_size(p.width, level)), f64::from(mip_size(p.height, level)));
        let (u, v) = (rng.range(-0.2, 1.2) as f32, rng.range(-0.2, 1.2) as f32);
        let got = sample_color_level(&p, &pyr, u, v, level);
        let tx = (f64::from(u).clamp(0.0, 1.0) * w - 0.5).clamp(0.0, w - 1.0);
        let ty = (f64::from(v).clamp(0.0, 1.0) * h - 0.5).clamp(0.0, h - 1.0);
        let c = linear(tx, ty);
        let want = [c[0] + f64::from(level), c[1], c[2]];
        for (k, (g, e)) in [got.x, got.y, got.z].into_iter().zip(want).enumerate() {
            let err = (f64::from(g) - e).abs();
            assert!(err < 2e-5, "level {level} at ({u}, {v}), channel {k}: {g} vs {e}");
            worst = worst.max(err);
        }
    }
    eprintln!("bilinear colour samples: worst absolute error {worst:.2e}");
}

/// A trilinear sample at fractional mip m blends mip floor(m) and the next one by frac(m) (mips
/// of constant colour here), clamps m to [0, color_max_mip], and reads mip floor(m) alone at an
/// integer m.
#[test]
fn colour_samples_are_linear_between_mips() {
    let (p, _) = params(80, 60);
    let value = |level: u32| [1.0 + 3.0 * f64::from(level), 10.0 - f64::from(level * level), 0.5 * f64::from(level)];
    let pyr = pyramid(&p, |level, _, _| value(level));
    let top = f64::from(p.color_max_mip);
    let mut rng = Rng(reference::splitmix::SplitMix64(4));
    for i in 0..20_000 {
        let m = if i % 10 == 0 { (rng.next() % u64::from(p.color_max_mip + 3)) as f64 - 1.0 } else { rng.range(-1.0, top + 1.0) };
        let (u, v) = (rng.range(0.0, 1.0) as f32, rng.range(0.0, 1.0) as f32);
        let got = sample_color(&p, &pyr, u, v, m as f32);
        let mc = f64::from(m as f32).clamp(0.0, top);
        let l0 = mc.floor();
        let f = mc - l0;
        let (a, b) = (value(l0 as u32), value((l0 as u32 + 1).min(p.color_max_mip)));
        for (k, g) in [got.x, got.y, got.z].into_iter().enumerate() {
            let e = a[k] + (b[k] - a[k]) * f;
            assert!((f64::from(g) - e).abs() < 1e-5 * e.abs().max(1.0), "mip {m} channel {k}: {g} vs {e}");
        }
    }
}

/// HDRP `EdgeOfScreenFade`: Smoothstep01(Remap10(|2u - 1|)) Smoothstep01(Remap10(|2v - 1|)) with
/// Remap10(x) = saturate((1 - x) / length), 1 inside the fade band and 0 at the screen's edges.
#[test]
fn edge_of_screen_fade_is_the_product_of_the_axis_fades() {
    let smooth = |x: f64| x * x * (3.0 - 2.0 * x);
    let mut rng = Rng(reference::splitmix::SplitMix64(5));
    for _ in 0..50_000 {
        let length = rng.range(0.01, 1.0);
        let rcp = (1.0 / length) as f32;
        let (u, v) = (rng.range(0.0, 1.0) as f32, rng.range(0.0, 1.0) as f32);
        let axis = |t: f32| smooth(((1.0 - (2.0 * f64::from(t) - 1.0).abs()) * f64::from(rcp)).clamp(0.0, 1.0));
        let want = axis(u) * axis(v);
        let got = edge_of_screen_fade(u, v, rcp);
        assert!((f64::from(got) - want).abs() < 1e-4, "({u}, {v}), band {length}: {got} vs {want}");
    }
    // Inside the band on both axes nothing fades; at an edge everything does.
    assert_eq!(edge_of_screen_fade(0.5, 0.5, 10.0), 1.0);
    assert_eq!(edge_of_screen_fade(0.0, 0.5, 10.0), 0.0);
    assert_eq!(edge_of_screen_fade(0.5, 1.0, 10.0), 0.0);
}

/// Temporal accumulation with a static camera: every pixel with geometry finds its own history
/// texel, clamps it to the min / max box of the current frame's 3x3 neighbourhood and blends it
/// with weight max(1 / (n + 1), temporal_alpha), its count becoming min(n + 1, 1024); a pixel
/// without geometry restarts at the current value with count 1. Random current values and
/// histories with counts from 1 to 2000 (some inside the box, most clamped).
#[test]
fn temporal_blend_clamps_history_to_the_box_and_weighs_it_by_the_count() {
    let (w, h) = (48usize, 36usize);
    let (p, gbuf) = params(w, h);
    assert!(p.temporal_alpha > 0.0 && p.temporal_alpha < 1.0);
    let mut rng = Rng(reference::splitmix::SplitMix64(6));
    let current: Vec<f32> = (0..w * h * OUT_STRIDE).map(|_| rng.range(0.0, 1.0) as f32).collect();
    let counts = [1.0f32, 2.0, 3.0, 5.0, 9.0, 15.0, 40.0, 1023.0, 2000.0];
    let mut history = vec![0.0f32; w * h * HISTORY_STRIDE];
    for i in 0..w * h {
        for k in 0..4 {
            history[i * HISTORY_STRIDE + k] = rng.range(-0.2, 1.2) as f32;
        }
        history[i * HISTORY_STRIDE + 4] = counts[i % counts.len()];
    }
    let hit_distance = vec![0.0f32; w * h];
    let (mut blended, mut restarted) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let mut out = [0.0f32; HISTORY_STRIDE];
            temporal_pixel(&p, &gbuf, &gbuf, &hit_distance, &current, &history, x as u32, y as u32, &mut out, 0);
            let z = gbuf[i * GBUF_STRIDE];
            let cur = &current[i * OUT_STRIDE..i * OUT_STRIDE + 4];
            if !(z > 0.0 && z < f32::INFINITY) {
                assert_eq!(out, [cur[0], cur[1], cur[2], cur[3], 1.0], "pixel ({x}, {y}) without geometry");
                restarted += 1;
                continue;
            }
            let n = f64::from(history[i * HISTORY_STRIDE + 4]);
            let weight = (1.0 / (n + 1.0)).max(f64::from(p.temporal_alpha));
            for k in 0..4 {
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for qy in y.saturating_sub(1)..(y + 2).min(h) {
                    for qx in x.saturating_sub(1)..(x + 2).min(w) {
                        let c = f64::from(current[(qy * w + qx) * OUT_STRIDE + k]);
                        lo = lo.min(c);
                        hi = hi.max(c);
                    }
                }
                let hist = f64::from(history[i * HISTORY_STRIDE + k]).clamp(lo, hi);
                let want = hist + (f64::from(cur[k]) - hist) * weight;
                assert!((f64::from(out[k]) - want).abs() < 1e-6, "pixel ({x}, {y}) channel {k}, count {n}: {} vs {want}", out[k]);
            }
            assert_eq!(f64::from(out[4]), (n + 1.0).min(1024.0), "pixel ({x}, {y}): count");
            blended += 1;
        }
    }
    eprintln!("temporal blend: {blended} pixels blended with their history, {restarted} without geometry");
    assert!(blended > w * h / 2, "{blended} of {} pixels", w * h);
}

/// Filtered importance sampling (Stachowiak 2015): a ray of density pdf among N rays stands for a
/// cone of half-angle tangent sqrt(1 / (pi pdf N)), and its colour is read at the mip whose texel
/// is the cone's footprint, log2(2 |hit - origin| tan_half) in pixels (0 below one pixel), through
/// `log2_approx` (at most 0.086 below log2, exact at powers of two).
#[test]
fn fis_cone_and_mip_follow_the_footprint() {
    let mut rng = Rng(reference::splitmix::SplitMix64(7));
    for _ in 0..100_000 {
        let x = 2f64.powf(rng.range(-30.0, 30.0)) as f32;
        let err = (f64::from(x)).log2() - f64::from(log2_approx(x));
        assert!((0.0..=0.0861).contains(&err), "log2_approx({x}): {} (log2 {})", log2_approx(x), f64::from(x).log2());
        let k = (rng.next() % 60) as i32 - 30;
        assert_eq!(log2_approx(2f32.powi(k)), k as f32);

        let pdf = 10f64.powf(rng.range(-2.0, 4.0)) as f32;
        let n_rays = [1.0f32, 2.25, 9.0, 36.0][(rng.next() % 4) as usize];
        let tan_half = fis_tan_half(pdf, n_rays);
        let want = (1.0 / (std::f64::consts::PI * f64::from(pdf) * f64::from(n_rays))).sqrt();
        assert!((f64::from(tan_half) / want - 1.0).abs() < 1e-6, "pdf {pdf}, N {n_rays}: {tan_half} vs {want}");

        let origin = Vec3::new(rng.range(0.0, 1920.0) as f32, rng.range(0.0, 1080.0) as f32, 0.5);
        let (hx, hy) = (rng.range(0.0, 1920.0) as f32, rng.range(0.0, 1080.0) as f32);
        let dist = (f64::from(hx) - f64::from(origin.x)).hypot(f64::from(hy) - f64::from(origin.y));
        let footprint = (2.0 * dist * f64::from(tan_half)).log2();
        let mip = f64::from(fis_mip(origin, hx, hy, tan_half));
        if footprint <= 0.0 {
            assert_eq!(mip, 0.0, "footprint {footprint} below one pixel");
        } else {
            let err = footprint - mip;
            assert!((-1e-5..=0.0861).contains(&err), "dist {dist}, tan_half {tan_half}: mip {mip}, log2 footprint {footprint}");
        }
    }
}

/// The N of the cone: the resolve window's (2r + 1)^2 pixels times their rays (rays per pixel x
/// rays per quad / 4), at least 1; 1 pixel without reuse.
#[test]
fn fis_rays_in_window_counts_the_window() {
    let (p0, _) = params(16, 12);
    for (reuse, radius, spp, rpq) in [(true, 1, 1, 4), (true, 1, 1, 1), (true, 2, 4, 4), (false, 2, 1, 4), (true, 0, 1, 1)] {
        let mut p = p0;
        p.flags = if reuse { p.flags | FLAG_REUSE } else { p.flags & !FLAG_REUSE };
        p.resolve_radius = radius;
        p.samples_per_pixel = spp;
        p.rays_per_quad = rpq;
        let r = if reuse { radius } else { 0 };
        let want = (((2 * r + 1) * (2 * r + 1) * spp * rpq) as f32 / 4.0).max(1.0);
        assert_eq!(fis_rays_in_window(&p), want, "reuse {reuse}, radius {radius}, {spp} rays per pixel, {rpq} per quad");
    }
}

/// HDRP's `SSR_APPROX` resolve of a pixel whose ray hit pixel (hx, hy): the colour pyramid read at
/// the hit's previous-frame UV (hx / w, hy / h minus the motion vector stored at the hit) and at
/// mip roughness x color_max_mip, weighted by the opacity EdgeOfScreenFade(uv) x
/// PerceptualRoughnessFade(roughness) = Smoothstep01(saturate((end - r) / length)), premultiplied;
/// zero where the ray missed. On a moving camera's frame (non-zero motion vectors), random hits.
#[test]
fn ssr_approx_reads_the_reprojected_hit_at_the_roughness_mip() {
    let (w, h) = (64usize, 48usize);
    let g = scene("animated").unwrap().render_gbuffer(w, h, 20);
    let p = sssr_params(&g, &SsrSettings::default(), &SssrSettings::default()).unwrap();
    let gbuf = g.packed();
    let value = |level: u32| [0.25 + f64::from(level), 3.0 - 0.5 * f64::from(level), 0.125 * f64::from(level * level)];
    let pyr = pyramid(&p, |level, _, _| value(level));
    let mut rng = Rng(reference::splitmix::SplitMix64(8));
    let mut rays = vec![0.0f32; w * h * RAY_STRIDE];
    for i in 0..w * h {
        let b = i * RAY_STRIDE;
        rays[b] = rng.range(0.0, w as f64) as f32;
        rays[b + 1] = rng.range(0.0, h as f64) as f32;
        let hit = !rng.next().is_multiple_of(4);
        rays[b + RAY_INFO] = f32::from_bits(info::VALID | if hit { info::HIT } else { 0 });
    }
    let moving = (0..w * h).filter(|&i| gbuf[i * GBUF_STRIDE + 6] != 0.0 || gbuf[i * GBUF_STRIDE + 7] != 0.0).count();
    assert!(moving > w * h / 4, "the frame should have motion vectors ({moving} pixels)");
    let smooth = |x: f64| x * x * (3.0 - 2.0 * x);
    let remap10 = |x: f64, rcp: f32, end_rcp: f32| (f64::from(end_rcp) - x * f64::from(rcp)).clamp(0.0, 1.0);
    let (mut hits, mut faded) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let mut out = [0.0f32; OUT_STRIDE];
            hdrp_reproject_approx(&p, &gbuf, &pyr, &rays, x as u32, y as u32, &mut out, 0);
            let b = i * RAY_STRIDE;
            if rays[b + RAY_INFO].to_bits() & info::HIT == 0 {
                assert_eq!(out, [0.0; 4], "pixel ({x}, {y}): a miss reflects nothing");
                continue;
            }
            let (hx, hy) = (f64::from(rays[b]), f64::from(rays[b + 1]));
            let t = ((hy as usize) * w + hx as usize) * GBUF_STRIDE;
            let u = hx / w as f64 - f64::from(gbuf[t + 6]);
            let v = hy / h as f64 - f64::from(gbuf[t + 7]);
            let rough = f64::from(gbuf[i * GBUF_STRIDE + 4]);
            let edge = |c: f64| smooth(remap10((2.0 * c - 1.0).abs(), p.edge_fade_rcp_length, p.edge_fade_rcp_length));
            let opacity = edge(u) * edge(v) * smooth(remap10(rough, p.roughness_fade_rcp_length, p.roughness_fade_end_times_rcp_length));
            let mip = (rough * f64::from(p.color_max_mip)).clamp(0.0, f64::from(p.color_max_mip));
            let l0 = mip.floor() as u32;
            let (c0, c1) = (value(l0), value((l0 + 1).min(p.color_max_mip)));
            for k in 0..3 {
                let want = (c0[k] + (c1[k] - c0[k]) * (mip - f64::from(l0))) * opacity;
                assert!((f64::from(out[k]) - want).abs() < 1e-5 * want.abs().max(1.0), "pixel ({x}, {y}) channel {k}: {} vs {want} (rough {rough}, uv {u} {v})", out[k]);
            }
            assert!((f64::from(out[3]) - opacity).abs() < 1e-5, "pixel ({x}, {y}) opacity: {} vs {opacity}", out[3]);
            hits += 1;
            faded += usize::from(opacity > 0.0 && opacity < 1.0);
        }
    }
    eprintln!("SSR_APPROX: {hits} hits, {faded} partly faded");
    assert!(hits > w * h / 2 && faded > hits / 20, "{hits} hits, {faded} partly faded");
}

/// `m` as an f64 row-major array.
fn mat64(m: &Mat4) -> [[f64; 4]; 4] {
    [m.r0, m.r1, m.r2, m.r3].map(|r| [r.x, r.y, r.z, r.w].map(f64::from))
}

fn mul64(m: &[[f64; 4]; 4], v: [f64; 4]) -> [f64; 4] {
    m.map(|r| r[0] * v[0] + r[1] * v[1] + r[2] * v[2] + r[3] * v[3])
}

/// The inverse of a 4x4 matrix by Gauss-Jordan elimination with partial pivoting.
fn inverse64(m: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut a = *m;
    let mut inv = [[0.0; 4]; 4];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for c in 0..4 {
        let p = (c..4).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs())).unwrap();
        a.swap(c, p);
        inv.swap(c, p);
        let d = a[c][c];
        assert!(d.abs() > 1e-12, "singular matrix");
        for k in 0..4 {
            a[c][k] /= d;
            inv[c][k] /= d;
        }
        for r in 0..4 {
            if r != c {
                let f = a[r][c];
                for k in 0..4 {
                    a[r][k] -= f * a[c][k];
                    inv[r][k] -= f * inv[c][k];
                }
            }
        }
    }
    inv
}

/// Hit-based temporal reprojection (Stachowiak 2015, "reflection motion vectors"): the reflection
/// seen at a surface lies `dist` beyond it along the eye ray (a planar mirror's virtual image), and
/// its previous-frame UV is that point through the previous camera. Checked against the point
/// built in f64 (view -> world by `inv_view`, world -> previous view by the inverse of
/// `prev_inv_view`, `prev_proj`, perspective divide) on a moving camera's frame; on a static
/// camera every virtual image lands on its own pixel (it lies on the pixel's eye ray).
#[test]
fn virtual_image_lies_beyond_the_surface_along_the_eye_ray() {
    let (w, h) = (64usize, 48usize);
    let sc = scene("animated").unwrap();
    let mut checked = 0;
    for frame in [0, 20] {
        let g = sc.render_gbuffer(w, h, frame);
        let p = sssr_params(&g, &SsrSettings { frame, ..SsrSettings::default() }, &SssrSettings::default()).unwrap();
        let gbuf = g.packed();
        let moving = p.prev_inv_view != p.inv_view;
        assert_eq!(moving, frame == 20, "frame {frame}: the camera should move only after frame 0");
        let (inv_view, prev_view, prev_proj) = (mat64(&p.inv_view), inverse64(&mat64(&p.prev_inv_view)), mat64(&p.prev_proj));
        let mut rng = Rng(reference::splitmix::SplitMix64(9 + frame as u64));
        for _ in 0..2000 {
            let (x, y) = ((rng.next() % w as u64) as u32, (rng.next() % h as u64) as u32);
            let s = load_surface(&p, &gbuf, x, y);
            if !s.valid {
                continue;
            }
            let dist = rng.range(0.05, 8.0) as f32;
            let (u, v) = virtual_image_uv(&p, &s, dist);
            let pos = d64(s.pos);
            let k = 1.0 + f64::from(dist) / r64::dot(pos, pos).sqrt();
            let world = mul64(&inv_view, [pos[0] * k, pos[1] * k, pos[2] * k, 1.0]);
            let c = mul64(&prev_proj, mul64(&prev_view, world));
            assert!(c[3] > 0.0, "virtual image behind the previous camera");
            let (wu, wv) = (c[0] / c[3] * 0.5 + 0.5, 0.5 - c[1] / c[3] * 0.5);
            assert!((f64::from(u) - wu).abs() < 1e-4 && (f64::from(v) - wv).abs() < 1e-4, "frame {frame} pixel ({x}, {y}), dist {dist}: uv ({u}, {v}) vs f64 ({wu}, {wv})");
            if !moving {
                let (pu, pv) = ((f64::from(x) + 0.5) / w as f64, (f64::from(y) + 0.5) / h as f64);
                assert!((wu - pu).abs() < 1e-4 && (wv - pv).abs() < 1e-4, "static camera, pixel ({x}, {y}): virtual image at ({wu}, {wv})");
            }
            checked += 1;
        }
    }
    assert!(checked > 1000, "{checked} surfaces checked");
}
