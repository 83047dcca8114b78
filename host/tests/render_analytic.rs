//! The path tracer against closed forms and against itself (CPU backend; the GPU gives the same
//! bits, tests/tests/render_crosscheck.rs):
//! * white furnace: the compensated metal (base 1) reflects 1 within 1e-3 at every roughness and
//!   angle with Turquin or Kulla-Conty, and the energy table's E(mu, r) without (stratified
//!   estimate of the material's integral), and a coloured metal (F0 = 0.5) follows each
//!   compensation's formula; rendered on a plane under a uniform environment it
//!   gives the same within the Monte-Carlo error; a compensated dielectric plane renders the
//!   furnace kernel's albedo;
//! * a plane under a directional and a point light: every pixel equals f cos E (f from the
//!   material, E = irradiance at normal incidence, or I / d^2) to 1e-5;
//! * the three estimators (MIS, BSDF only, light only) agree on every 4x4 block of the built-in
//!   scene within 6 standard errors, and so does MIS with Sobol samples; the error falls as
//!   spp^-1/2 with PCG samples and as fast or faster, and lower, with Sobol samples;
//! * an emissive quad filling a plane's hemisphere lights it as a uniform sky does (MIS and BSDF
//!   sampling), and a small one gives the same mean with each estimator, which fails if either
//!   half of the MIS estimate loses its weight;
//! * the environment map's sampling density is what `pdf` says and integrates to 1.

use host::energy::{self, Compensation, TableSpec};
use host::render::environment::{self as env, EnvSpec};
use host::render::scene::{LightKind, Mat4, Material, MeshData, PunctualLight, Scene, SceneBuilder};
use host::render::scene::{Camera, Projection};
use host::render::{self, RenderImage, RenderInputs};
use host::Backend;
use shader_core::pt::integrator::{RenderParams, STRATEGY_BSDF, STRATEGY_LIGHT, STRATEGY_MIS};
use shader_core::pt::material::Material as Bsdf;
use shader_core::pt::sampler::{SAMPLER_PCG, SAMPLER_SOBOL};
use shader_core::pt::surface::MaterialPoint;
use shader_core::Vec3;
use std::sync::OnceLock;

fn lut() -> &'static [f32] {
    static LUT: OnceLock<Vec<f32>> = OnceLock::new();
    LUT.get_or_init(|| energy::precompute(&Backend::Cpu, &TableSpec::default(), None).unwrap().0.lut_buffer())
}

/// A square of half size `s` at height 0 facing +y.
fn plane(s: f32) -> MeshData {
    MeshData {
        name: "plane".into(),
        positions: vec![[-s, 0.0, -s], [s, 0.0, -s], [s, 0.0, s], [-s, 0.0, s]],
        normals: Some(vec![[0.0, 1.0, 0.0]; 4]),
        indices: Some(vec![0, 2, 1, 0, 3, 2]),
        ..MeshData::default()
    }
}

fn plane_scene(m: Material, lights: &[PunctualLight]) -> Scene {
    let mut b = SceneBuilder::new("test plane");
    let id = b.material(m);
    b.mesh(&plane(50.0), id, &Mat4::IDENTITY).unwrap();
    for l in lights {
        b.light(l.clone());
    }
    b.build().unwrap()
}

/// An orthographic camera looking at the origin from polar angle `theta` (in the xy plane).
fn ortho_at(theta: f32) -> Camera {
    let wo = [theta.sin(), theta.cos(), 0.0];
    Camera::look("ortho", [5.0 * wo[0], 5.0 * wo[1], 0.0], [-wo[0], -wo[1], 0.0], [0.0, 0.0, 1.0], Projection::Orthographic { xmag: 0.5, ymag: 0.5 })
}

fn params(cam: &Camera, w: u32, h: u32, strategy: u32, comp: Compensation, p_env: f32, max_depth: u32, seed: u32) -> RenderParams {
    RenderParams { width: w, height: h, spp: 1, sample_base: 0, seed, max_depth, rr_depth: 64, strategy, compensation: comp.id(), sampler: shader_core::pt::sampler::SAMPLER_PCG, clamp: 0.0, p_env, camera: cam.kernel(w, h).unwrap() }
}

fn render(scene: &Scene, e: &env::Environment, p: &RenderParams, spp: u32) -> RenderImage {
    let inputs = RenderInputs { scene: &scene.words, env: &e.words, lut: lut() };
    render::render(&Backend::Cpu, &inputs, p, spp, spp, |_| {}).unwrap().0
}

fn mean(v: &[f32]) -> f64 {
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64
}

/// Mean red radiance of the furnace plane seen from `theta`.
fn furnace(m: Material, theta: f32, comp: Compensation) -> f64 {
    let scene = plane_scene(m, &[]);
    let white = env::build(&EnvSpec::Uniform([1.0; 3]), 1.0, 0.0).unwrap();
    let p = params(&ortho_at(theta), 64, 64, STRATEGY_BSDF, comp, 1.0, 4, 1);
    let img = render(&scene, &white, &p, 256);
    let red: Vec<f32> = img.color.iter().step_by(3).copied().collect();
    mean(&red)
}

/// int f(wo, wi) cos dwi of the path tracer's material over a stratified 512 x 512 grid of
/// (u0, u1): two samples per point, the material's own and a cosine-weighted one, combined by
/// the balance heuristic (the cosine samples cover the Kulla-Conty lobe, which the visible-normal
/// samples of a low roughness reach only in their tails).
fn material_albedo(m: &MaterialPoint, theta: f32, comp: Compensation) -> f64 {
    let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
    let bsdf = Bsdf::new(m, wo, lut(), comp.id());
    let n = 512;
    let mut sum = 0.0f64;
    let term = |wi: Vec3| -> f64 {
        let p = 0.5 * bsdf.pdf(wo, wi) as f64 + 0.5 * (wi.z.max(0.0) as f64 / std::f64::consts::PI);
        if p > 0.0 {
            bsdf.f(wo, wi, lut()).x as f64 * wi.z.abs() as f64 / p
        } else {
            0.0
        }
    };
    for i in 0..n {
        for j in 0..n {
            let (u0, u1) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let s = bsdf.sample(wo, 0.5, u0, u1, lut());
            if s.is_valid() && s.pdf > 0.0 {
                sum += 0.5 * term(s.wi);
            }
            sum += 0.5 * term(shader_core::warp::sample_cosine_hemisphere(u0, u1));
        }
    }
    sum / (n * n) as f64
}

#[test]
fn white_furnace_compensated_metal_conserves_energy() {
    // For base colour 1 (F = 1) the formulas predict, with E the true directional albedo (f64
    // quadrature) and E_t the table's: Turquin E / E_t, Kulla-Conty E + (1 - E_t) (its E_avg is
    // the table's own integral), none E. Each must hold to the stratified estimate's accuracy,
    // and with the default 32 x 32 table the compensated albedo is 1 within 1e-3 everywhere.
    let q = reference::energy::Quadrature::default();
    let mut worst = 0.0f64;
    for &r in &[0.1f32, 0.25, 0.4, 0.55, 0.7, 0.85, 1.0] {
        for &deg in &[0.0f32, 45.0, 70.0] {
            let mp = MaterialPoint { base: Vec3::new(1.0, 1.0, 1.0), metallic: 1.0, roughness: r, emission: Vec3::ZERO, transmission: 0.0, ior: 1.5, double_sided: 0 };
            let theta = deg.to_radians();
            let mu = theta.cos();
            let e = reference::energy::albedo(mu as f64, (r * r) as f64, &q).0;
            let e_t = shader_core::energy::lut_e(lut(), mu, r) as f64;
            for (comp, want) in [(Compensation::Turquin, e / e_t), (Compensation::KullaConty, e + 1.0 - e_t), (Compensation::None, e)] {
                let a = material_albedo(&mp, theta, comp);
                assert!((a - want).abs() < 3e-4, "{} r {r} theta {deg}: albedo {a}, formula {want} (E {e}, table E {e_t})", comp.label());
                if comp != Compensation::None {
                    worst = worst.max((a - 1.0).abs());
                    assert!((a - 1.0).abs() < 1e-3, "{} r {r} theta {deg}: albedo {a}", comp.label());
                }
            }
        }
    }
    eprintln!("compensated metal furnace: largest |albedo - 1| = {worst:.2e}");
}

/// A coloured metal (F0 = 0.5) is where the compensations differ from a scale to 1: with E, E'
/// the true single-scattering integrals (f64 quadrature), E_F = F0 E + (1 - F0) E' (Schlick, F90
/// = 1), and E_t, E_avg the table's, the material's albedo is E_F uncompensated, E_F (1 + F0 (1 /
/// E_t - 1)) with Turquin's scale, and E_F + (1 - E_t) F_avg^2 E_avg / (1 - F_avg (1 - E_avg)),
/// F_avg = F0 + (1 - F0) / 21, with Kulla-Conty's lobe.
#[test]
fn white_furnace_coloured_metal_follows_each_compensation_formula() {
    let q = reference::energy::Quadrature::default();
    let f0 = 0.5f64;
    for &r in &[0.3f32, 0.6, 1.0] {
        for &deg in &[0.0f32, 60.0] {
            let mp = MaterialPoint { base: Vec3::new(0.5, 0.5, 0.5), metallic: 1.0, roughness: r, emission: Vec3::ZERO, transmission: 0.0, ior: 1.5, double_sided: 0 };
            let theta = deg.to_radians();
            let mu = theta.cos();
            let (e, e_p) = reference::energy::albedo(mu as f64, (r * r) as f64, &q);
            let e_f = f0 * e + (1.0 - f0) * e_p;
            let e_t = shader_core::energy::lut_e(lut(), mu, r) as f64;
            let e_avg = shader_core::energy::lut_e_avg(lut(), r) as f64;
            let f_avg = f0 + (1.0 - f0) / 21.0;
            let kc = e_f + (1.0 - e_t) * f_avg * f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg));
            for (comp, want) in [(Compensation::None, e_f), (Compensation::Turquin, e_f * (1.0 + f0 * (1.0 / e_t - 1.0))), (Compensation::KullaConty, kc)] {
                let a = material_albedo(&mp, theta, comp);
                eprintln!("F0 0.5 r {r} theta {deg} {}: albedo {a:.5}, formula {want:.5}", comp.label());
                assert!((a - want).abs() < 3e-4, "{} F0 0.5 r {r} theta {deg}: albedo {a}, formula {want}", comp.label());
            }
        }
    }
}

#[test]
fn white_furnace_metal_plane_renders_its_albedo() {
    // The renderer's estimate (10^6 paths; standard error about 1e-3 at r = 0.7) of what the
    // material conserves.
    for &(r, deg) in &[(0.3f32, 0.0f32), (0.7, 45.0), (1.0, 70.0)] {
        let theta = deg.to_radians();
        let m = Material::pbr("metal", [1.0; 3], 1.0, r);
        for comp in [Compensation::Turquin, Compensation::KullaConty] {
            let a = furnace(m.clone(), theta, comp);
            assert!((a - 1.0).abs() < 4e-3, "{} r {r} theta {deg}: rendered albedo {a}", comp.label());
        }
        let a = furnace(m, theta, Compensation::None);
        let e = shader_core::energy::lut_e(lut(), theta.cos(), r) as f64;
        assert!((a - e).abs() < 4e-3, "uncompensated r {r} theta {deg}: rendered {a}, table E {e}");
    }
}

#[test]
fn white_furnace_compensated_dielectric_matches_the_furnace_kernel() {
    for &r in &[0.3f32, 0.8] {
        let theta = 30f32.to_radians();
        let base = 0.6;
        let a = furnace(Material::pbr("plastic", [base; 3], 0.0, r), theta, Compensation::Turquin);
        let fm = shader_core::energy::FurnaceMaterial { base, metallic: 0.0, roughness: r, mode: Compensation::Turquin.id(), min_roughness: shader_core::energy::COMPENSATION_MIN_ROUGHNESS };
        let want = shader_core::energy::furnace_albedo(lut(), &fm, theta.cos(), 1 << 16, shader_core::energy::SEQ_SOBOL, 5, 0) as f64;
        assert!((a - want).abs() < 4e-3, "r {r}: rendered {a}, furnace kernel {want}");
    }
}

/// Red radiance per pixel, direct light only, of the plane seen from `theta` ([`ortho_at`]) at
/// 64 x 64 pixels and 256 samples each, lit either by a uniform sky of radiance 1 (`lamp` None) or
/// by an emissive quad of radiance 1, `lamp` = (half size, height), facing it from above.
fn overhead(m: &Material, theta: f32, strategy: u32, lamp: Option<(f32, f32)>) -> Vec<f32> {
    let mut b = SceneBuilder::new("plane under a light");
    let id = b.material(m.clone());
    b.mesh(&plane(50.0), id, &Mat4::IDENTITY).unwrap();
    if let Some((s, y)) = lamp {
        let emissive = b.material(Material { emissive: [1.0; 3], ..Material::pbr("lamp", [0.0; 3], 0.0, 1.0) });
        let quad = MeshData {
            name: "lamp".into(),
            positions: vec![[-s, y, -s], [s, y, -s], [s, y, s], [-s, y, s]],
            normals: Some(vec![[0.0, -1.0, 0.0]; 4]),
            indices: Some(vec![0, 1, 2, 0, 2, 3]),
            ..MeshData::default()
        };
        b.mesh(&quad, emissive, &Mat4::IDENTITY).unwrap();
    }
    let scene = b.build().unwrap();
    let sky = env::build(&if lamp.is_some() { EnvSpec::Black } else { EnvSpec::Uniform([1.0; 3]) }, 1.0, 0.0).unwrap();
    let p = params(&ortho_at(theta), 64, 64, strategy, Compensation::Turquin, if lamp.is_some() { 0.0 } else { 1.0 }, 1, 7);
    let img = render(&scene, &sky, &p, 256);
    img.color.iter().step_by(3).copied().collect()
}

/// The mean of `a - b` over pixels (two estimates of the same pixels) and its standard error, in f64.
fn paired_difference(a: &[f32], b: &[f32]) -> (f64, f64) {
    let d: Vec<f64> = a.iter().zip(b).map(|(&x, &y)| f64::from(x) - f64::from(y)).collect();
    let n = d.len() as f64;
    let m = d.iter().sum::<f64>() / n;
    (m, (d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt())
}

/// Direct light from emissive quads. One 20000 x 20000 wide at height 10 fills the plane's
/// hemisphere but for a cos-weighted 1e-6, so it lights the plane as a uniform sky of the same
/// radiance does (MIS and BSDF sampling; light sampling alone is left out there: uniform area
/// sampling of so large a quad puts almost every sample far away at grazing angles). One 2 x 2
/// wide at height 1, where light and BSDF sampling share the estimate, gives the same mean with
/// MIS, with BSDF sampling alone and with light sampling alone (within 5 standard errors). Both
/// fail if either half of the MIS estimate loses its weight (the light counted up to twice).
#[test]
fn area_lights_agree_with_the_sky_and_across_estimators() {
    for (m, deg) in [(Material::pbr("metal", [1.0; 3], 1.0, 0.5), 30.0f32), (Material::pbr("plastic", [0.6; 3], 0.0, 0.3), 60.0)] {
        let theta = deg.to_radians();
        let sky = overhead(&m, theta, STRATEGY_BSDF, None);
        let sky_mean = mean(&sky);
        for (name, strategy) in [("mis", STRATEGY_MIS), ("bsdf", STRATEGY_BSDF)] {
            let lit = mean(&overhead(&m, theta, strategy, Some((10_000.0, 10.0))));
            eprintln!("{} at {deg} degrees: uniform sky {sky_mean:.4}, hemisphere-filling quad ({name}) {lit:.4}", m.name);
            assert!((lit - sky_mean).abs() < 5e-3, "{} at {deg} degrees, {name}: area light {lit} vs uniform sky {sky_mean}", m.name);
        }
        let small = Some((1.0, 1.0));
        let mis = overhead(&m, theta, STRATEGY_MIS, small);
        for (name, strategy) in [("bsdf", STRATEGY_BSDF), ("light", STRATEGY_LIGHT)] {
            let other = overhead(&m, theta, strategy, small);
            let (d, se) = paired_difference(&mis, &other);
            let z = d.abs() / se;
            eprintln!("{} at {deg} degrees, 2 x 2 quad: mis {:.4}, {name} {:.4}, difference {d:.5} ({z:.1} standard errors)", m.name, mean(&mis), mean(&other));
            assert!(z < 5.0, "{} at {deg} degrees, 2 x 2 quad: mis {} vs {name} {} ({z:.1} standard errors)", m.name, mean(&mis), mean(&other));
        }
    }
}

/// Direct lighting from one delta light on a plane: every pixel is f(wo, wi) cos(theta_i) E.
fn delta_light_plane(light: PunctualLight, irradiance: impl Fn(Vec3) -> (Vec3, Vec3)) {
    let m = Material::pbr("plastic", [0.5, 0.3, 0.2], 0.0, 0.5);
    let scene = plane_scene(m.clone(), &[light]);
    let black = env::build(&EnvSpec::Black, 1.0, 0.0).unwrap();
    let theta = 40f32.to_radians();
    let cam = ortho_at(theta);
    let (w, h) = (16u32, 16u32);
    let mut p = params(&cam, w, h, STRATEGY_MIS, Compensation::None, 0.0, 1, 3);
    let camera = p.camera;
    p.spp = 1;
    let img = render(&scene, &black, &p, 1);
    let wo = Vec3::new(theta.sin(), theta.cos(), 0.0);
    let to_local = |v: Vec3| {
        // The plane's shading frame: normal +y; the BSDF is isotropic, so any tangent will do.
        Vec3::new(v.x, v.z, v.y)
    };
    let mp = MaterialPoint { base: Vec3::new(0.5, 0.3, 0.2), metallic: 0.0, roughness: 0.5, emission: Vec3::ZERO, transmission: 0.0, ior: 1.5, double_sided: 0 };
    let bsdf = Bsdf::new(&mp, to_local(wo), lut(), Compensation::None.id());
    let mut worst = 0.0f64;
    for py in 0..h {
        for px in 0..w {
            // The kernel's jittered primary ray of sample 0 of this pixel: its first two numbers.
            let mut sampler = shader_core::pt::sampler::Sampler::new(p.sampler, p.seed, py * w + px, 0);
            let (jx, jy) = sampler.next_2d();
            let ray = camera.ray(px as f32 + jx, py as f32 + jy, w, h);
            let t = -ray.o.y / ray.d.y;
            let (wi, e) = irradiance(ray.at(t));
            let f = bsdf.f(to_local(wo), to_local(wi), lut());
            let want = f.mul_elem(e) * wi.y;
            let i = (py * w + px) as usize * 3;
            for (g, w_) in [(img.color[i], want.x), (img.color[i + 1], want.y), (img.color[i + 2], want.z)] {
                worst = worst.max(((g - w_) as f64).abs() / (w_ as f64).abs());
            }
        }
    }
    // Rounding only: the kernel's hit point is the barycentric one, this test's the ray's.
    assert!(worst < 1e-4, "largest relative difference from f cos I / d^2: {worst}");
}

#[test]
fn directional_light_on_a_plane_is_f_cos_e() {
    let dir = Vec3::new(-0.3, -0.8, 0.2).normalize();
    let e = Vec3::new(2.0, 1.5, 1.0);
    let light = PunctualLight { name: "sun".into(), kind: LightKind::Directional, position: [0.0; 3], direction: [dir.x, dir.y, dir.z], intensity: [e.x, e.y, e.z], range: 0.0 };
    let m = Material::pbr("plastic", [0.5, 0.3, 0.2], 0.0, 0.5);
    let scene = plane_scene(m, &[light]);
    let black = env::build(&EnvSpec::Black, 1.0, 0.0).unwrap();
    let theta = 40f32.to_radians();
    let p = params(&ortho_at(theta), 8, 8, STRATEGY_MIS, Compensation::None, 0.0, 1, 3);
    let img = render(&scene, &black, &p, 2);
    let wo = Vec3::new(theta.sin(), theta.cos(), 0.0);
    let local = |v: Vec3| Vec3::new(v.x, v.z, v.y);
    let mp = MaterialPoint { base: Vec3::new(0.5, 0.3, 0.2), metallic: 0.0, roughness: 0.5, emission: Vec3::ZERO, transmission: 0.0, ior: 1.5, double_sided: 0 };
    let bsdf = Bsdf::new(&mp, local(wo), lut(), Compensation::None.id());
    let wi = -dir;
    let want = bsdf.f(local(wo), local(wi), lut()).mul_elem(e) * wi.y;
    for (k, px) in img.color.chunks_exact(3).enumerate() {
        for (g, w) in [(px[0], want.x), (px[1], want.y), (px[2], want.z)] {
            assert!(((g - w) / w).abs() < 1e-5, "pixel {k}: {g} vs f cos E = {w}");
        }
    }
}

#[test]
fn point_light_on_a_plane_falls_off_as_inverse_square() {
    let pos = Vec3::new(0.2, 1.5, -0.1);
    let i = Vec3::new(3.0, 2.0, 1.0);
    let light = PunctualLight { name: "bulb".into(), kind: LightKind::Point, position: [pos.x, pos.y, pos.z], direction: [0.0, -1.0, 0.0], intensity: [i.x, i.y, i.z], range: 0.0 };
    delta_light_plane(light, |x| {
        let v = pos - x;
        let d2 = v.dot(v);
        (v.normalize(), i / d2)
    });
}

/// Independent renders of the built-in scene: per 4x4 block and channel, the mean over runs and
/// its standard error.
fn block_stats(strategy: u32, sampler: u32, runs: u32, spp: u32) -> Vec<(f64, f64)> {
    let scene = Scene::builtin(6);
    let black = env::build(&EnvSpec::Black, 1.0, 0.0).unwrap();
    let cam = scene.cameras[0].clone();
    let (w, h) = (24u32, 24u32);
    let mut per_run: Vec<Vec<f64>> = Vec::new();
    for run in 0..runs {
        let p = RenderParams { sampler, ..params(&cam, w, h, strategy, Compensation::Turquin, 0.0, 5, 100 + run) };
        let img = render(&scene, &black, &p, spp);
        let mut blocks = vec![0.0f64; (w / 4 * h / 4 * 3) as usize];
        for y in 0..h {
            for x in 0..w {
                for c in 0..3 {
                    blocks[(((y / 4) * (w / 4) + x / 4) * 3 + c) as usize] += img.color[((y * w + x) * 3 + c) as usize] as f64 / 16.0;
                }
            }
        }
        per_run.push(blocks);
    }
    (0..per_run[0].len())
        .map(|k| {
            let n = runs as f64;
            let m = per_run.iter().map(|r| r[k]).sum::<f64>() / n;
            let var = per_run.iter().map(|r| (r[k] - m).powi(2)).sum::<f64>() / (n - 1.0);
            (m, (var / n).sqrt())
        })
        .collect()
}

#[test]
fn mis_bsdf_and_light_sampling_agree() {
    let mis = block_stats(STRATEGY_MIS, SAMPLER_PCG, 8, 16);
    let bsdf = block_stats(STRATEGY_BSDF, SAMPLER_PCG, 8, 16);
    let light = block_stats(STRATEGY_LIGHT, SAMPLER_PCG, 8, 16);
    let sobol = block_stats(STRATEGY_MIS, SAMPLER_SOBOL, 8, 16);
    let lit = mis.iter().filter(|(m, _)| *m > 0.01).count();
    assert!(lit > mis.len() / 2, "only {lit} of {} block values lit", mis.len());
    for (name, other) in [("bsdf", &bsdf), ("light", &light), ("mis with sobol samples", &sobol)] {
        let mut worst = 0.0f64;
        for (k, (a, b)) in mis.iter().zip(other.iter()).enumerate() {
            let se = (a.1 * a.1 + b.1 * b.1).sqrt().max(1e-4 * a.0.abs().max(1e-3));
            let z = (a.0 - b.0).abs() / se;
            worst = worst.max(z);
            assert!(z < 6.0, "block value {k}: mis {} +- {} vs {name} {} +- {}", a.0, a.1, b.0, b.1);
        }
        eprintln!("mis vs {name}: largest difference {worst:.2} standard errors");
    }
}

/// Relative RMSE of `img` against the mean of two independent references, the references' own
/// noise (estimated from their difference) removed: sqrt(mean (x - r)^2 - mean (r1 - r2)^2 / 4) / mean r.
fn relative_rmse(img: &RenderImage, r1: &RenderImage, r2: &RenderImage) -> f64 {
    let n = img.color.len() as f64;
    let (mut e2, mut d2, mut m) = (0.0f64, 0.0f64, 0.0f64);
    for ((x, a), b) in img.color.iter().zip(&r1.color).zip(&r2.color) {
        let r = 0.5 * (*a as f64 + *b as f64);
        e2 += (*x as f64 - r).powi(2) / n;
        d2 += (*a as f64 - *b as f64).powi(2) / n;
        m += r / n;
    }
    (e2 - d2 / 4.0).max(0.0).sqrt() / m
}

/// Least-squares slope of ln(error) against ln(spp).
fn log_slope(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>()
}

#[test]
fn error_falls_as_one_over_sqrt_spp() {
    let scene = Scene::builtin(6);
    let black = env::build(&EnvSpec::Black, 1.0, 0.0).unwrap();
    let cam = scene.cameras[0].clone();
    let (w, h) = (16u32, 16u32);
    let reference = render(&scene, &black, &params(&cam, w, h, STRATEGY_MIS, Compensation::Turquin, 0.0, 5, 999), 2048);
    let mut pts = Vec::new();
    for spp in [4u32, 16, 64, 256] {
        let img = render(&scene, &black, &params(&cam, w, h, STRATEGY_MIS, Compensation::Turquin, 0.0, 5, 7), spp);
        let mse = img.color.iter().zip(&reference.color).map(|(a, b)| ((a - b) as f64).powi(2)).sum::<f64>() / img.color.len() as f64;
        pts.push(((spp as f64).ln(), 0.5 * mse.ln()));
    }
    let slope = log_slope(&pts);
    eprintln!("RMSE slope against spp: {slope:.3}");
    assert!((slope + 0.5).abs() < 0.15, "RMSE falls as spp^{slope:.3}, expected spp^-0.5");
}

/// The shared Cornell box under a uniform sky at 32x32 (as `host render` lights it) and its two
/// independent 2048-spp PCG references, rendered once for the tests that measure error on it.
fn cornell_32() -> &'static (Scene, env::Environment, RenderImage, RenderImage) {
    static CELL: OnceLock<(Scene, env::Environment, RenderImage, RenderImage)> = OnceLock::new();
    CELL.get_or_init(|| {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");
        let scene = Scene::load(path).unwrap();
        let sky = env::build(&EnvSpec::Uniform([1.0; 3]), 1.0, 0.0).unwrap();
        let cam = scene.cameras[0].clone();
        let reference = |seed| render(&scene, &sky, &params(&cam, 32, 32, STRATEGY_MIS, Compensation::Turquin, 1.0, 8, seed), 2048);
        let (r1, r2) = (reference(999), reference(998));
        (scene, sky, r1, r2)
    })
}

#[test]
fn sobol_samples_converge_as_fast_or_faster_and_lower_than_pcg() {
    // The Cornell box is smooth enough that stratification shows.
    let (scene, sky, r1, r2) = cornell_32();
    let cam = scene.cameras[0].clone();
    let at = |sampler: u32, seed: u32, spp: u32| {
        let p = RenderParams { sampler, ..params(&cam, 32, 32, STRATEGY_MIS, Compensation::Turquin, 1.0, 8, seed) };
        render(scene, sky, &p, spp)
    };
    let mut err = [[0.0f64; 4]; 2];
    for (k, sampler) in [SAMPLER_PCG, SAMPLER_SOBOL].into_iter().enumerate() {
        let mut pts = Vec::new();
        for (j, spp) in [4u32, 16, 64, 256].into_iter().enumerate() {
            err[k][j] = relative_rmse(&at(sampler, 7, spp), r1, r2);
            pts.push(((spp as f64).ln(), err[k][j].ln()));
        }
        let slope = log_slope(&pts);
        eprintln!("sampler {sampler}: relative RMSE {:?}, slope against spp {slope:.3}", err[k]);
        assert!(slope < -0.4 && slope > -1.0, "sampler {sampler}: RMSE falls as spp^{slope:.3}, expected spp^-0.5 or faster");
    }
    // Stratified samples: lower error than independent ones at every spp from 16 on.
    for j in 1..4 {
        assert!(err[1][j] < 0.85 * err[0][j], "at {} spp Sobol's relative RMSE {} is not below 0.85 x PCG's {}", [4, 16, 64, 256][j], err[1][j], err[0][j]);
    }
}

#[test]
fn environment_map_density_is_consistent_and_normalized() {
    let (w, h) = (32u32, 16u32);
    let rgb: Vec<f32> = (0..w * h).flat_map(|i| { let (x, y) = (i % w, i / w); let hot = if (10..13).contains(&x) && (3..5).contains(&y) { 50.0 } else { 0.2 }; [hot, hot * 0.8, 0.1 + 0.01 * x as f32] }).collect();
    let e = env::from_map(w, h, &rgb, 1.0, 25.0).unwrap();
    let words = &e.words;
    // Sampled pdf equals the density function at the sampled direction.
    let mut rng = shader_core::rng::Pcg32::new(1, 2);
    for _ in 0..20_000 {
        let s = shader_core::pt::environment::sample(words, rng.next_f32(), rng.next_f32());
        assert!(s.pdf > 0.0);
        let p = shader_core::pt::environment::pdf(words, s.wi);
        assert!(((p - s.pdf) / s.pdf).abs() < 1e-4, "pdf {p} vs sample pdf {}", s.pdf);
        let l = shader_core::pt::environment::radiance(words, s.wi);
        assert!((l.x - s.li.x).abs() <= 1e-6 * l.x.abs().max(1.0));
    }
    // The density integrates to 1 over the sphere (midpoint rule on a fine (theta, phi) grid).
    let pdf = |d: Vec3| shader_core::pt::environment::pdf(words, d) as f64;
    let integral = sphere_integral(pdf);
    assert!((integral - 1.0).abs() < 5e-3, "density integrates to {integral}");
    // Samples land in proportion to the density: the hot spot's share of samples against its
    // share of the integral.
    let hot_dir = |d: Vec3| shader_core::pt::environment::radiance(words, d).x > 10.0;
    let n = 200_000;
    let hits = (0..n).filter(|_| hot_dir(shader_core::pt::environment::sample(words, rng.next_f32(), rng.next_f32()).wi)).count() as f64 / n as f64;
    let share = sphere_integral(|d| if hot_dir(d) { pdf(d) } else { 0.0 });
    assert!(share > 0.3, "the hot spot should hold most of the density: {share}");
    assert!((hits - share).abs() < 0.01, "hot spot: {hits} of the samples, {share} of the density");
}

/// The integral of `f` over the unit sphere by the midpoint rule on a 400 x 800 (theta, phi) grid.
fn sphere_integral(f: impl Fn(Vec3) -> f64) -> f64 {
    let (nt, np) = (400, 800);
    let (dt, dp) = (std::f64::consts::PI / nt as f64, 2.0 * std::f64::consts::PI / np as f64);
    let mut sum = 0.0f64;
    for i in 0..nt {
        let th = (i as f64 + 0.5) * dt;
        for j in 0..np {
            let ph = (j as f64 + 0.5) * dp;
            let d = Vec3::new((th.sin() * ph.cos()) as f32, th.cos() as f32, (th.sin() * ph.sin()) as f32);
            sum += f(d) * th.sin() * dt * dp;
        }
    }
    sum
}

#[test]
fn the_error_estimate_tracks_the_true_error_and_the_target_stops_the_render() {
    // The Cornell box under a uniform sky, 32x32: PCG samples (independent halves) give an
    // estimate within 25 % of the error against two 2048-spp references; Sobol samples' estimate
    // is conservative (at or above the true error, within 2.5x).
    let (scene, sky, r1, r2) = cornell_32();
    let cam = scene.cameras[0].clone();
    let inputs = RenderInputs { scene: &scene.words, env: &sky.words, lut: lut() };
    let p = |sampler: u32, seed: u32| RenderParams { sampler, ..params(&cam, 32, 32, STRATEGY_MIS, Compensation::Turquin, 1.0, 8, seed) };
    for (sampler, lo, hi) in [(SAMPLER_PCG, 0.75, 1.25), (SAMPLER_SOBOL, 1.0, 2.5)] {
        let mut estimates = Vec::new();
        let (img, _) = render::render_until(&Backend::Cpu, &inputs, &p(sampler, 7), 64, 4, |acc| estimates.push(acc.error_estimate()), |_| false).unwrap();
        assert_eq!(estimates[0], None, "one launch has no second half");
        let estimate = estimates.last().unwrap().unwrap();
        let truth = relative_rmse(&img, r1, r2);
        eprintln!("sampler {sampler}: estimated relative RMSE {estimate:.4}, against the references {truth:.4}");
        assert!(estimate >= lo * truth && estimate <= hi * truth, "sampler {sampler}: estimate {estimate} against true error {truth}");
    }
    // --target-error's rule: the render stops after the first launch whose estimate is at most
    // the target, before --spp, and not earlier.
    let target = 0.08;
    let mut estimates = Vec::new();
    let (img, _) = render::render_until(&Backend::Cpu, &inputs, &p(SAMPLER_SOBOL, 7), 4096, 4, |acc| estimates.push(acc.error_estimate()), |acc| acc.error_estimate().is_some_and(|e| e <= target)).unwrap();
    assert!(img.spp < 4096, "the target was never reached");
    assert!(estimates.last().unwrap().unwrap() <= target);
    assert!(estimates[..estimates.len() - 1].iter().all(|e| e.is_none_or(|e| e > target)), "it ran past the first launch under the target: {estimates:?}");
    assert!(relative_rmse(&img, r1, r2) <= target, "the image's true error is above the target");
}
