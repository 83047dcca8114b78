//! `host render --write-scene`: the built-in scene written as glTF renders back as the scene
//! itself (benches/peers renders that file with other renderers).

use std::path::Path;
use std::process::{Command, Output};

fn host(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host")).args(args).output().expect("running host")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn digest(o: &Output) -> String {
    let e = stderr(o);
    let at = e.find("image digest ").unwrap_or_else(|| panic!("no digest in: {e}"));
    e[at + 13..at + 29].to_string()
}

/// Renders SCENE (None: the built-in scene) on the CPU to `out` with `extra` options.
fn render(scene: Option<&Path>, out: &Path, size: &str, spp: &str, extra: &[&str]) -> Output {
    let mut args = vec!["render"];
    if let Some(s) = scene {
        args.push(s.to_str().unwrap());
    }
    args.extend(["--device", "cpu", "--width", size, "--height", size, "--spp", spp, "--quiet", "-o", out.to_str().unwrap()]);
    args.extend(extra);
    let o = host(&args);
    assert!(o.status.success(), "host {args:?}: {}", stderr(&o));
    o
}

fn mean_rgb(exr: &Path) -> f64 {
    let img = host::io::read_exr(exr).unwrap();
    let mut sum = 0.0;
    for c in ["R", "G", "B"] {
        sum += img.channel(c).unwrap().iter().map(|&v| v as f64).sum::<f64>();
    }
    sum / (3.0 * img.width as f64 * img.height as f64)
}

#[test]
fn written_builtin_scene_renders_bit_identical() {
    let dir = tempfile::tempdir().unwrap();
    let gltf = dir.path().join("builtin.gltf");
    let w = host(&["render", "--write-scene", gltf.to_str().unwrap(), "-o", dir.path().join("never.exr").to_str().unwrap()]);
    assert!(w.status.success(), "{}", stderr(&w));
    assert!(gltf.exists() && gltf.with_extension("bin").exists(), "{}", stderr(&w));
    assert!(!dir.path().join("never.exr").exists(), "--write-scene rendered");
    // Positions are moved to world space with the builder's own arithmetic, the materials'
    // factors and the camera (identity rotation) survive JSON exactly: the same scene buffer
    // up to the texture coordinates (not written; no texture reads them), so the same image.
    let direct = render(None, &dir.path().join("direct.exr"), "16", "1", &[]);
    let loaded = render(Some(&gltf), &dir.path().join("loaded.exr"), "16", "1", &[]);
    assert_eq!(digest(&direct), digest(&loaded), "the written built-in scene renders another image");
    assert!(!stderr(&loaded).contains("warning"), "{}", stderr(&loaded));
}

#[test]
fn written_scene_carries_the_overridden_camera() {
    let dir = tempfile::tempdir().unwrap();
    let gltf = dir.path().join("moved.gltf");
    let cam = ["--look-from", "0.3,1.2,3", "--look-at", "0,0.8,0", "--fov", "35", "--detail", "5"];
    let mut args = vec!["render", "--write-scene", gltf.to_str().unwrap()];
    args.extend(cam);
    let w = host(&args);
    assert!(w.status.success(), "{}", stderr(&w));
    let direct = dir.path().join("direct.exr");
    let loaded = dir.path().join("loaded.exr");
    render(None, &direct, "32", "16", &cam);
    render(Some(&gltf), &loaded, "32", "16", &[]);
    // A rotated camera goes through an f32 quaternion in the file, so its frame comes back
    // within a few ulps, not bit-identical (other digests): the same seeds then trace nearly
    // the same paths, and the image means agree to 4e-7 (measured), far below the 16-spp noise.
    // The camera left at the built-in one (a lost --look-at or --fov) moves the mean by 89%.
    let (a, b) = (mean_rgb(&direct), mean_rgb(&loaded));
    assert!((a - b).abs() <= 1e-4 * a, "mean {a} direct, {b} from the written file");
    let builtin = dir.path().join("builtin.exr");
    render(None, &builtin, "32", "16", &["--detail", "5"]);
    let c = mean_rgb(&builtin);
    assert!((a - c).abs() > 0.02 * a, "the override did not move the camera: {a} vs {c}");
}

#[test]
fn write_scene_refuses_other_formats_and_scene_files() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("s.glb");
    let o = host(&["render", "--write-scene", glb.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains(".gltf"), "{}", stderr(&o));
    assert!(!glb.exists());
    let cornell = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");
    let o = host(&["render", cornell, "--write-scene", dir.path().join("c.gltf").to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("built-in scene only"), "{}", stderr(&o));
}
