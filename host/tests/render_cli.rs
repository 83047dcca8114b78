//! `host render` as a user runs it: outputs, reproducibility, and bad input named.

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

const CORNELL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");

#[test]
fn builtin_render_writes_exr_png_and_json_and_is_reproducible() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sub/r.exr");
    let o = out.to_str().unwrap();
    let args = ["render", "--device", "cpu", "--width", "24", "--height", "16", "--spp", "3", "--spp-per-pass", "2", "--detail", "5", "--quiet", "-o", o];
    let a = host(&args);
    assert!(a.status.success(), "{}", stderr(&a));
    for ext in ["exr", "png", "json"] {
        assert!(out.with_extension(ext).exists(), "{ext} missing");
    }
    let exr = host::io::read_exr(&out).unwrap();
    assert_eq!((exr.width, exr.height), (24, 16));
    for c in ["R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z", "depth.Z"] {
        exr.channel(c).unwrap_or_else(|e| panic!("channel {c}: {e}"));
    }
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.with_extension("json")).unwrap()).unwrap();
    assert_eq!(json["spp"], 3);
    assert!(json["rays_per_second"].as_f64().unwrap() > 0.0);
    assert_eq!(json["digest"].as_str().unwrap(), digest(&a));
    // Same seed and settings, another split into launches: the same image.
    let mut again = args.to_vec();
    again[10] = "1";
    let b = host(&again);
    assert!(b.status.success(), "{}", stderr(&b));
    assert_eq!(digest(&a), digest(&b), "the launch split changed the image");
    let mut other = args.to_vec();
    other.extend(["--seed", "9"]);
    let c = host(&other);
    assert_ne!(digest(&a), digest(&c), "another seed gave the same image");
}

#[test]
fn cornell_box_without_lights_gets_a_uniform_environment() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.exr");
    let a = host(&["render", CORNELL, "--device", "cpu", "--width", "16", "--height", "16", "--spp", "2", "--quiet", "-o", out.to_str().unwrap()]);
    assert!(a.status.success(), "{}", stderr(&a));
    assert!(stderr(&a).contains("no lights"), "{}", stderr(&a));
    let black = host(&["render", CORNELL, "--device", "cpu", "--width", "16", "--height", "16", "--spp", "2", "--env", "black", "--quiet", "-o", out.to_str().unwrap()]);
    assert!(!black.status.success());
    assert!(stderr(&black).contains("nothing lights the scene"), "{}", stderr(&black));
}

#[test]
fn bad_options_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.exr");
    let o = out.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--spp", "0"], "--spp"),
        (&["--width", "0"], "--width"),
        (&["--max-depth", "0"], "--max-depth"),
        (&["--env", "1,2"], "three"),
        (&["--env=-1"], ">= 0"),
        (&["--clamp=-1"], "--clamp"),
        (&["--exposure", "nan"], "--exposure"),
        (&["--env-scale", "inf"], "--env-scale"),
        (&["--camera", "nosuch"], "built-in scene has one camera"),
        (&["--width", "16384", "--height", "16384"], "2^26"),
        (&["--strategy", "guess"], "guess"),
    ];
    for (extra, want) in cases {
        let mut args = vec!["render", "--device", "cpu", "--quiet", "--detail", "4", "-o", o];
        args.extend_from_slice(extra);
        let r = host(&args);
        assert!(!r.status.success(), "{extra:?} was accepted");
        assert!(stderr(&r).contains(want) && !stderr(&r).contains("multiple times"), "{extra:?}: {}", stderr(&r));
    }
    let r = host(&["render", CORNELL, "--device", "cpu", "--camera", "7", "-o", o]);
    assert!(stderr(&r).contains("no such camera") && stderr(&r).contains("0 "), "{}", stderr(&r));
    let missing = dir.path().join("none.gltf");
    let r = host(&["render", missing.to_str().unwrap(), "--device", "cpu", "-o", o]);
    assert!(!r.status.success());
    assert!(stderr(&r).contains("none.gltf"), "{}", stderr(&r));
    assert!(!Path::new(o).exists(), "a failed render wrote its output");
}
