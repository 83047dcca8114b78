//! SSR stage 3 and 4: HDRP passes cross-checked CPU vs GPU (0 ULP), Hi-Z against the brute-force
//! march, and the HDRP pipeline against the ray-traced reference.

use crosscheck::{assert_bits_equal, gpu_backend};
use host::ssr::cli::errors;
use host::ssr::metrics::{composite, error, tonemap};
use host::ssr::pipeline::{build_params, Runner};
use host::ssr::{render_reference, run_hdrp, scene, GBuffer, HdrpResolve, SsrSettings, TraceMode};
use host::Backend;
use shader_core::ssr::params::{FLAG_STOCHASTIC, TRACE_BRUTE_FORCE, TRACE_HIZ, TRACE_LINEAR};
use shader_core::ssr::resolve::{hdrp_reproject_approx, hdrp_resolve_neighborhood, HIT_STRIDE, NEIGHBORHOOD_3X3, NEIGHBORHOOD_CROSS5, OUT_STRIDE};
use shader_core::ssr::trace::{hdrp_trace_pixel, info, load_surface, RAY_STRIDE};

const W: usize = 128;
const H: usize = 128;

fn gb(name: &str) -> GBuffer {
    scene(name).unwrap().render_gbuffer(W, H, 0)
}

/// Every HDRP pass, every tracer and resolve, CPU vs lavapipe: identical bits. The passes run
/// over the list of pixels with a valid surface; the list is checked against the surfaces, and
/// every pass's output against its per-pixel function run over the whole frame (pixels off the
/// list: no ray, no hit record, no reflection), so skipping them changes nothing.
#[test]
fn hdrp_passes_match_gpu_bit_for_bit() {
    let Some(gpu) = gpu_backend() else { return };
    for name in ["floor", "thin"] {
        let g = gb(name);
        let s = SsrSettings::default();
        let gbuf = g.packed();
        let mut consts = build_params(&g, &s).unwrap();
        let mut c = Runner::new(&Backend::Cpu);
        let mut q = Runner::new(gpu);
        let dp = c.depth_pyramid(&consts, &g.depth_layers()).unwrap();
        assert_bits_equal("depth pyramid", 1, &dp, &q.depth_pyramid(&consts, &g.depth_layers()).unwrap());
        let cp = c.color_pyramid(&consts, &g.color).unwrap();
        assert_bits_equal("color pyramid", 3, &cp, &q.color_pyramid(&consts, &g.color).unwrap());
        let pixels = c.hdrp_pixels(&consts, &gbuf).unwrap();
        assert_bits_equal(&format!("{name} pixel list"), 1, &pixels, &q.hdrp_pixels(&consts, &gbuf).unwrap());
        let want: Vec<u32> = tile_order(W as u32, H as u32).filter(|&(x, y)| load_surface(&consts, &gbuf, x, y).valid).map(|(x, y)| y * W as u32 + x).collect();
        assert!(!want.is_empty() && want.len() < W * H, "{name}: the list should skip some pixels and keep some");
        assert_eq!(pixels.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), want, "{name}: the pixel list is the valid pixels in tile order");
        for (mode, steps, stochastic) in [
            (TRACE_HIZ, 0, false),
            (TRACE_LINEAR, 16, false),
            (TRACE_LINEAR, 64, false),
            (TRACE_BRUTE_FORCE, 0, false),
            (TRACE_HIZ, 0, true),
        ] {
            consts.trace_mode = mode;
            consts.linear_steps = steps.max(1);
            consts.flags = if stochastic { consts.flags | FLAG_STOCHASTIC } else { consts.flags & !FLAG_STOCHASTIC };
            let tag = format!("{name} mode {mode} steps {steps} stochastic {stochastic}");
            let rc = c.hdrp_trace(&consts, &gbuf, &dp, &pixels).unwrap();
            let rg = q.hdrp_trace(&consts, &gbuf, &dp, &pixels).unwrap();
            assert_bits_equal(&format!("{tag} trace"), RAY_STRIDE, &rc, &rg);
            let full = per_pixel::<RAY_STRIDE>(|x, y, o| hdrp_trace_pixel(&consts, &gbuf, &dp, x, y, o, 0));
            let no_ray = [0.0f32; RAY_STRIDE];
            for (i, (got, want)) in rc.chunks_exact(RAY_STRIDE).zip(full.chunks_exact(RAY_STRIDE)).enumerate() {
                let listed = want[3].to_bits() & info::VALID != 0;
                let expect = if listed { want } else { &no_ray[..] };
                assert!(got.iter().zip(expect).all(|(a, b)| a.to_bits() == b.to_bits()), "{tag}: pixel {i}: list trace {got:?}, per-pixel {want:?}");
            }
            let hc = c.ray_hits(&consts, &gbuf, &cp, &rc).unwrap();
            assert_bits_equal(&format!("{tag} hit records"), HIT_STRIDE, &hc, &q.ray_hits(&consts, &gbuf, &cp, &rc).unwrap());
            for m in [HdrpResolve::Approx, HdrpResolve::Block3x3, HdrpResolve::Cross5] {
                let oc = c.hdrp_reproject(&consts, &gbuf, &cp, &rc, &pixels, m).unwrap();
                let og = q.hdrp_reproject(&consts, &gbuf, &cp, &rc, &pixels, m).unwrap();
                assert_bits_equal(&format!("{tag} resolve {}", m.label()), 4, &oc, &og);
                let full = per_pixel::<OUT_STRIDE>(|x, y, o| match m {
                    HdrpResolve::Approx => hdrp_reproject_approx(&consts, &gbuf, &cp, &rc, x, y, o, 0),
                    _ => hdrp_resolve_neighborhood(&consts, &gbuf, &cp, &rc, &hc, if m == HdrpResolve::Block3x3 { NEIGHBORHOOD_3X3 } else { NEIGHBORHOOD_CROSS5 }, x, y, o, 0),
                });
                assert_bits_equal(&format!("{tag} resolve {} over the list = every pixel", m.label()), 4, &oc, &full);
            }
        }
    }
}

/// Pixels in 8x8-tile order (tiles row-major, pixels row-major within a tile).
fn tile_order(w: u32, h: u32) -> impl Iterator<Item = (u32, u32)> {
    let t = shader_core::ssr::stochastic::TILE;
    (0..h.div_ceil(t)).flat_map(move |ty| (0..w.div_ceil(t)).flat_map(move |tx| (0..t * t).map(move |k| (tx * t + k % t, ty * t + k / t)))).filter(move |&(x, y)| x < w && y < h)
}

/// `f(x, y, record)` for every pixel of the W x H frame, row-major, `S` floats each.
fn per_pixel<const S: usize>(f: impl Fn(u32, u32, &mut [f32])) -> Vec<f32> {
    let mut out = vec![0.0f32; W * H * S];
    for (i, o) in out.chunks_exact_mut(S).enumerate() {
        f((i % W) as u32, (i / W) as u32, o);
    }
    out
}

/// Decoded hits of an HDRP run: Some((x, y)) per pixel with a ray, None elsewhere.
fn hits(rays: &[f32]) -> Vec<Option<Option<(u32, u32)>>> {
    rays.chunks_exact(RAY_STRIDE)
        .map(|r| {
            let bits = r[3].to_bits();
            if bits & info::VALID == 0 {
                None
            } else if bits & info::HIT != 0 {
                Some(Some((r[0] as u32, r[1] as u32)))
            } else {
                Some(None)
            }
        })
        .collect()
}

/// On mirror pixels, the Hi-Z tracer finds the same hit pixel as the brute-force march.
#[test]
fn hiz_finds_the_same_hits_as_brute_force_on_mirrors() {
    for name in ["floor", "thin", "hallway"] {
        let g = gb(name);
        let s = SsrSettings { hiz_max_iterations: 1000, ..SsrSettings::default() };
        let hz = run_hdrp(&Backend::Cpu, &g, &s, TraceMode::HiZ, HdrpResolve::Approx).unwrap();
        let bf = run_hdrp(&Backend::Cpu, &g, &s, TraceMode::BruteForce, HdrpResolve::Approx).unwrap();
        let (a, b) = (hits(&hz.rays), hits(&bf.rays));
        let mut mirror = 0;
        let mut same = 0;
        let mut hit = 0;
        for i in 0..W * H {
            if g.roughness[i] != 0.0 || a[i].is_none() {
                continue;
            }
            mirror += 1;
            hit += b[i].unwrap().is_some() as usize;
            same += (a[i] == b[i]) as usize;
        }
        let frac = same as f64 / mirror as f64;
        eprintln!("{name}: {mirror} mirror pixels traced, brute force hits {hit}, Hi-Z agrees on {same} ({:.4})", frac);
        assert!(mirror > 500 || name == "hallway" && mirror > 100, "{name}: {mirror}");
        assert!(frac >= 0.995, "{name}: Hi-Z agrees with brute force on only {frac}");
    }
}

/// The HDRP pipeline (Hi-Z, SSR_APPROX) against the ray-traced reference, on mirror pixels whose
/// reflection stays on screen.
#[test]
fn hdrp_mirror_reflections_match_the_reference() {
    for name in ["floor", "thin"] {
        let sc = scene(name).unwrap();
        let g = sc.render_gbuffer(W, H, 0);
        let s = SsrSettings::default();
        let res = run_hdrp(&Backend::Cpu, &g, &s, TraceMode::HiZ, HdrpResolve::Approx).unwrap();
        let r = render_reference(&sc, &g, 0.6, 16);
        let comp = composite(&res.reflection, sc.sky);
        // Mirror pixels whose reflection is on-screen geometry (not the sky) and away from the
        // screen edge fade.
        let inner = |v: f32, n: usize| v >= 0.1 * n as f32 && v <= 0.9 * n as f32;
        let mask: Vec<bool> = (0..W * H)
            .map(|i| g.roughness[i] == 0.0 && inner(r.mirror_hit[2 * i], W) && inner(r.mirror_hit[2 * i + 1], H))
            .collect();
        let e = error(&comp, &r.onscreen, &mask);
        let all = errors(&res, &r, sc.sky);
        // Per-pixel error after tone mapping (so the emitter's reflection does not dominate).
        let (tc, tr) = (tonemap(&comp), tonemap(&r.onscreen));
        let mut close = 0;
        let mut n = 0;
        for i in (0..W * H).filter(|&i| mask[i]) {
            n += 1;
            let d = (0..3).map(|k| (tc[3 * i + k] - tr[3 * i + k]).abs()).fold(0.0f32, f32::max);
            close += (d < 0.05) as usize;
        }
        let frac = close as f64 / n as f64;
        eprintln!(
            "{name}: mirror pixels with on-screen reflections {} RMSE {:.4} rel {:.4}, within 0.05 tone-mapped {:.4}; {:?}",
            e.pixels, e.rmse, e.rel, frac, all
        );
        assert!(e.pixels > 300, "{}", e.pixels);
        assert!(frac >= 0.9, "{name}: only {frac} of mirror pixels within 0.05 of the reference");
    }
}
