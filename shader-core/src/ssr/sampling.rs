//! Reflection rays of a G-buffer pixel: the mirror direction, or a GGX visible-normal sample
//! with Stachowiak 2015's importance-sampling bias, and the sampler's density.

use crate::frame::orthonormal_basis;
use crate::fresnel::reflect;
use crate::rng;
use crate::vector::Vec3;
use crate::vndf;
use super::compare::clampf;
use super::layout::Surface;
use super::params::{SsrParams, SAMPLER_BOUNDED, SAMPLER_CAPS};

/// Perceptual roughness below which a pixel is a mirror: one deterministic ray, traced at every
/// pixel (never reused across pixels: its lobe is a Dirac).
pub const MIRROR_ROUGHNESS: f32 = 0.03;

/// One GGX reflection sample of `shader_core::vndf` in the local frame (normal +z, `wi` towards
/// the eye) by the sampler `sampler` (`SAMPLER_*`), with Stachowiak 2015's importance-sampling
/// bias: the u that maps to the lobe's radial/height coordinate is scaled into [0, keep)
/// (Heitz 2018 listing 1: u1, disk radius r = sqrt(u1); Dupuy & Benyoub 2023 and Eto & Tokuyoshi
/// 2023: u2, cap height z = (1 - u2)(1 + b) - b, z = 1 kept). At normal incidence both equal the
/// NDF sampler's u in tan^2(theta_m) = alpha^2 u / (1 - u) (Walter et al. 2007 eq. 35), the
/// coordinate Stachowiak truncates. The pdf is the untruncated sampler's (the truncated density is
/// pdf / keep on its support, a factor the ratio estimator cancels).
#[inline]
pub fn sample_reflection(sampler: u32, wi: Vec3, alpha: f32, u1: f32, u2: f32, keep: f32) -> vndf::ReflectionSample {
    if sampler == SAMPLER_CAPS {
        vndf::sample_vndf_caps(wi, alpha, alpha, u1, u2 * keep)
    } else if sampler == SAMPLER_BOUNDED {
        vndf::sample_vndf_bounded(wi, alpha, alpha, u1, u2 * keep)
    } else {
        vndf::sample_vndf_heitz(wi, alpha, alpha, u1 * keep, u2)
    }
}

/// Solid-angle density of the untruncated sampler `sampler` at the local reflection `wo`
/// (`shader_core::vndf::pdf_vndf_heitz` / `pdf_vndf_caps` / `pdf_vndf_bounded`; Heitz 2018 eq. 2
/// and Eto & Tokuyoshi 2023 eq. 8 times the reflection Jacobian 1 / (4 wi.wm)).
#[inline]
pub fn reflection_pdf(sampler: u32, wi: Vec3, wo: Vec3, alpha: f32) -> f32 {
    if sampler == SAMPLER_CAPS {
        vndf::pdf_vndf_caps(wi, wo, alpha, alpha)
    } else if sampler == SAMPLER_BOUNDED {
        vndf::pdf_vndf_bounded(wi, wo, alpha, alpha)
    } else {
        vndf::pdf_vndf_heitz(wi, wo, alpha, alpha)
    }
}

/// The ray of sample `smp` of pixel (x, y): mirror for mirror pixels (pdf 0 marks a Dirac),
/// otherwise a GGX reflection from the parameters' visible-normal sampler ([`sample_reflection`],
/// u1, u2 from PCG32) with the importance-sampling bias `sample_bias`; directions below the
/// surface are resampled (up to 4 tries). Returns (direction, pdf).
pub fn sample_ray(p: &SsrParams, s: &Surface, x: u32, y: u32, smp: u32) -> (Vec3, f32) {
    if s.perceptual_roughness < MIRROR_ROUGHNESS {
        return (reflect(s.v, s.n), 0.0);
    }
    let alpha = s.perceptual_roughness * s.perceptual_roughness;
    let seed = rng::pcg_hash((y * p.width + x) ^ rng::pcg_hash(p.frame * 16 + smp));
    let mut r = rng::Pcg32::new(seed, smp);
    let (t, b) = orthonormal_basis(s.n);
    let vl = Vec3::new(s.v.dot(t), s.v.dot(b), s.v.dot(s.n));
    let keep = 1.0 - clampf(p.sample_bias, 0.0, 0.999);
    let mut tries = 0;
    let mut l = reflect(s.v, s.n);
    let mut pdf = 0.0;
    while tries < 4 {
        let u1 = r.next_f32();
        let u2 = r.next_f32();
        let rs = sample_reflection(p.sampler, vl, alpha, u1, u2, keep);
        if rs.wo.z > 0.0 && rs.pdf > 0.0 && rs.pdf < f32::INFINITY {
            l = t * rs.wo.x + b * rs.wo.y + s.n * rs.wo.z;
            pdf = rs.pdf;
            break;
        }
        tries += 1;
    }
    (l, pdf)
}
