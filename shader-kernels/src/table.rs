//! The registry of functions that can be evaluated over a table of rows (`host eval`), and the
//! per-row kernel shared by the CPU and GPU backends.
//!
//! Column conventions: directions are split into `_x,_y,_z` columns in the local shading frame
//! (normal = +z); every NDF and masking function takes `alpha_x, alpha_y`.

use crate::bxdf_table;
use crate::microfacet_table;
use crate::vndf_table;
use shader_core::{masking, math, ndf, Vec3};
use spirv_std::num_traits::Float;

/// One evaluable function: its id (the value the kernel dispatches on), name and columns.
#[derive(Clone, Copy, Debug)]
pub struct FunctionInfo {
    pub id: u32,
    pub name: &'static str,
    pub summary: &'static str,
    pub inputs: &'static [&'static str],
    pub outputs: &'static [&'static str],
}

pub const GGX_D: u32 = 1;
pub const GGX_LAMBDA: u32 = 2;
pub const GGX_G1: u32 = 3;
pub const ARITH_PROBE: u32 = 4;
pub const MATH_UNARY: u32 = 5;
pub const MATH_BINARY: u32 = 6;

/// Every function [`eval_row`] knows, in id order.
pub const FUNCTIONS: &[FunctionInfo] = &[
    FunctionInfo {
        id: GGX_D,
        name: "ggx_d",
        summary: "GGX/Trowbridge-Reitz NDF D(wm), anisotropic (Heitz 2014 eq. 85)",
        inputs: &["wm_x", "wm_y", "wm_z", "alpha_x", "alpha_y"],
        outputs: &["d"],
    },
    FunctionInfo {
        id: GGX_LAMBDA,
        name: "ggx_lambda",
        summary: "GGX Smith Lambda(w) (Heitz 2014 eq. 86)",
        inputs: &["w_x", "w_y", "w_z", "alpha_x", "alpha_y"],
        outputs: &["lambda"],
    },
    FunctionInfo {
        id: GGX_G1,
        name: "ggx_g1",
        summary: "GGX Smith masking G1(w) = 1 / (1 + Lambda(w))",
        inputs: &["w_x", "w_y", "w_z", "alpha_x", "alpha_y"],
        outputs: &["g1"],
    },
    FunctionInfo {
        id: ARITH_PROBE,
        name: "arith_probe",
        summary: "The basic operations every kernel is built from: a+b, a-b, a*b, a/b, sqrt(a), 1/sqrt(a)",
        inputs: &["a", "b"],
        outputs: &["sum", "difference", "product", "quotient", "sqrt", "rsqrt"],
    },
    FunctionInfo {
        id: MATH_UNARY,
        name: "math_unary",
        summary: "The project's own one-argument elementary functions (shader-core math, shader-core/MATH.md)",
        inputs: &["x"],
        outputs: &[
            "sin", "cos", "tan", "atan", "asin", "acos", "exp", "exp2", "expm1", "log", "log2", "log1p", "erf", "erfc",
        ],
    },
    FunctionInfo {
        id: MATH_BINARY,
        name: "math_binary",
        summary: "The project's own two-argument elementary functions: atan2(y, x) and pow(x, y)",
        inputs: &["x", "y"],
        outputs: &["atan2", "pow"],
    },
    // Microfacet NDFs, Lambda/G1, G2 and visibility terms (ids 100..=199, evaluated in
    // `crate::microfacet_table`; docs/microfacet.md).
    FunctionInfo {
        id: microfacet_table::BECKMANN_D,
        name: "beckmann_d",
        summary: "Beckmann NDF D(wm), anisotropic (Walter 2007 eq. 25; Heitz 2014 sec. 5.4)",
        inputs: &["wm_x", "wm_y", "wm_z", "alpha_x", "alpha_y"],
        outputs: &["d"],
    },
    FunctionInfo {
        id: microfacet_table::BLINN_PHONG_D,
        name: "blinn_phong_d",
        summary: "Normalized Blinn-Phong NDF (n + 2)/(2 pi) cos^n (Walter 2007 eq. 30); exponent n >= 0",
        inputs: &["wm_x", "wm_y", "wm_z", "exponent"],
        outputs: &["d"],
    },
    FunctionInfo {
        id: microfacet_table::BLINN_PHONG_EXPONENT,
        name: "blinn_phong_exponent",
        summary: "Blinn-Phong exponent of Beckmann alpha, n = 2/alpha^2 - 2 (Walter 2007 eq. 32)",
        inputs: &["alpha"],
        outputs: &["exponent"],
    },
    FunctionInfo {
        id: microfacet_table::BLINN_PHONG_ALPHA,
        name: "blinn_phong_alpha",
        summary: "Beckmann alpha of a Blinn-Phong exponent, alpha = sqrt(2/(n + 2))",
        inputs: &["exponent"],
        outputs: &["alpha"],
    },
    FunctionInfo {
        id: microfacet_table::GTR1_D,
        name: "gtr1_d",
        summary: "GTR1 / Berry NDF (a^2-1)/(pi ln(a^2)(1 + (a^2-1)cos^2)), 1/pi at a = 1 (Burley 2012 B.2)",
        inputs: &["wm_x", "wm_y", "wm_z", "alpha"],
        outputs: &["d"],
    },
    FunctionInfo {
        id: microfacet_table::GTR2_D,
        name: "gtr2_d",
        summary: "GTR2 NDF a^2/(pi (1 + (a^2-1)cos^2)^2), isotropic GGX (Burley 2012 B.2)",
        inputs: &["wm_x", "wm_y", "wm_z", "alpha"],
        outputs: &["d"],
    },
    FunctionInfo {
        id: microfacet_table::DISNEY_ANISO_ALPHA,
        name: "disney_aniso_alpha",
        summary: "Disney anisotropy: aspect = sqrt(1 - 0.9 k), alpha_x = r^2/aspect, alpha_y = r^2 aspect (Burley 2012 B.2)",
        inputs: &["roughness", "anisotropic"],
        outputs: &["alpha_x", "alpha_y"],
    },
    FunctionInfo {
        id: microfacet_table::GGX_D_UE4,
        name: "ggx_d_ue4",
        summary: "GGX from n.h in UE4's form a^2/(pi ((NoH a^2 - NoH) NoH + 1)^2) (Karis 2013 eq. 2)",
        inputs: &["n_dot_h", "alpha"],
        outputs: &["d"],
    },
    FunctionInfo {
        id: microfacet_table::GGX_D_MOBILE_NAIVE,
        name: "ggx_d_mobile_naive",
        summary: "Filament D_GGX with 1 - NoH^2 computed naively, f32 (Filament PBR doc sec. 4.4.1)",
        inputs: &["n_dot_h", "alpha"],
        outputs: &["d"],
    },
    FunctionInfo {
        id: microfacet_table::GGX_D_MOBILE,
        name: "ggx_d_mobile",
        summary: "Filament mobile D_GGX with |n x h|^2 (Lagrange's identity), unit wh, f32 (Filament PBR doc sec. 4.4.1)",
        inputs: &["wh_x", "wh_y", "wh_z", "alpha"],
        outputs: &["d"],
    },
    FunctionInfo {
        id: microfacet_table::BECKMANN_LAMBDA,
        name: "beckmann_lambda",
        summary: "Exact Beckmann Smith Lambda (erfc; continued fraction for a >= 1.5) (Walter 2007 eq. 26)",
        inputs: &["w_x", "w_y", "w_z", "alpha_x", "alpha_y"],
        outputs: &["lambda"],
    },
    FunctionInfo {
        id: microfacet_table::BECKMANN_G1,
        name: "beckmann_g1",
        summary: "Exact Beckmann Smith G1 = 1/(1 + Lambda) (Heitz 2014 eq. 43)",
        inputs: &["w_x", "w_y", "w_z", "alpha_x", "alpha_y"],
        outputs: &["g1"],
    },
    FunctionInfo {
        id: microfacet_table::BECKMANN_LAMBDA_WALTER,
        name: "beckmann_lambda_walter",
        summary: "Walter's rational Beckmann Lambda (1 - 1.259a + 0.396a^2)/(3.535a + 2.181a^2), a < 1.6 (Walter 2007 eq. 27)",
        inputs: &["w_x", "w_y", "w_z", "alpha_x", "alpha_y"],
        outputs: &["lambda"],
    },
    FunctionInfo {
        id: microfacet_table::BECKMANN_G1_WALTER,
        name: "beckmann_g1_walter",
        summary: "Walter's rational Beckmann G1 (3.535a + 2.181a^2)/(1 + 2.276a + 2.577a^2), a < 1.6 (Walter 2007 eq. 27)",
        inputs: &["w_x", "w_y", "w_z", "alpha_x", "alpha_y"],
        outputs: &["g1"],
    },
    FunctionInfo {
        id: microfacet_table::GGX_G2_SEPARABLE,
        name: "ggx_g2_separable",
        summary: "GGX separable G2 = G1(wo) G1(wi) (Heitz 2014 eq. 98)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "alpha_x", "alpha_y"],
        outputs: &["g"],
    },
    FunctionInfo {
        id: microfacet_table::GGX_G2_HEIGHT_CORRELATED,
        name: "ggx_g2_height_correlated",
        summary: "GGX height-correlated G2 = 1/(1 + Lambda(wo) + Lambda(wi)) (Heitz 2014 eq. 99)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "alpha_x", "alpha_y"],
        outputs: &["g"],
    },
    FunctionInfo {
        id: microfacet_table::GGX_G2_DIRECTION_CORRELATED,
        name: "ggx_g2_direction_correlated",
        summary: "GGX direction-correlated G2 = l(phi) G1o G1i + (1 - l(phi)) min(G1o, G1i) (Heitz 2014 eq. 100)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "alpha_x", "alpha_y"],
        outputs: &["g"],
    },
    FunctionInfo {
        id: microfacet_table::GGX_G2_HEIGHT_DIRECTION_CORRELATED,
        name: "ggx_g2_height_direction_correlated",
        summary: "GGX height-direction-correlated G2 = 1/(1 + max(L) + l(phi) min(L)) (Heitz 2014 eq. 101)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "alpha_x", "alpha_y"],
        outputs: &["g"],
    },
    FunctionInfo {
        id: microfacet_table::BECKMANN_G2_HEIGHT_CORRELATED,
        name: "beckmann_g2_height_correlated",
        summary: "Beckmann height-correlated G2 with the exact Lambda (Heitz 2014 eq. 99)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "alpha_x", "alpha_y"],
        outputs: &["g"],
    },
    FunctionInfo {
        id: microfacet_table::V_FROSTBITE,
        name: "v_frostbite",
        summary: "Frostbite V_SmithGGXCorrelated, exact height-correlated V (Lagarde 2014 listing 2)",
        inputs: &["n_dot_v", "n_dot_l", "alpha"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_HDRP,
        name: "v_hdrp",
        summary: "Unity HDRP V_SmithJointGGX, exact (same arithmetic as v_frostbite)",
        inputs: &["n_dot_v", "n_dot_l", "alpha"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_HDRP_APPROX,
        name: "v_hdrp_approx",
        summary: "Unity HDRP V_SmithJointGGX with GetSmithJointGGXPartLambdaVApprox (view term linearized; not reciprocal)",
        inputs: &["n_dot_v", "n_dot_l", "alpha"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_UE4,
        name: "v_ue4",
        summary: "UE4 Vis_SmithJointApprox 0.5/(n.l(n.v(1-a)+a) + n.v(n.l(1-a)+a))",
        inputs: &["n_dot_v", "n_dot_l", "alpha"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_FILAMENT,
        name: "v_filament",
        summary: "Filament V_SmithGGXCorrelated, exact (same arithmetic as v_frostbite)",
        inputs: &["n_dot_v", "n_dot_l", "alpha"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_FILAMENT_FAST,
        name: "v_filament_fast",
        summary: "Filament V_SmithGGXCorrelated_Fast 0.5/mix(2 n.l n.v, n.l + n.v, a) (= Hammon 2017)",
        inputs: &["n_dot_v", "n_dot_l", "alpha"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_RESPAWN,
        name: "v_respawn",
        summary: "Respawn / Hammon 2017 0.5/lerp(2 n.l n.v, n.l + n.v, a) (RTR4 eq. 9.43)",
        inputs: &["n_dot_v", "n_dot_l", "alpha"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_IMPLICIT,
        name: "v_implicit",
        summary: "Implicit masking G2 = n.l n.v, V = 1/4",
        inputs: &["n_dot_v", "n_dot_l"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_NEUMANN,
        name: "v_neumann",
        summary: "Neumann et al. 1999 G2 = n.l n.v / max(n.l, n.v), V = 1/(4 max(n.l, n.v))",
        inputs: &["n_dot_v", "n_dot_l"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_KELEMEN,
        name: "v_kelemen",
        summary: "Kelemen & Szirmay-Kalos 2001 G2 = n.l n.v / (v.h)^2, V = 1/(4 (v.h)^2)",
        inputs: &["v_dot_h"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_SCHLICK_SMITH,
        name: "v_schlick_smith",
        summary: "Schlick-Smith with Karis's k = alpha/2: 0.25/((n.v(1-k)+k)(n.l(1-k)+k)) (Karis 2013 eq. 4)",
        inputs: &["n_dot_v", "n_dot_l", "alpha"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_SCHLICK_SMITH_REMAPPED,
        name: "v_schlick_smith_remapped",
        summary: "Schlick-Smith with Karis's analytic-light remap k = (sqrt(alpha) + 1)^2/8 (Karis 2013)",
        inputs: &["n_dot_v", "n_dot_l", "alpha"],
        outputs: &["v"],
    },
    FunctionInfo {
        id: microfacet_table::V_COOK_TORRANCE,
        name: "v_cook_torrance",
        summary: "Cook-Torrance V-cavity G2 = min(1, 2 n.h n.v/v.h, 2 n.h n.l/v.h) over 4 n.l n.v (Cook & Torrance 1982)",
        inputs: &["n_dot_v", "n_dot_l", "n_dot_h", "v_dot_h"],
        outputs: &["v"],
    },
    // Fresnel and BxDFs (ids 200..=219, evaluated in `crate::bxdf_table`; docs/bxdf.md).
    FunctionInfo {
        id: bxdf_table::FRESNEL_DIELECTRIC,
        name: "fresnel_dielectric",
        summary: "Dielectric Fresnel reflectance, cos < 0 = inside, TIR -> 1 (PBRT-v4 FrDielectric, eq. 9.5)",
        inputs: &["cos_theta_i", "eta"],
        outputs: &["f"],
    },
    FunctionInfo {
        id: bxdf_table::FRESNEL_CONDUCTOR,
        name: "fresnel_conductor",
        summary: "Conductor Fresnel reflectance for IOR eta + i k (PBRT-v4 FrComplex, eq. 9.6)",
        inputs: &["cos_theta_i", "eta", "k"],
        outputs: &["f"],
    },
    FunctionInfo {
        id: bxdf_table::FRESNEL_SCHLICK,
        name: "fresnel_schlick",
        summary: "Schlick's approximation F0 + (F90 - F0)(1 - |cos|)^5 (Schlick 1994 eq. 24)",
        inputs: &["cos_theta", "f0", "f90"],
        outputs: &["f"],
    },
    FunctionInfo {
        id: bxdf_table::GULBRANDSEN_NK,
        name: "gulbrandsen_nk",
        summary: "Reflectivity r and edge tint g -> conductor IOR (n, k) (Gulbrandsen 2014 eqs. 8-9)",
        inputs: &["r", "g"],
        outputs: &["n", "k"],
    },
    FunctionInfo {
        id: bxdf_table::GULBRANDSEN_RG,
        name: "gulbrandsen_rg",
        summary: "Conductor IOR (n, k) -> reflectivity r and edge tint g (inverse of Gulbrandsen 2014 eqs. 8-9)",
        inputs: &["n", "k"],
        outputs: &["r", "g"],
    },
    FunctionInfo {
        id: bxdf_table::REFRACT,
        name: "refract",
        summary: "Snell refraction of wi about n, eta relative; valid = 0 on TIR (PBRT-v4 Refract, eq. 9.4)",
        inputs: &["wi_x", "wi_y", "wi_z", "n_x", "n_y", "n_z", "eta"],
        outputs: &["wt_x", "wt_y", "wt_z", "etap", "valid"],
    },
    FunctionInfo {
        id: bxdf_table::GGX_VNDF_SAMPLE,
        name: "ggx_vndf_sample",
        summary: "GGX visible normal sample (Heitz 2018, JCGT 7(4) listing 1, as PBRT-v4 Sample_wm)",
        inputs: &["w_x", "w_y", "w_z", "alpha_x", "alpha_y", "u0", "u1"],
        outputs: &["wm_x", "wm_y", "wm_z"],
    },
    FunctionInfo {
        id: bxdf_table::GGX_VNDF_PDF,
        name: "ggx_vndf_pdf",
        summary: "GGX visible normal density G1(w) D(wm) |w.wm| / |w.z| (Heitz 2018 eq. 2)",
        inputs: &["w_x", "w_y", "w_z", "wm_x", "wm_y", "wm_z", "alpha_x", "alpha_y"],
        outputs: &["pdf"],
    },
    FunctionInfo {
        id: bxdf_table::LAMBERT_F,
        name: "lambert_f",
        summary: "Lambertian BRDF R / pi, same hemisphere only (PBRT-v4 DiffuseBxDF::f)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "r_r", "r_g", "r_b"],
        outputs: &["f_r", "f_g", "f_b"],
    },
    FunctionInfo {
        id: bxdf_table::LAMBERT_SAMPLE_F,
        name: "lambert_sample_f",
        summary: "Lambertian sample by the cosine-weighted concentric-disk hemisphere (PBRT-v4 DiffuseBxDF::Sample_f)",
        inputs: &["wo_x", "wo_y", "wo_z", "uc", "u0", "u1", "r_r", "r_g", "r_b"],
        outputs: &["wi_x", "wi_y", "wi_z", "f_r", "f_g", "f_b", "pdf", "flags"],
    },
    FunctionInfo {
        id: bxdf_table::LAMBERT_PDF,
        name: "lambert_pdf",
        summary: "Lambertian sampling density |cos theta_i| / pi, same hemisphere only",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z"],
        outputs: &["pdf"],
    },
    FunctionInfo {
        id: bxdf_table::CONDUCTOR_F,
        name: "conductor_f",
        summary: "Torrance-Sparrow conductor BRDF (no cosine): GGX D, height-correlated G, complex Fresnel per RGB (PBRT-v4 eq. 9.33)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "alpha_x", "alpha_y", "eta_r", "eta_g", "eta_b", "k_r", "k_g", "k_b"],
        outputs: &["f_r", "f_g", "f_b"],
    },
    FunctionInfo {
        id: bxdf_table::CONDUCTOR_SAMPLE_F,
        name: "conductor_sample_f",
        summary: "Conductor sample through GGX visible normals; mirror when alpha < 1e-3 (PBRT-v4 ConductorBxDF::Sample_f)",
        inputs: &["wo_x", "wo_y", "wo_z", "uc", "u0", "u1", "alpha_x", "alpha_y", "eta_r", "eta_g", "eta_b", "k_r", "k_g", "k_b"],
        outputs: &["wi_x", "wi_y", "wi_z", "f_r", "f_g", "f_b", "pdf", "flags"],
    },
    FunctionInfo {
        id: bxdf_table::CONDUCTOR_PDF,
        name: "conductor_pdf",
        summary: "Conductor sampling density D_wo(wm) / (4 |wo.wm|) (PBRT-v4 eq. 9.36)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "alpha_x", "alpha_y"],
        outputs: &["pdf"],
    },
    FunctionInfo {
        id: bxdf_table::DIELECTRIC_F,
        name: "dielectric_f",
        summary: "Rough dielectric BSDF (reflection + transmission, generalized half vector; mode 1 = importance) (PBRT-v4 DielectricBxDF::f)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "alpha_x", "alpha_y", "eta", "mode"],
        outputs: &["f"],
    },
    FunctionInfo {
        id: bxdf_table::DIELECTRIC_SAMPLE_F,
        name: "dielectric_sample_f",
        summary: "Dielectric sample: reflect with probability R/(R+T) else refract (PBRT-v4 DielectricBxDF::Sample_f)",
        inputs: &["wo_x", "wo_y", "wo_z", "uc", "u0", "u1", "alpha_x", "alpha_y", "eta", "mode"],
        outputs: &["wi_x", "wi_y", "wi_z", "f", "pdf", "flags", "etap"],
    },
    FunctionInfo {
        id: bxdf_table::DIELECTRIC_PDF,
        name: "dielectric_pdf",
        summary: "Dielectric sampling density (PBRT-v4 DielectricBxDF::PDF)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "alpha_x", "alpha_y", "eta", "mode"],
        outputs: &["pdf"],
    },
    FunctionInfo {
        id: bxdf_table::GLTF_F,
        name: "gltf_f",
        summary: "glTF 2.0 metal-rough BRDF mix(fresnel_mix(1.5, diffuse, specular), conductor_fresnel(base, specular), metallic), alpha = roughness^2",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "base_r", "base_g", "base_b", "metallic", "roughness"],
        outputs: &["f_r", "f_g", "f_b"],
    },
    FunctionInfo {
        id: bxdf_table::GLTF_SAMPLE_F,
        name: "gltf_sample_f",
        summary: "glTF metal-rough sample: specular (visible normals) or cosine lobe, mixture pdf",
        inputs: &["wo_x", "wo_y", "wo_z", "uc", "u0", "u1", "base_r", "base_g", "base_b", "metallic", "roughness"],
        outputs: &["wi_x", "wi_y", "wi_z", "f_r", "f_g", "f_b", "pdf", "flags"],
    },
    FunctionInfo {
        id: bxdf_table::GLTF_PDF,
        name: "gltf_pdf",
        summary: "glTF metal-rough sampling density (mixture of the specular and cosine lobes)",
        inputs: &["wo_x", "wo_y", "wo_z", "wi_x", "wi_y", "wi_z", "base_r", "base_g", "base_b", "metallic", "roughness"],
        outputs: &["pdf"],
    },
    // Reflection samplers and their densities (ids 400..=407, evaluated in `crate::vndf_table`;
    // docs/vndf.md). wo = reflect(wi, wm); pdf = solid-angle density of wo on the whole sphere.
    FunctionInfo {
        id: vndf_table::SAMPLE_NDF,
        name: "sample_ndf",
        summary: "GGX reflection by classic NDF sampling, pdf D(wm) wm.z / (4 |wi.wm|) (Walter et al. 2007 eqs. 35-38)",
        inputs: vndf_table::SAMPLE_INPUTS,
        outputs: vndf_table::SAMPLE_OUTPUTS,
    },
    FunctionInfo {
        id: vndf_table::SAMPLE_VNDF_HEITZ,
        name: "sample_vndf_heitz",
        summary: "GGX reflection by Heitz 2018 ellipsoid VNDF sampling (JCGT 7(4) listing 1)",
        inputs: vndf_table::SAMPLE_INPUTS,
        outputs: vndf_table::SAMPLE_OUTPUTS,
    },
    FunctionInfo {
        id: vndf_table::SAMPLE_VNDF_CAPS,
        name: "sample_vndf_caps",
        summary: "GGX reflection by Dupuy & Benyoub 2023 spherical-cap VNDF sampling (with the ellipsoid stretch)",
        inputs: vndf_table::SAMPLE_INPUTS,
        outputs: vndf_table::SAMPLE_OUTPUTS,
    },
    FunctionInfo {
        id: vndf_table::SAMPLE_VNDF_BOUNDED,
        name: "sample_vndf_bounded",
        summary: "GGX reflection by Eto & Tokuyoshi 2023 bounded VNDF sampling (SampleGGXReflection)",
        inputs: vndf_table::SAMPLE_INPUTS,
        outputs: vndf_table::SAMPLE_OUTPUTS,
    },
    FunctionInfo {
        id: vndf_table::PDF_NDF,
        name: "pdf_ndf",
        summary: "Density of sample_ndf at wo: D(wm) wm.z / (4 |wi.wm|), wm = +-normalize(wi + wo) with wm.z >= 0",
        inputs: vndf_table::PDF_INPUTS,
        outputs: vndf_table::PDF_OUTPUTS,
    },
    FunctionInfo {
        id: vndf_table::PDF_VNDF_HEITZ,
        name: "pdf_vndf_heitz",
        summary: "Density of sample_vndf_heitz at wo: D(wm) / (2 (wi.z + t)), stable form for wi.z < 0 (Heitz 2018 eq. 2)",
        inputs: vndf_table::PDF_INPUTS,
        outputs: vndf_table::PDF_OUTPUTS,
    },
    FunctionInfo {
        id: vndf_table::PDF_VNDF_CAPS,
        name: "pdf_vndf_caps",
        summary: "Density of sample_vndf_caps at wo (the same as pdf_vndf_heitz)",
        inputs: vndf_table::PDF_INPUTS,
        outputs: vndf_table::PDF_OUTPUTS,
    },
    FunctionInfo {
        id: vndf_table::PDF_VNDF_BOUNDED,
        name: "pdf_vndf_bounded",
        summary: "Density of sample_vndf_bounded at wo: D(wm) / (2 (k wi.z + t)) in the bounded cap (Eto & Tokuyoshi 2023 GGXReflectionPDF)",
        inputs: vndf_table::PDF_INPUTS,
        outputs: vndf_table::PDF_OUTPUTS,
    },
];

#[inline]
fn v3(x: &[f32], b: usize) -> Vec3 {
    Vec3::new(x[b], x[b + 1], x[b + 2])
}

/// Evaluate function `id` on the row starting at `x[xb]`, writing its outputs from `y[yb]`.
/// An unknown id writes nothing.
#[inline]
pub fn eval_row(id: u32, x: &[f32], xb: usize, y: &mut [f32], yb: usize) {
    match id {
        GGX_D => y[yb] = ndf::ggx_d(v3(x, xb), x[xb + 3], x[xb + 4]),
        GGX_LAMBDA => y[yb] = masking::ggx_lambda(v3(x, xb), x[xb + 3], x[xb + 4]),
        GGX_G1 => y[yb] = masking::ggx_g1(v3(x, xb), x[xb + 3], x[xb + 4]),
        ARITH_PROBE => {
            let (a, b) = (x[xb], x[xb + 1]);
            y[yb] = a + b;
            y[yb + 1] = a - b;
            y[yb + 2] = a * b;
            y[yb + 3] = a / b;
            y[yb + 4] = Float::sqrt(a);
            y[yb + 5] = 1.0 / Float::sqrt(a);
        }
        MATH_UNARY => {
            let v = x[xb];
            y[yb] = math::sin(v);
            y[yb + 1] = math::cos(v);
            y[yb + 2] = math::tan(v);
            y[yb + 3] = math::atan(v);
            y[yb + 4] = math::asin(v);
            y[yb + 5] = math::acos(v);
            y[yb + 6] = math::exp(v);
            y[yb + 7] = math::exp2(v);
            y[yb + 8] = math::expm1(v);
            y[yb + 9] = math::log(v);
            y[yb + 10] = math::log2(v);
            y[yb + 11] = math::log1p(v);
            y[yb + 12] = math::erf(v);
            y[yb + 13] = math::erfc(v);
        }
        MATH_BINARY => {
            let (a, b) = (x[xb], x[xb + 1]);
            y[yb] = math::atan2(b, a);
            y[yb + 1] = math::pow(a, b);
        }
        bxdf_table::FIRST..=bxdf_table::LAST => bxdf_table::eval_row(id, x, xb, y, yb),
        vndf_table::FIRST..=vndf_table::LAST => vndf_table::eval_row(id, x, xb, y, yb),
        microfacet_table::FIRST..=microfacet_table::LAST => microfacet_table::eval_row(id, x, xb, y, yb),
        _ => {}
    }
}
