//! SSR stage 1 and 2: G-buffer I/O and validation, procedural scenes, the ray-traced reference.

use host::ssr::{gbuffer::GBuffer, scene, Camera};
use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ssr_inputs_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn small(name: &str) -> GBuffer {
    scene(name).unwrap().render_gbuffer(64, 48, 0)
}

#[test]
fn procedural_scenes_render_valid_gbuffers() {
    for name in host::ssr::SCENES {
        let g = scene(name).unwrap().render_gbuffer(64, 48, 3);
        g.validate().unwrap_or_else(|e| panic!("{name}: {e:#}"));
        let sky = g.depth.iter().filter(|z| z.is_infinite()).count();
        let mirror = g.roughness.iter().zip(&g.depth).filter(|(r, z)| **r == 0.0 && z.is_finite()).count();
        assert!(sky < g.depth.len(), "{name}: all sky");
        assert!(mirror > 0 || name == "hallway", "{name}: no mirror pixels");
    }
    assert!(scene("nope").is_err());
}

#[test]
fn gbuffer_roundtrips_through_exr_and_json() {
    let g = small("floor");
    let p = tmp("floor.exr");
    g.save(&p).unwrap();
    let r = GBuffer::load(&p).unwrap();
    assert_eq!((r.width, r.height), (g.width, g.height));
    for (a, b) in [
        (&g.depth, &r.depth),
        (&g.normal, &r.normal),
        (&g.color, &r.color),
        (&g.motion, &r.motion),
        (&g.roughness, &r.roughness),
        (&g.metalness, &r.metalness),
        (&g.base_color, &r.base_color),
        (g.depth_far.as_ref().unwrap(), r.depth_far.as_ref().unwrap()),
    ] {
        assert_eq!(a.len(), b.len());
        assert!(a.iter().zip(b.iter()).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
    assert_eq!(r.camera, g.camera);
    // A G-buffer without the optional far depth stays without it (the tracers then keep HDRP's
    // constant slab: no far-depth layer in the parameters).
    let mut old = g.clone();
    old.depth_far = None;
    let p = tmp("floor_nofar.exr");
    old.save(&p).unwrap();
    let r = GBuffer::load(&p).unwrap();
    assert!(r.depth_far.is_none());
    let consts = host::ssr::pipeline::build_params(&r, &host::ssr::SsrSettings::default()).unwrap();
    assert_eq!(consts.far_depth_offset, 0);
}

/// The analytic scenes' far depth: never nearer than the depth, +inf exactly on the sky, and
/// larger than the depth where a sphere's outline is within a pixel.
#[test]
fn far_depth_bounds_the_depth() {
    let g = small("floor");
    let far = g.depth_far.as_ref().unwrap();
    assert!(far.iter().zip(&g.depth).all(|(f, z)| f >= z && (f.is_infinite() == z.is_infinite())));
    assert!(far.iter().zip(&g.depth).any(|(f, z)| z.is_finite() && *f > *z * 1.01));
}

fn expect_err(g: &GBuffer, want: &str) {
    let e = format!("{:#}", g.validate().expect_err(want));
    assert!(e.contains(want), "error {e:?} should mention {want:?}");
}

#[test]
fn bad_gbuffers_give_clear_errors() {
    let g = small("floor");
    // Mismatched sizes.
    let mut b = g.clone();
    b.roughness.pop();
    expect_err(&b, "size mismatch");
    // NaN depth.
    let mut b = g.clone();
    b.depth[5 * 64 + 7] = f32::NAN;
    expect_err(&b, "depth is NaN at pixel (7, 5)");
    // Non-invertible camera.
    let mut b = g.clone();
    b.camera.world_to_view[0..4].copy_from_slice(&[0.0; 4]);
    expect_err(&b, "not invertible");
    // Non-rigid camera.
    let mut b = g.clone();
    b.previous_camera.world_to_view[0] *= 2.0;
    expect_err(&b, "not rigid");
    // Bad field of view.
    let mut b = g.clone();
    b.camera.fov_y_degrees = 0.0;
    expect_err(&b, "fov_y_degrees");
    // Roughness out of range, non-finite motion.
    let mut b = g.clone();
    b.roughness[3] = 1.5;
    expect_err(&b, "roughness must be in [0, 1]");
    let mut b = g.clone();
    b.motion[9] = f32::INFINITY;
    expect_err(&b, "motion vector is not finite");
    // Base colour: NaN or outside [0, 1] (pixel named), or a missing channel's worth of values.
    let mut b = g.clone();
    b.base_color[3 * (2 * 64 + 4) + 1] = f32::NAN;
    expect_err(&b, "base color must be in [0, 1], got NaN at pixel (4, 2)");
    let mut b = g.clone();
    b.base_color[0] = 1.25;
    expect_err(&b, "base color must be in [0, 1]");
    let mut b = g.clone();
    b.base_color.truncate(3);
    expect_err(&b, "base color has 3 values");
    // Far depth nearer than the depth, or of the wrong size.
    let mut b = g.clone();
    b.depth_far.as_mut().unwrap()[40 * 64 + 10] = 0.5 * g.depth[40 * 64 + 10];
    expect_err(&b, "depth_far must be >= depth");
    let mut b = g.clone();
    b.depth_far.as_mut().unwrap().pop();
    expect_err(&b, "depth_far has");
}

#[test]
fn bad_gbuffer_files_give_clear_errors() {
    let g = small("thin");
    // Missing channel.
    let p = tmp("missing.exr");
    let n = g.width * g.height;
    host::io::write_exr(&p, g.width, g.height, &[("depth", &g.depth), ("roughness", &g.roughness[..n])]).unwrap();
    std::fs::write(
        host::ssr::gbuffer::camera_path(&p),
        serde_json_like(&g),
    )
    .unwrap();
    let e = format!("{:#}", GBuffer::load(&p).unwrap_err());
    assert!(e.contains("is not a G-buffer: it lacks the channels normal.X"), "{e}");
    // Size mismatch between EXR and JSON.
    let p = tmp("size.exr");
    g.save(&p).unwrap();
    let json = std::fs::read_to_string(host::ssr::gbuffer::camera_path(&p)).unwrap();
    std::fs::write(host::ssr::gbuffer::camera_path(&p), json.replacen("\"width\": 64", "\"width\": 65", 1)).unwrap();
    let e = format!("{:#}", GBuffer::load(&p).unwrap_err());
    assert!(e.contains("size mismatch"), "{e}");
    // Missing camera file.
    let p = tmp("nocam.exr");
    g.save(&p).unwrap();
    std::fs::remove_file(host::ssr::gbuffer::camera_path(&p)).unwrap();
    let e = format!("{:#}", GBuffer::load(&p).unwrap_err());
    assert!(e.contains("camera file"), "{e}");
    // NaN depth in a file.
    let mut b = g.clone();
    b.depth[0] = f32::NAN;
    let p = tmp("nan.exr");
    b.save(&p).unwrap();
    let e = format!("{:#}", GBuffer::load(&p).unwrap_err());
    assert!(e.contains("depth is NaN at pixel (0, 0)"), "{e}");
}

fn serde_json_like(g: &GBuffer) -> String {
    let p = tmp("tmpcam.exr");
    g.save(&p).unwrap();
    std::fs::read_to_string(host::ssr::gbuffer::camera_path(&p)).unwrap()
}

#[test]
fn camera_matrices_invert_and_project_consistently() {
    use host::ssr::camera::V3;
    let c = Camera::look_at(V3::new(1.0, 2.0, -3.0), V3::new(0.0, 0.5, 4.0), V3::Y, 55.0, 0.1);
    c.validate("camera").unwrap();
    let v = c.view();
    let inv = c.inv_view().unwrap();
    let id = v.mul_mat(&inv).to_rows();
    for (i, x) in id.iter().enumerate() {
        let want = if i % 5 == 0 { 1.0 } else { 0.0 };
        assert!((x - want).abs() < 1e-5, "{id:?}");
    }
    let e = c.eye();
    assert!((e[0] - 1.0).abs() < 1e-5 && (e[1] - 2.0).abs() < 1e-5 && (e[2] + 3.0).abs() < 1e-5);
    // Primary ray through a pixel projects back onto that pixel.
    let d = c.ray_dir(200, 100, 37.5, 81.5);
    let p = e + d * 7.0;
    let (sx, sy) = c.view_to_screen(200, 100, c.to_view(p));
    assert!((sx - 37.5).abs() < 1e-3 && (sy - 81.5).abs() < 1e-3, "{sx} {sy}");
}

#[test]
fn reference_mirror_matches_onscreen_where_rays_stay_on_screen() {
    let s = scene("floor").unwrap();
    let g = s.render_gbuffer(64, 48, 0);
    let r = host::ssr::render_reference(&s, &g, 0.6, 16);
    let glossy = r.glossy.iter().filter(|&&b| b).count();
    assert!(glossy > 500, "{glossy}");
    let mut full = 0;
    for i in 0..g.width * g.height {
        if r.glossy[i] && r.onscreen_fraction[i] == 1.0 {
            full += 1;
            assert_eq!(&r.all[3 * i..3 * i + 3], &r.onscreen[3 * i..3 * i + 3]);
        }
    }
    assert!(full > 100, "{full}");
}

/// The depth pyramid holds device depth (near / z) and each coarser cell the maximum of the cells
/// below: bit for bit the device depth of an independently built pyramid of minimum linear depth
/// (the form the tracers read before the conversion moved into the pyramid), far-depth layer
/// included, on odd-sized frames (edge texels of odd mips).
#[test]
fn depth_pyramid_is_device_depth_of_the_min_linear_pyramid() {
    use host::ssr::pipeline::{build_params, pyramid_texels, Runner};
    use shader_core::ssr::params::mip_size;
    use shader_core::ssr::trace::{device_depth, p_mip_offset};
    // 67x45 has 8 mips, 37x29 7: the last pass writes two mips or one.
    for (name, w, h) in [("floor", 67, 45), ("hallway", 67, 45), ("thin", 37, 29)] {
        let g = scene(name).unwrap().render_gbuffer(w, h, 0);
        let p = build_params(&g, &host::ssr::SsrSettings::default()).unwrap();
        assert!(p.far_depth_offset != 0 && p.mip_count > 4, "{name}: the test wants a far layer and several mips");
        let pyr = Runner::new(&host::Backend::Cpu).depth_pyramid(&p, &g.depth_layers()).unwrap();
        let (w, h) = (p.width, p.height);
        // Oracle: min of linear depth, level by level, then near / z with the native division.
        let mut lin = vec![0.0f32; pyramid_texels(w, h)];
        lin[..(w * h) as usize].copy_from_slice(&g.depth);
        for l in 1..p.mip_count {
            let (pw, ph, lw, lh) = (mip_size(w, l - 1), mip_size(h, l - 1), mip_size(w, l), mip_size(h, l));
            let (src, dst) = (p_mip_offset(&p, l - 1) as usize, p_mip_offset(&p, l) as usize);
            for y in 0..lh {
                for x in 0..lw {
                    let mut m = f32::INFINITY;
                    for (cx, cy) in [(2 * x, 2 * y), (2 * x + 1, 2 * y), (2 * x, 2 * y + 1), (2 * x + 1, 2 * y + 1)] {
                        if cx < pw && cy < ph {
                            m = m.min(lin[src + (cy * pw + cx) as usize]);
                        }
                    }
                    lin[dst + (y * lw + x) as usize] = m;
                }
            }
        }
        let want: Vec<f32> = lin.iter().chain(g.depth_far.as_ref().unwrap()).map(|z| p.near / *z).collect();
        assert_eq!(pyr.len(), want.len(), "{name}");
        for (i, (a, b)) in pyr.iter().zip(&want).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "{name}: texel {i}: {a} vs {b}");
            assert_eq!(a.to_bits(), device_depth(&p, if i < lin.len() { lin[i] } else { g.depth_far.as_ref().unwrap()[i - lin.len()] }).to_bits());
        }
        // Depth <= 0 or NaN has no device depth the max pyramid could order: refused by name.
        for bad in [0.0f32, -1.0, f32::NAN] {
            let mut d = g.depth_layers();
            d[5] = bad;
            let e = Runner::new(&host::Backend::Cpu).depth_pyramid(&p, &d).unwrap_err().to_string();
            assert!(e.contains("depth must be > 0") && e.contains("pixel (5, 0)"), "{name}: {e}");
        }
    }
}

/// The colour pyramid (two mips per pass, `resolve::color_block`) is, texel for texel, the box
/// average of an independently built pyramid: mip by mip, each texel ((a + b) + (c + d)) * 0.25
/// of the (up to) 2x2 texels below, edge texels repeated for odd sizes; on odd-sized frames with
/// an even and an odd number of mips (so the last pass writes one mip or two).
#[test]
fn color_pyramid_is_the_box_pyramid_of_the_frame() {
    use host::ssr::pipeline::{build_params, pyramid_texels, Runner};
    use shader_core::ssr::params::mip_size;
    use shader_core::ssr::trace::p_mip_offset;
    let mut mip_counts = Vec::new();
    for (name, w, h) in [("floor", 67, 45), ("thin", 37, 29), ("hallway", 5, 3)] {
        let g = scene(name).unwrap().render_gbuffer(w, h, 0);
        let p = build_params(&g, &host::ssr::SsrSettings::default()).unwrap();
        mip_counts.push(p.mip_count);
        let pyr = Runner::new(&host::Backend::Cpu).color_pyramid(&p, &g.color).unwrap();
        let (w, h) = (p.width, p.height);
        let mut want = vec![f32::NAN; pyramid_texels(w, h) * 3];
        want[..g.color.len()].copy_from_slice(&g.color);
        for l in 1..p.mip_count {
            let (pw, ph, lw, lh) = (mip_size(w, l - 1), mip_size(h, l - 1), mip_size(w, l), mip_size(h, l));
            let (src, dst) = (p_mip_offset(&p, l - 1) as usize, p_mip_offset(&p, l) as usize);
            for y in 0..lh {
                for x in 0..lw {
                    let (x1, y1) = ((2 * x + 1).min(pw - 1), (2 * y + 1).min(ph - 1));
                    for c in 0..3 {
                        let t = |tx: u32, ty: u32| want[(src + (ty * pw + tx) as usize) * 3 + c];
                        want[(dst + (y * lw + x) as usize) * 3 + c] = ((t(2 * x, 2 * y) + t(x1, 2 * y)) + (t(2 * x, y1) + t(x1, y1))) * 0.25;
                    }
                }
            }
        }
        assert_eq!(pyr.len(), want.len(), "{name}");
        for (i, (a, b)) in pyr.iter().zip(&want).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "{name}: value {i} (texel {}): {a} vs {b}", i / 3);
        }
    }
    assert!(mip_counts.iter().any(|m| m % 2 == 0) && mip_counts.iter().any(|m| m % 2 == 1), "mip counts {mip_counts:?}: want both parities");
}

/// The trilinear colour lookup is the lerp of the two bilinear level lookups around its mip
/// (`resolve::sample_color` addresses mip l0 + 1 from mip l0's offset), at every mip of the
/// pyramid of an odd-sized frame, inside and outside [0, 1] in u and v.
#[test]
fn trilinear_colour_lookup_is_the_lerp_of_its_two_levels() {
    use host::ssr::pipeline::{build_params, Runner};
    use shader_core::ssr::resolve::{lerp, sample_color, sample_color_level};
    let g = scene("thin").unwrap().render_gbuffer(37, 29, 0);
    let p = build_params(&g, &host::ssr::SsrSettings::default()).unwrap();
    let pyr = Runner::new(&host::Backend::Cpu).color_pyramid(&p, &g.color).unwrap();
    assert!(p.color_max_mip >= 3, "{}", p.color_max_mip);
    let mut checked = 0;
    for level in 0..=p.color_max_mip {
        for f in [0.0f32, 0.25, 0.5, 0.875] {
            for (u, v) in [(0.0f32, 0.0f32), (0.3, 0.7), (0.51, 0.49), (1.0, 1.0), (-0.2, 1.3), (0.97, 0.03)] {
                let c = sample_color(&p, &pyr, u, v, level as f32 + f);
                let a = sample_color_level(&p, &pyr, u, v, level);
                let want = if f > 0.0 && level < p.color_max_mip {
                    let b = sample_color_level(&p, &pyr, u, v, level + 1);
                    [lerp(a.x, b.x, f), lerp(a.y, b.y, f), lerp(a.z, b.z, f)]
                } else {
                    [a.x, a.y, a.z]
                };
                assert_eq!([c.x.to_bits(), c.y.to_bits(), c.z.to_bits()], want.map(f32::to_bits), "mip {level} + {f} at ({u}, {v})");
                checked += 1;
            }
        }
    }
    assert!(checked > 50);
}
