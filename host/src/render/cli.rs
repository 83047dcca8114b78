//! `host render`: options, validation, the progress bar, and the EXR / PNG / JSON outputs.

use super::environment::{self, EnvSpec};
use super::scene::Scene;
use super::gbuffer::Progress;
use super::scene::Camera;
use super::{RenderInputs, ToneMap};
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

/// The random numbers of the path samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SamplerKind {
    /// Padded Owen-scrambled Sobol (Burley 2020): each pixel's samples stratified in every 1D
    /// and 2D dimension; lower error than pcg at equal spp, best at powers of two.
    Sobol,
    /// Independent uniform numbers (one PCG32 stream per pixel sample).
    Pcg,
}

impl SamplerKind {
    /// The kernel's constant.
    pub fn id(self) -> u32 {
        match self {
            SamplerKind::Sobol => shader_core::pt::sampler::SAMPLER_SOBOL,
            SamplerKind::Pcg => shader_core::pt::sampler::SAMPLER_PCG,
        }
    }

    /// The name `--sampler` takes.
    pub fn label(self) -> &'static str {
        match self {
            SamplerKind::Sobol => "sobol",
            SamplerKind::Pcg => "pcg",
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
/// (`host render --help` shows the doc of the `Render` command in `main.rs`: limits, Ctrl-C.)
#[derive(clap::Args, Debug, Clone)]
pub struct RenderCommand {
    /// A glTF 2.0 scene (.gltf with its buffers and images, or .glb); omitted: the built-in scene.
    pub scene: Option<PathBuf>,
    /// Output: `NAME.exr` or `NAME.png`. Either way the render writes the set `NAME.exr` (linear),
    /// `NAME.png` (tone-mapped) and `NAME.json` (summary), all checked before rendering and
    /// renamed into place together once all are written; other extensions are refused.
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
    /// Camera override: the eye position x,y,z (world units). Alone, the chosen camera moves
    /// there keeping its direction.
    #[arg(long, value_parser = parse_vec3, allow_negative_numbers = true)]
    pub look_from: Option<[f32; 3]>,
    /// Camera override: the point x,y,z the camera looks at (from --look-from, else from the
    /// chosen camera's position).
    #[arg(long, value_parser = parse_vec3, allow_negative_numbers = true)]
    pub look_at: Option<[f32; 3]>,
    /// Camera override: the up direction x,y,z (default: the chosen camera's; not parallel to
    /// the view direction).
    #[arg(long, value_parser = parse_vec3, allow_negative_numbers = true)]
    pub up: Option<[f32; 3]>,
    /// Camera override: the vertical field of view in degrees, in (0, 180) (perspective cameras
    /// only).
    #[arg(long, value_parser = crate::cli_args::f32_in(1e-3, 179.9))]
    pub fov: Option<f32>,
    /// Exposure of the PNG in stops, within [-64, 64] (the EXR is never scaled).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Tone curve of the PNG: aces (Narkowicz's ACES fit), reinhard (x / (1 + x)) or clamp.
    #[arg(long, value_enum, default_value = "aces")]
    pub tonemap: ToneMap,
    /// Seed of the random numbers.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Random numbers: sobol (Owen-scrambled Sobol, stratified per pixel) or pcg (independent).
    #[arg(long, value_enum, default_value = "sobol")]
    pub sampler: SamplerKind,
    /// Estimator: mis, bsdf or light.
    #[arg(long, value_enum, default_value = "mis")]
    pub strategy: Strategy,
    /// Energy compensation of the specular lobe: turquin, kulla-conty or none.
    #[arg(long, value_parser = crate::cli_args::named(&Compensation::ALL, Compensation::label), default_value = "turquin")]
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
    /// No progress bar or progress lines.
    #[arg(long)]
    pub quiet: bool,
    /// Threads of the CPU backend (default: one per core). Refused when the GPU backend runs.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// Stop once the estimated relative RMSE of the image is at most this (after a launch, from
    /// two at least; --spp stays the most it renders). The estimate compares the even and the odd
    /// launches' samples (`render::Accumulator::error_estimate`; conservative with Sobol samples)
    /// and reads only the image's sums, so the render stops at the same sample count on every
    /// backend. Within [1e-5, 1].
    #[arg(long, value_parser = crate::cli_args::f32_in(1e-5, 1.0))]
    pub target_error: Option<f32>,
    /// Adaptive sampling: after each launch, stop sampling every pixel whose standard error
    /// (from two halves of its samples) is at most this fraction of the image's mean radiance,
    /// once it has --adaptive-min-spp samples and its 8 neighbours are under it too; the next
    /// launches render only the others. The stopped pixels are read from the image's sums, so
    /// every backend stops the same ones. Within [1e-4, 1]; off by default.
    #[arg(long, value_parser = crate::cli_args::f32_in(1e-4, 1.0))]
    pub adaptive_threshold: Option<f32>,
    /// Samples every pixel takes before adaptive sampling may stop it.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(2..=1_000_000))]
    pub adaptive_min_spp: u32,
    /// Stop after the launch that reaches this many seconds of rendering (--spp stays the most it
    /// renders). Unlike --target-error, where it stops depends on the machine's speed. Within
    /// [0.001, 31536000].
    #[arg(long, value_parser = crate::cli_args::f32_in(0.001, 31_536_000.0))]
    pub time_limit: Option<f32>,
    /// When stderr is not a terminal: seconds between progress lines (samples done, rate,
    /// time left, error estimate); 0 = a line after every launch.
    #[arg(long, default_value_t = 5.0, value_parser = crate::cli_args::f32_in(0.0, 86400.0))]
    pub progress_every: f32,
    /// Also write the SSR inputs of this view: the G-buffer EXR `host ssr --input` reads (with
    /// its camera JSON beside it) and the path-traced reference of the normalized glossy
    /// reflection (`<stem>.reference.exr`, all geometry and on-screen only). Perspective
    /// cameras only.
    #[arg(long)]
    pub gbuffer: Option<PathBuf>,
    /// With --gbuffer: reference samples per glossy pixel (each a path-traced reflected ray); 0 = no
    /// reference.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(0..=1_000_000))]
    pub reference_spp: u32,
    /// With --gbuffer: pixels with perceptual roughness <= this get reference values (match
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
    /// Write the scene this command would render as glTF 2.0 (`PATH.gltf` and its buffer
    /// `PATH.bin`) with the camera it would use (after --camera, --look-from, --look-at, --up,
    /// --fov, --orbit/--frame), and exit without rendering (-o is not written). The built-in
    /// scene only (at --detail): a SCENE file is already glTF. For renderers that read glTF
    /// (benches/peers).
    #[arg(long, value_name = "PATH.gltf")]
    pub write_scene: Option<PathBuf>,
}

/// A scene ready to render: the loaded scene, its camera, environment and tables.
pub struct Prepared {
    pub scene: Scene,
    pub camera: Camera,
    pub camera_label: String,
    pub env: environment::Environment,
    pub lut: Vec<f32>,
    pub p_env: f32,
    /// What the render supplies or changes on its own (the uniform environment of a scene
    /// without lights): printed as a notice and recorded in the JSON's `warnings`.
    pub notices: Vec<String>,
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
        if self.exposure.abs() > super::EXPOSURE_LIMIT {
            bail!(
                "--exposure {}: at most {} stops either way (2^{} scales every pixel of any image to black or white, and overflows the tone curve's arithmetic)",
                self.exposure,
                super::EXPOSURE_LIMIT,
                self.exposure
            );
        }
        self.outputs()?;
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
            sampler: self.sampler.id(),
            clamp: self.clamp,
            p_env: prep.p_env,
            camera: self.frame_camera(prep, 0)?.kernel(self.width, self.height)?,
        })
    }

    /// The camera of the rendered frame (`offset` 0) or of a frame before it (`offset` -1),
    /// on the --orbit path.
    pub fn frame_camera(&self, prep: &Prepared, offset: i32) -> Result<Camera> {
        Ok(match self.orbit {
            None => prep.camera.clone(),
            Some(deg) => {
                let k = self.frame.unwrap_or(1) as f64 + offset as f64;
                prep.camera.orbited(prep.scene.bounds.bounding_sphere().0, k * deg)
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
        let (camera, camera_label) = self.override_camera(camera, camera_label)?;
        let mut notices = Vec::new();
        let spec = match &self.env {
            Some(e) => e.clone(),
            None if !scene.has_lights() => {
                let n = "the scene has no lights: lighting it with a uniform environment of radiance 1 (--env)".to_string();
                eprintln!("notice: {n}");
                notices.push(n);
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
        if let Some(w) = overflow_risk(&scene, &env, self.spp) {
            eprintln!("warning: {w}");
            notices.push(w);
        }
        let lut = match (&self.lut, self.compensation) {
            (None, Compensation::None) => vec![0.0; shader_core::energy::LUT_HEADER],
            (lut, _) => crate::energy::tables_cached(backend, lut)?.lut_buffer(),
        };
        Ok(Prepared { scene, camera, camera_label, env, lut, p_env, notices })
    }
}

/// A finite x,y,z.
fn parse_vec3(s: &str) -> Result<[f32; 3], String> {
    let v: Vec<f32> = s.split(',').map(|p| p.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|_| format!("{s:?}: expected three numbers x,y,z"))?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([*x, *y, *z]),
        [_, _, _] => Err(format!("{s:?}: the components must be finite")),
        _ => Err(format!("{s:?}: expected three numbers x,y,z, got {}", v.len())),
    }
}

impl RenderCommand {
    /// The camera with --look-from, --look-at, --up and --fov applied, and its label.
    pub fn override_camera(&self, mut cam: Camera, label: String) -> Result<(Camera, String)> {
        let mut what = Vec::new();
        if let Some(p) = self.look_from {
            cam.position = p;
            what.push(format!("--look-from {p:?}"));
        }
        if let Some(t) = self.look_at {
            let d = [t[0] - cam.position[0], t[1] - cam.position[1], t[2] - cam.position[2]];
            if d == [0.0; 3] {
                bail!("--look-at {t:?}: the camera is at that point (give another, or --look-from)");
            }
            cam.forward = d;
            what.push(format!("--look-at {t:?}"));
        }
        if let Some(u) = self.up {
            cam.up = u;
            what.push(format!("--up {u:?}"));
        }
        if let Some(f) = self.fov {
            let super::scene::Projection::Perspective { yfov, .. } = &mut cam.projection else {
                bail!("--fov {f}: the camera ({label}) is orthographic");
            };
            *yfov = f.to_radians();
            what.push(format!("--fov {f}"));
        }
        if what.is_empty() {
            return Ok((cam, label));
        }
        // checked here, with the options named: a zero direction or an up along the view
        cam.kernel(self.width, self.height).with_context(|| format!("camera overrides {}", what.join(" ")))?;
        Ok((cam, format!("{label} with {}", what.join(" "))))
    }
}

/// Headroom below f32::MAX that a pixel's sum of samples needs: a sample's radiance is the
/// emitted radiance times BSDF / pdf ratios that can reach 1e4 and more.
const OVERFLOW_HEADROOM: f64 = 1e4;

/// A warning, before rendering, when the brightest emitter (emitted radiance, punctual intensity
/// or the environment's mean radiance) times the samples per pixel comes within [`OVERFLOW_HEADROOM`] of f32::MAX:
/// the per-pixel sums may overflow to infinity (the render then fails naming the non-finite
/// pixels).
pub fn overflow_risk(scene: &Scene, env: &environment::Environment, spp: u32) -> Option<String> {
    let mut peak = (0.0f64, String::new());
    let mut see = |v: f64, what: String| {
        if v > peak.0 {
            peak = (v, what);
        }
    };
    for m in &scene.materials {
        see(m.emissive.iter().fold(0.0f32, |a, &b| a.max(b)) as f64, format!("material '{}': emitted radiance", m.name));
    }
    for l in &scene.punctual_lights {
        see(l.intensity.iter().fold(0.0f32, |a, &b| a.max(b)) as f64, format!("light '{}': intensity", l.name));
    }
    see(env.mean_radiance.iter().fold(0.0f32, |a, &b| a.max(b)) as f64, "environment: mean radiance".to_string());
    let (v, what) = peak;
    (v * spp as f64 * OVERFLOW_HEADROOM > f32::MAX as f64).then(|| {
        format!("{what} {:e} times {spp} samples per pixel comes within {OVERFLOW_HEADROOM:e} of the largest f32 ({:e}): pixel sums may overflow to infinity", v as f32, f32::MAX)
    })
}

/// The camera `--camera` names (name or index, [`Scene::camera`]), else the scene's first, else
/// a framing.
pub fn pick_camera(scene: &Scene, want: Option<&str>) -> Result<(Camera, String)> {
    let cams = &scene.cameras;
    let label = |c: &Camera| {
        let i = cams.iter().position(|x| std::ptr::eq(x, c)).unwrap_or(0);
        format!("camera {i} {:?}", c.name)
    };
    if let Some(w) = want {
        let Some(c) = scene.camera(w) else {
            let names: Vec<String> = cams.iter().enumerate().map(|(i, c)| format!("{i} {:?}", c.name)).collect();
            bail!("--camera {w:?}: no such camera; the scene has {}", if names.is_empty() { "none".to_string() } else { names.join(", ") });
        };
        return Ok((c.clone(), label(c)));
    }
    match cams.first() {
        Some(c) => Ok((c.clone(), label(c))),
        None => Ok((Camera::framing(&scene.bounds), "framing camera (the scene has none)".into())),
    }
}

/// The files one render writes (`-o`): the linear EXR, the tone-mapped PNG, the JSON summary.
#[derive(Clone, Debug, PartialEq)]
pub struct Outputs {
    pub exr: PathBuf,
    pub png: PathBuf,
    pub json: PathBuf,
}

impl RenderCommand {
    /// The output set of `-o`: `NAME.exr` or `NAME.png` both give `NAME.{exr,png,json}`.
    pub fn outputs(&self) -> Result<Outputs> {
        let o = &self.output;
        if o.is_dir() {
            bail!("-o {}: it is a directory; give a file name (such as {})", o.display(), o.join("render.exr").display());
        }
        let ext = o.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            // the name as given for its own kind (`X.EXR` stays `X.EXR`)
            Some("exr") => Ok(Outputs { exr: o.clone(), png: o.with_extension("png"), json: o.with_extension("json") }),
            Some("png") => Ok(Outputs { exr: o.with_extension("exr"), png: o.clone(), json: o.with_extension("json") }),
            _ => bail!(
                "-o {}: give a name ending in .exr or .png; a render writes NAME.exr (linear), NAME.png (tone-mapped) and NAME.json (summary) together",
                o.display()
            ),
        }
    }

    /// Every file this command will write, checked before any work: each directory can be
    /// written to, no name is an existing directory, no two outputs share a name.
    pub fn check_outputs(&self) -> Result<Vec<PathBuf>> {
        let o = self.outputs()?;
        let mut all = vec![o.exr, o.png, o.json];
        if let Some(g) = &self.gbuffer {
            all.push(g.clone());
            all.push(crate::ssr::gbuffer::camera_path(g));
            if self.reference_spp > 0 {
                all.push(super::gbuffer::reference_path(g));
            }
        }
        for (i, p) in all.iter().enumerate() {
            if all[..i].contains(p) {
                bail!("{} would be written twice: -o and --gbuffer must name different files", p.display());
            }
            crate::io::check_output_file(p)?;
        }
        Ok(all)
    }
}

/// Ctrl-C presses seen by the render (the handler counts them; the second exits).
static INTERRUPTS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);

/// Install the Ctrl-C (SIGINT) handler: the first press asks the render to stop after the
/// launch under way, the second exits at once (status 130) without writing.
fn install_interrupt_handler() -> Result<()> {
    ctrlc::set_handler(|| {
        let n = INTERRUPTS.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1;
        if n == 1 {
            eprintln!("\ninterrupted: finishing the launch under way, then writing the samples so far (Ctrl-C again aborts without writing)");
        } else {
            eprintln!("\ninterrupted twice: aborting, nothing written");
            std::process::exit(130);
        }
    })
    .context("installing the Ctrl-C handler")
}

fn interrupted() -> bool {
    INTERRUPTS.load(std::sync::atomic::Ordering::SeqCst) > 0
}

/// Run `host render`.
pub fn main(cmd: RenderCommand) -> Result<()> {
    cmd.validate()?;
    if let Some(path) = &cmd.write_scene {
        return write_scene(&cmd, path);
    }
    let outputs = cmd.outputs()?;
    cmd.check_outputs()?;
    let t_all = Instant::now();
    if let Some(n) = cmd.threads {
        if cmd.device == DeviceChoice::Gpu {
            bail!("--threads {n}: only the CPU backend runs on threads; --device gpu was given");
        }
        rayon::ThreadPoolBuilder::new().num_threads(n as usize).build_global().context("--threads: setting up the CPU backend's threads")?;
    }
    let backend = Backend::select(cmd.device)?;
    eprintln!("{}", backend.describe());
    if let (Some(n), true) = (cmd.threads, backend.is_gpu()) {
        bail!("--threads {n}: only the CPU backend runs on threads, and --device auto picked the GPU backend (use --device cpu)");
    }
    install_interrupt_handler()?;
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
    let mut bar = Bar::new(&cmd);
    bar.start("rendering", cmd.spp);
    let mut error_estimate = None;
    let mut stop_rule = "spp";
    let adaptive = cmd.adaptive_threshold.map(|t| super::Adaptive { threshold: t as f64, min_spp: cmd.adaptive_min_spp });
    let rendered = super::render_adaptive(
        &backend,
        &inputs,
        &params,
        cmd.spp,
        cmd.spp_per_pass,
        adaptive,
        |acc| {
            error_estimate = acc.error_estimate();
            bar.error = error_estimate;
            if adaptive.is_some() {
                bar.active = Some(acc.stopped.iter().filter(|s| s.is_none()).count() as f64 / acc.stopped.len() as f64);
            }
            bar.update(acc.spp)
        },
        |acc| {
            if interrupted() {
                stop_rule = "interrupt";
            } else if cmd.target_error.is_some_and(|t| acc.error_estimate().is_some_and(|e| e <= t as f64)) {
                stop_rule = "target-error";
            } else if cmd.time_limit.is_some_and(|t| t_render.elapsed().as_secs_f64() >= t as f64) {
                stop_rule = "time-limit";
            }
            stop_rule != "spp"
        },
    );
    bar.finish();
    let (img, time) = rendered?;
    if stop_rule == "spp" && img.spp < cmd.spp {
        stop_rule = "adaptive";
        eprintln!("adaptive sampling stopped every pixel by {} of {} spp", img.spp, cmd.spp);
    }
    if adaptive.is_some() {
        let mean = img.pixel_spp.iter().map(|&n| n as f64).sum::<f64>() / img.pixel_spp.len().max(1) as f64;
        eprintln!("adaptive sampling: {mean:.1} samples per pixel on average ({} to {})", img.pixel_spp.iter().min().unwrap_or(&0), img.pixel_spp.iter().max().unwrap_or(&0));
    }
    if stop_rule == "target-error" || stop_rule == "time-limit" {
        eprintln!(
            "stopped by --{stop_rule} at {} of {} spp (estimated relative RMSE {})",
            img.spp,
            cmd.spp,
            error_estimate.map(|e| format!("{e:.4}")).unwrap_or_else(|| "not yet known".into())
        );
    }
    // a Ctrl-C after the last launch still skips the --gbuffer stage below
    let stopped = stop_rule == "interrupt" || interrupted();
    let mut warnings: Vec<String> = s.warnings.iter().chain(&prep.notices).cloned().collect();
    let wall = t_render.elapsed().as_secs_f64();
    let compile = backend.compile_seconds(&shader_kernels::render::PT_RENDER);
    let digest = img.digest();
    eprintln!(
        "rendered {}x{} at {} spp{} in {:.3} s ({}; wall {:.3} s{}): {:.3} M rays/s, {:.3} M samples/s; image digest {digest:016x}",
        cmd.width,
        cmd.height,
        img.spp,
        if stopped && img.spp < cmd.spp { format!(" (interrupted: {} of {} spp)", img.spp, cmd.spp) } else { String::new() },
        time.seconds,
        time.source,
        wall,
        compile.map(|c| format!(", of which driver compile {c:.3} s")).unwrap_or_default(),
        img.rays / wall / 1e6,
        pixels * img.spp as f64 / wall / 1e6
    );
    let nonfinite = img.color.chunks_exact(3).filter(|c| c.iter().any(|v| !v.is_finite())).count();
    if nonfinite > 0 {
        let w = format!(
            "{nonfinite} of {} pixels are not finite (NaN or infinite radiance; magenta in the PNG): the scene's radiance overflows f32 on the way to a pixel",
            img.width as usize * img.height as usize
        );
        eprintln!("error: {w}");
        warnings.push(w);
    }
    let mut set = crate::io::FileSet::new();
    let gbuffer = match &cmd.gbuffer {
        Some(_) if stopped => {
            let w = "--gbuffer: not written, the render was interrupted".to_string();
            eprintln!("notice: {w}");
            warnings.push(w);
            None
        }
        Some(path) => Some(export_gbuffer(&cmd, path, &backend, &prep, &inputs, &params, &img, &mut set)?),
        None => None,
    };
    // A Ctrl-C during the --gbuffer stage ends its launches early: the G-buffer and reference
    // are written with the samples done (its JSON says how many).
    let gbuffer_stopped = cmd.gbuffer.is_some() && !stopped && interrupted();
    if gbuffer_stopped {
        warnings.push("--gbuffer: interrupted; the reference holds the samples done (gbuffer.reference_samples)".into());
    }
    let stopped = stopped || gbuffer_stopped;
    let (png, json) = (outputs.png.clone(), outputs.json.clone());
    set.stage(&[&outputs.exr], |t| super::write_exr(t, &img))?;
    set.stage(&[&png], |t| crate::io::write_png(t, &super::preview(img.width, img.height, &img.color, cmd.exposure, cmd.tonemap)))?;
    let mut summary = serde_json::json!({
        "scene": cmd.scene.as_ref().map(|p| p.display().to_string()),
        "backend": backend.describe(),
        "width": cmd.width, "height": cmd.height, "spp": cmd.spp, "spp_per_pass": cmd.spp_per_pass,
        "samples_per_pixel": img.spp, "interrupted": stopped, "nonfinite_pixels": nonfinite, "threads": rayon::current_num_threads(),
        "max_depth": cmd.max_depth, "rr_depth": cmd.rr_depth, "seed": cmd.seed, "sampler": cmd.sampler.label(),
        "strategy": format!("{:?}", cmd.strategy).to_lowercase(), "compensation": cmd.compensation.label(),
        "clamp": cmd.clamp, "camera": prep.camera_label, "environment": prep.env.label,
        "tonemap": format!("{:?}", cmd.tonemap).to_lowercase(), "exposure": cmd.exposure,
        "triangles": s.counts.triangles, "bvh_nodes": s.counts.nodes, "lights": s.counts.lights,
        "scene_bytes": s.words.len() * 4, "bvh_build_seconds": s.build_seconds, "load_seconds": load_s,
        "render_seconds": time.seconds, "render_timing": time.source.to_string(), "render_wall_seconds": wall,
        "driver_compile_seconds": compile, "rays": img.rays, "rays_per_second": img.rays / wall,
        "digest": format!("{digest:016x}"), "warnings": warnings, "total_seconds": t_all.elapsed().as_secs_f64(),
        "orbit_degrees_per_frame": cmd.orbit, "frame": cmd.orbit.map(|_| cmd.frame.unwrap_or(1)), "gbuffer": gbuffer,
    });
    // What ended the render and the error estimate (the json! macro takes no more keys).
    summary["stopped_by"] = serde_json::json!(if stopped { "interrupt" } else { stop_rule });
    summary["target_error"] = serde_json::json!(cmd.target_error);
    summary["time_limit"] = serde_json::json!(cmd.time_limit);
    summary["error_estimate"] = serde_json::json!(error_estimate);
    let mean_spp = img.pixel_spp.iter().map(|&n| n as f64).sum::<f64>() / img.pixel_spp.len().max(1) as f64;
    summary["adaptive"] = match adaptive {
        Some(a) => serde_json::json!({
            "threshold": a.threshold, "min_spp": a.min_spp, "mean_spp": mean_spp,
            "pixels_stopped_early": img.pixel_spp.iter().filter(|&&n| n < img.spp).count(),
            "min_pixel_spp": img.pixel_spp.iter().min(), "max_pixel_spp": img.pixel_spp.iter().max(),
        }),
        None => serde_json::Value::Null,
    };
    let text = serde_json::to_string_pretty(&summary)? + "\n";
    set.stage(&[&json], |t| Ok(std::fs::write(t, &text)?))?;
    let written = set.commit()?;
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    eprintln!("wrote {}", names.join(", "));
    if nonfinite > 0 {
        bail!("{nonfinite} pixels are not finite (the files are written for inspection; the JSON's nonfinite_pixels counts them)");
    }
    if stopped {
        match gbuffer.as_ref().and_then(|g| g["reference_samples"].as_u64()).filter(|_| gbuffer_stopped) {
            Some(r) => eprintln!("interrupted: the render is whole; the reference holds {r} of {} samples per glossy pixel", cmd.reference_spp),
            None => eprintln!("interrupted: the files hold {} of {} samples per pixel", img.spp, cmd.spp),
        }
        std::process::exit(130);
    }
    Ok(())
}

/// A progress bar per stage showing samples/s ([`super::gbuffer::Progress`]); hidden with
/// `--quiet`.
struct Bar {
    quiet: bool,
    /// stderr is not a terminal: log lines every `every` seconds instead of the bar.
    lines: bool,
    every: f64,
    last_line: f64,
    total: u32,
    pixels: f64,
    what: String,
    t0: Instant,
    bar: indicatif::ProgressBar,
    /// The render's error estimate after the last launch (shown in the progress).
    error: Option<f64>,
    /// With adaptive sampling: the fraction of pixels still sampled.
    active: Option<f64>,
}

impl Bar {
    fn new(cmd: &RenderCommand) -> Bar {
        use std::io::IsTerminal;
        Bar {
            quiet: cmd.quiet,
            lines: !std::io::stderr().is_terminal(),
            every: cmd.progress_every as f64,
            last_line: 0.0,
            total: 0,
            pixels: cmd.width as f64 * cmd.height as f64,
            what: String::new(),
            t0: Instant::now(),
            bar: indicatif::ProgressBar::hidden(),
            error: None,
            active: None,
        }
    }
}

/// One progress line: `what: done/total spp (pct), rate, elapsed, time left`.
pub fn progress_line(what: &str, done: u32, total: u32, seconds: f64, pixels: f64) -> String {
    let rate = done as f64 / seconds.max(1e-9);
    let left = (total.saturating_sub(done)) as f64 / rate.max(1e-12);
    format!(
        "{what}: {done}/{total} spp ({:.1}%), {:.3} M samples/s, {seconds:.1} s elapsed, about {left:.1} s left",
        100.0 * done as f64 / total.max(1) as f64,
        rate * pixels / 1e6
    )
}

impl Bar {
    /// The error estimate and the pixels still sampled, for the progress.
    fn extra(&self) -> String {
        let mut s = self.error.map(|e| format!(", error ~{e:.4}")).unwrap_or_default();
        if let Some(a) = self.active {
            s += &format!(", {:.1}% of pixels sampled", 100.0 * a);
        }
        s
    }
}

impl super::gbuffer::Progress for Bar {
    fn stop_check(&self) -> fn() -> bool {
        interrupted
    }

    fn start(&mut self, what: &str, total: u32) {
        self.what = what.to_string();
        self.t0 = Instant::now();
        self.total = total;
        self.last_line = 0.0;
        self.bar = if self.quiet || self.lines {
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
    }
    fn update(&mut self, done: u32) {
        self.bar.set_position(done as u64);
        let dt = self.t0.elapsed().as_secs_f64();
        if self.lines && !self.quiet && done < self.total && dt - self.last_line >= self.every {
            self.last_line = dt;
            eprintln!("{}{}", progress_line(&self.what, done, self.total, dt, self.pixels), self.extra());
        }
        let error = self.extra();
        self.bar.set_message(format!("{}: {:.2} M samples/s{error}", self.what, done as f64 * self.pixels / dt.max(1e-9) / 1e6));
    }
    fn finish(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// `--gbuffer`: render the previous frame's colour (when the camera moves), the G-buffer and
/// the reference, and write them; returns the summary's `gbuffer` entry.
fn export_gbuffer(cmd: &RenderCommand, path: &Path, backend: &Backend, prep: &Prepared, inputs: &RenderInputs<'_>, params: &RenderParams, img: &super::RenderImage, set: &mut crate::io::FileSet) -> Result<serde_json::Value> {
    use super::gbuffer::{export_frame, FrameSpec};
    let (w, h) = (cmd.width, cmd.height);
    let radius = prep.scene.bounds.bounding_sphere().1;
    let spec = FrameSpec {
        params: *params,
        previous: cmd.frame_camera(prep, -1)?.kernel(w, h)?,
        spp: cmd.spp,
        spp_per_pass: cmd.spp_per_pass,
        reference_spp: cmd.reference_spp,
        max_roughness: cmd.max_roughness,
        fallback: prep.env.mean_radiance,
        near: (radius * 1e-3).max(1e-6),
    };
    let ref_path = super::gbuffer::reference_path(path);
    let info = (cmd.reference_spp > 0).then(|| crate::ssr::gbuffer::ReferenceFile {
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
        noise_rel: None,
    });
    let e = export_frame(backend, inputs, &spec, Some(&img.color), info, &mut Bar::new(cmd))?;
    let cam = crate::ssr::gbuffer::camera_path(path);
    set.stage(&[path, &cam], |t| e.gbuffer.save(t))?;
    let mut files = vec![path.display().to_string(), cam.display().to_string()];
    if let Some(r) = &e.reference {
        set.stage(&[&ref_path], |t| r.save(t))?;
        files.push(ref_path.display().to_string());
    }
    let glossy = e.reference.as_ref().map(|r| r.glossy.iter().filter(|g| **g).count()).unwrap_or(0);
    eprintln!(
        "G-buffer{}: {:.3} s ({}; wall {:.3} s, {:.3} M rays/s), {} glossy pixels{}; writes {} with the render's files",
        match e.gbuffer.reference.as_ref().and_then(|r| r.noise_rel) {
            Some(n) => format!(" + reference ({} samples per glossy pixel, relative noise {n:.4})", e.gbuffer.reference.as_ref().map_or(0, |r| r.samples)),
            None if cmd.reference_spp > 0 => format!(" + reference ({} of {} samples per glossy pixel)", e.gbuffer.reference.as_ref().map_or(0, |r| r.samples), cmd.reference_spp),
            None => String::new(),
        },
        e.gbuffer_time.seconds,
        e.gbuffer_time.source,
        e.gbuffer_wall,
        e.rays / e.gbuffer_wall.max(1e-9) / 1e6,
        glossy,
        if e.previous_seconds > 0.0 { format!("; previous frame's colour {:.3} s", e.previous_seconds) } else { String::new() },
        files.join(", ") + " (renamed into place with the render's files)"
    );
    Ok(serde_json::json!({
        "files": files, "reference_spp": cmd.reference_spp,
        "reference_samples": e.gbuffer.reference.as_ref().map(|r| r.samples).unwrap_or(0), "max_roughness": cmd.max_roughness,
        "fallback": spec.fallback, "near": spec.near, "glossy_pixels": glossy, "seconds": e.gbuffer_time.seconds, "wall_seconds": e.gbuffer_wall,
        "rays": e.rays, "previous_frame_seconds": e.previous_seconds,
        "reference_noise_rel": e.gbuffer.reference.as_ref().and_then(|r| r.noise_rel),
    }))
}

/// `--write-scene`: the built-in scene at --detail with the camera the render would use, as
/// glTF; nothing is rendered.
fn write_scene(cmd: &RenderCommand, path: &Path) -> Result<()> {
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gltf")) {
        bail!("--write-scene {}: give a name ending in .gltf (the writer writes NAME.gltf and its buffer NAME.bin)", path.display());
    }
    if let Some(s) = &cmd.scene {
        bail!("--write-scene: writes the built-in scene only; {} is already a glTF scene (omit SCENE)", s.display());
    }
    if cmd.gbuffer.is_some() {
        bail!("--write-scene: renders nothing, so --gbuffer writes nothing; give one or the other");
    }
    crate::io::check_output_file(path)?;
    crate::io::check_output_file(&path.with_extension("bin"))?;
    let scene = Scene::builtin(cmd.detail);
    let (camera, label) = pick_camera(&scene, cmd.camera.as_deref())?;
    let (camera, label) = cmd.override_camera(camera, label)?;
    // as frame_camera: the --orbit path's frame
    let camera = match cmd.orbit {
        None => camera,
        Some(deg) => camera.orbited(scene.bounds.bounding_sphere().0, cmd.frame.unwrap_or(1) as f64 * deg),
    };
    camera.kernel(cmd.width, cmd.height)?;
    if cmd.env.is_some() {
        eprintln!("notice: --env is not written (glTF has no environment); the built-in scene has its own light");
    }
    super::scene::cornell_spheres_gltf(cmd.detail, Some(&camera))?.write(path).with_context(|| format!("--write-scene {}", path.display()))?;
    eprintln!(
        "wrote {} and {}: the built-in scene (detail {}, {} triangles), {label}",
        path.display(),
        path.with_extension("bin").display(),
        cmd.detail,
        scene.counts.triangles
    );
    Ok(())
}
