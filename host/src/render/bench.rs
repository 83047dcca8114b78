//! `host bench render`: rays per second of the path tracer on the CPU backend (all threads and
//! one) and the GPU backend on the same image (whose digests must agree), cost against scene
//! size, the time to a given error at 512x512 with Sobol and with PCG samples, and memory. Writes `out/render-bench.md` + `.json`.

use super::environment::{self, EnvSpec};
use super::scene::{builtin_detail_for_triangles, Scene};
use super::RenderInputs;
use crate::energy::Compensation;
use crate::report::RunInfo;
use anyhow::{Context, Result};
use runner::{Backend, DeviceChoice};
use serde::Serialize;
use shader_core::pt::integrator::{RenderParams, STRATEGY_MIS};
use shader_core::pt::sampler::{SAMPLER_PCG, SAMPLER_SOBOL};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// Options of `host bench render`.
#[derive(clap::Args, Debug, Clone)]
pub struct RenderBenchArgs {
    /// GPU backend to time besides the CPU backend: auto (a Vulkan adapter if there is one,
    /// lavapipe included), gpu (required), cpu (CPU backend only).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// Smaller images and fewer samples (a quick look; the docs quote full runs).
    #[arg(long)]
    pub quick: bool,
    /// Markdown report (the JSON is written beside it).
    #[arg(long, default_value = "out/render-bench.md")]
    pub report: PathBuf,
}

/// One measured row.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// What was measured: "backend", "scene size", "time to error", "memory".
    pub measure: String,
    pub backend: String,
    pub triangles: usize,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub seconds: f64,
    pub rays: f64,
    pub rays_per_second: f64,
    pub samples_per_second: f64,
    /// Driver compile time of the kernel (GPU), seconds.
    pub compile_seconds: Option<f64>,
    pub bvh_build_seconds: f64,
    pub scene_bytes: usize,
    /// Relative RMSE (time-to-error rows).
    pub relative_rmse: Option<f64>,
    pub digest: String,
    pub note: String,
}

fn params(scene: &Scene, w: u32, h: u32, seed: u32) -> Result<RenderParams> {
    let cam = scene.cameras.first().context("the built-in scene has a camera")?;
    Ok(RenderParams { width: w, height: h, spp: 1, sample_base: 0, seed, max_depth: 8, rr_depth: 3, strategy: STRATEGY_MIS, compensation: Compensation::Turquin.id(), sampler: SAMPLER_SOBOL, clamp: 0.0, p_env: 0.0, camera: cam.kernel(w, h)? })
}

struct Timed {
    img: super::RenderImage,
    wall: f64,
}

fn timed(backend: &Backend, inputs: &RenderInputs<'_>, p: &RenderParams, spp: u32) -> Result<Timed> {
    let t0 = Instant::now();
    let (img, _) = super::render(backend, inputs, p, spp, spp.min(4), |_| {})?;
    Ok(Timed { img, wall: t0.elapsed().as_secs_f64() })
}

#[allow(clippy::too_many_arguments)]
fn row(measure: &str, backend: &str, scene: &Scene, p: &RenderParams, spp: u32, t: &Timed, compile: Option<f64>, note: String) -> Row {
    let samples = p.width as f64 * p.height as f64 * spp as f64;
    Row {
        measure: measure.into(),
        backend: backend.into(),
        triangles: scene.counts.triangles,
        width: p.width,
        height: p.height,
        spp,
        seconds: t.wall,
        rays: t.img.rays,
        rays_per_second: t.img.rays / t.wall,
        samples_per_second: samples / t.wall,
        compile_seconds: compile,
        bvh_build_seconds: scene.build_seconds,
        scene_bytes: scene.words.len() * 4,
        relative_rmse: None,
        digest: format!("{:016x}", t.img.digest()),
        note,
    }
}

/// Relative RMSE of one image from two independent renders `a`, `b` of it: sqrt(mean (a - b)^2 / 2)
/// / mean (a + b) / 2, in f64.
fn relative_rmse_of_pair(a: &[f32], b: &[f32]) -> f64 {
    let n = a.len() as f64;
    let mse2: f64 = a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>() / n;
    let mean: f64 = a.iter().zip(b).map(|(x, y)| 0.5 * (*x as f64 + *y as f64)).sum::<f64>() / n;
    (mse2 / 2.0).sqrt() / mean
}

/// Run the benchmark.
pub fn run(a: &RenderBenchArgs) -> Result<()> {
    crate::io::prepare_output(&a.report)?;
    let (cpu, gpu) = Backend::bench_pair(a.device)?;
    let info = RunInfo::start(gpu.as_ref().map(|g| g.describe()));
    let lut = crate::energy::tables_cached(&cpu, &None)?.lut_buffer();
    let black = environment::build(&EnvSpec::Black, 1.0, 0.0)?;
    let mut rows = Vec::new();
    let (w, h, spp) = if a.quick { (128, 128, 4) } else { (256, 256, 8) };

    // Backends on the default built-in scene.
    let scene = Scene::builtin(super::scene::DEFAULT_DETAIL);
    let inputs = RenderInputs { scene: &scene.words, env: &black.words, lut: &lut };
    let p = params(&scene, w, h, 1)?;
    let all = timed(&cpu, &inputs, &p, spp)?;
    eprintln!("CPU {} threads: {:.3} M rays/s", crate::cpu::threads(), all.img.rays / all.wall / 1e6);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?.install(|| timed(&cpu, &inputs, &p, spp))?;
    eprintln!("CPU 1 thread: {:.3} M rays/s", one.img.rays / one.wall / 1e6);
    let scaling = (all.img.rays / all.wall) / (one.img.rays / one.wall);
    rows.push(row("backend", &format!("CPU, {} threads", crate::cpu::threads()), &scene, &p, spp, &all, None, format!("{scaling:.2}x the 1-thread rate")));
    rows.push(row("backend", "CPU, 1 thread", &scene, &p, spp, &one, None, String::new()));
    if let Some(g) = &gpu {
        // The first launch compiles the pipeline: one tiny launch first, its time reported apart.
        let warm = RenderParams { width: 8, height: 8, ..p };
        let t0 = Instant::now();
        super::launch(g, &inputs, &warm)?;
        let first = t0.elapsed().as_secs_f64();
        let compile = g.compile_seconds(&shader_kernels::render::PT_RENDER);
        let t = timed(g, &inputs, &p, spp)?;
        eprintln!("GPU: {:.3} M rays/s (first launch {first:.2} s)", t.img.rays / t.wall / 1e6);
        let same = t.img.digest() == all.img.digest();
        let ratio = (t.img.rays / t.wall) / (all.img.rays / all.wall);
        rows.push(row("backend", &g.describe(), &scene, &p, spp, &t, compile, format!("{ratio:.3}x the CPU rate; image {} the CPU's", if same { "bit-identical to" } else { "DIFFERS from" })));
        if !same {
            anyhow::bail!("the GPU image differs from the CPU image (digests {:016x} vs {:016x})", t.img.digest(), all.img.digest());
        }
    }

    // Cost against scene size (CPU backend).
    for target in [1_000usize, 30_000, 300_000] {
        let d = builtin_detail_for_triangles(target);
        let s = Scene::builtin(d);
        let inputs = RenderInputs { scene: &s.words, env: &black.words, lut: &lut };
        let p = params(&s, w, h, 1)?;
        let t = timed(&cpu, &inputs, &p, spp)?;
        eprintln!("{} triangles: {:.3} M rays/s, BVH {:.3} s", s.counts.triangles, t.img.rays / t.wall / 1e6, s.build_seconds);
        rows.push(row("scene size", "CPU", &s, &p, spp, &t, None, format!("{} BVH nodes", s.counts.nodes)));
    }

    // Time to error at 512x512 (CPU), per sampler: the relative RMSE of an n-spp image,
    // estimated from two independent renders (E|a - b|^2 = 2 Var for unbiased a, b with
    // independent random numbers or scrambles), at two sample counts; the spp a target error
    // needs, from the power law RMSE ~ spp^b through the two points.
    let (ew, eh) = if a.quick { (256, 256) } else { (512, 512) };
    let ladder = if a.quick { [4u32, 16] } else { [16u32, 64] };
    for (sampler, name) in [(SAMPLER_SOBOL, "sobol"), (SAMPLER_PCG, "pcg")] {
        let mut pts = Vec::new();
        for es in ladder {
            let pa = RenderParams { sampler, ..params(&scene, ew, eh, 11)? };
            let pb = RenderParams { sampler, ..params(&scene, ew, eh, 12)? };
            let ta = timed(&cpu, &inputs, &pa, es)?;
            let tb = timed(&cpu, &inputs, &pb, es)?;
            let rel = relative_rmse_of_pair(&ta.img.color, &tb.img.color);
            eprintln!("{ew}x{eh}, {name}, {es} spp: relative RMSE {rel:.4} in {:.2} s", ta.wall);
            pts.push((es, rel, ta.wall / es as f64));
            let mut note = String::new();
            if pts.len() == 2 {
                let ((n0, e0, _), (n1, e1, per_spp)) = (pts[0], pts[1]);
                let b = (e1 / e0).ln() / (n1 as f64 / n0 as f64).ln();
                let _ = write!(note, "RMSE ~ spp^{b:.3}; ");
                for target in [0.1f64, 0.05] {
                    let need = n1 as f64 * (target / e1).powf(1.0 / b);
                    let _ = write!(note, "error {target}: ~{need:.0} spp, ~{:.0} s; ", need * per_spp);
                }
            }
            let mut r = row("time to error", &format!("CPU, {name} samples"), &scene, &pa, es, &ta, None, note.trim_end_matches("; ").to_string());
            r.relative_rmse = Some(rel);
            rows.push(r);
        }
    }

    // Memory.
    let out_bytes = w as usize * h as usize * shader_kernels::render::OUT_STRIDE * 4;
    rows.push(Row {
        measure: "memory".into(),
        backend: "-".into(),
        triangles: scene.counts.triangles,
        width: w,
        height: h,
        spp: 0,
        seconds: 0.0,
        rays: 0.0,
        rays_per_second: 0.0,
        samples_per_second: 0.0,
        compile_seconds: None,
        bvh_build_seconds: scene.build_seconds,
        scene_bytes: scene.words.len() * 4,
        relative_rmse: None,
        digest: String::new(),
        note: format!("scene buffer {:.2} MB, output {:.2} MB per launch at {w}x{h}, energy LUT {:.1} KB", scene.words.len() as f64 * 4e-6, out_bytes as f64 * 1e-6, lut.len() as f64 * 4e-3),
    });

    let mut md = String::new();
    let _ = writeln!(md, "# Path tracer benchmark\n");
    let _ = writeln!(md, "`{}`\n", info.command);
    let _ = writeln!(md, "Machine: {} ({} CPU threads); GPU backend: {}; load average at start {:?}.\n", info.cpu, info.cpu_threads, info.adapter.as_deref().unwrap_or("none"), info.load_average_start);
    let _ = writeln!(md, "Built-in Cornell box, MIS, max depth 8, Russian roulette from bounce 3, Turquin compensation, Sobol samples (the time-to-error rows: Sobol and PCG). Rays = closest-hit (primary + secondary) + shadow rays.\n");
    let _ = writeln!(md, "| measure | backend | triangles | image | spp | seconds | M rays/s | M samples/s | compile s | BVH build s | scene MB | rel. RMSE | note |");
    let _ = writeln!(md, "|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for r in &rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {}x{} | {} | {:.3} | {:.3} | {:.3} | {} | {:.3} | {:.2} | {} | {} |",
            r.measure,
            r.backend,
            r.triangles,
            r.width,
            r.height,
            r.spp,
            r.seconds,
            r.rays_per_second / 1e6,
            r.samples_per_second / 1e6,
            r.compile_seconds.map(|c| format!("{c:.2}")).unwrap_or_else(|| "-".into()),
            r.bvh_build_seconds,
            r.scene_bytes as f64 * 1e-6,
            r.relative_rmse.map(|e| format!("{e:.4}")).unwrap_or_else(|| "-".into()),
            r.note
        );
    }
    crate::io::write_file(&a.report, &md)?;
    let json = crate::report::write_json(&a.report, info, &rows)?;
    eprintln!("wrote {} and {}", a.report.display(), json.display());
    Ok(())
}
