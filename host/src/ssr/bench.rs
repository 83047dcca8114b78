//! `host bench ssr`: every configuration (HDRP linear N steps, HDRP Hi-Z with each resolve, SSSR 1
//! and 4 rays per pixel with and without reuse, with and without 16 frames of temporal
//! accumulation, sparse 1 ray per quad) on every built-in scene: RMSE and relative RMSE against
//! the ray-traced reference (on pixels whose reference rays stay on screen, and over all glossy
//! pixels), FLIP on tone-mapped images, time per pass on the CPU and GPU backends, skipped work;
//! written as a Markdown report, a JSON file of the same figures and a PNG of error against
//! time (default under out/; `cargo xtask docs-reports` writes docs/reports/ssr-bench.*).

use super::cli::{errors, Errors};
use super::metrics::{composite, tonemap};
use super::pipeline::{run_hdrp, HdrpResolve, SsrResult, SsrSettings, TraceMode, VndfSampler};
use super::reference::{render_reference, Reference};
use super::scene::scene;
use super::gbuffer::GBuffer;
use super::gltf_scenes::GltfScene;
use super::sssr::{run_sssr, FrameSequence, FrameSource, Reprojection, SssrSettings, StaticView};
use super::metrics::figure;
use crate::cli_args::pixels;
use crate::{Backend, DeviceChoice};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, clap::Args)]
pub struct BenchArgs {
    /// Scenes, comma separated: built-in (floor, hallway, thin, animated) and glTF scenes made by
    /// the project and path traced (cornell, pillars, orbit; `ssr::gltf_scenes`).
    #[arg(long, default_value = "floor,hallway,thin,animated,cornell,pillars,orbit")]
    pub scenes: String,
    /// Configurations to run, by their numbers in the report (1-based, comma separated; the
    /// plot's legend lists them); default all.
    #[arg(long)]
    pub configs: Option<String>,
    /// glTF scenes: where their files and exported G-buffers go (exports are reused when their
    /// settings match).
    #[arg(long, default_value = "out/ssr-scenes")]
    pub scene_dir: PathBuf,
    /// glTF scenes: the Cornell box `.gltf` (one external buffer) the `cornell` scene is made
    /// from; default the copy of the repository's `scenes/cornell_box/` built into the program.
    #[arg(long)]
    pub cornell: Option<PathBuf>,
    /// glTF scenes: path-traced samples per pixel of the colour buffer (the previous frame).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub colour_spp: u32,
    /// glTF scenes: samples per pixel of the colour buffers of the frames before the measured
    /// one (the camera path's history and the view before a camera cut).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub history_colour_spp: u32,
    /// Image width in pixels (1 to 4096).
    #[arg(long, default_value_t = 192, value_parser = pixels)]
    pub width: usize,
    /// Image height in pixels (1 to 4096).
    #[arg(long, default_value_t = 192, value_parser = pixels)]
    pub height: usize,
    /// Reference rays per glossy pixel, at least 1 (glTF scenes: path-traced samples).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..))]
    pub reference_samples: u32,
    /// Frame of the animated scenes' camera paths (temporal runs end there).
    #[arg(long, default_value_t = 20)]
    pub frame: u32,
    /// Also time every configuration on the GPU backend: auto = any Vulkan adapter, lavapipe
    /// included (none: CPU only), gpu = an error without one, cpu = CPU only.
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// Markdown report (docs/reports/ssr-bench.md is one; `cargo xtask docs-reports`
    /// regenerates it); the JSON figures go beside it (`.json`).
    #[arg(long, default_value = "out/ssr_bench.md")]
    pub report: PathBuf,
    /// PNG of error against time [default: the report's path with extension .png].
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

impl BenchArgs {
    /// The PNG's path.
    pub fn plot_path(&self) -> PathBuf {
        self.plot.clone().unwrap_or_else(|| self.report.with_extension("png"))
    }
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
                    "SSSR {rays}{}{}{}{}{}{}",
                    if s.reuse { " reuse" } else { "" },
                    if s.fis && !s.ray_color { " per-pair-colour" } else { "" },
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
    v.push(Config::Sssr(SssrSettings { ray_color: false, ..d.clone() }, h));
    v.push(Config::Sssr(SssrSettings { ray_color: false, temporal_frames: 16, ..d.clone() }, h));
    v
}

/// Run one configuration; temporal runs take their earlier frames from `source`.
pub fn run_config(backend: &Backend, source: &dyn FrameSource, gb: &super::GBuffer, s: &SsrSettings, c: &Config, frame: u32) -> Result<SsrResult> {
    run_config_frames(backend, source, gb, s, c, frame, None)
}

/// [`run_config`] with the number of temporal frames overridden by `frames` (e.g. 2 to time
/// one temporal frame, or to measure a camera cut).
pub fn run_config_frames(backend: &Backend, source: &dyn FrameSource, gb: &super::GBuffer, s: &SsrSettings, c: &Config, frame: u32, frames: Option<u32>) -> Result<SsrResult> {
    match c {
        Config::Hdrp(t, r) => run_hdrp(backend, gb, s, *t, *r),
        Config::Sssr(t, smp) => run_sssr(backend, Some(source), gb, &SsrSettings { sampler: *smp, ..s.clone() }, t, frame, frames.unwrap_or(t.temporal_frames)),
    }
}

/// One scene of the benchmark, ready to run.
pub struct BenchInput {
    pub name: String,
    /// The G-buffer of the measured frame.
    pub gbuffer: GBuffer,
    pub reference: Reference,
    /// What a reflection that finds nothing returns (the reference's fallback).
    pub sky: [f32; 3],
    /// The measured frame of the camera path (0 for static cameras).
    pub frame: u32,
    /// Whether the camera moves (no temporal-stability figure then).
    pub animated: bool,
    /// The G-buffers of earlier frames for temporal runs.
    pub frames: Box<dyn FrameSource>,
    /// Another view of the scene: the frames before a camera cut to the measured frame.
    pub cut_from: GBuffer,
    /// How the inputs were made.
    pub provenance: String,
}

/// A built-in scene at the bench's size: its G-buffer, its ray-traced reference; the camera
/// cut comes from the next built-in scene (another room entirely).
pub fn builtin_input(name: &str, a: &BenchArgs) -> Result<BenchInput> {
    let sc = scene(name)?;
    let frame = if sc.animated() { a.frame } else { 0 };
    let gb = sc.render_gbuffer(a.width, a.height, frame);
    gb.validate()?;
    let min_smoothness = SsrSettings::default().min_smoothness;
    let t0 = std::time::Instant::now();
    let reference = render_reference(&sc, &gb, 1.0 - min_smoothness, a.reference_samples);
    let other = super::scene::SCENES.iter().cycle().skip_while(|n| **n != name).nth(1).copied().unwrap_or("floor");
    let cut_from = scene(other)?.render_gbuffer(a.width, a.height, 0);
    Ok(BenchInput {
        name: name.into(),
        sky: sc.sky,
        frame,
        animated: sc.animated(),
        provenance: format!("built-in analytic scene, ray-traced reference ({} rays per glossy pixel, {:.1} s); camera cut from `{other}`", reference.samples, t0.elapsed().as_secs_f64()),
        gbuffer: gb,
        reference,
        frames: Box::new(sc),
        cut_from,
    })
}

/// A glTF scene of [`super::gltf_scenes`]: written to `--scene-dir`, loaded, and path traced
/// by the G-buffer export of `host render --gbuffer` on `backend` (the measured frame with its
/// reference; on a camera path the 15 frames before it; a view turned by 40 degrees for the
/// camera cut). Exports are stored in `--scene-dir` and reused when their settings match.
pub fn gltf_input(which: GltfScene, a: &BenchArgs, backend: &Backend, lut: &[f32]) -> Result<BenchInput> {
    use crate::render::environment::{self, EnvSpec};
    use crate::render::gbuffer::{export_frame, reference_path, FrameSpec, Quiet};
    use crate::render::scene::Scene as RenderScene;
    use crate::render::RenderInputs;
    use shader_core::pt::integrator::{RenderParams, STRATEGY_MIS};
    let t0 = std::time::Instant::now();
    let path = which.write(&a.scene_dir, a.cornell.as_deref())?;
    let sc = RenderScene::load(&path).with_context(|| format!("loading {}", path.display()))?;
    if !sc.warnings.is_empty() {
        anyhow::bail!("{}: the project's own scene loads with warnings: {}", path.display(), sc.warnings.join("; "));
    }
    let env = environment::build(&EnvSpec::Uniform(which.sky()), 1.0, 0.0)?;
    let base = sc.cameras.first().with_context(|| format!("{}: no camera", path.display()))?.clone();
    let pivot = sc.bounds.bounding_sphere().0;
    let near = (sc.bounds.bounding_sphere().1 * 1e-3).max(1e-6);
    let frame = if which.orbit().is_some() { a.frame } else { 0 };
    let camera_at = |degrees: f64| -> Result<shader_core::pt::camera::Camera> {
        base.orbited(pivot, degrees).kernel(a.width as u32, a.height as u32)
    };
    let angle = |f: i64| which.orbit().map(|d| f as f64 * d).unwrap_or(0.0);
    let inputs = RenderInputs { scene: &sc.words, env: &env.words, lut };
    let params = |cam| RenderParams {
        width: a.width as u32,
        height: a.height as u32,
        spp: 1,
        sample_base: 0,
        seed: 0,
        max_depth: 8,
        rr_depth: 3,
        strategy: STRATEGY_MIS,
        compensation: crate::energy::Compensation::Turquin.id(),
        sampler: shader_core::pt::sampler::SAMPLER_PCG,
        clamp: 0.0,
        p_env: if sc.has_lights() { 0.5 } else { 1.0 },
        camera: cam,
    };
    let max_roughness = 1.0 - SsrSettings::default().min_smoothness;
    // One exported frame at `degrees` (previous frame at `previous_degrees`), reused from disk
    // when a file of the same settings exists.
    let export = |tag: &str, degrees: f64, previous_degrees: f64, colour_spp: u32, reference_spp: u32| -> Result<(GBuffer, Option<Reference>)> {
        let file = a.scene_dir.join(format!("{}-{}x{}-{tag}-c{colour_spp}-r{reference_spp}.exr", which.name(), a.width, a.height));
        if file.exists() {
            let g = GBuffer::load(&file)?;
            let r = match (g.reference_path(&file), &g.reference) {
                (Some(rp), Some(info)) => Some(Reference::load(&rp, g.width, g.height, info.samples)?),
                _ => None,
            };
            if r.is_some() == (reference_spp > 0) {
                return Ok((g, r));
            }
        }
        let spec = FrameSpec {
            params: params(camera_at(degrees)?),
            previous: camera_at(previous_degrees)?,
            spp: colour_spp,
            spp_per_pass: colour_spp.min(8),
            reference_spp,
            max_roughness,
            fallback: env.mean_radiance,
            near,
        };
        let rp = reference_path(&file);
        let info = (reference_spp > 0).then(|| super::gbuffer::ReferenceFile {
            file: rp.file_name().expect("a file name").to_string_lossy().into_owned(),
            samples: reference_spp,
            max_roughness,
            method: "path traced (MIS, max depth 8, Turquin compensation, seed 0); fallback = the environment's radiance".into(),
            noise_rel: None,
        });
        let t = std::time::Instant::now();
        let e = export_frame(backend, &inputs, &spec, None, info, &mut Quiet)?;
        eprintln!("  exported {} in {:.1} s ({:.2} M rays/s in the G-buffer pass)", file.display(), t.elapsed().as_secs_f64(), e.rays / e.gbuffer_wall.max(1e-9) / 1e6);
        e.gbuffer.save(&file)?;
        if let Some(r) = &e.reference {
            r.save(&rp)?;
        }
        Ok((e.gbuffer, e.reference))
    };
    let f = frame as i64;
    let (gb, reference) = export("main", angle(f), angle(f - 1), a.colour_spp, a.reference_samples)?;
    let reference = reference.context("the measured frame's reference")?;
    let mut seq = Vec::new();
    if which.orbit().is_some() {
        for k in (f - 15).max(0)..f {
            seq.push(export(&format!("f{k}"), angle(k), angle(k - 1), a.history_colour_spp, 0)?.0);
        }
    }
    let cut = angle(f) - 40.0;
    let (cut_from, _) = export("cut", cut, cut, a.history_colour_spp, 0)?;
    Ok(BenchInput {
        name: which.name().into(),
        sky: gb.fallback,
        frame,
        animated: which.orbit().is_some(),
        provenance: format!(
            "glTF scene `{}` ({} triangles) path traced on the {} backend: colour {} spp (earlier frames {} spp), reference {} samples per glossy pixel (its own relative noise {}){}; camera cut from a view turned by 40 degrees; inputs ready in {:.1} s",
            path.display(),
            sc.counts.triangles,
            if backend.is_gpu() { "GPU" } else { "CPU" },
            a.colour_spp,
            a.history_colour_spp,
            a.reference_samples,
            gb.reference.as_ref().and_then(|r| r.noise_rel).map(|n| figure(n, 3)).unwrap_or_else(|| "n/a".into()),
            which.orbit().map(|d| format!("; camera orbiting {d} degrees per frame, frame {frame}")).unwrap_or_default(),
            t0.elapsed().as_secs_f64()
        ),
        gbuffer: gb,
        reference,
        frames: Box::new(FrameSequence { first: (f - 15).max(0) as u32, frames: seq }),
        cut_from,
    })
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
#[derive(Clone, Debug, serde::Serialize)]
pub struct Row {
    pub scene: String,
    /// The configuration's number (`--configs`).
    pub number: usize,
    pub config: String,
    pub errors: Errors,
    /// On-screen relative RMSE with the reference's own noise taken out (NaN where the
    /// reference has no noise estimate: the analytic references are exact per ray).
    pub onscreen_above_noise: f64,
    /// Against the on-screen reference over glossy, non-mirror pixels (where sampling matters).
    pub rough: super::metrics::ErrorStats,
    pub flip: f32,
    /// Specular (composite x FG) against the reference's specular integral, on-screen reference,
    /// glossy pixels.
    pub specular: super::metrics::ErrorStats,
    /// Temporal stability on a static camera ([`flicker`]); `None` for a moving camera.
    pub flicker: Option<f64>,
    /// Temporal rows: on-screen relative RMSE of the first frame after a camera cut
    /// ([`super::GBuffer::after_cut`]), with the history of the other view.
    pub after_cut_rel: Option<f64>,
    /// The same frame without history (one frame of the configuration): what the cut costs with
    /// no ghosting at all.
    pub after_cut_fresh_rel: Option<f64>,
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

/// Relative frame-to-frame change of the composite over the reference's glossy pixels:
/// RMS(composite_k - composite_k-1) / RMS(reference) (temporal stability: 0 = no flicker).
pub fn flicker(a: &[f32], b: &[f32], input: &BenchInput) -> f64 {
    let (ca, cb) = (composite(a, input.sky), composite(b, input.sky));
    let r = &input.reference;
    let (mut d2, mut r2) = (0.0f64, 0.0f64);
    for i in 0..r.glossy.len() {
        if r.glossy[i] {
            for c in 0..3 {
                d2 += (f64::from(ca[3 * i + c]) - f64::from(cb[3 * i + c])).powi(2);
                r2 += f64::from(r.onscreen[3 * i + c]).powi(2);
            }
        }
    }
    if r2 > 0.0 {
        (d2 / r2).sqrt()
    } else {
        f64::NAN
    }
}

/// Selected configurations (`--configs`), numbered from 1.
pub fn selected_configs(a: &BenchArgs) -> Result<Vec<(usize, Config)>> {
    let all: Vec<(usize, Config)> = configs().into_iter().enumerate().map(|(i, c)| (i + 1, c)).collect();
    let Some(list) = &a.configs else { return Ok(all) };
    let mut v = Vec::new();
    for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let n: usize = item.parse().with_context(|| format!("--configs: {item:?} is not a configuration number"))?;
        let c = all.iter().find(|(i, _)| *i == n).with_context(|| format!("--configs: no configuration {n} (1 to {})", all.len()))?;
        v.push(c.clone());
    }
    anyhow::ensure!(!v.is_empty(), "--configs selects nothing");
    Ok(v)
}

/// Measure the selected configurations on one scene.
pub fn bench_scene(cpu: &Backend, gpu: Option<&Backend>, input: &BenchInput, a: &BenchArgs, lut: &[f32]) -> Result<Vec<Row>> {
    let (name, gb, reference, sky, frame) = (input.name.as_str(), &input.gbuffer, &input.reference, input.sky, input.frame);
    let src = input.frames.as_ref();
    let s = SsrSettings { frame, ..SsrSettings::default() };
    // The specular column's inputs, the same for every configuration.
    let spec_consts = super::pipeline::build_params(gb, &s)?;
    let packed = gb.packed();
    let on_mask: Vec<bool> = reference.glossy.iter().zip(&reference.onscreen_fraction).map(|(&g, &f)| g && f >= 0.999).collect();
    let noise = super::reference::noise_rel(reference, &on_mask);
    let mut rows = Vec::new();
    // The first frame after the camera cut (made on first use, shared by the temporal rows).
    let mut cut_frame: Option<GBuffer> = None;
    for (number, c) in selected_configs(a)? {
        let res = run_config(cpu, src, gb, &s, &c, frame)?;
        let e = errors(&res, reference, sky);
        let mut rough_ref = reference.clone();
        for (i, g) in rough_ref.glossy.iter_mut().enumerate() {
            *g = *g && gb.roughness[i] >= shader_core::ssr::stochastic::MIRROR_ROUGHNESS;
        }
        let rough = errors(&res, &rough_ref, sky).algorithm;
        let comp = composite(&res.reflection, sky);
        // FLIP of an empty mask compares two black images: not a measurement.
        let flip = if e.all.pixels > 0 { flip_mean(&comp, &reference.all, &reference.glossy, gb.width, gb.height) } else { f32::NAN };
        let comp4: Vec<f32> = comp.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 1.0]).collect();
        let spec = super::pipeline::Runner::new(cpu).specular(&spec_consts, &packed, &gb.base_color, lut, &comp4)?;
        let spec_rgb: Vec<f32> = spec.chunks_exact(4).flat_map(|c| [c[0], c[1], c[2]]).collect();
        let specular = super::metrics::error(&spec_rgb, &reference.specular_onscreen, &reference.glossy);
        let temporal = matches!(&c, Config::Sssr(t, _) if t.temporal_frames > 1);
        // Temporal stability on a static camera: the last two frames of a temporal run, or two
        // single frames with different random numbers.
        let stability = if input.animated {
            None
        } else if let Some(prev) = &res.previous_reflection {
            Some(flicker(&res.reflection, prev, input))
        } else {
            let s2 = SsrSettings { frame: frame + 1, ..s.clone() };
            let other = run_config(cpu, src, gb, &s2, &c, frame + 1)?;
            Some(flicker(&res.reflection, &other.reflection, input))
        };
        // Ghosting: the first frame after a cut from another view, its history built over
        // `temporal_frames - 1` frames of that view.
        // The cut frame is this frame's G-buffer with the previous camera, motion vectors and
        // previous colour of the other view (`GBuffer::after_cut`); the same frame without any
        // history is the comparison point (what the cut costs with no ghosting at all).
        let after_cut = if let (true, Config::Sssr(t, _)) = (temporal, &c) {
            let before = StaticView(&input.cut_from);
            if cut_frame.is_none() {
                cut_frame = Some(gb.after_cut(&input.cut_from)?);
            }
            let cut = cut_frame.as_ref().expect("made above");
            let s_cut = SsrSettings { frame: t.temporal_frames - 1, ..s.clone() };
            let r = run_config_frames(cpu, &before, cut, &s_cut, &c, t.temporal_frames - 1, None)?;
            let fresh = run_config_frames(cpu, &before, cut, &s_cut, &c, t.temporal_frames - 1, Some(1))?;
            Some((errors(&r, reference, sky).onscreen.rel, errors(&fresh, reference, sky).onscreen.rel))
        } else {
            None
        };
        let (cpu_ms, cpu_passes) = passes(&res);
        let (mut gpu_ms, mut gpu_passes, mut bit_exact) = (None, None, None);
        if let Some(g) = gpu {
            // Temporal rows are timed and compared over two frames (the last frame's passes
            // are what one frame costs); the first dispatch of an entry point includes the
            // driver's shader compilation: warm up.
            let frames = temporal.then_some(2);
            let cpu_ref;
            let cref = if temporal {
                cpu_ref = run_config_frames(cpu, src, gb, &s, &c, frame, frames)?;
                &cpu_ref
            } else {
                &res
            };
            let _ = run_config_frames(g, src, gb, &s, &c, frame, Some(1)).with_context(|| format!("{name} {} on the GPU", c.label()))?;
            let rg = run_config_frames(g, src, gb, &s, &c, frame, frames).with_context(|| format!("{name} {} on the GPU", c.label()))?;
            let (t, p) = passes(&rg);
            gpu_ms = Some(t);
            gpu_passes = Some(p);
            bit_exact = Some(
                rg.reflection.len() == cref.reflection.len()
                    && rg.reflection.iter().zip(&cref.reflection).all(|(x, y)| x.to_bits() == y.to_bits())
                    && rg.rays.iter().zip(&cref.rays).all(|(x, y)| x.to_bits() == y.to_bits()),
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
            "  {name:<8} {number:>2} {:<26} on-screen rel {} (above noise {})  rough rel {}  all rel {}  FLIP {:.4}  flicker {}  after cut {}  CPU {:.1} ms{}",
            c.label(),
            figure(e.onscreen.rel, 3),
            figure(super::reference::above_noise(e.onscreen.rel, noise), 3),
            figure(rough.rel, 3),
            figure(e.all.rel, 3),
            flip,
            stability.map(|v| figure(v, 3)).unwrap_or_else(|| "-".into()),
            after_cut.map(|(v, f)| format!("{} (no history {})", figure(v, 3), figure(f, 3))).unwrap_or_else(|| "-".into()),
            cpu_ms,
            gpu_ms.map(|t| format!("  GPU {t:.1} ms")).unwrap_or_default()
        );
        rows.push(Row {
            scene: name.into(),
            number,
            config: c.label(),
            onscreen_above_noise: super::reference::above_noise(e.onscreen.rel, noise),
            errors: e,
            rough,
            flip,
            specular,
            flicker: stability,
            after_cut_rel: after_cut.map(|v| v.0),
            after_cut_fresh_rel: after_cut.map(|v| v.1),
            cpu_ms,
            cpu_passes,
            gpu_ms,
            gpu_passes,
            bit_exact,
            tiles_skipped,
            pixels_skipped,
        });
    }
    Ok(rows)
}

/// `host bench ssr`.
pub fn run(a: &BenchArgs) -> Result<()> {
    let plot_path = a.plot_path();
    crate::io::prepare_output(&a.report)?;
    crate::io::prepare_output(&plot_path)?;
    let cpu = Backend::Cpu;
    let gpu = Backend::gpu_column(a.device)?;
    let gpu_name = gpu.as_ref().map(|g| g.describe());
    if let Some(n) = &gpu_name {
        eprintln!("{n}");
    }
    let info = crate::report::RunInfo::start(gpu_name.clone());
    // Energy tables for the specular column (the default tables, deterministic Sobol points,
    // cached in the user cache directory like every command's).
    let lut = crate::energy::tables_cached(&cpu, &None)?.lut_buffer();
    // The glTF scenes' inputs are path traced on a hardware GPU if there is one, else on the
    // CPU backend (a software adapter such as lavapipe path traces far slower than the CPU
    // backend; the image is the same bits either way).
    let exporter = if a.scenes.split(',').any(|n| GltfScene::by_name(n.trim()).is_some()) { Backend::select(DeviceChoice::Auto)? } else { Backend::Cpu };
    let mut all = Vec::new();
    let mut refs = Vec::new();
    for name in a.scenes.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        eprintln!("scene {name}:");
        let input = match GltfScene::by_name(name) {
            Some(g) => gltf_input(g, a, &exporter, &lut)?,
            None if super::scene::SCENES.contains(&name) => builtin_input(name, a)?,
            None => anyhow::bail!("--scenes: unknown scene {name:?}; built-in: {}; glTF: {}", super::scene::SCENES.join(", "), super::gltf_scenes::NAMES.join(", ")),
        };
        eprintln!("  {}", input.provenance);
        let rows = bench_scene(&cpu, gpu.as_ref(), &input, a, &lut)?;
        let r = &input.reference;
        let on = r.glossy.iter().zip(&r.onscreen_fraction).filter(|(g, f)| **g && **f >= 0.999).count();
        refs.push(SceneInfo { name: name.to_string(), glossy: r.glossy.iter().filter(|g| **g).count(), onscreen: on, provenance: input.provenance.clone() });
        all.extend(rows);
    }
    let md = report(a, &all, &refs, gpu_name.as_deref());
    crate::io::write_file(&a.report, md)?;
    plot(&plot_path, &all, gpu_name.as_deref())?;
    let json = crate::report::write_json(&a.report, info, &all)?;
    for p in [&a.report, &plot_path, &json] {
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// What the report says about one scene.
pub struct SceneInfo {
    pub name: String,
    /// Glossy pixels, and those whose reference rays all stay on screen.
    pub glossy: usize,
    pub onscreen: usize,
    pub provenance: String,
}

fn report(a: &BenchArgs, rows: &[Row], refs: &[SceneInfo], gpu: Option<&str>) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "## Measured comparison (`host bench ssr`)\n");
    let _ = writeln!(
        s,
        "Command: `{}cargo run --release -p host -- bench ssr --scenes {} --width {} --height {} --reference-samples {} --colour-spp {} --history-colour-spp {} --frame {}{} --report {} --plot {}` \
         ({}x{} pixels; reference: {} rays per glossy pixel).\n",
        crate::report::adapter_env(),
        a.scenes,
        a.width,
        a.height,
        a.reference_samples,
        a.colour_spp,
        a.history_colour_spp,
        a.frame,
        a.configs.as_ref().map(|c| format!(" --configs {c}")).unwrap_or_default(),
        a.report.display(),
        a.plot_path().display(),
        a.width,
        a.height,
        a.reference_samples
    );
    let _ = writeln!(s, "CPU backend: native, {} threads. GPU backend: {}.\n", crate::cpu::threads(), gpu.unwrap_or("none available"));
    let _ = writeln!(
        s,
        "Columns: **on-screen** = RMSE / relative RMSE against the on-screen-only reference on pixels whose reference \
         rays all stay on screen (the algorithm's own error); **above noise** = on-screen rel with the path-traced \
         reference's own noise taken out, sqrt(rel^2 - noise^2) (glTF scenes; the noise is estimated per pixel from two halves of \
         the reference's samples; - for the analytic references); **non-mirror rel** = relative RMSE against the on-screen reference over glossy pixels \
         with perceptual roughness >= 0.03 (where ray sampling, reuse and temporal filtering matter); **all glossy** = against the all-geometry reference \
         over every glossy pixel (adds what SSR cannot see); **FLIP** = mean FLIP of the tone-mapped composite \
         against the tone-mapped all-geometry reference (glossy pixels only); **specular rel** = relative RMSE of the \
         specular term (composite x preintegrated FG from the energy tables) against the reference's specular integral \
         (Fresnel inside the integral; on-screen reference, glossy pixels); times are the sum over passes \
         (CPU: wall clock; GPU: timestamp queries; temporal rows: the last frame); **skipped** = fraction of \
         8x8 tiles skipped / of pixels that traced no ray; **bits** = CPU and GPU reflections and ray records \
         identical (temporal rows: over two frames); **flicker** = temporal stability on a static camera, \
         RMS of the change of the composite between the last two frames (two independent frames for \
         single-frame configurations) over the RMS of the reference, glossy pixels (- for a moving camera); \
         **after cut** = on-screen relative RMSE of the first frame after a camera cut from another view \
         (previous camera, motion vectors and previous colour of that view, its history accumulated over 15 \
         frames of it), and in parentheses the same frame without history (ghosting = the difference).\n"
    );
    for SceneInfo { name: scene, glossy, onscreen: on, provenance } in refs {
        if *glossy == 0 {
            let _ = writeln!(s, "### {scene}: no glossy pixels: nothing measured (errors n/a)\n");
        }
        let _ = writeln!(s, "### {scene} ({glossy} glossy pixels, {on} with all reference rays on screen)\n");
        let _ = writeln!(s, "Inputs: {provenance}.\n");
        let _ = writeln!(
            s,
            "| # | configuration | on-screen RMSE | on-screen rel | above noise | non-mirror rel | all glossy RMSE | all glossy rel | FLIP | specular rel | flicker | after cut | CPU ms | GPU ms | skipped tiles / pixels | bits |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
        for r in rows.iter().filter(|r| &r.scene == scene) {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1} | {} | {} | {} |",
                r.number,
                r.config,
                figure(r.errors.onscreen.rmse, 4),
                figure(r.errors.onscreen.rel, 3),
                if r.onscreen_above_noise.is_nan() { "-".to_string() } else { figure(r.onscreen_above_noise, 3) },
                figure(r.rough.rel, 3),
                figure(r.errors.all.rmse, 4),
                figure(r.errors.all.rel, 3),
                figure(f64::from(r.flip), 4),
                figure(r.specular.rel, 3),
                r.flicker.map(|v| figure(v, 3)).unwrap_or_else(|| "-".into()),
                match (r.after_cut_rel, r.after_cut_fresh_rel) {
                    (Some(v), Some(f)) => format!("{} ({})", figure(v, 3), figure(f, 3)),
                    _ => "-".into(),
                },
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

/// Relative RMSE (on-screen pixels) against time per frame, one series per scene, each point
/// labelled with its configuration's number (the footnote lists them); rows where nothing was
/// measured are left out.
fn plot(path: &Path, rows: &[Row], gpu: Option<&str>) -> Result<()> {
    use crate::plot::{Axis, Plot, Series};
    let mut configs: Vec<(usize, &str)> = Vec::new();
    let mut series: Vec<Series> = Vec::new();
    for r in rows {
        let n = r.number;
        if !configs.iter().any(|(k, _)| *k == n) {
            configs.push((n, &r.config));
        }
        let p = (r.gpu_ms.unwrap_or(r.cpu_ms), r.errors.onscreen.rel);
        match series.iter_mut().find(|s| s.label == r.scene) {
            Some(s) => {
                s.points.push(p);
                s.point_labels.push(n.to_string());
            }
            None => series.push(Series { point_labels: vec![n.to_string()], ..Series::scatter(&r.scene, vec![p]) }),
        }
    }
    configs.sort();
    let legend: Vec<String> = configs.iter().map(|(i, c)| format!("{i} = {c}")).collect();
    let footnotes = vec![
        format!("Configurations: {}.", legend.join("; ")),
        match gpu {
            Some(g) => format!("Time: GPU backend, sum over passes; GPU: {g}"),
            None => "Time: CPU backend (no GPU in this run), sum over passes, wall clock.".into(),
        },
    ];
    Plot {
        title: format!("SSR: relative RMSE (on-screen pixels) vs time per frame ({} backend)", if gpu.is_some() { "GPU" } else { "CPU" }),
        x: Axis::log("milliseconds per frame (sum over passes)"),
        y: Axis::log("relative RMSE vs on-screen reference"),
        series,
        footnotes,
        size: (1800, 1200),
    }
    .save_png(path)
}

/// `host bench ssr-ablate`: the stochastic pipeline with its parts switched off one at a time, and
/// HDRP's resolves, on one scene; relative RMSE against the on-screen reference over non-mirror
/// glossy pixels, in total and per roughness value (to find where SSSR's error comes from).
#[derive(Clone, Debug, clap::Args)]
pub struct AblateArgs {
    /// Built-in scene: floor, hallway, thin, animated (animated: frame 20).
    #[arg(long, default_value = "floor")]
    pub scene: String,
    /// Image width in pixels (1 to 4096).
    #[arg(long, default_value_t = 128, value_parser = pixels)]
    pub width: usize,
    /// Image height in pixels (1 to 4096).
    #[arg(long, default_value_t = 128, value_parser = pixels)]
    pub height: usize,
    /// Reference rays per glossy pixel, at least 1.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..))]
    pub reference_samples: u32,
    /// Rays per tracing pixel of the SSSR variants (1 to 8; the temporal rows use 1).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=8))]
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
        ("  - colour per (pixel, ray) pair, not per ray".into(), Config::Sssr(SssrSettings { ray_color: false, ..base.clone() }, VndfSampler::Heitz)),
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
        "`host bench ssr-ablate --scene {} --width {} --height {} --reference-samples {} --spp {}`: relative RMSE vs the on-screen reference\n",
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
        let _ = write!(out, "| {label} | {} | {} | {} |", figure(glossy.rel, 3), figure(all.rel, 3), figure(on.rel, 3));
        for b in &bands {
            let e = errors(&res, &masked(&|i| nm(i) && ((gb.roughness[i] * 100.0).round() / 100.0) == *b), sc.sky).algorithm;
            let _ = write!(out, " {} |", figure(e.rel, 3));
        }
        let (mut sa, mut na) = (0.0f64, 0usize);
        for i in 0..gb.width * gb.height {
            if reference.glossy[i] && nm(i) {
                sa += f64::from(res.reflection[4 * i + 3]);
                na += 1;
            }
        }
        let _ = writeln!(out, " {} |", figure(if na > 0 { sa / na as f64 } else { f64::NAN }, 3));
        eprintln!("{label}: {}", figure(all.rel, 3));
    }
    println!("{out}");
    Ok(())
}

/// `host bench ssr-wall`: wall-clock time of one stochastic frame (pyramids through resolve) on the GPU
/// backend, with every pass its own submission and read-back (as the per-pass cross-checks run
/// them) against the whole frame in one command buffer with the indirect trace
/// (`Runner::sssr_frame_passes`, what `host ssr` uses). Medians over `--repeats` runs after one
/// warm-up; both include uploads and read-backs.
#[derive(Clone, Debug, clap::Args)]
pub struct WallArgs {
    /// Built-in scene: floor, hallway, thin, animated (frame 0).
    #[arg(long, default_value = "floor")]
    pub scene: String,
    /// Image sizes to time, e.g. 128x128,512x512.
    #[arg(long, default_value = "128x128,512x512")]
    pub sizes: String,
    /// Timed runs of each variant per size, at least 1, after one untimed warm-up run; the
    /// table shows their medians.
    #[arg(long, default_value_t = 7, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeats: u32,
}

fn parse_size(s: &str) -> Result<(usize, usize)> {
    let (w, h) = s.split_once('x').with_context(|| format!("size {s:?} is not WIDTHxHEIGHT"))?;
    let (w, h): (usize, usize) = (w.trim().parse().with_context(|| format!("width in {s:?}"))?, h.trim().parse().with_context(|| format!("height in {s:?}"))?);
    anyhow::ensure!(w > 0 && h > 0, "size {s:?} must be positive");
    Ok((w, h))
}

use crate::timing::median;

pub fn run_wall(a: &WallArgs) -> Result<()> {
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
            super::pipeline::Runner::new(&gpu).sssr_frame_passes_separately(&consts, &gbuf, &g.depth_layers(), &g.color)?;
            Ok(t0.elapsed().as_secs_f64() * 1e3)
        };
        let chained = || -> Result<f64> {
            let t0 = std::time::Instant::now();
            super::pipeline::Runner::new(&gpu).sssr_frame_passes(&consts, &gbuf, &g.depth_layers(), &g.color)?;
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
