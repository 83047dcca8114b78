//! `host bench storage`: what reading a storage buffer costs the GPU backend's adapter, next to
//! the CPU reading the same values: the floor under every kernel that does little arithmetic per
//! value it reads (the SSR depth and colour pyramids, the specular pass, the neighbourhood
//! resolves; docs/ssr.md).
//!
//! Hand-written WGSL kernels (host/src/wgsl/storage.wgsl, compiled by naga), no project math:
//! invocation `i` sums K floats into `output[i]`, read from its own record of K (`input[i K + j]`,
//! as the SSR passes read G-buffer, ray and hit records) or K times from addresses every
//! invocation shares (`input[j]`, as the SSR passes read their parameter record while it was a
//! storage buffer), as K `f32` loads or K / 4 `vec4<f32>` loads. Every GPU result is checked
//! against the CPU's sums (exact: the inputs are multiples of 1/4), so a kernel that skipped its
//! reads would fail the run rather than look fast. GPU times are the timestamp queries around the
//! compute pass (uploads and readback excluded), CPU times the backend's thread pool over the same
//! reads; the fastest of `--repeats` runs after one warm-up, medians beside them.

use crate::backend::{Backend, DeviceChoice};
use crate::gpu::{groups_2d, GpuContext, OutputSpec};
use crate::report::{write_json, RunInfo};
use crate::timing::best_and_median;
use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// The WGSL template (`ELEM`, `SUM` and the entry points' prefix are filled in per load width).
const WGSL_TEMPLATE: &str = include_str!("wgsl/storage.wgsl");

/// Options of `host bench storage`.
#[derive(clap::Args, Debug, Clone)]
pub struct StorageArgs {
    /// Invocations per dispatch (default 2^21, about the pixels of a 1920x1080 frame).
    #[arg(long, default_value_t = 1 << 21, value_parser = clap::value_parser!(u32).range(1024..=1 << 24))]
    pub invocations: u32,
    /// Timed runs per kernel and backend (after one warm-up); the fastest is reported.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub repeats: u32,
    /// Markdown report; the JSON report is written beside it (same name, .json).
    #[arg(long, short, default_value = "out/storage-bench.md")]
    pub output: PathBuf,
}

/// One kernel: its entry point, floats it reads per invocation, load instructions per
/// invocation, and whether every invocation reads the same addresses.
struct Kernel {
    entry: &'static str,
    floats: usize,
    loads: usize,
    shared: bool,
}

const KERNELS: [Kernel; 6] = [
    Kernel { entry: "f32_own_1", floats: 1, loads: 1, shared: false },
    Kernel { entry: "f32_own_4", floats: 4, loads: 4, shared: false },
    Kernel { entry: "f32_own_16", floats: 16, loads: 16, shared: false },
    Kernel { entry: "f32_shared_16", floats: 16, loads: 16, shared: true },
    Kernel { entry: "vec4_own_1", floats: 4, loads: 1, shared: false },
    Kernel { entry: "vec4_own_4", floats: 16, loads: 4, shared: false },
];

/// One kernel's figures.
#[derive(Clone, Debug, Serialize)]
pub struct StorageRow {
    pub kernel: String,
    pub floats_per_invocation: usize,
    pub load_instructions_per_invocation: usize,
    pub shared_addresses: bool,
    pub gpu_ns_per_invocation: f64,
    pub gpu_median_ns_per_invocation: f64,
    /// Storage load instructions per second (all lanes), from the fastest run.
    pub gpu_load_instructions_per_s: f64,
    pub cpu_ns_per_invocation: f64,
    pub cpu_median_ns_per_invocation: f64,
    /// gpu_ns_per_invocation / cpu_ns_per_invocation.
    pub gpu_over_cpu_time: f64,
}

/// The WGSL module of one load width: `f32` or `vec4` records, entry points prefixed by it.
fn wgsl_module(prefix: &str) -> String {
    let (elem, sum) = if prefix == "vec4" { ("vec4<f32>", "v.x + v.y + v.z + v.w") } else { ("f32", "v") };
    WGSL_TEMPLATE.replace("ELEM", elem).replace("SUM", sum).replace("fn own_", &format!("fn {prefix}_own_")).replace("fn shared_", &format!("fn {prefix}_shared_"))
}

/// The input of kernel `k`: multiples of 1/4 below 2, so every sum is exact in f32.
fn input_of(k: &Kernel, n: usize) -> Vec<f32> {
    let len = if k.shared { k.floats } else { n * k.floats };
    (0..len).map(|j| (j % 7) as f32 * 0.25).collect()
}

/// The sums the kernel must produce, computed on the CPU backend's threads into `out`; returns
/// the seconds it took.
fn cpu_sums(k: &Kernel, input: &[f32], out: &mut [f32]) -> f64 {
    let t0 = Instant::now();
    let f = k.floats;
    if k.shared {
        out.par_iter_mut().for_each(|o| *o = input[..f].iter().sum());
    } else {
        out.par_iter_mut().zip(input.par_chunks_exact(f)).for_each(|(o, r)| *o = r.iter().sum());
    }
    t0.elapsed().as_secs_f64()
}

pub fn run(a: &StorageArgs) -> Result<()> {
    crate::io::prepare_output(&a.output)?;
    let backend = Backend::select(DeviceChoice::Gpu).context("host bench storage times the GPU backend's adapter")?;
    let Backend::Gpu(g) = &backend else { bail!("host bench storage needs the GPU backend") };
    eprintln!("{}", backend.describe());
    let info = RunInfo::start(Some(g.describe()));
    for prefix in ["f32", "vec4"] {
        let names: Vec<&str> = KERNELS.iter().map(|k| k.entry).filter(|e| e.starts_with(prefix)).collect();
        g.add_wgsl(&format!("storage bench ({prefix})"), &wgsl_module(prefix), &names)?;
    }
    let n = a.invocations as usize;
    let mut rows = Vec::new();
    let mut expected = vec![0.0f32; n];
    for k in &KERNELS {
        let input = input_of(k, n);
        let mut cpu = Vec::new();
        cpu_sums(k, &input, &mut expected);
        for _ in 0..a.repeats {
            cpu.push(cpu_sums(k, &input, &mut expected));
        }
        let mut gpu = Vec::new();
        for run in 0..=a.repeats {
            let (sums, secs) = gpu_sums(g, k.entry, &input, n)?;
            if let Some(i) = (0..n).find(|&i| sums[i].to_bits() != expected[i].to_bits()) {
                bail!("{}: invocation {i} wrote {} where its reads sum to {}", k.entry, sums[i], expected[i]);
            }
            if run > 0 {
                gpu.push(secs);
            }
        }
        let (gb, gm) = best_and_median(gpu);
        let (cb, cm) = best_and_median(cpu);
        let per = |s: f64| s * 1e9 / n as f64;
        let row = StorageRow {
            kernel: k.entry.into(),
            floats_per_invocation: k.floats,
            load_instructions_per_invocation: k.loads,
            shared_addresses: k.shared,
            gpu_ns_per_invocation: per(gb),
            gpu_median_ns_per_invocation: per(gm),
            gpu_load_instructions_per_s: (n * k.loads) as f64 / gb,
            cpu_ns_per_invocation: per(cb),
            cpu_median_ns_per_invocation: per(cm),
            gpu_over_cpu_time: gb / cb,
        };
        eprintln!("{:<14} GPU {:>7.2} ns  CPU {:>6.2} ns per invocation", row.kernel, row.gpu_ns_per_invocation, row.cpu_ns_per_invocation);
        rows.push(row);
    }
    let md = markdown(&info, a, &rows);
    crate::io::write_file(&a.output, md)?;
    let json = write_json(&a.output, info, &rows)?;
    println!("wrote {}", a.output.display());
    println!("wrote {}", json.display());
    Ok(())
}

/// One GPU dispatch of `entry` over `n` invocations: the sums and the pass's seconds.
fn gpu_sums(g: &GpuContext, entry: &str, input: &[f32], n: usize) -> Result<(Vec<f32>, f64)> {
    let (gx, gy) = groups_2d((n as u32).div_ceil(shader_kernels::WORKGROUP_SIZE));
    let args = [n as u32, gx];
    let (out, t) = g
        .dispatch(entry, &[bytemuck::cast_slice(&args), bytemuck::cast_slice(input)], &[OutputSpec::zeroed(n * 4)], (gx, gy, 1))
        .with_context(|| format!("dispatching {entry}"))?;
    Ok((bytemuck::cast_slice(&out[0]).to_vec(), t.seconds))
}

fn markdown(info: &RunInfo, a: &StorageArgs, rows: &[StorageRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Storage-buffer reads: GPU backend against CPU\n");
    let _ = writeln!(s, "Command: `{}`  ", info.command);
    let _ = writeln!(s, "CPU: {} ({} threads); load average at start {:?}  ", info.cpu, info.cpu_threads, info.load_average_start.unwrap_or_default());
    let _ = writeln!(s, "Adapter: {}  ", info.adapter.as_deref().unwrap_or("-"));
    let _ = writeln!(s, "{} invocations per dispatch, fastest of {} runs after a warm-up (median in brackets); every GPU sum checked against the CPU's.\n", a.invocations, a.repeats);
    let _ = writeln!(s, "| kernel | floats read per invocation | load instructions | addresses | GPU ns / invocation | GPU load instructions / s | CPU ns / invocation | GPU time / CPU time |");
    let _ = writeln!(s, "| --- | ---: | ---: | --- | ---: | ---: | ---: | ---: |");
    for r in rows {
        let _ = writeln!(
            s,
            "| `{}` | {} | {} | {} | {:.2} ({:.2}) | {:.0} M | {:.2} ({:.2}) | {:.1} |",
            r.kernel,
            r.floats_per_invocation,
            r.load_instructions_per_invocation,
            if r.shared_addresses { "shared by all" } else { "own record" },
            r.gpu_ns_per_invocation,
            r.gpu_median_ns_per_invocation,
            r.gpu_load_instructions_per_s / 1e6,
            r.cpu_ns_per_invocation,
            r.cpu_median_ns_per_invocation,
            r.gpu_over_cpu_time
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modules_name_their_entry_points_and_load_width() {
        let f = wgsl_module("f32");
        assert!(f.contains("array<f32>") && f.contains("fn f32_own_16") && f.contains("fn f32_shared_16") && !f.contains("ELEM"));
        let v = wgsl_module("vec4");
        assert!(v.contains("array<vec4<f32>>") && v.contains("fn vec4_own_4") && v.contains("v.x + v.y + v.z + v.w"));
        // Every kernel's entry point is in the module of its prefix.
        for k in &KERNELS {
            let prefix = k.entry.split('_').next().unwrap();
            assert!(wgsl_module(prefix).contains(&format!("fn {}(", k.entry)), "{}", k.entry);
        }
    }

    #[test]
    fn cpu_sums_read_each_invocations_record() {
        let k = &KERNELS[1];
        let input = input_of(k, 3);
        let mut out = vec![0.0; 3];
        cpu_sums(k, &input, &mut out);
        assert_eq!(out, vec![0.0 + 0.25 + 0.5 + 0.75, 1.0 + 1.25 + 1.5 + 0.0, 0.25 + 0.5 + 0.75 + 1.0]);
    }
}
