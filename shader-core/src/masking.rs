//! Smith masking-shadowing: Lambda, G1 and the G2 forms, in the local frame (normal = +z), and the
//! engines' visibility terms V = G2 / (4 |n.l| |n.v|).
//!
//! Conventions (asserted by the project's microfacet stress tests):
//! * Directions need not be normalized: every vector form here is scale invariant and evaluated
//!   after an exact power-of-two rescaling ([`Vec3::pow2_rescaled`]), so any finite non-zero
//!   vector works.
//! * A direction with `w.z == 0` is exactly grazing: Lambda = +Inf, G1 = 0, for every alpha >= 0
//!   (alpha = 0 included); so is one whose |z| is below 2^-149 of its largest component (z vanishes
//!   in the rescaling; the exact Lambda there exceeds 1e36 alpha). Lambda is otherwise +Inf only
//!   where the exact value exceeds f32::MAX. The zero vector, and a NaN or infinite component,
//!   give NaN.
//! * Lambda and G1 use |w.z| (the microsurface is seen from either side the same way; back-facing
//!   rejection belongs to the caller that knows the geometry). The G2 forms take (wo, wi) and
//!   likewise use |z| of each; they omit the chi+(wm) factors (as PBRT's `G(wo, wi)`).
//! * Roughness conventions are those of [`crate::ndf`]: finite alpha >= 0; negative, NaN or
//!   infinite alpha gives NaN; alpha = 0 is a smooth surface (Lambda = 0, G1 = 1 off grazing).
//! * Visibility terms take cosines: |cos| is used and clamped to 1 (as engines `saturate(abs())`);
//!   NaN propagates. Their roughness domain is alpha in [0, 1], the engines' (alpha > 1 gives NaN:
//!   the engines' rearranged arithmetic cancels there). V is +Inf only where the exact value is
//!   infinite (both cosines 0, or alpha = 0 with a cosine 0, for the forms whose limit is
//!   1 / (4 n.l n.v); v.h = 0 for Kelemen).
//!
//! ```
//! use shader_core::masking::{ggx_g1, ggx_g2_height_correlated, ggx_lambda, v_smith_ggx_correlated};
//! use shader_core::Vec3;
//! // Along the normal nothing is masked: Lambda = 0, G1 = 1.
//! assert_eq!(ggx_lambda(Vec3::Z, 0.5, 0.5), 0.0);
//! assert_eq!(ggx_g1(Vec3::Z, 0.5, 0.5), 1.0);
//! // Exactly grazing: Lambda = +inf, G1 = 0, even for a smooth surface.
//! let grazing = Vec3::new(1.0, 0.0, 0.0);
//! assert_eq!(ggx_lambda(grazing, 0.5, 0.5), f32::INFINITY);
//! assert_eq!(ggx_g1(grazing, 0.0, 0.0), 0.0);
//! // Scale invariance: the direction need not be normalized.
//! let w = Vec3::new(0.3, 0.4, 0.5);
//! assert_eq!(ggx_g1(w, 0.2, 0.7), ggx_g1(w * 1024.0, 0.2, 0.7));
//! // Height-correlated G2 lies in [0, min(G1(wo), G1(wi))].
//! let (wo, wi) = (Vec3::new(0.8, 0.0, 0.6), Vec3::new(-0.6, 0.0, 0.8));
//! let g2 = ggx_g2_height_correlated(wo, wi, 0.5, 0.5);
//! assert!(g2 > 0.0 && g2 <= ggx_g1(wo, 0.5, 0.5).min(ggx_g1(wi, 0.5, 0.5)));
//! // Invalid roughness gives NaN.
//! assert!(ggx_g1(w, -0.1, 0.5).is_nan());
//! // The visibility term is G2 / (4 n.l n.v).
//! let v = v_smith_ggx_correlated(0.6, 0.8, 0.5);
//! assert!((v - g2 / (4.0 * 0.6 * 0.8)).abs() < 1e-6 * v);
//! ```

use crate::ieee;
use crate::math;
use crate::ndf::alpha_valid;
use crate::vector::Vec3;

/// 1 / sqrt(pi).
const FRAC_1_SQRT_PI: f32 = 0.564_189_6;

#[inline]
fn min2(a: f32, b: f32) -> f32 {
    if b < a {
        b
    } else {
        a
    }
}

#[inline]
fn max2(a: f32, b: f32) -> f32 {
    if b > a {
        b
    } else {
        a
    }
}

#[inline]
fn is_zero(w: Vec3) -> bool {
    w.x == 0.0 && w.y == 0.0 && w.z == 0.0
}

/// alpha^2 tan^2(theta) of direction `w` for anisotropic roughness: (x^2 ax^2 + y^2 ay^2) / z^2
/// (Heitz 2014, eq. 80 with the projected roughness of eq. 77).
#[inline]
pub fn ggx_alpha2_tan2(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    let ax = w.x * alpha_x;
    let ay = w.y * alpha_y;
    ieee::div(ax * ax + ay * ay, w.z * w.z)
}

/// GGX Smith Lambda (Heitz 2014, eq. 86): (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2, evaluated as
/// a2t2 / (2 (1 + sqrt(1 + a2t2))) to avoid cancellation near normal incidence.
#[inline]
pub fn ggx_lambda(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !alpha_valid(alpha_x, alpha_y) || !w.is_finite() || is_zero(w) {
        return f32::NAN;
    }
    // Grazing; also when z is below 2^-149 of the largest component and vanishes in the rescaling.
    let w = w.pow2_rescaled();
    if w.z == 0.0 {
        return f32::INFINITY;
    }
    let ax = w.x * alpha_x;
    let ay = w.y * alpha_y;
    let p = ax * ax + ay * ay;
    if p == 0.0 {
        // Normal incidence or alpha = 0 (z^2 may have underflowed: no 0/0).
        return 0.0;
    }
    let a2t2 = ieee::div(p, w.z * w.z); // = ggx_alpha2_tan2(w, alpha_x, alpha_y)
    if a2t2 == f32::INFINITY {
        // Near grazing alpha^2 tan^2 overflows while Lambda ~ alpha tan / 2 need not:
        // Lambda = (p / (|z| + sqrt(z^2 + p))) / (2 |z|), ordered so nothing underflows early.
        let z = w.z.abs();
        return ieee::div(ieee::div(p, z + ieee::sqrt(z * z + p)), 2.0 * z);
    }
    ieee::div(a2t2, 2.0 * (1.0 + ieee::sqrt(1.0 + a2t2)))
}

/// GGX Smith G1 = 1 / (1 + Lambda) (Heitz 2014, eq. 43), evaluated as
/// 2 |z| / (|z| + sqrt(z^2 + x^2 ax^2 + y^2 ay^2)), which is finite everywhere and 0 at grazing.
#[inline]
pub fn ggx_g1(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !alpha_valid(alpha_x, alpha_y) || !w.is_finite() || is_zero(w) {
        return f32::NAN;
    }
    let w = w.pow2_rescaled();
    if w.z == 0.0 {
        return 0.0;
    }
    let z = w.z.abs();
    let ax = w.x * alpha_x;
    let ay = w.y * alpha_y;
    let r = ieee::sqrt(z * z + ax * ax + ay * ay);
    // r >= |z| exactly; only underflow of z^2 (z < 1e-19 relative, near grazing) can break it.
    let r = if r < z { z } else { r };
    ieee::div(2.0 * z, z + r)
}

/// Beckmann's a = 1 / (alpha_o tan theta) = |z| / sqrt(x^2 ax^2 + y^2 ay^2) (Walter 2007 eq. 26;
/// anisotropic alpha_o from Heitz 2014 eq. 80). Returns +Inf at normal incidence or alpha = 0, 0 at
/// grazing, NaN for invalid input (see the module conventions).
#[inline]
pub fn beckmann_a(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !alpha_valid(alpha_x, alpha_y) || !w.is_finite() || is_zero(w) {
        return f32::NAN;
    }
    let w = w.pow2_rescaled();
    if w.z == 0.0 {
        return 0.0;
    }
    let ax = w.x * alpha_x;
    let ay = w.y * alpha_y;
    let p = ax * ax + ay * ay;
    if p == 0.0 {
        return f32::INFINITY;
    }
    ieee::div(w.z.abs(), ieee::sqrt(p))
}

/// Exact Beckmann Lambda as a function of a (Walter 2007 eq. 26 / Heitz 2014 sec. 5.1):
/// (erf(a) - 1)/2 + exp(-a^2)/(2 a sqrt(pi)) = (exp(-a^2)/(a sqrt(pi)) - erfc(a)) / 2 for a < 1.5;
/// above, the two terms cancel, so erfc is replaced by its Laplace continued fraction
/// exp(-a^2)/sqrt(pi) / (a + K), K = (1/2)/(a + 1/(a + (3/2)/(a + ...))) (32, 24, 12 or 8 levels
/// for a < 2, 3, 5, above: truncation below 1e-8 relative), giving Lambda = exp(-a^2) K /
/// (2 sqrt(pi) a (a + K)) with no cancellation; 0 for a >= 10.5 (below the smallest f32).
/// a = 0: +Inf; a = +Inf: 0.
#[inline]
pub fn beckmann_lambda_from_a(a: f32) -> f32 {
    if a.is_nan() {
        return f32::NAN;
    }
    if a == f32::INFINITY {
        return 0.0;
    }
    if a < 1.5 {
        // Halved before the division so 1/a near f32::MAX does not overflow early.
        ieee::div(math::exp(-(a * a)) * (0.5 * FRAC_1_SQRT_PI), a) - 0.5 * math::erfc(a)
    } else if a >= 10.5 {
        // exp(-a^2) < 2e-48: Lambda < exp(-a^2) / (4 sqrt(pi) a^3) rounds to 0.
        0.0
    } else {
        // Levels so that the truncation error stays below 1e-8 relative (7e-9 at a = 1.5 with 32,
        // 1e-9 at a = 2 with 24, 1e-8 at a = 3 with 12, 2e-9 at a = 5 with 8).
        let mut i: u32 = if a < 2.0 {
            32
        } else if a < 3.0 {
            24
        } else if a < 5.0 {
            12
        } else {
            8
        };
        let mut k = 0.0f32;
        while i > 0 {
            k = ieee::div(i as f32 * 0.5, a + k);
            i -= 1;
        }
        ieee::div(math::exp(-(a * a)) * k * FRAC_1_SQRT_PI, 2.0 * a * (a + k))
    }
}

/// Exact Beckmann Smith Lambda (Walter 2007 eq. 26; Heitz 2014 sec. 5.1), anisotropic through the
/// projected roughness (Heitz 2014 eq. 80), via [`beckmann_lambda_from_a`] (uses `math::erfc`).
#[inline]
pub fn beckmann_lambda(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    beckmann_lambda_from_a(beckmann_a(w, alpha_x, alpha_y))
}

/// Exact Beckmann Smith G1 = 1 / (1 + Lambda) (Heitz 2014 eq. 43 with [`beckmann_lambda`]).
#[inline]
pub fn beckmann_g1(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    ieee::div(1.0, 1.0 + beckmann_lambda(w, alpha_x, alpha_y))
}

/// Walter's rational approximation of the Beckmann Lambda (Walter 2007 eq. 27, written for Lambda
/// as in RTR4 sec. 9.8.1): (1 - 1.259 a + 0.396 a^2) / (3.535 a + 2.181 a^2) for a < 1.6, else 0;
/// clamped to >= 0 (the published numerator is negative for a in (1.548, 1.6), down to -5.6e-5).
#[inline]
pub fn beckmann_lambda_walter(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    let a = beckmann_a(w, alpha_x, alpha_y);
    if a.is_nan() {
        return f32::NAN;
    }
    if a < 1.6 {
        let l = ieee::div(1.0 - 1.259 * a + 0.396 * (a * a), 3.535 * a + 2.181 * (a * a));
        if l > 0.0 {
            l
        } else {
            0.0
        }
    } else {
        0.0
    }
}

/// Walter's rational approximation of the Beckmann G1 (Walter 2007 eq. 27):
/// (3.535 a + 2.181 a^2) / (1 + 2.276 a + 2.577 a^2) for a < 1.6, else 1; clamped to <= 1 (the
/// published rational exceeds 1 for a in (1.548, 1.6), by up to 6e-5).
#[inline]
pub fn beckmann_g1_walter(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    let a = beckmann_a(w, alpha_x, alpha_y);
    if a.is_nan() {
        return f32::NAN;
    }
    if a < 1.6 {
        let g = ieee::div(3.535 * a + 2.181 * (a * a), 1.0 + 2.276 * a + 2.577 * (a * a));
        min2(g, 1.0)
    } else {
        1.0
    }
}

// ---------------------------------------------------------------------------------------------
// G2: joint masking-shadowing from two Lambda values (Heitz 2014 sec. 6). Each form is symmetric
// in (wo, wi) to the bit: the two Lambda (or G1) values are combined with commutative operations.
// ---------------------------------------------------------------------------------------------

/// Separable G2 = G1(wo) G1(wi) (Heitz 2014 eq. 98), from the two Lambda values.
#[inline]
pub fn g2_separable_from_lambda(lambda_o: f32, lambda_i: f32) -> f32 {
    (ieee::div(1.0, 1.0 + lambda_o)) * (ieee::div(1.0, 1.0 + lambda_i))
}

/// Height-correlated G2 = 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014 eq. 99).
#[inline]
pub fn g2_height_correlated_from_lambda(lambda_o: f32, lambda_i: f32) -> f32 {
    ieee::div(1.0, 1.0 + (lambda_o + lambda_i))
}

/// Direction-correlated G2 (Heitz 2014 eq. 100, after Ashikhmin et al. 2000): the separable form
/// blended with the fully correlated one, lambda(phi) G1o G1i + (1 - lambda(phi)) min(G1o, G1i).
#[inline]
pub fn g2_direction_correlated_from_lambda(lambda_o: f32, lambda_i: f32, phi: f32) -> f32 {
    let g1o = ieee::div(1.0, 1.0 + lambda_o);
    let g1i = ieee::div(1.0, 1.0 + lambda_i);
    let l = ginneken_lambda(phi);
    l * (g1o * g1i) + (1.0 - l) * min2(g1o, g1i)
}

/// Height-direction-correlated G2 (Heitz 2014 eq. 101):
/// 1 / (1 + max(Lambda_o, Lambda_i) + lambda(phi) min(Lambda_o, Lambda_i)).
#[inline]
pub fn g2_height_direction_correlated_from_lambda(lambda_o: f32, lambda_i: f32, phi: f32) -> f32 {
    if lambda_o.is_nan() || lambda_i.is_nan() {
        return f32::NAN;
    }
    let hi = max2(lambda_o, lambda_i);
    let lo = min2(lambda_o, lambda_i);
    if hi == f32::INFINITY {
        return 0.0;
    }
    ieee::div(1.0, 1.0 + hi + ginneken_lambda(phi) * lo)
}

/// Van Ginneken et al. 1998's empirical correlation factor (Heitz 2014 eq. 101; RTR4 sec. 9.7):
/// lambda(phi) = 4.41 phi / (4.41 phi + 1), phi in [0, pi] the azimuth between the two directions.
#[inline]
pub fn ginneken_lambda(phi: f32) -> f32 {
    let t = 4.41 * phi;
    ieee::div(t, t + 1.0)
}

/// Azimuth difference phi in [0, pi] between the projections of `wo` and `wi` on the tangent plane:
/// atan2(|o x i|_z, o_xy . i_xy), symmetric in its arguments; 0 when either projection is zero.
#[inline]
pub fn azimuth_difference(wo: Vec3, wi: Vec3) -> f32 {
    let o = wo.pow2_rescaled();
    let i = wi.pow2_rescaled();
    let c = (o.x * i.y - o.y * i.x).abs();
    let d = o.x * i.x + o.y * i.y;
    if c == 0.0 && d == 0.0 {
        return 0.0;
    }
    math::atan2(c, d)
}

/// GGX separable G2 = G1(wo) G1(wi) (Heitz 2014 eq. 98 with eq. 86).
#[inline]
pub fn ggx_g2_separable(wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    ggx_g1(wo, alpha_x, alpha_y) * ggx_g1(wi, alpha_x, alpha_y)
}

/// GGX height-correlated G2 = 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014 eq. 99 with eq. 86).
#[inline]
pub fn ggx_g2_height_correlated(wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    g2_height_correlated_from_lambda(ggx_lambda(wo, alpha_x, alpha_y), ggx_lambda(wi, alpha_x, alpha_y))
}

/// GGX direction-correlated G2 (Heitz 2014 eq. 100, Ashikhmin-style blend, van Ginneken lambda(phi)).
#[inline]
pub fn ggx_g2_direction_correlated(wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    let lo = ggx_lambda(wo, alpha_x, alpha_y);
    let li = ggx_lambda(wi, alpha_x, alpha_y);
    if lo.is_nan() || li.is_nan() {
        return f32::NAN;
    }
    g2_direction_correlated_from_lambda(lo, li, azimuth_difference(wo, wi))
}

/// GGX height-direction-correlated G2 (Heitz 2014 eq. 101 with eq. 86).
#[inline]
pub fn ggx_g2_height_direction_correlated(wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    let lo = ggx_lambda(wo, alpha_x, alpha_y);
    let li = ggx_lambda(wi, alpha_x, alpha_y);
    if lo.is_nan() || li.is_nan() {
        return f32::NAN;
    }
    g2_height_direction_correlated_from_lambda(lo, li, azimuth_difference(wo, wi))
}

/// Beckmann height-correlated G2 (Heitz 2014 eq. 99 with the exact Beckmann Lambda).
#[inline]
pub fn beckmann_g2_height_correlated(wo: Vec3, wi: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    g2_height_correlated_from_lambda(beckmann_lambda(wo, alpha_x, alpha_y), beckmann_lambda(wi, alpha_x, alpha_y))
}

// ---------------------------------------------------------------------------------------------
// Visibility V = G2 / (4 |n.l| |n.v|), isotropic, from cosines (the engines' forms).
// ---------------------------------------------------------------------------------------------

/// The visibility terms' roughness domain: alpha in [0, 1] (the engines clamp roughness there; for
/// alpha > 1 their rearranged arithmetic cancels, e.g. Lagarde's (-c a^2 + c) c + a^2 at c = 1).
#[inline]
fn v_alpha_valid(alpha: f32) -> bool {
    alpha >= 0.0 && alpha <= 1.0
}

/// |c| clamped to 1; NaN stays NaN.
#[inline]
fn sat_abs(c: f32) -> f32 {
    let a = c.abs();
    if a > 1.0 {
        1.0
    } else {
        a
    }
}

/// sqrt((-c a^2 + c) c + a^2) = sqrt(c^2 (1 - a^2) + a^2), the GGX "part lambda" of Lagarde 2014.
#[inline]
fn ggx_part_lambda(c: f32, a2: f32) -> f32 {
    ieee::sqrt((-c * a2 + c) * c + a2)
}

/// Exact height-correlated Smith-GGX visibility, Lagarde's rearrangement (Lagarde & de Rousiers 2014,
/// "Moving Frostbite to PBR", listing 2; RTR4 eq. 9.42): 0.5 / (n.l sqrt((-n.v a^2 + n.v)
/// n.v + a^2) + n.v sqrt((-n.l a^2 + n.l) n.l + a^2)). Shared by [`v_frostbite`], [`v_hdrp`] and
/// [`v_filament`], whose sources use this same sequence of operations.
#[inline]
pub fn v_smith_ggx_correlated(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    if !v_alpha_valid(alpha) {
        return f32::NAN;
    }
    let nv = sat_abs(n_dot_v);
    let nl = sat_abs(n_dot_l);
    let a2 = alpha * alpha;
    let lambda_v = nl * ggx_part_lambda(nv, a2);
    let lambda_l = nv * ggx_part_lambda(nl, a2);
    ieee::div(0.5, lambda_v + lambda_l)
}

/// Frostbite `V_SmithGGXCorrelated` (Lagarde & de Rousiers 2014, listing 2): exact.
#[inline]
pub fn v_frostbite(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha)
}

/// Unity HDRP `V_SmithJointGGX` with `GetSmithJointGGXPartLambdaV` (HDRP `BSDF.hlsl`, after
/// Lagarde 2014): exact; `roughness` there is alpha.
#[inline]
pub fn v_hdrp(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha)
}

/// Google Filament `V_SmithGGXCorrelated` (Filament PBR doc sec. 4.4.2, after Heitz 2014 eq. 99):
/// exact; `roughness` there is alpha.
#[inline]
pub fn v_filament(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha)
}

/// Unity HDRP `V_SmithJointGGX` fed `GetSmithJointGGXPartLambdaVApprox` (HDRP `BSDF.hlsl`, the
/// seed's listing): the view part linearized, n.l (n.v (1 - a) + a), the light part exact,
/// 0.5 / (that + n.v sqrt((-n.l a^2 + n.l) n.l + a^2)). Not symmetric in (v, l).
#[inline]
pub fn v_hdrp_approx(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    if !v_alpha_valid(alpha) {
        return f32::NAN;
    }
    let nv = sat_abs(n_dot_v);
    let nl = sat_abs(n_dot_l);
    let a2 = alpha * alpha;
    let part_lambda_v = nv * (1.0 - alpha) + alpha;
    let lambda_v = nl * part_lambda_v;
    let lambda_l = nv * ggx_part_lambda(nl, a2);
    ieee::div(0.5, lambda_v + lambda_l)
}

/// UE4 `Vis_SmithJointApprox` (UE4 `BRDF.ush`, after Heitz 2014; the seed's listing with
/// a = sqrt(a2) = alpha): 0.5 / (n.l (n.v (1 - a) + a) + n.v (n.l (1 - a) + a)).
#[inline]
pub fn v_ue4(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    if !v_alpha_valid(alpha) {
        return f32::NAN;
    }
    let nv = sat_abs(n_dot_v);
    let nl = sat_abs(n_dot_l);
    let a = alpha;
    let vis_v = nl * (nv * (1.0 - a) + a);
    let vis_l = nv * (nl * (1.0 - a) + a);
    ieee::div(0.5, vis_v + vis_l)
}

/// Hammon's approximation (Hammon 2017, "PBR Diffuse Lighting for GGX+Smith Microsurfaces", GDC;
/// RTR4 eq. 9.43): V = 0.5 / lerp(2 n.l n.v, n.l + n.v, alpha), lerp(x, y, s) = x (1 - s) + y s.
#[inline]
pub fn v_respawn(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    if !v_alpha_valid(alpha) {
        return f32::NAN;
    }
    let nv = sat_abs(n_dot_v);
    let nl = sat_abs(n_dot_l);
    let x = 2.0 * (nl * nv);
    let y = nl + nv;
    ieee::div(0.5, x * (1.0 - alpha) + y * alpha)
}

/// Filament `V_SmithGGXCorrelated_Fast` (Filament PBR doc sec. 4.4.2): 0.5 / mix(2 n.l n.v,
/// n.l + n.v, alpha), which is Hammon's form; GLSL's mix is x (1 - a) + y a, so the arithmetic,
/// and every result, is that of [`v_respawn`].
#[inline]
pub fn v_filament_fast(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    v_respawn(n_dot_v, n_dot_l, alpha)
}

/// Implicit masking (RTR4 sec. 9.8, after Hoffman 2013): G2 = n.l n.v, so V = 1/4 for every
/// configuration (the 0/0 limit at grazing is taken as 1/4). NaN cosines: NaN.
#[inline]
pub fn v_implicit(n_dot_v: f32, n_dot_l: f32) -> f32 {
    if n_dot_v.is_nan() || n_dot_l.is_nan() {
        return f32::NAN;
    }
    0.25
}

/// Neumann et al. 1999 (RTR4 sec. 9.8; UE4 `Vis_Neumann`): G2 = n.l n.v / max(n.l, n.v), so
/// V = 1 / (4 max(n.l, n.v)). Both cosines 0: +Inf.
#[inline]
pub fn v_neumann(n_dot_v: f32, n_dot_l: f32) -> f32 {
    let nv = sat_abs(n_dot_v);
    let nl = sat_abs(n_dot_l);
    if nv.is_nan() || nl.is_nan() {
        return f32::NAN;
    }
    ieee::div(1.0, 4.0 * max2(nv, nl))
}

/// Kelemen & Szirmay-Kalos 2001 (RTR4 sec. 9.8; UE4 `Vis_Kelemen` without its 1e-5): G2 =
/// n.l n.v / (v.h)^2, so V = 1 / (4 (v.h)^2). v.h = 0: +Inf.
#[inline]
pub fn v_kelemen(v_dot_h: f32) -> f32 {
    let vh = sat_abs(v_dot_h);
    ieee::div(1.0, 4.0 * (vh * vh))
}

/// Schlick-Smith (Schlick 1994 G1 = n.v / (n.v (1 - k) + k), fitted to Smith-GGX by Karis 2013,
/// "Real Shading in Unreal Engine 4", eq. 4, with k = alpha / 2; UE4 `Vis_Schlick`):
/// V = 0.25 / ((n.v (1 - k) + k)(n.l (1 - k) + k)).
#[inline]
pub fn v_schlick_smith(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    if !v_alpha_valid(alpha) {
        return f32::NAN;
    }
    schlick_smith_k(sat_abs(n_dot_v), sat_abs(n_dot_l), alpha * 0.5)
}

/// Schlick-Smith with Karis's "hotness" remap for analytic lights (Karis 2013, eq. 4 and the text
/// after it): k = (r + 1)^2 / 8 with perceptual roughness r = sqrt(alpha). Deliberately not a fit
/// of Smith: it reduces the highlight of rough surfaces.
#[inline]
pub fn v_schlick_smith_remapped(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    if !v_alpha_valid(alpha) {
        return f32::NAN;
    }
    let r1 = ieee::sqrt(alpha) + 1.0;
    schlick_smith_k(sat_abs(n_dot_v), sat_abs(n_dot_l), r1 * r1 * 0.125)
}

#[inline]
fn schlick_smith_k(nv: f32, nl: f32, k: f32) -> f32 {
    let gv = nv * (1.0 - k) + k;
    let gl = nl * (1.0 - k) + k;
    ieee::div(0.25, gv * gl)
}

/// Cook-Torrance V-cavity (Cook & Torrance 1982, geometrical attenuation G, after Blinn 1977): G2 =
/// min(1, 2 n.h n.v / v.h, 2 n.h n.l / v.h), as V = min(1 / (4 n.l n.v), n.h / (2 v.h n.l),
/// n.h / (2 v.h n.v)) so the grazing limits stay finite. v.h = 0: the first term alone.
#[inline]
pub fn v_cook_torrance(n_dot_v: f32, n_dot_l: f32, n_dot_h: f32, v_dot_h: f32) -> f32 {
    let nv = sat_abs(n_dot_v);
    let nl = sat_abs(n_dot_l);
    let nh = sat_abs(n_dot_h);
    let vh = sat_abs(v_dot_h);
    if nv.is_nan() || nl.is_nan() || nh.is_nan() || vh.is_nan() {
        return f32::NAN;
    }
    let full = ieee::div(1.0, 4.0 * (nl * nv));
    if vh == 0.0 {
        return full;
    }
    let t = 2.0 * vh;
    min2(full, min2(ieee::div(nh, t * nl), ieee::div(nh, t * nv)))
}
