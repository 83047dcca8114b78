//! Fresnel functions and the BxDFs of `shader_core::{fresnel, bxdf}` (docs/bxdf.md).
//!
//! `mode` is 1 for importance transport and anything else for radiance; `flags` is the
//! `BxDFFlags` bit set as a float (0 = no sample); `valid` is 1 or 0.

use shader_core::bxdf::{
    BxDF, ConductorBxDF, DielectricBxDF, DiffuseBxDF, GltfMetalRoughBxDF, TrowbridgeReitz, MODE_IMPORTANCE,
    MODE_RADIANCE, SAMPLE_ALL,
};
use shader_core::{fresnel, vndf, Vec3};

/// The transport mode of a `mode` column: 1 = importance, anything else = radiance.
#[inline(always)]
fn transport(m: f32) -> u32 {
    if m == 1.0 {
        MODE_IMPORTANCE
    } else {
        MODE_RADIANCE
    }
}

crate::evaluable! { group = "bxdf";
    fresnel_dielectric "Dielectric Fresnel reflectance, cos < 0 = inside, TIR -> 1 (PBRT-v4 FrDielectric, eq. 9.5)"
        (cos_theta_i: f32, eta: f32) -> (f: f32) { fresnel::dielectric(cos_theta_i, eta) }
    fresnel_conductor "Conductor Fresnel reflectance for IOR eta + i k (PBRT-v4 FrComplex, eq. 9.6)"
        (cos_theta_i: f32, eta: f32, k: f32) -> (f: f32) { fresnel::conductor(cos_theta_i, eta, k) }
    fresnel_schlick "Schlick's approximation F0 + (F90 - F0)(1 - |cos|)^5 (Schlick 1994 eq. 24)"
        (cos_theta: f32, f0: f32, f90: f32) -> (f: f32) { fresnel::schlick(cos_theta, f0, f90) }
    fresnel_f0 "Normal-incidence reflectance of a dielectric, F0 = ((eta - 1)/(eta + 1))^2 (Schlick 1994 eq. 24)"
        (eta: f32) -> (f0: f32) { fresnel::f0_from_eta(eta) }
    gulbrandsen_nk "Reflectivity r and edge tint g -> conductor IOR (n, k) (Gulbrandsen 2014 eqs. 8-9)"
        (r: f32, g: f32) -> (n: f32, k: f32) {
            let nk = fresnel::gulbrandsen_nk(r, g);
            (nk.re, nk.im)
        }
    gulbrandsen_rg "Conductor IOR (n, k) -> reflectivity r and edge tint g (inverse of Gulbrandsen 2014 eqs. 8-9)"
        (n: f32, k: f32) -> (r: f32, g: f32) {
            let rg = fresnel::gulbrandsen_r_g(n, k);
            (rg.r, rg.g)
        }
    refract "Snell refraction of wi about n, eta relative; valid = 0 on TIR (PBRT-v4 Refract, eq. 9.4)"
        (wi: Vec3, n: Vec3, eta: f32) -> (wt: Vec3, etap: f32, valid: f32) {
            let r = fresnel::refract(wi, n, eta);
            (r.wt, r.etap, r.valid as f32)
        }
    ggx_vndf_sample "GGX visible normal sample (Heitz 2018, JCGT 7(4) listing 1, as PBRT-v4 Sample_wm)"
        (w: Vec3, alpha_x: f32, alpha_y: f32, u0: f32, u1: f32) -> (wm: Vec3) {
            vndf::ggx_sample_visible_heitz2018(w, alpha_x, alpha_y, u0, u1)
        }
    ggx_vndf_pdf "GGX visible normal density G1(w) D(wm) |w.wm| / |w.z| (Heitz 2018 eq. 2)"
        (w: Vec3, wm: Vec3, alpha_x: f32, alpha_y: f32) -> (pdf: f32) { vndf::ggx_visible_pdf(w, wm, alpha_x, alpha_y) }
    lambert_f "Lambertian BRDF R / pi, same hemisphere only (PBRT-v4 DiffuseBxDF::f)"
        (wo: Vec3, wi: Vec3, r: Rgb) -> (f: Rgb) { DiffuseBxDF::new(r).f(wo, wi, MODE_RADIANCE) }
    lambert_sample_f "Lambertian sample by the cosine-weighted concentric-disk hemisphere (PBRT-v4 DiffuseBxDF::Sample_f)"
        (wo: Vec3, uc: f32, u0: f32, u1: f32, r: Rgb) -> (wi: Vec3, f: Rgb, pdf: f32, flags: f32) {
            let s = DiffuseBxDF::new(r).sample_f(wo, uc, u0, u1, MODE_RADIANCE, SAMPLE_ALL);
            (s.wi, s.f, s.pdf, s.flags as f32)
        }
    lambert_pdf "Lambertian sampling density |cos theta_i| / pi, same hemisphere only"
        (wo: Vec3, wi: Vec3) -> (pdf: f32) {
            DiffuseBxDF::new(Vec3::new(1.0, 1.0, 1.0)).pdf(wo, wi, MODE_RADIANCE, SAMPLE_ALL)
        }
    conductor_f "Torrance-Sparrow conductor BRDF (no cosine): GGX D, height-correlated G, complex Fresnel per RGB (PBRT-v4 eq. 9.33)"
        (wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32, eta: Rgb, k: Rgb) -> (f: Rgb) {
            ConductorBxDF::new(TrowbridgeReitz::new(alpha_x, alpha_y), eta, k).f(wo, wi, MODE_RADIANCE)
        }
    conductor_sample_f "Conductor sample through GGX visible normals; mirror when alpha < 1e-3 (PBRT-v4 ConductorBxDF::Sample_f)"
        (wo: Vec3, uc: f32, u0: f32, u1: f32, alpha_x: f32, alpha_y: f32, eta: Rgb, k: Rgb) -> (wi: Vec3, f: Rgb, pdf: f32, flags: f32) {
            let b = ConductorBxDF::new(TrowbridgeReitz::new(alpha_x, alpha_y), eta, k);
            let s = b.sample_f(wo, uc, u0, u1, MODE_RADIANCE, SAMPLE_ALL);
            (s.wi, s.f, s.pdf, s.flags as f32)
        }
    conductor_pdf "Conductor sampling density D_wo(wm) / (4 |wo.wm|) (PBRT-v4 eq. 9.36)"
        (wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> (pdf: f32) {
            // The pdf does not depend on the Fresnel parameters: a perfect conductor stands in.
            let b = ConductorBxDF::new(TrowbridgeReitz::new(alpha_x, alpha_y), Vec3::ZERO, Vec3::new(1.0, 1.0, 1.0));
            b.pdf(wo, wi, MODE_RADIANCE, SAMPLE_ALL)
        }
    dielectric_f "Rough dielectric BSDF (reflection + transmission, generalized half vector; mode 1 = importance) (PBRT-v4 DielectricBxDF::f)"
        (wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32, eta: f32, mode: f32) -> (f: f32) {
            DielectricBxDF::new(TrowbridgeReitz::new(alpha_x, alpha_y), eta).f(wo, wi, transport(mode)).x
        }
    dielectric_sample_f "Dielectric sample: reflect with probability R/(R+T) else refract (PBRT-v4 DielectricBxDF::Sample_f)"
        (wo: Vec3, uc: f32, u0: f32, u1: f32, alpha_x: f32, alpha_y: f32, eta: f32, mode: f32)
        -> (wi: Vec3, f: f32, pdf: f32, flags: f32, etap: f32) {
            let b = DielectricBxDF::new(TrowbridgeReitz::new(alpha_x, alpha_y), eta);
            let s = b.sample_f(wo, uc, u0, u1, transport(mode), SAMPLE_ALL);
            (s.wi, s.f.x, s.pdf, s.flags as f32, s.eta)
        }
    dielectric_pdf "Dielectric sampling density (PBRT-v4 DielectricBxDF::PDF)"
        (wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32, eta: f32, mode: f32) -> (pdf: f32) {
            DielectricBxDF::new(TrowbridgeReitz::new(alpha_x, alpha_y), eta).pdf(wo, wi, transport(mode), SAMPLE_ALL)
        }
    gltf_f "glTF 2.0 metal-rough BRDF mix(fresnel_mix(1.5, diffuse, specular), conductor_fresnel(base, specular), metallic), alpha = roughness^2"
        (wo: Vec3, wi: Vec3, base: Rgb, metallic: f32, roughness: f32) -> (f: Rgb) {
            GltfMetalRoughBxDF::new(base, metallic, roughness).f(wo, wi, MODE_RADIANCE)
        }
    gltf_sample_f "glTF metal-rough sample: specular (visible normals) or cosine lobe, mixture pdf"
        (wo: Vec3, uc: f32, u0: f32, u1: f32, base: Rgb, metallic: f32, roughness: f32) -> (wi: Vec3, f: Rgb, pdf: f32, flags: f32) {
            let s = GltfMetalRoughBxDF::new(base, metallic, roughness).sample_f(wo, uc, u0, u1, MODE_RADIANCE, SAMPLE_ALL);
            (s.wi, s.f, s.pdf, s.flags as f32)
        }
    gltf_pdf "glTF metal-rough sampling density (mixture of the specular and cosine lobes)"
        (wo: Vec3, wi: Vec3, base: Rgb, metallic: f32, roughness: f32) -> (pdf: f32) {
            GltfMetalRoughBxDF::new(base, metallic, roughness).pdf(wo, wi, MODE_RADIANCE, SAMPLE_ALL)
        }
}
