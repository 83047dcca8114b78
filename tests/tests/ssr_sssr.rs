//! SSR stage 5: the stochastic pipeline's passes CPU vs GPU (0 ULP), the compacted ray list,
//! tile classification, and the effect of ray reuse and temporal accumulation.

use crosscheck::{compare_outputs, gpu_backend};
use host::ssr::cli::errors;
use host::ssr::pipeline::Runner;
use host::ssr::sssr::{expected_list, run_sssr, sssr_params, SssrSettings};
use host::ssr::{render_reference, scene, SsrSettings};
use host::Backend;
use shader_core::ssr::stochastic::{HISTORY_STRIDE, LIST_STRIDE, TILE_SKIP, TILE_STRIDE};
use shader_core::ssr::trace::RAY_STRIDE;

const W: usize = 128;
const H: usize = 96;

fn assert_same(what: &str, stride: usize, cpu: &[f32], gpu: &[f32]) {
    let cols: Vec<String> = (0..stride).map(|k| format!("{what}[{k}]")).collect();
    let refs: Vec<&str> = cols.iter().map(|s| s.as_str()).collect();
    let rep = compare_outputs(&refs, cpu, gpu);
    let diff: usize = rep.iter().map(|c| c.differing).sum();
    let first = rep.iter().find_map(|c| c.first_difference.map(|d| (c.name.clone(), d)));
    eprintln!("{what}: {} values compared, {diff} differ", cpu.len());
    assert_eq!(diff, 0, "{what}: CPU and GPU differ; first: {first:?}");
}

/// Every stochastic pass on both backends, for 1/2/4 rays per quad, 1/4 rays per pixel, with and
/// without reuse: identical bits, and the same ray list as the CPU-side expectation.
#[test]
fn sssr_passes_match_gpu_bit_for_bit() {
    let Some(gpu) = gpu_backend() else { return };
    for name in ["floor", "hallway"] {
        let g = scene(name).unwrap().render_gbuffer(W, H, 0);
        let gbuf = g.packed();
        for (rpq, spp, reuse) in [(4, 1, true), (2, 1, true), (1, 4, true), (4, 4, false)] {
            let s = SsrSettings { frame: 5, ..SsrSettings::default() };
            let t = SssrSettings { rays_per_quad: rpq, samples_per_pixel: spp, reuse, ..SssrSettings::default() };
            let consts = sssr_params(&g, &s, &t).unwrap();
            let tag = format!("{name} rpq {rpq} spp {spp} reuse {reuse}");
            let mut c = Runner::new(&Backend::Cpu);
            let mut q = Runner::new(gpu);
            let dp = c.depth_pyramid(&consts, &g.depth).unwrap();
            let cp = c.color_pyramid(&consts, &g.color).unwrap();
            let tiles = c.sssr_classify(&consts, &gbuf).unwrap();
            assert_same(&format!("{tag} classify"), TILE_STRIDE, &tiles, &q.sssr_classify(&consts, &gbuf).unwrap());
            let off = c.sssr_prefix(&tiles).unwrap();
            assert_same(&format!("{tag} prefix"), 1, &off, &q.sssr_prefix(&tiles).unwrap());
            let list = c.sssr_emit(&consts, &gbuf, &off).unwrap();
            assert_same(&format!("{tag} list"), LIST_STRIDE, &list, &q.sssr_emit(&consts, &gbuf, &off).unwrap());
            let count = off[off.len() - 1].to_bits() as usize;
            let want = expected_list(&g, &s, &t).unwrap();
            assert_eq!(count, want.len(), "{tag}: ray count");
            for (k, (pixel, smp)) in want.iter().enumerate() {
                assert_eq!(list[k * LIST_STRIDE].to_bits(), *pixel, "{tag}: entry {k}");
                assert_eq!(list[k * LIST_STRIDE + 1].to_bits() & 0xff, *smp, "{tag}: entry {k}");
            }
            let rays = c.sssr_trace(&consts, &gbuf, &dp, &list, count).unwrap();
            assert_same(&format!("{tag} trace"), RAY_STRIDE, &rays, &q.sssr_trace(&consts, &gbuf, &dp, &list, count).unwrap());
            let res = c.sssr_resolve(&consts, &gbuf, &cp, &rays).unwrap();
            assert_same(&format!("{tag} resolve"), 4, &res, &q.sssr_resolve(&consts, &gbuf, &cp, &rays).unwrap());
            // Temporal: a history that is the resolve itself shifted by a frame count.
            let hist: Vec<f32> = res.chunks_exact(4).flat_map(|c| [c[0] * 0.5, c[1], c[2] * 2.0, c[3], 3.0]).collect();
            let tc = c.sssr_temporal(&consts, &gbuf, &res, &hist).unwrap();
            assert_same(&format!("{tag} temporal"), HISTORY_STRIDE, &tc, &q.sssr_temporal(&consts, &gbuf, &res, &hist).unwrap());
        }
    }
}

/// Tiles of sky or of too-rough surfaces are skipped; every eligible pixel of a 4-rays-per-quad
/// run gets a ray, and 1 ray per quad traces about a quarter of them (plus every mirror pixel).
#[test]
fn tile_classification_skips_sky_and_rough_tiles() {
    let g = scene("floor").unwrap().render_gbuffer(W, H, 0);
    let s = SsrSettings::default();
    let full = run_sssr(&Backend::Cpu, None, &g, &s, &SssrSettings::default(), 0, 1).unwrap();
    let t = full.tiles.unwrap();
    eprintln!("tiles {} skipped {} rays {} eligible {}", t.tiles, t.skipped, t.rays, t.eligible_pixels);
    assert!(t.skipped * 5 > t.tiles, "a fifth of the tiles (the sky) should be skipped");
    assert_eq!(t.rays, t.eligible_pixels);
    // The tiles of the top rows are sky.
    assert_eq!(t.classes[0], TILE_SKIP);
    let sparse = run_sssr(&Backend::Cpu, None, &g, &s, &SssrSettings { rays_per_quad: 1, ..SssrSettings::default() }, 0, 1).unwrap();
    let ts = sparse.tiles.unwrap();
    let mirror = (0..W * H).filter(|&i| g.depth[i].is_finite() && g.roughness[i] < 0.03).count();
    eprintln!("1 ray per quad: {} rays, {mirror} mirror pixels", ts.rays);
    assert!(ts.rays < mirror + (t.eligible_pixels - mirror) / 4 + W * H / 64, "{}", ts.rays);
    assert!(ts.rays >= mirror);
}

/// Reuse and temporal accumulation lower the error of a sparse (1 ray per quad) run.
#[test]
fn reuse_and_temporal_accumulation_reduce_error() {
    let sc = scene("floor").unwrap();
    let g = sc.render_gbuffer(W, H, 0);
    let s = SsrSettings::default();
    let r = render_reference(&sc, &g, 0.6, 64);
    let glossy_only = |res: &host::ssr::SsrResult| {
        // Error over non-mirror glossy pixels: where sampling noise lives.
        let mut rr = r.clone();
        for i in 0..W * H {
            rr.glossy[i] = rr.glossy[i] && g.roughness[i] >= 0.03;
        }
        errors(res, &rr, sc.sky).algorithm
    };
    let base = SssrSettings { rays_per_quad: 1, ..SssrSettings::default() };
    let no_reuse = run_sssr(&Backend::Cpu, None, &g, &s, &SssrSettings { reuse: false, ..base.clone() }, 0, 1).unwrap();
    let reuse = run_sssr(&Backend::Cpu, None, &g, &s, &base, 0, 1).unwrap();
    let temporal = run_sssr(&Backend::Cpu, None, &g, &s, &SssrSettings { temporal_frames: 16, ..base.clone() }, 0, 16).unwrap();
    let (a, b, c) = (glossy_only(&no_reuse), glossy_only(&reuse), glossy_only(&temporal));
    eprintln!("1 ray/quad: no reuse {:.4}, reuse {:.4}, reuse + 16 temporal frames {:.4} (RMSE)", a.rmse, b.rmse, c.rmse);
    assert!(b.rmse < a.rmse, "reuse should help");
    assert!(c.rmse < b.rmse, "temporal accumulation should help");
}
