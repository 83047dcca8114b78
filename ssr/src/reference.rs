//! The ray-traced reference: the true specular reflection of every glossy pixel, by casting rays
//! in the analytic scene (f64), split into what any ray sees ("all geometry") and what a
//! screen-space method could at best see ("on-screen geometry only": a hit counts only if its
//! point projects inside the screen and is the surface visible there; otherwise the ray sees the
//! fallback, the sky, as SSR's composite would).
//!
//! Mirror pixels (perceptual roughness 0) use the one reflected ray; glossy pixels average
//! GGX-VNDF-sampled rays (Heitz 2018; stratified) with weights G2/G1 = (1 + Lambda(v)) /
//! (1 + Lambda(v) + Lambda(l)) (height-correlated Smith, F = 1): the same normalized-BRDF average
//! HDRP's and the stochastic SSR's outputs estimate (before the FG term). The specular versions
//! are the integral itself, (1/N) sum F(v.h) G2/G1 L with Schlick's F of the glTF metal-rough f0
//! (mix(0.04, base colour, metalness), f90 = 1): what the reflection times the preintegrated FG
//! term (`shader_core::ssr::specular`) approximates.

use super::camera::V3;
use super::gbuffer::GBuffer;
use super::scene::{basis, Scene};
use rayon::prelude::*;

/// The reference for one frame.
#[derive(Clone, Debug)]
pub struct Reference {
    pub width: usize,
    pub height: usize,
    /// RGB per pixel, all geometry (pixels outside `glossy`: the sky, the fallback SSR's
    /// composite shows there too).
    pub all: Vec<f32>,
    /// RGB per pixel, on-screen geometry only.
    pub onscreen: Vec<f32>,
    /// Specular integral (with Fresnel, not normalized) per pixel: all geometry, on-screen only.
    pub specular_all: Vec<f32>,
    pub specular_onscreen: Vec<f32>,
    /// Weighted fraction of rays whose result is the same both ways (escaped, or hit visible
    /// on-screen geometry), per pixel.
    pub onscreen_fraction: Vec<f32>,
    /// Pixels the reference covers: geometry with perceptual roughness <= the cut-off.
    pub glossy: Vec<bool>,
    /// Mirror pixels: the screen position (pixels) of the reflected ray's hit when it is visible
    /// on screen; NaN otherwise (2 per pixel).
    pub mirror_hit: Vec<f32>,
    pub samples: u32,
    /// Per pixel, the estimated variance of `onscreen` (mean over RGB) where the reference is a
    /// Monte-Carlo estimate that measured it (path-traced references: from two halves of the
    /// samples); `None` for references without one.
    pub noise_var: Option<Vec<f32>>,
}

/// The reference's own relative noise over `mask`: sqrt(mean noise variance) / RMS of the
/// on-screen reference there, when the reference carries a variance estimate.
pub fn noise_rel(r: &Reference, mask: &[bool]) -> Option<f64> {
    let var = r.noise_var.as_ref()?;
    let (mut v, mut r2, mut n) = (0.0f64, 0.0f64, 0usize);
    for (i, &m) in mask.iter().enumerate() {
        if m {
            v += f64::from(var[i]);
            r2 += (0..3).map(|c| f64::from(r.onscreen[3 * i + c]).powi(2)).sum::<f64>() / 3.0;
            n += 1;
        }
    }
    (n > 0 && r2 > 0.0).then(|| (v / r2).sqrt())
}

/// A relative error with the reference's own noise taken out: sqrt(max(0, rel^2 - noise^2))
/// (squared errors add for independent noise), NaN when either is unknown.
pub fn above_noise(rel: f64, noise: Option<f64>) -> f64 {
    match noise {
        Some(n) if rel.is_finite() => (rel * rel - n * n).max(0.0).sqrt(),
        _ => f64::NAN,
    }
}

fn lambda(c: f64, alpha: f64) -> f64 {
    let c2 = (c * c).min(1.0);
    let t2 = (1.0 - c2) / c2;
    0.5 * (-1.0 + (1.0 + alpha * alpha * t2).sqrt())
}

/// Heitz 2018 VNDF sample in the local frame (v.z > 0), f64.
fn sample_vndf(v: V3, alpha: f64, u1: f64, u2: f64) -> V3 {
    let vh = V3::new(alpha * v[0], alpha * v[1], v[2]).normalize();
    let lensq = vh[0] * vh[0] + vh[1] * vh[1];
    let t1 = if lensq > 0.0 { V3::new(-vh[1], vh[0], 0.0) * (1.0 / lensq.sqrt()) } else { V3::X };
    let t2 = vh.cross(t1);
    let r = u1.sqrt();
    let phi = 2.0 * std::f64::consts::PI * u2;
    let p1 = r * phi.cos();
    let mut p2 = r * phi.sin();
    let s = 0.5 * (1.0 + vh[2]);
    p2 = (1.0 - s) * (1.0 - p1 * p1).sqrt() + s * p2;
    let pz = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    let nh = ((t1 * p1) + (t2 * p2)) + (vh * pz);
    V3::new(alpha * nh[0], alpha * nh[1], nh[2].max(0.0)).normalize()
}

fn hash64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

fn unit(x: u64) -> f64 {
    (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Render the reference for frame `frame` of `scene`, matching G-buffer `gb` (same size and
/// camera), for pixels with perceptual roughness <= `max_roughness`, with `samples` rays per
/// glossy pixel (rounded to a square for stratification).
pub fn render_reference(scene: &Scene, gb: &GBuffer, max_roughness: f32, samples: u32) -> Reference {
    let (w, h) = (gb.width, gb.height);
    let cam = gb.camera;
    let eye = cam.eye();
    let strata = (samples as f64).sqrt().round().max(1.0) as u32;
    let sky = V3::new(scene.sky[0] as f64, scene.sky[1] as f64, scene.sky[2] as f64);
    let sky_f32 = scene.sky;
    let rows: Vec<([f32; 3], [f32; 3], f32, bool, [f32; 2], [f32; 3], [f32; 3])> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let d = cam.ray_dir(w, h, x as f64 + 0.5, y as f64 + 0.5);
            // Pixels that trace no reflection (sky, rougher than the cut-off, back-facing) show
            // the fallback environment, as SSR's composite (reflection over the sky) does there;
            // their specular integral is 0, as the specular pass's FG is.
            let none = ([sky_f32[0], sky_f32[1], sky_f32[2]], [sky_f32[0], sky_f32[1], sky_f32[2]], 0.0, false, [f32::NAN; 2], [0.0; 3], [0.0; 3]);
            let Some(hit) = scene.cast(eye, d, 1e-9) else { return none };
            let m = &scene.objects[hit.object].material;
            let rough = m.roughness_at(hit.p);
            if rough > max_roughness {
                return none;
            }
            let n = hit.n;
            let v = d * -1.0;
            let nv = n.dot(v);
            if nv <= 0.0 {
                return none;
            }
            let alpha = f64::from(rough) * f64::from(rough);
            let (t, b) = basis(n);
            let vl = V3::new(v.dot(t), v.dot(b), nv);
            let origin = hit.p + (n * (1e-6));
            let mut acc_all = [0.0; 3];
            let mut acc_on = [0.0; 3];
            let mut acc_same = 0.0;
            let mut acc_w = 0.0;
            let mut mirror_hit = [f32::NAN; 2];
            let mut spec_all = [0.0; 3];
            let mut spec_on = [0.0; 3];
            let metal = f64::from(m.metalness);
            let f0: [f64; 3] = std::array::from_fn(|c| 0.04 + (m.albedo[c] - 0.04) * metal);
            let count = if rough == 0.0 { 1 } else { strata * strata };
            for k in 0..count {
                let mut vh = nv;
                let l = if rough == 0.0 {
                    (n * (2.0 * nv)) - v
                } else {
                    let hsh = hash64((i as u64) << 20 ^ k as u64);
                    let (sx, sy) = ((k % strata) as f64, (k / strata) as f64);
                    let u1 = (sx + unit(hsh)) / strata as f64;
                    let u2 = (sy + unit(hash64(hsh))) / strata as f64;
                    let m_l = sample_vndf(vl, alpha, u1, u2);
                    let m_w = ((t * m_l[0]) + (b * m_l[1])) + (n * m_l[2]);
                    vh = v.dot(m_w);
                    (m_w * (2.0 * vh)) - v
                };
                let nl = n.dot(l);
                if nl <= 0.0 {
                    continue;
                }
                let wgt = if rough == 0.0 {
                    1.0
                } else {
                    let lv = lambda(nv, alpha) + 1.0;
                    lv / (lv + lambda(nl, alpha))
                };
                let (c_all, c_on) = match scene.cast(origin, l, 1e-6) {
                    None => (sky, sky),
                    Some(rh) => {
                        let c = scene.shade(&rh);
                        let vv = cam.to_view(rh.p);
                        let mut on = false;
                        if vv[2] > f64::from(cam.near) {
                            let (px, py) = cam.view_to_screen(w, h, vv);
                            if px >= 0.0 && py >= 0.0 && px < w as f64 && py < h as f64 {
                                let to = rh.p - eye;
                                let dist = to.dot(to).sqrt();
                                if let Some(vh) = scene.cast(eye, to * (1.0 / dist), 1e-9) {
                                    on = (vh.t - dist).abs() <= 1e-6 * dist.max(1.0) * 10.0;
                                }
                                if on && rough == 0.0 {
                                    mirror_hit = [px as f32, py as f32];
                                }
                            }
                        }
                        (c, if on { c } else { sky })
                    }
                };
                let schlick = (1.0 - vh.clamp(0.0, 1.0)).powi(5);
                for k in 0..3 {
                    acc_all[k] += wgt * c_all[k];
                    acc_on[k] += wgt * c_on[k];
                    let fw = wgt * (f0[k] + (1.0 - f0[k]) * schlick);
                    spec_all[k] += fw * c_all[k];
                    spec_on[k] += fw * c_on[k];
                }
                if c_all == c_on {
                    acc_same += wgt;
                }
                acc_w += wgt;
            }
            let sp = |a: [f64; 3]| [(a[0] / count as f64) as f32, (a[1] / count as f64) as f32, (a[2] / count as f64) as f32];
            if acc_w <= 0.0 {
                return (
                    [sky[0] as f32, sky[1] as f32, sky[2] as f32],
                    [sky[0] as f32, sky[1] as f32, sky[2] as f32],
                    1.0,
                    true,
                    mirror_hit,
                    [0.0; 3],
                    [0.0; 3],
                );
            }
            let f = |a: [f64; 3]| [(a[0] / acc_w) as f32, (a[1] / acc_w) as f32, (a[2] / acc_w) as f32];
            (f(acc_all), f(acc_on), (acc_same / acc_w) as f32, true, mirror_hit, sp(spec_all), sp(spec_on))
        })
        .collect();
    let mut r = Reference {
        width: w,
        height: h,
        all: Vec::with_capacity(3 * w * h),
        onscreen: Vec::with_capacity(3 * w * h),
        specular_all: Vec::with_capacity(3 * w * h),
        specular_onscreen: Vec::with_capacity(3 * w * h),
        onscreen_fraction: Vec::with_capacity(w * h),
        glossy: Vec::with_capacity(w * h),
        mirror_hit: Vec::with_capacity(2 * w * h),
        samples: if samples <= 1 { 1 } else { strata * strata },
        noise_var: None,
    };
    for (a, o, f, g, m, sa, so) in rows {
        r.specular_all.extend_from_slice(&sa);
        r.specular_onscreen.extend_from_slice(&so);
        r.mirror_hit.extend_from_slice(&m);
        r.all.extend_from_slice(&a);
        r.onscreen.extend_from_slice(&o);
        r.onscreen_fraction.push(f);
        r.glossy.push(g);
    }
    r
}

/// EXR channels of a saved reference (interleaved RGB images split per channel).
pub const REFERENCE_CHANNELS: [&str; 14] = [
    "all.R", "all.G", "all.B", "onscreen.R", "onscreen.G", "onscreen.B", "specular_all.R", "specular_all.G", "specular_all.B",
    "specular_onscreen.R", "specular_onscreen.G", "specular_onscreen.B", "onscreen_fraction", "glossy",
];

impl Reference {
    /// Write the reference as an EXR with [`REFERENCE_CHANNELS`] (`glossy` = 1 or 0), and
    /// `noise_var` when it has one.
    pub fn save(&self, path: &std::path::Path) -> anyhow::Result<()> {
        let n = self.width * self.height;
        let ch = |v: &[f32], k: usize| -> Vec<f32> { (0..n).map(|i| v[3 * i + k]).collect() };
        let mut chans: Vec<Vec<f32>> = Vec::new();
        for img in [&self.all, &self.onscreen, &self.specular_all, &self.specular_onscreen] {
            chans.extend((0..3).map(|k| ch(img, k)));
        }
        chans.push(self.onscreen_fraction.clone());
        chans.push(self.glossy.iter().map(|&g| if g { 1.0 } else { 0.0 }).collect());
        let mut refs: Vec<(&str, &[f32])> = REFERENCE_CHANNELS.iter().zip(&chans).map(|(n, c)| (*n, c.as_slice())).collect();
        if let Some(v) = &self.noise_var {
            refs.push(("noise_var", v.as_slice()));
        }
        fileio::write_exr(path, self.width, self.height, &refs)
    }

    /// Read a reference written by [`Reference::save`] for a `width x height` G-buffer; the
    /// error names a wrong size, a missing channel or a bad value.
    pub fn load(path: &std::path::Path, width: usize, height: usize, samples: u32) -> anyhow::Result<Reference> {
        use anyhow::{bail, Context};
        let img = fileio::read_exr(path).with_context(|| format!("reading the reference {}", path.display()))?;
        if img.width != width || img.height != height {
            bail!("the reference {} is {}x{}, the G-buffer {width}x{height}", path.display(), img.width, img.height);
        }
        let n = width * height;
        let get = |name: &str| -> anyhow::Result<&[f32]> {
            let c = img.channel(name).with_context(|| format!("in the reference {}", path.display()))?;
            if let Some(i) = c.iter().position(|v| !v.is_finite() || *v < 0.0) {
                bail!("the reference {} channel {name} is {} at pixel ({}, {}): must be finite and >= 0", path.display(), c[i], i % width, i / width);
            }
            Ok(c)
        };
        let rgb = |base: &str| -> anyhow::Result<Vec<f32>> {
            let cs = [get(&format!("{base}.R"))?, get(&format!("{base}.G"))?, get(&format!("{base}.B"))?];
            Ok((0..n).flat_map(|i| cs.map(|c| c[i])).collect())
        };
        let glossy = get("glossy")?;
        if let Some(i) = glossy.iter().position(|&g| g != 0.0 && g != 1.0) {
            bail!("the reference {} channel glossy must be 0 or 1, got {} at pixel ({}, {})", path.display(), glossy[i], i % width, i / width);
        }
        Ok(Reference {
            width,
            height,
            all: rgb("all")?,
            onscreen: rgb("onscreen")?,
            specular_all: rgb("specular_all")?,
            specular_onscreen: rgb("specular_onscreen")?,
            onscreen_fraction: get("onscreen_fraction")?.to_vec(),
            glossy: glossy.iter().map(|&g| g == 1.0).collect(),
            mirror_hit: vec![f32::NAN; 2 * n],
            samples,
            noise_var: match img.channel("noise_var") {
                Ok(_) => Some(get("noise_var")?.to_vec()),
                Err(_) => None,
            },
        })
    }
}
