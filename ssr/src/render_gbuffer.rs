//! `host render --gbuffer`: the SSR inputs of a glTF scene (the G-buffer `host ssr --input`
//! reads, [`crate::gbuffer`]) and the path-traced reference SSR is judged against
//! (`shader_core::pt::gbuffer`), from the kernel `render::pt_gbuffer` on either backend.
//!
//! World convention: glTF is right-handed (the camera looks down its -z with x right, y up);
//! the SSR pipelines use a left-handed world (view space x right, y up, +z forward, and a
//! world-to-view rotation with determinant +1). The G-buffer therefore holds the glTF world
//! mirrored in x: normals (-x, y, z), and cameras built from the mirrored eye and axes. Depth,
//! roughness, colours, motion vectors and the reference are image quantities and unaffected.
//!
//! Camera path: with `--orbit DEG` the camera of frame k is the scene's camera turned by k DEG
//! degrees about the vertical axis (+y) through the scene's bounding-sphere centre. The
//! G-buffer is frame `--frame`; its colour buffer (the previous frame's colour) is frame
//! `--frame - 1` rendered with the same settings, and its motion vectors reproject each pixel's
//! first hit (for the sky, its direction) into that frame.

use render::RenderInputs;
use crate::camera::{mirror, Camera as SsrCamera, V3};
use crate::gbuffer::{GBuffer, ReferenceFile};
use crate::reference::Reference;
use anyhow::{bail, Context, Result};
use runner::{Backend, Launch, Timing};
use std::path::{Path, PathBuf};
use shader_core::pt::camera::Camera;
use shader_core::pt::gbuffer::GBufferParams;
use shader_core::pt::integrator::RenderParams;
use shader_core::pt::gbuffer::GBufferPixel;
use shader_kernels::render::{GBufferArgs, GBUFFER_STRIDE, PT_GBUFFER};

/// One launch: the G-buffer and reference samples `p.render.sample_base .. + p.render.spp` of
/// every pixel; `GBUFFER_STRIDE` floats per pixel.
pub fn launch(backend: &Backend, inputs: &RenderInputs<'_>, p: &GBufferParams) -> Result<(Vec<f32>, Timing)> {
    let pixels = p.render.width as usize * p.render.height as usize;
    backend.run(&PT_GBUFFER, Launch::new(GBufferArgs::new(p), &inputs.bindings()), pixels, GBUFFER_STRIDE)
}

/// The kernel's output over all launches: one record per pixel, its reference sums added over
/// launches (`GBufferPixel::add_sums`).
#[derive(Clone, Debug, PartialEq)]
pub struct GBufferSums {
    pub width: u32,
    pub height: u32,
    /// Reference samples per glossy pixel.
    pub samples: u32,
    pub pixels: Vec<GBufferPixel>,
}

impl GBufferSums {
    /// The records as the kernel's buffer holds them (`GBUFFER_STRIDE` words per pixel): what
    /// a CPU-vs-GPU comparison checks bit for bit.
    pub fn words(&self) -> Vec<f32> {
        let mut w = vec![0.0; self.pixels.len() * GBUFFER_STRIDE];
        for (i, p) in self.pixels.iter().enumerate() {
            p.store(&mut w, i * GBUFFER_STRIDE);
        }
        w
    }

    /// Add `o`'s reference sums pixel by pixel (two runs over disjoint samples).
    fn add_sums(&mut self, o: &[GBufferPixel]) {
        for (a, b) in self.pixels.iter_mut().zip(o) {
            a.add_sums(b);
        }
    }
}

/// The G-buffer and `samples` reference samples per glossy pixel in launches of at most
/// `per_pass` samples (`samples` = 0: one launch, G-buffer only); `progress(samples done)`
/// after each launch.
pub fn render_gbuffer(backend: &Backend, inputs: &RenderInputs<'_>, base: &GBufferParams, samples: u32, per_pass: u32, progress: impl FnMut(u32)) -> Result<(GBufferSums, Timing)> {
    render_gbuffer_until(backend, inputs, base, samples, per_pass, progress, || false)
}

/// [`render_gbuffer`], stopping early when `stop()` is true after a launch (the first launch
/// always runs): the sums then hold the reference samples of the launches done, and
/// [`GBufferSums::samples`] says how many.
pub fn render_gbuffer_until(backend: &Backend, inputs: &RenderInputs<'_>, base: &GBufferParams, samples: u32, per_pass: u32, mut progress: impl FnMut(u32), stop: impl Fn() -> bool) -> Result<(GBufferSums, Timing)> {
    if per_pass == 0 {
        bail!("reference samples per pass must be at least 1");
    }
    let mut sums: Option<GBufferSums> = None;
    let (done, time) = runner::in_launches(samples, per_pass, stop, |done, n| {
        let mut p = *base;
        p.render.spp = n;
        p.render.sample_base = base.render.sample_base + done;
        let (out, t) = launch(backend, inputs, &p).with_context(|| format!("G-buffer launch at reference sample {done}"))?;
        let pixels: Vec<GBufferPixel> = (0..out.len() / GBUFFER_STRIDE).map(|i| GBufferPixel::load(&out, i * GBUFFER_STRIDE)).collect();
        match &mut sums {
            None => sums = Some(GBufferSums { width: base.render.width, height: base.render.height, samples, pixels }),
            Some(s) => s.add_sums(&pixels),
        }
        progress(done + n);
        Ok(t)
    })?;
    let mut sums = sums.expect("at least one launch");
    sums.samples = done;
    Ok((sums, time))
}

/// What [`to_ssr`] needs besides the kernel output.
pub struct Frames {
    /// SSR cameras of this and the previous frame.
    pub ssr_camera: SsrCamera,
    pub ssr_previous: SsrCamera,
    /// The previous frame's colour (interleaved RGB).
    pub color: Vec<f32>,
    /// The on-screen reference's fallback radiance.
    pub fallback: [f32; 3],
}

/// The G-buffer (and, with reference samples, the reference) of the kernel output `g`.
/// `reference` names the reference entry the G-buffer's JSON will carry.
pub fn to_ssr(g: &GBufferSums, f: Frames, reference: Option<ReferenceFile>) -> Result<(GBuffer, Option<Reference>)> {
    let (w, h) = (g.width as usize, g.height as usize);
    let n = w * h;
    if f.color.len() != 3 * n {
        bail!("colour buffer has {} values for {w}x{h}", f.color.len());
    }
    let mut gb = GBuffer::empty(w, h, f.color, f.ssr_camera, f.ssr_previous, f.fallback);
    gb.reference = if g.samples > 0 { reference } else { None };
    let mut r = Reference {
        width: w,
        height: h,
        all: Vec::with_capacity(3 * n),
        onscreen: Vec::with_capacity(3 * n),
        specular_all: Vec::with_capacity(3 * n),
        specular_onscreen: Vec::with_capacity(3 * n),
        onscreen_fraction: Vec::with_capacity(n),
        glossy: Vec::with_capacity(n),
        mirror_hit: vec![f32::NAN; 2 * n],
        samples: g.samples,
        noise_var: None,
    };
    for (i, px) in g.pixels.iter().enumerate() {
        let (sx, sy) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
        let depth = px.depth;
        gb.depth.push(depth);
        let nm = mirror(V3::new(px.normal.x as f64, px.normal.y as f64, px.normal.z as f64));
        gb.normal.extend(nm.as_vec3().to_array());
        gb.roughness.push(px.roughness);
        gb.metalness.push(px.metallic);
        gb.base_color.extend_from_slice(&rgb(px.base));
        gb.motion.extend(f.ssr_camera.motion_at_depth(&f.ssr_previous, w, h, sx, sy, depth));
        let glossy = px.glossy != 0;
        gb.depth_far.as_mut().expect("allocated above").push(px.depth_far);
        let (weight, same, samples) = (px.weight, px.weight_same, px.samples);
        if !glossy || !(weight > 0.0) {
            r.all.extend_from_slice(&f.fallback);
            r.onscreen.extend_from_slice(&f.fallback);
            r.specular_all.extend_from_slice(&[0.0; 3]);
            r.specular_onscreen.extend_from_slice(&[0.0; 3]);
            r.onscreen_fraction.push(if glossy { 1.0 } else { 0.0 });
        } else {
            r.all.extend(rgb(px.all).map(|v| v / weight));
            r.onscreen.extend(rgb(px.onscreen).map(|v| v / weight));
            r.specular_all.extend(rgb(px.specular_all).map(|v| v / samples));
            r.specular_onscreen.extend(rgb(px.specular_onscreen).map(|v| v / samples));
            r.onscreen_fraction.push(same / weight);
        }
        r.glossy.push(glossy);
    }
    gb.validate().context("the exported G-buffer")?;
    Ok((gb, (g.samples > 0).then_some(r)))
}

/// Progress of a long export, told per stage (the CLI shows a bar, a benchmark nothing).
pub trait Progress {
    /// A stage of `total` samples starts.
    fn start(&mut self, what: &str, total: u32);
    /// `done` samples of the stage are done.
    fn update(&mut self, done: u32);
    /// The stage ended.
    fn finish(&mut self);
    /// The check, called between launches, that ends the export early (Ctrl-C in the CLI): the
    /// frame is then exported with the samples done. The default never stops.
    fn stop_check(&self) -> fn() -> bool {
        || false
    }
}

/// [`Progress`] that shows nothing.
pub struct Quiet;

impl Progress for Quiet {
    fn start(&mut self, _: &str, _: u32) {}
    fn update(&mut self, _: u32) {}
    fn finish(&mut self) {}
}

/// One exported frame's settings.
#[derive(Clone, Debug)]
pub struct FrameSpec {
    /// The render's parameters with this frame's camera (`spp` is ignored: see `spp`).
    pub params: RenderParams,
    /// The previous frame's camera (its colour is the G-buffer's colour buffer).
    pub previous: Camera,
    /// Colour samples per pixel of the previous frame's render, in launches of `spp_per_pass`.
    pub spp: u32,
    pub spp_per_pass: u32,
    /// Reference samples per glossy pixel (0: no reference).
    pub reference_spp: u32,
    /// Perceptual roughness cut-off of the reference.
    pub max_roughness: f32,
    /// The environment's mean radiance: the on-screen reference's fallback.
    pub fallback: [f32; 3],
    /// The SSR cameras' near plane.
    pub near: f32,
}

/// An exported frame with its costs.
pub struct Exported {
    pub gbuffer: GBuffer,
    pub reference: Option<Reference>,
    /// The G-buffer kernel's time (GPU timestamps or wall clock) and wall clock, seconds.
    pub gbuffer_time: Timing,
    pub gbuffer_wall: f64,
    /// Rays the G-buffer kernel traced.
    pub rays: f64,
    /// Seconds spent rendering the previous frame's colour (0 when `current_colour` was used).
    pub previous_seconds: f64,
}

/// Export one frame: the previous frame's colour (rendered, unless the camera did not move and
/// `current_colour`, this frame's image, is given), the G-buffer and, with reference samples,
/// the reference; `reference` names the reference entry the G-buffer's JSON will carry.
pub fn export_frame(backend: &Backend, inputs: &RenderInputs<'_>, spec: &FrameSpec, current_colour: Option<&[f32]>, reference: Option<ReferenceFile>, progress: &mut dyn Progress) -> Result<Exported> {
    let (w, h) = (spec.params.width, spec.params.height);
    let ssr_cam = SsrCamera::from_kernel(&spec.params.camera, spec.near)?;
    let ssr_prev = SsrCamera::from_kernel(&spec.previous, spec.near)?;
    let t0 = std::time::Instant::now();
    let color = match current_colour {
        Some(c) if spec.previous == spec.params.camera => {
            if c.len() != 3 * w as usize * h as usize {
                bail!("the current frame's colour has {} values, the frame {}x{} needs {}", c.len(), w, h, 3 * w as usize * h as usize);
            }
            c.to_vec()
        }
        _ => {
            let p = RenderParams { camera: spec.previous, ..spec.params };
            progress.start("previous frame", spec.spp);
            let stop = progress.stop_check();
            let r = render::render_until(backend, inputs, &p, spec.spp, spec.spp_per_pass, |acc| progress.update(acc.spp), |_| stop());
            progress.finish();
            r?.0.color
        }
    };
    let previous_seconds = if current_colour.is_some() && spec.previous == spec.params.camera { 0.0 } else { t0.elapsed().as_secs_f64() };
    let gp = GBufferParams { render: spec.params, max_roughness: spec.max_roughness, fallback: shader_core::Vec3::new(spec.fallback[0], spec.fallback[1], spec.fallback[2]) };
    let t1 = std::time::Instant::now();
    progress.start("G-buffer + reference", spec.reference_spp);
    // The reference in two halves of disjoint samples: their difference measures its noise.
    let half = spec.reference_spp / 2;
    let first = if half == 0 { spec.reference_spp } else { half };
    let stop = progress.stop_check();
    let r = render_gbuffer_until(backend, inputs, &gp, first, spec.spp_per_pass, |d| progress.update(d), stop).and_then(|(a, ta)| {
        // Stopped in the first half (or no second one): no noise estimate.
        if half == 0 || a.samples < first || stop() {
            return Ok((a, ta, (None, None)));
        }
        let second = GBufferParams { render: RenderParams { sample_base: spec.params.sample_base + half, ..gp.render }, ..gp };
        let (b, tb) = render_gbuffer_until(backend, inputs, &second, spec.reference_spp - half, spec.spp_per_pass, |d| progress.update(half + d), stop)?;
        // The noise estimate compares the two halves: only when the second one is whole.
        let noise = if b.samples == spec.reference_spp - half { (noise_floor(&a, &b), pixel_noise_var(&a, &b)) } else { (None, None) };
        let mut sum = a;
        sum.add_sums(&b.pixels);
        sum.samples += b.samples;
        Ok((sum, ta + tb, noise))
    });
    progress.finish();
    let (sums, gbuffer_time, (noise, noise_var)) = r?;
    // The samples actually taken (fewer than asked for when the export was stopped).
    let reference = reference.map(|r| ReferenceFile { noise_rel: noise, samples: sums.samples, ..r });
    let gbuffer_wall = t1.elapsed().as_secs_f64();
    let rays: f64 = sums.pixels.iter().map(|p| p.rays as f64).sum();
    let (gbuffer, mut reference) = to_ssr(&sums, Frames { ssr_camera: ssr_cam, ssr_previous: ssr_prev, color, fallback: spec.fallback }, reference)?;
    if let Some(r) = reference.as_mut() {
        r.noise_var = noise_var;
    }
    Ok(Exported { gbuffer, reference, gbuffer_time, gbuffer_wall, rays, previous_seconds })
}

/// The relative noise of a reference made of the two halves `a` and `b` (equal sample counts,
/// disjoint samples): RMS over glossy pixels and channels of (a - b) / 2, over the RMS of
/// (a + b) / 2 (each half's normalized reflection; the standard error of their mean for
/// independent halves). `None` when no pixel has reference weight.
pub fn noise_floor(a: &GBufferSums, b: &GBufferSums) -> Option<f64> {
    let (mut d2, mut r2) = (0.0f64, 0.0f64);
    for (x, y) in a.pixels.iter().zip(&b.pixels) {
        let (wa, wb) = (f64::from(x.weight), f64::from(y.weight));
        if x.glossy == 0 || !(wa > 0.0) || !(wb > 0.0) {
            continue;
        }
        for c in 0..3 {
            let (xa, yb) = (f64::from(rgb(x.all)[c]), f64::from(rgb(y.all)[c]));
            let (ra, rb) = (xa / wa, yb / wb);
            d2 += (ra - rb).powi(2) / 4.0;
            r2 += ((xa + yb) / (wa + wb)).powi(2);
        }
    }
    (r2 > 0.0).then(|| (d2 / r2).sqrt())
}

/// Per pixel, the variance of the on-screen reference (the mean of halves `a` and `b`, equal
/// sample counts, disjoint samples), estimated as ((a - b) / 2)^2 of the halves' normalized
/// on-screen reflections, averaged over RGB; 0 where either half has no weight.
pub fn pixel_noise_var(a: &GBufferSums, b: &GBufferSums) -> Option<Vec<f32>> {
    let v = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(x, y)| {
            let (wa, wb) = (f64::from(x.weight), f64::from(y.weight));
            if x.glossy == 0 || !(wa > 0.0) || !(wb > 0.0) {
                return 0.0;
            }
            let d: f64 = (0..3).map(|c| ((f64::from(rgb(x.onscreen)[c]) / wa - f64::from(rgb(y.onscreen)[c]) / wb) / 2.0).powi(2)).sum();
            (d / 3.0) as f32
        })
        .collect();
    Some(v)
}

/// A kernel vector's components.
fn rgb(v: shader_core::Vec3) -> [f32; 3] {
    [v.x, v.y, v.z]
}

/// The reference EXR beside G-buffer `path`: `<stem>.reference.exr`.
pub fn reference_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "gbuffer".into());
    path.with_file_name(format!("{stem}.reference.exr"))
}
