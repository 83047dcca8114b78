//! Edge continuity of the mirror reflections at 1920x1080 (docs/ssr.md, "Comb fringes along the top
//! edges of the sphere reflections"): floor pixels between a sphere's lower outline and its
//! reflection reflect rays that pass under the sphere; with HDRP's constant 1% slab, the
//! grazing outline texels catch some of them (false hits: dark teeth above the true edge of the
//! reflection): most of them are rays that reach the outline texel behind its visible surface and
//! truly hit the sphere's underside, hidden from the camera (the on-screen reference shows the
//! sky there). A mip-0 slab that ends where the texel's visible surface does (the G-buffer's far
//! depth, `shader_core::ssr::trace::slab_base`) removes them.
//!
//! Measure (the one of docs/ssr.md's table): mirror pixels (perceptual roughness 0) in the inner
//! 80% of the screen whose tone-mapped SSR composite differs from the on-screen reference (1 ray,
//! exact for mirrors) by more than 0.1 in some channel ("wrong"), and among them those where the
//! reference sees the sky ("false hits": SSR shows a hit where there is none).

use host::ssr::metrics::{composite, tonemap};
use host::ssr::sssr::{run_sssr, SssrSettings};
use host::ssr::{render_reference, run_hdrp, scene, HdrpResolve, SsrSettings, TraceMode};
use host::Backend;

/// Wrong and false-hit mirror pixels of one pipeline on one frame.
#[derive(Clone, Copy, Debug)]
struct EdgeErrors {
    mirror: usize,
    wrong: usize,
    false_hits: usize,
}

/// Which pipeline produces the reflection.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Pipeline {
    /// HDRP, Hi-Z tracing, SSR_APPROX resolve (mirror rays).
    Hdrp,
    /// Stochastic SSR, one frame, default settings (Hi-Z for every ray; mirrors trace mirror rays).
    Sssr,
}

/// The measure of the module doc for `name` at `w` x `h`, for each pipeline asked for.
fn measure(name: &str, w: usize, h: usize, pipelines: &[Pipeline]) -> Vec<EdgeErrors> {
    let sc = scene(name).unwrap();
    let g = sc.render_gbuffer(w, h, 0);
    let reference = render_reference(&sc, &g, 0.0, 1);
    let want = tonemap(&reference.onscreen);
    let s = SsrSettings::default();
    pipelines
        .iter()
        .map(|&pl| {
            let res = match pl {
                Pipeline::Hdrp => run_hdrp(&Backend::Cpu, &g, &s, TraceMode::HiZ, HdrpResolve::Approx).unwrap(),
                Pipeline::Sssr => run_sssr(&Backend::Cpu, Some(&sc), &g, &s, &SssrSettings::default(), 0, 1).unwrap(),
            };
            let got = tonemap(&composite(&res.reflection, g.fallback));
            let mut e = EdgeErrors { mirror: 0, wrong: 0, false_hits: 0 };
            let (x0, x1, y0, y1) = (w / 10, w - w / 10, h / 10, h - h / 10);
            for y in y0..y1 {
                for x in x0..x1 {
                    let i = y * w + x;
                    if !(g.depth[i].is_finite() && g.roughness[i] == 0.0 && reference.glossy[i]) {
                        continue;
                    }
                    e.mirror += 1;
                    let differs = (0..3).any(|k| (got[3 * i + k] - want[3 * i + k]).abs() > 0.1);
                    if differs {
                        e.wrong += 1;
                        if reference.mirror_hit[2 * i].is_nan() {
                            e.false_hits += 1;
                        }
                    }
                }
            }
            eprintln!("{name} {w}x{h} {pl:?}: {} mirror pixels, {} wrong ({} false hits)", e.mirror, e.wrong, e.false_hits);
            e
        })
        .collect()
}

/// The fringes on `floor` at 1080p, HDRP (Hi-Z, SSR_APPROX) and stochastic SSR. With HDRP's
/// constant 1% slab both had 8263 wrong pixels, 898 of them false hits (docs/ssr.md); the
/// far-depth slab has 7505 (268, single pixels along the edges): asserted below 450 and 7900.
#[test]
fn floor_1080p_sphere_reflection_edges_have_no_fringes() {
    let r = measure("floor", 1920, 1080, &[Pipeline::Hdrp, Pipeline::Sssr]);
    for (pl, e) in [Pipeline::Hdrp, Pipeline::Sssr].iter().zip(&r) {
        assert!(e.mirror > 100_000, "{pl:?}: too few mirror pixels to measure ({})", e.mirror);
        assert!(e.false_hits < 450, "{pl:?}: {} false hits along the reflections' edges (fringes)", e.false_hits);
        assert!(e.wrong < 7900, "{pl:?}: {} wrong mirror pixels", e.wrong);
    }
}

/// docs/ssr.md's before/after table: floor and thin at 1080p and 128x128 (HDRP Hi-Z, SSR_APPROX;
/// and SSSR). Run with `--ignored --nocapture`.
#[test]
#[ignore]
fn fringe_table() {
    for (w, h) in [(1920, 1080), (128, 128)] {
        for name in ["floor", "thin"] {
            measure(name, w, h, &[Pipeline::Hdrp, Pipeline::Sssr]);
        }
    }
}
