//! `host bench microfacet`: cost and accuracy of the microfacet approximations.
//!
//! Three groups, each measured against an f64 reference over a documented grid
//! ([`crate::microfacet_ref`]):
//!
//! * **Visibility** V = G2 / (4 n.l n.v): every engine form against the exact isotropic
//!   height-correlated Smith-GGX V. Grid: theta_v, theta_l in [0, 89.9] degrees (`--grid` values
//!   each, uniform in angle), the azimuth between them in [0, pi] (8 values; it matters only for
//!   the forms that read n.h or v.h), alpha log-spaced in [1e-3, 1] (16 values).
//! * **GGX D forms**: the scale-invariant `ggx_d`, `gtr2_d`, UE4's n.h form, Filament's naive and
//!   Lagrange ("mobile") forms in f32, and the two mobile forms in emulated fp16
//!   ([`crate::ggx_fp16`]), against the exact D at the exact half vector. Grid: alpha log-spaced in
//!   [2^-7, 1] (16 values; below about 2^-8 Filament's intermediate k^2 = pi D overflows fp16 at
//!   the peak, which would hide the cancellation this group is about), tan(theta_h) = alpha t with
//!   t uniform in [0, 10] (`--grid` x 64 values: the lobe down to D/D(0) = 1e-4), azimuth 0.3 rad.
//! * **Beckmann Lambda / G1**: exact (erfc) and Walter's rational approximation, against the f64
//!   exact Lambda. Grid: theta in [0, 89.9] degrees (`--grid` x 32 values), alpha log-spaced in
//!   [1e-3, 1] (32 values).
//!
//! Inputs are rounded to f32 before evaluation; the reference is evaluated at the f32 inputs,
//! except for the GGX D forms, whose reference is at the exact (f64) half vector: the rounding of
//! n.h to f32 or fp16 is the very error those forms differ in. Errors are relative,
//! |x - ref| / max(|ref|, 2^-126): a reference below the normal f32 range (a Beckmann Lambda of
//! 1e-300, say) counts in absolute terms, since no f32 result can be relatively close to it.
//!
//! Cost: each registered function runs over `--rows` rows (the grid's inputs repeated) on the CPU
//! backend (wall clock, all threads) and on the GPU backend (timestamp queries around the compute
//! pass where the adapter has them, else wall clock), `--repeats` times after one warm-up run; the
//! fastest run is reported as evaluations per second (on a shared machine other processes only ever
//! slow a run down, so the minimum time is the least disturbed estimate; the median is printed too). The fp16 forms have no kernel (the kernels are
//! f32): they are evaluated on the host for their error only.

use crate::timing::{cpu_model, load_average};
use crate::backend::{Backend, DeviceChoice};
use crate::bench_kernels::time_eval;
use crate::eval::find_function;
use crate::ggx_fp16;
use crate::microfacet_ref as r64;
use anyhow::{bail, Context, Result};
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Options of `host bench microfacet`.
#[derive(clap::Args, Debug, Clone)]
pub struct MicrofacetArgs {
    /// GPU backend to time besides the CPU backend: auto (a Vulkan adapter if there is one),
    /// gpu (required), cpu (CPU backend only).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// Rows per timed evaluation (batch size).
    #[arg(long, default_value_t = 1 << 20)]
    pub rows: usize,
    /// Timed runs per function and backend (after one warm-up); the fastest is reported.
    #[arg(long, default_value_t = 5)]
    pub repeats: usize,
    /// Error-grid resolution: angle samples per axis of the visibility grid (the other grids scale with it).
    #[arg(long, default_value_t = 64)]
    pub grid: usize,
    /// Markdown report.
    /// (`cargo xtask docs-reports` regenerates the committed one under docs/reports/.) A JSON
    /// file with every figure is written beside it (same name, .json).
    #[arg(long, short, default_value = "out/microfacet-cost.md")]
    pub output: PathBuf,
    /// PNG scatter plot (error vs evaluations/s).
    #[arg(long, default_value = "out/microfacet-cost.png")]
    pub plot: PathBuf,
    /// Skip timing (errors only).
    #[arg(long)]
    pub no_timing: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Group {
    Visibility,
    GgxD,
    Beckmann,
}

impl Group {
    fn title(self) -> &'static str {
        match self {
            Group::Visibility => "Visibility V = G2 / (4 n.l n.v) vs exact height-correlated Smith-GGX",
            Group::GgxD => "GGX D forms (fp32 kernels, fp16 emulated) vs exact D at the exact half vector",
            Group::Beckmann => "Beckmann Lambda / G1: exact (erfc) vs Walter's rational, vs f64 exact",
        }
    }
}

/// One grid point: every quantity a case may read, and the references.
#[derive(Clone, Copy, Debug)]
struct Point {
    /// f32-rounded inputs.
    nv: f32,
    nl: f32,
    nh: f32,
    vh: f32,
    alpha: f32,
    w: [f32; 3],
    /// Exact (f64) half vector or direction, for the D forms.
    h64: [f64; 3],
    /// Reference value for V / D / Lambda; G1 reference for the G1 cases.
    reference: f64,
    reference_g1: f64,
    /// Where, for the "worst at" column.
    theta_deg: f64,
    theta2_deg: f64,
}

/// A measured case.
struct Case {
    name: &'static str,
    group: Group,
    source: &'static str,
    /// Evaluated by a registered kernel (timed) or on the host (fp16 emulation).
    host_eval: Option<fn(&Point) -> f32>,
    /// Compare against `reference_g1` rather than `reference`.
    g1: bool,
}

fn cases() -> Vec<Case> {
    use Group::*;
    let k = |name, group, source| Case { name, group, source, host_eval: None, g1: false };
    vec![
        k("v_frostbite", Visibility, "Lagarde 2014 listing 2 (exact)"),
        k("v_hdrp", Visibility, "HDRP V_SmithJointGGX (exact)"),
        k("v_filament", Visibility, "Filament V_SmithGGXCorrelated (exact)"),
        k("v_hdrp_approx", Visibility, "HDRP, PartLambdaVApprox (view linearized)"),
        k("v_ue4", Visibility, "UE4 Vis_SmithJointApprox"),
        k("v_respawn", Visibility, "Hammon 2017 (RTR4 eq. 9.43)"),
        k("v_filament_fast", Visibility, "Filament _Fast (= Hammon)"),
        k("v_schlick_smith", Visibility, "Schlick-Smith, k = alpha/2 (Karis 2013)"),
        k("v_schlick_smith_remapped", Visibility, "Schlick-Smith, k = (r+1)^2/8 (Karis 2013)"),
        k("v_neumann", Visibility, "Neumann 1999"),
        k("v_kelemen", Visibility, "Kelemen & Szirmay-Kalos 2001"),
        k("v_implicit", Visibility, "implicit, V = 1/4"),
        k("v_cook_torrance", Visibility, "Cook-Torrance V-cavity"),
        k("ggx_d", GgxD, "scale-invariant vector form (Heitz 2014 eq. 85)"),
        k("gtr2_d", GgxD, "GTR2 vector form (Burley 2012)"),
        k("ggx_d_ue4", GgxD, "UE4 D_GGX from f32 n.h"),
        k("ggx_d_mobile_naive", GgxD, "Filament D_GGX, 1 - NoH^2 (f32)"),
        k("ggx_d_mobile", GgxD, "Filament D_GGX, \\|n x h\\|^2 (f32)"),
        Case {
            name: "fp16 mobile naive",
            group: GgxD,
            source: "seed GGX_Mobile, 1 - NoH^2, emulated fp16",
            host_eval: Some(|p| ggx_fp16::ggx_d_mobile_naive_fp16(p.h64[2] as f32, p.alpha)),
            g1: false,
        },
        Case {
            name: "fp16 mobile Lagrange",
            group: GgxD,
            source: "seed GGX_Mobile, cross(n, h), emulated fp16",
            host_eval: Some(|p| ggx_fp16::ggx_d_mobile_fp16([p.h64[0] as f32, p.h64[1] as f32, p.h64[2] as f32], p.alpha)),
            g1: false,
        },
        k("beckmann_lambda", Beckmann, "exact, erfc + continued fraction"),
        k("beckmann_lambda_walter", Beckmann, "Walter 2007 eq. 27 (Lambda form)"),
        Case { name: "beckmann_g1", group: Beckmann, source: "exact, 1/(1 + Lambda)", host_eval: None, g1: true },
        Case { name: "beckmann_g1_walter", group: Beckmann, source: "Walter 2007 eq. 27 (G1 form)", host_eval: None, g1: true },
    ]
}

fn log_space(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (n - 1).max(1) as f64).exp()).collect()
}

fn visibility_grid(n: usize) -> Vec<Point> {
    let thetas: Vec<f64> = (0..n).map(|i| 89.9 * i as f64 / (n - 1).max(1) as f64).collect();
    let mut pts = Vec::new();
    for &alpha in &log_space(1e-3, 1.0, 16) {
        let a = alpha as f32;
        for &tv in &thetas {
            for &tl in &thetas {
                for j in 0..8 {
                    let phi = PI * j as f64 / 7.0;
                    let v = r64::dir(tv.to_radians(), 0.0);
                    let l = r64::dir(tl.to_radians(), phi);
                    let h = r64::normalize([v[0] + l[0], v[1] + l[1], v[2] + l[2]]);
                    let (nv, nl) = (v[2] as f32, l[2] as f32);
                    let reference = r64::v_smith_ggx_correlated(nv as f64, nl as f64, a as f64);
                    pts.push(Point {
                        nv,
                        nl,
                        nh: h[2] as f32,
                        vh: r64::dot(v, h) as f32,
                        alpha: a,
                        w: [0.0; 3],
                        h64: h,
                        reference,
                        reference_g1: 0.0,
                        theta_deg: tv,
                        theta2_deg: tl,
                    });
                }
            }
        }
    }
    pts
}

fn ggx_d_grid(n: usize) -> Vec<Point> {
    let nt = n * 64;
    let mut pts = Vec::new();
    for &alpha in &log_space(1.0 / 128.0, 1.0, 16) {
        let a = alpha as f32;
        for i in 0..nt {
            let t = 10.0 * i as f64 / (nt - 1) as f64;
            let theta = (a as f64 * t).atan();
            let h = r64::dir(theta, 0.3);
            pts.push(Point {
                nv: 0.0,
                nl: 0.0,
                nh: h[2] as f32,
                vh: 0.0,
                alpha: a,
                w: [h[0] as f32, h[1] as f32, h[2] as f32],
                h64: h,
                reference: r64::ggx_d_cos(h[2], a as f64),
                reference_g1: 0.0,
                theta_deg: theta.to_degrees(),
                theta2_deg: 0.0,
            });
        }
    }
    pts
}

fn beckmann_grid(n: usize) -> Vec<Point> {
    let nt = n * 32;
    let mut pts = Vec::new();
    for &alpha in &log_space(1e-3, 1.0, 32) {
        let a = alpha as f32;
        for i in 0..nt {
            let theta = 89.9 * i as f64 / (nt - 1) as f64;
            let d = r64::dir(theta.to_radians(), 0.7);
            let w = [d[0] as f32, d[1] as f32, d[2] as f32];
            let lambda = r64::beckmann_lambda([w[0] as f64, w[1] as f64, w[2] as f64], a as f64, a as f64);
            pts.push(Point {
                nv: 0.0,
                nl: 0.0,
                nh: 0.0,
                vh: 0.0,
                alpha: a,
                w,
                h64: d,
                reference: lambda,
                reference_g1: 1.0 / (1.0 + lambda),
                theta_deg: theta,
                theta2_deg: 0.0,
            });
        }
    }
    pts
}

/// The value of input column `col` at `p`.
fn column(col: &str, p: &Point) -> Result<f32> {
    Ok(match col {
        "n_dot_v" => p.nv,
        "n_dot_l" => p.nl,
        "n_dot_h" => p.nh,
        "v_dot_h" => p.vh,
        "alpha" | "alpha_x" | "alpha_y" => p.alpha,
        "wm_x" | "wh_x" | "w_x" => p.w[0],
        "wm_y" | "wh_y" | "w_y" => p.w[1],
        "wm_z" | "wh_z" | "w_z" => p.w[2],
        _ => bail!("bench: no grid value for input column {col:?}"),
    })
}

/// Error statistics of one case.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ErrorStats {
    pub max_rel: f64,
    pub mean_rel: f64,
    pub max_abs: f64,
    pub non_finite: usize,
    pub worst: String,
    pub points: usize,
}

fn error_stats(values: &[f32], pts: &[Point], g1: bool, group: Group) -> ErrorStats {
    let mut s = ErrorStats { points: pts.len(), ..Default::default() };
    let mut sum = 0.0;
    for (&x, p) in values.iter().zip(pts) {
        let r = if g1 { p.reference_g1 } else { p.reference };
        if !x.is_finite() {
            s.non_finite += 1;
            continue;
        }
        let x = x as f64;
        let abs = (x - r).abs();
        let rel = abs / r.abs().max(f32::MIN_POSITIVE as f64);
        sum += rel;
        s.max_abs = s.max_abs.max(abs);
        if rel > s.max_rel || s.worst.is_empty() {
            s.max_rel = rel;
            s.worst = match group {
                Group::Visibility => format!("θv={:.1}° θl={:.1}° α={:.2e}", p.theta_deg, p.theta2_deg, p.alpha),
                Group::GgxD => format!("θh={:.3}° α={:.2e}", p.theta_deg, p.alpha),
                Group::Beckmann => format!("θ={:.2}° α={:.2e}", p.theta_deg, p.alpha),
            };
        }
    }
    s.mean_rel = sum / (pts.len() - s.non_finite).max(1) as f64;
    s
}

/// One row of the report.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Measured {
    pub name: String,
    pub group: String,
    pub source: String,
    pub error: ErrorStats,
    pub cpu_evals_per_s: Option<f64>,
    pub gpu_evals_per_s: Option<f64>,
    /// Median-run rates (CPU, GPU), printed beside the fastest.
    pub cpu_median_per_s: Option<f64>,
    pub gpu_median_per_s: Option<f64>,
    pub gpu_timing: Option<String>,
    /// The hand-written WGSL kernel of the same formula on the same adapter (`ggx_d` only;
    /// [`crate::bench_kernels::WGSL_REFERENCES`]), and the rust-gpu rate over it: the median
    /// of the per-round ratios of the two timed in alternation ([`crate::bench_kernels::time_paired`]).
    pub wgsl_evals_per_s: Option<f64>,
    pub rust_gpu_over_wgsl: Option<f64>,
}


/// Run the benchmark and write the report and plot.
pub fn run(a: &MicrofacetArgs) -> Result<()> {
    anyhow::ensure!(a.grid >= 4, "--grid must be at least 4");
    anyhow::ensure!(a.rows >= 1024, "--rows must be at least 1024");
    anyhow::ensure!(a.repeats >= 1, "--repeats must be at least 1");
    // Fail before the measurements when an output cannot be written.
    crate::io::prepare_output(&a.output)?;
    crate::io::prepare_output(&a.plot)?;
    let load_start = load_average();
    let (cpu, gpu) = Backend::bench_pair(a.device)?;
    let grids = [
        (Group::Visibility, visibility_grid(a.grid)),
        (Group::GgxD, ggx_d_grid(a.grid)),
        (Group::Beckmann, beckmann_grid(a.grid)),
    ];
    let cases = cases();
    let kernels = cases.iter().filter(|c| c.host_eval.is_none()).count();
    let timing_steps = if a.no_timing { 0 } else { kernels * (a.repeats + 1) * (1 + gpu.is_some() as usize) };
    let pb = indicatif::ProgressBar::new((cases.len() + timing_steps) as u64);
    pb.set_style(
        indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let mut out = Vec::new();
    for case in &cases {
        pb.set_message(case.name);
        let pts = &grids.iter().find(|(g, _)| *g == case.group).unwrap().1;
        let (values, timed) = match case.host_eval {
            Some(f) => (pts.iter().map(f).collect::<Vec<f32>>(), None),
            None => {
                let f = find_function(case.name)?;
                let mut rows = Vec::with_capacity(pts.len() * f.inputs.len());
                for p in pts {
                    for col in f.inputs {
                        rows.push(column(col, p)?);
                    }
                }
                let (vals, _) = cpu.eval_table(f, &rows, pts.len())?;
                (vals, Some((f, rows)))
            }
        };
        pb.inc(1);
        let error = error_stats(&values, pts, case.g1, case.group);
        let mut m = Measured {
            name: case.name.into(),
            group: format!("{:?}", case.group),
            source: case.source.into(),
            error,
            cpu_evals_per_s: None,
            gpu_evals_per_s: None,
            cpu_median_per_s: None,
            gpu_median_per_s: None,
            gpu_timing: None,
            wgsl_evals_per_s: None,
            rust_gpu_over_wgsl: None,
        };
        if let (Some((f, rows)), false) = (timed, a.no_timing) {
            let stride = f.inputs.len();
            let n = rows.len() / stride;
            let mut table = Vec::with_capacity(a.rows * stride);
            for i in 0..a.rows {
                let r = i % n;
                table.extend_from_slice(&rows[r * stride..(r + 1) * stride]);
            }
            let (c, cm, _) = time_eval(&cpu, f, &table, a.rows, a.repeats as u32, &|| pb.inc(1))?;
            m.cpu_evals_per_s = Some(c);
            m.cpu_median_per_s = Some(cm);
            if let Some(g) = &gpu {
                let (r, rm, src) = time_eval(g, f, &table, a.rows, a.repeats as u32, &|| pb.inc(1)).with_context(|| format!("timing {} on the GPU", f.name))?;
                m.gpu_evals_per_s = Some(r);
                m.gpu_median_per_s = Some(rm);
                m.gpu_timing = Some(src);
                if let (Some(gc), Some(entry)) = (g.gpu(), crate::bench_kernels::wgsl_entry(f.name)) {
                    let pr = crate::bench_kernels::time_paired(g, gc, entry, f, &table, a.rows, a.repeats as u32)?;
                    m.wgsl_evals_per_s = Some(pr.wgsl);
                    m.rust_gpu_over_wgsl = Some(pr.ratio);
                }
            }
        }
        out.push(m);
    }
    pb.finish_and_clear();
    let load = format!("{load_start} at the start, {} at the end", load_average());
    let md = markdown(a, &out, &grids.iter().map(|(g, p)| (*g, p.len())).collect::<Vec<_>>(), &cpu, gpu.as_ref(), &load);
    crate::io::write_file(&a.output, md)?;
    eprintln!("wrote {}", a.output.display());
    let json = a.output.with_extension("json");
    let doc = serde_json::json!({
        "command": crate::report::command_line(),
        "cpu": cpu_model(),
        "cpu_backend": cpu.describe(),
        "gpu_backend": gpu.as_ref().map(|g| g.describe()),
        "load_average": load,
        "rows_per_run": a.rows,
        "repeats": a.repeats,
        "functions": out,
    });
    crate::io::write_file(&json, serde_json::to_string_pretty(&doc)?)?;
    eprintln!("wrote {}", json.display());
    if !a.no_timing {
        plot(&a.plot, &out, gpu.as_ref().map(|g| g.describe()))?;
        eprintln!("wrote {}", a.plot.display());
    }
    Ok(())
}



fn fmt_rate(r: Option<f64>) -> String {
    match r {
        Some(r) if r < 1e7 => format!("{:.2}", r / 1e6),
        Some(r) => format!("{:.1}", r / 1e6),
        None => "n/a".into(),
    }
}

/// "fastest (median)" in Mevals/s.
fn fmt_rates(best: Option<f64>, median: Option<f64>) -> String {
    match (best, median) {
        (Some(b), Some(m)) => format!("{} ({})", fmt_rate(Some(b)), fmt_rate(Some(m))),
        (b, _) => fmt_rate(b),
    }
}

fn markdown(a: &MicrofacetArgs, rows: &[Measured], grids: &[(Group, usize)], cpu: &Backend, gpu: Option<&Backend>, load: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Microfacet approximations: cost and accuracy\n");
    let _ = writeln!(
        s,
        "Generated by `cargo run --release -p host -- bench microfacet --device {} --rows {} --repeats {} --grid {}` \
         (method, grids and reference: `host/src/bench_microfacet.rs`; functions: `docs/microfacet.md`).\n",
        format!("{:?}", a.device).to_lowercase(),
        a.rows,
        a.repeats,
        a.grid
    );
    let _ = writeln!(s, "- {} on {} ({} logical CPUs; 1-minute load average {load})", cpu.describe(), cpu_model(), std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0));
    match gpu {
        Some(g) => {
            let _ = writeln!(s, "- {}", g.describe());
            if let Some(gb) = g.gpu() {
                if gb.info.device_type == wgpu::DeviceType::Cpu {
                    let _ = writeln!(
                        s,
                        "- **The Vulkan adapter is a software rasterizer (lavapipe) running on the same CPU cores**: its column \
                         is not a GPU measurement (see `docs/microfacet.md`)."
                    );
                }
            }
        }
        None => {
            let _ = writeln!(s, "- GPU backend: none (run with a Vulkan adapter for the GPU column)");
        }
    }
    let _ = writeln!(
        s,
        "- Cost: fastest of {} timed runs of {} rows after one warm-up (median in parentheses); Mevals/s = 10^6 evaluations per second. \
         CPU: wall clock of the rayon-parallel evaluation. GPU: {}.",
        a.repeats,
        a.rows,
        match gpu.map(|g| g.gpu()) {
            Some(Some(g)) if g.timestamps => "timestamp queries around the compute pass (kernel time, no transfers)",
            Some(_) => "wall clock including transfers (the adapter has no timestamp queries)",
            None => "not measured",
        }
    );
    let _ = writeln!(s, "- Error: relative, |x - ref| / max(|ref|, 2^-126), max and mean over the grid; `worst at` is the grid point of the max.\n");
    for &(g, n) in grids {
        let _ = writeln!(s, "## {}\n", g.title());
        let _ = writeln!(
            s,
            "Grid: {n} points ({}).\n",
            match g {
                Group::Visibility => format!("θv, θl: {} values each in [0, 89.9]°; azimuth between them: 8 values in [0, π]; α: 16 log-spaced in [1e-3, 1]", a.grid),
                Group::GgxD => format!("α: 16 log-spaced in [2^-7, 1]; tan θh = α t, t: {} values in [0, 10]; φh = 0.3", a.grid * 64),
                Group::Beckmann => format!("θ: {} values in [0, 89.9]°; α: 32 log-spaced in [1e-3, 1]; φ = 0.7", a.grid * 32),
            }
        );
        let _ = writeln!(s, "| function | form | max rel err | mean rel err | max abs err | worst at | non-finite | CPU Mevals/s | GPU Mevals/s |");
        let _ = writeln!(s, "| --- | --- | ---: | ---: | ---: | --- | ---: | ---: | ---: |");
        for m in rows.iter().filter(|m| m.group == format!("{g:?}")) {
            let _ = writeln!(
                s,
                "| `{}` | {} | {:.3e} | {:.3e} | {:.3e} | {} | {} | {} | {} |",
                m.name,
                m.source,
                m.error.max_rel,
                m.error.mean_rel,
                m.error.max_abs,
                m.error.worst,
                m.error.non_finite,
                fmt_rates(m.cpu_evals_per_s, m.cpu_median_per_s),
                fmt_rates(m.gpu_evals_per_s, m.gpu_median_per_s)
            );
        }
        let _ = writeln!(s);
    }
    let wgsl: Vec<&Measured> = rows.iter().filter(|m| m.wgsl_evals_per_s.is_some()).collect();
    if !wgsl.is_empty() {
        let _ = writeln!(s, "## rust-gpu kernel against a hand-written WGSL kernel of the same formula
");
        let _ = writeln!(
            s,
            "Same adapter, same rows, same run; the WGSL (`host/src/wgsl/reference.wgsl`, compiled by naga) is a speed \
             reference only, not bit-exact. The two kernels are timed in alternation (one run of each per round); \
             rates are the fastest run of each, ratio = the median over the rounds of rust-gpu rate / WGSL rate.\n"
        );
        let _ = writeln!(s, "| function | rust-gpu Mevals/s | WGSL Mevals/s | ratio |");
        let _ = writeln!(s, "| --- | ---: | ---: | ---: |");
        for m in wgsl {
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {:.2} |",
                m.name,
                fmt_rate(m.gpu_evals_per_s),
                fmt_rate(m.wgsl_evals_per_s),
                m.rust_gpu_over_wgsl.unwrap_or(f64::NAN)
            );
        }
        let _ = writeln!(s);
    }
    s
}

/// Scatter plot: max relative error (log) against evaluations per second (log), one labelled point
/// per function and backend ([`crate::plot`]); functions with bitwise-equal errors on one backend
/// share one label ("a = b").
fn plot(path: &Path, rows: &[Measured], gpu_name: Option<String>) -> Result<()> {
    use crate::plot::{Axis, Plot, Series};
    let series_of = |label: &str, rate: &dyn Fn(&Measured) -> Option<f64>| {
        let mut s = Series::scatter(label, Vec::new());
        let mut first_of_error: Vec<(u64, usize)> = Vec::new();
        for m in rows {
            let Some(r) = rate(m) else { continue };
            let e = m.error.max_rel.max(1e-9);
            match first_of_error.iter().find(|(bits, _)| *bits == e.to_bits()) {
                Some(&(_, k)) => {
                    s.point_labels[k] = format!("{} = {}", s.point_labels[k], m.name);
                    s.point_labels.push(String::new());
                }
                None => {
                    first_of_error.push((e.to_bits(), s.points.len()));
                    s.point_labels.push(m.name.clone());
                }
            }
            s.points.push((r, e));
        }
        s
    };
    let mut series = vec![series_of("CPU backend", &|m| m.cpu_evals_per_s)];
    if gpu_name.is_some() {
        series.push(series_of("GPU backend", &|m| m.gpu_evals_per_s));
    }
    anyhow::ensure!(series.iter().any(|s| !s.points.is_empty()), "nothing timed: no plot");
    let mut footnotes = Vec::new();
    if let Some(g) = gpu_name {
        footnotes.push(g);
    }
    let untimed: Vec<String> = rows.iter().filter(|m| m.cpu_evals_per_s.is_none()).map(|m| format!("{} {:.2e}", m.name, m.error.max_rel)).collect();
    if !untimed.is_empty() {
        footnotes.push(format!("Not plotted (no kernel; error only, max rel): {}", untimed.join(", ")));
    }
    Plot {
        title: "Microfacet approximations: max relative error vs evaluations/s".into(),
        x: Axis::log("evaluations per second"),
        y: Axis::log("max relative error over the grid"),
        series,
        footnotes,
        size: (1800, 1200),
    }
    .save_png(path)
}
