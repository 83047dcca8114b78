//! `host render --gbuffer`: the exported SSR inputs and the path-traced reference against closed
//! forms (a mirror floor under a uniform sky, the GGX directional albedo), the camera path's
//! motion vectors against the previous frame's depth, the SSR pipeline on an exported G-buffer
//! against its reference (which fails if the world's handedness is converted wrongly), and bad
//! input named.

use host::render::environment::{self as env, EnvSpec};
use host::render::gbuffer::{render_gbuffer, to_ssr, Frames};
use host::render::scene::{Camera, Projection};
use host::ssr::camera::Camera as SsrCamera;
use host::render::scene::{Mat4, Material, MeshData, Scene, SceneBuilder};
use host::render::{self, RenderInputs};
use host::ssr::{GBuffer, Reference};
use host::Backend;
use shader_core::pt::gbuffer::GBufferParams;
use shader_core::pt::integrator::{RenderParams, STRATEGY_MIS};
use std::process::{Command, Output};

const CORNELL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");

fn quad(y: f32, s: f32) -> MeshData {
    MeshData {
        name: "floor".into(),
        positions: vec![[-s, y, -s], [s, y, -s], [s, y, s], [-s, y, s]],
        normals: Some(vec![[0.0, 1.0, 0.0]; 4]),
        indices: Some(vec![0, 2, 1, 0, 3, 2]),
        ..MeshData::default()
    }
}

fn cube(lo: [f32; 3], hi: [f32; 3]) -> MeshData {
    let p = |i: usize| [if i & 1 != 0 { hi[0] } else { lo[0] }, if i & 2 != 0 { hi[1] } else { lo[1] }, if i & 4 != 0 { hi[2] } else { lo[2] }];
    MeshData {
        name: "box".into(),
        positions: (0..8).map(p).collect(),
        indices: Some(vec![0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5]),
        ..MeshData::default()
    }
}

/// A floor of `floor` material, optionally with a red diffuse box on the camera's right.
fn floor_scene(floor: Material, with_box: bool) -> Scene {
    let mut b = SceneBuilder::new("test floor");
    let f = b.material(floor);
    b.mesh(&quad(0.0, 40.0), f, &Mat4::IDENTITY).unwrap();
    if with_box {
        let red = b.material(Material::pbr("red", [0.8, 0.1, 0.1], 0.0, 1.0));
        b.mesh(&cube([0.3, 0.0, -0.8], [1.3, 1.0, 0.2]), red, &Mat4::IDENTITY).unwrap();
    }
    b.build().unwrap()
}

fn camera() -> Camera {
    let (eye, at) = ([0.0f32, 1.2, 3.5], [0.0f32, 0.3, 0.0]);
    let f = [at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]];
    Camera::look("test", eye, f, [0.0, 1.0, 0.0], Projection::Perspective { yfov: 0.8, aspect: None })
}

fn params(cam: &Camera, w: u32, h: u32, seed: u32) -> RenderParams {
    RenderParams {
        width: w,
        height: h,
        spp: 1,
        sample_base: 0,
        seed,
        max_depth: 4,
        rr_depth: 8,
        strategy: STRATEGY_MIS,
        compensation: shader_core::energy::COMP_NONE,
        sampler: shader_core::pt::sampler::SAMPLER_PCG,
        clamp: 0.0,
        p_env: 1.0,
        camera: cam.kernel(w, h).unwrap(),
    }
}

/// The G-buffer and reference of `scene` under a uniform sky `sky`, seen by `cam` (previous
/// frame `prev`), with `spp` colour samples and `ref_spp` reference samples, on the CPU.
fn export(scene: &Scene, sky: [f32; 3], cam: &Camera, prev: &Camera, w: u32, h: u32, spp: u32, ref_spp: u32, max_roughness: f32) -> (GBuffer, Option<Reference>) {
    let e = env::build(&EnvSpec::Uniform(sky), 1.0, 0.0).unwrap();
    let lut = vec![0.0; shader_core::energy::LUT_HEADER];
    let inputs = RenderInputs { scene: &scene.words, env: &e.words, lut: &lut };
    let p = params(cam, w, h, 3);
    let pp = params(prev, w, h, 3);
    let (img, _) = render::render(&Backend::Cpu, &inputs, &pp, spp, spp, |_| {}).unwrap();
    let gp = GBufferParams { render: p, max_roughness, fallback: shader_core::Vec3::new(sky[0], sky[1], sky[2]) };
    let (sums, _) = render_gbuffer(&Backend::Cpu, &inputs, &gp, ref_spp, 64, |_| {}).unwrap();
    let frames = Frames { ssr_camera: SsrCamera::from_kernel(&p.camera, 0.01).unwrap(), ssr_previous: SsrCamera::from_kernel(&pp.camera, 0.01).unwrap(), color: img.color, fallback: sky };
    to_ssr(&sums, frames, None).unwrap()
}

/// Mirror floor, uniform sky: every reflected ray escapes, so both references are the sky, the
/// specular integral is the sky times Schlick's F(n.v), and the G-buffer is the plane's.
#[test]
fn mirror_floor_under_a_uniform_sky_reflects_the_sky_with_schlick_fresnel() {
    let sky = [0.3, 0.5, 0.7];
    let scene = floor_scene(Material::pbr("mirror", [0.5, 0.6, 0.7], 1.0, 0.0), false);
    let (w, h) = (48u32, 32u32);
    let (gb, r) = export(&scene, sky, &camera(), &camera(), w, h, 1, 4, 0.6);
    let r = r.expect("a reference");
    let (mut floor, mut sky_px) = (0, 0);
    for i in 0..(w * h) as usize {
        let (sx, sy) = ((i % w as usize) as f64 + 0.5, (i / w as usize) as f64 + 0.5);
        if !gb.depth[i].is_finite() {
            sky_px += 1;
            assert!(!r.glossy[i]);
            assert_eq!(gb.motion[2 * i..2 * i + 2], [0.0, 0.0]);
            continue;
        }
        floor += 1;
        // The G-buffer: the plane y = 0 (the x-mirrored world leaves y alone), normal +y.
        let p = gb.camera.unproject(w as usize, h as usize, sx, sy, gb.depth[i] as f64);
        assert!(p[1].abs() < 1e-4, "pixel {i}: unprojected point {p:?} is not on the floor");
        assert_eq!(&gb.normal[3 * i..3 * i + 3], &[-0.0, 1.0, 0.0]);
        assert_eq!((gb.roughness[i], gb.metalness[i]), (0.0, 1.0));
        assert_eq!(gb.motion[2 * i..2 * i + 2], [0.0, 0.0], "a static camera has no motion");
        assert!(r.glossy[i]);
        let d = gb.camera.ray_dir(w as usize, h as usize, sx, sy);
        let nv = -d[1];
        for c in 0..3 {
            let f0 = [0.5, 0.6, 0.7][c];
            let f = f0 + (1.0 - f0) * (1.0 - nv).powi(5);
            assert!((r.all[3 * i + c] - sky[c]).abs() <= 1e-6, "pixel {i}: all {} vs sky {}", r.all[3 * i + c], sky[c]);
            assert_eq!(r.onscreen[3 * i + c], sky[c], "escaping rays take the fallback");
            let want = sky[c] as f64 * f;
            assert!((r.specular_all[3 * i + c] as f64 - want).abs() <= 2e-6, "pixel {i} channel {c}: specular {} vs {want}", r.specular_all[3 * i + c]);
        }
        assert_eq!(r.onscreen_fraction[i], 1.0);
    }
    assert!(floor > 500 && sky_px > 100, "floor {floor}, sky {sky_px}");
}

/// GGX directional albedo E(mu) = int D(h) G2(v, l) / (4 mu) dl by midpoint quadrature (f64).
fn ggx_albedo(mu: f64, alpha: f64) -> f64 {
    let v = [(1.0 - mu * mu).sqrt(), 0.0, mu];
    let lambda = |c: f64| {
        let t2 = (1.0 - c * c) / (c * c);
        0.5 * (-1.0 + (1.0 + alpha * alpha * t2).sqrt())
    };
    let (nt, np) = (1200, 600);
    let mut e = 0.0;
    for i in 0..nt {
        let th = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
        for j in 0..np {
            let ph = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
            let l = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
            let hv = [v[0] + l[0], v[1] + l[1], v[2] + l[2]];
            let hl = (hv[0] * hv[0] + hv[1] * hv[1] + hv[2] * hv[2]).sqrt();
            let cz = hv[2] / hl;
            let a2 = alpha * alpha;
            let dd = cz * cz * (a2 - 1.0) + 1.0;
            let d = a2 / (std::f64::consts::PI * dd * dd);
            let g2 = 1.0 / (1.0 + lambda(mu) + lambda(l[2]));
            e += d * g2 / (4.0 * mu) * th.sin();
        }
    }
    e * (std::f64::consts::FRAC_PI_2 / nt as f64) * (std::f64::consts::TAU / np as f64)
}

/// A rough white metal floor (F = 1) under a sky of 1: the normalized reflection is 1 and the
/// specular integral is the GGX directional albedo at each pixel's n.v.
#[test]
fn glossy_floor_specular_reference_is_the_ggx_directional_albedo() {
    let roughness = 0.5f32;
    let scene = floor_scene(Material::pbr("metal", [1.0, 1.0, 1.0], 1.0, roughness), false);
    let (w, h) = (8u32, 6u32);
    let (gb, r) = export(&scene, [1.0; 3], &camera(), &camera(), w, h, 1, 4096, 0.6);
    let r = r.unwrap();
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    for i in 0..(w * h) as usize {
        if !r.glossy[i] {
            continue;
        }
        let (sx, sy) = ((i % w as usize) as f64 + 0.5, (i / w as usize) as f64 + 0.5);
        let mu = -gb.camera.ray_dir(w as usize, h as usize, sx, sy)[1];
        let e = ggx_albedo(mu, (roughness * roughness) as f64);
        for c in 0..3 {
            assert!((r.all[3 * i + c] - 1.0).abs() < 1e-5, "normalized reflection {}", r.all[3 * i + c]);
            let d = (r.specular_all[3 * i + c] as f64 - e).abs();
            worst = worst.max(d);
            // G2/G1 is in [0, 1] with a variance below 0.05: 5 sigma of the mean of 4096 is 0.017.
            assert!(d < 0.017, "pixel {i} (mu {mu:.3}): specular {} vs E(mu) {e:.4}", r.specular_all[3 * i + c]);
        }
        checked += 1;
    }
    assert!(checked > 20, "{checked} pixels");
    eprintln!("worst |specular - E(mu)| = {worst:.5} over {checked} pixels");
}

/// SSR (HDRP, Hi-Z) on an exported G-buffer of a mirror floor with a red box: its reflection
/// agrees with the path-traced on-screen reference where the reference's rays stay on screen.
/// A wrong handedness conversion (normals or camera not mirrored together) moves the box's
/// reflection and fails this.
#[test]
fn ssr_on_an_exported_gbuffer_agrees_with_its_reference() {
    use host::ssr::cli::errors;
    use host::ssr::{run_hdrp, HdrpResolve, SsrSettings, TraceMode};
    let scene = floor_scene(Material::pbr("mirror", [0.9, 0.9, 0.9], 1.0, 0.0), true);
    let (w, h) = (128u32, 96u32);
    let (gb, r) = export(&scene, [1.0; 3], &camera(), &camera(), w, h, 64, 64, 0.6);
    let r = r.unwrap();
    // The far depth (`shader_core::pt::gbuffer::far_depth`): written, never nearer than the
    // depth, and farther than it somewhere (along the box's outlines).
    let far = gb.depth_far.as_ref().expect("the kernel writes the far depth");
    assert!(far.iter().zip(&gb.depth).all(|(f, z)| f >= z && f.is_infinite() == z.is_infinite()));
    assert!(far.iter().zip(&gb.depth).any(|(f, z)| z.is_finite() && *f > *z * 1.01), "no outline in the far depth");
    // The box's reflection is on screen: on-screen pixels whose rays all hit the visible box.
    let red = (0..(w * h) as usize).filter(|&i| r.glossy[i] && r.onscreen_fraction[i] >= 0.999 && r.onscreen[3 * i] > 2.0 * r.onscreen[3 * i + 1]).count();
    assert!(red > 200, "only {red} floor pixels reflect the red box");
    let res = run_hdrp(&Backend::Cpu, &gb, &SsrSettings::default(), TraceMode::HiZ, HdrpResolve::Approx).unwrap();
    let e = errors(&res, &r, gb.fallback);
    eprintln!("on-screen pixels {}: RMSE {:.4} rel {:.4}; all glossy {}: rel {:.4}", e.onscreen.pixels, e.onscreen.rmse, e.onscreen.rel, e.all.pixels, e.all.rel);
    assert!(e.onscreen.pixels > 1000);
    assert!(e.onscreen.rel < 0.1, "SSR vs the on-screen reference: relative error {:.4}", e.onscreen.rel);
}

fn host(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host")).args(args).output().expect("running host")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `--orbit`: frame 1's motion vectors carry each pixel onto frame 0, where frame 0's own
/// G-buffer has the reprojected point's depth; frame 1's colour buffer is frame 0's render.
#[test]
fn orbit_motion_vectors_land_on_the_previous_frames_surface() {
    let dir = tempfile::tempdir().unwrap();
    let run = |frame: &str| {
        let g = dir.path().join(format!("g{frame}.exr"));
        let o = dir.path().join(format!("r{frame}.exr"));
        let out = host(&[
            "render", CORNELL, "--device", "cpu", "--width", "64", "--height", "64", "--spp", "2", "--quiet", "--orbit", "6", "--frame", frame,
            "--reference-spp", "0", "--gbuffer", g.to_str().unwrap(), "-o", o.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        (GBuffer::load(&g).unwrap(), host::io::read_exr(&o).unwrap())
    };
    let (g1, _) = run("1");
    let (g0, r0) = run("0");
    assert!(g1.reference.is_none() && !dir.path().join("g1.reference.exr").exists(), "--reference-spp 0 writes no reference");
    assert_eq!(g1.previous_camera, g0.camera, "frame 1's previous camera is frame 0's camera");
    let colour0: Vec<f32> = (0..64 * 64).flat_map(|i| ["R", "G", "B"].map(|c| r0.channel(c).unwrap()[i])).collect();
    assert_eq!(g1.color, colour0, "frame 1's colour buffer is frame 0's image");
    let (w, h) = (64usize, 64usize);
    // Where frame 0's depth is smooth around the landing pixel, frame 0 sees the reprojected
    // point there (agree) or something in front of it (a disocclusion: the point is hidden in
    // frame 0). Something behind it would mean a wrong motion vector or camera.
    let (mut agree, mut hidden, mut wrong, mut moved) = (0, 0, 0, 0);
    for y in 2..h - 2 {
        for x in 2..w - 2 {
            let i = y * w + x;
            if !g1.depth[i].is_finite() {
                continue;
            }
            let (sx, sy) = (x as f64 + 0.5, y as f64 + 0.5);
            let p = g1.camera.unproject(w, h, sx, sy, g1.depth[i] as f64);
            let (px, py) = (sx - g1.motion[2 * i] as f64 * w as f64, sy - g1.motion[2 * i + 1] as f64 * h as f64);
            let (qx, qy) = (px.floor() as isize, py.floor() as isize);
            if qx < 1 || qy < 1 || qx >= w as isize - 1 || qy >= h as isize - 1 {
                continue;
            }
            let dq = |dx: isize, dy: isize| g0.depth[((qy + dy) as usize) * w + (qx + dx) as usize];
            let d0 = dq(0, 0);
            let smooth = [(-1, 0), (1, 0), (0, -1), (0, 1)].iter().all(|&(a, b)| (dq(a, b) - d0).abs() < 0.03 * d0);
            if !smooth {
                continue;
            }
            let z = g0.camera.to_view(p)[2];
            if (z - d0 as f64).abs() < 0.06 * z {
                agree += 1;
            } else if z > d0 as f64 {
                hidden += 1;
            } else {
                wrong += 1;
                eprintln!("pixel ({x}, {y}): reprojected depth {z:.4}, frame 0 sees {d0:.4} behind it at ({qx}, {qy})");
            }
            if (px - sx).abs() > 0.5 {
                moved += 1;
            }
        }
    }
    eprintln!("agree {agree}, hidden in frame 0 {hidden}, wrong {wrong}, moved {moved}");
    assert!(agree > 800 && moved > 500, "agree {agree}, moved {moved}");
    assert!(hidden * 20 < agree, "{hidden} disocclusions for {agree} agreeing pixels: motion vectors look wrong");
    assert_eq!(wrong, 0, "reprojected points in front of what frame 0 sees");
}

#[test]
fn gbuffer_export_bad_input_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let g = dir.path().join("g.exr");
    let gs = g.to_str().unwrap();
    let o = dir.path().join("r.exr");
    let os = o.to_str().unwrap();
    let base = ["render", "--device", "cpu", "--width", "16", "--height", "16", "--spp", "1", "--quiet", "--detail", "4", "-o", os];
    let with = |extra: &[&str]| {
        let mut a: Vec<&str> = base.to_vec();
        a.extend_from_slice(extra);
        host(&a)
    };
    let e = with(&["--frame", "2"]);
    assert!(!e.status.success() && stderr(&e).contains("--orbit"), "{}", stderr(&e));
    let e = with(&["--gbuffer", gs, "--max-roughness", "1.5"]);
    assert!(!e.status.success() && stderr(&e).contains("max-roughness"), "{}", stderr(&e));
    let e = with(&["--gbuffer", gs, "--orbit", "inf"]);
    assert!(!e.status.success() && stderr(&e).contains("--orbit"), "{}", stderr(&e));
    // The exported G-buffer runs through `host ssr --input`, which refuses a mismatched cut-off.
    let ok = with(&["--gbuffer", gs, "--reference-spp", "2"]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    let s = dir.path().join("s.exr");
    let run = host(&["ssr", "--input", gs, "--device", "cpu", "-o", s.to_str().unwrap()]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(stderr(&run).contains("reference: g.reference.exr"), "{}", stderr(&run));
    let bad = host(&["ssr", "--input", gs, "--device", "cpu", "--min-smoothness", "0.7", "--smoothness-fade-start", "0.8", "-o", s.to_str().unwrap()]);
    assert!(!bad.status.success() && stderr(&bad).contains("covers perceptual roughness <= 0.6"), "{}", stderr(&bad));
    // A missing reference file is named.
    std::fs::remove_file(dir.path().join("g.reference.exr")).unwrap();
    let gone = host(&["ssr", "--input", gs, "--device", "cpu", "-o", s.to_str().unwrap()]);
    assert!(!gone.status.success() && stderr(&gone).contains("g.reference.exr"), "{}", stderr(&gone));
}

/// An orthographic camera cannot feed SSR: named before any work.
#[test]
fn orthographic_cameras_are_refused_for_gbuffers() {
    let mut spec = camera();
    spec.projection = Projection::Orthographic { xmag: 1.0, ymag: 1.0 };
    let cam = spec.kernel(16, 16).unwrap();
    let e = SsrCamera::from_kernel(&cam, 0.01).unwrap_err().to_string();
    assert!(e.contains("perspective"), "{e}");
    // Orbiting keeps the camera rigid and turns it about +y.
    let o = camera().orbited([0.0, 0.0, 0.0], 90.0);
    assert!((o.position[0] - 3.5).abs() < 1e-5 && o.position[2].abs() < 1e-5, "{:?}", o.position);
}

/// The reference's noise estimate (two halves of its samples) predicts how far two independent
/// references of the same pixels lie apart: per pixel E[(r1 - r2)^2] = 2 var, so the RMS
/// difference of two seeds over sqrt(2) must match the estimated noise, within 25 %.
#[test]
fn reference_noise_estimate_matches_two_independent_references() {
    use host::render::gbuffer::{export_frame, FrameSpec, Quiet};
    use host::ssr::reference::noise_rel;
    let scene = floor_scene(Material::pbr("glossy", [0.9, 0.9, 0.9], 1.0, 0.3), true);
    let sky = [1.0, 0.9, 0.8];
    let e = env::build(&EnvSpec::Uniform(sky), 1.0, 0.0).unwrap();
    let lut = vec![0.0; shader_core::energy::LUT_HEADER];
    let inputs = RenderInputs { scene: &scene.words, env: &e.words, lut: &lut };
    let (w, h) = (64u32, 48u32);
    let run = |seed: u32| {
        let p = RenderParams { seed, ..params(&camera(), w, h, seed) };
        let spec = FrameSpec { params: p, previous: p.camera, spp: 1, spp_per_pass: 1, reference_spp: 32, max_roughness: 0.6, fallback: sky, near: 0.01 };
        export_frame(&Backend::Cpu, &inputs, &spec, None, None, &mut Quiet).unwrap().reference.unwrap()
    };
    let (a, b) = (run(1), run(2));
    let mask: Vec<bool> = a.glossy.iter().zip(&a.onscreen_fraction).map(|(&g, &f)| g && f >= 0.999).collect();
    assert!(mask.iter().filter(|m| **m).count() > 500);
    let (na, nb) = (noise_rel(&a, &mask).unwrap(), noise_rel(&b, &mask).unwrap());
    let (mut d2, mut r2) = (0.0f64, 0.0f64);
    for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
        for c in 0..3 {
            d2 += (f64::from(a.onscreen[3 * i + c]) - f64::from(b.onscreen[3 * i + c])).powi(2);
            r2 += f64::from(a.onscreen[3 * i + c]).powi(2);
        }
    }
    let empirical = (d2 / r2 / 2.0).sqrt();
    eprintln!("estimated noise {na:.4} / {nb:.4}, empirical {empirical:.4}");
    assert!(na > 0.005, "the red box's reflection in a rough floor is noisy: {na}");
    for n in [na, nb] {
        assert!((n / empirical - 1.0).abs() < 0.25, "estimated {n:.4} vs empirical {empirical:.4}");
    }
    assert_eq!(host::ssr::reference::above_noise(0.05, Some(0.1)), 0.0);
    assert!((host::ssr::reference::above_noise(0.5, Some(0.3)) - 0.4).abs() < 1e-12);
    assert!(host::ssr::reference::above_noise(0.5, None).is_nan());
}
