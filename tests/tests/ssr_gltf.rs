//! SSR on real scenes: every HDRP and stochastic pass CPU vs GPU (0 ULP) on G-buffers that the
//! path tracer exports from the SSR benchmark's glTF scenes (`host::ssr::gltf_scenes`: the Cornell
//! box with a glossy floor, thin objects over floor strips of four roughnesses, an orbiting
//! camera), each with its far-depth layer; the orbit scene's temporal pass with its previous
//! frame.

use crosscheck::ssr::sssr_passes_bit_equal;
use crosscheck::{assert_bits_equal, gpu_backend};
use host::render::environment::{self as env, EnvSpec};
use host::render::gbuffer::{export_frame, FrameSpec, Quiet};
use host::render::scene::Scene;
use host::render::RenderInputs;
use host::ssr::gltf_scenes::{GltfScene, NAMES};
use host::ssr::pipeline::{build_params, HdrpResolve, Runner};
use host::ssr::sssr::{sssr_params, SssrSettings};
use host::ssr::{GBuffer, SsrSettings};
use host::Backend;
use shader_core::pt::integrator::{RenderParams, STRATEGY_MIS};
use shader_core::ssr::params::{TRACE_BRUTE_FORCE, TRACE_HIZ, TRACE_LINEAR};
use shader_core::ssr::resolve::HIT_STRIDE;
use shader_core::ssr::trace::RAY_STRIDE;

const CORNELL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");
const W: u32 = 96;
const H: u32 = 64;

/// Frames 0 and 1 of `which` (its camera path, or twice the static view), exported on the CPU
/// at 2 spp without a reference.
fn frames(which: GltfScene, dir: &std::path::Path) -> (GBuffer, GBuffer) {
    let path = which.write(dir, Some(std::path::Path::new(CORNELL))).unwrap();
    let sc = Scene::load(&path).unwrap();
    let e = env::build(&EnvSpec::Uniform(which.sky()), 1.0, 0.0).unwrap();
    let lut = vec![0.0; shader_core::energy::LUT_HEADER];
    let inputs = RenderInputs { scene: &sc.words, env: &e.words, lut: &lut };
    let base = sc.cameras[0].clone();
    let pivot = sc.bounds.bounding_sphere().0;
    let cam = |k: f64| base.orbited(pivot, k * which.orbit().unwrap_or(0.0)).kernel(W, H).unwrap();
    let one = |k: f64| {
        let params = RenderParams {
            width: W,
            height: H,
            spp: 1,
            sample_base: 0,
            seed: 5,
            max_depth: 4,
            rr_depth: 3,
            strategy: STRATEGY_MIS,
            compensation: shader_core::energy::COMP_NONE,
            sampler: shader_core::pt::sampler::SAMPLER_PCG,
            clamp: 0.0,
            p_env: if sc.has_lights() { 0.5 } else { 1.0 },
            camera: cam(k),
        };
        let spec = FrameSpec { params, previous: cam(k - 1.0), spp: 2, spp_per_pass: 2, reference_spp: 0, max_roughness: 0.6, fallback: which.sky(), near: 0.01 };
        export_frame(&Backend::Cpu, &inputs, &spec, None, None, &mut Quiet).unwrap().gbuffer
    };
    (one(0.0), one(1.0))
}

#[test]
fn ssr_passes_match_gpu_bit_for_bit_on_gltf_scenes() {
    let Some(gpu) = gpu_backend() else { return };
    let dir = std::env::temp_dir().join(format!("ssr_gltf_{}", std::process::id()));
    for name in NAMES {
        let which = GltfScene::by_name(name).unwrap();
        let (g0, g) = frames(which, &dir);
        assert!(g.depth_far.is_some(), "{name}: the export carries the far depth");
        let glossy = g.roughness.iter().zip(&g.depth).filter(|(r, d)| **r <= 0.6 && d.is_finite()).count();
        assert!(glossy > (W * H) as usize / 20, "{name}: only {glossy} glossy pixels");
        let gbuf = g.packed();
        let mut c = Runner::new(&Backend::Cpu);
        let mut q = Runner::new(gpu);
        // HDRP: pyramids, every tracer, every resolve.
        let s = SsrSettings::default();
        let mut consts = build_params(&g, &s).unwrap();
        let dp = c.depth_pyramid(&consts, &g.depth_layers()).unwrap();
        assert_bits_equal(&format!("{name} depth pyramid"), 1, &dp, &q.depth_pyramid(&consts, &g.depth_layers()).unwrap());
        let cp = c.color_pyramid(&consts, &g.color).unwrap();
        assert_bits_equal(&format!("{name} colour pyramid"), 3, &cp, &q.color_pyramid(&consts, &g.color).unwrap());
        let pixels = c.hdrp_pixels(&consts, &gbuf).unwrap();
        assert_bits_equal(&format!("{name} HDRP pixel list"), 1, &pixels, &q.hdrp_pixels(&consts, &gbuf).unwrap());
        let mut hits = 0;
        for (mode, steps) in [(TRACE_HIZ, 0), (TRACE_LINEAR, 32), (TRACE_BRUTE_FORCE, 0)] {
            consts.trace_mode = mode;
            consts.linear_steps = steps.max(1);
            let rc = c.hdrp_trace(&consts, &gbuf, &dp, &pixels).unwrap();
            assert_bits_equal(&format!("{name} HDRP trace mode {mode}"), RAY_STRIDE, &rc, &q.hdrp_trace(&consts, &gbuf, &dp, &pixels).unwrap());
            let hc = c.ray_hits(&consts, &gbuf, &cp, &rc).unwrap();
            assert_bits_equal(&format!("{name} HDRP hit records mode {mode}"), HIT_STRIDE, &hc, &q.ray_hits(&consts, &gbuf, &cp, &rc).unwrap());
            hits += rc.chunks_exact(RAY_STRIDE).filter(|r| r[shader_core::ssr::trace::RAY_INFO].to_bits() & shader_core::ssr::trace::info::HIT != 0).count();
            for m in [HdrpResolve::Approx, HdrpResolve::Block3x3, HdrpResolve::Cross5] {
                let oc = c.hdrp_reproject(&consts, &gbuf, &cp, &rc, &pixels, m).unwrap();
                assert_bits_equal(&format!("{name} HDRP resolve {}", m.label()), 4, &oc, &q.hdrp_reproject(&consts, &gbuf, &cp, &rc, &pixels, m).unwrap());
            }
        }
        assert!(hits > 100, "{name}: only {hits} hits over three tracers: the comparison would prove little");
        // Stochastic: classify, scan, emit, trace, resolve, hit distance, temporal (both
        // reprojections, the previous frame's G-buffer for rejection).
        for t in [SssrSettings::default(), SssrSettings { rays_per_quad: 1, samples_per_pixel: 4, ..SssrSettings::default() }] {
            let s = SsrSettings { frame: 3, ..SsrSettings::default() };
            let mut consts = sssr_params(&g, &s, &t).unwrap();
            let tag = format!("{name} SSSR rpq {} spp {}", t.rays_per_quad, t.samples_per_pixel);
            let f = sssr_passes_bit_equal(&tag, &mut c, &mut q, &mut consts, &gbuf, &g0.packed(), &dp, &cp);
            assert!(f.count > 0, "{tag}: no rays");
        }
        // The specular pass with the G-buffer's base colours.
        let lut = host::energy::precompute(&Backend::Cpu, &host::energy::TableSpec::default(), None).unwrap().0.lut_buffer();
        let consts = build_params(&g, &SsrSettings::default()).unwrap();
        let refl: Vec<f32> = g.color.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 1.0]).collect();
        let sc = c.specular(&consts, &gbuf, &g.base_color, &lut, &refl).unwrap();
        assert_bits_equal(&format!("{name} specular"), 4, &sc, &q.specular(&consts, &gbuf, &g.base_color, &lut, &refl).unwrap());
    }
    std::fs::remove_dir_all(&dir).ok();
}
