//! The `host` binary as a user runs it.

use std::process::{Command, Output};

fn host(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_host"));
    cmd.args(args).env("XDG_RUNTIME_DIR", std::env::temp_dir());
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("running host")
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// Hide every Vulkan driver from the loader: what a machine without a GPU stack sees.
const NO_VULKAN: &[(&str, &str)] = &[("VK_ICD_FILENAMES", "/nonexistent.json"), ("VK_DRIVER_FILES", "/nonexistent.json")];

#[test]
fn eval_list_names_every_function_with_columns() {
    let o = host(&["eval", "--list"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    let t = text(&o);
    for f in shader_kernels::eval::functions() {
        assert!(t.contains(f.name), "{} missing from --list", f.name);
        assert!(t.contains(&f.inputs.join(",")), "{} inputs missing", f.name);
    }
}

#[test]
fn eval_csv_round_trip_on_cpu() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.csv");
    let output = dir.path().join("out.csv");
    std::fs::write(&input, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,1,0.5,0.5\n0.6,0,0.8,0.3,0.3\n").unwrap();
    let o = host(&["eval", "ggx_d", "-i", input.to_str().unwrap(), "-o", output.to_str().unwrap(), "--device", "cpu"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    let out = std::fs::read_to_string(&output).unwrap();
    let mut lines = out.lines();
    assert_eq!(lines.next().unwrap(), "wm_x,wm_y,wm_z,alpha_x,alpha_y,d");
    let d: f32 = lines.next().unwrap().rsplit(',').next().unwrap().parse().unwrap();
    // D(n) = 1 / (pi alpha^2) for GGX.
    assert!((d - 1.0 / (std::f32::consts::PI * 0.25)).abs() < 1e-6, "{d}");
}

#[test]
fn bad_csv_input_is_named_in_the_error() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.csv");
    std::fs::write(&input, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,inf,0.5,0.5\n").unwrap();
    let o = host(&["eval", "ggx_d", "-i", input.to_str().unwrap(), "--device", "cpu"], &[]);
    assert!(!o.status.success());
    assert!(text(&o).contains("row 2, column wm_z"), "{}", text(&o));
    let o = host(&["eval", "no_such_function", "-i", input.to_str().unwrap()], &[]);
    assert!(!o.status.success());
    assert!(text(&o).contains("unknown function"), "{}", text(&o));
}

#[test]
fn auto_falls_back_to_cpu_without_an_adapter_and_gpu_fails_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("g.exr");
    let o = host(&["grid", "-o", exr.to_str().unwrap(), "--width", "16", "--height", "8"], NO_VULKAN);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("no Vulkan adapter found, running on the CPU backend"), "{}", text(&o));
    assert!(exr.exists());
    let o = host(&["grid", "-o", exr.to_str().unwrap(), "--device", "gpu"], NO_VULKAN);
    assert!(!o.status.success());
    assert!(text(&o).contains("no Vulkan adapter found"), "{}", text(&o));
}

#[test]
fn grid_writes_an_exr_a_user_can_open_and_pngs() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("sub/ggx.exr");
    let o = host(&["grid", "-o", exr.to_str().unwrap(), "--width", "32", "--height", "16", "--device", "cpu"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    let img = host::io::read_exr(&exr).unwrap();
    assert_eq!((img.width, img.height), (32, 16));
    let g1 = img.channel("ggx_g1").unwrap();
    assert!(g1.iter().all(|v| (0.0..=1.0).contains(v)));
    for name in ["ggx_d", "ggx_lambda", "ggx_g1"] {
        assert!(dir.path().join(format!("sub/ggx.{name}.png")).exists());
    }
    let o = host(&["grid", "--alpha-min", "0"], &[]);
    assert!(!o.status.success());
    assert!(text(&o).contains("--alpha-min must be a positive number"), "{}", text(&o));
}
