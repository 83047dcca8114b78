//! The glTF 2.0 metallic-roughness material (glTF 2.0 specification, appendix B "BRDF
//! Implementation", B.3 "Complete Model"):
//!
//! ```text
//! alpha           = roughness^2
//! specular_brdf   = D(h) G2(wo, wi) / (4 |n.wo| |n.wi|)        (GGX D, height-correlated Smith G2)
//! metal_brdf      = conductor_fresnel(f0 = base, specular_brdf)
//!                 = specular_brdf * (base + (1 - base) (1 - |wo.h|)^5)
//! dielectric_brdf = fresnel_mix(ior = 1.5, base = diffuse_brdf(base) = base / pi, layer = specular_brdf)
//!                 = mix(base / pi, specular_brdf, f0 + (1 - f0) (1 - |wo.h|)^5),  f0 = ((1 - 1.5)/(1 + 1.5))^2
//! f               = mix(dielectric_brdf, metal_brdf, metallic)
//! ```
//!
//! h = normalize(wo + wi). The spec's example uses the separable G1(wo) G1(wi); this module uses
//! the height-correlated Smith G2 of the other BxDFs (the spec allows any Smith joint form).
//! This is a single-scattering model: it loses energy (a white-furnace test returns less than 1
//! at high roughness; see [`crate::energy`] for the compensation).
//! Effectively smooth alpha (< 1e-3) makes the specular lobe a Dirac delta: `f` then holds only
//! the diffuse part, and `sample_f` picks the mirror direction with probability p_spec.
//!
//! Sampling: the specular lobe (visible normals) with probability p_spec(wo), else the cosine
//! hemisphere; p_spec = w_s / (w_s + w_d) with w_s = (1 - m) F_d(|cos_o|) + m mean(F_m(|cos_o|)),
//! w_d = (1 - m) (1 - F_d(|cos_o|)) mean(base) (1 when both are 0). sample_f returns the full f and
//! the mixture pdf p_spec pdf_spec + (1 - p_spec) pdf_diffuse (one-sample MIS with the balance
//! heuristic), so its value and pdf equal `f(wo, wi)` and `pdf(wo, wi)`.
//!
//! Parameters are clamped to the spec's [0, 1] (base color per channel, metallic, roughness);
//! NaN parameters give NaN outputs. Two-sided: wo below the surface reflects below.
//!
//! ```
//! use shader_core::bxdf::{BxDF, GltfMetalRoughBxDF, MODE_RADIANCE, SAMPLE_ALL};
//! use shader_core::Vec3;
//! let m = GltfMetalRoughBxDF::new(Vec3::new(0.9, 0.6, 0.2), 0.5, 0.4);
//! assert_eq!(m.distrib.alpha_x, 0.4 * 0.4); // alpha = roughness^2
//! // Parameters are clamped to [0, 1].
//! assert_eq!(GltfMetalRoughBxDF::new(Vec3::new(2.0, -1.0, 0.5), 1.5, -0.2).metallic, 1.0);
//! // sample_f returns the full f and the mixture pdf: the same as f() and pdf() for that wi.
//! let wo = Vec3::new(0.4, -0.2, 0.89);
//! let s = m.sample_f(wo, 0.3, 0.6, 0.2, MODE_RADIANCE, SAMPLE_ALL);
//! assert!(s.is_valid());
//! let (f, pdf) = (m.f(wo, s.wi, MODE_RADIANCE), m.pdf(wo, s.wi, MODE_RADIANCE, SAMPLE_ALL));
//! assert!((s.pdf - pdf).abs() <= 1e-4 * pdf && (s.f.x - f.x).abs() <= 1e-4 * f.x);
//! assert!((GltfMetalRoughBxDF::dielectric_f0() - 0.04).abs() < 1e-8);
//! ```

use crate::ieee;
use super::microfacet::{roughness_to_alpha, TrowbridgeReitz};
use super::{
    face_forward, is_zero, mean, same_hemisphere, splat, unit_or_zero, BSDFSample, BxDF, DIFFUSE,
    DIFFUSE_REFLECTION, GLOSSY, GLOSSY_REFLECTION, REFLECTION, SAMPLE_REFLECTION, SPECULAR,
    SPECULAR_REFLECTION,
};
use crate::fresnel;
use crate::vector::Vec3;
use crate::warp;
use core::f32::consts::FRAC_1_PI;

/// The dielectric IOR of the glTF metal-rough model.
pub const GLTF_IOR: f32 = 1.5;

#[inline]
fn clamp01(x: f32) -> f32 {
    if x > 1.0 {
        1.0
    } else if x < 0.0 {
        0.0
    } else {
        x
    }
}

/// The Fresnel and specular factors of [`GltfMetalRoughBxDF`]'s f at one (wo, wi).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LobeTerms {
    /// Dielectric Schlick Fresnel F_d(|wo.h|), f0 = 0.04.
    pub fd: f32,
    /// Metal Schlick Fresnel F_m(|wo.h|), f0 = base colour (zero when effectively smooth).
    pub fm: Vec3,
    /// D(h) G2(wo, wi) / (4 |cos_o| |cos_i|) (0 when effectively smooth).
    pub spec: f32,
}

/// glTF metal-rough material: base color (linear RGB), metallic, perceptual roughness.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GltfMetalRoughBxDF {
    /// Base colour, linear RGB, each channel in [0, 1] (clamped by [`GltfMetalRoughBxDF::new`]).
    pub base: Vec3,
    /// Metallic factor in [0, 1]: 0 dielectric, 1 metal.
    pub metallic: f32,
    /// Perceptual roughness in [0, 1] (alpha = roughness^2).
    pub roughness: f32,
    /// GGX with alpha_x = alpha_y = roughness^2.
    pub distrib: TrowbridgeReitz,
}

impl GltfMetalRoughBxDF {
    /// Clamps every parameter to [0, 1] (NaN stays NaN and makes the outputs NaN).
    #[inline]
    pub fn new(base: Vec3, metallic: f32, roughness: f32) -> Self {
        let base = Vec3::new(clamp01(base.x), clamp01(base.y), clamp01(base.z));
        let metallic = clamp01(metallic);
        let roughness = clamp01(roughness);
        let alpha = roughness_to_alpha(roughness);
        GltfMetalRoughBxDF { base, metallic, roughness, distrib: TrowbridgeReitz::new(alpha, alpha) }
    }

    /// True unless a parameter is NaN.
    #[inline]
    pub fn is_valid(&self) -> bool {
        !(self.base.x.is_nan() || self.base.y.is_nan() || self.base.z.is_nan() || self.metallic.is_nan() || self.roughness.is_nan())
    }

    /// F0 of the dielectric layer, ((1 - ior) / (1 + ior))^2 for ior = 1.5.
    #[inline]
    pub fn dielectric_f0() -> f32 {
        fresnel::f0_from_eta(GLTF_IOR)
    }

    /// Probability of sampling the specular lobe for this wo (see the module documentation).
    #[inline]
    pub fn specular_probability(&self, wo: Vec3) -> f32 {
        let cos_o = wo.z.abs();
        let m = self.metallic;
        let fd = fresnel::schlick(cos_o, Self::dielectric_f0(), 1.0);
        let fm = fresnel::schlick_rgb(cos_o, self.base, splat(1.0));
        let ws = (1.0 - m) * fd + m * mean(fm);
        let wd = (1.0 - m) * (1.0 - fd) * mean(self.base);
        let sum = ws + wd;
        if sum > 0.0 {
            ieee::div(ws, sum)
        } else {
            1.0
        }
    }

    /// The factors of f for unit wo, wi on the same side: the dielectric Fresnel F_d(|wo.h|),
    /// the metal Fresnel F_m(|wo.h|) and the specular BRDF D G2 / (4 |cos_o cos_i|) (0 and F_m
    /// unset when effectively smooth). [`GltfMetalRoughBxDF::f`] and the energy-compensated
    /// material of the path tracer (`pt::material`) combine the same terms.
    #[inline]
    pub fn lobe_terms(&self, wo: Vec3, wi: Vec3) -> LobeTerms {
        let wm = face_forward((wo + wi).normalize(), Vec3::Z);
        let vdoth = super::half_vector_cos(wo, wi, wm).abs();
        let fd = fresnel::schlick(vdoth, Self::dielectric_f0(), 1.0);
        if self.distrib.effectively_smooth() {
            return LobeTerms { fd, fm: Vec3::ZERO, spec: 0.0 };
        }
        let spec = ieee::div(self.distrib.d(wm) * self.distrib.g(wo, wi), 4.0 * (wi.z.abs() * wo.z.abs()));
        let fm = fresnel::schlick_rgb(vdoth, self.base, splat(1.0));
        LobeTerms { fd, fm, spec }
    }

    /// The two lobes for unit wo, wi on the same side: (diffuse part, specular part) of f, the
    /// specular part 0 when effectively smooth.
    #[inline]
    fn lobes(&self, wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
        let t = self.lobe_terms(wo, wi);
        let m = self.metallic;
        // (1 - metallic) (1 - F_d) base / pi
        let diffuse = self.base * ((1.0 - m) * (1.0 - t.fd) * FRAC_1_PI);
        if self.distrib.effectively_smooth() {
            return (diffuse, Vec3::ZERO);
        }
        // (1 - metallic) F_d spec + metallic F_m spec
        let fspec = splat((1.0 - m) * t.fd) + t.fm * m;
        (diffuse, fspec * t.spec)
    }

    /// Density of the specular (visible-normal) lobe alone at wi, for unit wo, wi on the same
    /// side (0 when effectively smooth).
    #[inline]
    pub fn specular_lobe_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.specular_pdf(wo, wi)
    }

    /// Specular lobe density at wi (visible normals), for unit wo, wi on the same side.
    #[inline]
    fn specular_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.distrib.effectively_smooth() {
            return 0.0;
        }
        let wm = face_forward((wo + wi).normalize(), Vec3::Z);
        ieee::div(self.distrib.pdf(wo, wm), 4.0 * wo.dot(wm).abs())
    }

    /// Full f and mixture pdf for unit wo, wi (wo.z != 0), 0 when not on the same side.
    #[inline]
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if !same_hemisphere(wo, wi) {
            return (Vec3::ZERO, 0.0);
        }
        let (d, s) = self.lobes(wo, wi);
        (d + s, self.mixture_pdf(wo, wi))
    }

    /// Density of the lobe mixture that `sample_f` draws from, for unit wo, wi on the same side:
    /// p_s D_vis(wm) / (4 |wo.wm|) + (1 - p_s) |cos theta_i| / pi, p_s = `specular_probability(wo)`.
    #[inline]
    fn mixture_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let ps = self.specular_probability(wo);
        ps * self.specular_pdf(wo, wi) + (1.0 - ps) * warp::cosine_hemisphere_pdf(wi.z.abs())
    }
}

impl BxDF for GltfMetalRoughBxDF {
    #[inline]
    fn flags(&self) -> u32 {
        let lobe = if self.distrib.effectively_smooth() { SPECULAR } else { GLOSSY };
        let diffuse = if self.metallic < 1.0 { DIFFUSE } else { 0 };
        REFLECTION | lobe | diffuse
    }

    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3, _mode: u32) -> Vec3 {
        if !self.is_valid() {
            return splat(f32::NAN);
        }
        let wo = unit_or_zero(wo);
        let wi = unit_or_zero(wi);
        self.f_pdf(wo, wi).0
    }

    #[inline]
    fn sample_f(&self, wo: Vec3, uc: f32, u0: f32, u1: f32, _mode: u32, sample_flags: u32) -> BSDFSample {
        if !self.is_valid() {
            return BSDFSample::INVALID_PARAMS;
        }
        let wo = unit_or_zero(wo);
        if sample_flags & SAMPLE_REFLECTION == 0 || is_zero(wo) || wo.z == 0.0 {
            return BSDFSample::NONE;
        }
        let ps = self.specular_probability(wo);
        if uc < ps {
            if self.distrib.effectively_smooth() {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                let cos = wi.z.abs();
                let m = self.metallic;
                let fd = fresnel::schlick(cos, Self::dielectric_f0(), 1.0);
                let fm = fresnel::schlick_rgb(cos, self.base, splat(1.0));
                let f = (splat((1.0 - m) * fd) + fm * m) / cos;
                return BSDFSample::new(f, wi, ps, SPECULAR_REFLECTION, 1.0).checked();
            }
            let wm = self.distrib.sample_wm(wo, u0, u1);
            let wi = fresnel::reflect(wo, wm);
            if !same_hemisphere(wo, wi) {
                return BSDFSample::NONE;
            }
            let wi = unit_or_zero(wi);
            let (f, pdf) = self.f_pdf(wo, wi);
            return BSDFSample::new(f, wi, pdf, GLOSSY_REFLECTION, 1.0).checked();
        }
        let mut wi = warp::sample_cosine_hemisphere(u0, u1);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let (f, pdf) = self.f_pdf(wo, wi);
        BSDFSample::new(f, wi, pdf, DIFFUSE_REFLECTION, 1.0).checked()
    }

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
        self.mixture_pdf(wo, wi)
    }
}
