//! `host bench kernels`: the rate of every evaluable function on each backend, so the cost of
//! the harness (dispatch, layout, bounds checks) can be told apart from the cost of the math.
//!
//! Per function: evaluations per second on the CPU backend with all threads and with one thread
//! (their ratio is the CPU scaling), on the GPU backend (timestamp queries around the compute
//! pass: kernel time only, uploads and readback excluded) with both builds of the module (the
//! exact one, whose division and square root are `shader_core::ieee`'s corrected routines, and the
//! native one, which `HOST_DIV_SQRT=auto` loads where the driver rounds them correctly), and the driver's compile time of the function's own entry
//! point (its pipeline creation, first use). For `ggx_d` and
//! `sample_vndf_heitz` a hand-written WGSL kernel of the same formula (host/src/wgsl/
//! reference.wgsl, compiled by naga) runs over the same rows on the same adapter in the same
//! run: the rust-gpu / WGSL rate ratio says how far the rust-gpu kernel is from what the adapter
//! does with straightforward shader code. Rates are the fastest of `--repeats` timed runs after
//! one warm-up (other processes only slow runs down); medians are reported too.
//!
//! Inputs: `--rows` rows per function, drawn from fixed per-column ranges (see [`column_range`])
//! with a fixed seed, so two runs time the same work.

use crate::backend::{Backend, DeviceChoice};
use crate::gpu::{groups_2d, GpuContext, OutputSpec};
use crate::shaders::DivSqrt;
use crate::timing::{cpu_model, load_average};
use anyhow::{bail, Context, Result};
use serde::Serialize;
use shader_kernels::eval::{functions, EvalArgs, FunctionInfo};
use std::fmt::Write as _;
use std::path::PathBuf;

/// The WGSL speed references: (registered function, WGSL entry point).
pub const WGSL_REFERENCES: &[(&str, &str)] = &[("ggx_d", "wgsl_ggx_d"), ("sample_vndf_heitz", "wgsl_sample_vndf_heitz")];

/// The WGSL source of the references.
pub const WGSL_SOURCE: &str = include_str!("wgsl/reference.wgsl");

/// Options of `host bench kernels`.
#[derive(clap::Args, Debug, Clone)]
pub struct KernelsArgs {
    /// GPU backend to time besides the CPU backend: auto (a Vulkan adapter if there is one,
    /// lavapipe included), gpu (required), cpu (CPU columns only).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// Rows per timed evaluation (batch size).
    #[arg(long, default_value_t = 1 << 20, value_parser = clap::value_parser!(u32).range(1024..=1 << 26))]
    pub rows: u32,
    /// Timed runs per function and backend (after one warm-up); the fastest is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub repeats: u32,
    /// Only these functions (comma-separated names; default: every registered function).
    #[arg(long, value_delimiter = ',')]
    pub functions: Vec<String>,
    /// Markdown report; the JSON report is written beside it (same name, .json).
    #[arg(long, short, default_value = "out/kernel-rates.md")]
    pub output: PathBuf,
}

/// One function's measured rates (evaluations per second).
#[derive(Clone, Debug, Serialize)]
pub struct KernelRow {
    pub name: String,
    pub group: String,
    pub entry_point: String,
    pub cpu_rate: f64,
    pub cpu_median_rate: f64,
    pub cpu_one_thread_rate: f64,
    /// cpu_rate / cpu_one_thread_rate, the two timed in alternation ([`time_cpu_scaling`]).
    pub cpu_scaling: f64,
    /// Median over the alternated rounds of (one-thread time / all-thread time).
    pub cpu_scaling_median: f64,
    /// The exact build: division and square root by `shader_core::ieee` (exact anywhere).
    pub gpu_rate: Option<f64>,
    pub gpu_median_rate: Option<f64>,
    pub gpu_timing: Option<String>,
    /// Seconds the driver took to create this entry point's pipeline (exact build).
    pub gpu_compile_seconds: Option<f64>,
    /// The "native" build (`OpFDiv` / `Sqrt`), same adapter, same rows.
    pub gpu_native_rate: Option<f64>,
    pub gpu_native_compile_seconds: Option<f64>,
    /// gpu_native_rate / gpu_rate: what exact division and square root cost.
    pub exact_slowdown: Option<f64>,
    pub wgsl_rate: Option<f64>,
    /// The native build's rate over the WGSL kernel's (both with the driver's division and square
    /// root), timed in alternation: the median of the per-round ratios ([`time_paired`]).
    pub rust_gpu_over_wgsl: Option<f64>,
    /// gpu_rate / wgsl_rate (the default, exact module).
    pub exact_over_wgsl: Option<f64>,
}

impl KernelRow {
    /// The row of function `name` with its CPU figures and no GPU figures yet.
    pub fn cpu_only(name: &str, group: &str, entry_point: &str, c: CpuRates) -> KernelRow {
        KernelRow {
            name: name.into(),
            group: group.into(),
            entry_point: entry_point.into(),
            cpu_rate: c.rate,
            cpu_median_rate: c.median_rate,
            cpu_one_thread_rate: c.one_thread_rate,
            cpu_scaling: c.scaling,
            cpu_scaling_median: c.scaling_median,
            gpu_rate: None,
            gpu_median_rate: None,
            gpu_timing: None,
            gpu_compile_seconds: None,
            gpu_native_rate: None,
            gpu_native_compile_seconds: None,
            exact_slowdown: None,
            wgsl_rate: None,
            rust_gpu_over_wgsl: None,
            exact_over_wgsl: None,
        }
    }
}

/// The whole report, as written to JSON.
#[derive(Clone, Debug, Serialize)]
pub struct KernelReport {
    pub command: String,
    pub cpu: String,
    pub cpu_threads: usize,
    pub load_average_start: String,
    pub load_average_end: String,
    pub adapter: Option<String>,
    /// The build `--device gpu` loads on this adapter (`HOST_DIV_SQRT` as set for this run,
    /// `auto` by default) and why: "exact" or "native".
    pub default_build: Option<String>,
    pub default_build_why: Option<String>,
    pub rows: u32,
    pub repeats: u32,
    /// How many functions the run was asked for; `functions` holds fewer while it runs (the
    /// report is rewritten after every function, so a run cut short leaves what it measured).
    pub functions_total: usize,
    /// The exact build's cost over the native one (`exact_slowdown`) across the functions
    /// measured on both: median and worst, with the worst function's name.
    pub exact_slowdown_median: Option<f64>,
    pub exact_slowdown_worst: Option<f64>,
    pub exact_slowdown_worst_function: Option<String>,
    pub functions: Vec<KernelRow>,
}

/// (median, worst, worst function) of the rows' `exact_slowdown`, where any row has one.
fn exact_slowdown_summary(rows: &[KernelRow]) -> (Option<f64>, Option<f64>, Option<String>) {
    let both: Vec<(&str, f64)> = rows.iter().filter_map(|k| k.exact_slowdown.map(|x| (k.name.as_str(), x))).collect();
    let Some(&(worst_name, worst)) = both.iter().max_by(|a, b| a.1.total_cmp(&b.1)) else { return (None, None, None) };
    (Some(median(both.iter().map(|b| b.1).collect())), Some(worst), Some(worst_name.to_string()))
}

/// The range each input column is drawn from, by column name: directions are handled apart
/// (unit vectors in the upper hemisphere); `(lo, hi)` uniform otherwise.
pub fn column_range(col: &str) -> (f32, f32) {
    match col {
        c if c.starts_with("alpha") => (0.01, 1.0),
        "u0" | "u1" | "u2" | "uc" | "roughness" | "metallic" | "anisotropic" | "r" | "g" | "f0" | "f90" => (0.0, 1.0),
        c if c.starts_with("n_dot") || c.starts_with("v_dot") => (0.01, 1.0),
        c if c.starts_with("cos") => (-1.0, 1.0),
        "eta" | "n" => (1.1, 2.5),
        "k" => (0.0, 4.0),
        "exponent" => (0.0, 1000.0),
        "mode" => (0.0, 1.0),
        "x" | "y" | "a" | "b" => (-4.0, 4.0),
        c if c.starts_with("eta_") || c.starts_with("k_") => (0.2, 3.0),
        _ => (0.0, 1.0),
    }
}

/// `rows` rows of `f`'s inputs: `_x,_y,_z` triples are unit vectors with z > 0, other columns
/// uniform in [`column_range`]; a fixed PCG stream per function.
pub fn bench_inputs(f: &FunctionInfo, rows: usize) -> Vec<f32> {
    let mut rng = shader_core::rng::Pcg32::new(0x6b65_726e, f.name.bytes().fold(0u32, |h, b| h.wrapping_mul(31).wrapping_add(b as u32)));
    let ni = f.inputs.len();
    let mut v = vec![0.0f32; rows * ni];
    for r in 0..rows {
        let mut c = 0;
        while c < ni {
            let name = f.inputs[c];
            let is_dir = name.ends_with("_x") && f.inputs.get(c + 2).is_some_and(|z| z.ends_with("_z") && z[..z.len() - 2] == name[..name.len() - 2]);
            if is_dir {
                let cos_theta = 0.02 + 0.98 * rng.next_f32();
                let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
                let s = (1.0 - cos_theta * cos_theta).sqrt();
                v[r * ni + c] = s * phi.cos();
                v[r * ni + c + 1] = s * phi.sin();
                v[r * ni + c + 2] = cos_theta;
                c += 3;
            } else {
                let (lo, hi) = column_range(name);
                v[r * ni + c] = lo + (hi - lo) * rng.next_f32();
                c += 1;
            }
        }
    }
    v
}

use crate::timing::{best_and_median, median};

/// (best rate, median rate, timing source) of `f` over `input` on `backend`: one warm-up run,
/// then `repeats` timed runs; `tick` is called after each run (a progress bar's step).
pub fn time_eval(backend: &Backend, f: &FunctionInfo, input: &[f32], rows: usize, repeats: u32, tick: &dyn Fn()) -> Result<(f64, f64, String)> {
    // One output buffer for every run, as a program evaluating repeatedly would keep it: the CPU
    // backend's time is then the evaluation's, not the allocator's and the page faults'.
    let mut out = Vec::new();
    let warm = backend.eval_table_into(f, input, rows, &mut out)?;
    tick();
    let mut secs = Vec::new();
    for _ in 0..repeats {
        secs.push(backend.eval_table_into(f, input, rows, &mut out)?.seconds);
        tick();
    }
    let (best, med) = best_and_median(secs);
    Ok((rows as f64 / best, rows as f64 / med, warm.source.to_string()))
}

/// The WGSL reference entry point of registered function `name`, if it has one.
pub fn wgsl_entry(name: &str) -> Option<&'static str> {
    WGSL_REFERENCES.iter().find(|(n, _)| *n == name).map(|(_, e)| *e)
}

/// Load the WGSL reference module into `g` (first use) and create `entry`'s pipeline; the
/// (args, groups) of a launch over `rows` rows of `f`'s layout.
fn prepare_wgsl(g: &crate::gpu::GpuContext, entry: &str, f: &FunctionInfo, rows: usize) -> Result<(EvalArgs, (u32, u32, u32))> {
    let wg = shader_kernels::WORKGROUP_SIZE as usize;
    if rows * f.inputs.len().max(f.outputs.len()) * 4 > g.max_binding_bytes() {
        bail!("--rows {rows} exceeds the adapter's storage binding size for the WGSL reference");
    }
    if !g.has_module_for(entry) {
        let entries: Vec<&str> = WGSL_REFERENCES.iter().map(|(_, e)| *e).collect();
        g.add_wgsl("wgsl reference kernels", WGSL_SOURCE, &entries)?;
    }
    g.prepare(entry, 2, 1)?;
    let (gx, gy) = groups_2d(rows.div_ceil(wg) as u32);
    Ok((EvalArgs { rows: rows as u32, groups_x: gx }, (gx, gy, 1)))
}

/// Seconds of one launch of WGSL reference `entry` (prepared by [`prepare_wgsl`]).
fn wgsl_once(g: &crate::gpu::GpuContext, entry: &str, f: &FunctionInfo, input: &[f32], rows: usize, launch: &(EvalArgs, (u32, u32, u32))) -> Result<f64> {
    let (args, groups) = launch;
    let (_, t) = g.dispatch(entry, &[bytemuck::bytes_of(args), bytemuck::cast_slice(input)], &[OutputSpec::zeroed(rows * f.outputs.len() * 4)], *groups)?;
    Ok(t.seconds)
}

/// What [`time_paired`] measures.
#[derive(Clone, Copy, Debug)]
pub struct PairedRates {
    /// Best WGSL rate over the rounds (evaluations per second).
    pub wgsl: f64,
    /// Median over the rounds of (rust-gpu rate / WGSL rate) within the round.
    pub ratio: f64,
}

/// The rust-gpu kernel of `f` on `backend` (a GPU backend) and its WGSL reference `entry` on `g`
/// (the same adapter), timed in alternation: one warm-up each, then `repeats` rounds of one run
/// of each, so both see the same machine (on a shared machine the rate drifts by up to 2x between
/// runs a few seconds apart, which skews a ratio of two separately timed series).
pub fn time_paired(backend: &Backend, g: &crate::gpu::GpuContext, entry: &str, f: &FunctionInfo, input: &[f32], rows: usize, repeats: u32) -> Result<PairedRates> {
    let launch = prepare_wgsl(g, entry, f, rows)?;
    let mut out = Vec::new();
    backend.eval_table_into(f, input, rows, &mut out)?;
    wgsl_once(g, entry, f, input, rows, &launch)?;
    let (mut theirs, mut ratios) = (Vec::new(), Vec::new());
    for _ in 0..repeats.max(1) {
        let o = backend.eval_table_into(f, input, rows, &mut out)?.seconds;
        let w = wgsl_once(g, entry, f, input, rows, &launch)?;
        theirs.push(w);
        ratios.push(w / o);
    }
    let (best_w, _) = best_and_median(theirs);
    Ok(PairedRates { wgsl: rows as f64 / best_w, ratio: median(ratios) })
}

/// What [`time_cpu_scaling`] measures (evaluations per second).
#[derive(Clone, Copy, Debug)]
pub struct CpuRates {
    /// Best rate with all the CPU backend's threads.
    pub rate: f64,
    /// Median rate with all threads.
    pub median_rate: f64,
    /// Best rate on one thread.
    pub one_thread_rate: f64,
    /// Fastest one-thread time / fastest all-thread time.
    pub scaling: f64,
    /// Median over the rounds of (one-thread time / all-thread time) within the round.
    pub scaling_median: f64,
}

/// All-thread time the rounds of [`time_cpu_scaling`] cover at least (up to
/// [`CPU_SCALING_MAX_ROUNDS`] rounds), so sub-millisecond functions get more than `--repeats`.
const CPU_SCALING_SECONDS: f64 = 0.25;
/// Most rounds [`time_cpu_scaling`] runs.
const CPU_SCALING_MAX_ROUNDS: usize = 100;

/// `f` on the CPU backend with all its threads and on `one_thread` (a one-thread pool), timed in
/// alternation: rounds of one timed evaluation of each, each right after an untimed one on the
/// same threads (so that neither pays for waking the cores the other left idle: on a virtual
/// machine that alone cost up to half of a sub-millisecond evaluation); `repeats` rounds, more
/// for a function whose evaluations on all threads would not fill [`CPU_SCALING_SECONDS`] (the
/// cheapest take half a millisecond, within reach of one burst of load). The scaling is the
/// ratio of the two series' fastest times, as every rate here is the fastest run: on a shared
/// machine a burst of load on one core slows the all-thread runs it meets (the median of the
/// per-round ratios is kept beside it). Two series timed one after the other instead put a
/// burst in one series only (a recorded run gave 0.96x for `v_kelemen` that way, 1.8x in
/// alternation).
pub fn time_cpu_scaling(cpu: &Backend, one_thread: &rayon::ThreadPool, f: &FunctionInfo, input: &[f32], rows: usize, repeats: u32) -> Result<CpuRates> {
    let mut out = Vec::new();
    let warm = cpu.eval_table_into(f, input, rows, &mut out)?.seconds;
    let rounds = (repeats.max(1) as usize).max(((CPU_SCALING_SECONDS / warm.max(1e-9)).ceil() as usize).min(CPU_SCALING_MAX_ROUNDS));
    let (mut all, mut one, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..rounds {
        cpu.eval_table_into(f, input, rows, &mut out)?;
        let a = cpu.eval_table_into(f, input, rows, &mut out)?.seconds;
        let o = one_thread.install(|| -> Result<f64> {
            cpu.eval_table_into(f, input, rows, &mut out)?;
            Ok(cpu.eval_table_into(f, input, rows, &mut out)?.seconds)
        })?;
        all.push(a);
        one.push(o);
        ratios.push(o / a);
    }
    let (best_all, median_all) = best_and_median(all);
    let (best_one, _) = best_and_median(one);
    Ok(CpuRates {
        rate: rows as f64 / best_all,
        median_rate: rows as f64 / median_all,
        one_thread_rate: rows as f64 / best_one,
        scaling: best_one / best_all,
        scaling_median: median(ratios),
    })
}

/// Run the benchmark and write the Markdown and JSON reports.
pub fn run(a: &KernelsArgs) -> Result<()> {
    crate::io::prepare_output(&a.output)?;
    let json_path = a.output.with_extension("json");
    let selected: Vec<&'static FunctionInfo> = if a.functions.is_empty() {
        functions().collect()
    } else {
        a.functions.iter().map(|n| crate::eval::find_function(n)).collect::<Result<_>>()?
    };
    let load_start = load_average();
    let (cpu, gpu) = Backend::bench_pair(a.device)?;
    // Both builds of the main module on the same adapter: the exact one and the native.
    let default_build = gpu.as_ref().and_then(|b| b.gpu()).map(|g| (if g.div_sqrt == DivSqrt::Native { "native" } else { "exact" }.to_string(), g.div_sqrt_why.clone()));
    let (gpu, native) = match gpu.and_then(Backend::into_gpu) {
        Some(g) => {
            // The build `HOST_DIV_SQRT` selected is already loaded: load only the other one.
            let other = |v: DivSqrt| -> Result<Box<GpuContext>> {
                let m = crate::shaders::load_variant(v).map_err(anyhow::Error::msg)?;
                Ok(Box::new(GpuContext::new(&m)?))
            };
            let (exact, native) = match g.div_sqrt {
                DivSqrt::Exact => (g, other(DivSqrt::Native)?),
                DivSqrt::Native => (other(DivSqrt::Exact)?, g),
            };
            (Some(Backend::from(exact)), Some(Backend::from(native)))
        }
        None => (None, None),
    };
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().context("creating a one-thread pool")?;
    let rows = a.rows as usize;
    let pb = indicatif::ProgressBar::new(selected.len() as u64);
    pb.set_style(
        indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let total = selected.len();
    let adapter = gpu.as_ref().map(|g| g.describe());
    let default_build_why = default_build.as_ref().map(|b| b.1.clone());
    let default_build = default_build.map(|b| b.0);
    // Rewritten after every function, so a run that is stopped (a device call's time limit)
    // leaves a report of what it measured, marked partial.
    let write = |functions: &[KernelRow]| -> Result<String> {
        let summary = exact_slowdown_summary(functions);
        let report = KernelReport {
            command: crate::report::command_line(),
            cpu: cpu_model(),
            cpu_threads: crate::cpu::threads(),
            load_average_start: load_start.clone(),
            load_average_end: load_average(),
            adapter: adapter.clone(),
            default_build: default_build.clone(),
            default_build_why: default_build_why.clone(),
            rows: a.rows,
            repeats: a.repeats,
            functions_total: total,
            exact_slowdown_median: summary.0,
            exact_slowdown_worst: summary.1,
            exact_slowdown_worst_function: summary.2,
            functions: functions.to_vec(),
        };
        let md = markdown(&report);
        crate::io::write_file(&a.output, &md)?;
        crate::io::write_file(&json_path, serde_json::to_string_pretty(&report)?)?;
        Ok(md)
    };
    let mut out = Vec::new();
    for f in selected {
        pb.set_message(f.name);
        let input = bench_inputs(f, rows);
        let mut row = KernelRow::cpu_only(f.name, f.group, f.entry, time_cpu_scaling(&cpu, &one_thread, f, &input, rows, a.repeats)?);
        if let Some(g) = gpu.as_ref().and_then(|b| b.gpu()) {
            row.gpu_compile_seconds = Some(g.prepare(f.entry, 2, 1)?);
            let backend = gpu.as_ref().expect("GPU backend");
            let (r, m, src) = time_eval(backend, f, &input, rows, a.repeats, &|| {}).with_context(|| format!("timing {} on the GPU", f.name))?;
            row.gpu_rate = Some(r);
            row.gpu_median_rate = Some(m);
            row.gpu_timing = Some(src);
            if let Some(n) = native.as_ref().and_then(|b| b.gpu()) {
                row.gpu_native_compile_seconds = Some(n.prepare(f.entry, 2, 1)?);
                let (nr, _, _) = time_eval(native.as_ref().expect("native"), f, &input, rows, a.repeats, &|| {}).with_context(|| format!("timing {} (native module)", f.name))?;
                row.gpu_native_rate = Some(nr);
                row.exact_slowdown = Some(nr / r);
                if let Some(entry) = wgsl_entry(f.name) {
                    let pr = time_paired(native.as_ref().expect("native"), n, entry, f, &input, rows, a.repeats).with_context(|| format!("timing the WGSL {}", f.name))?;
                    row.wgsl_rate = Some(pr.wgsl);
                    row.rust_gpu_over_wgsl = Some(pr.ratio);
                    row.exact_over_wgsl = Some(r / pr.wgsl);
                }
            }
        }
        out.push(row);
        write(&out)?;
        pb.inc(1);
    }
    pb.finish_and_clear();
    let md = write(&out)?;
    eprint!("{md}");
    eprintln!("wrote {} and {}", a.output.display(), json_path.display());
    Ok(())
}

fn rate(v: Option<f64>) -> String {
    v.map_or("-".into(), |r| format!("{:.1}", r / 1e6))
}

/// The report as a Markdown table (rates in millions of evaluations per second).
pub fn markdown(r: &KernelReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "Command: `{}`\n", r.command);
    if r.functions.len() < r.functions_total {
        let _ = writeln!(s, "**Partial report**: {} of {} functions measured so far (the run was stopped or is still running).\n", r.functions.len(), r.functions_total);
    }
    let _ = writeln!(
        s,
        "Machine: {} ({} threads), load average {} at the start, {} at the end; {}; {} rows per run, best of {} runs.\n",
        r.cpu,
        r.cpu_threads,
        r.load_average_start,
        r.load_average_end,
        r.adapter.as_deref().unwrap_or("no GPU backend"),
        r.rows,
        r.repeats
    );
    if let Some(b) = &r.default_build {
        let _ = writeln!(
            s,
            "`--device gpu` loads the **{b}** build on this adapter ({}).\n",
            r.default_build_why.as_deref().unwrap_or("")
        );
    }
    let _ = writeln!(
        s,
        "GPU = the exact build (division and square root by `shader_core::ieee`, exact on any conformant device); \
         GPU native = the same kernels with `OpFDiv`/`Sqrt` (the build `HOST_DIV_SQRT=auto` loads where the driver rounds them correctly); exact cost = native rate / GPU rate. \
         WGSL = a hand-written kernel of the same formula (`host/src/wgsl/reference.wgsl`, naga, the driver's division); \
         rust-gpu / WGSL compares the native build with it, exact / WGSL the exact one. Compile = pipeline creation \
         (the driver's compile of that entry point). CPU scaling = CPU M/s / CPU 1-thread M/s, the two timed \
         in alternation (in brackets the median over the rounds of the ratio within a round). M/s = 10^6 evaluations per second.\n"
    );
    if !r.functions.is_empty() {
        let scaling: Vec<f64> = r.functions.iter().map(|k| k.cpu_scaling).collect();
        let at_least = scaling.iter().filter(|&&x| x >= 1.8).count();
        let lowest = r.functions.iter().min_by(|a, b| a.cpu_scaling.total_cmp(&b.cpu_scaling)).expect("non-empty");
        let _ = writeln!(
            s,
            "CPU scaling on {} threads: median {:.2}x, at least 1.8x for {} of {} functions, lowest {:.2}x (`{}`).\n",
            r.cpu_threads,
            median(scaling),
            at_least,
            r.functions.len(),
            lowest.cpu_scaling,
            lowest.name
        );
    }
    if let (Some(med), Some(worst), Some(name)) = (r.exact_slowdown_median, r.exact_slowdown_worst, &r.exact_slowdown_worst_function) {
        let n = r.functions.iter().filter(|k| k.exact_slowdown.is_some()).count();
        let _ = writeln!(s, "Exact cost (native rate / exact rate) over {n} functions: median {med:.2}x, worst {worst:.2}x (`{name}`).\n");
    }
    let _ = writeln!(s, "| function | CPU M/s | CPU 1-thread M/s | CPU scaling | GPU M/s | GPU median M/s | GPU compile ms | GPU native M/s | native compile ms | exact cost | WGSL M/s | rust-gpu / WGSL | exact / WGSL |");
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let ms = |c: Option<f64>| c.map_or("-".into(), |c| format!("{:.0}", c * 1e3));
    let x = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.2}"));
    for k in &r.functions {
        let _ = writeln!(
            s,
            "| {} | {:.1} | {:.1} | {:.2} ({:.2}) | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            k.name,
            k.cpu_rate / 1e6,
            k.cpu_one_thread_rate / 1e6,
            k.cpu_scaling,
            k.cpu_scaling_median,
            rate(k.gpu_rate),
            rate(k.gpu_median_rate),
            ms(k.gpu_compile_seconds),
            rate(k.gpu_native_rate),
            ms(k.gpu_native_compile_seconds),
            x(k.exact_slowdown),
            rate(k.wgsl_rate),
            x(k.rust_gpu_over_wgsl),
            x(k.exact_over_wgsl),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_scaling_is_the_ratio_of_the_fastest_runs_and_the_report_counts_it() {
        let f = crate::eval::find_function("ggx_d").unwrap();
        let rows = 4096;
        let input = bench_inputs(f, rows);
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let r = time_cpu_scaling(&Backend::Cpu, &one, f, &input, rows, 3).unwrap();
        assert!(r.rate > 0.0 && r.rate.is_finite() && r.one_thread_rate > 0.0 && r.one_thread_rate.is_finite(), "{r:?}");
        assert!(r.median_rate <= r.rate, "{r:?}");
        assert!((r.scaling - r.rate / r.one_thread_rate).abs() <= 1e-9 * r.scaling, "{r:?}");
        assert!(r.scaling_median > 0.0 && r.scaling_median.is_finite(), "{r:?}");

        let row = |name: &str, scaling: f64| {
            KernelRow::cpu_only(name, "g", "e", CpuRates { rate: 2.0e6, median_rate: 1.0e6, one_thread_rate: 1.0e6, scaling, scaling_median: 1.5 })
        };
        let report = KernelReport {
            command: "host bench kernels".into(),
            cpu: "test CPU".into(),
            cpu_threads: 2,
            load_average_start: "0".into(),
            load_average_end: "0".into(),
            adapter: None,
            default_build: None,
            default_build_why: None,
            rows: 1,
            repeats: 1,
            functions_total: 3,
            exact_slowdown_median: None,
            exact_slowdown_worst: None,
            exact_slowdown_worst_function: None,
            functions: vec![row("a", 1.95), row("b", 1.79), row("c", 1.8)],
        };
        let md = markdown(&report);
        assert!(!md.contains("Exact cost"), "{md}");
        // The exact build's cost: median and worst over the rows measured on both builds.
        let mut rows = report.functions.clone();
        for (k, x) in rows.iter_mut().zip([Some(1.5), None, Some(2.5)]) {
            k.exact_slowdown = x;
        }
        rows.push(KernelRow { exact_slowdown: Some(1.1), ..row("d", 1.9) });
        assert_eq!(exact_slowdown_summary(&rows), (Some(1.5), Some(2.5), Some("c".to_string())));
        let (m, w, n) = exact_slowdown_summary(&rows);
        let md2 = markdown(&KernelReport { exact_slowdown_median: m, exact_slowdown_worst: w, exact_slowdown_worst_function: n, functions: rows, ..report.clone() });
        assert!(md2.contains("Exact cost (native rate / exact rate) over 3 functions: median 1.50x, worst 2.50x (`c`)."), "{md2}");
        assert!(md.contains("CPU scaling on 2 threads: median 1.80x, at least 1.8x for 2 of 3 functions, lowest 1.79x (`b`)."), "{md}");
        assert!(md.contains("| b | 2.0 | 1.0 | 1.79 (1.50) |"), "{md}");
    }

    #[test]
    fn bench_inputs_are_in_range_with_unit_directions() {
        let f = crate::eval::find_function("conductor_sample_f").unwrap();
        let v = bench_inputs(f, 100);
        assert_eq!(v.len(), 100 * f.inputs.len());
        for row in v.chunks(f.inputs.len()) {
            let len2 = row[0] * row[0] + row[1] * row[1] + row[2] * row[2];
            assert!((len2 - 1.0).abs() < 1e-5 && row[2] > 0.0, "{row:?}");
            for (x, c) in row.iter().zip(f.inputs).skip(3) {
                let (lo, hi) = column_range(c);
                assert!(*x >= lo && *x <= hi, "{c} = {x}");
            }
        }
    }
}
