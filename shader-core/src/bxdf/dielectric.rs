//! Dielectric interface, smooth or rough, reflection and transmission (PBRT-v4 section 9.5 and 9.7,
//! `DielectricBxDF`; Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces").
//!
//! `eta` is the relative IOR eta_t / eta_i of the medium below the surface (wo.z < 0 side) over
//! the medium above. Rough transmission uses the generalized half vector wm = normalize(eta' wi + wo)
//! (Walter 2007 eq. 16; PBRT-v4 eq. 9.34) with eta' = eta when wo is above (cos_o > 0) and 1/eta when
//! below, face-forwarded to +z; microfacets back-facing to wo or wi are discarded.
//!
//! Radiance scaling (PBRT-v4 section 9.5.2): radiance is not symmetric across a refractive
//! boundary. In [`MODE_RADIANCE`] the transmitted value is divided by eta'^2 (the solid-angle
//! compression of radiance entering a denser medium); in [`MODE_IMPORTANCE`](super::MODE_IMPORTANCE) it is not. Hence
//! f_radiance(wo, wi) = f_importance(wi, wo), and reflection is reciprocal in both modes.
//! Energy: with G2 = 1, integral of (f_R + f_T,importance) |cos_i| dwi = 1 exactly (the microsurface
//! only splits energy by F, 1 - F).
//!
//! ```
//! use shader_core::bxdf::{BxDF, DielectricBxDF, TrowbridgeReitz, MODE_IMPORTANCE, MODE_RADIANCE, SAMPLE_ALL};
//! use shader_core::Vec3;
//! let glass = DielectricBxDF::new(TrowbridgeReitz::new(0.2, 0.2), 1.5);
//! assert!(glass.is_valid());
//! let wo = Vec3::new(0.3, 0.0, 0.95);
//! // Reflection is reciprocal in both modes.
//! let wr = Vec3::new(-0.2, 0.1, 0.97);
//! assert_eq!(glass.f(wo, wr, MODE_RADIANCE), glass.f(wr, wo, MODE_RADIANCE));
//! // Transmission: f_radiance(wo, wi) = f_importance(wi, wo).
//! let wt = Vec3::new(-0.1, 0.05, -0.99);
//! let a = glass.f(wo, wt, MODE_RADIANCE).x;
//! let b = glass.f(wt, wo, MODE_IMPORTANCE).x;
//! assert!(a > 0.0 && (a - b).abs() <= 1e-5 * a, "{a} vs {b}");
//! // Non-positive IOR is invalid: NaN outputs, no sample.
//! let bad = DielectricBxDF::new(TrowbridgeReitz::new(0.2, 0.2), 0.0);
//! assert!(bad.pdf(wo, wr, MODE_RADIANCE, SAMPLE_ALL).is_nan());
//! assert!(!bad.sample_f(wo, 0.5, 0.5, 0.5, MODE_RADIANCE, SAMPLE_ALL).is_valid());
//! ```

use crate::ieee;
use super::microfacet::TrowbridgeReitz;
use super::{
    face_forward, is_zero, same_hemisphere, unit_or_zero, BSDFSample, BxDF, GLOSSY, GLOSSY_REFLECTION,
    GLOSSY_TRANSMISSION, MODE_RADIANCE, REFLECTION, SAMPLE_REFLECTION, SAMPLE_TRANSMISSION, SPECULAR,
    SPECULAR_REFLECTION, SPECULAR_TRANSMISSION, TRANSMISSION,
};
use crate::fresnel;
use crate::vector::Vec3;

/// Dielectric interface with relative IOR `eta` (valid: 0 < eta < inf) and GGX roughness.
/// `f` is a scalar (the same in R, G, B); it is returned in all three channels.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DielectricBxDF {
    /// The GGX microfacet distribution (roughness alpha_x, alpha_y; effectively smooth below 1e-3).
    pub distrib: TrowbridgeReitz,
    /// Relative IOR eta_t / eta_i of the medium below the surface over the medium above (valid:
    /// 0 < eta < inf; 1.5 for glass in air).
    pub eta: f32,
}

/// Generalized half vector of a pair: (wm face-forwarded and unit, eta', is_reflection), or
/// wm = 0 when the configuration has none (grazing, wm = 0, back-facing microfacet).
#[derive(Clone, Copy)]
struct HalfVector {
    wm: Vec3,
    etap: f32,
    /// 1 for a reflection pair, 0 for transmission (u32: no bool in structs for SPIR-V).
    reflect: u32,
}

impl DielectricBxDF {
    /// The dielectric with these parameters, stored as given (check with [`DielectricBxDF::is_valid`]).
    #[inline]
    pub fn new(distrib: TrowbridgeReitz, eta: f32) -> Self {
        DielectricBxDF { distrib, eta }
    }

    /// True when the roughness is valid and 0 < eta < inf.
    #[inline]
    pub fn is_valid(&self) -> bool {
        self.distrib.is_valid() && self.eta > 0.0 && self.eta < f32::INFINITY
    }

    /// PBRT-v4's generalized half vector with the back-facing test, for unit wo, wi.
    #[inline]
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> HalfVector {
        let cos_o = wo.z;
        let cos_i = wi.z;
        let reflect = if cos_i * cos_o > 0.0 { 1 } else { 0 };
        let etap = if reflect == 1 {
            1.0
        } else if cos_o > 0.0 {
            self.eta
        } else {
            ieee::div(1.0, self.eta)
        };
        let none = HalfVector { wm: Vec3::ZERO, etap, reflect };
        let wm = wi * etap + wo;
        if cos_i == 0.0 || cos_o == 0.0 || wm.length_squared() == 0.0 {
            return none;
        }
        let wm = face_forward(unit_or_zero(wm), Vec3::Z);
        if is_zero(wm) || wm.dot(wi) * cos_i < 0.0 || wm.dot(wo) * cos_o < 0.0 {
            return none;
        }
        HalfVector { wm, etap, reflect }
    }

    /// Reflection and transmission selection probabilities (R, T) masked by `sample_flags`.
    #[inline]
    fn probabilities(r: f32, sample_flags: u32) -> (f32, f32) {
        let pr = if sample_flags & SAMPLE_REFLECTION != 0 { r } else { 0.0 };
        let pt = if sample_flags & SAMPLE_TRANSMISSION != 0 { 1.0 - r } else { 0.0 };
        (pr, pt)
    }
}

impl BxDF for DielectricBxDF {
    /// PBRT-v4 `DielectricBxDF::Flags`: eta == 1 has no reflection; specular when smooth.
    /// One deliberate difference: eta == 1 with rough alpha reports SPECULAR (PBRT says GLOSSY),
    /// because `sample_f` then returns the specular pass-through wi = -wo, as PBRT's does.
    #[inline]
    fn flags(&self) -> u32 {
        if self.eta == 1.0 {
            return TRANSMISSION | SPECULAR;
        }
        if self.distrib.effectively_smooth() {
            REFLECTION | TRANSMISSION | SPECULAR
        } else {
            REFLECTION | TRANSMISSION | GLOSSY
        }
    }

    /// PBRT-v4 `DielectricBxDF::f` (rough only; 0 when smooth or eta == 1):
    /// reflection D G F / |4 cos_i cos_o|; transmission
    /// D (1 - F) G |wi.wm wo.wm| / |cos_i cos_o (wi.wm + wo.wm / eta')^2|, / eta'^2 for radiance.
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3, mode: u32) -> Vec3 {
        if !self.is_valid() {
            return super::splat(f32::NAN);
        }
        let wo = unit_or_zero(wo);
        let wi = unit_or_zero(wi);
        if self.eta == 1.0 || self.distrib.effectively_smooth() || is_zero(wo) || is_zero(wi) {
            return Vec3::ZERO;
        }
        let h = self.half_vector(wo, wi);
        if is_zero(h.wm) {
            return Vec3::ZERO;
        }
        let wm = h.wm;
        // Reflection: the symmetric half-angle cosine (reciprocal to the bit); refraction: wo.wm.
        let fr = fresnel::dielectric(if h.reflect == 1 { super::half_vector_cos(wo, wi, wm) } else { wo.dot(wm) }, self.eta);
        let d = self.distrib.d(wm);
        let g = self.distrib.g(wo, wi);
        let v = if h.reflect == 1 {
            ieee::div(d * g * fr, (4.0 * (wi.z * wo.z)).abs())
        } else {
            let s = wi.dot(wm) + ieee::div(wo.dot(wm), h.etap);
            let denom = s * s * wi.z * wo.z;
            let ft = d * (1.0 - fr) * g * (ieee::div(wi.dot(wm) * wo.dot(wm), denom)).abs();
            let ft = if mode == MODE_RADIANCE { ieee::div(ft, h.etap * h.etap) } else { ft };
            // eta within ~1e-7 of 1 makes (wi.wm + wo.wm / eta')^2 round to 0 near wi = -wo (the
            // lobe tends to a delta): such non-finite values are dropped (documented).
            if ft < f32::INFINITY {
                ft
            } else {
                0.0
            }
        };
        super::splat(v)
    }

    /// PBRT-v4 `DielectricBxDF::Sample_f`: choose reflection with probability R / (R + T) (F at
    /// wo.z when smooth, at wo.wm for the sampled visible normal when rough), else refract.
    #[inline]
    fn sample_f(&self, wo: Vec3, uc: f32, u0: f32, u1: f32, mode: u32, sample_flags: u32) -> BSDFSample {
        if !self.is_valid() {
            return BSDFSample::INVALID_PARAMS;
        }
        let wo = unit_or_zero(wo);
        if is_zero(wo) || wo.z == 0.0 {
            return BSDFSample::NONE;
        }
        if self.eta == 1.0 || self.distrib.effectively_smooth() {
            // Perfect specular interface.
            let r = fresnel::dielectric(wo.z, self.eta);
            let t = 1.0 - r;
            let (pr, pt) = Self::probabilities(r, sample_flags);
            if pr == 0.0 && pt == 0.0 {
                return BSDFSample::NONE;
            }
            if uc < ieee::div(pr, pr + pt) {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                let f = super::splat(ieee::div(r, wi.z.abs()));
                return BSDFSample::new(f, wi, ieee::div(pr, pr + pt), SPECULAR_REFLECTION, 1.0).checked();
            }
            let rf = fresnel::refract(wo, Vec3::Z, self.eta);
            if rf.valid == 0 {
                return BSDFSample::NONE;
            }
            let wi = rf.wt;
            let mut ft = ieee::div(t, wi.z.abs());
            if mode == MODE_RADIANCE {
                ft = ieee::div(ft, rf.etap * rf.etap);
            }
            return BSDFSample::new(super::splat(ft), wi, ieee::div(pt, pr + pt), SPECULAR_TRANSMISSION, rf.etap).checked();
        }
        // Rough interface: sample a visible normal first.
        let wm = self.distrib.sample_wm(wo, u0, u1);
        let r = fresnel::dielectric(wo.dot(wm), self.eta);
        let t = 1.0 - r;
        let (pr, pt) = Self::probabilities(r, sample_flags);
        if pr == 0.0 && pt == 0.0 {
            return BSDFSample::NONE;
        }
        if uc < ieee::div(pr, pr + pt) {
            let wi = fresnel::reflect(wo, wm);
            if !same_hemisphere(wo, wi) {
                return BSDFSample::NONE;
            }
            let pdf = ieee::div(ieee::div(self.distrib.pdf(wo, wm), 4.0 * wo.dot(wm).abs()) * pr, pr + pt);
            let f = ieee::div(self.distrib.d(wm) * self.distrib.g(wo, wi) * r, 4.0 * wi.z * wo.z);
            BSDFSample::new(super::splat(f), wi, pdf, GLOSSY_REFLECTION, 1.0).checked()
        } else {
            let rf = fresnel::refract(wo, wm, self.eta);
            let wi = rf.wt;
            if rf.valid == 0 || same_hemisphere(wo, wi) || wi.z == 0.0 {
                return BSDFSample::NONE;
            }
            let s = wi.dot(wm) + ieee::div(wo.dot(wm), rf.etap);
            let denom = s * s;
            let dwm_dwi = ieee::div(wi.dot(wm).abs(), denom);
            let pdf = ieee::div(self.distrib.pdf(wo, wm) * dwm_dwi * pt, pr + pt);
            let mut ft = t * self.distrib.d(wm) * self.distrib.g(wo, wi)
                * (ieee::div(wi.dot(wm) * wo.dot(wm), wi.z * wo.z * denom)).abs();
            if mode == MODE_RADIANCE {
                ft = ieee::div(ft, rf.etap * rf.etap);
            }
            BSDFSample::new(super::splat(ft), wi, pdf, GLOSSY_TRANSMISSION, rf.etap).checked()
        }
    }

    /// PBRT-v4 `DielectricBxDF::PDF`: D_wo(wm) / (4 |wo.wm|) R/(R+T) for reflection,
    /// D_wo(wm) |wi.wm| / (wi.wm + wo.wm / eta')^2 T/(R+T) for transmission; 0 when smooth.
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3, _mode: u32, sample_flags: u32) -> f32 {
        if !self.is_valid() {
            return f32::NAN;
        }
        let wo = unit_or_zero(wo);
        let wi = unit_or_zero(wi);
        if self.eta == 1.0 || self.distrib.effectively_smooth() || is_zero(wo) || is_zero(wi) {
            return 0.0;
        }
        let h = self.half_vector(wo, wi);
        if is_zero(h.wm) {
            return 0.0;
        }
        let wm = h.wm;
        let r = fresnel::dielectric(wo.dot(wm), self.eta);
        let (pr, pt) = Self::probabilities(r, sample_flags);
        if pr == 0.0 && pt == 0.0 {
            return 0.0;
        }
        if h.reflect == 1 {
            ieee::div(ieee::div(self.distrib.pdf(wo, wm), 4.0 * wo.dot(wm).abs()) * pr, pr + pt)
        } else {
            let s = wi.dot(wm) + ieee::div(wo.dot(wm), h.etap);
            let dwm_dwi = ieee::div(wi.dot(wm).abs(), s * s);
            let p = ieee::div(self.distrib.pdf(wo, wm) * dwm_dwi * pt, pr + pt);
            // As in `f`: a density that rounds to infinity (eta -> 1) is dropped.
            if p < f32::INFINITY {
                p
            } else {
                0.0
            }
        }
    }
}
