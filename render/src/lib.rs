//! The path tracer of `shader_core::pt` on glTF scenes (`host render` is its command line), on
//! the CPU backend or a Vulkan GPU, with the same per-pixel kernel function
//! (`shader_kernels::render::pixel`) on both.
//!
//! A render is a sequence of launches of `--spp-per-pass` samples each; every launch returns the
//! per-pixel sums of its samples and [`Accumulator`] adds them in launch order, so the image
//! depends only on the scene, the settings and the seed (and is bit-identical between backends).

//!
//! ```
//! use shader_core::pt::integrator::{RenderParams, STRATEGY_MIS};
//! // the built-in Cornell box at 16x16, 2 samples per pixel, on the CPU backend
//! let scene = scene::Scene::builtin(scene::DEFAULT_DETAIL);
//! let camera = scene.camera("0").unwrap().kernel(16, 16)?;
//! let env = scene::environment::build(&scene::environment::EnvSpec::Black, 1.0, 0.0)?;
//! let lut = vec![0.0; shader_core::energy::LUT_HEADER]; // no energy compensation
//! let compensation = shader_core::energy::COMP_NONE;
//! let params = RenderParams { width: 16, height: 16, spp: 1, sample_base: 0, seed: 1, max_depth: 4, rr_depth: 3, strategy: STRATEGY_MIS, compensation, sampler: shader_core::pt::sampler::SAMPLER_PCG, clamp: 0.0, p_env: 0.0, camera };
//! let inputs = render::RenderInputs { scene: &scene.words, env: &env.words, lut: &lut };
//! let (img, _timing) = render::render(&runner::Backend::Cpu, &inputs, &params, 2, 1, |_done| {})?;
//! assert!(img.color.iter().all(|v| v.is_finite()) && img.color.iter().any(|&v| v > 0.0));
//! # Ok::<(), anyhow::Error>(())
//! ```

use anyhow::{bail, Context, Result};
use runner::{Backend, Launch, Timing};
use shader_core::pt::integrator::{PixelSums, RenderParams};
use shader_kernels::render::{RenderArgs, OUT_STRIDE, PT_RENDER};

/// Everything a launch binds besides its parameters.
pub struct RenderInputs<'a> {
    /// Scene words (`shader_core::pt::scene`).
    pub scene: &'a [u32],
    /// Environment buffer (`shader_core::pt::environment`).
    pub env: &'a [f32],
    /// Energy LUT (`shader_core::energy`).
    pub lut: &'a [f32],
}

impl RenderInputs<'_> {
    /// The kernels' bindings after their argument record: scene, environment, LUT.
    pub fn bindings(&self) -> [&[u8]; 3] {
        [bytemuck::cast_slice(self.scene), bytemuck::cast_slice(self.env), bytemuck::cast_slice(self.lut)]
    }
}

/// One launch: samples `p.sample_base .. + p.spp` of every pixel. Returns `OUT_STRIDE` floats
/// per pixel and the time.
pub fn launch(backend: &Backend, inputs: &RenderInputs<'_>, p: &RenderParams) -> Result<(Vec<f32>, Timing)> {
    let pixels = p.width as usize * p.height as usize;
    backend.run(&PT_RENDER, Launch::new(RenderArgs::new(p), &inputs.bindings()), pixels, OUT_STRIDE)
}

/// The running per-pixel sums of a progressive render, and the radiance sums of every second
/// launch apart (the "half buffer" of the error estimate, [`Accumulator::error_estimate`]).
#[derive(Clone, Debug)]
pub struct Accumulator {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples accumulated so far.
    pub spp: u32,
    /// `OUT_STRIDE` sums per pixel.
    pub sums: Vec<f32>,
    /// Launches added so far.
    pub launches: u32,
    /// Radiance sums (RGB per pixel) of the odd-numbered launches (the second, fourth, ...).
    pub odd: Vec<f32>,
    /// Samples per pixel in `odd`.
    pub odd_spp: u32,
}

impl Accumulator {
    /// Empty sums for a `width x height` image.
    pub fn new(width: u32, height: u32) -> Accumulator {
        let n = width as usize * height as usize;
        Accumulator { width, height, spp: 0, sums: vec![0.0; n * OUT_STRIDE], launches: 0, odd: vec![0.0; n * 3], odd_spp: 0 }
    }

    /// Add one launch's output of `spp` samples.
    pub fn add(&mut self, out: &[f32], spp: u32) {
        assert_eq!(out.len(), self.sums.len(), "launch output size");
        for (s, v) in self.sums.iter_mut().zip(out) {
            *s += *v;
        }
        if self.launches % 2 == 1 {
            for (i, h) in self.odd.chunks_exact_mut(3).enumerate() {
                let c = PixelSums::load(out, i * OUT_STRIDE).color;
                h[0] += c.x;
                h[1] += c.y;
                h[2] += c.z;
            }
            self.odd_spp += spp;
        }
        self.launches += 1;
        self.spp += spp;
    }

    /// Estimated relative RMSE of the mean image so far, from its two halves (the even and the
    /// odd launches' samples, means a and b over n_a and n_b samples): sqrt(mean (a - b)^2
    /// n_a n_b / (n_a + n_b)^2) / mean of the image, means over pixels and RGB channels, in f64
    /// (for independent samples the expected square of a - b is Var (1/n_a + 1/n_b), so this is
    /// the image's standard error relative to its mean; with Sobol samples, stratified across the
    /// halves, it overestimates). None before two launches, or when the image's mean is not
    /// positive and finite.
    pub fn error_estimate(&self) -> Option<f64> {
        let (na, nb) = ((self.spp - self.odd_spp) as f64, self.odd_spp as f64);
        if na == 0.0 || nb == 0.0 {
            return None;
        }
        let (mut d2, mut m) = (0.0f64, 0.0f64);
        let n = self.odd.len() as f64;
        for (i, h) in self.odd.chunks_exact(3).enumerate() {
            let all = PixelSums::load(&self.sums, i * OUT_STRIDE).color;
            for (t, b) in [all.x, all.y, all.z].into_iter().zip(h) {
                let (t, b) = (t as f64, *b as f64);
                d2 += ((t - b) / na - b / nb).powi(2) / n;
                m += t / (na + nb) / n;
            }
        }
        let e = (d2 * na * nb).sqrt() / (na + nb) / m;
        (m > 0.0 && e.is_finite()).then_some(e)
    }

    /// The mean image so far.
    pub fn image(&self) -> RenderImage {
        let n = self.width as usize * self.height as usize;
        let inv = if self.spp > 0 { 1.0 / self.spp as f32 } else { 0.0 };
        let mut img = RenderImage {
            width: self.width,
            height: self.height,
            spp: self.spp,
            color: Vec::with_capacity(3 * n),
            albedo: Vec::with_capacity(3 * n),
            normal: Vec::with_capacity(3 * n),
            depth: Vec::with_capacity(n),
            rays: 0.0,
        };
        let scaled = |v: shader_core::Vec3| [v.x * inv, v.y * inv, v.z * inv];
        for i in 0..n {
            let px = PixelSums::load(&self.sums, i * OUT_STRIDE);
            img.color.extend(scaled(px.color));
            img.albedo.extend(scaled(px.albedo));
            img.normal.extend(scaled(px.normal));
            img.depth.push(px.depth * inv);
            img.rays += px.rays as f64;
        }
        img
    }
}

/// A rendered image: the mean over its samples of radiance and the first-hit AOVs
/// (interleaved RGB / XYZ, top row first).
#[derive(Clone, Debug, PartialEq)]
pub struct RenderImage {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    /// Linear radiance.
    pub color: Vec<f32>,
    /// First-hit base colour.
    pub albedo: Vec<f32>,
    /// First-hit world shading normal.
    pub normal: Vec<f32>,
    /// First-hit depth along the camera's forward axis (0 where no sample hit).
    pub depth: Vec<f32>,
    /// Rays traced (closest-hit + shadow).
    pub rays: f64,
}

impl RenderImage {
    /// FNV-1a 64 of every value's bits (colour, then the AOVs): equal digests mean identical
    /// images.
    pub fn digest(&self) -> u64 {
        digest(self.color.iter().chain(&self.albedo).chain(&self.normal).chain(&self.depth))
    }
}

/// FNV-1a 64 over the bits of `values`.
pub fn digest<'a>(values: impl IntoIterator<Item = &'a f32>) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for v in values {
        for b in v.to_bits().to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// Render `total_spp` samples per pixel in launches of at most `spp_per_pass`, calling
/// `progress(samples done)` after each launch. Returns the image and the summed launch time.
pub fn render(backend: &Backend, inputs: &RenderInputs<'_>, base: &RenderParams, total_spp: u32, spp_per_pass: u32, mut progress: impl FnMut(u32)) -> Result<(RenderImage, Timing)> {
    render_until(backend, inputs, base, total_spp, spp_per_pass, |acc| progress(acc.spp), |_| false)
}

/// [`render`], with `progress` given the sums after each launch and stopping early when
/// `stop(sums)` is true after a launch (at least one launch runs, so the image holds samples):
/// the image then holds the samples of the launches done ([`RenderImage::spp`] of them in every
/// pixel). A stop rule that reads only the sums (e.g. [`Accumulator::error_estimate`] against a
/// target) stops at the same launch on every backend.
pub fn render_until(backend: &Backend, inputs: &RenderInputs<'_>, base: &RenderParams, total_spp: u32, spp_per_pass: u32, mut progress: impl FnMut(&Accumulator), mut stop: impl FnMut(&Accumulator) -> bool) -> Result<(RenderImage, Timing)> {
    if total_spp == 0 || spp_per_pass == 0 {
        bail!("spp and spp per pass must be at least 1");
    }
    let mut acc = Accumulator::new(base.width, base.height);
    let done = std::cell::Cell::new(false);
    let (_, time) = runner::in_launches(total_spp, spp_per_pass, || done.get(), |first, n| {
        let p = RenderParams { spp: n, sample_base: base.sample_base + first, ..*base };
        let (out, t) = launch(backend, inputs, &p).with_context(|| format!("render launch at sample {first}"))?;
        acc.add(&out, n);
        progress(&acc);
        done.set(stop(&acc));
        Ok(t)
    })?;
    Ok((acc.image(), time))
}

/// Write the render as a linear EXR (R, G, B, albedo.R/G/B, normal.X/Y/Z, depth.Z).
pub fn write_exr(path: &std::path::Path, img: &RenderImage) -> Result<()> {
    let n = img.width as usize * img.height as usize;
    let ch = |v: &[f32], k: usize, s: usize| -> Vec<f32> { (0..n).map(|i| v[s * i + k]).collect() };
    let chans: Vec<(&str, Vec<f32>)> = vec![
        ("R", ch(&img.color, 0, 3)),
        ("G", ch(&img.color, 1, 3)),
        ("B", ch(&img.color, 2, 3)),
        ("albedo.R", ch(&img.albedo, 0, 3)),
        ("albedo.G", ch(&img.albedo, 1, 3)),
        ("albedo.B", ch(&img.albedo, 2, 3)),
        ("normal.X", ch(&img.normal, 0, 3)),
        ("normal.Y", ch(&img.normal, 1, 3)),
        ("normal.Z", ch(&img.normal, 2, 3)),
        ("depth.Z", img.depth.clone()),
    ];
    let refs: Vec<(&str, &[f32])> = chans.iter().map(|(n, v)| (*n, v.as_slice())).collect();
    fileio::write_exr(path, img.width as usize, img.height as usize, &refs)
}
