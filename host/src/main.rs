//! `host`: run the shading kernels on the GPU (wgpu/Vulkan) or the CPU and write the results.

use anyhow::{Context, Result};
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use host::{Backend, DeviceChoice};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "host",
    version,
    about = "Microfacet shading kernels written once in Rust, run on the GPU (rust-gpu SPIR-V via wgpu) or natively on the CPU",
    long_about = "Microfacet shading kernels written once in Rust, run on the GPU (rust-gpu SPIR-V via \
wgpu/Vulkan: a real GPU or Mesa lavapipe) or natively on the CPU with the very same code.\n\n\
--device auto uses a hardware GPU when there is one and otherwise the native CPU backend (a software \
Vulkan adapter such as lavapipe only with --device gpu), and says which and why. HOST_ADAPTER=<substring> picks an adapter by name or driver (e.g. llvmpipe, 22.3.6); HOST_DIV_SQRT=auto (default)|exact|native picks the build of the GPU kernels (auto: the driver's own division and square root where it rounds them correctly, checked at start-up, e.g. lavapipe; else the exact build, the device's division and square root corrected exactly)."
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Show the Vulkan adapters, the backend `--device` would pick, and the SPIR-V manifest; for
    /// a GPU backend, also which build of the kernels it loaded (HOST_DIV_SQRT: auto, exact or
    /// native division / square root) and whether the adapter's own division and square root
    /// are correctly rounded on the probe rows.
    Info {
        /// The choice whose backend to report: auto, cpu or gpu.
        #[arg(long, value_enum, default_value = "auto")]
        device: DeviceChoice,
        /// Print the same as one JSON object on standard output (adapters, spirv, backend,
        /// native_div_sqrt).
        #[arg(long)]
        json: bool,
    },
    /// Evaluate one shading function over a table (`--list` shows every function and its columns).
    ///
    /// CSV input: a header naming the function's input columns (any order; a missing, unknown or
    /// repeated column is an error). Directions are separate _x,_y,_z columns in the local
    /// shading frame (normal = +z), colours _r,_g,_b. The output CSV repeats the inputs and
    /// appends the outputs, each float written so it reads back to the same bits.
    ///
    /// NumPy input/output, chosen by the `.npy` extension: input shape (rows, inputs) with the
    /// columns in `--list` order, dtype float32 (float64 is rounded to float32); the output
    /// holds the outputs only, shape (rows, outputs), float32. Other extensions (`.npz`, ...)
    /// are refused; a name without one is CSV.
    ///
    /// Errors name the row as data rows counted from 1 in both formats (the CSV header is not
    /// counted), and the column.
    Eval {
        /// Function name, e.g. ggx_d.
        function: Option<String>,
        /// List every function with its input and output columns.
        #[arg(long)]
        list: bool,
        /// With --list: print the list as JSON (name, summary, group, inputs, outputs, entry_point).
        #[arg(long, requires = "list")]
        json: bool,
        /// Input table: .csv, .npy, or '-' for CSV on standard input.
        #[arg(long, short)]
        input: Option<PathBuf>,
        /// Output table: .csv or .npy ('-' or omitted: CSV on standard output). Its directory is
        /// created; an existing file is replaced only once the whole result is written.
        #[arg(long, short)]
        output: Option<PathBuf>,
        /// Backend: auto, cpu or gpu (see `host --help`).
        #[arg(long, value_enum, default_value = "auto")]
        device: DeviceChoice,
        /// Accept NaN and infinite inputs, and write NaN outputs (for stress testing), instead of
        /// rejecting them. Without it, a row whose output is NaN (every function returns NaN for
        /// inputs outside its domain, such as a negative roughness: docs/microfacet.md) is an
        /// error naming the row and its inputs.
        #[arg(long)]
        allow_nonfinite: bool,
    },
    /// Evaluate GGX D, Lambda and G1 over (angle, roughness) and write an EXR plus PNG previews.
    ///
    /// Columns: theta from 0 to 90 degrees (of wm for D, of w for Lambda and G1) at azimuth 0.
    /// Rows: alpha_x log-spaced from --alpha-max (top) to --alpha-min (bottom), alpha_y = alpha_x * --aspect.
    /// The PNGs show log10 D in [-6, 6], log10(1 + Lambda) in [0, 3] and G1 in [0, 1] (magenta = non-finite).
    Grid {
        /// Output EXR (channels ggx_d, ggx_lambda, ggx_g1); PNGs are written beside it.
        #[arg(long, short, default_value = "out/ggx_grid.exr")]
        output: PathBuf,
        /// Columns: theta samples from 0 to 90 degrees (at least 2; width x height at most 2^26).
        #[arg(long, default_value_t = 512)]
        width: usize,
        /// Rows: alpha_x samples, log-spaced (at least 2).
        #[arg(long, default_value_t = 256)]
        height: usize,
        /// alpha_x of the bottom row (positive).
        #[arg(long, default_value_t = 1e-3)]
        alpha_min: f32,
        /// alpha_x of the top row (above --alpha-min).
        #[arg(long, default_value_t = 1.0)]
        alpha_max: f32,
        /// alpha_y / alpha_x (positive; 1 = isotropic).
        #[arg(long, default_value_t = 1.0)]
        aspect: f32,
        /// Backend: auto, cpu or gpu (see `host --help`).
        #[arg(long, value_enum, default_value = "auto")]
        device: DeviceChoice,
    },
    /// Path-trace a glTF scene (or the built-in Cornell box) on the CPU or a GPU: EXR + PNG + JSON.
    ///
    /// Without SCENE, renders the built-in Cornell box: an area light, a front row of gold metal
    /// spheres and a back row of blue plastic spheres with roughness 0 to 1. Writes a linear EXR
    /// (R, G, B plus albedo.*, normal.* and depth.Z first-hit AOVs, each the mean over the pixel's
    /// samples), a tone-mapped PNG and a JSON summary (settings, scene, times, rays/s, image
    /// digest, warnings). The same seed and settings give a bit-identical image on every backend.
    /// A glTF file that breaks a bound of the specification is refused, naming the JSON path.
    ///
    /// Limits: width and height 1..=16384 with at most 2^26 pixels, --spp 1..=1000000,
    /// --exposure within [-64, 64].
    ///
    /// Ctrl-C (SIGINT) finishes the launch under way and writes the samples so far (every pixel
    /// holds the same number of samples; the JSON says `"interrupted": true` and
    /// `samples_per_pixel`), then exits with status 130; a second Ctrl-C aborts at once without
    /// writing. When stderr is not a terminal (a log, CI), a progress line is printed every
    /// --progress-every seconds instead of the bar.
    Render(host::render::cli::RenderCommand),
    /// Screen-space reflections (HDRP or stochastic SSR) on a built-in scene or an EXR G-buffer.
    ///
    /// Writes the reflection EXR (premultiplied RGB + opacity, the composite over the sky, hit
    /// mask, steps, and the ray-traced reference for built-in scenes) with PNG previews and debug
    /// views beside it, and prints the time per pass and the error against the reference.
    /// `host bench ssr` runs every configuration on every scene and writes the report.
    Ssr(host::ssr::cli::SsrCommand),
    /// Cost, accuracy and speed benchmarks, one per feature: `host bench microfacet | vndf |
    /// kernels | storage | render | energy | ssr | ssr-ablate | ssr-wall | ssr-passes`.
    Bench(host::bench::BenchCli),
    /// Energy compensation for GGX (Kulla-Conty, Turquin): `host energy precompute | furnace`
    /// (its benchmark: `host bench energy`).
    Energy(host::energy::EnergyCli),
}

/// The CLI's logger: the runner's info and warn messages (the `log` facade; which backend
/// `--device auto` picked and why, driver warnings) on stderr, as written. Other crates' logs
/// (wgpu's) stay off.
struct StderrLog;

impl log::Log for StderrLog {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Info && m.target().starts_with("runner")
    }
    fn log(&self, r: &log::Record) {
        if self.enabled(r.metadata()) {
            eprintln!("{}", r.args());
        }
    }
    fn flush(&self) {}
}

fn main() {
    if log::set_logger(&StderrLog).is_ok() {
        log::set_max_level(log::LevelFilter::Info);
    }
    let matches = Cli::command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    // Whether an option of `host ssr` was given on the command line (not a default).
    let ssr_given = |id: &str| {
        matches.subcommand_matches("ssr").and_then(|m| m.value_source(id)) == Some(clap::parser::ValueSource::CommandLine)
    };
    if let Err(e) = run(cli, &ssr_given) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli, ssr_given: &dyn Fn(&str) -> bool) -> Result<()> {
    match cli.cmd {
        Cmd::Info { device, json } => info(device, json),
        Cmd::Bench(b) => b.run(),
        Cmd::Energy(e) => e.run(),
        Cmd::Eval { function, list, json, input, output, device, allow_nonfinite } => {
            if list {
                if json {
                    println!("{}", host::eval::list_json());
                } else {
                    print!("{}", host::eval::list());
                }
                return Ok(());
            }
            let name = function.context("name a function (see `host eval --list`)")?;
            let f = host::eval::find_function(&name)?;
            let input = input.context("--input is required (a .csv or .npy file, or - for CSV on standard input)")?;
            let output = output.filter(|p| p.as_os_str() != "-");
            if let Some(p) = &output {
                host::eval::Format::of(p)?;
                host::io::prepare_output(p)?;
            }
            let t0 = std::time::Instant::now();
            let table = host::eval::read_table(f, &input, allow_nonfinite)?;
            let t_read = t0.elapsed().as_secs_f64();
            let backend = Backend::select(device)?;
            eprintln!("{}", backend.describe());
            let (out, t) = host::eval::run(&backend, f, &table)?;
            host::eval::check_outputs(f, &table, &out, allow_nonfinite)?;
            let t1 = std::time::Instant::now();
            match &output {
                Some(p) => {
                    host::eval::write_table(f, &table, &out, p)?;
                    eprintln!("wrote {} rows to {}", table.rows, p.display());
                }
                None => host::eval::write_table(f, &table, &out, std::path::Path::new("-"))?,
            }
            eprintln!(
                "{}: {} rows evaluated in {:.3} ms ({}); read {:.3} ms, write {:.3} ms",
                f.name,
                table.rows,
                t.seconds * 1e3,
                t.source,
                t_read * 1e3,
                t1.elapsed().as_secs_f64() * 1e3
            );
            Ok(())
        }
        Cmd::Ssr(cmd) => host::ssr::cli::main(cmd, ssr_given),
        Cmd::Render(cmd) => host::render::cli::main(cmd),
        Cmd::Grid { output, width, height, alpha_min, alpha_max, aspect, device } => {
            let spec = host::grid::GridSpec { width, height, alpha_min, alpha_max, aspect };
            spec.validate()?;
            host::io::prepare_output(&output)?;
            let backend = Backend::select(device)?;
            eprintln!("{}", backend.describe());
            let results = host::grid::evaluate(&backend, &spec)?;
            for r in &results {
                eprintln!(
                    "{:<11} {}x{} = {} evaluations in {:.3} ms ({})",
                    r.name,
                    width,
                    height,
                    width * height,
                    r.seconds * 1e3,
                    r.timing_source
                );
            }
            let pngs = host::grid::write(&output, &spec, &results)?;
            eprintln!("wrote {}", output.display());
            for p in pngs {
                eprintln!("wrote {}", p.display());
            }
            Ok(())
        }
    }
}

fn info(device: DeviceChoice, json: bool) -> Result<()> {
    host::gpu::ensure_xdg_runtime_dir();
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(desc);
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
    // the text lines, and the same facts as JSON
    let mut text = vec![format!("Vulkan adapters: {}", adapters.len())];
    let mut list = Vec::new();
    for a in &adapters {
        let i = a.get_info();
        let float = host::float_controls::describe_adapter(a);
        text.push(format!("  {} ({:?}, driver {} {})", i.name, i.device_type, i.driver, i.driver_info));
        text.push(format!("    {float}"));
        list.push(serde_json::json!({"name": i.name, "device_type": format!("{:?}", i.device_type), "driver": i.driver, "driver_info": i.driver_info, "float_controls": float}));
    }
    let spirv = match host::shaders::load() {
        Ok(m) => {
            text.push(format!(
                "SPIR-V: {} bytes, entry points {:?}, built with {} / spirv-builder {}, sources {} (fresh)",
                m.manifest.spv_bytes, m.manifest.entry_points, m.manifest.toolchain, m.manifest.spirv_builder, m.manifest.source_hash
            ));
            serde_json::json!({"usable": true, "bytes": m.manifest.spv_bytes, "entry_points": m.manifest.entry_points, "toolchain": m.manifest.toolchain, "spirv_builder": m.manifest.spirv_builder, "source_hash": m.manifest.source_hash})
        }
        Err(e) => {
            text.push(format!("SPIR-V: unusable: {e}"));
            serde_json::json!({"usable": false, "error": e.to_string()})
        }
    };
    // What the exact build's division and square root cost, in SPIR-V instructions per call.
    let exact = host::shaders::load_variant(host::shaders::DivSqrt::Exact).map_err(anyhow::Error::msg)?;
    let routines: Vec<(String, usize)> = shader_manifest::function_sizes(&exact.words)
        .map_err(anyhow::Error::msg)?
        .into_iter()
        .filter(|(n, _)| shader_manifest::is_kept_function_name(n))
        .collect();
    let shown: Vec<String> = routines.iter().map(|(n, c)| format!("{} {c}", n.rsplit("::").next().unwrap_or(n))).collect();
    text.push(format!("exact build's routines (SPIR-V instructions): {}", if shown.is_empty() { "none named".to_string() } else { shown.join(", ") }));
    let backend = Backend::select(device)?;
    text.push(format!("--device {:?} selects: {}", device, backend.describe()));
    let mut probe = serde_json::Value::Null;
    if let Some(g) = backend.gpu() {
        // Whatever auto chose: is the native build's division correctly rounded here? (Probed on
        // the loaded context when it holds the native build, else on a second one.)
        let p = if g.div_sqrt == host::shaders::DivSqrt::Native {
            host::div_sqrt_probe::run(g)?
        } else {
            let native = host::shaders::load_variant(host::shaders::DivSqrt::Native).map_err(anyhow::Error::msg)?;
            let gpu = host::gpu::GpuContext::new(&native)?;
            host::div_sqrt_probe::run(&gpu)?
        };
        text.push(match &p.first {
            None => format!("native build's OpFDiv/Sqrt on {}: correctly rounded on all {} probe rows", g.info.name, p.rows),
            Some(first) => format!("native build's OpFDiv/Sqrt on {}: differ from correctly rounded on {} of {} probe rows, first: {first}", g.info.name, p.differing, p.rows),
        });
        probe = serde_json::json!({"adapter": g.info.name, "rows": p.rows, "differing": p.differing, "first": p.first.as_ref().map(|f| f.to_string())});
    }
    if json {
        let v = serde_json::json!({"adapters": list, "spirv": spirv, "exact_routines": routines, "device": format!("{device:?}").to_lowercase(), "backend": backend.describe(), "native_div_sqrt": probe});
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        for l in text {
            println!("{l}");
        }
    }
    Ok(())
}
