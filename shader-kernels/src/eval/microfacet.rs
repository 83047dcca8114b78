//! Microfacet NDFs and roughness parameterizations, Beckmann Lambda/G1, G2 forms and
//! visibility terms of `shader_core::{ndf, masking}` (docs/microfacet.md documents each
//! function, its source and its invalid-input behaviour).

use shader_core::{masking, ndf};

crate::evaluable! { group = "microfacet";
    beckmann_d "Beckmann NDF D(wm), anisotropic (Walter 2007 eq. 25; Heitz 2014 sec. 5.4)"
        (wm: Vec3, alpha_x: f32, alpha_y: f32) -> (d: f32) { ndf::beckmann_d(wm, alpha_x, alpha_y) }
    blinn_phong_d "Normalized Blinn-Phong NDF (n + 2)/(2 pi) cos^n (Walter 2007 eq. 30); exponent n >= 0"
        (wm: Vec3, exponent: f32) -> (d: f32) { ndf::blinn_phong_d(wm, exponent) }
    blinn_phong_exponent "Blinn-Phong exponent of Beckmann alpha, n = 2/alpha^2 - 2 (Walter 2007 eq. 32)"
        (alpha: f32) -> (exponent: f32) { ndf::blinn_phong_exponent_from_alpha(alpha) }
    blinn_phong_alpha "Beckmann alpha of a Blinn-Phong exponent, alpha = sqrt(2/(n + 2))"
        (exponent: f32) -> (alpha: f32) { ndf::blinn_phong_alpha_from_exponent(exponent) }
    gtr1_d "GTR1 / Berry NDF (a^2-1)/(pi ln(a^2)(1 + (a^2-1)cos^2)), 1/pi at a = 1 (Burley 2012 B.2)"
        (wm: Vec3, alpha: f32) -> (d: f32) { ndf::gtr1_d(wm, alpha) }
    gtr2_d "GTR2 NDF a^2/(pi (1 + (a^2-1)cos^2)^2), isotropic GGX (Burley 2012 B.2)"
        (wm: Vec3, alpha: f32) -> (d: f32) { ndf::gtr2_d(wm, alpha) }
    disney_aniso_alpha "Disney anisotropy: aspect = sqrt(1 - 0.9 k), alpha_x = r^2/aspect, alpha_y = r^2 aspect (Burley 2012 B.2)"
        (roughness: f32, anisotropic: f32) -> (alpha_x: f32, alpha_y: f32) { ndf::disney_aniso_alphas(roughness, anisotropic) }
    ggx_d_ue4 "GGX from n.h in UE4's form a^2/(pi ((NoH a^2 - NoH) NoH + 1)^2) (Karis 2013 eq. 2)"
        (n_dot_h: f32, alpha: f32) -> (d: f32) { ndf::ggx_d_ue4(n_dot_h, alpha) }
    ggx_d_mobile_naive "Filament D_GGX with 1 - NoH^2 computed naively, f32 (Filament PBR doc sec. 4.4.1)"
        (n_dot_h: f32, alpha: f32) -> (d: f32) { ndf::ggx_d_mobile_naive(n_dot_h, alpha) }
    ggx_d_mobile "Filament mobile D_GGX with |n x h|^2 (Lagrange's identity), unit wh, f32 (Filament PBR doc sec. 4.4.1)"
        (wh: Vec3, alpha: f32) -> (d: f32) { ndf::ggx_d_mobile(wh, alpha) }
    beckmann_lambda "Exact Beckmann Smith Lambda (erfc; continued fraction for a >= 1.5) (Walter 2007 eq. 26)"
        (w: Vec3, alpha_x: f32, alpha_y: f32) -> (lambda: f32) { masking::beckmann_lambda(w, alpha_x, alpha_y) }
    beckmann_g1 "Exact Beckmann Smith G1 = 1/(1 + Lambda) (Heitz 2014 eq. 43)"
        (w: Vec3, alpha_x: f32, alpha_y: f32) -> (g1: f32) { masking::beckmann_g1(w, alpha_x, alpha_y) }
    beckmann_lambda_walter "Walter's rational Beckmann Lambda (1 - 1.259a + 0.396a^2)/(3.535a + 2.181a^2), a < 1.6 (Walter 2007 eq. 27)"
        (w: Vec3, alpha_x: f32, alpha_y: f32) -> (lambda: f32) { masking::beckmann_lambda_walter(w, alpha_x, alpha_y) }
    beckmann_g1_walter "Walter's rational Beckmann G1 (3.535a + 2.181a^2)/(1 + 2.276a + 2.577a^2), a < 1.6 (Walter 2007 eq. 27)"
        (w: Vec3, alpha_x: f32, alpha_y: f32) -> (g1: f32) { masking::beckmann_g1_walter(w, alpha_x, alpha_y) }
    ggx_g2_separable "GGX separable G2 = G1(wo) G1(wi) (Heitz 2014 eq. 98)"
        (wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> (g: f32) { masking::ggx_g2_separable(wo, wi, alpha_x, alpha_y) }
    ggx_g2_height_correlated "GGX height-correlated G2 = 1/(1 + Lambda(wo) + Lambda(wi)) (Heitz 2014 eq. 99)"
        (wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> (g: f32) { masking::ggx_g2_height_correlated(wo, wi, alpha_x, alpha_y) }
    ggx_g2_direction_correlated "GGX direction-correlated G2 = l(phi) G1o G1i + (1 - l(phi)) min(G1o, G1i) (Heitz 2014 eq. 100)"
        (wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> (g: f32) { masking::ggx_g2_direction_correlated(wo, wi, alpha_x, alpha_y) }
    ggx_g2_height_direction_correlated "GGX height-direction-correlated G2 = 1/(1 + max(L) + l(phi) min(L)) (Heitz 2014 eq. 101)"
        (wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> (g: f32) { masking::ggx_g2_height_direction_correlated(wo, wi, alpha_x, alpha_y) }
    beckmann_g2_height_correlated "Beckmann height-correlated G2 with the exact Lambda (Heitz 2014 eq. 99)"
        (wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> (g: f32) { masking::beckmann_g2_height_correlated(wo, wi, alpha_x, alpha_y) }
    v_frostbite "Frostbite V_SmithGGXCorrelated, exact height-correlated V (Lagarde 2014 listing 2)"
        (n_dot_v: f32, n_dot_l: f32, alpha: f32) -> (v: f32) { masking::v_frostbite(n_dot_v, n_dot_l, alpha) }
    v_hdrp "Unity HDRP V_SmithJointGGX, exact (same arithmetic as v_frostbite)"
        (n_dot_v: f32, n_dot_l: f32, alpha: f32) -> (v: f32) { masking::v_hdrp(n_dot_v, n_dot_l, alpha) }
    v_hdrp_approx "Unity HDRP V_SmithJointGGX with GetSmithJointGGXPartLambdaVApprox (view term linearized; not reciprocal)"
        (n_dot_v: f32, n_dot_l: f32, alpha: f32) -> (v: f32) { masking::v_hdrp_approx(n_dot_v, n_dot_l, alpha) }
    v_ue4 "UE4 Vis_SmithJointApprox 0.5/(n.l(n.v(1-a)+a) + n.v(n.l(1-a)+a))"
        (n_dot_v: f32, n_dot_l: f32, alpha: f32) -> (v: f32) { masking::v_ue4(n_dot_v, n_dot_l, alpha) }
    v_filament "Filament V_SmithGGXCorrelated, exact (same arithmetic as v_frostbite)"
        (n_dot_v: f32, n_dot_l: f32, alpha: f32) -> (v: f32) { masking::v_filament(n_dot_v, n_dot_l, alpha) }
    v_filament_fast "Filament V_SmithGGXCorrelated_Fast 0.5/mix(2 n.l n.v, n.l + n.v, a) (= Hammon 2017)"
        (n_dot_v: f32, n_dot_l: f32, alpha: f32) -> (v: f32) { masking::v_filament_fast(n_dot_v, n_dot_l, alpha) }
    v_respawn "Respawn / Hammon 2017 0.5/lerp(2 n.l n.v, n.l + n.v, a) (RTR4 eq. 9.43)"
        (n_dot_v: f32, n_dot_l: f32, alpha: f32) -> (v: f32) { masking::v_respawn(n_dot_v, n_dot_l, alpha) }
    v_implicit "Implicit masking G2 = n.l n.v, V = 1/4"
        (n_dot_v: f32, n_dot_l: f32) -> (v: f32) { masking::v_implicit(n_dot_v, n_dot_l) }
    v_neumann "Neumann et al. 1999 G2 = n.l n.v / max(n.l, n.v), V = 1/(4 max(n.l, n.v))"
        (n_dot_v: f32, n_dot_l: f32) -> (v: f32) { masking::v_neumann(n_dot_v, n_dot_l) }
    v_kelemen "Kelemen & Szirmay-Kalos 2001 G2 = n.l n.v / (v.h)^2, V = 1/(4 (v.h)^2)"
        (v_dot_h: f32) -> (v: f32) { masking::v_kelemen(v_dot_h) }
    v_schlick_smith "Schlick-Smith with Karis's k = alpha/2: 0.25/((n.v(1-k)+k)(n.l(1-k)+k)) (Karis 2013 eq. 4)"
        (n_dot_v: f32, n_dot_l: f32, alpha: f32) -> (v: f32) { masking::v_schlick_smith(n_dot_v, n_dot_l, alpha) }
    v_schlick_smith_remapped "Schlick-Smith with Karis's analytic-light remap k = (sqrt(alpha) + 1)^2/8 (Karis 2013)"
        (n_dot_v: f32, n_dot_l: f32, alpha: f32) -> (v: f32) { masking::v_schlick_smith_remapped(n_dot_v, n_dot_l, alpha) }
    v_cook_torrance "Cook-Torrance V-cavity G2 = min(1, 2 n.h n.v/v.h, 2 n.h n.l/v.h) over 4 n.l n.v (Cook & Torrance 1982)"
        (n_dot_v: f32, n_dot_l: f32, n_dot_h: f32, v_dot_h: f32) -> (v: f32) { masking::v_cook_torrance(n_dot_v, n_dot_l, n_dot_h, v_dot_h) }
}
