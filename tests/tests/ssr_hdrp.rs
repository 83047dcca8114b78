//! SSR stage 3 and 4: HDRP passes cross-checked CPU vs GPU (0 ULP), Hi-Z against the brute-force
//! march, and the HDRP pipeline against the ray-traced reference.

use crosscheck::{assert_bits_equal, gpu_backend};
use host::ssr::cli::errors;
use host::ssr::metrics::{composite, error, tonemap};
use host::ssr::pipeline::{build_params, Runner};
use host::ssr::{render_reference, run_hdrp, scene, GBuffer, HdrpResolve, SsrSettings, TraceMode};
use host::Backend;
use shader_core::ssr::params::{FLAG_STOCHASTIC, TRACE_BRUTE_FORCE, TRACE_HIZ, TRACE_LINEAR};
use shader_core::ssr::resolve::HIT_STRIDE;
use shader_core::ssr::trace::{info, RAY_STRIDE};

const W: usize = 128;
const H: usize = 128;

fn gb(name: &str) -> GBuffer {
    scene(name).unwrap().render_gbuffer(W, H, 0)
}

/// Every HDRP pass, every tracer and resolve, CPU vs lavapipe: identical bits.
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
            let rc = c.hdrp_trace(&consts, &gbuf, &dp).unwrap();
            let rg = q.hdrp_trace(&consts, &gbuf, &dp).unwrap();
            assert_bits_equal(&format!("{name} trace mode {mode} steps {steps} stochastic {stochastic}"), RAY_STRIDE, &rc, &rg);
            let hc = c.ray_hits(&consts, &gbuf, &rc).unwrap();
            assert_bits_equal(&format!("{name} hit records mode {mode} stochastic {stochastic}"), HIT_STRIDE, &hc, &q.ray_hits(&consts, &gbuf, &rc).unwrap());
            for m in [HdrpResolve::Approx, HdrpResolve::Block3x3, HdrpResolve::Cross5] {
                let oc = c.hdrp_reproject(&consts, &gbuf, &cp, &rc, m).unwrap();
                let og = q.hdrp_reproject(&consts, &gbuf, &cp, &rc, m).unwrap();
                assert_bits_equal(&format!("{name} resolve {}", m.label()), 4, &oc, &og);
            }
        }
    }
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
