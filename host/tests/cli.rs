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

/// `host` with `XDG_RUNTIME_DIR` removed from its environment.
fn host_without_xdg(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host")).args(args).env_remove("XDG_RUNTIME_DIR").output().expect("running host")
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
    // the first data row (the header is not counted)
    assert!(text(&o).contains("row 1, column wm_z"), "{}", text(&o));
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
    assert!(text(&o).contains("--device auto: CPU backend") && text(&o).contains("no Vulkan adapter"), "{}", text(&o));
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
        // the map (enlarged to the legend's width) with tick marks on its axes, above a legend
        // strip with the colour bar
        let png = image::open(dir.path().join(format!("sub/ggx.{name}.png"))).unwrap().to_rgb8();
        let l = host::ssr::legend::layout(32, 16, true);
        assert_eq!(png.dimensions(), (l.width as u32, l.height as u32), "{name}");
        assert!(l.left > 0, "room for the y labels");
        let mut legend: Vec<[u8; 3]> = (l.image_h as u32..png.height()).flat_map(|y| (0..png.width()).map(move |x| (x, y))).map(|(x, y)| png.get_pixel(x, y).0).collect();
        legend.sort();
        legend.dedup();
        for c in [host::io::colormap(0.0), host::io::colormap(1.0), [0, 0, 0]] {
            assert!(legend.contains(&c), "{name}: the legend lacks {c:?}");
        }
        // tick marks: dark pixels in the left margin (the y labels) and just below the image
        let dark = |x: u32, y: u32| png.get_pixel(x, y).0.iter().all(|&c| c < 100);
        assert!((0..l.image_h as u32).any(|y| (0..l.left as u32 - 2).any(|x| dark(x, y))), "{name}: no y tick labels");
        let below = l.image_h as u32 + 3;
        assert!((l.left as u32..(l.left + l.image_w) as u32).filter(|&x| dark(x, below)).count() >= 7, "{name}: fewer than 7 x ticks");
    }
    let o = host(&["grid", "--alpha-min", "0"], &[]);
    assert!(!o.status.success());
    assert!(text(&o).contains("--alpha-min must be a positive number"), "{}", text(&o));
}

/// Assert that `host args` fails and that its message contains every one of `needles`.
#[track_caller]
fn fails_with(args: &[&str], needles: &[&str]) -> String {
    let o = host(args, &[]);
    let t = text(&o);
    assert!(!o.status.success(), "host {args:?} succeeded:\n{t}");
    assert!(!t.contains("panicked"), "host {args:?} panicked:\n{t}");
    for n in needles {
        assert!(t.contains(n), "host {args:?}: {n:?} missing from:\n{t}");
    }
    t
}

fn path(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn ssr_rejects_out_of_range_options_naming_option_and_range() {
    for (arg, option, range) in [
        ("--thickness=-1", "--thickness", "[0, 1]"),
        ("--thickness=nan", "--thickness", "[0, 1]"),
        ("--screen-fade=-5", "--screen-fade", "[0, 1]"),
        ("--bias=2", "--bias", "[0, 1)"),
        ("--bias=-3", "--bias", "[0, 1)"),
        ("--bias=1", "--bias", "[0, 1)"),
        ("--temporal-frames=0", "--temporal-frames", "1.."),
        ("--max-steps=0", "--max-steps", "1.."),
        ("--min-smoothness=1.5", "--min-smoothness", "[0, 1]"),
        ("--smoothness-fade-start=-0.1", "--smoothness-fade-start", "[0, 1]"),
        ("--hiz-roughness-cut=2", "--hiz-roughness-cut", "[0, 1]"),
        ("--spp=9", "--spp", "1..=8"),
        ("--rays-per-quad=3", "--rays-per-quad", "1, 2, 4"),
        ("--width=0", "--width", "1 to 4096"),
    ] {
        fails_with(&["ssr", arg, "--device", "cpu"], &[option, range]);
    }
}

#[test]
fn ssr_rejects_options_of_the_other_pipeline_and_a_fade_before_the_cut() {
    fails_with(&["ssr", "--resolve", "3x3", "--pipeline", "sssr", "--device", "cpu"], &["--resolve applies to --pipeline hdrp only"]);
    fails_with(&["ssr", "--trace", "linear16", "--pipeline", "sssr", "--device", "cpu"], &["--trace applies to --pipeline hdrp only"]);
    fails_with(&["ssr", "--spp", "4", "--device", "cpu"], &["--spp applies to --pipeline sssr only"]);
    fails_with(&["ssr", "--no-reuse", "--pipeline", "hdrp", "--device", "cpu"], &["--no-reuse applies to --pipeline sssr only"]);
    fails_with(&["ssr", "--no-ray-color", "--pipeline", "hdrp", "--device", "cpu"], &["--no-ray-color applies to --pipeline sssr only"]);
    fails_with(&["ssr", "--no-ray-color", "--no-fis", "--pipeline", "sssr", "--device", "cpu"], &["--no-ray-color", "--no-fis"]);
    fails_with(&["ssr", "--sampler", "caps", "--device", "cpu"], &["--sampler applies to"]);
    fails_with(&["ssr", "--min-smoothness", "0.7", "--device", "cpu"], &["--smoothness-fade-start (0.5) must be at least --min-smoothness (0.7)"]);
}

#[test]
fn ssr_with_no_glossy_pixel_says_nothing_was_measured() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ssr.exr");
    let o = host(
        &["ssr", "--scene", "animated", "--frame", "100000", "--width", "32", "--height", "32", "--device", "cpu", "-o", path(&out)],
        &[],
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("no glossy pixels: nothing measured"), "{t}");
    assert!(!t.contains("RMSE 0.0000"), "{t}");
}

/// Write an energy LUT with `host energy precompute` and return its .bin path.
fn precompute_lut(dir: &std::path::Path, name: &str, resolution: &str, samples: &str) -> std::path::PathBuf {
    let exr = dir.join(format!("{name}.exr"));
    let o = host(&["energy", "precompute", "--resolution", resolution, "--samples", samples, "--device", "cpu", "-o", path(&exr)], &[]);
    assert!(o.status.success(), "{}", text(&o));
    exr.with_extension("bin")
}

#[test]
fn unusable_energy_luts_are_rejected_naming_file_and_problem() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.exr");
    let one_sample = precompute_lut(dir.path(), "one_sample", "8", "1");
    fails_with(&["energy", "furnace", "--lut", path(&one_sample), "--device", "cpu", "-o", path(&out)], &[path(&one_sample), "1 samples: too few"]);
    let tiny = precompute_lut(dir.path(), "tiny", "1", "64");
    fails_with(&["ssr", "--lut", path(&tiny), "--width", "16", "--height", "16", "--device", "cpu", "-o", path(&out)], &[path(&tiny), "1 x 1", "too coarse"]);
    // A NaN in E: the first E word follows the magic, the two counts and the 4-word header.
    let good = precompute_lut(dir.path(), "good", "8", "64");
    let mut bytes = std::fs::read(&good).unwrap();
    bytes[32..36].copy_from_slice(&f32::NAN.to_bits().to_le_bytes());
    let nan = dir.path().join("nan.bin");
    std::fs::write(&nan, &bytes).unwrap();
    fails_with(&["energy", "furnace", "--lut", path(&nan), "--device", "cpu", "-o", path(&out)], &[path(&nan), "E at mu cell 0, roughness cell 0 is NaN"]);
    let truncated = dir.path().join("truncated.bin");
    std::fs::write(&truncated, &bytes[..bytes.len() - 6]).unwrap();
    fails_with(&["energy", "furnace", "--lut", path(&truncated), "--device", "cpu", "-o", path(&out)], &[path(&truncated)]);
}

#[test]
fn unwritable_outputs_fail_before_the_work_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    // A regular file where a directory is needed: unwritable even for root.
    let file = dir.path().join("file");
    std::fs::write(&file, "x").unwrap();
    let bad = file.join("sub/out.exr");
    let bad_md = file.join("sub/report.md");
    for args in [
        vec!["grid", "--device", "cpu", "-o", path(&bad)],
        vec!["energy", "precompute", "--device", "cpu", "-o", path(&bad)],
        vec!["energy", "furnace", "--device", "cpu", "-o", path(&bad)],
        vec!["bench", "energy", "--device", "cpu", "--report", path(&bad_md)],
        vec!["ssr", "--device", "cpu", "-o", path(&bad)],
        vec!["bench", "ssr", "--device", "cpu", "--report", path(&bad_md)],
        vec!["bench", "microfacet", "--device", "cpu", "--output", path(&bad_md)],
        vec!["bench", "vndf", "--device", "cpu", "--output", path(&bad_md)],
    ] {
        let t0 = std::time::Instant::now();
        let t = fails_with(&args, &["cannot write", path(&file)]);
        assert!(!t.contains("precomputing"), "{args:?} worked before failing:\n{t}");
        assert!(t0.elapsed().as_secs() < 5, "{args:?} took {:?} to fail", t0.elapsed());
    }
    // A read-only directory (root may write anyway: then there is nothing to test).
    let ro = dir.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    if std::fs::write(ro.join("probe"), "x").is_err() {
        fails_with(&["energy", "furnace", "--device", "cpu", "-o", path(&ro.join("f.exr"))], &["not writable", path(&ro)]);
    }
}

#[test]
fn benches_write_to_out_by_default_with_json_beside_the_markdown() {
    for (args, default) in [(["bench", "energy", "--help"], "out/energy-bench.md"), (["bench", "ssr", "--help"], "out/ssr_bench.md")] {
        let o = host(&args, &[]);
        assert!(text(&o).contains(default), "{}", text(&o));
    }
    let dir = tempfile::tempdir().unwrap();
    let md = dir.path().join("ssr.md");
    let o = host(
        &["bench", "ssr", "--scenes", "floor", "--width", "24", "--height", "24", "--reference-samples", "2", "--device", "cpu", "--report", path(&md)],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(md.with_extension("png").exists());
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(md.with_extension("json")).unwrap()).unwrap();
    assert!(json["run"]["cpu_threads"].as_u64().unwrap() >= 1);
    assert!(json["run"]["load_average_start"].is_array());
    assert!(!json["rows"].as_array().unwrap().is_empty());
}

#[test]
fn xdg_runtime_dir_is_provided_when_unset() {
    let o = host_without_xdg(&["info"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(!text(&o).contains("XDG_RUNTIME_DIR"), "{}", text(&o));
}

#[test]
fn device_auto_prefers_the_cpu_backend_to_a_software_adapter() {
    let o = host(&["info"], &[]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    if t.contains("DiscreteGpu") || t.contains("IntegratedGpu") || t.contains("VirtualGpu") {
        assert!(t.contains("--device auto: GPU backend, hardware adapter"), "{t}");
        return;
    }
    assert!(t.contains("--device auto: CPU backend"), "{t}");
    assert!(t.contains("no hardware GPU, only the software adapter") || t.contains("no Vulkan adapter"), "{t}");
    assert!(t.contains("selects: CPU backend"), "{t}");
    if t.contains("llvmpipe") {
        // Naming an adapter is asking for it.
        let o = host(&["info"], &[("HOST_ADAPTER", "llvmpipe")]);
        assert!(text(&o).contains("because HOST_ADAPTER=\"llvmpipe\" names an adapter"), "{}", text(&o));
        assert!(text(&o).contains("selects: GPU backend: llvmpipe"), "{}", text(&o));
        // The driver description counts too (two lavapipes differ only there), and a name that
        // matches nothing is an error listing what there is.
        let o = host(&["info", "--device", "gpu"], &[("HOST_ADAPTER", "mesa")]);
        assert!(text(&o).contains("selects: GPU backend: llvmpipe"), "{}", text(&o));
        let o = host(&["info", "--device", "gpu"], &[("HOST_ADAPTER", "no such adapter")]);
        assert!(!o.status.success(), "{}", text(&o));
        assert!(text(&o).contains("no Vulkan adapter matches HOST_ADAPTER=\"no such adapter\"; available: llvmpipe"), "{}", text(&o));
    }
}

#[test]
fn every_option_is_documented_and_help_matches_defaults() {
    for cmd in [&["grid"][..], &["ssr"], &["bench", "ssr-ablate"], &["bench", "ssr-wall"], &["bench", "ssr"], &["bench", "ssr-passes"], &["bench", "energy"], &["energy", "precompute"], &["energy", "furnace"], &["info"], &["render"], &["eval"]] {
        let mut args = cmd.to_vec();
        args.push("--help");
        let o = host(&args, &[]);
        let t = text(&o);
        let lines: Vec<&str> = t.lines().map(str::trim).collect();
        for (i, line) in lines.iter().enumerate().filter(|(_, l)| l.starts_with("--") || (l.starts_with('-') && l.get(2..3) == Some(",") && !l.starts_with("-h,"))) {
            // Long help: "--opt <OPT>" then its text, then "[default: x]": the text must come first.
            // (or "--opt <OPT>  text [default: x]" on one line when it fits).
            let help = match line.split_once("  ") {
                Some((_, h)) => h.trim(),
                None => lines.get(i + 1).copied().unwrap_or(""),
            };
            assert!(!help.is_empty() && !help.starts_with('[') && !help.starts_with('-'), "host {cmd:?}: undocumented option: {line}");
        }
    }
    let t = text(&host(&["ssr", "--help"], &[]));
    assert!(t.contains("0.4 here") && t.contains("HDRP's default is 0.9"), "{t}");
}

#[test]
fn ssr_bench_shows_na_where_nothing_was_measured() {
    let dir = tempfile::tempdir().unwrap();
    let md = dir.path().join("empty.md");
    let o = host(
        &["bench", "ssr", "--scenes", "animated", "--frame", "100000", "--width", "16", "--height", "16", "--reference-samples", "1", "--device", "cpu", "--report", path(&md)],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    let report = std::fs::read_to_string(&md).unwrap();
    assert!(report.contains("no glossy pixels: nothing measured"), "{report}");
    let rows: Vec<&str> = report.lines().filter(|l| l.starts_with("| ") && (l.contains("| HDRP") || l.contains("| SSSR"))).collect();
    assert!(!rows.is_empty());
    for r in rows {
        assert!(r.contains("| n/a |") && !r.contains("| 0.000 |") && !r.contains("| 0.0000 |"), "{r}");
    }
}

// `host eval`: table formats, bad tables, output locations.

#[test]
fn list_json_has_every_function_with_columns_and_entry_point() {
    let o = host(&["eval", "--list", "--json"], &[]);
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
    let o = host(&["eval", "ggx_d", "-i", dir.path().join("in.npy").to_str().unwrap(), "-o", out_npy.to_str().unwrap(), "--device", "cpu"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    let o = host(&["eval", "ggx_d", "-i", csv_in.to_str().unwrap(), "-o", out_csv.to_str().unwrap(), "--device", "cpu"], &[]);
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
    let o = host(&["eval", "ggx_d", "-i", p.to_str().unwrap(), "--device", "cpu"], &[]);
    assert!(!o.status.success());
    assert!(text(&o).contains("\"alpha_x\" twice"), "{}", text(&o));
    let mut npy = Vec::new();
    host::npy::write(&mut npy, &[2, 3], &[0.0; 6]).unwrap();
    let p = dir.path().join("bad.npy");
    std::fs::write(&p, npy).unwrap();
    let o = host(&["eval", "ggx_d", "-i", p.to_str().unwrap(), "--device", "cpu"], &[]);
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
        let o = host(&["eval", "ggx_d", "-i", p.to_str().unwrap(), "-o", out.to_str().unwrap(), "--device", device], &[]);
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
    let o = host(&["eval", "math_unary", "-i", p.to_str().unwrap(), "-o", out.to_str().unwrap(), "--device", "cpu"], &[]);
    assert!(!o.status.success());
    assert!(text(&o).contains(&format!("writing {}", out.display())), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(out.join("keep")).unwrap(), "keep");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().filter_map(|e| e.ok()).filter(|e| e.file_name().to_string_lossy().starts_with(".tmp")).collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

/// `host bench ssr-passes`: one row per pass with a cell per backend, the bits compared, JSON beside
/// the Markdown; configurations are checked as `host ssr` checks its options, and a backend that
/// does not exist is named.
#[test]
fn ssr_passes_times_every_backend_and_compares_their_bits() {
    let dir = tempfile::tempdir().unwrap();
    let md = dir.path().join("passes.md");
    let (w, h) = ("--width=40", "--height=24");
    // The GPU column needs an adapter (CI has lavapipe); without one, the CPU backend twice.
    let devices = if text(&host(&["info"], &[])).contains("llvmpipe") { "cpu,gpu:llvmpipe" } else { "cpu,cpu" };
    let o = host(
        &["bench", "ssr-passes", "--config", "--scene floor --pipeline sssr", "--config", "--scene thin --pipeline hdrp --resolve 3x3", w, h, "--devices", devices, "--rounds", "1", "--report", path(&md)],
        &[],
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let report = std::fs::read_to_string(&md).unwrap();
    for needle in ["| 1 | `--scene floor --pipeline sssr` | 40x24 |", "| depth pyramid |", "| resolve |", "| specular |", "| **frame** |", "| reflection + specular bits | same | same |"] {
        assert!(report.contains(needle), "{needle:?} missing from:\n{report}");
    }
    // Every timed cell holds one figure per backend.
    let frame = report.lines().find(|l| l.starts_with("| **frame** |")).unwrap();
    assert_eq!(frame.matches(" / ").count(), 2, "{frame}");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(md.with_extension("json")).unwrap()).unwrap();
    let rows = json["rows"].as_array().unwrap();
    assert!(rows.iter().any(|r| r["pass"] == "trace" && r["rounds_ms"].as_array().unwrap().len() == 1 && r["fastest_ms"].as_f64().unwrap() > 0.0), "{json}");
    assert!(rows.iter().all(|r| r["same_bits_as_first"] == true));
    // Against that run as the baseline: a ratio per cell, "-" for a configuration it lacks.
    let md2 = dir.path().join("again.md");
    let baseline = md.with_extension("json");
    let o = host(
        &["bench", "ssr-passes", "--config", "--scene floor --pipeline sssr", "--config", "--scene floor --pipeline hdrp", w, h, "--devices", devices, "--rounds", "1", "--baseline", path(&baseline), "--report", path(&md2)],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o));
    let again = std::fs::read_to_string(&md2).unwrap();
    let ratios = again.split("over the baseline's").nth(1).unwrap_or_else(|| panic!("no baseline table:\n{again}"));
    let frame = ratios.lines().find(|l| l.starts_with("| **frame** |")).unwrap();
    let cells: Vec<&str> = frame.trim_matches('|').split('|').map(str::trim).collect();
    assert!(cells[1].split(" / ").all(|c| c.ends_with('x') && c.trim_end_matches('x').parse::<f64>().unwrap() > 0.0), "{frame}");
    assert_eq!(cells[2], "- / -", "{frame}");
    // Bad input is named.
    let not_passes = dir.path().join("other.json");
    std::fs::write(&not_passes, r#"{"run": {}, "rows": [{"scene": "floor"}]}"#).unwrap();
    fails_with(&["bench", "ssr-passes", w, h, "--devices", "cpu", "--baseline", path(&not_passes)], &["--baseline", "other.json", "not a `host bench ssr-passes` JSON"]);
    fails_with(&["bench", "ssr-passes", w, h, "--devices", "cpu", "--baseline", "/nonexistent/b.json"], &["--baseline", "/nonexistent/b.json"]);
    fails_with(&["bench", "ssr-passes", w, h, "--devices", "cpu,tpu"], &["--devices", "\"tpu\"", "gpu:NAME"]);
    if devices.contains("gpu") {
        fails_with(&["bench", "ssr-passes", w, h, "--devices", "gpu:no such adapter"], &["gpu:no such adapter", "no Vulkan adapter matches \"no such adapter\"; available: llvmpipe"]);
    }
    fails_with(&["bench", "ssr-passes", "--config", "--scene floor --width 64", "--devices", "cpu"], &["--config", "--width"]);
    fails_with(&["bench", "ssr-passes", "--config", "--scene floor --pipeline sssr --resolve 3x3", w, h, "--devices", "cpu"], &["--resolve", "--pipeline hdrp"]);
    fails_with(&["bench", "ssr-passes", "--config", "--scene floor --thickness=-1", w, h, "--devices", "cpu"], &["--thickness", "[0, 1]"]);
    fails_with(&["bench", "ssr-passes", "--rounds", "0"], &["--rounds"]);
}

/// `-o out.npz` is refused before any work (only .csv and .npy are written), and CSV and .npy
/// inputs name a bad row the same way: data rows from 1, the header not counted.
#[test]
fn eval_refuses_other_formats_and_numbers_rows_alike() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("in.csv");
    std::fs::write(&csv, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,1,0.5,0.5\n0,0,1,inf,0.5\n").unwrap();
    let npz = dir.path().join("out.npz");
    let o = host(&["eval", "ggx_d", "-i", csv.to_str().unwrap(), "-o", npz.to_str().unwrap(), "--device", "cpu"], &[]);
    assert!(!o.status.success());
    assert!(text(&o).contains("not .npz") && text(&o).contains(".npy"), "{}", text(&o));
    assert!(!npz.exists(), "a .npz was written");
    let o = host(&["eval", "ggx_d", "-i", csv.to_str().unwrap(), "--device", "cpu"], &[]);
    assert!(!o.status.success());
    assert!(text(&o).contains("row 2, column alpha_x"), "{}", text(&o));
    let mut npy = Vec::new();
    host::npy::write(&mut npy, &[2, 5], &[0.0, 0.0, 1.0, 0.5, 0.5, 0.0, 0.0, 1.0, f32::INFINITY, 0.5]).unwrap();
    let p = dir.path().join("in.npy");
    std::fs::write(&p, npy).unwrap();
    let o = host(&["eval", "ggx_d", "-i", p.to_str().unwrap(), "--device", "cpu"], &[]);
    assert!(!o.status.success());
    assert!(text(&o).contains("row 2, column alpha_x"), "{}", text(&o));
    let help = host(&["eval", "--help"], &[]);
    assert!(text(&help).contains("data rows counted from 1"), "{}", text(&help));
}

/// `host ssr --input` given a render (not a G-buffer) names the missing channels, not the
/// render's JSON summary as a bad camera file.
#[test]
fn ssr_input_that_is_a_render_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let r = dir.path().join("render.exr");
    let o = host(&["render", "--device", "cpu", "--detail", "4", "--width", "8", "--height", "8", "--spp", "1", "--quiet", "-o", r.to_str().unwrap()], &[]);
    assert!(o.status.success(), "{}", text(&o));
    let s = dir.path().join("s.exr");
    let o = host(&["ssr", "--input", r.to_str().unwrap(), "--device", "cpu", "-o", s.to_str().unwrap()], &[]);
    assert!(!o.status.success());
    let t = text(&o);
    assert!(t.contains("is not a G-buffer") && t.contains("roughness") && t.contains("--gbuffer"), "{t}");
    assert!(!t.contains("camera file"), "{t}");
}

/// An input outside the function's domain (alpha_x = -0.5 for ggx_d, for which every function
/// returns NaN) is an error naming the row and its inputs, not a NaN row with status 0;
/// --allow-nonfinite writes the NaN row.
#[test]
fn eval_names_a_row_outside_the_domain() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("in.csv");
    std::fs::write(&csv, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,1,0.5,0.5\n0,0,1,-0.5,0.5\n").unwrap();
    let out = dir.path().join("out.csv");
    let o = host(&["eval", "ggx_d", "-i", csv.to_str().unwrap(), "-o", out.to_str().unwrap(), "--device", "cpu"], &[]);
    assert!(!o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("row 2: ggx_d returns NaN") && text(&o).contains("alpha_x = -0.5") && text(&o).contains("1 of 2 rows"), "{}", text(&o));
    assert!(!out.exists());
    let o = host(&["eval", "ggx_d", "-i", csv.to_str().unwrap(), "-o", out.to_str().unwrap(), "--device", "cpu", "--allow-nonfinite"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(std::fs::read_to_string(&out).unwrap().lines().nth(2).unwrap().ends_with(",NaN"));
}

/// `host info --json`: the facts of the text as one JSON object.
#[test]
fn info_json_has_the_adapters_and_the_backend() {
    let t = host(&["info"], &[]);
    assert!(t.status.success(), "{}", text(&t));
    let o = host(&["info", "--json"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("info --json prints JSON");
    let adapters = v["adapters"].as_array().unwrap();
    let out = String::from_utf8_lossy(&t.stdout);
    assert!(out.starts_with(&format!("Vulkan adapters: {}", adapters.len())), "{out}");
    for a in adapters {
        assert!(out.contains(a["name"].as_str().unwrap()), "{out}");
    }
    assert!(out.contains(&format!("selects: {}", v["backend"].as_str().unwrap())), "{out}");
    assert_eq!(v["spirv"]["usable"], true, "{v}");
    assert_eq!(v["device"], "auto");
}

/// `host energy furnace` and `host ssr` take the default energy tables from the user cache, as
/// `host render` does: computed on the first run, read on every later one.
#[test]
fn furnace_and_ssr_reuse_the_cached_energy_tables() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let env = [("XDG_CACHE_HOME", cache.to_str().unwrap())];
    let f = dir.path().join("f.exr");
    let furnace = ["energy", "furnace", "--device", "cpu", "--spheres", "2", "--size", "4", "--samples", "1", "-o", f.to_str().unwrap()];
    let first = host(&furnace, &env);
    assert!(first.status.success(), "{}", text(&first));
    assert!(text(&first).contains("precomputing the default energy tables"), "{}", text(&first));
    let cached: Vec<_> = std::fs::read_dir(cache.join("one-source-shading")).unwrap().collect();
    assert_eq!(cached.len(), 1, "{cached:?}");
    let again = host(&furnace, &env);
    assert!(again.status.success(), "{}", text(&again));
    assert!(!text(&again).contains("precomputing"), "the furnace recomputed the tables: {}", text(&again));
    let s = dir.path().join("s.exr");
    let ssr = host(&["ssr", "--scene", "floor", "--width", "16", "--height", "16", "--device", "cpu", "--reference-samples", "0", "-o", s.to_str().unwrap()], &env);
    assert!(ssr.status.success(), "{}", text(&ssr));
    assert!(!text(&ssr).contains("precomputing"), "ssr recomputed the tables: {}", text(&ssr));
}

/// The furnace PNG labels its rows (material, compensation) and columns (roughness), and the
/// environment around the spheres is coloured, so a white sphere (albedo 1) shows against it.
#[test]
fn furnace_png_is_labelled_and_shows_white_spheres() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("f.exr");
    let o = host(&["energy", "furnace", "--device", "cpu", "--spheres", "3", "--size", "24", "--samples", "4", "-o", f.to_str().unwrap()], &[]);
    assert!(o.status.success(), "{}", text(&o));
    let png = image::open(f.with_extension("png")).unwrap().to_rgb8();
    let (w, h) = (3 * 24, 6 * 24);
    assert!(png.width() > w && png.height() > h, "no room for labels: {:?}", png.dimensions());
    let (left, top) = (png.width() - w, png.height() - h);
    // the corner of the first sphere cell is environment, its centre the sphere (roughness 0
    // metal with compensation: albedo about 1, white)
    assert_eq!(png.get_pixel(left, top).0, host::energy::FURNACE_BACKGROUND);
    let c = png.get_pixel(left + 12, top + 24 + 12).0;
    assert!(c.iter().all(|&v| v > 240), "{c:?}");
    // dark label text left of and above the image
    let dark = |x0: u32, x1: u32, y0: u32, y1: u32| (y0..y1).flat_map(|y| (x0..x1).map(move |x| (x, y))).filter(|&(x, y)| png.get_pixel(x, y).0.iter().all(|&v| v < 100)).count();
    assert!(dark(0, left, top, png.height()) > 50, "no row labels");
    assert!(dark(left, png.width(), 0, top) > 20, "no column labels");
}

/// `host energy precompute`'s table PNGs are enlarged to a readable size with a legend: the
/// quantity, the axes and a colour bar.
#[test]
fn energy_table_pngs_have_a_legend() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("t.exr");
    let o = host(&["energy", "precompute", "--resolution", "8", "--samples", "64", "--avg-samples", "64", "--device", "cpu", "-o", exr.to_str().unwrap()], &[]);
    assert!(o.status.success(), "{}", text(&o));
    for name in ["t.E.png", "t.E_prime.png"] {
        let png = image::open(dir.path().join(name)).unwrap().to_rgb8();
        let l = host::ssr::legend::layout(8, 8, true);
        assert_eq!(png.dimensions(), (l.width as u32, l.height as u32), "{name}");
        let strip: Vec<[u8; 3]> = (l.image_h as u32..png.height()).flat_map(|y| (0..png.width()).map(move |x| (x, y))).map(|(x, y)| png.get_pixel(x, y).0).collect();
        for c in [host::io::colormap(0.0), host::io::colormap(1.0), [0, 0, 0]] {
            assert!(strip.contains(&c), "{name}: the legend lacks {c:?}");
        }
    }
}

/// Every benchmark is under `host bench`, and its help names each one; the old spellings
/// (`host ssr bench`, `host energy bench`) are refused.
#[test]
fn one_bench_tree_names_every_benchmark() {
    let t = text(&host(&["bench", "--help"], &[]));
    for sub in ["microfacet", "vndf", "kernels", "storage", "render", "energy", "ssr", "ssr-ablate", "ssr-wall", "ssr-passes"] {
        assert!(t.lines().any(|l| l.trim_start().starts_with(&format!("{sub} "))), "`host bench --help` does not list {sub}:\n{t}");
    }
    fails_with(&["ssr", "bench"], &["unexpected argument 'bench'"]);
    fails_with(&["energy", "bench"], &["unrecognized subcommand 'bench'"]);
}
