//! The path tracer's surface BSDF: the glTF 2.0 metal-rough BxDF (appendix B.3) with energy
//! compensation of its specular lobe (Kulla & Conty 2017, "Revisiting Physically Based Shading
//! at Imageworks", eq. 2-4; Turquin 2019, "Practical multiple scattering compensation for
//! microfacet models", eq. 10-11) and the dielectric diffuse scaled by 1 - E'' (the specular
//! albedo), mixed with the rough dielectric BxDF for `KHR_materials_transmission`.
//!
//! f = (1 - t) f_gltf' + t f_dielectric with t = transmission (1 - metallic), where f_gltf' is,
//! per compensation mode (`shader_core::energy::COMP_*`):
//! * off: the glTF BxDF itself, `(1 - m)(1 - F_d) base/pi + ((1 - m) F_d + m F_m) spec`;
//! * Turquin: `(1 - m) s_d base/pi + ((1 - m) F_d k_d + m F_m k_m) spec`, with
//!   k = 1 + F0 (1 - E(mu_o)) / E(mu_o) per channel (F0 = 0.04 dielectric, base colour metal) and
//!   s_d = 1 - k_d E''(mu_o) the diffuse scale;
//! * Kulla-Conty: the glTF lobes with s_d = 1 - (E''(mu_o) + E_ms) plus the multiple-scattering
//!   lobe `(1 - E(mu_i)) c / pi`, c = pi f_ms / (1 - E(mu_i)) per channel (Fresnel-averaged).
//!
//! Below `energy::COMPENSATION_MIN_ROUGHNESS` the specular terms are not compensated (as in the
//! white-furnace kernel); effectively smooth (Dirac) lobes are never compensated (E = 1 there to
//! within 1e-4). The dielectric (transmission) part is not compensated. Sampling: the transmission
//! part with probability t, else the glTF BxDF's own mixture (VNDF + cosine), whose cosine lobe
//! also covers the Kulla-Conty lobe; `sample` returns the full mixture f and pdf for non-Dirac
//! samples, so it can be weighted by MIS like any other direction.
//!
//! ```
//! use shader_core::bxdf::{BxDF, GltfMetalRoughBxDF, MODE_RADIANCE};
//! use shader_core::energy::COMP_NONE;
//! use shader_core::pt::material::Material;
//! use shader_core::pt::surface::MaterialPoint;
//! use shader_core::Vec3;
//! // Without compensation or transmission the material is the glTF BxDF itself, to the bit (the
//! // energy tables are not read, so none are passed).
//! let mp = MaterialPoint { base: Vec3::new(0.8, 0.5, 0.2), metallic: 0.3, roughness: 0.6, ior: 1.5, ..Default::default() };
//! let (wo, wi) = (Vec3::new(0.3, 0.1, 0.95).normalize(), Vec3::new(-0.5, 0.2, 0.84).normalize());
//! let m = Material::new(&mp, wo, &[], COMP_NONE);
//! let g = GltfMetalRoughBxDF::new(mp.base, mp.metallic, mp.roughness);
//! assert_eq!(m.f(wo, wi, &[]), g.f(wo, wi, MODE_RADIANCE));
//! ```

use crate::bxdf::{BxDF, DielectricBxDF, GltfMetalRoughBxDF, TrowbridgeReitz, MODE_RADIANCE, SAMPLE_ALL, SPECULAR};
use crate::bxdf::{same_hemisphere, splat, BSDFSample};
use crate::energy::{self, COMPENSATION_MIN_ROUGHNESS, COMP_KULLA_CONTY, COMP_NONE, COMP_TURQUIN, DIELECTRIC_F0, MU_MIN};
use crate::ieee;
use crate::pt::surface::MaterialPoint;
use crate::vector::Vec3;
use core::f32::consts::{FRAC_1_PI, PI};

/// The BSDF at one shading point for one outgoing direction (local frame, normal = +z).
#[derive(Clone, Copy, Debug, Default)]
pub struct Material {
    /// The glTF metal-rough BxDF (parameters clamped to [0, 1]).
    pub gltf: GltfMetalRoughBxDF,
    /// The transmissive dielectric (relative IOR = material IOR, roughness as the glTF lobe).
    pub dielectric: DielectricBxDF,
    /// Weight of the dielectric, transmission (1 - metallic), in [0, 1].
    pub t: f32,
    /// Compensation mode ([`COMP_NONE`], [`COMP_KULLA_CONTY`], [`COMP_TURQUIN`]); `COMP_NONE`
    /// where the roughness is below the compensation threshold.
    pub mode: u32,
    /// Turquin scale k of the metal lobe, per channel (1 when off).
    pub k_m: Vec3,
    /// Turquin scale k of the dielectric specular lobe (1 when off).
    pub k_d: f32,
    /// Scale of the diffuse lobe (with compensation; unused when off).
    pub s_d: f32,
    /// Kulla-Conty: pi f_ms / (1 - E(mu_i)) of the whole material, per channel (0 when off).
    pub c_ms: Vec3,
}

/// pi f_ms / (1 - E(mu_i)) of Kulla-Conty for Schlick F0 `f0` (F90 = 1).
#[inline]
fn kulla_conty_factor(e_o: f32, e_avg: f32, f0: f32) -> f32 {
    energy::kulla_conty_f_ms(e_o, 0.0, e_avg, energy::schlick_f_avg(f0, 1.0)) * PI
}

#[inline]
fn clamp01(x: f32) -> f32 {
    crate::math::clamp(x, 0.0, 1.0)
}

impl Material {
    /// The BSDF of material point `mp` seen from local `wo`, compensated per `mode` with the
    /// energy tables in `lut` (`shader_core::energy`'s LUT buffer; unread when `mode` is off).
    #[inline]
    pub fn new(mp: &MaterialPoint, wo: Vec3, lut: &[f32], mode: u32) -> Material {
        let gltf = GltfMetalRoughBxDF::new(mp.base, mp.metallic, mp.roughness);
        let distrib = gltf.distrib;
        let dielectric = DielectricBxDF::new(TrowbridgeReitz::new(distrib.alpha_x, distrib.alpha_y), mp.ior);
        let t = clamp01(mp.transmission) * (1.0 - gltf.metallic);
        let mut mat = Material { gltf, dielectric, t, mode: COMP_NONE, k_m: splat(1.0), k_d: 1.0, s_d: 1.0, c_ms: Vec3::ZERO };
        let r = gltf.roughness;
        if mode == COMP_NONE || !(r >= COMPENSATION_MIN_ROUGHNESS) || distrib.effectively_smooth() {
            return mat;
        }
        mat.mode = mode;
        let mu = crate::math::max(wo.z.abs(), MU_MIN);
        let (e_o, e_p) = energy::lut_e_and_e_prime(lut, mu, r);
        // Specular albedo of the dielectric lobe, E'' = F0 E + (1 - F0) E' (Schlick split).
        let e2_d = energy::schlick_albedo(e_o, e_p, DIELECTRIC_F0, 1.0);
        let m = gltf.metallic;
        let base = gltf.base;
        if mode == COMP_TURQUIN {
            mat.k_m = Vec3::new(energy::turquin_scale(e_o, base.x), energy::turquin_scale(e_o, base.y), energy::turquin_scale(e_o, base.z));
            mat.k_d = energy::turquin_scale(e_o, DIELECTRIC_F0);
            mat.s_d = 1.0 - e2_d * mat.k_d;
        } else if mode == COMP_KULLA_CONTY {
            let e_avg = energy::lut_e_avg(lut, r);
            let kc_d = kulla_conty_factor(e_o, e_avg, DIELECTRIC_F0);
            let kc_m = Vec3::new(kulla_conty_factor(e_o, e_avg, base.x), kulla_conty_factor(e_o, e_avg, base.y), kulla_conty_factor(e_o, e_avg, base.z));
            mat.c_ms = kc_m * m + splat(kc_d * (1.0 - m));
            mat.s_d = 1.0 - (e2_d + energy::kulla_conty_albedo(e_o, e_avg, energy::schlick_f_avg(DIELECTRIC_F0, 1.0)));
        }
        if !(mat.s_d > 0.0) {
            mat.s_d = 0.0;
        }
        mat
    }

    /// f of the reflective (glTF) part for unit local wo, wi, compensation included.
    #[inline]
    fn f_gltf(&self, wo: Vec3, wi: Vec3, lut: &[f32]) -> Vec3 {
        if self.mode == COMP_NONE {
            return self.gltf.f(wo, wi, MODE_RADIANCE);
        }
        if !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        let lt = self.gltf.lobe_terms(wo, wi);
        let m = self.gltf.metallic;
        let diffuse = self.gltf.base * ((1.0 - m) * self.s_d * FRAC_1_PI);
        let spec = (splat((1.0 - m) * lt.fd * self.k_d) + lt.fm.mul_elem(self.k_m) * m) * lt.spec;
        let mut f = diffuse + spec;
        if self.mode == COMP_KULLA_CONTY {
            let e_i = energy::lut_e(lut, crate::math::max(wi.z.abs(), MU_MIN), self.gltf.roughness);
            f = f + self.c_ms * ((1.0 - e_i) * FRAC_1_PI);
        }
        f
    }

    /// BSDF value f(wo, wi) (no cosine) for local directions.
    #[inline]
    pub fn f(&self, wo: Vec3, wi: Vec3, lut: &[f32]) -> Vec3 {
        let wo = crate::bxdf::unit_or_zero(wo);
        let wi = crate::bxdf::unit_or_zero(wi);
        let mut f = Vec3::ZERO;
        if self.t < 1.0 {
            f = self.f_gltf(wo, wi, lut) * (1.0 - self.t);
        }
        if self.t > 0.0 {
            f = f + self.dielectric.f(wo, wi, MODE_RADIANCE) * self.t;
        }
        f
    }

    /// Solid-angle density of [`Material::sample`] at wi (non-Dirac parts).
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let mut p = 0.0;
        if self.t < 1.0 {
            p = self.gltf.pdf(wo, wi, MODE_RADIANCE, SAMPLE_ALL) * (1.0 - self.t);
        }
        if self.t > 0.0 {
            p = p + self.dielectric.pdf(wo, wi, MODE_RADIANCE, SAMPLE_ALL) * self.t;
        }
        p
    }

    /// True when every lobe is a Dirac delta (no light sampling can help).
    #[inline]
    pub fn is_specular(&self) -> bool {
        let smooth = self.gltf.distrib.effectively_smooth();
        smooth && (self.gltf.metallic >= 1.0 || self.t >= 1.0)
    }

    /// Sample wi from local wo with uniform numbers (uc, u0, u1): a Dirac sample carries its
    /// lobe's f and discrete probability (times the part's selection probability); any other
    /// sample carries the full mixture f(wo, wi) and pdf(wo, wi).
    #[inline]
    pub fn sample(&self, wo: Vec3, uc: f32, u0: f32, u1: f32, lut: &[f32]) -> BSDFSample {
        let use_t = uc < self.t;
        let s = if use_t {
            self.dielectric.sample_f(wo, ieee::div(uc, self.t), u0, u1, MODE_RADIANCE, SAMPLE_ALL)
        } else {
            let uc2 = ieee::div(uc - self.t, 1.0 - self.t);
            self.gltf.sample_f(wo, crate::math::min(uc2, 0.99999994), u0, u1, MODE_RADIANCE, SAMPLE_ALL)
        };
        if !s.is_valid() {
            return s;
        }
        if s.flags & SPECULAR != 0 {
            let p = if use_t { self.t } else { 1.0 - self.t };
            return BSDFSample::new(s.f * p, s.wi, s.pdf * p, s.flags, s.eta);
        }
        let f = self.f(wo, s.wi, lut);
        let pdf = self.pdf(wo, s.wi);
        BSDFSample::new(f, s.wi, pdf, s.flags, s.eta).checked()
    }
}
