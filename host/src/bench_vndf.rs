//! `host bench vndf`: the GGX reflection samplers of `shader_core::vndf` compared over a grid of
//! roughness and incidence (docs/vndf.md; the generated report is docs/reports/vndf-bench.md).
//!
//! Methods: classic NDF sampling (Walter et al. 2007), Heitz 2018 ellipsoid VNDF, Dupuy & Benyoub
//! 2023 spherical caps, Eto & Tokuyoshi 2023 bounded VNDF, through their registered kernels
//! (`sample_ndf`, `sample_vndf_heitz`, `sample_vndf_caps`, `sample_vndf_bounded`).
//!
//! Grid: isotropic alpha in [`ALPHAS`], theta_i in [`THETAS_DEG`] (azimuth 0), wi rounded to f32.
//! Per method and grid point, `--samples` samples are drawn on the CPU backend (PCG32 stream
//! = grid index, the same random numbers for every method; the GPU backend returns the same bits,
//! tests/tests/vndf_crosscheck.rs) and give:
//!
//! * the fraction of reflected directions below the horizon (wo.z <= 0), wasted samples;
//! * the one-sample estimator of the directional albedo of a GGX conductor with Schlick Fresnel,
//!   X = F(wi.h) D(h) G2(wi, wo) / (4 wi.z pdf) for wo.z > 0 and 0 below the horizon
//!   (height-correlated Smith G2, f64 from the f32 sample and the pdf the sampler returned), its
//!   mean and variance;
//! * the relative RMS error of the albedo estimate at equal sampling time,
//!   sqrt(Var[X] / (rate T)) / albedo, for a budget T (`--budget-ms`) and the method's measured
//!   rate on each backend (time of sampling only; the estimator's evaluation is not timed).
//!
//! Rates: each sampler runs over a `--rows` table mixing every grid point (random u1, u2) on the
//! CPU backend (wall clock, all threads) and the GPU backend (timestamp queries where the adapter
//! has them, else wall clock), `--repeats` times after one warm-up; the median is reported.

use crate::timing::{cpu_model, load_average};
use crate::backend::{Backend, DeviceChoice};
use crate::eval::find_function;
use shader_kernels::eval::FunctionInfo;
use crate::microfacet_ref as r64;
use anyhow::{Context, Result};
use rayon::prelude::*;
use shader_core::rng::Pcg32;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Options of `host bench vndf`.
#[derive(clap::Args, Debug, Clone)]
pub struct VndfArgs {
    /// GPU backend to time besides the CPU backend: auto (a Vulkan adapter if there is one),
    /// gpu (required), cpu (CPU backend only).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// Samples per method and grid point for the horizon fraction and the estimator's variance.
    #[arg(long, default_value_t = 1 << 20)]
    pub samples: usize,
    /// Rows per timed run (mixing every grid point).
    #[arg(long, default_value_t = 1 << 20)]
    pub rows: usize,
    /// Timed runs per method and backend (after one warm-up); the median is reported.
    #[arg(long, default_value_t = 5)]
    pub repeats: usize,
    /// Schlick F0 of the glossy reflection whose albedo is estimated.
    #[arg(long, default_value_t = 0.04)]
    pub f0: f64,
    /// Sampling-time budget (milliseconds) of the equal-time error.
    #[arg(long, default_value_t = 1.0)]
    pub budget_ms: f64,
    /// Markdown report (`cargo xtask docs-reports` regenerates the committed one under
    /// docs/reports/).
    /// A JSON file with every figure is written beside it (same name, .json).
    #[arg(long, short, default_value = "out/vndf-bench.md")]
    pub output: PathBuf,
    /// PNG: relative error at equal time vs theta_i, one panel per alpha.
    #[arg(long, default_value = "out/vndf-bench.png")]
    pub plot: PathBuf,
}

/// (registered sampler, label).
pub const METHODS: [(&str, &str); 4] = [
    ("sample_ndf", "NDF (Walter 2007)"),
    ("sample_vndf_heitz", "ellipsoid VNDF (Heitz 2018)"),
    ("sample_vndf_caps", "spherical caps (Dupuy & Benyoub 2023)"),
    ("sample_vndf_bounded", "bounded VNDF (Eto & Tokuyoshi 2023)"),
];

/// Isotropic roughness values of the grid.
pub const ALPHAS: [f32; 6] = [0.05, 0.1, 0.2, 0.4, 0.7, 1.0];
/// Incidence angles (degrees) of the grid.
pub const THETAS_DEG: [f64; 7] = [0.0, 30.0, 60.0, 75.0, 85.0, 88.0, 89.5];

/// One grid point.
#[derive(Clone, Copy, Debug)]
pub struct Point {
    pub alpha: f32,
    pub theta_deg: f64,
}

impl Point {
    /// wi at azimuth 0, rounded to f32.
    pub fn wi(&self) -> [f32; 3] {
        let t = self.theta_deg.to_radians();
        [t.sin() as f32, 0.0, t.cos() as f32]
    }
}

/// The grid, alpha-major.
pub fn grid() -> Vec<Point> {
    ALPHAS.iter().flat_map(|&alpha| THETAS_DEG.iter().map(move |&theta_deg| Point { alpha, theta_deg })).collect()
}

/// Rows (wi, alpha_x, alpha_y, u1, u2) of `n` samples at `p`, PCG32 stream `stream`.
fn sample_rows(p: &Point, n: usize, stream: u32) -> Vec<f32> {
    let wi = p.wi();
    let mut rng = Pcg32::new(0x76d5_f00d, stream);
    let mut rows = Vec::with_capacity(n * 7);
    for _ in 0..n {
        let u1 = rng.next_f32();
        let u2 = rng.next_f32();
        rows.extend_from_slice(&[wi[0], wi[1], wi[2], p.alpha, p.alpha, u1, u2]);
    }
    rows
}

/// Statistics of one method at one grid point.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stats {
    /// Fraction of samples with wo.z <= 0.
    pub below: f64,
    /// Mean of the albedo estimator.
    pub mean: f64,
    /// Variance of one sample of the estimator.
    pub var: f64,
    /// Samples with a non-finite direction or pdf, or pdf <= 0 above the horizon (must be 0).
    pub bad: usize,
}

/// Schlick's Fresnel F0 + (1 - F0)(1 - c)^5.
fn schlick(f0: f64, c: f64) -> f64 {
    let m = (1.0 - c).clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (1.0 - f0) * m2 * m2 * m
}

/// The albedo estimator of one sample (0 below the horizon); None for an invalid sample.
pub fn estimator(wi: [f32; 3], alpha: f32, f0: f64, wo: [f32; 3], pdf: f32) -> Option<f64> {
    if !(wo.iter().all(|x| x.is_finite()) && pdf.is_finite() && pdf >= 0.0) {
        return None;
    }
    if wo[2] <= 0.0 {
        return Some(0.0);
    }
    if pdf <= 0.0 {
        return None;
    }
    let i = wi.map(f64::from);
    let o = wo.map(f64::from);
    let a = f64::from(alpha);
    let h = r64::normalize([i[0] + o[0], i[1] + o[1], i[2] + o[2]]);
    let d = r64::ggx_d(h, a, a);
    let g2 = r64::g2_height_correlated(r64::ggx_lambda(o, a, a), r64::ggx_lambda(i, a, a));
    let f = schlick(f0, r64::dot(i, h));
    Some(f * d * g2 / (4.0 * i[2] * f64::from(pdf)))
}

/// Horizon fraction and estimator statistics of sampler outputs (wo_x, wo_y, wo_z, pdf per row).
pub fn stats(p: &Point, f0: f64, out: &[f32]) -> Stats {
    let wi = p.wi();
    let n = out.len() / 4;
    let (below, bad, sum, sum2) = out
        .par_chunks(4 * 4096)
        .map(|c| {
            let (mut below, mut bad, mut s, mut s2) = (0usize, 0usize, 0.0f64, 0.0f64);
            for r in c.chunks_exact(4) {
                let wo = [r[0], r[1], r[2]];
                below += (r[2] <= 0.0) as usize;
                match estimator(wi, p.alpha, f0, wo, r[3]) {
                    Some(x) => {
                        s += x;
                        s2 += x * x;
                    }
                    None => bad += 1,
                }
            }
            (below, bad, s, s2)
        })
        .reduce(|| (0, 0, 0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2, a.3 + b.3));
    let nf = n as f64;
    let mean = sum / nf;
    let var = ((sum2 - nf * mean * mean) / (nf - 1.0)).max(0.0);
    Stats { below: below as f64 / nf, mean, var, bad }
}

use crate::timing::median;

/// Median samples per second of each function of `ids` over `table` on `backend`, and the timing
/// source. The functions take turns (one warm-up round, then `repeats` timed rounds), so a change
/// in the machine's load during the measurement affects every method alike.
fn time_backend(backend: &Backend, fs: &[&FunctionInfo], table: &[f32], repeats: usize) -> Result<(Vec<f64>, String)> {
    let rows = table.len() / 7;
    let mut source = String::new();
    // One output buffer per function, reused by every run (bench_kernels::time_eval says why).
    let mut outs = vec![Vec::new(); fs.len()];
    for (k, &f) in fs.iter().enumerate() {
        let warm = backend.eval_table_into(f, table, rows, &mut outs[k])?;
        source = warm.source.to_string();
    }
    let mut secs = vec![Vec::with_capacity(repeats); fs.len()];
    for _ in 0..repeats {
        for (k, &f) in fs.iter().enumerate() {
            let t = backend.eval_table_into(f, table, rows, &mut outs[k])?;
            secs[k].push(t.seconds);
        }
    }
    Ok((secs.into_iter().map(|s| rows as f64 / median(s)).collect(), source))
}

/// Everything measured for one method.
#[derive(Clone, Debug)]
pub struct MethodResult {
    pub name: &'static str,
    pub label: &'static str,
    /// Per grid point, in [`grid`] order.
    pub stats: Vec<Stats>,
    pub cpu_rate: f64,
    pub gpu_rate: Option<f64>,
    /// Best rate of the hand-written WGSL kernel of the same sampler on the same adapter
    /// (`sample_vndf_heitz` only; [`crate::bench_kernels::WGSL_REFERENCES`]) and the rust-gpu
    /// kernel's rate over it, both timed in alternation ([`crate::bench_kernels::time_paired`]).
    pub wgsl_rate: Option<f64>,
    pub rust_gpu_over_wgsl: Option<f64>,
}

/// Run the benchmark and write the report and plot.
pub fn run(a: &VndfArgs) -> Result<()> {
    anyhow::ensure!(a.samples >= 1000, "--samples must be at least 1000");
    anyhow::ensure!(a.rows >= 1024, "--rows must be at least 1024");
    anyhow::ensure!(a.repeats >= 1, "--repeats must be at least 1");
    anyhow::ensure!((0.0..=1.0).contains(&a.f0), "--f0 must be in [0, 1]");
    anyhow::ensure!(a.budget_ms > 0.0 && a.budget_ms.is_finite(), "--budget-ms must be positive");
    // Fail before the measurements when an output cannot be written.
    crate::io::prepare_output(&a.output)?;
    crate::io::prepare_output(&a.plot)?;
    let load_start = load_average();
    let (cpu, gpu) = Backend::bench_pair(a.device)?;
    let pts = grid();
    // The timing table: every grid point in turn, fresh random numbers.
    let mut timing_table = Vec::with_capacity(a.rows * 7);
    let mut rng = Pcg32::new(0x7173_u32, 1);
    for i in 0..a.rows {
        let p = pts[i % pts.len()];
        let wi = p.wi();
        timing_table.extend_from_slice(&[wi[0], wi[1], wi[2], p.alpha, p.alpha, rng.next_f32(), rng.next_f32()]);
    }
    let mut results = Vec::new();
    for &(name, label) in &METHODS {
        let f = find_function(name)?;
        let t0 = std::time::Instant::now();
        let mut per_point = Vec::with_capacity(pts.len());
        for (k, p) in pts.iter().enumerate() {
            let rows = sample_rows(p, a.samples, k as u32);
            let (out, _) = cpu.eval_table(f, &rows, a.samples).with_context(|| format!("sampling {name}"))?;
            let s = stats(p, a.f0, &out);
            anyhow::ensure!(s.bad == 0, "{name} alpha {} theta {}: {} invalid samples", p.alpha, p.theta_deg, s.bad);
            per_point.push(s);
        }
        eprintln!("{name}: statistics in {:.1} s", t0.elapsed().as_secs_f64());
        results.push(MethodResult { name, label, stats: per_point, cpu_rate: 0.0, gpu_rate: None, wgsl_rate: None, rust_gpu_over_wgsl: None });
    }
    let ids = METHODS.iter().map(|(name, _)| find_function(name)).collect::<Result<Vec<&FunctionInfo>>>()?;
    let (cpu_rates, _) = time_backend(&cpu, &ids, &timing_table, a.repeats)?;
    let mut gpu_source = None;
    let gpu_rates = match &gpu {
        Some(g) => {
            let (r, src) = time_backend(g, &ids, &timing_table, a.repeats).context("timing on the GPU")?;
            gpu_source = Some(src);
            Some(r)
        }
        None => None,
    };
    for (k, r) in results.iter_mut().enumerate() {
        r.cpu_rate = cpu_rates[k];
        r.gpu_rate = gpu_rates.as_ref().map(|g| g[k]);
        if let (Some(g), Some(entry)) = (gpu.as_ref().and_then(|b| b.gpu()), crate::bench_kernels::wgsl_entry(r.name)) {
            let f = find_function(r.name)?;
            let pr = crate::bench_kernels::time_paired(gpu.as_ref().expect("GPU backend"), g, entry, f, &timing_table, a.rows, a.repeats as u32)?;
            r.wgsl_rate = Some(pr.wgsl);
            r.rust_gpu_over_wgsl = Some(pr.ratio);
        }
        eprintln!(
            "{}: {:.2} Msamples/s CPU, {} GPU",
            r.name,
            r.cpu_rate / 1e6,
            r.gpu_rate.map_or("n/a".to_string(), |g| format!("{:.3} Msamples/s", g / 1e6))
        );
    }
    let load = format!("{load_start} at the start, {} at the end", load_average());
    let md = markdown(a, &pts, &results, &cpu, gpu.as_ref(), gpu_source.as_deref(), &load);
    crate::io::write_file(&a.output, md)?;
    eprintln!("wrote {}", a.output.display());
    let json = a.output.with_extension("json");
    let doc = serde_json::json!({
        "command": crate::report::command_line(),
        "cpu": crate::timing::cpu_model(),
        "cpu_backend": cpu.describe(),
        "gpu_backend": gpu.as_ref().map(|g| g.describe()),
        "load_average": load,
        "rows_per_run": a.rows,
        "repeats": a.repeats,
        "grid": pts.iter().map(|p| serde_json::json!({"alpha": p.alpha, "theta_deg": p.theta_deg})).collect::<Vec<_>>(),
        "methods": results.iter().map(|r| serde_json::json!({
            "name": r.name,
            "label": r.label,
            "cpu_samples_per_s": r.cpu_rate,
            "gpu_samples_per_s": r.gpu_rate,
            "wgsl_samples_per_s": r.wgsl_rate,
            "rust_gpu_over_wgsl": r.rust_gpu_over_wgsl,
            "below_horizon": r.stats.iter().map(|s| s.below).collect::<Vec<_>>(),
            "albedo_mean": r.stats.iter().map(|s| s.mean).collect::<Vec<_>>(),
            "albedo_variance": r.stats.iter().map(|s| s.var).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
    });
    crate::io::write_file(&json, serde_json::to_string_pretty(&doc)?)?;
    eprintln!("wrote {}", json.display());
    plot(&a.plot, a, &pts, &results, gpu.as_ref().map(|g| g.describe()))?;
    eprintln!("wrote {}", a.plot.display());
    Ok(())
}

/// Inverse-variance weighted mean of the methods' albedo estimates at grid point `k` (the
/// reference the relative errors are taken against).
fn reference_albedo(results: &[MethodResult], k: usize, n: usize) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for r in results {
        let s = r.stats[k];
        let w = n as f64 / s.var.max(1e-300);
        num += w * s.mean;
        den += w;
    }
    num / den
}

/// Relative RMS error of the albedo estimate after `budget_s` seconds of sampling at `rate`.
pub fn equal_time_error(s: &Stats, rate: f64, budget_s: f64, albedo: f64) -> f64 {
    (s.var / (rate * budget_s)).sqrt() / albedo
}



fn geo_mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x.ln(), n + 1));
    (s / n as f64).exp()
}

fn markdown(a: &VndfArgs, pts: &[Point], res: &[MethodResult], cpu: &Backend, gpu: Option<&Backend>, gpu_source: Option<&str>, load: &str) -> String {
    let budget = a.budget_ms * 1e-3;
    let mut s = String::new();
    let _ = writeln!(s, "# GGX reflection samplers: horizon losses, variance, cost\n");
    let _ = writeln!(
        s,
        "Generated by `cargo run --release -p host -- bench vndf --device {} --samples {} --rows {} --repeats {} --f0 {} --budget-ms {}` \
         (method: `host/src/bench_vndf.rs`; samplers: `shader-core/src/vndf.rs`; discussion: `docs/vndf.md`).\n",
        format!("{:?}", a.device).to_lowercase(),
        a.samples,
        a.rows,
        a.repeats,
        a.f0,
        a.budget_ms
    );
    let _ = writeln!(
        s,
        "- CPU: {} on {} ({} logical CPUs; 1-minute load average {load})",
        cpu.describe(),
        cpu_model(),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0)
    );
    match gpu {
        Some(g) => {
            let _ = writeln!(s, "- GPU: {} (kernel times by {})", g.describe(), gpu_source.unwrap_or("?"));
        }
        None => {
            let _ = writeln!(s, "- GPU backend: none (run with a Vulkan adapter for the GPU columns)");
        }
    }
    let _ = writeln!(
        s,
        "- Grid: isotropic α ∈ {{{}}} × θi ∈ {{{}}}° (azimuth 0); {} samples per method and grid point, PCG32 stream = grid index \
         (the same random numbers for every method). Deterministic: the horizon fractions, means and variances below are the same \
         on every run and every machine (the kernels are bit-exact across backends); the rates are not.",
        ALPHAS.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(", "),
        THETAS_DEG.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(", "),
        a.samples
    );
    let _ = writeln!(
        s,
        "- Estimator: directional albedo of a GGX conductor, Schlick Fresnel F0 = {}, height-correlated Smith G2: \
         X = F D G2 / (4 cos θi pdf) for wo above the horizon, 0 below.",
        a.f0
    );
    let _ = writeln!(
        s,
        "- Equal-time error: relative RMS error sqrt(Var[X] / (rate · T)) / albedo after T = {} ms of sampling on the backend \
         (sampling time only), albedo = inverse-variance weighted mean of the four methods.\n",
        a.budget_ms
    );

    let _ = writeln!(s, "## Cost\n");
    let _ = writeln!(
        s,
        "Median of {} runs of {} rows (every grid point in turn) after one warm-up; the four kernels take turns, so a change \
         of load during the measurement affects them alike. The GPU backend is whatever `--device` found (lavapipe is Vulkan \
         on the CPU, not a GPU).\n",
        a.repeats,
        a.rows
    );
    let _ = writeln!(s, "| method | kernel | CPU Msamples/s | GPU Msamples/s | WGSL Msamples/s | rust-gpu / WGSL |");
    let _ = writeln!(s, "| --- | --- | ---: | ---: | ---: | ---: |");
    for r in res {
        let _ = writeln!(
            s,
            "| {} | `{}` | {:.2} | {} | {} | {} |",
            r.label,
            r.name,
            r.cpu_rate / 1e6,
            r.gpu_rate.map_or("n/a".to_string(), |g| format!("{:.3}", g / 1e6)),
            r.wgsl_rate.map_or("-".to_string(), |g| format!("{:.3}", g / 1e6)),
            r.rust_gpu_over_wgsl.map_or("-".to_string(), |x| format!("{x:.2}")),
        );
    }
    if res.iter().any(|r| r.wgsl_rate.is_some()) {
        let _ = writeln!(
            s,
            "\nWGSL: a hand-written kernel of the same sampler (`host/src/wgsl/reference.wgsl`, compiled by naga; a speed \
             reference only, not bit-exact), same adapter, same rows, same run; the WGSL column is its fastest run, rust-gpu / WGSL the median \
             of the per-round rate ratios of the two kernels timed in alternation (one run of each per round)."
        );
    }
    let _ = writeln!(s);

    // Summary numbers quoted by docs/vndf.md.
    let caps = res.iter().position(|r| r.name == "sample_vndf_caps");
    let bounded = res.iter().position(|r| r.name == "sample_vndf_bounded");
    let _ = writeln!(s, "## Summary\n");
    if let (Some(c), Some(b)) = (caps, bounded) {
        let lossy: Vec<usize> = (0..pts.len()).filter(|&k| res[c].stats[k].below > 0.0).collect();
        let fewer = lossy.iter().filter(|&&k| res[b].stats[k].below < res[c].stats[k].below).count();
        let worst_c = (0..pts.len()).max_by(|&x, &y| res[c].stats[x].below.partial_cmp(&res[c].stats[y].below).unwrap()).unwrap();
        let _ = writeln!(
            s,
            "- Below the horizon: spherical caps lose samples at {} of {} grid points; bounded VNDF loses fewer at {} of them \
             (never more: {}). Worst case for caps: α = {}, θi = {}°: caps {:.2} %, bounded {:.2} %.",
            lossy.len(),
            pts.len(),
            fewer,
            (0..pts.len()).all(|k| res[b].stats[k].below <= res[c].stats[k].below),
            pts[worst_c].alpha,
            pts[worst_c].theta_deg,
            100.0 * res[c].stats[worst_c].below,
            100.0 * res[b].stats[worst_c].below
        );
    }
    for r in res {
        let rel: Vec<f64> = (0..pts.len()).map(|k| r.stats[k].var / res[1].stats[k].var.max(1e-300)).collect();
        let _ = writeln!(
            s,
            "- {}: variance per sample relative to the ellipsoid VNDF, geometric mean over the grid {:.3} (range {:.3} .. {:.3}); \
             mean horizon loss {:.2} %.",
            r.label,
            geo_mean(rel.iter().copied()),
            rel.iter().copied().fold(f64::INFINITY, f64::min),
            rel.iter().copied().fold(0.0, f64::max),
            100.0 * r.stats.iter().map(|x| x.below).sum::<f64>() / pts.len() as f64
        );
    }
    // Which method reaches the lowest error at equal time, per backend.
    let backends: Vec<(&str, Box<dyn Fn(&MethodResult) -> Option<f64>>)> =
        vec![("CPU", Box::new(|r: &MethodResult| Some(r.cpu_rate))), ("GPU", Box::new(|r: &MethodResult| r.gpu_rate))];
    for (bname, rate) in &backends {
        if res.iter().any(|r| rate(r).is_none()) {
            continue;
        }
        let mut wins = vec![0usize; res.len()];
        for k in 0..pts.len() {
            let alb = reference_albedo(res, k, a.samples);
            let best = (0..res.len())
                .min_by(|&x, &y| {
                    let ex = equal_time_error(&res[x].stats[k], rate(&res[x]).unwrap(), budget, alb);
                    let ey = equal_time_error(&res[y].stats[k], rate(&res[y]).unwrap(), budget, alb);
                    ex.partial_cmp(&ey).unwrap()
                })
                .unwrap();
            wins[best] += 1;
        }
        let _ = writeln!(
            s,
            "- Lowest error at equal time on the {bname} backend (grid points won): {}.",
            res.iter().zip(&wins).map(|(r, w)| format!("{} {w}", r.label)).collect::<Vec<_>>().join(", ")
        );
    }
    // Unbiasedness check: every method's mean agrees with the reference.
    let mut worst_z = (0.0f64, "", 0usize);
    for r in res {
        for k in 0..pts.len() {
            let st = r.stats[k];
            let z = (st.mean - reference_albedo(res, k, a.samples)).abs() / (st.var / a.samples as f64).sqrt().max(1e-300);
            if z > worst_z.0 {
                worst_z = (z, r.name, k);
            }
        }
    }
    let _ = writeln!(
        s,
        "- Consistency: the largest deviation of a method's albedo estimate from the reference is {:.2} standard errors \
         ({} at α = {}, θi = {}°){}.\n",
        worst_z.0,
        worst_z.1,
        pts[worst_z.2].alpha,
        pts[worst_z.2].theta_deg,
        if worst_z.0 > 5.0 { " — SUSPICIOUS: a sampler and its pdf may disagree" } else { "" }
    );

    let _ = writeln!(s, "## Fraction of reflected directions below the horizon (%)\n");
    let _ = writeln!(s, "| α | θi | {} |", res.iter().map(|r| r.label).collect::<Vec<_>>().join(" | "));
    let _ = writeln!(s, "| ---: | ---: |{}", " ---: |".repeat(res.len()));
    for (k, p) in pts.iter().enumerate() {
        let _ = writeln!(s, "| {} | {} | {} |", p.alpha, p.theta_deg, res.iter().map(|r| format!("{:.3}", 100.0 * r.stats[k].below)).collect::<Vec<_>>().join(" | "));
    }
    let _ = writeln!(s);

    let _ = writeln!(s, "## Albedo estimator: relative standard deviation of one sample, σ/albedo\n");
    let _ = writeln!(s, "| α | θi | albedo | {} |", res.iter().map(|r| r.label).collect::<Vec<_>>().join(" | "));
    let _ = writeln!(s, "| ---: | ---: | ---: |{}", " ---: |".repeat(res.len()));
    for (k, p) in pts.iter().enumerate() {
        let alb = reference_albedo(res, k, a.samples);
        let _ = writeln!(
            s,
            "| {} | {} | {:.5} | {} |",
            p.alpha,
            p.theta_deg,
            alb,
            res.iter().map(|r| format!("{:.4}", r.stats[k].var.sqrt() / alb)).collect::<Vec<_>>().join(" | ")
        );
    }
    let _ = writeln!(s);

    let _ = writeln!(s, "## Relative RMS error at equal time ({} ms of sampling; %)\n", a.budget_ms);
    let gpu_cols = res.iter().all(|r| r.gpu_rate.is_some());
    let mut head = res.iter().map(|r| format!("CPU: {}", r.label)).collect::<Vec<_>>();
    if gpu_cols {
        head.extend(res.iter().map(|r| format!("GPU: {}", r.label)));
    }
    let _ = writeln!(s, "| α | θi | {} |", head.join(" | "));
    let _ = writeln!(s, "| ---: | ---: |{}", " ---: |".repeat(head.len()));
    for (k, p) in pts.iter().enumerate() {
        let alb = reference_albedo(res, k, a.samples);
        let mut cols: Vec<String> = res.iter().map(|r| format!("{:.4}", 100.0 * equal_time_error(&r.stats[k], r.cpu_rate, budget, alb))).collect();
        if gpu_cols {
            cols.extend(res.iter().map(|r| format!("{:.4}", 100.0 * equal_time_error(&r.stats[k], r.gpu_rate.unwrap(), budget, alb))));
        }
        let _ = writeln!(s, "| {} | {} | {} |", p.alpha, p.theta_deg, cols.join(" | "));
    }
    let _ = writeln!(s);
    let _ = writeln!(s, "Plot: `{}` (one panel per α; circles CPU backend, triangles GPU backend).", a.plot.display());
    s
}

/// Relative error at equal time against theta_i, one panel per alpha, one colour per method.
fn plot(path: &Path, a: &VndfArgs, pts: &[Point], res: &[MethodResult], gpu_name: Option<String>) -> Result<()> {
    use plotters::prelude::*;
    static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    let budget = a.budget_ms * 1e-3;
    let (w, h) = (1800u32, 1150u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let colors = [RGBColor(127, 127, 127), RGBColor(31, 119, 180), RGBColor(44, 160, 44), RGBColor(214, 39, 40)];
    // Every plotted value, for a shared y range.
    let mut all = Vec::new();
    for r in res {
        for (k, _) in pts.iter().enumerate() {
            let alb = reference_albedo(res, k, a.samples);
            all.push(equal_time_error(&r.stats[k], r.cpu_rate, budget, alb));
            if let Some(g) = r.gpu_rate {
                all.push(equal_time_error(&r.stats[k], g, budget, alb));
            }
        }
    }
    let all: Vec<f64> = all.into_iter().filter(|x| x.is_finite() && *x > 0.0).collect();
    anyhow::ensure!(!all.is_empty(), "nothing to plot");
    let ymin = all.iter().copied().fold(f64::INFINITY, f64::min) / 1.5;
    let ymax = all.iter().copied().fold(0.0, f64::max) * 1.5;
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
        let title = format!(
            "GGX reflection sampling: relative RMS error of the albedo estimate after {} ms of sampling (● CPU backend{})",
            a.budget_ms,
            if gpu_name.is_some() { ", ▲ GPU backend" } else { "" }
        );
        let (top, rest) = root.split_vertically(60);
        top.draw(&Text::new(title, (30, 18), ("sans-serif", 26).into_font())).map_err(|e| anyhow::anyhow!("{e}"))?;
        let (panels_area, footer) = rest.split_vertically(h as i32 - 60 - 70);
        let panels = panels_area.split_evenly((2, 3));
        for (pi, (area, &alpha)) in panels.iter().zip(ALPHAS.iter()).enumerate() {
            let mut chart = ChartBuilder::on(area)
                .caption(format!("α = {alpha}"), ("sans-serif", 22))
                .margin(12)
                .x_label_area_size(45)
                .y_label_area_size(70)
                .build_cartesian_2d(-2.0f64..92.0f64, (ymin..ymax).log_scale())
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            chart
                .configure_mesh()
                .x_desc("θi (degrees)")
                .y_desc(if pi % 3 == 0 { "relative RMS error" } else { "" })
                .label_style(("sans-serif", 15))
                .axis_desc_style(("sans-serif", 17))
                .x_label_formatter(&|x| format!("{x:.0}"))
                .y_label_formatter(&|y| format!("{y:.0e}"))
                .draw()
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            let ks: Vec<usize> = (0..pts.len()).filter(|&k| pts[k].alpha == alpha).collect();
            for (r, col) in res.iter().zip(colors) {
                let series = |rate: f64| -> Vec<(f64, f64)> {
                    ks.iter()
                        .map(|&k| (pts[k].theta_deg, equal_time_error(&r.stats[k], rate, budget, reference_albedo(res, k, a.samples))))
                        .filter(|p| p.1.is_finite() && p.1 > 0.0)
                        .collect()
                };
                let cpu_pts = series(r.cpu_rate);
                // The ellipsoid and the caps share one distribution: draw the first wider so
                // both stay visible where they coincide.
                let width = if r.name == "sample_vndf_heitz" { 6 } else { 2 };
                let s = chart.draw_series(std::iter::once(PathElement::new(cpu_pts.clone(), col.stroke_width(width)))).map_err(|e| anyhow::anyhow!("{e}"))?;
                if pi == 0 {
                    s.label(r.label).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], col.stroke_width(3)));
                }
                chart.draw_series(cpu_pts.iter().map(|p| Circle::new(*p, 5, col.filled()))).map_err(|e| anyhow::anyhow!("{e}"))?;
                if let Some(g) = r.gpu_rate {
                    let gpu_pts = series(g);
                    chart.draw_series(std::iter::once(PathElement::new(gpu_pts.clone(), col.stroke_width(1)))).map_err(|e| anyhow::anyhow!("{e}"))?;
                    chart.draw_series(gpu_pts.iter().map(|p| TriangleMarker::new(*p, 6, col.filled()))).map_err(|e| anyhow::anyhow!("{e}"))?;
                }
            }
            if pi == 0 {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperLeft)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .label_font(("sans-serif", 14))
                    .draw()
                    .map_err(|e| anyhow::anyhow!("{e}"))?;
            }
        }
        let mut lines = vec![format!(
            "Estimator: albedo of a GGX conductor (Schlick F0 = {}, height-correlated G2), {} samples per point; rate = measured samples/s of each kernel.",
            a.f0, a.samples
        )];
        if let Some(g) = gpu_name {
            lines.push(g.chars().take(170).collect());
        }
        for (i, l) in lines.iter().enumerate() {
            footer.draw(&Text::new(l.clone(), (30, 10 + 24 * i as i32), ("sans-serif", 16).into_font())).map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    crate::io::create_parent_dir(path)?;
    image::save_buffer(path, &buf, w, h, image::ColorType::Rgb8).with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The estimator of a perfect importance sampler is constant: with pdf = F D G2 / (4 wi.z)
    /// times a constant c, X = 1 / c.
    #[test]
    fn estimator_divides_by_the_pdf() {
        let p = Point { alpha: 0.3, theta_deg: 40.0 };
        let wi = p.wi();
        let wo = [-0.3f32, 0.2, 0.932_737_9];
        let x1 = estimator(wi, p.alpha, 0.04, wo, 1.0).unwrap();
        let x2 = estimator(wi, p.alpha, 0.04, wo, 2.0).unwrap();
        assert!((x1 - 2.0 * x2).abs() < 1e-12 * x1);
        assert_eq!(estimator(wi, p.alpha, 0.04, [0.0, 0.6, -0.8], 3.0), Some(0.0));
        assert_eq!(estimator(wi, p.alpha, 0.04, wo, f32::NAN), None);
        assert_eq!(estimator(wi, p.alpha, 0.04, wo, 0.0), None);
    }

    #[test]
    fn schlick_endpoints() {
        assert_eq!(schlick(0.04, 1.0), 0.04);
        assert!((schlick(0.04, 0.0) - 1.0).abs() < 1e-15);
    }
}
