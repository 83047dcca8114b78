//! `host render`: options, validation, the progress bar, and the EXR / PNG / JSON outputs.

use super::environment::{self, EnvSpec};
use super::scene::Scene;
use super::{CameraSpec, RenderInputs, ToneMap};
use crate::energy::Compensation;
use anyhow::{bail, Context, Result};
use runner::{Backend, DeviceChoice};
use shader_core::pt::integrator::{RenderParams, STRATEGY_BSDF, STRATEGY_LIGHT, STRATEGY_MIS};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Path-sampling estimator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Strategy {
    /// Light sampling and BSDF sampling combined by MIS (power heuristic).
    Mis,
    /// BSDF sampling only (punctual lights contribute nothing).
    Bsdf,
    /// Light sampling only at non-specular vertices.
    Light,
}

impl Strategy {
    /// The kernel's constant.
    pub fn id(self) -> u32 {
        match self {
            Strategy::Mis => STRATEGY_MIS,
            Strategy::Bsdf => STRATEGY_BSDF,
            Strategy::Light => STRATEGY_LIGHT,
        }
    }
}

/// Render a glTF scene (or the built-in one) with the path tracer, on the CPU or a GPU.
///
/// Without SCENE, renders the built-in Cornell box: an area light, a front row of gold metal
/// spheres and a back row of blue plastic spheres with roughness 0 to 1. Writes a linear EXR
/// (R, G, B plus albedo.*, normal.* and depth.Z first-hit AOVs, each the mean over the pixel's
/// samples), a tone-mapped PNG beside it and a JSON summary (settings, scene, times, rays/s,
/// image digest). The same seed and settings give a bit-identical image on every backend.
#[derive(clap::Args, Debug, Clone)]
pub struct RenderCommand {
    /// A glTF 2.0 scene (.gltf with its buffers and images, or .glb); omitted: the built-in scene.
    pub scene: Option<PathBuf>,
    /// Output EXR; the PNG (`.png`) and the JSON summary (`.json`) are written beside it.
    #[arg(long, short, default_value = "out/render.exr")]
    pub output: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub height: u32,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub spp: u32,
    /// Samples per pixel in one kernel launch (the progress bar moves once per launch; smaller
    /// launches keep a GPU responsive).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub spp_per_pass: u32,
    /// Longest path in bounces (1 = direct lighting only).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub max_depth: u32,
    /// Bounce from which Russian roulette may end paths (survival probability = the path
    /// throughput's largest component, at least 0.05).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub rr_depth: u32,
    /// Backend: auto, cpu or gpu (see `host --help`).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// A glTF camera by index or name (default: the scene's first camera, else a camera
    /// framing the scene from +z). The image's aspect ratio is used; yfov is kept.
    #[arg(long)]
    pub camera: Option<String>,
    /// Exposure of the PNG in stops (the EXR is never scaled).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Tone curve of the PNG: aces (Narkowicz's ACES fit), reinhard (x / (1 + x)) or clamp.
    #[arg(long, value_enum, default_value = "aces")]
    pub tonemap: ToneMap,
    /// Seed of the random numbers.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Estimator: mis, bsdf or light.
    #[arg(long, value_enum, default_value = "mis")]
    pub strategy: Strategy,
    /// Energy compensation of the specular lobe: turquin, kulla-conty or none.
    #[arg(long, value_enum, default_value = "turquin")]
    pub compensation: Compensation,
    /// Energy tables (`host energy precompute` output .bin); default: the default tables,
    /// computed once and cached in the user cache directory.
    #[arg(long)]
    pub lut: Option<PathBuf>,
    /// Environment: black, a radiance (one number or r,g,b), or an equirectangular .exr/.hdr
    /// map. Default: black, or a uniform radiance of 1 for a scene without lights.
    #[arg(long, value_parser = EnvSpec::parse)]
    pub env: Option<EnvSpec>,
    /// Multiplier of the environment's radiance.
    #[arg(long, default_value_t = 1.0)]
    pub env_scale: f32,
    /// Rotation of the environment map about +y, degrees.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub env_rotation: f32,
    /// Clamp each sample's radiance to this largest component (biased; 0 = off).
    #[arg(long, default_value_t = 0.0)]
    pub clamp: f32,
    /// Tessellation of the built-in scene's spheres (triangles grow as its square).
    #[arg(long, default_value_t = super::scene::DEFAULT_DETAIL, value_parser = clap::value_parser!(u32).range(3..=1024))]
    pub detail: u32,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Also write the SSR inputs of this view: the G-buffer EXR `host ssr --input` reads (with
    /// its camera JSON beside it) and the path-traced reference of the normalized glossy
    /// reflection (`<stem>.reference.exr`, all geometry and on-screen only). Perspective
    /// cameras only.
    #[arg(long)]
    pub gbuffer: Option<PathBuf>,
    /// --gbuffer: reference samples per glossy pixel (each a path-traced reflected ray); 0 = no
    /// reference.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(0..=1_000_000))]
    pub reference_spp: u32,
    /// --gbuffer: pixels with perceptual roughness <= this get reference values (match
    /// `host ssr --min-smoothness` = 1 - this; the default 0.6 matches its default 0.4).
    #[arg(long, default_value_t = 0.6, value_parser = crate::cli_args::f32_in(0.0, 1.0))]
    pub max_roughness: f32,
    /// Camera path: frame k's camera is the chosen one turned by k x DEG degrees about the
    /// vertical axis through the scene's centre. With --gbuffer, the colour buffer and motion
    /// vectors come from frame --frame - 1.
    #[arg(long, allow_negative_numbers = true)]
    pub orbit: Option<f64>,
    /// Frame of the --orbit camera path (default 1).
    #[arg(long, requires = "orbit", allow_negative_numbers = true)]
    pub frame: Option<i32>,
}

/// A scene ready to render: the loaded scene, its camera, environment and tables.
pub struct Prepared {
    pub scene: Scene,
    pub camera: CameraSpec,
    pub camera_label: String,
    pub env: environment::Environment,
    pub lut: Vec<f32>,
    pub p_env: f32,
}

impl RenderCommand {
    /// Check the options that clap cannot.
    pub fn validate(&self) -> Result<()> {
        if (self.width as u64) * (self.height as u64) > 1 << 26 {
            bail!("--width x --height = {} pixels; at most 2^26", self.width as u64 * self.height as u64);
        }
        if !self.exposure.is_finite() {
            bail!("--exposure {}: must be finite", self.exposure);
        }
        if !self.clamp.is_finite() || self.clamp < 0.0 {
            bail!("--clamp {}: must be finite and >= 0 (0 = off)", self.clamp);
        }
        if let Some(o) = self.orbit {
            if !o.is_finite() {
                bail!("--orbit {o}: must be a finite number of degrees per frame");
            }
        }
        if self.gbuffer.is_some() && self.width.max(self.height) > 8192 {
            bail!("--gbuffer: {}x{} is larger than the SSR pipelines take (8192 per side)", self.width, self.height);
        }
        if self.scene.is_none() && self.camera.is_some() && self.camera.as_deref() != Some("0") && self.camera.as_deref() != Some("default") {
            bail!("--camera {:?}: the built-in scene has one camera, \"default\" (index 0)", self.camera.as_deref().unwrap_or(""));
        }
        Ok(())
    }

    /// The integrator parameters of these options.
    pub fn params(&self, prep: &Prepared) -> Result<RenderParams> {
        Ok(RenderParams {
            width: self.width,
            height: self.height,
            spp: self.spp_per_pass,
            sample_base: 0,
            seed: self.seed,
            max_depth: self.max_depth,
            rr_depth: self.rr_depth,
            strategy: self.strategy.id(),
            compensation: self.compensation.id(),
            clamp: self.clamp,
            p_env: prep.p_env,
            camera: self.frame_camera(prep, 0)?.camera(self.width, self.height)?,
        })
    }

    /// The camera of the rendered frame (`offset` 0) or of a frame before it (`offset` -1),
    /// on the --orbit path.
    pub fn frame_camera(&self, prep: &Prepared, offset: i32) -> Result<CameraSpec> {
        Ok(match self.orbit {
            None => prep.camera.clone(),
            Some(deg) => {
                let k = self.frame.unwrap_or(1) as f64 + offset as f64;
                super::gbuffer::orbit(&prep.camera, prep.scene.bounds.bounding_sphere().0, k * deg)
            }
        })
    }

    /// Load the scene, pick the camera and the environment, and get the energy tables.
    pub fn prepare(&self, backend: &Backend) -> Result<Prepared> {
        let scene = match &self.scene {
            Some(p) => Scene::load(p).with_context(|| format!("loading {}", p.display()))?,
            None => Scene::builtin(self.detail),
        };
        for w in &scene.warnings {
            eprintln!("warning: {w}");
        }
        let (camera, camera_label) = pick_camera(&scene, self.camera.as_deref())?;
        let spec = match &self.env {
            Some(e) => e.clone(),
            None if !scene.has_lights() => {
                eprintln!("notice: the scene has no lights: lighting it with a uniform environment of radiance 1 (--env)");
                EnvSpec::Uniform([1.0; 3])
            }
            None => EnvSpec::Black,
        };
        let env = environment::build(&spec, self.env_scale, self.env_rotation)?;
        if env.is_black() && !scene.has_lights() {
            bail!("nothing lights the scene: it has no lights and --env is black (the image would be black)");
        }
        // Next-event estimation picks the environment or the scene's lights; with both, half
        // and half (both estimators are unbiased for any split).
        let p_env = match (env.is_black(), scene.has_lights()) {
            (true, _) => 0.0,
            (false, false) => 1.0,
            (false, true) => 0.5,
        };
        let lut = match (&self.lut, self.compensation) {
            (None, Compensation::None) => vec![0.0; shader_core::energy::LUT_HEADER],
            (lut, _) => crate::energy::tables_cached(backend, lut)?.lut_buffer(),
        };
        Ok(Prepared { scene, camera, camera_label, env, lut, p_env })
    }
}

/// The camera `--camera` names (name or index, [`Scene::camera`]), else the scene's first, else
/// a framing.
pub fn pick_camera(scene: &Scene, want: Option<&str>) -> Result<(CameraSpec, String)> {
    let cams = &scene.cameras;
    let label = |c: &super::scene::CameraDesc| {
        let i = cams.iter().position(|x| std::ptr::eq(x, c)).unwrap_or(0);
        format!("camera {i} {:?}", c.name)
    };
    if let Some(w) = want {
        let Some(c) = scene.camera(w) else {
            let names: Vec<String> = cams.iter().enumerate().map(|(i, c)| format!("{i} {:?}", c.name)).collect();
            bail!("--camera {w:?}: no such camera; the scene has {}", if names.is_empty() { "none".to_string() } else { names.join(", ") });
        };
        return Ok((CameraSpec::from_desc(c), label(c)));
    }
    match cams.first() {
        Some(c) => Ok((CameraSpec::from_desc(c), label(c))),
        None => Ok((CameraSpec::framing(&scene.bounds), "framing camera (the scene has none)".into())),
    }
}

/// The outputs beside `exr`: (PNG, JSON).
pub fn sidecars(exr: &Path) -> (PathBuf, PathBuf) {
    (exr.with_extension("png"), exr.with_extension("json"))
}

/// Run `host render`.
pub fn main(cmd: RenderCommand) -> Result<()> {
    cmd.validate()?;
    crate::io::prepare_output(&cmd.output)?;
    if let Some(g) = &cmd.gbuffer {
        crate::io::prepare_output(g)?;
    }
    let t_all = Instant::now();
    let backend = Backend::select(cmd.device)?;
    eprintln!("{}", backend.describe());
    let t_load = Instant::now();
    let prep = cmd.prepare(&backend)?;
    let load_s = t_load.elapsed().as_secs_f64();
    let s = &prep.scene;
    eprintln!(
        "scene: {} ({} triangles, {} BVH nodes built in {:.3} s, {} lights, {} textures); {}; environment: {}",
        cmd.scene.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| "built-in Cornell box".into()),
        s.counts.triangles,
        s.counts.nodes,
        s.build_seconds,
        s.counts.lights,
        s.counts.textures,
        prep.camera_label,
        prep.env.label
    );
    let params = cmd.params(&prep)?;
    let inputs = RenderInputs { scene: &s.words, env: &prep.env.words, lut: &prep.lut };
    let pixels = cmd.width as f64 * cmd.height as f64;
    let t_render = Instant::now();
    let (img, time) = progressive(&cmd, "rendering", cmd.spp, |progress| super::render(&backend, &inputs, &params, cmd.spp, cmd.spp_per_pass, progress))?;
    let wall = t_render.elapsed().as_secs_f64();
    let compile = match &backend {
        Backend::Gpu(g) => g.compile_seconds(super::ENTRY),
        Backend::Cpu => None,
    };
    let digest = img.digest();
    eprintln!(
        "rendered {}x{} at {} spp in {:.3} s ({}; wall {:.3} s{}): {:.3} M rays/s, {:.3} M samples/s; image digest {digest:016x}",
        cmd.width,
        cmd.height,
        cmd.spp,
        time.seconds,
        time.source,
        wall,
        compile.map(|c| format!(", of which driver compile {c:.3} s")).unwrap_or_default(),
        img.rays / wall / 1e6,
        pixels * cmd.spp as f64 / wall / 1e6
    );
    let gbuffer = match &cmd.gbuffer {
        Some(path) => Some(export_gbuffer(&cmd, path, &backend, &prep, &inputs, &params, &img)?),
        None => None,
    };
    super::write_exr(&cmd.output, &img)?;
    let (png, json) = sidecars(&cmd.output);
    crate::io::write_png(&png, &super::preview(img.width, img.height, &img.color, cmd.exposure, cmd.tonemap))?;
    let summary = serde_json::json!({
        "scene": cmd.scene.as_ref().map(|p| p.display().to_string()),
        "backend": backend.describe(),
        "width": cmd.width, "height": cmd.height, "spp": cmd.spp, "spp_per_pass": cmd.spp_per_pass,
        "max_depth": cmd.max_depth, "rr_depth": cmd.rr_depth, "seed": cmd.seed,
        "strategy": format!("{:?}", cmd.strategy).to_lowercase(), "compensation": cmd.compensation.label(),
        "clamp": cmd.clamp, "camera": prep.camera_label, "environment": prep.env.label,
        "tonemap": format!("{:?}", cmd.tonemap).to_lowercase(), "exposure": cmd.exposure,
        "triangles": s.counts.triangles, "bvh_nodes": s.counts.nodes, "lights": s.counts.lights,
        "scene_bytes": s.words.len() * 4, "bvh_build_seconds": s.build_seconds, "load_seconds": load_s,
        "render_seconds": time.seconds, "render_timing": time.source.to_string(), "render_wall_seconds": wall,
        "driver_compile_seconds": compile, "rays": img.rays, "rays_per_second": img.rays / wall,
        "digest": format!("{digest:016x}"), "warnings": s.warnings, "total_seconds": t_all.elapsed().as_secs_f64(),
        "orbit_degrees_per_frame": cmd.orbit, "frame": cmd.orbit.map(|_| cmd.frame.unwrap_or(1)), "gbuffer": gbuffer,
    });
    crate::io::write_file(&json, serde_json::to_string_pretty(&summary)? + "\n")?;
    eprintln!("wrote {}, {}, {}", cmd.output.display(), png.display(), json.display());
    Ok(())
}

/// Run `work` (a progressive render of `total` samples) under a progress bar named `what`,
/// showing samples/s; `work` gets the callback to call with the samples done.
fn progressive<T>(cmd: &RenderCommand, what: &str, total: u32, work: impl FnOnce(&mut dyn FnMut(u32)) -> Result<T>) -> Result<T> {
    let bar = if cmd.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        let b = indicatif::ProgressBar::new(total as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} spp, {elapsed_precise} elapsed, eta {eta}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        b.set_message(what.to_string());
        b
    };
    let pixels = cmd.width as f64 * cmd.height as f64;
    let t0 = Instant::now();
    let r = work(&mut |done| {
        bar.set_position(done as u64);
        let dt = t0.elapsed().as_secs_f64();
        bar.set_message(format!("{what}: {:.2} M samples/s", done as f64 * pixels / dt.max(1e-9) / 1e6));
    });
    bar.finish_and_clear();
    r
}

/// The reference EXR beside G-buffer `path`: `<stem>.reference.exr`.
pub fn reference_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "gbuffer".into());
    path.with_file_name(format!("{stem}.reference.exr"))
}

/// `--gbuffer`: render the previous frame's colour (when the camera moves), the G-buffer and
/// the reference, and write them; returns the summary's `gbuffer` entry.
fn export_gbuffer(
    cmd: &RenderCommand,
    path: &Path,
    backend: &Backend,
    prep: &Prepared,
    inputs: &RenderInputs<'_>,
    params: &RenderParams,
    img: &super::RenderImage,
) -> Result<serde_json::Value> {
    use super::gbuffer::{render_gbuffer, ssr_camera, to_ssr, Frames};
    use shader_core::pt::gbuffer::GBufferParams;
    let (w, h) = (cmd.width, cmd.height);
    let previous = cmd.frame_camera(prep, -1)?.camera(w, h)?;
    let radius = prep.scene.bounds.bounding_sphere().1;
    let near = (radius * 1e-3).max(1e-6);
    let ssr_cam = ssr_camera(&params.camera, near)?;
    let ssr_prev = ssr_camera(&previous, near)?;
    let t0 = Instant::now();
    let color = if previous == params.camera {
        img.color.clone()
    } else {
        let p = RenderParams { camera: previous, ..*params };
        let (prev_img, _) = progressive(cmd, "previous frame", cmd.spp, |progress| super::render(backend, inputs, &p, cmd.spp, cmd.spp_per_pass, progress))?;
        prev_img.color
    };
    let colour_s = t0.elapsed().as_secs_f64();
    let m = prep.env.mean_radiance;
    let gp = GBufferParams { render: *params, max_roughness: cmd.max_roughness, fallback: shader_core::Vec3::new(m[0], m[1], m[2]) };
    let t1 = Instant::now();
    let (sums, time) = progressive(cmd, "G-buffer + reference", cmd.reference_spp, |progress| {
        render_gbuffer(backend, inputs, &gp, cmd.reference_spp, cmd.spp_per_pass, progress)
    })?;
    let wall = t1.elapsed().as_secs_f64();
    let rays: f64 = sums.values.chunks_exact(shader_kernels::render::GBUFFER_STRIDE).map(|p| p[26] as f64).sum();
    let ref_path = reference_path(path);
    let info = crate::ssr::gbuffer::ReferenceFile {
        file: ref_path.file_name().expect("a file name").to_string_lossy().into_owned(),
        samples: cmd.reference_spp,
        max_roughness: cmd.max_roughness,
        method: format!(
            "path traced: {} strategy, max depth {}, {} compensation, seed {}; fallback = the environment's mean radiance",
            format!("{:?}", cmd.strategy).to_lowercase(),
            cmd.max_depth,
            cmd.compensation.label(),
            cmd.seed
        ),
    };
    let (gb, reference) = to_ssr(&sums, Frames { ssr_camera: ssr_cam, ssr_previous: ssr_prev, color, fallback: m }, Some(info))?;
    gb.save(path)?;
    let mut files = vec![path.display().to_string(), crate::ssr::gbuffer::camera_path(path).display().to_string()];
    if let Some(r) = &reference {
        r.save(&ref_path)?;
        files.push(ref_path.display().to_string());
    }
    let glossy = reference.as_ref().map(|r| r.glossy.iter().filter(|g| **g).count()).unwrap_or(0);
    eprintln!(
        "G-buffer{}: {:.3} s ({}; wall {:.3} s, {:.3} M rays/s), {} glossy pixels{}; wrote {}",
        if cmd.reference_spp > 0 { format!(" + reference ({} samples per glossy pixel)", cmd.reference_spp) } else { String::new() },
        time.seconds,
        time.source,
        wall,
        rays / wall.max(1e-9) / 1e6,
        glossy,
        if colour_s > 0.01 { format!("; previous frame's colour {colour_s:.3} s") } else { String::new() },
        files.join(", ")
    );
    Ok(serde_json::json!({
        "files": files, "reference_spp": cmd.reference_spp, "max_roughness": cmd.max_roughness,
        "fallback": m, "near": near, "glossy_pixels": glossy, "seconds": time.seconds, "wall_seconds": wall,
        "rays": rays, "previous_frame_seconds": colour_s,
    }))
}
