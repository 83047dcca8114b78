//! The path tracer CPU vs GPU (0 ULP): every pixel of the radiance and of every AOV, on the
//! built-in scene for every estimator and compensation mode (Sobol samples) and with PCG samples, on the Cornell box of `scenes/cornell_box/` over
//! several progressive launches (stopped by an error target, and with adaptive sampling's pixel lists), and on a test-made scene with textures, a normal map, an alpha
//! mask, transmission, punctual lights and an environment map; the G-buffer / SSR reference
//! kernel (`render::pt_gbuffer`) on the Cornell box and the feature scene over progressive
//! launches.

use crosscheck::{assert_bits_equal, gpu_backend};
use host::energy::{self, Compensation, TableSpec};
use host::render::environment::{self as env, EnvSpec};
use host::render::scene::{LightKind, Mat4, Material, MeshData, PunctualLight, Scene, SceneBuilder, Texture, UvTransform, Wrap, AlphaMode, Camera, Projection};
use host::render::{self, RenderImage, RenderInputs};
use host::Backend;
use shader_core::pt::integrator::{RenderParams, STRATEGY_BSDF, STRATEGY_LIGHT, STRATEGY_MIS};
use shader_core::pt::sampler::{SAMPLER_PCG, SAMPLER_SOBOL};

fn lut() -> Vec<f32> {
    let spec = TableSpec { n_mu: 16, n_r: 16, n_avg: 16, samples: 256, avg_samples: 512, chunk: 256, ..TableSpec::default() };
    energy::precompute(&Backend::Cpu, &spec, None).unwrap().0.lut_buffer()
}

fn params(scene: &Scene, w: u32, h: u32, strategy: u32, compensation: u32, p_env: f32) -> RenderParams {
    let cam = match scene.cameras.first() {
        Some(c) => c.clone(),
        None => host::render::scene::Camera::framing(&scene.bounds),
    };
    RenderParams {
        width: w,
        height: h,
        spp: 1,
        sample_base: 0,
        seed: 7,
        max_depth: 6,
        rr_depth: 2,
        strategy,
        compensation,
        sampler: SAMPLER_SOBOL,
        clamp: 0.0,
        p_env,
        camera: cam.kernel(w, h).unwrap(),
    }
}

fn compare(tag: &str, c: &RenderImage, g: &RenderImage) {
    assert_bits_equal(&format!("{tag} colour"), 3, &c.color, &g.color);
    assert_bits_equal(&format!("{tag} albedo"), 3, &c.albedo, &g.albedo);
    assert_bits_equal(&format!("{tag} normal"), 3, &c.normal, &g.normal);
    assert_bits_equal(&format!("{tag} depth"), 1, &c.depth, &g.depth);
    assert_eq!(c.rays, g.rays, "{tag}: rays traced");
    let lit = c.color.iter().filter(|v| **v > 0.0).count();
    assert!(lit > c.color.len() / 50, "{tag}: only {lit} of {} values lit: the comparison would prove little", c.color.len());
}

fn both(tag: &str, gpu: &Backend, inputs: &RenderInputs<'_>, p: &RenderParams, spp: u32, per_pass: u32) {
    let (c, _) = render::render(&Backend::Cpu, inputs, p, spp, per_pass, |_| {}).unwrap();
    let (g, _) = render::render(gpu, inputs, p, spp, per_pass, |_| {}).unwrap();
    compare(tag, &c, &g);
}

#[test]
fn builtin_scene_every_strategy_and_compensation() {
    let Some(gpu) = gpu_backend() else { return };
    let scene = Scene::builtin(8);
    let lut = lut();
    let black = env::build(&EnvSpec::Black, 1.0, 0.0).unwrap();
    let inputs = RenderInputs { scene: &scene.words, env: &black.words, lut: &lut };
    for (strategy, name) in [(STRATEGY_MIS, "mis"), (STRATEGY_BSDF, "bsdf"), (STRATEGY_LIGHT, "light")] {
        for comp in Compensation::ALL {
            let p = params(&scene, 40, 30, strategy, comp.id(), 0.0);
            both(&format!("builtin {name} {}", comp.label()), gpu, &inputs, &p, 2, 2);
        }
    }
    // The other sampler: independent PCG32 numbers.
    let p = RenderParams { sampler: SAMPLER_PCG, ..params(&scene, 40, 30, STRATEGY_MIS, Compensation::Turquin.id(), 0.0) };
    both("builtin mis turquin pcg", gpu, &inputs, &p, 2, 2);
}

#[test]
fn cornell_box_progressive_launches() {
    let Some(gpu) = gpu_backend() else { return };
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");
    let scene = Scene::load(path).unwrap();
    let lut = lut();
    let sky = env::build(&EnvSpec::Uniform([1.0, 0.9, 0.8]), 1.0, 0.0).unwrap();
    let inputs = RenderInputs { scene: &scene.words, env: &sky.words, lut: &lut };
    let p = params(&scene, 32, 32, STRATEGY_MIS, Compensation::Turquin.id(), 1.0);
    both("cornell box", gpu, &inputs, &p, 3, 1);
    // --target-error's stop rule reads only the sums: both backends stop after the same launch
    // with the same image.
    let p = params(&scene, 16, 16, STRATEGY_MIS, Compensation::Turquin.id(), 1.0);
    let until = |b: &Backend| render::render_until(b, &inputs, &p, 256, 2, |_| {}, |acc| acc.error_estimate().is_some_and(|e| e <= 0.2)).unwrap().0;
    let (c, g) = (until(&Backend::Cpu), until(gpu));
    assert!(c.spp < 256, "the target error was not reached");
    assert_eq!(c.spp, g.spp, "the backends stopped at different sample counts");
    compare("cornell box, stopped at --target-error 0.2", &c, &g);
    // Adaptive sampling: the same pixels stop after the same launches (pixel lists launched).
    let rule = render::Adaptive { threshold: 0.15, min_spp: 4 };
    let adaptive = |b: &Backend| render::render_adaptive(b, &inputs, &p, 64, 2, Some(rule), |_| {}, |_| false).unwrap().0;
    let (c, g) = (adaptive(&Backend::Cpu), adaptive(gpu));
    assert!(c.pixel_spp.iter().any(|&n| n < 64), "no pixel stopped early");
    assert_eq!(c.pixel_spp, g.pixel_spp, "the backends stopped different pixels");
    compare("cornell box, adaptive sampling", &c, &g);
}

/// A quad floor with a checker base-colour texture and a bumpy normal map (each through a
/// `KHR_texture_transform` of its own) and a masked cut-out, a
/// glass sphere-ish box (transmission), a rough metal quad, point, spot and directional lights
/// and an equirectangular environment.
fn feature_scene() -> (Scene, env::Environment) {
    let mut b = SceneBuilder::new("test: every material feature");
    let n = 16u32;
    let checker: Vec<u8> = (0..n * n).flat_map(|i| if ((i % n) / 4 + (i / n) / 4).is_multiple_of(2) { [230, 200, 40, 255] } else { [30, 60, 200, 120] }).collect();
    let bumps: Vec<u8> = (0..n * n).flat_map(|i| [128 + ((i % n) as u8) * 6, 128 - ((i / n) as u8) * 5, 230, 255]).collect();
    let tex = |name: &str, rgba: Vec<u8>, wrap: Wrap, nearest: bool| Texture { name: name.into(), width: n, height: n, rgba, wrap_s: wrap, wrap_t: Wrap::Mirror, nearest };
    let t_base = b.texture(tex("checker", checker, Wrap::Repeat, false)).unwrap();
    let t_normal = b.texture(tex("bumps", bumps, Wrap::Clamp, true)).unwrap();
    let floor_m = b.material(Material {
        base_color_texture: Some(t_base),
        normal_texture: Some(t_normal),
        base_color_uv: UvTransform { offset: [0.3, -0.1], rotation: 0.35, scale: [1.25, 0.8] },
        normal_uv: UvTransform { offset: [0.0, 0.5], rotation: 0.0, scale: [2.0, 2.0] },
        alpha_mode: AlphaMode::Mask(0.5),
        ..Material::pbr("floor", [1.0, 1.0, 1.0], 0.0, 0.6)
    });
    let glass = b.material(Material { transmission: 1.0, ior: 1.45, ..Material::pbr("glass", [1.0, 1.0, 1.0], 0.0, 0.1) });
    let metal = b.material(Material::pbr("metal", [0.9, 0.6, 0.5], 1.0, 0.35));
    let quad = |y: f32, s: f32, uv_scale: f32| MeshData {
        name: "quad".into(),
        positions: vec![[-s, y, -s], [s, y, -s], [s, y, s], [-s, y, s]],
        normals: Some(vec![[0.0, 1.0, 0.0]; 4]),
        uvs: Some(vec![[0.0, 0.0], [uv_scale, 0.0], [uv_scale, uv_scale], [0.0, uv_scale]]),
        tangents: Some(vec![[1.0, 0.0, 0.0, 1.0]; 4]),
        indices: Some(vec![0, 2, 1, 0, 3, 2]),
    };
    b.mesh(&quad(0.0, 2.0, 3.0), floor_m, &Mat4::IDENTITY).unwrap();
    b.mesh(&quad(0.0, 0.5, 1.0), metal, &Mat4::translation(glam::DVec3::new(1.0, 0.4, -0.5))).unwrap();
    let cube = MeshData {
        name: "cube".into(),
        positions: vec![[-0.4, 0.0, -0.4], [0.4, 0.0, -0.4], [0.4, 0.8, -0.4], [-0.4, 0.8, -0.4], [-0.4, 0.0, 0.4], [0.4, 0.0, 0.4], [0.4, 0.8, 0.4], [-0.4, 0.8, 0.4]],
        indices: Some(vec![0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5, 3, 7, 6, 3, 6, 2, 0, 1, 5, 0, 5, 4]),
        ..MeshData::default()
    };
    b.mesh(&cube, glass, &Mat4::translation(glam::DVec3::new(-0.6, 0.01, 0.2))).unwrap();
    b.light(PunctualLight { name: "point".into(), kind: LightKind::Point, position: [0.5, 2.0, 1.0], direction: [0.0, -1.0, 0.0], intensity: [8.0, 7.0, 6.0], range: 10.0 });
    b.light(PunctualLight { name: "spot".into(), kind: LightKind::Spot { inner_cone: 0.3, outer_cone: 0.6 }, position: [-1.0, 2.5, 0.0], direction: [0.3, -1.0, 0.0], intensity: [20.0, 20.0, 25.0], range: 0.0 });
    b.light(PunctualLight { name: "sun".into(), kind: LightKind::Directional, position: [0.0; 3], direction: [-0.3, -0.8, -0.5], intensity: [1.5, 1.4, 1.2], range: 0.0 });
    b.camera(Camera { name: "test".into(), position: [0.0, 1.6, 3.0], forward: [0.0, -0.45, -0.89], up: [0.0, 0.89, -0.45], projection: Projection::Perspective { yfov: 0.9, aspect: None } });
    let scene = b.build().unwrap();
    let (w, h) = (16u32, 8u32);
    let map: Vec<f32> = (0..w * h).flat_map(|i| { let y = (i / w) as f32; [0.2 + 0.1 * y, 0.3, 0.1 + 0.05 * (i % w) as f32] }).collect();
    let e = env::from_map(w, h, &map, 1.0, 30.0).unwrap();
    (scene, e)
}

#[test]
fn feature_scene_with_environment_map() {
    let Some(gpu) = gpu_backend() else { return };
    let (scene, e) = feature_scene();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let lut = lut();
    let inputs = RenderInputs { scene: &scene.words, env: &e.words, lut: &lut };
    for comp in [Compensation::Turquin, Compensation::KullaConty] {
        let p = params(&scene, 32, 24, STRATEGY_MIS, comp.id(), 0.5);
        both(&format!("feature scene {}", comp.label()), gpu, &inputs, &p, 2, 1);
    }
}

/// The G-buffer kernel CPU vs GPU: every output value (G-buffer, reference sums, ray counts)
/// over two progressive launches.
fn gbuffer_both(tag: &str, gpu: &Backend, inputs: &RenderInputs<'_>, p: &RenderParams, max_roughness: f32) {
    use host::render::gbuffer::render_gbuffer;
    use shader_core::pt::gbuffer::GBufferParams;
    let gp = GBufferParams { render: *p, max_roughness, fallback: shader_core::Vec3::new(0.25, 0.5, 0.75) };
    let (c, _) = render_gbuffer(&Backend::Cpu, inputs, &gp, 3, 2, |_| {}).unwrap();
    let (g, _) = render_gbuffer(gpu, inputs, &gp, 3, 2, |_| {}).unwrap();
    assert_bits_equal(&format!("{tag} G-buffer + reference"), shader_kernels::render::GBUFFER_STRIDE, &c.words(), &g.words());
    let glossy = c.pixels.iter().filter(|px| px.glossy != 0 && px.weight > 0.0 && px.all.x > 0.0).count();
    assert!(glossy > c.pixels.len() / 20, "{tag}: only {glossy} glossy pixels with reference radiance: the comparison would prove little");
}

#[test]
fn gbuffer_and_reference_cornell_box_and_feature_scene() {
    let Some(gpu) = gpu_backend() else { return };
    let lut = lut();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");
    let scene = Scene::load(path).unwrap();
    let sky = env::build(&EnvSpec::Uniform([1.0, 0.9, 0.8]), 1.0, 0.0).unwrap();
    let inputs = RenderInputs { scene: &scene.words, env: &sky.words, lut: &lut };
    gbuffer_both("cornell box", gpu, &inputs, &params(&scene, 32, 32, STRATEGY_MIS, Compensation::Turquin.id(), 1.0), 1.0);
    let (scene, e) = feature_scene();
    let inputs = RenderInputs { scene: &scene.words, env: &e.words, lut: &lut };
    gbuffer_both("feature scene", gpu, &inputs, &params(&scene, 32, 24, STRATEGY_MIS, Compensation::Turquin.id(), 0.5), 0.7);
}
