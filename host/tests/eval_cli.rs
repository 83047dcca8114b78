//! `host eval` as a user runs it: table formats, bad tables, output locations.

use std::process::{Command, Output};

fn host(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host")).args(args).env("XDG_RUNTIME_DIR", std::env::temp_dir()).output().expect("running host")
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

#[test]
fn list_json_has_every_function_with_columns_and_entry_point() {
    let o = host(&["eval", "--list", "--json"]);
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("--list --json prints JSON");
    let list = v.as_array().unwrap();
    assert_eq!(list.len(), shader_kernels::eval::functions().count());
    for (j, f) in list.iter().zip(shader_kernels::eval::functions()) {
        assert_eq!(j["name"], f.name);
        assert_eq!(j["entry_point"], f.entry);
        assert_eq!(j["inputs"].as_array().unwrap().len(), f.inputs.len());
        assert_eq!(j["outputs"].as_array().unwrap().len(), f.outputs.len());
    }
}

#[test]
fn npy_in_and_out_keeps_bits_and_creates_the_directory() {
    let dir = tempfile::tempdir().unwrap();
    let csv_in = dir.path().join("in.csv");
    std::fs::write(&csv_in, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,1,0.5,0.5\n0.6,0,0.8,0.3,0.2\n").unwrap();
    let mut npy_in = Vec::new();
    host::npy::write(&mut npy_in, &[2, 5], &[0.0, 0.0, 1.0, 0.5, 0.5, 0.6, 0.0, 0.8, 0.3, 0.2]).unwrap();
    std::fs::write(dir.path().join("in.npy"), npy_in).unwrap();
    let out_npy = dir.path().join("new/dir/out.npy");
    let out_csv = dir.path().join("other/out.csv");
    let o = host(&["eval", "ggx_d", "-i", dir.path().join("in.npy").to_str().unwrap(), "-o", out_npy.to_str().unwrap(), "--device", "cpu"]);
    assert!(o.status.success(), "{}", text(&o));
    let o = host(&["eval", "ggx_d", "-i", csv_in.to_str().unwrap(), "-o", out_csv.to_str().unwrap(), "--device", "cpu"]);
    assert!(o.status.success(), "{}", text(&o));
    let a = host::npy::read(&std::fs::read(&out_npy).unwrap()).unwrap();
    assert_eq!(a.shape, vec![2, 1]);
    let csv = std::fs::read_to_string(&out_csv).unwrap();
    let from_csv: Vec<f32> = csv.lines().skip(1).map(|l| l.rsplit(',').next().unwrap().parse().unwrap()).collect();
    assert_eq!(a.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), from_csv.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
}

#[test]
fn repeated_column_and_wrong_npy_shape_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("dup.csv");
    std::fs::write(&p, "wm_x,wm_y,wm_z,alpha_x,alpha_y,alpha_x\n0,0,1,0.5,0.5,0.1\n").unwrap();
    let o = host(&["eval", "ggx_d", "-i", p.to_str().unwrap(), "--device", "cpu"]);
    assert!(!o.status.success());
    assert!(text(&o).contains("\"alpha_x\" twice"), "{}", text(&o));
    let mut npy = Vec::new();
    host::npy::write(&mut npy, &[2, 3], &[0.0; 6]).unwrap();
    let p = dir.path().join("bad.npy");
    std::fs::write(&p, npy).unwrap();
    let o = host(&["eval", "ggx_d", "-i", p.to_str().unwrap(), "--device", "cpu"]);
    assert!(!o.status.success());
    assert!(text(&o).contains("3 columns; ggx_d needs 5"), "{}", text(&o));
}

/// A header-only table is zero rows on every backend (it used to panic on the GPU backend).
#[test]
fn header_only_table_gives_an_empty_result() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("h.csv");
    std::fs::write(&p, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n").unwrap();
    for device in ["cpu", "gpu"] {
        let out = dir.path().join(format!("o_{device}.csv"));
        let o = host(&["eval", "ggx_d", "-i", p.to_str().unwrap(), "-o", out.to_str().unwrap(), "--device", device]);
        if device == "gpu" && text(&o).contains("no Vulkan adapter") {
            assert!(std::env::var("CI").is_err(), "CI needs a Vulkan adapter: {}", text(&o));
            eprintln!("SKIPPED the GPU case: no Vulkan adapter");
            continue;
        }
        assert!(o.status.success(), "{device}: {}", text(&o));
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "wm_x,wm_y,wm_z,alpha_x,alpha_y,d\n");
    }
}

/// A failed write leaves an existing output untouched.
#[test]
fn failed_write_keeps_the_existing_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("in.csv");
    std::fs::write(&p, "x\n0.5\n").unwrap();
    // The output's directory exists but the name is taken by a directory: creating the
    // temporary file beside it works, the rename onto it fails.
    let out = dir.path().join("taken");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("keep"), "keep").unwrap();
    let o = host(&["eval", "math_unary", "-i", p.to_str().unwrap(), "-o", out.to_str().unwrap(), "--device", "cpu"]);
    assert!(!o.status.success());
    assert!(text(&o).contains(&format!("writing {}", out.display())), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(out.join("keep")).unwrap(), "keep");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().filter_map(|e| e.ok()).filter(|e| e.file_name().to_string_lossy().starts_with(".tmp")).collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}
