//! Lambertian reflection (PBRT-v4 `DiffuseBxDF`, section 9.2): f = R / pi, sampled with Malley's
//! cosine-weighted hemisphere (concentric disk), pdf = |cos theta_i| / pi.
//!
//! ```
//! use shader_core::bxdf::{BxDF, DiffuseBxDF, MODE_RADIANCE, SAMPLE_ALL};
//! use shader_core::Vec3;
//! let d = DiffuseBxDF::new(Vec3::new(1.0, 1.0, 1.0));
//! let wo = Vec3::new(0.0, 0.0, -1.0); // below the surface: the BxDF is two-sided
//! let s = d.sample_f(wo, 0.0, 0.5, 0.5, MODE_RADIANCE, SAMPLE_ALL);
//! assert_eq!(s.wi, Vec3::new(0.0, 0.0, -1.0)); // the centre of the square maps to -wo's normal
//! assert_eq!(s.pdf, core::f32::consts::FRAC_1_PI); // |cos| / pi
//! ```

use super::{is_zero, same_hemisphere, unit_or_zero, BSDFSample, BxDF, DIFFUSE_REFLECTION, SAMPLE_REFLECTION};
use crate::vector::Vec3;
use crate::warp;
use core::f32::consts::FRAC_1_PI;

/// Lambertian reflection with reflectance `r` (RGB; valid: finite components, NaN/inf -> NaN out).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DiffuseBxDF {
    /// Reflectance R per RGB channel (usually in [0, 1]; not clamped).
    pub r: Vec3,
}

impl DiffuseBxDF {
    /// The Lambertian BxDF of reflectance `r`.
    #[inline]
    pub fn new(r: Vec3) -> Self {
        DiffuseBxDF { r }
    }

    #[inline]
    fn is_valid(&self) -> bool {
        self.r.is_finite()
    }
}

impl BxDF for DiffuseBxDF {
    #[inline]
    fn flags(&self) -> u32 {
        DIFFUSE_REFLECTION
    }

    /// R / pi when `wo`, `wi` are on the same side (Lambert 1760; PBRT-v4 eq. 9.3's constant BRDF).
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3, _mode: u32) -> Vec3 {
        if !self.is_valid() {
            return super::splat(f32::NAN);
        }
        let wo = unit_or_zero(wo);
        let wi = unit_or_zero(wi);
        if !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        self.r * FRAC_1_PI
    }

    /// Cosine-weighted hemisphere on `wo`'s side (PBRT-v4 `DiffuseBxDF::Sample_f`); `uc` unused.
    #[inline]
    fn sample_f(&self, wo: Vec3, _uc: f32, u0: f32, u1: f32, _mode: u32, sample_flags: u32) -> BSDFSample {
        if !self.is_valid() {
            return BSDFSample::INVALID_PARAMS;
        }
        let wo = unit_or_zero(wo);
        if sample_flags & SAMPLE_REFLECTION == 0 || is_zero(wo) || wo.z == 0.0 {
            return BSDFSample::NONE;
        }
        let mut wi = warp::sample_cosine_hemisphere(u0, u1);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = warp::cosine_hemisphere_pdf(wi.z.abs());
        BSDFSample::new(self.r * FRAC_1_PI, wi, pdf, DIFFUSE_REFLECTION, 1.0).checked()
    }

    /// |cos theta_i| / pi on `wo`'s side, else 0.
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3, _mode: u32, sample_flags: u32) -> f32 {
        if !self.is_valid() {
            return f32::NAN;
        }
        let wo = unit_or_zero(wo);
        let wi = unit_or_zero(wi);
        if sample_flags & SAMPLE_REFLECTION == 0 || !same_hemisphere(wo, wi) {
            return 0.0;
        }
        warp::cosine_hemisphere_pdf(wi.z.abs())
    }
}
