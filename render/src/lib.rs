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
    run_pt_render(backend, inputs, RenderArgs::new(p), &[0], pixels)
}

/// One launch of samples `p.sample_base .. + p.spp` of the pixels `list` names (row-major
/// indices): `OUT_STRIDE` floats per list entry, in list order, and the time.
pub fn launch_list(backend: &Backend, inputs: &RenderInputs<'_>, p: &RenderParams, list: &[u32]) -> Result<(Vec<f32>, Timing)> {
    run_pt_render(backend, inputs, RenderArgs { pixel_list: 1, ..RenderArgs::new(p) }, list, list.len())
}

fn run_pt_render(backend: &Backend, inputs: &RenderInputs<'_>, args: RenderArgs, list: &[u32], count: usize) -> Result<(Vec<f32>, Timing)> {
    let [scene, env, lut] = inputs.bindings();
    backend.run(&PT_RENDER, Launch::new(args, &[scene, env, lut, bytemuck::cast_slice(list)]), count, OUT_STRIDE)
}

/// The running per-pixel sums of a progressive render, and the radiance sums of every second
/// launch apart (the "half buffer" of the error estimate, [`Accumulator::error_estimate`]).
/// With adaptive sampling ([`Adaptive`]) a pixel may stop: its sums and sample counts freeze
/// while the other pixels go on.
#[derive(Clone, Debug)]
pub struct Accumulator {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples accumulated so far by the pixels still sampled (the most any pixel holds).
    pub spp: u32,
    /// `OUT_STRIDE` sums per pixel.
    pub sums: Vec<f32>,
    /// Launches added so far.
    pub launches: u32,
    /// Radiance sums (RGB per pixel) of the odd-numbered launches (the second, fourth, ...).
    pub odd: Vec<f32>,
    /// Samples per pixel in `odd` (pixels still sampled).
    pub odd_spp: u32,
    /// Per pixel: `None` while it is sampled, else the (samples, odd-half samples) it stopped with.
    pub stopped: Vec<Option<(u32, u32)>>,
}

impl Accumulator {
    /// Empty sums for a `width x height` image.
    pub fn new(width: u32, height: u32) -> Accumulator {
        let n = width as usize * height as usize;
        Accumulator { width, height, spp: 0, sums: vec![0.0; n * OUT_STRIDE], launches: 0, odd: vec![0.0; n * 3], odd_spp: 0, stopped: vec![None; n] }
    }

    /// Add one launch's output of `spp` samples of every pixel.
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

    /// Add one launch's output of `spp` samples of the pixels `list` names (every pixel still
    /// sampled, in the order [`Accumulator::active`] gives).
    pub fn add_list(&mut self, out: &[f32], list: &[u32], spp: u32) {
        assert_eq!(out.len(), list.len() * OUT_STRIDE, "launch output size");
        let odd = self.launches % 2 == 1;
        for (k, &px) in list.iter().enumerate() {
            let (src, dst) = (&out[k * OUT_STRIDE..(k + 1) * OUT_STRIDE], px as usize * OUT_STRIDE);
            for (s, v) in self.sums[dst..dst + OUT_STRIDE].iter_mut().zip(src) {
                *s += *v;
            }
            if odd {
                let c = PixelSums::load(src, 0).color;
                let h = &mut self.odd[px as usize * 3..px as usize * 3 + 3];
                h[0] += c.x;
                h[1] += c.y;
                h[2] += c.z;
            }
        }
        if odd {
            self.odd_spp += spp;
        }
        self.launches += 1;
        self.spp += spp;
    }

    /// The pixels still sampled, in row-major order.
    pub fn active(&self) -> Vec<u32> {
        self.stopped.iter().enumerate().filter(|(_, s)| s.is_none()).map(|(i, _)| i as u32).collect()
    }

    /// (samples, odd-half samples) of pixel `i`.
    pub fn pixel_spp(&self, i: usize) -> (u32, u32) {
        self.stopped[i].unwrap_or((self.spp, self.odd_spp))
    }

    /// Estimated relative RMSE of the mean image so far, from its two halves (the even and the
    /// odd launches' samples of each pixel, means a and b over n_a and n_b samples): sqrt(mean
    /// (a - b)^2 n_a n_b / (n_a + n_b)^2) / mean of the image, means over pixels and RGB
    /// channels, in f64 (for independent samples the expected square of a - b is
    /// Var (1/n_a + 1/n_b), so this is the image's standard error relative to its mean; with
    /// Sobol samples, stratified across the halves, it overestimates). None before two launches,
    /// or when the image's mean is not positive and finite.
    pub fn error_estimate(&self) -> Option<f64> {
        if self.odd_spp == 0 || self.spp == self.odd_spp {
            return None;
        }
        let mut d2 = 0.0f64;
        let n = self.odd.len() as f64;
        for i in 0..self.stopped.len() {
            d2 += self.pixel_variance(i) * 3.0 / n;
        }
        let m = self.mean();
        let e = d2.sqrt() / m;
        (m > 0.0 && e.is_finite()).then_some(e)
    }

    /// Mean radiance of the image so far over pixels and RGB, in f64.
    fn mean(&self) -> f64 {
        let n = self.odd.len() as f64;
        let mut m = 0.0f64;
        for i in 0..self.stopped.len() {
            let (spp, _) = self.pixel_spp(i);
            if spp > 0 {
                let t = PixelSums::load(&self.sums, i * OUT_STRIDE).color;
                m += (t.x as f64 + t.y as f64 + t.z as f64) / spp as f64 / n;
            }
        }
        m
    }

    /// The mean over RGB of the squared standard error of pixel `i`'s mean, from its halves
    /// ((a - b)^2 n_a n_b / (n_a + n_b)^2 per channel); 0 while a half is empty.
    pub fn pixel_variance(&self, i: usize) -> f64 {
        let (n, nb) = self.pixel_spp(i);
        let na = n - nb;
        if na == 0 || nb == 0 {
            return 0.0;
        }
        let (na, nb) = (na as f64, nb as f64);
        let t = PixelSums::load(&self.sums, i * OUT_STRIDE).color;
        let h = &self.odd[i * 3..i * 3 + 3];
        let mut d2 = 0.0;
        for (t, b) in [t.x, t.y, t.z].into_iter().zip(h) {
            let (t, b) = (t as f64, *b as f64);
            d2 += ((t - b) / na - b / nb).powi(2) / 3.0;
        }
        d2 * na * nb / (na + nb).powi(2)
    }

    /// The mean image so far (each pixel's sums over its own sample count).
    pub fn image(&self) -> RenderImage {
        let n = self.width as usize * self.height as usize;
        let mut img = RenderImage {
            width: self.width,
            height: self.height,
            spp: self.spp,
            color: Vec::with_capacity(3 * n),
            albedo: Vec::with_capacity(3 * n),
            normal: Vec::with_capacity(3 * n),
            depth: Vec::with_capacity(n),
            rays: 0.0,
            pixel_spp: Vec::with_capacity(n),
        };
        for i in 0..n {
            let (spp, _) = self.pixel_spp(i);
            let inv = if spp > 0 { 1.0 / spp as f32 } else { 0.0 };
            let scaled = |v: shader_core::Vec3| [v.x * inv, v.y * inv, v.z * inv];
            let px = PixelSums::load(&self.sums, i * OUT_STRIDE);
            img.color.extend(scaled(px.color));
            img.albedo.extend(scaled(px.albedo));
            img.normal.extend(scaled(px.normal));
            img.depth.push(px.depth * inv);
            img.rays += px.rays as f64;
            img.pixel_spp.push(spp);
        }
        img
    }

    /// Adaptive sampling's rule after a launch: stop every pixel that has at least
    /// `a.min_spp` samples and whose standard error relative to the image's mean
    /// (sqrt([`Accumulator::pixel_variance`]) / mean) is at most `a.threshold`, and whose 8
    /// neighbours are all at most the threshold or stopped too (so a pixel that happened to draw
    /// two close halves next to noisy ones keeps going). Reads only the sums, so every backend
    /// stops the same pixels. Returns how many pixels it stopped.
    pub fn stop_converged(&mut self, a: &Adaptive) -> usize {
        if self.spp < a.min_spp.max(2) || self.odd_spp == 0 || self.spp == self.odd_spp {
            return 0;
        }
        let m = self.mean();
        if !(m > 0.0 && m.is_finite()) {
            return 0;
        }
        let (w, h) = (self.width as usize, self.height as usize);
        let limit = (a.threshold * m).powi(2);
        let under: Vec<bool> = (0..w * h).map(|i| self.stopped[i].is_some() || self.pixel_variance(i) <= limit).collect();
        let mut stopped = 0;
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if self.stopped[i].is_some() || !under[i] {
                    continue;
                }
                let calm = (y.saturating_sub(1)..(y + 2).min(h)).all(|yy| (x.saturating_sub(1)..(x + 2).min(w)).all(|xx| under[yy * w + xx]));
                if calm {
                    self.stopped[i] = Some((self.spp, self.odd_spp));
                    stopped += 1;
                }
            }
        }
        stopped
    }
}

/// Adaptive sampling (`host render --adaptive-threshold`): pixels stop once their own error is
/// small against the image ([`Accumulator::stop_converged`]); the launches after that render
/// only the pixels still sampled ([`launch_list`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// Largest standard error of a pixel's mean, relative to the image's mean radiance, at which
    /// it stops.
    pub threshold: f64,
    /// Samples every pixel takes before it may stop.
    pub min_spp: u32,
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
    /// Samples of each pixel (all `spp` unless adaptive sampling stopped some pixels earlier).
    pub pixel_spp: Vec<u32>,
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
pub fn render_until(backend: &Backend, inputs: &RenderInputs<'_>, base: &RenderParams, total_spp: u32, spp_per_pass: u32, progress: impl FnMut(&Accumulator), stop: impl FnMut(&Accumulator) -> bool) -> Result<(RenderImage, Timing)> {
    render_adaptive(backend, inputs, base, total_spp, spp_per_pass, None, progress, stop)
}

/// [`render_until`] with optional adaptive sampling: after each launch the pixels
/// [`Accumulator::stop_converged`] picks stop, and the next launches render the others only; the
/// render ends when `total_spp` is reached, every pixel has stopped or `stop(sums)` says so.
/// Without `adaptive` every launch renders every pixel.
pub fn render_adaptive(
    backend: &Backend,
    inputs: &RenderInputs<'_>,
    base: &RenderParams,
    total_spp: u32,
    spp_per_pass: u32,
    adaptive: Option<Adaptive>,
    mut progress: impl FnMut(&Accumulator),
    mut stop: impl FnMut(&Accumulator) -> bool,
) -> Result<(RenderImage, Timing)> {
    if total_spp == 0 || spp_per_pass == 0 {
        bail!("spp and spp per pass must be at least 1");
    }
    let mut acc = Accumulator::new(base.width, base.height);
    let done = std::cell::Cell::new(false);
    let (_, time) = runner::in_launches(total_spp, spp_per_pass, || done.get(), |first, n| {
        let p = RenderParams { spp: n, sample_base: base.sample_base + first, ..*base };
        let every = acc.stopped.iter().all(|s| s.is_none());
        let t = if every {
            let (out, t) = launch(backend, inputs, &p).with_context(|| format!("render launch at sample {first}"))?;
            acc.add(&out, n);
            t
        } else {
            let list = acc.active();
            let (out, t) = launch_list(backend, inputs, &p, &list).with_context(|| format!("render launch at sample {first} ({} pixels)", list.len()))?;
            acc.add_list(&out, &list, n);
            t
        };
        if let Some(a) = &adaptive {
            acc.stop_converged(a);
        }
        progress(&acc);
        done.set(stop(&acc) || acc.stopped.iter().all(|s| s.is_some()));
        Ok(t)
    })?;
    Ok((acc.image(), time))
}

/// Write the render as a linear EXR (R, G, B, albedo.R/G/B, normal.X/Y/Z, depth.Z; and
/// samples.Y, each pixel's sample count, when adaptive sampling stopped some pixels early).
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
    let mut chans = chans;
    if img.pixel_spp.iter().any(|&s| s != img.spp) {
        // adaptive sampling: each pixel's sample count
        chans.push(("samples.Y", img.pixel_spp.iter().map(|&s| s as f32).collect()));
    }
    let refs: Vec<(&str, &[f32])> = chans.iter().map(|(n, v)| (*n, v.as_slice())).collect();
    fileio::write_exr(path, img.width as usize, img.height as usize, &refs)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Launch output with radiance `c(pixel)` per pixel (the other sums 0).
    fn out(n: usize, c: impl Fn(usize) -> f32) -> Vec<f32> {
        let mut v = vec![0.0; n * OUT_STRIDE];
        for i in 0..n {
            v[i * OUT_STRIDE..i * OUT_STRIDE + 3].fill(c(i));
        }
        v
    }

    #[test]
    fn converged_pixels_stop_and_the_others_go_on() {
        // 8x8 pixels, 2 samples per launch. Columns 0-3 draw the same radiance in every launch
        // (no error); columns 4-7 alternate 0.5 and 1.5 per sample (large error).
        let (w, h) = (8u32, 8u32);
        let n = (w * h) as usize;
        let noisy = |i: usize| i % 8 >= 4;
        let launch_out = |k: u32| out(n, |i| if noisy(i) { 2.0 * if k.is_multiple_of(2) { 0.5 } else { 1.5 } } else { 2.0 });
        let rule = Adaptive { threshold: 0.05, min_spp: 4 };
        let mut acc = Accumulator::new(w, h);
        acc.add(&launch_out(0), 2);
        assert_eq!(acc.stop_converged(&rule), 0, "one launch: no second half yet");
        acc.add(&launch_out(1), 2);
        // 4 samples: calm pixels stop except those next to a noisy one (column 3).
        assert_eq!(acc.stop_converged(&rule), 3 * 8);
        for i in 0..n {
            let x = i % 8;
            assert_eq!(acc.stopped[i].is_some(), x < 3, "pixel {i}");
        }
        // The next launch renders only the pixels still sampled; the stopped keep their sums.
        let list = acc.active();
        assert_eq!(list.len(), 5 * 8);
        let frozen = acc.sums.clone();
        let part: Vec<f32> = list.iter().flat_map(|&p| launch_out(2)[p as usize * OUT_STRIDE..(p as usize + 1) * OUT_STRIDE].to_vec()).collect();
        acc.add_list(&part, &list, 2);
        let img = acc.image();
        for i in 0..n {
            let x = i % 8;
            assert_eq!(img.pixel_spp[i], if x < 3 { 4 } else { 6 }, "pixel {i}");
            if x < 3 {
                assert_eq!(acc.sums[i * OUT_STRIDE], frozen[i * OUT_STRIDE]);
            }
            // each pixel's mean over its own samples: 1 calm; (1 + 3 + 1) / 6 noisy
            let want = if x < 4 { 1.0 } else { 5.0 / 6.0 };
            assert!((img.color[i * 3] - want).abs() < 1e-6, "pixel {i}: {}", img.color[i * 3]);
        }
        // A threshold no pixel meets stops none; a loose one stops every pixel.
        let mut strict = Accumulator::new(w, h);
        strict.add(&launch_out(0), 2);
        strict.add(&launch_out(1), 2);
        let mut loose = strict.clone();
        assert_eq!(strict.stop_converged(&Adaptive { threshold: 1e-9, min_spp: 4 }), 3 * 8, "only the exactly calm pixels");
        assert_eq!(loose.stop_converged(&Adaptive { threshold: 10.0, min_spp: 4 }), n);
        // Below min_spp nothing stops.
        let mut early = Accumulator::new(w, h);
        early.add(&launch_out(0), 2);
        early.add(&launch_out(1), 2);
        assert_eq!(early.stop_converged(&Adaptive { threshold: 10.0, min_spp: 8 }), 0);
    }
}
