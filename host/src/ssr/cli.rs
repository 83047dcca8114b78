//! `host ssr`: run either SSR pipeline on a built-in scene or an EXR G-buffer, write the
//! reflection (EXR + PNG), debug views and per-pass times, and the error against the ray-traced
//! reference where the scene is procedural. `host bench ssr` writes the comparison report.

use super::gbuffer::GBuffer;
use super::metrics::{composite, error, figure, ErrorStats};
use super::pipeline::{run_hdrp, HdrpResolve, SsrResult, SsrSettings, TraceMode, VndfSampler};
use super::reference::{render_reference, Reference};
use super::scene::{scene, Scene};
use super::sssr::{run_sssr, Reprojection, SssrSettings};
use super::legend::{self, Legend};
use crate::io::{write_exr, write_rgb_preview_png};
use crate::cli_args::{f32_in, f32_in_half_open, pixels, u32_of};
use crate::{Backend, DeviceChoice};
use anyhow::{bail, Context, Result};
use shader_core::ssr::stochastic::{TILE_HIZ, TILE_LINEAR, TILE_MIXED, TILE_SKIP};
use shader_core::ssr::trace::{info, RAY_INFO, RAY_STRIDE};
use std::path::{Path, PathBuf};

/// Which pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PipelineChoice {
    /// Unity HDRP: one mirror ray per pixel, SSR_APPROX or a GetSSRSampleWeight neighbourhood.
    Hdrp,
    /// Frostbite stochastic SSR: tiles, ray list, VNDF rays, BRDF-weighted reuse, temporal.
    Sssr,
}

/// Options shared by `host ssr` and `host bench ssr`.
#[derive(Clone, Debug, clap::Args)]
pub struct RunArgs {
    /// Built-in scene: floor, hallway, thin, animated.
    #[arg(long, default_value = "floor", conflicts_with = "input")]
    pub scene: String,
    /// G-buffer EXR (with its camera JSON beside it) instead of a built-in scene.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// The SSR pipeline; options marked HDRP or SSSR apply to that pipeline only (an error otherwise).
    #[arg(long, value_enum, default_value = "hdrp")]
    pub pipeline: PipelineChoice,
    /// HDRP: tracer: hiz, linear<N> (e.g. linear32, N in 1..=4096) or brute (every pixel along the ray).
    #[arg(long, default_value = "hiz")]
    pub trace: String,
    /// HDRP: resolve: approx (SSR_APPROX), 3x3 or cross5.
    #[arg(long, default_value = "approx")]
    pub resolve: String,
    /// Image width in pixels of a built-in scene (1 to 4096).
    #[arg(long, default_value_t = 256, value_parser = pixels)]
    pub width: usize,
    /// Image height in pixels of a built-in scene (1 to 4096).
    #[arg(long, default_value_t = 256, value_parser = pixels)]
    pub height: usize,
    /// Frame of an animated scene's camera path.
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// Hi-Z iteration limit, at least 1 (HDRP presets: 16, 32, 64).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_steps: u32,
    /// Object thickness relative to depth, in [0, 1] (HDRP's default and range).
    #[arg(long, default_value_t = 0.01, value_parser = f32_in(0.0, 1.0))]
    pub thickness: f32,
    /// Screen-edge fade length in [0, 1] (HDRP's default and range).
    #[arg(long, default_value_t = 0.1, value_parser = f32_in(0.0, 1.0))]
    pub screen_fade: f32,
    /// Trace pixels with perceptual roughness <= 1 - min_smoothness, in [0, 1] (0.4 here, to
    /// study glossy reflections; HDRP's default is 0.9).
    #[arg(long, default_value_t = 0.4, value_parser = f32_in(0.0, 1.0))]
    pub min_smoothness: f32,
    /// The roughness fade starts at perceptual roughness 1 - smoothness_fade_start; in
    /// [--min-smoothness, 1] (0.5 here; HDRP's default is 0.9).
    #[arg(long, default_value_t = 0.5, value_parser = f32_in(0.0, 1.0))]
    pub smoothness_fade_start: f32,
    /// SSSR: tracing pixels per 2x2 quad: 4 = full resolution, 1 = half resolution (one tracing
    /// pixel per quad, the pattern rotating with the frame), 2 = checkerboard; the other pixels of
    /// the quad reuse their neighbours' rays in the resolve.
    #[arg(long, default_value_t = 4, value_parser = u32_of(&[1, 2, 4]))]
    pub rays_per_quad: u32,
    /// SSSR: rays per tracing pixel (1 to 8).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub spp: u32,
    /// SSSR: resolve each pixel from its own rays only (no neighbour reuse).
    #[arg(long)]
    pub no_reuse: bool,
    /// SSSR: frames of temporal accumulation, at least 1 (1 = none).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub temporal_frames: u32,
    /// SSSR: importance-sampling bias in [0, 1) (the VNDF's radial u is scaled by 1 - bias; 0 =
    /// unbiased).
    #[arg(long, default_value_t = 0.1, value_parser = f32_in_half_open(0.0, 1.0))]
    pub bias: f32,
    /// SSSR: perceptual roughness in [0, 1] from which rays use the 16-step linear march instead
    /// of Hi-Z (1 = Hi-Z for every ray; Stachowiak's split is about 0.2).
    #[arg(long, default_value_t = 1.0, value_parser = f32_in(0.0, 1.0))]
    pub hiz_roughness_cut: f32,
    /// SSSR: disable filtered importance sampling (colour pyramid mip from the ray cone).
    #[arg(long)]
    pub no_fis: bool,
    /// SSSR with filtered importance sampling: sample the colour pyramid per (pixel, ray) pair at
    /// the resolving pixel's cone footprint, instead of once per ray at the footprint seen from
    /// the ray's own pixel, which every pixel reusing the ray then reads (the default, as
    /// FidelityFX SSSR stores a radiance per ray): about four times the resolve's reads for
    /// reflections that differ in the last digits (docs/ssr.md "Colour per ray").
    #[arg(long, conflicts_with = "no_fis")]
    pub no_ray_color: bool,
    /// GGX visible-normal sampler of the stochastic rays (SSSR, and HDRP with --resolve 3x3 or cross5).
    #[arg(long, value_parser = crate::cli_args::named(&VndfSampler::ALL, |v| v.label()), default_value = "heitz")]
    pub sampler: VndfSampler,
    /// SSSR temporal reprojection of the history: through the virtual image of the reflected
    /// hit (falls back to the surface's motion where the pixel's rays missed or the texel is
    /// rejected), or the surface's motion vector only.
    #[arg(long, value_parser = crate::cli_args::named(&Reprojection::ALL, Reprojection::label), default_value = "hit")]
    pub reprojection: Reprojection,
    /// SSSR: disable the depth/normal history rejection (the neighbourhood clamp stays).
    #[arg(long)]
    pub no_history_rejection: bool,
    /// Reference rays per glossy pixel (built-in scenes); 0 skips the reference (no error
    /// figures, no reference images), also the one a G-buffer's JSON names.
    #[arg(long, default_value_t = 64)]
    pub reference_samples: u32,
    /// Backend: auto, cpu or gpu (see `host --help`).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// Energy tables (`host energy precompute` .bin) for the specular output's preintegrated FG
    /// term; without it the default tables, computed once and cached in the user cache
    /// directory (as `host render` does).
    #[arg(long)]
    pub lut: Option<PathBuf>,
}

/// Options that apply to one pipeline only (field names = clap ids).
const HDRP_ONLY: &[&str] = &["trace", "resolve"];
const SSSR_ONLY: &[&str] = &[
    "rays_per_quad",
    "spp",
    "no_reuse",
    "temporal_frames",
    "bias",
    "hiz_roughness_cut",
    "no_fis",
    "no_ray_color",
    "reprojection",
    "no_history_rejection",
];

impl RunArgs {
    /// Check what single options' ranges cannot: that options given on the command line
    /// (`given(id)`, id = field name) apply to the chosen pipeline, and the smoothness order.
    pub fn validate(&self, given: &dyn Fn(&str) -> bool) -> Result<()> {
        let flag = |id: &str| format!("--{}", id.replace('_', "-"));
        let (own, other, other_name) = match self.pipeline {
            PipelineChoice::Hdrp => ("hdrp", SSSR_ONLY, "sssr"),
            PipelineChoice::Sssr => ("sssr", HDRP_ONLY, "hdrp"),
        };
        if let Some(id) = other.iter().find(|id| given(id)) {
            bail!("{} applies to --pipeline {other_name} only, not to --pipeline {own}", flag(id));
        }
        if self.pipeline == PipelineChoice::Hdrp && given("sampler") && parse_resolve(&self.resolve)? == HdrpResolve::Approx {
            bail!("--sampler applies to --pipeline sssr and to --resolve 3x3 or cross5, not to --resolve approx");
        }
        if self.smoothness_fade_start < self.min_smoothness {
            bail!(
                "--smoothness-fade-start ({}) must be at least --min-smoothness ({}): the fade ends where tracing stops",
                self.smoothness_fade_start,
                self.min_smoothness
            );
        }
        parse_trace(&self.trace)?;
        Ok(())
    }

    pub fn settings(&self) -> SsrSettings {
        SsrSettings {
            thickness: self.thickness,
            screen_fade: self.screen_fade,
            min_smoothness: self.min_smoothness,
            smoothness_fade_start: self.smoothness_fade_start,
            hiz_max_iterations: self.max_steps,
            frame: self.frame,
            sampler: self.sampler,
            ..SsrSettings::default()
        }
    }

    pub fn sssr(&self) -> SssrSettings {
        SssrSettings {
            rays_per_quad: self.rays_per_quad,
            samples_per_pixel: self.spp,
            reuse: !self.no_reuse,
            temporal_frames: self.temporal_frames,
            sample_bias: self.bias,
            hiz_roughness_cut: self.hiz_roughness_cut,
            fis: !self.no_fis,
            ray_color: !self.no_ray_color,
            reprojection: self.reprojection,
            history_rejection: !self.no_history_rejection,
            ..SssrSettings::default()
        }
    }
}

/// Parse a tracer name.
pub fn parse_trace(s: &str) -> Result<TraceMode> {
    Ok(match s {
        "hiz" => TraceMode::HiZ,
        "brute" => TraceMode::BruteForce,
        _ => match s.strip_prefix("linear").and_then(|n| n.parse::<u32>().ok()) {
            Some(n) if n > 0 && n <= 4096 => TraceMode::Linear(n),
            _ => bail!("unknown tracer {s:?}: use hiz, brute or linear<N> (e.g. linear32)"),
        },
    })
}

/// Parse an HDRP resolve name.
pub fn parse_resolve(s: &str) -> Result<HdrpResolve> {
    Ok(match s {
        "approx" => HdrpResolve::Approx,
        "3x3" => HdrpResolve::Block3x3,
        "cross5" => HdrpResolve::Cross5,
        _ => bail!("unknown resolve {s:?}: use approx, 3x3 or cross5"),
    })
}

/// The largest step count a ray of this run can record: the fixed top of the step-count scale.
pub fn steps_limit(a: &RunArgs, width: usize, height: usize) -> Result<u32> {
    Ok(match a.pipeline {
        PipelineChoice::Hdrp => match parse_trace(&a.trace)? {
            TraceMode::HiZ => a.max_steps,
            TraceMode::Linear(n) => n,
            // trace::trace_brute_force's cell limit.
            TraceMode::BruteForce => 2 * (width + height) as u32 + 4,
        },
        PipelineChoice::Sssr if a.hiz_roughness_cut < 1.0 => a.max_steps.max(a.sssr().rough_linear_steps),
        PipelineChoice::Sssr => a.max_steps,
    })
}

/// The input of a run: a G-buffer and, for built-in scenes, the scene; for a G-buffer file, the
/// reference its JSON names.
pub struct Input {
    pub gbuffer: GBuffer,
    pub scene: Option<Scene>,
    pub reference: Option<Reference>,
}

pub fn load_input(a: &RunArgs) -> Result<Input> {
    if let Some(p) = &a.input {
        let gbuffer = GBuffer::load(p)?;
        let reference = match (gbuffer.reference_path(p), &gbuffer.reference) {
            (Some(rp), Some(info)) if a.reference_samples > 0 => Some(Reference::load(&rp, gbuffer.width, gbuffer.height, info.samples)?),
            _ => None,
        };
        return Ok(Input { gbuffer, scene: None, reference });
    }
    if a.width == 0 || a.height == 0 || a.width > 4096 || a.height > 4096 {
        bail!("--width/--height must be in 1..=4096");
    }
    let s = scene(&a.scene)?;
    let g = s.render_gbuffer(a.width, a.height, a.frame);
    g.validate()?;
    Ok(Input { gbuffer: g, scene: Some(s), reference: None })
}

/// Run the chosen pipeline.
pub fn run_pipeline(backend: &Backend, input: &Input, a: &RunArgs) -> Result<SsrResult> {
    let s = a.settings();
    match a.pipeline {
        PipelineChoice::Hdrp => run_hdrp(backend, &input.gbuffer, &s, parse_trace(&a.trace)?, parse_resolve(&a.resolve)?),
        PipelineChoice::Sssr => {
            let frames = a.sssr().temporal_frames.max(1);
            run_sssr(backend, input.scene.as_ref().map(|s| s as &dyn super::sssr::FrameSource), &input.gbuffer, &s, &a.sssr(), a.frame, frames)
        }
    }
}

/// One frame: [`run_pipeline`], then the specular pass (the reflection composited over the
/// sky, times FG from the energy tables `lut`). Returns the result, whose `times` end with the
/// specular pass's, and the specular term (premultiplied RGB and opacity per pixel).
pub fn run_frame(backend: &Backend, input: &Input, a: &RunArgs, lut: &[f32]) -> Result<(SsrResult, Vec<f32>)> {
    let mut result = run_pipeline(backend, input, a)?;
    let consts = super::pipeline::build_params(&input.gbuffer, &a.settings())?;
    let comp: Vec<f32> = composite(&result.reflection, input.gbuffer.fallback).chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 1.0]).collect();
    let mut r = super::pipeline::Runner::new(backend);
    let specular = r.specular(&consts, &input.gbuffer.packed(), &input.gbuffer.base_color, lut, &comp)?;
    result.times.extend(r.times);
    Ok((result, specular))
}

/// Errors of a result against a reference.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Errors {
    /// Against the on-screen reference, on pixels whose reference rays all stay on screen.
    pub onscreen: ErrorStats,
    /// Against the all-geometry reference over all glossy pixels.
    pub all: ErrorStats,
    /// Against the on-screen reference over all glossy pixels (the algorithm's own error).
    pub algorithm: ErrorStats,
}

pub fn errors(result: &SsrResult, reference: &Reference, sky: [f32; 3]) -> Errors {
    let c = composite(&result.reflection, sky);
    let on_mask: Vec<bool> =
        reference.glossy.iter().zip(&reference.onscreen_fraction).map(|(&g, &f)| g && f >= 0.999).collect();
    Errors {
        onscreen: error(&c, &reference.onscreen, &on_mask),
        all: error(&c, &reference.all, &reference.glossy),
        algorithm: error(&c, &reference.onscreen, &reference.glossy),
    }
}

/// Hit mask and step counts of the ray records (first sample per pixel).
pub fn hit_and_steps(result: &SsrResult) -> (Vec<f32>, Vec<f32>) {
    let n = result.width * result.height;
    let per = result.rays.len() / RAY_STRIDE / n.max(1);
    let mut hit = vec![0.0; n];
    let mut steps = vec![0.0; n];
    for i in 0..n {
        let mut h = 0.0;
        let mut s = 0.0;
        let mut valid = 0.0;
        for k in 0..per.max(1) {
            let b = (i * per.max(1) + k) * RAY_STRIDE;
            let bits = result.rays[b + RAY_INFO].to_bits();
            if bits & info::VALID != 0 {
                valid += 1.0;
                if bits & info::HIT != 0 {
                    h += 1.0;
                }
                s += (bits >> info::STEPS_SHIFT) as f32;
            }
        }
        hit[i] = if valid > 0.0 { h / valid } else { -1.0 };
        steps[i] = if valid > 0.0 { s / valid } else { 0.0 };
    }
    (hit, steps)
}

/// Top of the error image's scale (mean absolute RGB difference, linear radiance).
pub const ERROR_SCALE: f32 = 0.5;

/// Write the reflection EXR, previews and debug views; returns the files written.
/// `steps_limit` is the top of the step-count scale (the tracer's iteration limit, see
/// [`steps_limit`]); the debug PNGs carry a legend strip below the image.
pub fn write_outputs(out: &Path, input: &Input, result: &SsrResult, reference: Option<&Reference>, sky: [f32; 3], steps_limit: u32) -> Result<Vec<PathBuf>> {
    let (w, h) = (result.width, result.height);
    let n = w * h;
    let comp = composite(&result.reflection, sky);
    let ch = |v: &[f32], k: usize, s: usize| -> Vec<f32> { (0..n).map(|i| v[s * i + k]).collect() };
    let (hit, steps) = hit_and_steps(result);
    let mut chans: Vec<(String, Vec<f32>)> = vec![
        ("R".into(), ch(&result.reflection, 0, 4)),
        ("G".into(), ch(&result.reflection, 1, 4)),
        ("B".into(), ch(&result.reflection, 2, 4)),
        ("A".into(), ch(&result.reflection, 3, 4)),
        ("composite.R".into(), ch(&comp, 0, 3)),
        ("composite.G".into(), ch(&comp, 1, 3)),
        ("composite.B".into(), ch(&comp, 2, 3)),
        ("hit".into(), hit.clone()),
        ("steps".into(), steps.clone()),
    ];
    if let Some(r) = reference {
        for (name, img) in [("reference_all", &r.all), ("reference_onscreen", &r.onscreen)] {
            for (k, c) in ["R", "G", "B"].iter().enumerate() {
                chans.push((format!("{name}.{c}"), ch(img, k, 3)));
            }
        }
        chans.push(("reference_onscreen_fraction".into(), r.onscreen_fraction.clone()));
    }
    let refs: Vec<(&str, &[f32])> = chans.iter().map(|(a, b)| (a.as_str(), b.as_slice())).collect();
    write_exr(out, w, h, &refs)?;
    let mut files = vec![out.to_path_buf()];
    let stem = out.with_extension("");
    let p = |s: &str| PathBuf::from(format!("{}.{s}.png", stem.display()));
    write_rgb_preview_png(&p("composite"), w, h, &comp, 0.0)?;
    files.push(p("composite"));
    write_rgb_preview_png(&p("scene"), w, h, &input.gbuffer.color, 0.0)?;
    files.push(p("scene"));
    let hit_px: Vec<[u8; 3]> = hit.iter().map(|&v| if v < 0.0 { legend::NO_VALUE } else { legend::ramp(v, 0.0, 1.0) }).collect();
    let hit_legend = Legend {
        title: "hit: fraction of the pixel's rays that hit on screen".into(),
        bar: Some((0.0, 1.0, legend::ticks(0.0, 1.0, 4))),
        swatches: vec![(legend::NO_VALUE, "no ray".into())],
        axes: None,
    };
    legend::write_png(&p("hit"), w, h, &hit_px, &hit_legend)?;
    files.push(p("hit"));
    let limit = steps_limit.max(1) as f32;
    let steps_px: Vec<[u8; 3]> = steps
        .iter()
        .zip(&hit)
        .map(|(&v, &hv)| if hv < 0.0 { legend::NO_VALUE } else { legend::ramp(v, 0.0, limit) })
        .collect();
    let steps_legend = Legend {
        title: format!("steps: tracer iterations per ray (scale 0 .. the iteration limit {steps_limit})"),
        bar: Some((0.0, limit, legend::ticks(0.0, limit, 4))),
        swatches: vec![(legend::NO_VALUE, "no ray".into())],
        axes: None,
    };
    legend::write_png(&p("steps"), w, h, &steps_px, &steps_legend)?;
    files.push(p("steps"));
    if let Some(t) = &result.tiles {
        let tw = w.div_ceil(8);
        let class_colour = |c: u32| legend::ramp(c as f32, 0.0, 3.0);
        let img: Vec<[u8; 3]> = (0..n).map(|i| class_colour(t.classes[(i / w / 8) * tw + (i % w) / 8])).collect();
        let tiles_legend = Legend {
            title: "tiles: class of each 8x8 tile".into(),
            bar: None,
            swatches: vec![
                (class_colour(TILE_SKIP), "skipped".into()),
                (class_colour(TILE_HIZ), "Hi-Z".into()),
                (class_colour(TILE_LINEAR), "linear".into()),
                (class_colour(TILE_MIXED), "mixed".into()),
            ],
            axes: None,
        };
        legend::write_png(&p("tiles"), w, h, &img, &tiles_legend)?;
        files.push(p("tiles"));
    }
    if let Some(r) = reference {
        write_rgb_preview_png(&p("reference"), w, h, &r.all, 0.0)?;
        files.push(p("reference"));
        write_rgb_preview_png(&p("reference_onscreen"), w, h, &r.onscreen, 0.0)?;
        files.push(p("reference_onscreen"));
        let err: Vec<[u8; 3]> = (0..n)
            .map(|i| {
                if !r.glossy[i] {
                    return legend::NO_VALUE;
                }
                let d: f32 = (0..3).map(|k| (comp[3 * i + k] - r.onscreen[3 * i + k]).abs()).sum();
                legend::ramp(d / 3.0, 0.0, ERROR_SCALE)
            })
            .collect();
        let err_legend = Legend {
            title: "error: mean |composite - on-screen reference| over RGB (linear)".into(),
            bar: Some((0.0, ERROR_SCALE, legend::ticks(0.0, ERROR_SCALE, 5))),
            swatches: vec![(legend::NO_VALUE, "not glossy".into())],
            axes: None,
        };
        legend::write_png(&p("error"), w, h, &err, &err_legend)?;
        files.push(p("error"));
    }
    Ok(files)
}

/// The specular EXR (`<stem>.specular.exr`: RGB, and the reference integrals where one exists)
/// and its PNG preview.
fn write_specular(out: &Path, result: &SsrResult, specular: &[f32], reference: Option<&Reference>) -> Result<Vec<PathBuf>> {
    let (w, h) = (result.width, result.height);
    let n = w * h;
    let ch = |v: &[f32], k: usize, s: usize| -> Vec<f32> { (0..n).map(|i| v[s * i + k]).collect() };
    let mut chans: Vec<(String, Vec<f32>)> = ["R", "G", "B"].iter().enumerate().map(|(k, c)| (c.to_string(), ch(specular, k, 4))).collect();
    if let Some(r) = reference {
        for (name, img) in [("reference_all", &r.specular_all), ("reference_onscreen", &r.specular_onscreen)] {
            for (k, c) in ["R", "G", "B"].iter().enumerate() {
                chans.push((format!("{name}.{c}"), ch(img, k, 3)));
            }
        }
    }
    let refs: Vec<(&str, &[f32])> = chans.iter().map(|(a, b)| (a.as_str(), b.as_slice())).collect();
    let stem = out.with_extension("");
    let exr = PathBuf::from(format!("{}.specular.exr", stem.display()));
    write_exr(&exr, w, h, &refs)?;
    let png = PathBuf::from(format!("{}.specular.png", stem.display()));
    let rgb: Vec<f32> = specular.chunks_exact(4).flat_map(|c| [c[0], c[1], c[2]]).collect();
    write_rgb_preview_png(&png, w, h, &rgb, 0.0)?;
    Ok(vec![exr, png])
}

/// The lit frame: scene colour + specular (reflection x preintegrated FG), RGB per pixel. The
/// colour is the current frame's (built-in scenes render it; an EXR G-buffer's `color` is used
/// as given, the previous frame's for a moving camera).
pub fn lit_frame(colour: &[f32], specular: &[f32]) -> Vec<f32> {
    colour.chunks_exact(3).zip(specular.chunks_exact(4)).flat_map(|(c, s)| [c[0] + s[0], c[1] + s[1], c[2] + s[2]]).collect()
}

/// The lit frame EXR (`<stem>.lit.exr`: `R G B`, and `reference.R/G/B` = the same scene colour
/// plus the reference's specular integral over all geometry) and its PNGs (`.lit.png`,
/// `.lit_reference.png`).
fn write_lit(out: &Path, w: usize, h: usize, lit: &[f32], lit_reference: Option<&[f32]>) -> Result<Vec<PathBuf>> {
    let n = w * h;
    let ch = |v: &[f32], k: usize| -> Vec<f32> { (0..n).map(|i| v[3 * i + k]).collect() };
    let mut chans: Vec<(String, Vec<f32>)> = ["R", "G", "B"].iter().enumerate().map(|(k, c)| (c.to_string(), ch(lit, k))).collect();
    if let Some(r) = lit_reference {
        chans.extend(["R", "G", "B"].iter().enumerate().map(|(k, c)| (format!("reference.{c}"), ch(r, k))));
    }
    let refs: Vec<(&str, &[f32])> = chans.iter().map(|(a, b)| (a.as_str(), b.as_slice())).collect();
    let stem = out.with_extension("");
    let exr = PathBuf::from(format!("{}.lit.exr", stem.display()));
    write_exr(&exr, w, h, &refs)?;
    let png = PathBuf::from(format!("{}.lit.png", stem.display()));
    write_rgb_preview_png(&png, w, h, lit, 0.0)?;
    let mut files = vec![exr, png];
    if let Some(r) = lit_reference {
        let png = PathBuf::from(format!("{}.lit_reference.png", stem.display()));
        write_rgb_preview_png(&png, w, h, r, 0.0)?;
        files.push(png);
    }
    Ok(files)
}

/// `host ssr`.
pub fn run(a: &RunArgs, output: &Path, save_gbuffer: Option<&Path>) -> Result<()> {
    crate::io::prepare_output(output)?;
    if let Some(p) = save_gbuffer {
        crate::io::prepare_output(p)?;
    }
    let input = load_input(a)?;
    if let Some(p) = save_gbuffer {
        input.gbuffer.save(p)?;
        eprintln!("wrote G-buffer {} (+ {})", p.display(), super::gbuffer::camera_path(p).display());
    }
    let (w, h) = (input.gbuffer.width, input.gbuffer.height);
    let limit = steps_limit(a, w, h)?;
    let backend = Backend::select(a.device)?;
    eprintln!("{}", backend.describe());
    let tables = crate::energy::tables_cached(&backend, &a.lut)?;
    let (result, specular) = run_frame(&backend, &input, a, &tables.lut_buffer())?;
    let sky = input.gbuffer.fallback;
    for t in &result.times {
        eprintln!("  {:<16} {:>9.3} ms ({})", t.name, t.seconds * 1e3, t.source);
    }
    let frame_total: f64 = result.times.iter().map(|t| t.seconds).sum();
    eprintln!("  {:<16} {:>9.3} ms (sum of the {} passes above, specular included)", "frame total", frame_total * 1e3, result.times.len());
    if let Some(t) = &result.tiles {
        eprintln!(
            "  tiles: {} of {} skipped, {} rays for {} eligible pixels",
            t.skipped, t.tiles, t.rays, t.eligible_pixels
        );
    }
    let reference = match (&input.scene, &input.reference) {
        _ if a.reference_samples == 0 => {
            eprintln!("  reference: skipped (--reference-samples 0): no error figures, no reference images or channels");
            None
        }
        (Some(s), _) => {
            let t0 = std::time::Instant::now();
            let r = render_reference(s, &input.gbuffer, 1.0 - a.min_smoothness, a.reference_samples);
            eprintln!(
                "  reference: {:.3} s ({} {} per glossy pixel, f64 ray caster on the CPU, not part of the frame)",
                t0.elapsed().as_secs_f64(),
                r.samples,
                if r.samples == 1 { "ray" } else { "rays" }
            );
            Some(r)
        }
        (None, Some(r)) => {
            let info = input.gbuffer.reference.as_ref().expect("a loaded reference has its entry");
            if (info.max_roughness - (1.0 - a.min_smoothness)).abs() > 1e-6 {
                bail!(
                    "the G-buffer's reference covers perceptual roughness <= {}, this run traces <= {} (--min-smoothness {}): run with --min-smoothness {} or export the reference again with --max-roughness {}",
                    info.max_roughness,
                    1.0 - a.min_smoothness,
                    a.min_smoothness,
                    1.0 - info.max_roughness,
                    1.0 - a.min_smoothness
                );
            }
            eprintln!(
                "  reference: {} ({} samples per glossy pixel, {}{})",
                info.file,
                info.samples,
                info.method,
                info.noise_rel.map(|n| format!("; its own relative noise {n:.4}: errors are measured against it")).unwrap_or_default()
            );
            Some(r.clone())
        }
        (None, None) => {
            eprintln!("  reference: none (the G-buffer's JSON names no reference; `host render --gbuffer` writes one)");
            None
        }
    };
    if let Some(r) = &reference {
        let e = errors(&result, r, sky);
        if e.all.pixels == 0 {
            eprintln!("  error vs reference: n/a: no glossy pixels: nothing measured (see --min-smoothness, --frame)");
        } else {
            let spec_rgb: Vec<f32> = specular.chunks_exact(4).flat_map(|c| [c[0], c[1], c[2]]).collect();
            let es = error(&spec_rgb, &r.specular_onscreen, &r.glossy);
            let ea = error(&spec_rgb, &r.specular_all, &r.glossy);
            let f = |e: &ErrorStats| format!("RMSE {} rel {}", figure(e.rmse, 4), figure(e.rel, 3));
            let on_mask: Vec<bool> = r.glossy.iter().zip(&r.onscreen_fraction).map(|(&g, &f)| g && f >= 0.999).collect();
            let above = match super::reference::noise_rel(r, &on_mask) {
                Some(n) => format!(" (the reference's own noise {}: above it {})", figure(n, 3), figure(super::reference::above_noise(e.onscreen.rel, Some(n)), 3)),
                None => String::new(),
            };
            eprintln!(
                "  error vs reference: on-screen pixels ({}) {}{above}; all glossy ({}) {} (vs on-screen reference: {})",
                e.onscreen.pixels,
                f(&e.onscreen),
                e.all.pixels,
                f(&e.all),
                f(&e.algorithm)
            );
            eprintln!("  specular (x FG) vs reference integral: glossy pixels ({}) on-screen {}; all geometry {}", es.pixels, f(&es), f(&ea));
        }
    }
    // The lit frame, with the current frame's colour.
    let colour = match &input.scene {
        Some(s) if input.gbuffer.previous_camera != input.gbuffer.camera => s.render_color(w, h, &input.gbuffer.camera),
        _ => input.gbuffer.color.clone(),
    };
    let lit = lit_frame(&colour, &specular);
    let lit_reference = reference.as_ref().map(|r| {
        let spec: Vec<f32> = r.specular_all.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 0.0]).collect();
        lit_frame(&colour, &spec)
    });
    let mut files = write_outputs(output, &input, &result, reference.as_ref(), sky, limit).context("writing outputs")?;
    files.extend(write_specular(output, &result, &specular, reference.as_ref()).context("writing the specular output")?);
    files.extend(write_lit(output, w, h, &lit, lit_reference.as_deref()).context("writing the lit frame")?);
    for f in files {
        eprintln!("wrote {}", f.display());
    }
    Ok(())
}

/// `host ssr` (its benchmarks are `host bench ssr | ssr-ablate | ssr-wall | ssr-passes`).
#[derive(Clone, Debug, clap::Args)]
pub struct SsrCommand {
    #[command(flatten)]
    pub run: RunArgs,
    /// Output EXR; PNGs are written beside it.
    #[arg(long, short, default_value = "out/ssr.exr")]
    pub output: PathBuf,
    /// Also write the input G-buffer as EXR + camera JSON (the documented input format).
    #[arg(long)]
    pub save_gbuffer: Option<PathBuf>,
}

/// `host ssr ...`; `given(id)` says whether option `id` (a field name) was on the command line.
pub fn main(cmd: SsrCommand, given: &dyn Fn(&str) -> bool) -> Result<()> {
    cmd.run.validate(given)?;
    run(&cmd.run, &cmd.output, cmd.save_gbuffer.as_deref())
}
