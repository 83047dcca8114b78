//! `host ssr bench`: every configuration (HDRP linear N steps, HDRP Hi-Z with each resolve, SSSR 1
//! and 4 rays per pixel with and without reuse, with and without 16 frames of temporal
//! accumulation, sparse 1 ray per quad) on every built-in scene: RMSE and relative RMSE against
//! the ray-traced reference (on pixels whose reference rays stay on screen, and over all glossy
//! pixels), FLIP on tone-mapped images, time per pass on the CPU and GPU backends, skipped work;
//! written as a Markdown report and a PNG of error against time.

use super::cli::{errors, Errors};
use super::metrics::{composite, tonemap};
use super::pipeline::{run_hdrp, HdrpResolve, SsrResult, SsrSettings, TraceMode, VndfSampler};
use super::reference::{render_reference, Reference};
use super::scene::scene;
use super::sssr::{run_sssr, Reprojection, SssrSettings};
use crate::{Backend, DeviceChoice};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, clap::Args)]
pub struct BenchArgs {
    /// Scenes, comma separated.
    #[arg(long, default_value = "floor,hallway,thin,animated")]
    pub scenes: String,
    #[arg(long, default_value_t = 192)]
    pub width: usize,
    #[arg(long, default_value_t = 192)]
    pub height: usize,
    /// Reference rays per glossy pixel.
    #[arg(long, default_value_t = 64)]
    pub reference_samples: u32,
    /// Frame of the animated scene's camera path (temporal runs end there).
    #[arg(long, default_value_t = 20)]
    pub frame: u32,
    /// Also time every configuration on the GPU backend (when a Vulkan adapter exists).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// Markdown report (the "Measured comparison" section of docs/ssr.md is one).
    #[arg(long, default_value = "out/ssr_bench.md")]
    pub report: PathBuf,
    /// PNG of error against time.
    #[arg(long, default_value = "docs/ssr_error_vs_time.png")]
    pub plot: PathBuf,
}

/// One configuration.
#[derive(Clone, Debug)]
pub enum Config {
    Hdrp(TraceMode, HdrpResolve),
    Sssr(SssrSettings, VndfSampler),
}

impl Config {
    pub fn label(&self) -> String {
        match self {
            Config::Hdrp(t, r) => format!("HDRP {} {}", t.label(), r.label()),
            Config::Sssr(s, smp) => {
                let rays = if s.rays_per_quad == 4 { format!("{} rpp", s.samples_per_pixel) } else { format!("{}/quad", s.rays_per_quad * s.samples_per_pixel) };
                let d = SssrSettings::default();
                format!(
                    "SSSR {rays}{}{}{}{}{}",
                    if s.reuse { " reuse" } else { "" },
                    if s.temporal_frames > 1 { format!(" +T{}", s.temporal_frames) } else { String::new() },
                    if s.temporal_frames > 1 && s.reprojection == Reprojection::Surface { " surface-reproj" } else { "" },
                    if s.hiz_roughness_cut != d.hiz_roughness_cut { format!(" linear16>={}", s.hiz_roughness_cut) } else { String::new() },
                    if *smp != VndfSampler::Heitz { format!(" {}", smp.label()) } else { String::new() },
                )
            }
        }
    }
}

/// The configurations of the report.
pub fn configs() -> Vec<Config> {
    let mut v = vec![
        Config::Hdrp(TraceMode::Linear(16), HdrpResolve::Approx),
        Config::Hdrp(TraceMode::Linear(32), HdrpResolve::Approx),
        Config::Hdrp(TraceMode::Linear(64), HdrpResolve::Approx),
        Config::Hdrp(TraceMode::HiZ, HdrpResolve::Approx),
        Config::Hdrp(TraceMode::HiZ, HdrpResolve::Block3x3),
        Config::Hdrp(TraceMode::HiZ, HdrpResolve::Cross5),
    ];
    let d = SssrSettings::default();
    let h = VndfSampler::Heitz;
    v.push(Config::Sssr(SssrSettings { reuse: false, ..d.clone() }, h));
    v.push(Config::Sssr(d.clone(), h));
    v.push(Config::Sssr(SssrSettings { hiz_roughness_cut: 0.2, ..d.clone() }, h));
    v.push(Config::Sssr(d.clone(), VndfSampler::Caps));
    v.push(Config::Sssr(d.clone(), VndfSampler::Bounded));
    v.push(Config::Sssr(SssrSettings { temporal_frames: 16, ..d.clone() }, h));
    v.push(Config::Sssr(SssrSettings { temporal_frames: 16, reprojection: Reprojection::Surface, ..d.clone() }, h));
    v.push(Config::Sssr(SssrSettings { samples_per_pixel: 4, ..d.clone() }, h));
    v.push(Config::Sssr(SssrSettings { samples_per_pixel: 4, temporal_frames: 16, ..d.clone() }, h));
    v.push(Config::Sssr(SssrSettings { rays_per_quad: 1, ..d.clone() }, h));
    v.push(Config::Sssr(SssrSettings { rays_per_quad: 1, temporal_frames: 16, ..d.clone() }, h));
    v
}

/// Run one configuration.
pub fn run_config(backend: &Backend, sc: &super::scene::Scene, gb: &super::GBuffer, s: &SsrSettings, c: &Config, frame: u32) -> Result<SsrResult> {
    match c {
        Config::Hdrp(t, r) => run_hdrp(backend, gb, s, *t, *r),
        Config::Sssr(t, smp) => run_sssr(backend, Some(sc), gb, &SsrSettings { sampler: *smp, ..s.clone() }, t, frame, t.temporal_frames),
    }
}

/// FLIP (NVIDIA, Andersson et al. 2020) mean error between two tone-mapped RGB images (pixels
/// outside `mask` set to black in both), at the default 67 pixels per degree.
pub fn flip_mean(a: &[f32], b: &[f32], mask: &[bool], w: usize, h: usize) -> f32 {
    let to8 = |img: &[f32]| -> Vec<u8> {
        let t = tonemap(img);
        t.iter()
            .enumerate()
            .map(|(i, v)| if mask[i / 3] { (v * 255.0).round().clamp(0.0, 255.0) as u8 } else { 0 })
            .collect()
    };
    let (ia, ib) = (to8(a), to8(b));
    let fa = nv_flip::FlipImageRgb8::with_data(w as u32, h as u32, &ib);
    let fb = nv_flip::FlipImageRgb8::with_data(w as u32, h as u32, &ia);
    let err = nv_flip::flip(fa, fb, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    nv_flip::FlipPool::from_image(&err).mean()
}

/// One measured row.
#[derive(Clone, Debug)]
pub struct Row {
    pub scene: String,
    pub config: String,
    pub errors: Errors,
    /// Against the on-screen reference over glossy, non-mirror pixels (where sampling matters).
    pub rough: super::metrics::ErrorStats,
    pub flip: f32,
    /// Specular (composite x FG) against the reference's specular integral, on-screen reference,
    /// glossy pixels.
    pub specular: super::metrics::ErrorStats,
    pub cpu_ms: f64,
    pub cpu_passes: String,
    pub gpu_ms: Option<f64>,
    pub gpu_passes: Option<String>,
    pub bit_exact: Option<bool>,
    pub tiles_skipped: Option<f64>,
    pub pixels_skipped: Option<f64>,
}

fn passes(r: &SsrResult) -> (f64, String) {
    let total: f64 = r.times.iter().map(|t| t.seconds).sum::<f64>() * 1e3;
    let s = r.times.iter().map(|t| format!("{} {:.2}", t.name, t.seconds * 1e3)).collect::<Vec<_>>().join(", ");
    (total, s)
}

/// Measure every configuration on one scene.
pub fn bench_scene(cpu: &Backend, gpu: Option<&Backend>, name: &str, a: &BenchArgs, lut: &[f32]) -> Result<(Vec<Row>, Reference)> {
    let sc = scene(name)?;
    let frame = if sc.animated() { a.frame } else { 0 };
    let gb = sc.render_gbuffer(a.width, a.height, frame);
    gb.validate()?;
    let s = SsrSettings { frame, ..SsrSettings::default() };
    let reference = render_reference(&sc, &gb, 1.0 - s.min_smoothness, a.reference_samples);
    // The specular column's inputs, the same for every configuration.
    let spec_consts = super::pipeline::build_params(&gb, &s)?;
    let packed = gb.packed();
    let mut rows = Vec::new();
    for c in configs() {
        let res = run_config(cpu, &sc, &gb, &s, &c, frame)?;
        let e = errors(&res, &reference, sc.sky);
        let mut rough_ref = reference.clone();
        for (i, g) in rough_ref.glossy.iter_mut().enumerate() {
            *g = *g && gb.roughness[i] >= shader_core::ssr::stochastic::MIRROR_ROUGHNESS;
        }
        let rough = errors(&res, &rough_ref, sc.sky).algorithm;
        let comp = composite(&res.reflection, sc.sky);
        let flip = flip_mean(&comp, &reference.all, &reference.glossy, gb.width, gb.height);
        let comp4: Vec<f32> = comp.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 1.0]).collect();
        let spec = super::pipeline::Runner::new(cpu).specular(&spec_consts, &packed, &gb.base_color, lut, &comp4)?;
        let spec_rgb: Vec<f32> = spec.chunks_exact(4).flat_map(|c| [c[0], c[1], c[2]]).collect();
        let specular = super::metrics::error(&spec_rgb, &reference.specular_onscreen, &reference.glossy);
        let (cpu_ms, cpu_passes) = passes(&res);
        let (mut gpu_ms, mut gpu_passes, mut bit_exact) = (None, None, None);
        if let Some(g) = gpu {
            // The first dispatch of an entry point includes the driver's shader compilation: warm up.
            let _ = run_config(g, &sc, &gb, &s, &c, frame).with_context(|| format!("{name} {} on the GPU", c.label()))?;
            let rg = run_config(g, &sc, &gb, &s, &c, frame).with_context(|| format!("{name} {} on the GPU", c.label()))?;
            let (t, p) = passes(&rg);
            gpu_ms = Some(t);
            gpu_passes = Some(p);
            bit_exact = Some(
                rg.reflection.len() == res.reflection.len()
                    && rg.reflection.iter().zip(&res.reflection).all(|(x, y)| x.to_bits() == y.to_bits())
                    && rg.rays.iter().zip(&res.rays).all(|(x, y)| x.to_bits() == y.to_bits()),
            );
        }
        let (tiles_skipped, pixels_skipped) = match &res.tiles {
            Some(t) => (
                Some(t.skipped as f64 / t.tiles as f64),
                Some(1.0 - t.rays as f64 / (gb.width * gb.height) as f64 / f64::from(match &c { Config::Sssr(x, _) => x.samples_per_pixel, _ => 1 })),
            ),
            None => (None, None),
        };
        eprintln!(
            "  {name:<8} {:<26} on-screen rel {:.3}  rough rel {:.3}  all rel {:.3}  FLIP {:.4}  CPU {:.1} ms{}",
            c.label(),
            e.onscreen.rel,
            rough.rel,
            e.all.rel,
            flip,
            cpu_ms,
            gpu_ms.map(|t| format!("  GPU {t:.1} ms")).unwrap_or_default()
        );
        rows.push(Row {
            scene: name.into(),
            config: c.label(),
            errors: e,
            rough,
            flip,
            specular,
            cpu_ms,
            cpu_passes,
            gpu_ms,
            gpu_passes,
            bit_exact,
            tiles_skipped,
            pixels_skipped,
        });
    }
    Ok((rows, reference))
}

/// `host ssr bench`.
pub fn run(a: &BenchArgs) -> Result<()> {
    let cpu = Backend::Cpu;
    let gpu = match a.device {
        DeviceChoice::Cpu => None,
        _ => match Backend::select(DeviceChoice::Gpu) {
            Ok(b) => Some(b),
            Err(e) if a.device == DeviceChoice::Auto => {
                eprintln!("notice: no GPU backend ({e:#}); timing the CPU backend only");
                None
            }
            Err(e) => return Err(e),
        },
    };
    let gpu_name = gpu.as_ref().map(|g| g.describe());
    if let Some(n) = &gpu_name {
        eprintln!("{n}");
    }
    // Energy tables for the specular column (default precompute, deterministic Sobol points).
    let lut = crate::energy::precompute(&cpu, &crate::energy::TableSpec::default(), false)?.0.lut_buffer();
    let mut all = Vec::new();
    let mut refs = Vec::new();
    for name in a.scenes.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        eprintln!("scene {name}:");
        let (rows, r) = bench_scene(&cpu, gpu.as_ref(), name, a, &lut)?;
        let on = r.glossy.iter().zip(&r.onscreen_fraction).filter(|(g, f)| **g && **f >= 0.999).count();
        refs.push((name.to_string(), r.glossy.iter().filter(|g| **g).count(), on));
        all.extend(rows);
    }
    let md = report(a, &all, &refs, gpu_name.as_deref());
    crate::io::create_parent_dir(&a.report)?;
    std::fs::write(&a.report, md).with_context(|| format!("writing {}", a.report.display()))?;
    eprintln!("wrote {}", a.report.display());
    plot(&a.plot, &all, gpu_name.as_deref())?;
    eprintln!("wrote {}", a.plot.display());
    Ok(())
}

fn report(a: &BenchArgs, rows: &[Row], refs: &[(String, usize, usize)], gpu: Option<&str>) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "## Measured comparison (`host ssr bench`)\n");
    let _ = writeln!(
        s,
        "Command: `cargo run --release -p host -- ssr bench --width {} --height {} --reference-samples {} --frame {} --report {} --plot {}` \
         ({}x{} pixels; reference: {} rays per glossy pixel).\n",
        a.width,
        a.height,
        a.reference_samples,
        a.frame,
        a.report.display(),
        a.plot.display(),
        a.width,
        a.height,
        a.reference_samples
    );
    let _ = writeln!(s, "CPU backend: native, {} threads. GPU backend: {}.\n", crate::cpu::threads(), gpu.unwrap_or("none available"));
    let _ = writeln!(
        s,
        "Columns: **on-screen** = RMSE / relative RMSE against the on-screen-only reference on pixels whose reference \
         rays all stay on screen (the algorithm's own error); **non-mirror rel** = relative RMSE against the on-screen reference over glossy pixels \
         with perceptual roughness >= 0.03 (where ray sampling, reuse and temporal filtering matter); **all glossy** = against the all-geometry reference \
         over every glossy pixel (adds what SSR cannot see); **FLIP** = mean FLIP of the tone-mapped composite \
         against the tone-mapped all-geometry reference (glossy pixels only); **specular rel** = relative RMSE of the \
         specular term (composite x preintegrated FG from the energy tables) against the reference's specular integral \
         (Fresnel inside the integral; on-screen reference, glossy pixels); times are the sum over passes \
         (CPU: wall clock; GPU: timestamp queries; temporal rows: the last frame); **skipped** = fraction of \
         8x8 tiles skipped / of pixels that traced no ray; **bits** = CPU and GPU reflections and ray records \
         identical.\n"
    );
    for (scene, glossy, on) in refs {
        let _ = writeln!(s, "### {scene} ({glossy} glossy pixels, {on} with all reference rays on screen)\n");
        let _ = writeln!(
            s,
            "| configuration | on-screen RMSE | on-screen rel | non-mirror rel | all glossy RMSE | all glossy rel | FLIP | specular rel | CPU ms | GPU ms | skipped tiles / pixels | bits |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|");
        for r in rows.iter().filter(|r| &r.scene == scene) {
            let _ = writeln!(
                s,
                "| {} | {:.4} | {:.3} | {:.3} | {:.4} | {:.3} | {:.4} | {:.3} | {:.1} | {} | {} | {} |",
                r.config,
                r.errors.onscreen.rmse,
                r.errors.onscreen.rel,
                r.rough.rel,
                r.errors.all.rmse,
                r.errors.all.rel,
                r.flip,
                r.specular.rel,
                r.cpu_ms,
                r.gpu_ms.map(|t| format!("{t:.1}")).unwrap_or_else(|| "-".into()),
                match (r.tiles_skipped, r.pixels_skipped) {
                    (Some(t), Some(p)) => format!("{:.0}% / {:.0}%", t * 100.0, p * 100.0),
                    _ => "-".into(),
                },
                match r.bit_exact {
                    Some(true) => "same",
                    Some(false) => "DIFFER",
                    None => "-",
                }
            );
        }
        let _ = writeln!(s);
        let _ = writeln!(s, "<details><summary>time per pass (ms)</summary>\n");
        for r in rows.iter().filter(|r| &r.scene == scene) {
            let _ = writeln!(s, "- {}: CPU {}{}", r.config, r.cpu_passes, r.gpu_passes.as_ref().map(|g| format!("; GPU {g}")).unwrap_or_default());
        }
        let _ = writeln!(s, "\n</details>\n");
    }
    s
}

/// Relative RMSE (on-screen pixels) against time per frame, one colour per scene.
fn plot(path: &Path, rows: &[Row], gpu: Option<&str>) -> Result<()> {
    use plotters::prelude::*;
    static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    let (w, h) = (1800u32, 1200u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let time = |r: &Row| r.gpu_ms.unwrap_or(r.cpu_ms).max(1e-3);
    let pts: Vec<(f64, f64, &Row)> = rows.iter().map(|r| (time(r), r.errors.onscreen.rel.max(1e-4), r)).collect();
    anyhow::ensure!(!pts.is_empty(), "nothing measured");
    let (xmin, xmax) = pts.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (ymin, ymax) = pts.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let scenes: Vec<String> = {
        let mut v: Vec<String> = rows.iter().map(|r| r.scene.clone()).collect();
        v.dedup();
        v
    };
    let palette = [RGBColor(31, 119, 180), RGBColor(214, 39, 40), RGBColor(44, 160, 44), RGBColor(148, 103, 189), RGBColor(255, 127, 14)];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
        let caption = format!(
            "SSR: relative RMSE (on-screen pixels) vs time per frame ({} backend)",
            if gpu.is_some() { "GPU" } else { "CPU" }
        );
        let mut chart = ChartBuilder::on(&root)
            .caption(caption, ("sans-serif", 30))
            .margin(30)
            .x_label_area_size(70)
            .y_label_area_size(100)
            .build_cartesian_2d((xmin / 1.5..xmax * 2.5).log_scale(), (ymin / 1.3..ymax * 1.3).log_scale())
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_desc("milliseconds per frame (sum over passes)")
            .y_desc("relative RMSE vs on-screen reference")
            .label_style(("sans-serif", 20))
            .axis_desc_style(("sans-serif", 24))
            .draw()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        for (k, sname) in scenes.iter().enumerate() {
            let c = palette[k % palette.len()];
            chart
                .draw_series(pts.iter().filter(|p| &p.2.scene == sname).map(|p| Circle::new((p.0, p.1), 7, c.filled())))
                .map_err(|e| anyhow::anyhow!("{e}"))?
                .label(sname.clone())
                .legend(move |(x, y)| Circle::new((x, y), 7, c.filled()));
        }
        chart
            .configure_series_labels()
            .label_font(("sans-serif", 22))
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        let mut placed: Vec<(i32, i32)> = Vec::new();
        for p in &pts {
            let k = scenes.iter().position(|s| s == &p.2.scene).unwrap_or(0);
            let (px, py) = chart.backend_coord(&(p.0, p.1));
            let mut y = py - 8;
            while placed.iter().any(|&(x0, y0)| (x0 - px).abs() < 200 && (y0 - y).abs() < 15) {
                y += 15;
            }
            placed.push((px, y));
            root.draw(&Text::new(p.2.config.clone(), (px + 10, y), ("sans-serif", 14).into_font().color(&palette[k % palette.len()])))
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        if let Some(g) = gpu {
            root.draw(&Text::new(format!("GPU: {}", g.chars().take(110).collect::<String>()), (40, h as i32 - 30), ("sans-serif", 16).into_font()))
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    crate::io::create_parent_dir(path)?;
    image::save_buffer(path, &buf, w, h, image::ColorType::Rgb8).with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// `host ssr ablate`: the stochastic pipeline with its parts switched off one at a time, and
/// HDRP's resolves, on one scene; relative RMSE against the on-screen reference over non-mirror
/// glossy pixels, in total and per roughness value (to find where SSSR's error comes from).
#[derive(Clone, Debug, clap::Args)]
pub struct AblateArgs {
    #[arg(long, default_value = "floor")]
    pub scene: String,
    #[arg(long, default_value_t = 128)]
    pub width: usize,
    #[arg(long, default_value_t = 128)]
    pub height: usize,
    #[arg(long, default_value_t = 64)]
    pub reference_samples: u32,
    /// Rays per pixel of the SSSR variants.
    #[arg(long, default_value_t = 4)]
    pub spp: u32,
}

/// The ablation's configurations: (label, pipeline settings, configuration).
pub fn ablation_configs(spp: u32) -> Vec<(String, Config)> {
    let base = SssrSettings { samples_per_pixel: spp, ..SssrSettings::default() };
    let plain = SssrSettings { fis: false, sample_bias: 0.0, ..base.clone() };
    let mut v = vec![
        ("HDRP hiz 3x3".to_string(), Config::Hdrp(TraceMode::HiZ, HdrpResolve::Block3x3)),
        ("HDRP hiz cross5".to_string(), Config::Hdrp(TraceMode::HiZ, HdrpResolve::Cross5)),
        (format!("SSSR {spp} rpp reuse (defaults)"), Config::Sssr(base.clone(), VndfSampler::Heitz)),
        ("  - pdf stored at sampling (old weights)".into(), Config::Sssr(SssrSettings { sampled_pdf: true, ..base.clone() }, VndfSampler::Heitz)),
        ("  - FIS off".into(), Config::Sssr(SssrSettings { fis: false, ..base.clone() }, VndfSampler::Heitz)),
        ("  - bias 0".into(), Config::Sssr(SssrSettings { sample_bias: 0.0, ..base.clone() }, VndfSampler::Heitz)),
        ("  + linear 16-step march for roughness >= 0.2 (old default)".into(), Config::Sssr(SssrSettings { hiz_roughness_cut: 0.2, ..base.clone() }, VndfSampler::Heitz)),
        ("  - FIS and bias off (plain)".into(), Config::Sssr(plain.clone(), VndfSampler::Heitz)),
        ("  plain, reuse off".into(), Config::Sssr(SssrSettings { reuse: false, ..plain.clone() }, VndfSampler::Heitz)),
        ("  plain, pdf stored at sampling".into(), Config::Sssr(SssrSettings { sampled_pdf: true, ..plain.clone() }, VndfSampler::Heitz)),
        ("  plain, pdf stored at sampling, reuse off".into(), Config::Sssr(SssrSettings { sampled_pdf: true, reuse: false, ..plain.clone() }, VndfSampler::Heitz)),
    ];
    for smp in [VndfSampler::Caps, VndfSampler::Bounded] {
        v.push((format!("SSSR {spp} rpp reuse, sampler {}", smp.label()), Config::Sssr(base.clone(), smp)));
    }
    let one = SssrSettings { samples_per_pixel: 1, ..base.clone() };
    v.push(("SSSR 1 rpp reuse, 1 frame".into(), Config::Sssr(one.clone(), VndfSampler::Heitz)));
    for (name, reprojection, history_rejection) in [
        ("surface motion, clamp only", Reprojection::Surface, false),
        ("surface motion + depth/normal rejection", Reprojection::Surface, true),
        ("hit (virtual image), clamp only", Reprojection::Hit, false),
        ("hit (virtual image) + depth/normal rejection", Reprojection::Hit, true),
    ] {
        v.push((
            format!("SSSR 1 rpp reuse +T16, {name}"),
            Config::Sssr(SssrSettings { temporal_frames: 16, reprojection, history_rejection, ..one.clone() }, VndfSampler::Heitz),
        ));
    }
    v
}

/// Run the ablation and print its table (Markdown).
pub fn run_ablate(a: &AblateArgs) -> Result<()> {
    let sc = scene(&a.scene)?;
    let frame = if sc.animated() { 20 } else { 0 };
    let gb = sc.render_gbuffer(a.width, a.height, frame);
    gb.validate()?;
    let s0 = SsrSettings { frame, ..SsrSettings::default() };
    let reference = render_reference(&sc, &gb, 1.0 - s0.min_smoothness, a.reference_samples);
    let mut bands: Vec<f32> = Vec::new();
    for (i, g) in reference.glossy.iter().enumerate() {
        let r = (gb.roughness[i] * 100.0).round() / 100.0;
        if *g && gb.roughness[i] >= shader_core::ssr::stochastic::MIRROR_ROUGHNESS && !bands.contains(&r) {
            bands.push(r);
        }
    }
    bands.sort_by(|x, y| x.total_cmp(y));
    let masked = |keep: &dyn Fn(usize) -> bool| {
        let mut r = reference.clone();
        for (i, g) in r.glossy.iter_mut().enumerate() {
            *g = *g && keep(i);
        }
        r
    };
    let mut out = String::new();
    let _ = writeln!(
        out,
        "`host ssr ablate --scene {} --width {} --height {} --reference-samples {} --spp {}`: relative RMSE vs the on-screen reference\n",
        a.scene, a.width, a.height, a.reference_samples, a.spp
    );
    let _ = write!(out, "| configuration | glossy rel | non-mirror rel | on-screen-only pixels, non-mirror rel |");
    for b in &bands {
        let _ = write!(out, " roughness {b:.2} rel |");
    }
    let _ = writeln!(out, " opacity mean (non-mirror) |");
    let _ = writeln!(out, "|---|---|---|---|{}---|", "---|".repeat(bands.len()));
    for (label, c) in ablation_configs(a.spp) {
        let res = run_config(&Backend::Cpu, &sc, &gb, &s0, &c, frame)?;
        let nm = |i: usize| gb.roughness[i] >= shader_core::ssr::stochastic::MIRROR_ROUGHNESS;
        let all = errors(&res, &masked(&nm), sc.sky).algorithm;
        let on = errors(&res, &masked(&|i| nm(i) && reference.onscreen_fraction[i] >= 0.999), sc.sky).algorithm;
        let glossy = errors(&res, &reference, sc.sky).algorithm;
        let _ = write!(out, "| {label} | {:.3} | {:.3} | {:.3} |", glossy.rel, all.rel, on.rel);
        for b in &bands {
            let e = errors(&res, &masked(&|i| nm(i) && ((gb.roughness[i] * 100.0).round() / 100.0) == *b), sc.sky).algorithm;
            let _ = write!(out, " {:.3} |", e.rel);
        }
        let (mut sa, mut na) = (0.0f64, 0usize);
        for i in 0..gb.width * gb.height {
            if reference.glossy[i] && nm(i) {
                sa += f64::from(res.reflection[4 * i + 3]);
                na += 1;
            }
        }
        let _ = writeln!(out, " {:.3} |", sa / na.max(1) as f64);
        eprintln!("{label}: {:.3}", all.rel);
    }
    println!("{out}");
    Ok(())
}

/// `host ssr wall`: wall-clock time of one stochastic frame (pyramids through resolve) on the GPU
/// backend, with every pass its own submission and read-back (as the per-pass cross-checks run
/// them) against the whole frame in one command buffer with the indirect trace
/// (`Runner::sssr_frame_passes`, what `host ssr` uses). Medians over `--repeats` runs after one
/// warm-up; both include uploads and read-backs.
#[derive(Clone, Debug, clap::Args)]
pub struct WallArgs {
    #[arg(long, default_value = "floor")]
    pub scene: String,
    /// Image sizes to time, e.g. 128x128,512x512.
    #[arg(long, default_value = "128x128,512x512")]
    pub sizes: String,
    #[arg(long, default_value_t = 7)]
    pub repeats: usize,
}

fn parse_size(s: &str) -> Result<(usize, usize)> {
    let (w, h) = s.split_once('x').with_context(|| format!("size {s:?} is not WIDTHxHEIGHT"))?;
    let (w, h): (usize, usize) = (w.trim().parse().with_context(|| format!("width in {s:?}"))?, h.trim().parse().with_context(|| format!("height in {s:?}"))?);
    anyhow::ensure!(w > 0 && h > 0, "size {s:?} must be positive");
    Ok((w, h))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

pub fn run_wall(a: &WallArgs) -> Result<()> {
    anyhow::ensure!(a.repeats > 0, "--repeats must be at least 1");
    let gpu = Backend::select(DeviceChoice::Gpu)?;
    eprintln!("{}", gpu.describe());
    let sc = scene(&a.scene)?;
    println!("| size | separate submissions (ms) | one command buffer (ms) | ratio |");
    println!("|---|---|---|---|");
    for size in a.sizes.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (w, h) = parse_size(size)?;
        let g = sc.render_gbuffer(w, h, 0);
        let consts = super::sssr::sssr_params(&g, &SsrSettings::default(), &SssrSettings::default())?;
        let gbuf = g.packed();
        let separate = || -> Result<f64> {
            let t0 = std::time::Instant::now();
            super::pipeline::Runner::new(&gpu).sssr_frame_passes_separately(&consts, &gbuf, &g.depth, &g.color)?;
            Ok(t0.elapsed().as_secs_f64() * 1e3)
        };
        let chained = || -> Result<f64> {
            let t0 = std::time::Instant::now();
            super::pipeline::Runner::new(&gpu).sssr_frame_passes(&consts, &gbuf, &g.depth, &g.color)?;
            Ok(t0.elapsed().as_secs_f64() * 1e3)
        };
        separate()?;
        chained()?;
        let (mut s, mut c) = (Vec::new(), Vec::new());
        for _ in 0..a.repeats {
            s.push(separate()?);
            c.push(chained()?);
        }
        let (ms, mc) = (median(s), median(c));
        println!("| {w}x{h} | {ms:.1} | {mc:.1} | {:.2} |", mc / ms);
    }
    Ok(())
}
