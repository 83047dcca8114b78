//! Developer tasks. `cargo xtask --help` lists them.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use cargo_gpu_install::spirv_builder::Capability;
use shader_manifest::{
    Manifest, MANIFEST_PATH, NATIVE_MANIFEST_PATH, NATIVE_SPV_PATH, SHADER_CRATES, SPV_PATH, SUBGROUP_MANIFEST_PATH, SUBGROUP_SPV_PATH,
    USER_SHADER_CRATES, USER_SHADER_MANIFEST_PATH, USER_SHADER_SPV_PATH,
};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

mod feature_deps;
mod launch_check;
mod import_cycles;
mod lavapipe;
mod mutants;
mod repo_paths;

/// The nightly that `spirv-builder 0.11.0` requires (its `rust-toolchain.toml`).
const TOOLCHAIN: &str = "nightly-2026-08-15";
const SPIRV_BUILDER: &str = "0.11.0";
const TARGET: &str = "spirv-unknown-vulkan1.2";

#[derive(Parser)]
#[command(about = "Developer tasks for the shading workspace")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Compile `shader-kernels` to SPIR-V with rust-gpu and store it (with its manifest) under runner/shaders/,
    /// and the example shader crate `examples/user-shader` beside its sources.
    ///
    /// The first run on a machine installs the pinned nightly (rust-src, rustc-dev, llvm-tools) and
    /// builds the `rustc_codegen_spirv` backend into the user cache (~/.cache/rust-gpu); the
    /// README's "Toolchains and the shader build" gives the measured time. Later runs reuse it.
    BuildShaders {
        /// Rebuild into a temporary directory and fail if the committed SPIR-V or manifest differ.
        #[arg(long)]
        check: bool,
        /// Only these modules (comma separated): kernels, native, subgroup, user-shader. Default: all.
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
    },
    /// Run the whole test suite, CPU-vs-GPU comparisons included (the README's test command).
    ///
    /// Installs Mesa lavapipe with apt-get when no Vulkan loader/ICD is present and we run as root
    /// (or --install-lavapipe is given); otherwise prints the command to run. Under CI=true a GPU
    /// comparison that cannot run fails the run.
    Test {
        /// Install lavapipe with apt-get if no Vulkan driver is found (default when running as root).
        #[arg(long)]
        install_lavapipe: bool,
        /// Extra arguments for `cargo test`.
        #[arg(trailing_var_arg = true)]
        rest: Vec<String>,
    },
    /// Download Mesa 25.0.7's lavapipe (Debian 12 backports, pinned by SHA-256) into
    /// target/lavapipe/ once, and print the environment that makes a program load it instead of
    /// the system's lavapipe (Mesa 22.3.6 on Debian 12), e.g.
    /// `env $(cargo xtask lavapipe) ./target/release/host bench storage`.
    ///
    /// Same LLVM 15, same bits (the test command checks both); the newer llvmpipe reads storage
    /// buffers 2-20x faster (docs/reports/storage-bench-mesa25.md). The system's Mesa is not
    /// touched.
    Lavapipe,
    /// Regenerate every measured report under docs/reports/ from fresh runs of the host's
    /// benchmarks.
    ///
    /// Builds the host (release) and runs, with explicit docs/reports/ output paths: bench
    /// microfacet (microfacet-cost.md, .png), bench vndf (vndf-bench.md, .png), bench kernels
    /// (kernel-rates.md), bench storage (storage-bench.md), the last two again on Mesa 25.0.7's
    /// lavapipe (*-mesa25.md; `cargo xtask lavapipe`), host bench energy (energy-bench.md, .png,
    /// .json), bench render (render-bench.md), energy furnace (energy-furnace.png), the SSR
    /// per-pass times (ssr-passes-1080p.md) and host bench ssr (ssr-bench.md, .png, .json). Every
    /// report is a file of its own (each with a JSON beside it); no hand-written doc is
    /// rewritten. Other outputs go to out/docs-reports/. Takes tens of minutes on 2 cores;
    /// review the diff before committing (the docs quote some of the figures).
    DocsReports {
        /// Only these reports (comma separated): microfacet, vndf, kernels, storage, storage-mesa25,
        /// kernels-mesa25, energy, render, furnace, ssr-passes, ssr.
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
    },
    /// Check that the formula tests catch wrong formulas: each mutant in xtask/src/mutants.rs
    /// replaces one formula's source with a wrong one, runs the CPU-side test meant to catch it
    /// and restores the file; fails if a test passes on its mutant (or fails on the unchanged
    /// source), or if a mutant's source piece is no longer in its file. Prints a Markdown table.
    /// About a minute per mutant on 2 cores (each rebuilds the crates above shader-core).
    Mutants {
        /// Only the mutants whose name contains this text.
        #[arg(long, default_value = "")]
        only: String,
    },
    /// Fail if any source, test, script, manifest or doc of the repository names a path outside
    /// it (xtask/src/repo_paths.rs says the rules): a fresh clone has nothing beside it. Also run
    /// by `cargo test -p xtask`.
    CheckPaths,
    /// Fail if the source files of a workspace crate import each other in a circle (a `use` or an
    /// inline `crate::`/`super::`/`self::` path from one file to another, directly or through
    /// others; xtask/src/import_cycles.rs says the rules). Prints each circle's files, with the
    /// names imported along its edges.
    CheckCycles,
    /// Fail if a feature crate below the CLI (fileio, scene, render, ssr, energy, eval, runner)
    /// depends on clap, plotters, indicatif or image at any depth, or has no doc example in its
    /// crate documentation (xtask/src/feature_deps.rs).
    CheckDeps,
    /// Fail if a library or binary source outside the launch mechanism (runner) and the kernel
    /// declarations (shader-kernels) writes an entry-point name in a string literal or branches
    /// on the backend's variant (xtask/src/launch_check.rs).
    CheckLaunch,
    /// Pack the real-GPU check for a machine without a Rust toolchain into .gpu-bundle/ (ignored
    /// by git): the host binary and the CPU-vs-GPU test binaries, stripped and xz-compressed, the
    /// Cornell box the tests read, and `run.sh` (xtask/gpu-run.sh), which runs the tests
    /// with CI=true and the kernel, SSR and render benchmarks there and writes its reports to $OUT.
    /// Fails if the bundle would exceed the device tool's 64 MiB transfer.
    GpuBundle {
        /// Test binaries of the `crosscheck` crate to include (comma separated). The default,
        /// `all_crosschecks`, holds every test file of the crate in one binary (each binary
        /// embeds the SPIR-V modules, about 9 MiB compressed, so only a few would fit).
        #[arg(long, value_delimiter = ',', default_value = "all_crosschecks")]
        tests: Vec<String>,
    },
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

fn main() -> Result<()> {
    match Cli::parse().cmd {
        Cmd::BuildShaders { check, only } => build_shaders(check, &only),
        Cmd::Test {
            install_lavapipe,
            rest,
        } => test(install_lavapipe, &rest),
        Cmd::Lavapipe => {
            let icd = lavapipe::ensure(&workspace_root())?;
            let vars: Vec<String> = lavapipe::env(&icd).iter().map(|(k, v)| format!("{k}={v}")).collect();
            println!("{}", vars.join(" "));
            Ok(())
        }
        Cmd::DocsReports { only } => docs_reports(&only),
        Cmd::GpuBundle { tests } => gpu_bundle(&tests),
        Cmd::Mutants { only } => mutants::run(&workspace_root(), &only),
        Cmd::CheckPaths => {
            let found = repo_paths::scan_tree(&workspace_root()).context("reading the tree")?;
            for f in &found {
                eprintln!("{f}");
            }
            if !found.is_empty() {
                bail!("{} path(s) outside the repository: a fresh clone has nothing beside it", found.len());
            }
            eprintln!("[check-paths] no path outside the repository");
            Ok(())
        }
        Cmd::CheckDeps => feature_deps::check(&workspace_root()),
        Cmd::CheckLaunch => {
            let faults = launch_check::scan_workspace(&workspace_root()).map_err(anyhow::Error::msg)?;
            for f in &faults {
                eprintln!("{f}");
            }
            if !faults.is_empty() {
                bail!("{} launch(es) outside the launch mechanism", faults.len());
            }
            eprintln!("[check-launch] every kernel is launched through its declaration; no source branches on the backend's variant");
            Ok(())
        }
        Cmd::CheckCycles => {
            let cycles = import_cycles::scan_workspace(&workspace_root()).map_err(anyhow::Error::msg)?;
            for c in &cycles {
                eprint!("{c}");
            }
            if !cycles.is_empty() {
                bail!("{} import circle(s): move what the files share into a module below them", cycles.len());
            }
            eprintln!("[check-cycles] no import circle in any workspace crate");
            Ok(())
        }
    }
}

/// The device tool's limit on what travels with one call: the working tree (tracked files) and
/// the carried paths together, less 4 MiB for the Vulkan loader packages (.gl/).
const TRANSFER_LIMIT: u64 = (64 - 4) << 20;

fn gpu_bundle(tests: &[String]) -> Result<()> {
    let root = workspace_root();
    let scenes = root.join("scenes/cornell_box");
    if !scenes.join("cornell_box.gltf").exists() {
        bail!("{} is missing: the render and SSR cross-checks read it", scenes.display());
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let ok = Command::new(&cargo).current_dir(&root).args(["build", "--release", "-p", "host"]).status().context("running cargo build")?.success();
    if !ok {
        bail!("cargo build --release -p host failed");
    }
    let mut args: Vec<String> = ["test", "--release", "-p", "crosscheck", "--no-run", "--message-format=json"].iter().map(|a| a.to_string()).collect();
    for t in tests {
        args.push("--test".into());
        args.push(t.clone());
    }
    let out = Command::new(&cargo).current_dir(&root).args(&args).stderr(std::process::Stdio::inherit()).output().context("running cargo test --no-run")?;
    if !out.status.success() {
        bail!("cargo test --no-run failed for {}", tests.join(", "));
    }
    // Each test binary appears as `"executable":"<path>"` in a compiler-artifact line whose
    // target name is the test's.
    let text = String::from_utf8_lossy(&out.stdout);
    let mut binaries: Vec<(String, PathBuf)> = Vec::new();
    for t in tests {
        let line = text
            .lines()
            .find(|l| l.contains(&format!("\"name\":\"{t}\"")) && l.contains("\"executable\":\""))
            .with_context(|| format!("cargo built no test binary named {t}"))?;
        let exe = line.split("\"executable\":\"").nth(1).and_then(|r| r.split('"').next()).context("unreadable cargo JSON")?;
        binaries.push((format!("test-{t}"), PathBuf::from(exe)));
    }
    binaries.push(("host".into(), root.join("target/release/host")));
    let dir = root.join(".gpu-bundle");
    if dir.exists() {
        std::fs::remove_dir_all(&dir).with_context(|| format!("removing {}", dir.display()))?;
    }
    std::fs::create_dir_all(dir.join("bin"))?;
    for (name, exe) in &binaries {
        let tmp = dir.join(name);
        std::fs::copy(exe, &tmp).with_context(|| format!("copying {}", exe.display()))?;
        let strip = Command::new("strip").arg(&tmp).status().context("running strip (binutils)")?;
        if !strip.success() {
            bail!("strip failed on {}", tmp.display());
        }
        let xz = Command::new("xz").args(["-T0", "-6", "-f"]).arg(&tmp).status().context("running xz")?;
        if !xz.success() {
            bail!("xz failed on {}", tmp.display());
        }
        std::fs::rename(dir.join(format!("{name}.xz")), dir.join("bin").join(format!("{name}.xz")))?;
    }
    std::fs::create_dir_all(dir.join("scenes/cornell_box"))?;
    for e in std::fs::read_dir(&scenes)? {
        let e = e?;
        if e.file_type()?.is_file() {
            std::fs::copy(e.path(), dir.join("scenes/cornell_box").join(e.file_name()))?;
        }
    }
    std::fs::copy(root.join("xtask/gpu-run.sh"), dir.join("run.sh"))?;
    // The test binaries reach the scenes through CARGO_MANIFEST_DIR baked in at build time.
    std::fs::write(dir.join("baked.env"), format!("BAKED_ROOT={}\n", root.display()))?;
    let head = Command::new("git").current_dir(&root).args(["describe", "--always", "--dirty"]).output().context("running git describe")?;
    std::fs::write(dir.join("commit"), String::from_utf8_lossy(&head.stdout).trim())?;
    let size = dir_size(&dir)?;
    for e in std::fs::read_dir(dir.join("bin"))? {
        let e = e?;
        eprintln!("[gpu-bundle] {} {:.1} MiB", e.file_name().to_string_lossy(), e.metadata()?.len() as f64 / 1048576.0);
    }
    let files = Command::new("git").current_dir(&root).args(["ls-files", "-z"]).output().context("running git ls-files")?;
    let tree: u64 = files
        .stdout
        .split(|&b| b == 0)
        .filter(|p| !p.is_empty())
        .filter_map(|p| std::fs::metadata(root.join(String::from_utf8_lossy(p).as_ref())).ok())
        .map(|m| m.len())
        .sum();
    if size + tree > TRANSFER_LIMIT {
        bail!(
            "the bundle ({:.1} MiB) and the working tree ({:.1} MiB) exceed the {} MiB a device call carries: pass fewer --tests",
            size as f64 / 1048576.0,
            tree as f64 / 1048576.0,
            TRANSFER_LIMIT >> 20
        );
    }
    eprintln!(
        "[gpu-bundle] wrote {} ({:.1} MiB; with the working tree {:.1} MiB). On the device machine: carry [\".gpu-bundle\", \".gl\"], run `bash .gpu-bundle/run.sh`",
        dir.display(),
        size as f64 / 1048576.0,
        (size + tree) as f64 / 1048576.0
    );
    Ok(())
}

fn dir_size(dir: &Path) -> Result<u64> {
    let mut total = 0;
    for e in std::fs::read_dir(dir)? {
        let e = e?;
        total += if e.file_type()?.is_dir() { dir_size(&e.path())? } else { e.metadata()?.len() };
    }
    Ok(total)
}

/// The reports of `cargo xtask docs-reports`: (name, host arguments). Each writes its own files
/// under docs/reports/ (outputs that are not reports go to out/docs-reports/). A name ending in
/// `-mesa25` runs on Mesa 25.0.7's lavapipe ([`lavapipe`]), `ssr-passes` on both lavapipes and
/// the CPU backend, the rest on the machine's own Vulkan driver.
const REPORTS: &[(&str, &[&str])] = &[
    (
        "microfacet",
        &["bench", "microfacet", "--device", "gpu", "--rows", "262144", "--repeats", "5", "--grid", "64", "--output", "docs/reports/microfacet-cost.md", "--plot", "docs/reports/microfacet-cost.png"],
    ),
    (
        "vndf",
        &[
            "bench", "vndf", "--device", "auto", "--samples", "1048576", "--rows", "1048576", "--repeats", "5", "--f0", "0.04", "--budget-ms", "1", "--output",
            "docs/reports/vndf-bench.md", "--plot", "docs/reports/vndf-bench.png",
        ],
    ),
    ("kernels", &["bench", "kernels", "--device", "gpu", "--rows", "262144", "--repeats", "3", "--output", "docs/reports/kernel-rates.md"]),
    ("storage", &["bench", "storage", "--repeats", "5", "--output", "docs/reports/storage-bench.md"]),
    ("storage-mesa25", &["bench", "storage", "--repeats", "5", "--output", "docs/reports/storage-bench-mesa25.md"]),
    ("kernels-mesa25", &["bench", "kernels", "--device", "gpu", "--rows", "262144", "--repeats", "3", "--output", "docs/reports/kernel-rates-mesa25.md"]),
    ("energy", &["bench", "energy", "--device", "auto", "--report", "docs/reports/energy-bench.md"]),
    ("render", &["bench", "render", "--device", "auto", "--report", "docs/reports/render-bench.md"]),
    ("furnace", &["energy", "furnace", "--device", "auto", "--spheres", "11", "--size", "64", "--samples", "256", "-o", "out/docs-reports/energy-furnace.exr"]),
    (
        "ssr-passes",
        &[
            "bench",
            "ssr-passes",
            "--devices",
            "gpu:22.3.6,gpu:25.0.7,cpu",
            "--config",
            "--scene floor --pipeline sssr",
            "--config",
            "--scene floor --pipeline hdrp",
            "--config",
            "--scene floor --pipeline hdrp --resolve 3x3",
            "--config",
            "--input out/ssr-scenes/cornell-1920x1080-main-c16-r64.exr --pipeline sssr",
            "--config",
            "--input out/ssr-scenes/cornell-1920x1080-main-c16-r64.exr --pipeline hdrp",
            "--report",
            "docs/reports/ssr-passes-1080p.md",
        ],
    ),
    (
        "ssr",
        &[
            "bench", "ssr", "--device", "auto", "--width", "128", "--height", "128", "--reference-samples", "256", "--colour-spp", "64", "--frame",
            "20", "--report", "docs/reports/ssr-bench.md", "--plot", "docs/reports/ssr-bench.png",
        ],
    ),
];

fn docs_reports(only: &[String]) -> Result<()> {
    let root = workspace_root();
    for name in only {
        if !REPORTS.iter().any(|(n, _)| n == name) {
            bail!("unknown report {name:?}; known: {}", REPORTS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "));
        }
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(&cargo).current_dir(&root).args(["build", "--release", "-p", "host"]).status().context("running cargo build")?;
    if !status.success() {
        bail!("cargo build --release -p host failed");
    }
    let target = std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|| root.join("target"));
    let host = target.join("release").join("host");
    // Run it by its path relative to the workspace (the reports quote their command line).
    let host = host.strip_prefix(&root).map(|r| PathBuf::from(".").join(r)).unwrap_or(host);
    for (name, args) in REPORTS.iter().filter(|(n, _)| only.is_empty() || only.iter().any(|o| o == n)) {
        eprintln!("[docs-reports] {name}: host {}", args.join(" "));
        let t0 = Instant::now();
        let mut cmd = Command::new(&host);
        cmd.current_dir(&root).args(*args);
        if name.ends_with("-mesa25") {
            for (k, v) in lavapipe::env(&lavapipe::ensure(&root)?) {
                cmd.env(k, v);
            }
        }
        if *name == "ssr-passes" {
            // Both lavapipes in one process; the cornell G-buffer is the 1080p bench's export.
            let cornell = root.join("out/ssr-scenes/cornell-1920x1080-main-c16-r64.exr");
            if !cornell.exists() {
                bail!("[docs-reports] ssr-passes needs {} (written by the 1080p `host bench ssr` of docs/ssr.md's \"Commands\")", cornell.display());
            }
            for (k, v) in lavapipe::env_beside_system(&lavapipe::ensure(&root)?)? {
                cmd.env(k, v);
            }
        }
        let status = cmd.status().with_context(|| format!("running {}", host.display()))?;
        if !status.success() {
            bail!("[docs-reports] {name} failed: host {}", args.join(" "));
        }
        if *name == "furnace" {
            std::fs::copy(root.join("out/docs-reports/energy-furnace.png"), root.join("docs/reports/energy-furnace.png"))
                .context("copying the furnace PNG to docs/reports/")?;
        }
        eprintln!("[docs-reports] {name}: done in {:.0?}", t0.elapsed());
    }
    eprintln!("[docs-reports] review `git diff docs/reports/` (the docs quote some of the figures)");
    Ok(())
}

/// The modules `cargo xtask build-shaders` writes (the names `--only` takes).
const MODULES: [&str; 4] = ["kernels", "native", "subgroup", "user-shader"];

fn build_shaders(check: bool, only: &[String]) -> Result<()> {
    for name in only {
        if !MODULES.contains(&name.as_str()) {
            bail!("unknown module {name:?}; known: {}", MODULES.join(", "));
        }
    }
    let wanted = |m: &str| only.is_empty() || only.iter().any(|o| o == m);
    let root = workspace_root();
    let shader_crate = root.join("shader-kernels");
    let t0 = Instant::now();
    eprintln!(
        "[build-shaders] preparing rust-gpu {SPIRV_BUILDER} backend on {TOOLCHAIN} \
         (cached in ~/.cache/rust-gpu; the first build on a machine takes long: see the README, \
         \"Toolchains and the shader build\")"
    );
    let mut install = cargo_gpu_install::install::Install::from_shader_crate(shader_crate.clone());
    install.auto_install_rust_toolchain = true;
    let backend = install
        .run()
        .context("installing the rust-gpu codegen backend")?;
    if backend.toolchain_channel != TOOLCHAIN {
        eprintln!(
            "[build-shaders] note: backend toolchain is {} (xtask pins {TOOLCHAIN})",
            backend.toolchain_channel
        );
    }
    eprintln!(
        "[build-shaders] backend ready in {:.0?}: {}",
        t0.elapsed(),
        backend.rustc_codegen_spirv_location.display()
    );

    if wanted("kernels") {
        build_module(&backend, &root, &shader_crate, &[], &[], &SHADER_CRATES, SPV_PATH, MANIFEST_PATH, "spirv-builder", check)?;
    }
    // The same kernels with native OpFDiv / Sqrt (shader_core::ieee::EXACT = false), for the
    // speed comparison and drivers known to round them correctly (docs/exactness.md).
    if wanted("native") {
        build_module(&backend, &root, &shader_crate, &["native-div-sqrt"], &[], &SHADER_CRATES, NATIVE_SPV_PATH, NATIVE_MANIFEST_PATH, "spirv-builder-native", check)?;
    }
    // The subgroup module: only the kernels that need subgroup operations, with their capabilities
    // (a device without them could not load a module declaring them; see shader-kernels/src/lib.rs).
    if wanted("subgroup") {
        build_module(
            &backend,
            &root,
            &shader_crate,
            &["subgroup-module"],
            &[Capability::GroupNonUniform, Capability::GroupNonUniformArithmetic],
            &SHADER_CRATES,
            SUBGROUP_SPV_PATH,
            SUBGROUP_MANIFEST_PATH,
            "spirv-builder-subgroup",
            check,
        )?;
    }
    // The example of a shader crate of one's own on shader-core (README, "Your own shader crate
    // on shader-core"): same backend, same post-processing. It shares the main module's target
    // directory, so shader-core and spirv-std are compiled for SPIR-V only once.
    if wanted("user-shader") {
        build_module(&backend, &root, &root.join("examples/user-shader"), &[], &[], &USER_SHADER_CRATES, USER_SHADER_SPV_PATH, USER_SHADER_MANIFEST_PATH, "spirv-builder", check)?;
    }
    Ok(())
}

/// Build one SPIR-V module of `shader_crate` (with `features` and extra `capabilities`), apply the
/// float decorations, and write it and its manifest (whose source hash covers `hash_crates`) to
/// `spv_rel` / `manifest_rel` (or, with `check`, compare against the committed files).
#[allow(clippy::too_many_arguments)]
fn build_module(
    backend: &cargo_gpu_install::install::InstalledBackend,
    root: &Path,
    shader_crate: &Path,
    features: &[&str],
    capabilities: &[Capability],
    hash_crates: &[&str],
    spv_rel: &str,
    manifest_rel: &str,
    target_dir: &str,
    check: bool,
) -> Result<()> {
    let t1 = Instant::now();
    let mut builder = backend.to_spirv_builder(shader_crate, TARGET);
    if !features.is_empty() {
        builder = builder.shader_crate_features(features.iter().map(|f| f.to_string()));
    }
    for c in capabilities {
        builder = builder.capability(*c);
    }
    builder.release = true;
    builder.multimodule = false;
    builder.build_script.defaults = false;
    // Full names so the seed functions of shader_core::ieee can be found by name; every name but
    // theirs and their callers' is stripped below (shader_manifest::strip_debug_info).
    builder.spirv_metadata = cargo_gpu_install::spirv_builder::SpirvMetadata::Full;
    // spirv-opt reassociates float arithmetic with constants (SPIRV-Tools folding rules apply to
    // every float op not decorated NoContraction), which breaks bit-exactness with the CPU. The
    // driver optimizes the module anyway, under the NoContraction decorations added below.
    builder.extra_args.push("--no-spirv-opt".into());
    // Keep the shader build's own target dir outside the host's so a host `cargo build` never races it.
    builder.target_dir_path = Some(root.join("target").join(target_dir));
    let result = builder.build().with_context(|| format!("compiling {} to SPIR-V", shader_crate.display()))?;
    let spv_path = result.module.unwrap_single().to_path_buf();
    let raw = std::fs::read(&spv_path).with_context(|| format!("reading {}", spv_path.display()))?;
    let words = shader_manifest::strip_debug_info(&shader_manifest::spirv_words(&raw), shader_manifest::is_kept_function_name).map_err(anyhow::Error::msg)?;
    // Forbid the driver from contracting or reassociating float arithmetic (see shader-manifest).
    let words = shader_manifest::decorate_no_contraction(&words).map_err(anyhow::Error::msg)?;
    let words = shader_manifest::preserve_signed_zero_inf_nan(&words).map_err(anyhow::Error::msg)?;
    let (total, covered) = shader_manifest::no_contraction_coverage(&words).map_err(anyhow::Error::msg)?;
    eprintln!("[build-shaders] NoContraction on {covered} of {total} float arithmetic instructions");
    // Division, sqrt, FMA, transcendentals: not required correctly rounded by Vulkan; only the
    // seeds of shader_core::ieee may hold them (host/tests/stale_shaders.rs fails otherwise).
    let inexact = shader_manifest::inexact_float_instructions(&words).map_err(anyhow::Error::msg)?;
    let list: Vec<String> = inexact.iter().map(|(n, c)| format!("{n} x{c}")).collect();
    eprintln!("[build-shaders] float instructions Vulkan does not require exact: {}", if list.is_empty() { "none".into() } else { list.join(", ") });
    if !features.contains(&"native-div-sqrt") {
        for b in shader_manifest::seed_rule_breaches(&words).map_err(anyhow::Error::msg)? {
            eprintln!("[build-shaders] warning: {b}");
        }
    }
    let spv: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let mut entry_points = result.entry_points.clone();
    entry_points.sort();
    eprintln!(
        "[build-shaders] compiled {} bytes, entry points {:?} in {:.0?}",
        spv.len(),
        entry_points,
        t1.elapsed()
    );

    let manifest = Manifest {
        source_hash: shader_manifest::source_hash_of(root, hash_crates).context("hashing shader sources")?,
        spv_bytes: spv.len() as u64,
        toolchain: backend.toolchain_channel.clone(),
        spirv_builder: SPIRV_BUILDER.into(),
        target: TARGET.into(),
        entry_points,
    };
    let json = manifest.to_json();
    let spv_out = root.join(spv_rel);
    let manifest_out = root.join(manifest_rel);
    if check {
        let old_spv = shader_manifest::read_module(root, spv_rel).map_err(anyhow::Error::msg)?.unwrap_or_default();
        let old_manifest = std::fs::read_to_string(&manifest_out).unwrap_or_default();
        let mut problems = Vec::new();
        if old_spv != spv {
            problems.push(format!(
                "{spv_rel} differs from a fresh build ({} vs {} bytes)",
                old_spv.len(),
                spv.len()
            ));
        }
        if old_manifest != json {
            problems.push(format!("{manifest_rel} differs from a fresh build"));
        }
        if !problems.is_empty() {
            bail!(
                "{}; run `cargo xtask build-shaders` and commit the result",
                problems.join("; ")
            );
        }
        eprintln!("[build-shaders] --check: committed {spv_rel} and its manifest are up to date");
    } else {
        shader_manifest::write_module(root, spv_rel, &spv).with_context(|| format!("writing {}", spv_out.display()))?;
        std::fs::write(&manifest_out, json)?;
        eprintln!("[build-shaders] wrote {spv_rel} and {manifest_rel}");
    }
    Ok(())
}

fn has_vulkan_driver() -> bool {
    let icd_dirs = [
        "/usr/share/vulkan/icd.d",
        "/etc/vulkan/icd.d",
        "/usr/local/share/vulkan/icd.d",
    ];
    let icd = icd_dirs.iter().any(|d| {
        std::fs::read_dir(d)
            .map(|mut it| it.next().is_some())
            .unwrap_or(false)
    }) || std::env::var_os("VK_ICD_FILENAMES").is_some()
        || std::env::var_os("VK_DRIVER_FILES").is_some();
    let loader = ["/usr/lib/x86_64-linux-gnu/libvulkan.so.1", "/usr/lib/libvulkan.so.1", "/usr/lib64/libvulkan.so.1"]
        .iter()
        .any(|p| Path::new(p).exists());
    icd && loader
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
        .unwrap_or(false)
}

const LAVAPIPE_INSTALL: &str = "apt-get update && apt-get install -y mesa-vulkan-drivers libvulkan1";

fn test(install_lavapipe: bool, rest: &[String]) -> Result<()> {
    let root = workspace_root();
    if !has_vulkan_driver() {
        if install_lavapipe || is_root() {
            eprintln!("[test] no Vulkan driver found: installing Mesa lavapipe ({LAVAPIPE_INSTALL})");
            let ok = Command::new("sh")
                .arg("-c")
                .arg(format!("DEBIAN_FRONTEND=noninteractive {LAVAPIPE_INSTALL}"))
                .status()
                .context("running apt-get")?
                .success();
            if !ok {
                bail!("installing lavapipe failed; run as root: {LAVAPIPE_INSTALL}");
            }
        } else {
            eprintln!(
                "[test] WARNING: no Vulkan driver found, the GPU comparisons will be skipped. \
                 To run them, install lavapipe as root: {LAVAPIPE_INSTALL}"
            );
        }
    }
    // `cargo test` in the workspace, with an XDG_RUNTIME_DIR for the Vulkan loader.
    let cargo_test = |args: &[&str]| -> Result<Command> {
        let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
        c.current_dir(&root).arg("test").args(args).args(rest);
        if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            let dir = std::env::temp_dir().join("xdg-runtime");
            std::fs::create_dir_all(&dir)?;
            c.env("XDG_RUNTIME_DIR", dir);
        }
        Ok(c)
    };
    let mut cmd = cargo_test(&["--workspace", "--release", "--no-fail-fast"])?;
    eprintln!("[test] cargo test --workspace --release --no-fail-fast {}", rest.join(" "));
    let status = cmd.status().context("running cargo test")?;
    // The GPU backend loads the native build where the driver rounds division and square root
    // correctly (HOST_DIV_SQRT=auto: lavapipe), so the comparisons above ran on it; run them
    // again with the exact build, the one every other adapter (a real GPU) loads. An explicit
    // HOST_DIV_SQRT choice is left alone: the user asked for one build.
    let mut exact_ok = true;
    if matches!(std::env::var("HOST_DIV_SQRT").as_deref(), Err(_) | Ok("") | Ok("auto")) {
        let mut again = cargo_test(&["--release", "-p", "crosscheck", "--no-fail-fast"])?;
        again.env("HOST_DIV_SQRT", "exact");
        eprintln!("[test] HOST_DIV_SQRT=exact cargo test --release -p crosscheck --no-fail-fast {} (the CPU-vs-GPU comparisons with the exact build: the device's division and square root as seeds, corrected exactly)", rest.join(" "));
        exact_ok = again.status().context("running cargo test")?.success();
    }
    // The comparisons once more on the second lavapipe (Mesa 25.0.7, `lavapipe`), whose
    // llvmpipe compiles the same SPIR-V with other code paths: CI (and whoever may install it)
    // fetches it; a machine that cannot load it says why. HOST_ADAPTER names its driver, so the
    // run fails rather than quietly comparing on the system's lavapipe.
    let mut mesa25_ok = true;
    let wants_mesa25 = install_lavapipe || is_root() || std::env::var("CI").is_ok_and(|v| v == "true" || v == "1");
    match lavapipe::unsupported_reason() {
        Some(why) => eprintln!("[test] the comparisons on Mesa {} lavapipe do not run: {why}", lavapipe::MESA_VERSION),
        None if !wants_mesa25 => eprintln!(
            "[test] the comparisons on Mesa {} lavapipe do not run: pass --install-lavapipe (or run as root) to fetch it",
            lavapipe::MESA_VERSION
        ),
        None => match lavapipe::ensure(&root) {
            Err(e) => {
                eprintln!("[test] fetching Mesa {} lavapipe failed: {e:#}", lavapipe::MESA_VERSION);
                mesa25_ok = false;
            }
            Ok(icd) => {
                let mut again = cargo_test(&["--release", "-p", "crosscheck", "--no-fail-fast"])?;
                let mut shown = Vec::new();
                for (k, v) in lavapipe::env(&icd) {
                    shown.push(format!("{k}={v}"));
                    again.env(k, v);
                }
                eprintln!("[test] {} cargo test --release -p crosscheck --no-fail-fast {} (the CPU-vs-GPU comparisons on Mesa {} lavapipe)", shown.join(" "), rest.join(" "), lavapipe::MESA_VERSION);
                mesa25_ok = again.status().context("running cargo test")?.success();
            }
        },
    }
    if !status.success() || !exact_ok || !mesa25_ok {
        let mut which = Vec::new();
        if !exact_ok {
            which.push("with HOST_DIV_SQRT=exact".to_string());
        }
        if !mesa25_ok {
            which.push(format!("on Mesa {} lavapipe", lavapipe::MESA_VERSION));
        }
        bail!("tests failed{}", if which.is_empty() { String::new() } else { format!(" ({})", which.join("; ")) });
    }
    Ok(())
}
