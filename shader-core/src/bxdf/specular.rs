//! Perfect specular reflection with a constant reflectance R (PBRT-v4 section 9.3.1):
//! f(wo, wi) = R delta(wi - wr) / |cos theta_r| with wr = (-wo.x, -wo.y, wo.z). A Dirac delta has no
//! finite density: `f` and `pdf` return 0, `sample_f` returns wr with f = R / |cos| and pdf = 1.
//! The Fresnel-weighted mirrors are the smooth branches of [`super::ConductorBxDF`] and
//! [`super::DielectricBxDF`].
//!
//! ```
//! use shader_core::bxdf::{BxDF, SpecularReflectionBxDF, MODE_RADIANCE, SAMPLE_ALL, SPECULAR_REFLECTION};
//! use shader_core::Vec3;
//! let mirror = SpecularReflectionBxDF::new(Vec3::new(0.8, 0.8, 0.8));
//! let wo = Vec3::new(0.6, 0.0, 0.8);
//! let s = mirror.sample_f(wo, 0.5, 0.5, 0.5, MODE_RADIANCE, SAMPLE_ALL);
//! assert_eq!(s.wi, Vec3::new(-0.6, 0.0, 0.8)); // the mirror direction
//! assert_eq!((s.pdf, s.flags), (1.0, SPECULAR_REFLECTION));
//! assert_eq!(mirror.pdf(wo, s.wi, MODE_RADIANCE, SAMPLE_ALL), 0.0); // a delta has no density
//! ```

use super::{is_zero, unit_or_zero, BSDFSample, BxDF, SAMPLE_REFLECTION, SPECULAR_REFLECTION};
use crate::vector::Vec3;

/// A perfect mirror with reflectance `r` (RGB; NaN/inf components -> NaN outputs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpecularReflectionBxDF {
    /// Reflectance R per RGB channel (usually in [0, 1]; not clamped).
    pub r: Vec3,
}

impl SpecularReflectionBxDF {
    /// The mirror of reflectance `r`.
    #[inline]
    pub fn new(r: Vec3) -> Self {
        SpecularReflectionBxDF { r }
    }
}

impl BxDF for SpecularReflectionBxDF {
    #[inline]
    fn flags(&self) -> u32 {
        SPECULAR_REFLECTION
    }

    /// 0: a delta lobe cannot be evaluated for an arbitrary pair (NaN for invalid R).
    #[inline]
    fn f(&self, _wo: Vec3, _wi: Vec3, _mode: u32) -> Vec3 {
        if !self.r.is_finite() {
            return super::splat(f32::NAN);
        }
        Vec3::ZERO
    }

    /// wi = (-wo.x, -wo.y, wo.z), f = R / |cos theta_i|, pdf = 1, flags = specular reflection.
    #[inline]
    fn sample_f(&self, wo: Vec3, _uc: f32, _u0: f32, _u1: f32, _mode: u32, sample_flags: u32) -> BSDFSample {
        if !self.r.is_finite() {
            return BSDFSample::INVALID_PARAMS;
        }
        let wo = unit_or_zero(wo);
        if sample_flags & SAMPLE_REFLECTION == 0 || is_zero(wo) || wo.z == 0.0 {
            return BSDFSample::NONE;
        }
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        BSDFSample::new(self.r / wi.z.abs(), wi, 1.0, SPECULAR_REFLECTION, 1.0).checked()
    }

    /// 0 (delta lobe).
    #[inline]
    fn pdf(&self, _wo: Vec3, _wi: Vec3, _mode: u32, _sample_flags: u32) -> f32 {
        if !self.r.is_finite() {
            return f32::NAN;
        }
        0.0
    }
}
