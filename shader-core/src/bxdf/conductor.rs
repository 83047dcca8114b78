//! Rough conductor: the Torrance-Sparrow BRDF (Torrance & Sparrow 1967; PBRT-v4 eq. 9.33,
//! `ConductorBxDF`) f = D(wm) F(wo.wm) G(wo, wi) / (4 |cos theta_o| |cos theta_i|) with anisotropic
//! GGX D, height-correlated Smith G and the complex Fresnel equations per RGB channel; sampled by
//! visible normals (pdf = D_wo(wm) / (4 |wo.wm|), PBRT-v4 eq. 9.36). Effectively smooth alpha
//! gives the Fresnel-weighted perfect mirror.
//!
//! ```
//! use shader_core::bxdf::{BxDF, ConductorBxDF, TrowbridgeReitz, MODE_RADIANCE, GLOSSY_REFLECTION};
//! use shader_core::Vec3;
//! // Gold-like complex IOR per RGB channel, GGX alpha 0.3.
//! let gold = ConductorBxDF::new(TrowbridgeReitz::new(0.3, 0.3), Vec3::new(0.18, 0.42, 1.37), Vec3::new(3.42, 2.35, 1.77));
//! assert!(gold.is_valid());
//! assert_eq!(gold.flags(), GLOSSY_REFLECTION);
//! let (wo, wi) = (Vec3::new(0.3, 0.1, 0.9), Vec3::new(-0.5, 0.2, 0.7));
//! let f = gold.f(wo, wi, MODE_RADIANCE);
//! assert!(f.x > 0.0 && f.y > 0.0 && f.z > 0.0);
//! // Reciprocal to the bit.
//! assert_eq!(f, gold.f(wi, wo, MODE_RADIANCE));
//! // eta = k = 0 in a channel is invalid: NaN.
//! let bad = ConductorBxDF::new(TrowbridgeReitz::new(0.3, 0.3), Vec3::ZERO, Vec3::ZERO);
//! assert!(bad.f(wo, wi, MODE_RADIANCE).x.is_nan());
//! ```

use crate::ieee;
use super::microfacet::TrowbridgeReitz;
use super::{
    face_forward, is_zero, same_hemisphere, splat, unit_or_zero, BSDFSample, BxDF, GLOSSY_REFLECTION,
    REFLECTION, GLOSSY, SAMPLE_REFLECTION, SPECULAR, SPECULAR_REFLECTION,
};
use crate::fresnel;
use crate::vector::Vec3;

/// Conductor with complex IOR `eta + i k` per RGB channel and GGX roughness.
/// Valid: alpha as [`TrowbridgeReitz::is_valid`]; eta, k finite, >= 0, not both 0 per channel
/// (as [`fresnel::conductor`]); anything else -> NaN outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ConductorBxDF {
    /// The GGX microfacet distribution (roughness alpha_x, alpha_y).
    pub distrib: TrowbridgeReitz,
    /// Real part of the relative complex IOR per RGB channel (>= 0).
    pub eta: Vec3,
    /// Extinction coefficient (imaginary part of the IOR) per RGB channel (>= 0).
    pub k: Vec3,
}

#[inline]
fn channel_valid(eta: f32, k: f32) -> bool {
    eta >= 0.0 && eta < f32::INFINITY && k >= 0.0 && k < f32::INFINITY && !(eta == 0.0 && k == 0.0)
}

impl ConductorBxDF {
    /// The conductor with these parameters, stored as given (check with [`ConductorBxDF::is_valid`]).
    #[inline]
    pub fn new(distrib: TrowbridgeReitz, eta: Vec3, k: Vec3) -> Self {
        ConductorBxDF { distrib, eta, k }
    }

    /// True when the roughness and every channel's (eta, k) are valid (see the type's documentation).
    #[inline]
    pub fn is_valid(&self) -> bool {
        self.distrib.is_valid()
            && channel_valid(self.eta.x, self.k.x)
            && channel_valid(self.eta.y, self.k.y)
            && channel_valid(self.eta.z, self.k.z)
    }

    /// The Torrance-Sparrow value for unit `wo`, `wi` on the same side and microfacet normal
    /// `wm` (wm.z > 0): F(|wo.wm|) D(wm) G(wo, wi) / (4 |cos_i| |cos_o|).
    #[inline]
    fn torrance_sparrow(&self, wo: Vec3, wi: Vec3, wm: Vec3) -> Vec3 {
        let cos_o = wo.z.abs();
        let cos_i = wi.z.abs();
        let fr = fresnel::conductor_rgb(super::half_vector_cos(wo, wi, wm).abs(), self.eta, self.k);
        let s = ieee::div(self.distrib.d(wm) * self.distrib.g(wo, wi), 4.0 * (cos_i * cos_o));
        fr * s
    }
}

impl BxDF for ConductorBxDF {
    #[inline]
    fn flags(&self) -> u32 {
        if self.distrib.effectively_smooth() {
            REFLECTION | SPECULAR
        } else {
            REFLECTION | GLOSSY
        }
    }

    /// PBRT-v4 `ConductorBxDF::f`: 0 unless same hemisphere; 0 when effectively smooth;
    /// wm = normalize(wo + wi) (face-forwarded to +z).
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3, _mode: u32) -> Vec3 {
        if !self.is_valid() {
            return splat(f32::NAN);
        }
        let wo = unit_or_zero(wo);
        let wi = unit_or_zero(wi);
        if !same_hemisphere(wo, wi) || self.distrib.effectively_smooth() {
            return Vec3::ZERO;
        }
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return Vec3::ZERO;
        }
        let wm = face_forward(wm.normalize(), Vec3::Z);
        self.torrance_sparrow(wo, wi, wm)
    }

    /// PBRT-v4 `ConductorBxDF::Sample_f`: smooth -> mirror direction, f = F(|cos|) / |cos|,
    /// pdf 1; rough -> wm from the visible normals of wo, wi = reflect(wo, wm), rejected if it
    /// leaves wo's hemisphere.
    #[inline]
    fn sample_f(&self, wo: Vec3, _uc: f32, u0: f32, u1: f32, _mode: u32, sample_flags: u32) -> BSDFSample {
        if !self.is_valid() {
            return BSDFSample::INVALID_PARAMS;
        }
        let wo = unit_or_zero(wo);
        if sample_flags & SAMPLE_REFLECTION == 0 || is_zero(wo) || wo.z == 0.0 {
            return BSDFSample::NONE;
        }
        if self.distrib.effectively_smooth() {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let cos_i = wi.z.abs();
            let f = fresnel::conductor_rgb(cos_i, self.eta, self.k) / cos_i;
            return BSDFSample::new(f, wi, 1.0, SPECULAR_REFLECTION, 1.0).checked();
        }
        let wm = self.distrib.sample_wm(wo, u0, u1);
        let wi = fresnel::reflect(wo, wm);
        if !same_hemisphere(wo, wi) {
            return BSDFSample::NONE;
        }
        let pdf = ieee::div(self.distrib.pdf(wo, wm), 4.0 * wo.dot(wm).abs());
        let f = self.torrance_sparrow(wo, wi, wm);
        BSDFSample::new(f, wi, pdf, GLOSSY_REFLECTION, 1.0).checked()
    }

    /// PBRT-v4 `ConductorBxDF::PDF`: D_wo(wm) / (4 |wo.wm|), wm = normalize(wo + wi) face-forwarded.
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3, _mode: u32, sample_flags: u32) -> f32 {
        if !self.is_valid() {
            return f32::NAN;
        }
        let wo = unit_or_zero(wo);
        let wi = unit_or_zero(wi);
        if sample_flags & SAMPLE_REFLECTION == 0 || !same_hemisphere(wo, wi) || self.distrib.effectively_smooth() {
            return 0.0;
        }
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return 0.0;
        }
        let wm = face_forward(wm.normalize(), Vec3::Z);
        ieee::div(self.distrib.pdf(wo, wm), 4.0 * wo.dot(wm).abs())
    }
}
