//! `host`: run the shading kernels on the GPU (wgpu/Vulkan) or the CPU and write the results.

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use host::{Backend, DeviceChoice};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "host",
    version,
    about = "Microfacet shading kernels written once in Rust, run on the GPU (rust-gpu SPIR-V via wgpu) or natively on the CPU",
    long_about = "Microfacet shading kernels written once in Rust, run on the GPU (rust-gpu SPIR-V via \
wgpu/Vulkan: a real GPU or Mesa lavapipe) or natively on the CPU with the very same code.\n\n\
--device auto uses a Vulkan adapter when one exists and falls back to the CPU backend with a notice. \
HOST_ADAPTER=<substring> picks an adapter by name."
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Show the Vulkan adapters, the backend `--device` would pick, and the SPIR-V manifest.
    Info {
        #[arg(long, value_enum, default_value = "auto")]
        device: DeviceChoice,
    },
    /// Evaluate one shading function over a CSV table (`--list` shows every function and its columns).
    ///
    /// The input CSV's header names the function's input columns (any order). Directions are
    /// given as separate _x,_y,_z columns in the local shading frame (normal = +z). The output
    /// CSV repeats the inputs and appends the outputs, each float written so it reads back to
    /// the same bits.
    Eval {
        /// Function name, e.g. ggx_d.
        function: Option<String>,
        /// List every function with its input and output columns.
        #[arg(long)]
        list: bool,
        /// Input CSV ('-' for standard input).
        #[arg(long, short)]
        input: Option<PathBuf>,
        /// Output CSV ('-' or omitted for standard output).
        #[arg(long, short)]
        output: Option<PathBuf>,
        #[arg(long, value_enum, default_value = "auto")]
        device: DeviceChoice,
        /// Accept NaN and infinite inputs (for stress testing) instead of rejecting them.
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
        #[arg(long, short, default_value = "ggx_grid.exr")]
        output: PathBuf,
        #[arg(long, default_value_t = 512)]
        width: usize,
        #[arg(long, default_value_t = 256)]
        height: usize,
        #[arg(long, default_value_t = 1e-3)]
        alpha_min: f32,
        #[arg(long, default_value_t = 1.0)]
        alpha_max: f32,
        /// alpha_y / alpha_x.
        #[arg(long, default_value_t = 1.0)]
        aspect: f32,
        #[arg(long, value_enum, default_value = "auto")]
        device: DeviceChoice,
    },
    /// Screen-space reflections (HDRP or stochastic SSR) on a built-in scene or an EXR G-buffer.
    ///
    /// Writes the reflection EXR (premultiplied RGB + opacity, the composite over the sky, hit
    /// mask, steps, and the ray-traced reference for built-in scenes) with PNG previews and debug
    /// views beside it, and prints the time per pass and the error against the reference.
    /// `host ssr bench` runs every configuration on every scene and writes the report.
    Ssr(host::ssr::cli::SsrCommand),
    /// Cost and accuracy benchmarks: `host bench microfacet` (writes docs/microfacet-cost.md and .png).
    Bench(host::bench_microfacet::BenchCli),
    /// Energy compensation for GGX (Kulla-Conty, Turquin): `host energy precompute | furnace | bench`.
    Energy(host::energy::EnergyCli),
}

fn main() {
    if let Err(e) = run(Cli::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.cmd {
        Cmd::Info { device } => info(device),
        Cmd::Bench(b) => b.run(),
        Cmd::Energy(e) => e.run(),
        Cmd::Eval { function, list, input, output, device, allow_nonfinite } => {
            if list {
                print!("{}", host::eval::list());
                return Ok(());
            }
            let name = function.context("name a function (see `host eval --list`)")?;
            let f = host::eval::find_function(&name)?;
            let input = input.context("--input is required (a CSV file, or - for standard input)")?;
            let table = if input.as_os_str() == "-" {
                host::eval::parse_csv(f, std::io::stdin().lock(), allow_nonfinite)?
            } else {
                let file = std::fs::File::open(&input).with_context(|| format!("opening {}", input.display()))?;
                host::eval::parse_csv(f, file, allow_nonfinite).with_context(|| format!("in {}", input.display()))?
            };
            let backend = Backend::select(device)?;
            eprintln!("{}", backend.describe());
            let (out, t) = host::eval::run(&backend, f, &table)?;
            match output {
                Some(p) if p.as_os_str() != "-" => {
                    let file = std::fs::File::create(&p).with_context(|| format!("creating {}", p.display()))?;
                    host::eval::write_csv(f, &table, &out, std::io::BufWriter::new(file))?;
                    eprintln!("wrote {} rows to {}", table.rows, p.display());
                }
                _ => host::eval::write_csv(f, &table, &out, std::io::stdout().lock())?,
            }
            eprintln!("{}: {} rows in {:.3} ms ({})", f.name, table.rows, t.seconds * 1e3, t.source);
            Ok(())
        }
        Cmd::Ssr(cmd) => host::ssr::cli::main(cmd),
        Cmd::Grid { output, width, height, alpha_min, alpha_max, aspect, device } => {
            let spec = host::grid::GridSpec { width, height, alpha_min, alpha_max, aspect };
            spec.validate()?;
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

fn info(device: DeviceChoice) -> Result<()> {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(desc);
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
    println!("Vulkan adapters: {}", adapters.len());
    for a in &adapters {
        let i = a.get_info();
        println!("  {} ({:?}, driver {} {})", i.name, i.device_type, i.driver, i.driver_info);
        println!("    {}", host::float_controls::describe_adapter(a));
    }
    match host::shaders::load() {
        Ok(m) => println!(
            "SPIR-V: {} bytes, entry points {:?}, built with {} / spirv-builder {}, sources {} (fresh)",
            m.manifest.spv_bytes,
            m.manifest.entry_points,
            m.manifest.toolchain,
            m.manifest.spirv_builder,
            m.manifest.source_hash
        ),
        Err(e) => println!("SPIR-V: unusable: {e}"),
    }
    let backend = Backend::select(device)?;
    println!("--device {:?} selects: {}", device, backend.describe());
    Ok(())
}
