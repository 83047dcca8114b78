//! SSR at 1920x1080, the size a user first tries: the Hi-Z tracer against the brute-force per-pixel
//! march on the mirror rays of the built-in `floor` scene (HDRP's SSR_APPROX traces the mirror ray
//! of every glossy pixel), with HDRP's default iteration limit, and the trace pass CPU vs lavapipe.
//!
//! At 128x128 (ssr_hdrp.rs) Hi-Z and brute force agree on 99.95% of mirror pixels; at 1080p the
//! rays towards the eye (the front of the blue metal sphere reflects the camera side of the scene)
//! are where they part: a tracer that only descends on such rays marches one pixel per iteration
//! and runs out of iterations, leaving wedge-shaped holes in that sphere's reflection.

use crosscheck::{assert_bits_equal, gpu_backend};
use host::ssr::pipeline::{build_params, Runner};
use host::ssr::{scene, GBuffer, SsrSettings};
use host::Backend;
use rayon::prelude::*;
use shader_core::ssr::trace::{load_surface, reflect, screen_ray, trace_brute_force, trace_hiz, TraceHit, RAY_STRIDE};

const W: usize = 1920;
const H: usize = 1080;

fn floor_1080p() -> GBuffer {
    scene("floor").unwrap().render_gbuffer(W, H, 0)
}

/// What a trace found: the hit pixel, or None.
fn found(h: &TraceHit) -> Option<(u32, u32)> {
    h.hit.then_some((h.x, h.y))
}

/// Agreement counts of one class of rays.
#[derive(Default, Clone, Copy, Debug)]
struct Tally {
    rays: usize,
    same: usize,
    /// Rays where Hi-Z used its whole iteration budget.
    out_of_iterations: usize,
}

impl Tally {
    fn add(&mut self, same: bool, exhausted: bool) {
        self.rays += 1;
        self.same += same as usize;
        self.out_of_iterations += exhausted as usize;
    }
    fn merge(mut self, o: Tally) -> Tally {
        self.rays += o.rays;
        self.same += o.same;
        self.out_of_iterations += o.out_of_iterations;
        self
    }
    fn fraction(&self) -> f64 {
        self.same as f64 / self.rays as f64
    }
}

/// Hi-Z (HDRP's default 64 iterations) finds the same hit pixel as the brute-force march (no
/// limit) on the mirror rays of every second pixel in x and y (a quarter of the frame); rays
/// towards the eye are counted separately.
#[test]
fn hiz_matches_brute_force_at_1080p() {
    let g = floor_1080p();
    let s = SsrSettings::default();
    assert_eq!(s.hiz_max_iterations, 64, "the test is about HDRP's default limit");
    let consts = build_params(&g, &s).unwrap();
    let p = consts;
    let pyr = Runner::new(&Backend::Cpu).depth_pyramid(&consts, &g.depth_layers()).unwrap();
    let gbuf = g.packed();
    // (all rays, rays towards the eye, rays away from it, mirror-floor pixels).
    let (all, towards, away, mirror) = (0..H as u32)
        .into_par_iter()
        .step_by(2)
        .map(|y| {
            let mut t = [Tally::default(); 4];
            for x in (0..W as u32).step_by(2) {
                let sf = load_surface(&p, &gbuf, x, y);
                if !sf.valid {
                    continue;
                }
                let r = reflect(sf.v, sf.n);
                let (o, dir) = screen_ray(&p, &sf, r);
                let hz = trace_hiz(&p, &pyr, o, dir, p.depth_max_mip, p.hiz_max_iterations);
                let bf = trace_brute_force(&p, &pyr, o, dir);
                let same = found(&hz) == found(&bf);
                let exhausted = hz.steps >= p.hiz_max_iterations;
                t[0].add(same, exhausted);
                if dir.z > 0.0 {
                    t[1].add(same, exhausted);
                } else {
                    t[2].add(same, exhausted);
                }
                if g.roughness[(y as usize) * W + x as usize] == 0.0 {
                    t[3].add(same, exhausted);
                }
            }
            (t[0], t[1], t[2], t[3])
        })
        .reduce(
            || (Tally::default(), Tally::default(), Tally::default(), Tally::default()),
            |a, b| (a.0.merge(b.0), a.1.merge(b.1), a.2.merge(b.2), a.3.merge(b.3)),
        );
    for (name, t) in [("all mirror rays", all), ("towards the eye", towards), ("away from the eye", away), ("roughness-0 pixels", mirror)] {
        eprintln!(
            "floor 1920x1080, {name}: {} rays, Hi-Z = brute force on {} ({:.4}), Hi-Z out of iterations on {}",
            t.rays,
            t.same,
            t.fraction(),
            t.out_of_iterations
        );
    }
    assert!(towards.rays > 2000, "too few rays towards the eye to measure: {}", towards.rays);
    assert!(mirror.rays > 50_000, "too few mirror-floor pixels: {}", mirror.rays);
    assert!(towards.fraction() >= 0.98, "rays towards the eye: Hi-Z agrees with brute force on only {:.4}", towards.fraction());
    assert!(all.fraction() >= 0.98, "all mirror rays: Hi-Z agrees with brute force on only {:.4}", all.fraction());
}

/// The HDRP trace pass at 1080p (long Hi-Z loops, every ray direction), CPU vs lavapipe: identical bits.
#[test]
fn hdrp_trace_matches_gpu_at_1080p() {
    let Some(gpu) = gpu_backend() else { return };
    let g = floor_1080p();
    let consts = build_params(&g, &SsrSettings::default()).unwrap();
    let gbuf = g.packed();
    let mut c = Runner::new(&Backend::Cpu);
    let mut q = Runner::new(gpu);
    let dp = c.depth_pyramid(&consts, &g.depth_layers()).unwrap();
    assert_bits_equal("depth pyramid 1080p", 1, &dp, &q.depth_pyramid(&consts, &g.depth_layers()).unwrap());
    let pixels = c.hdrp_pixels(&consts, &gbuf).unwrap();
    assert_bits_equal("HDRP pixel list 1080p", 1, &pixels, &q.hdrp_pixels(&consts, &gbuf).unwrap());
    let rc = c.hdrp_trace(&consts, &gbuf, &dp, &pixels).unwrap();
    let rg = q.hdrp_trace(&consts, &gbuf, &dp, &pixels).unwrap();
    assert_bits_equal("HDRP trace 1080p", RAY_STRIDE, &rc, &rg);
}
