//! Microfacet normal distribution functions D(wm) in the local frame (normal = +z), the roughness
//! parameterizations that feed them, and the reduced-precision GGX forms used on mobile GPUs.
//!
//! Conventions shared by every NDF here (asserted by the project's microfacet stress tests):
//! * `wm` need not be normalized: each D taking a vector is evaluated in a scale-invariant form,
//!   D(s wm) = D(wm), after an exact power-of-two rescaling ([`Vec3::pow2_rescaled`]), so any finite
//!   non-zero vector works, denormal or huge components included. (The `*_mobile*`/`*_ue4` forms
//!   take n.h or a unit `wh` instead; they reproduce engine code and are not scale invariant.)
//! * D(wm) = 0 for `wm.z <= 0` (the distribution is one-sided, chi+(wm.n) in Heitz 2014); the
//!   zero vector has `z = 0` and gives 0.
//! * Roughness `alpha_x`, `alpha_y` must be finite and >= 0. `alpha = 0` is a perfectly smooth
//!   surface (a Dirac delta with no finite density): D returns 0. A negative, NaN or infinite alpha
//!   returns NaN. Physically meaningful roughness is <= ~1; every D here is finite for alpha up to
//!   at least 1e4.
//! * A NaN or infinite component in `wm` returns NaN.
//! * D is +Inf only where the true density exceeds `f32::MAX` (alpha below ~1e-19 at the peak).
//!
//! ```
//! use core::f32::consts::PI;
//! use shader_core::ndf::{beckmann_d, ggx_d};
//! use shader_core::Vec3;
//! // GGX D at the peak (wm = n) is 1 / (pi alpha^2), to the bit.
//! for alpha in [0.05f32, 0.3, 1.0] {
//!     assert_eq!(ggx_d(Vec3::Z, alpha, alpha), 1.0 / (PI * alpha * alpha));
//! }
//! // One-sided: no density below the surface; alpha = 0 (a Dirac) has no finite density.
//! assert_eq!(ggx_d(Vec3::new(0.0, 0.6, -0.8), 0.3, 0.3), 0.0);
//! assert_eq!(ggx_d(Vec3::Z, 0.0, 0.0), 0.0);
//! // Scale invariant: wm need not be normalized.
//! let wm = Vec3::new(0.2, -0.1, 0.9);
//! assert_eq!(ggx_d(wm, 0.4, 0.2), ggx_d(wm * 8.0, 0.4, 0.2));
//! // Invalid roughness or a NaN component: NaN.
//! assert!(ggx_d(wm, -0.1, 0.2).is_nan());
//! assert!(beckmann_d(Vec3::new(f32::NAN, 0.0, 1.0), 0.3, 0.3).is_nan());
//! ```

use crate::ieee;
use crate::math;
use crate::vector::Vec3;
use core::f32::consts::PI;

/// False unless both roughness values are valid (finite and >= 0; NaN is invalid): the one
/// roughness check of the NDFs, the masking functions, the samplers and the BxDFs.
#[inline]
pub fn alpha_valid(alpha_x: f32, alpha_y: f32) -> bool {
    alpha_x >= 0.0 && alpha_y >= 0.0 && alpha_x < f32::INFINITY && alpha_y < f32::INFINITY
}

/// Anisotropic GGX / Trowbridge-Reitz NDF (Heitz 2014, "Understanding the Masking-Shadowing
/// Function", eq. 85), evaluated as |wm|^4 / (pi ax ay (x^2/ax^2 + y^2/ay^2 + z^2)^2).
#[inline]
pub fn ggx_d(wm: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !alpha_valid(alpha_x, alpha_y) || !wm.is_finite() {
        return f32::NAN;
    }
    if wm.z <= 0.0 || alpha_x == 0.0 || alpha_y == 0.0 {
        return 0.0;
    }
    let wm = wm.pow2_rescaled();
    let sx = ieee::div(wm.x, alpha_x);
    let sy = ieee::div(wm.y, alpha_y);
    let q = sx * sx + sy * sy + wm.z * wm.z;
    let len2 = wm.length_squared();
    // (len2 / q)^2 / (pi ax ay); written as a ratio first so neither q^2 nor len2^2 overflows early.
    let r = ieee::div(len2, q);
    ieee::div(r * r, PI * alpha_x * alpha_y)
}

/// Anisotropic Beckmann NDF (Walter et al. 2007, "Microfacet Models for Refraction", eq. 25;
/// anisotropic form Heitz 2014 sec. 5.4): exp(-tan^2(theta) (cos^2 phi/ax^2 + sin^2 phi/ay^2))
/// / (pi ax ay cos^4 theta), evaluated as exp(-(x^2/ax^2 + y^2/ay^2)/z^2) (|wm|^2/z^2)^2 / (pi ax ay).
#[inline]
pub fn beckmann_d(wm: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !alpha_valid(alpha_x, alpha_y) || !wm.is_finite() {
        return f32::NAN;
    }
    if wm.z <= 0.0 || alpha_x == 0.0 || alpha_y == 0.0 {
        return 0.0;
    }
    let wm = wm.pow2_rescaled();
    let sx = ieee::div(wm.x, alpha_x);
    let sy = ieee::div(wm.y, alpha_y);
    let z2 = wm.z * wm.z;
    let e = math::exp(-(ieee::div(sx * sx + sy * sy, z2)));
    if e == 0.0 {
        // Far tail (or z^2 underflowed): the density is below the smallest float.
        return 0.0;
    }
    let r = ieee::div(wm.length_squared(), z2); // 1 / cos^2(theta)
    ieee::div(e * r * r, PI * alpha_x * alpha_y)
}

/// Blinn-Phong exponent equivalent to Beckmann roughness alpha (Walter 2007, eq. 32;
/// RTR4 sec. 9.8.1): n = 2 / alpha^2 - 2. alpha = 0 gives +Inf (a mirror); alpha > 1 gives a
/// negative exponent, which [`blinn_phong_d`] rejects. Negative, NaN or infinite alpha: NaN.
#[inline]
pub fn blinn_phong_exponent_from_alpha(alpha: f32) -> f32 {
    if !alpha_valid(alpha, alpha) {
        return f32::NAN;
    }
    ieee::div(2.0, alpha * alpha) - 2.0
}

/// Inverse of [`blinn_phong_exponent_from_alpha`]: alpha = sqrt(2 / (n + 2)); n = +Inf gives 0.
/// Exponents below 0 (no alpha <= 1 maps there) or NaN give NaN.
#[inline]
pub fn blinn_phong_alpha_from_exponent(exponent: f32) -> f32 {
    if !(exponent >= 0.0) {
        return f32::NAN;
    }
    ieee::sqrt(ieee::div(2.0, exponent + 2.0))
}

/// Normalized Blinn-Phong NDF (Walter 2007, eq. 30; RTR4 sec. 9.8.1):
/// D = (n + 2) / (2 pi) cos^n(theta), with cos^n = exp(-(n/2) log1p(tan^2 theta)).
/// `exponent` n >= 0 (n = 0 is the uniform 1/pi; n = +Inf a mirror: 0); n < 0 or NaN: NaN.
#[inline]
pub fn blinn_phong_d(wm: Vec3, exponent: f32) -> f32 {
    if !(exponent >= 0.0) || !wm.is_finite() {
        return f32::NAN;
    }
    if wm.z <= 0.0 || exponent == f32::INFINITY {
        return 0.0;
    }
    let norm = ieee::div(exponent + 2.0, 2.0 * PI);
    if exponent == 0.0 {
        return norm;
    }
    let wm = wm.pow2_rescaled();
    let t2 = ieee::div(wm.x * wm.x + wm.y * wm.y, wm.z * wm.z); // tan^2(theta)
    norm * math::exp(-(0.5 * exponent) * math::log1p(t2))
}

/// Berry / GTR1 NDF, the clearcoat lobe of the Disney BRDF (Burley 2012, "Physically-Based Shading
/// at Disney", appendix B.2, GTR with gamma = 1): D = (a^2 - 1) / (pi ln(a^2) (1 + (a^2 - 1) cos^2)),
/// evaluated as c |wm|^2 / (x^2 + y^2 + a^2 z^2) with c = (a^2 - 1) / (pi ln a^2) -> 1/pi at a = 1.
/// Burley uses alpha in (0, 1); the form is normalized for every alpha > 0 and is used so here.
#[inline]
pub fn gtr1_d(wm: Vec3, alpha: f32) -> f32 {
    if !alpha_valid(alpha, alpha) || !wm.is_finite() {
        return f32::NAN;
    }
    if wm.z <= 0.0 || alpha == 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let x = a2 - 1.0;
    let c = if x == 0.0 {
        ieee::div(1.0, PI)
    } else {
        // ln(a^2): log1p near alpha = 1 (no cancellation), 2 ln(alpha) elsewhere (a^2 may underflow).
        let l = if alpha > 0.5 && alpha < 2.0 { math::log1p(x) } else { 2.0 * math::log(alpha) };
        ieee::div(x, PI * l)
    };
    let wm = wm.pow2_rescaled();
    let den = wm.x * wm.x + wm.y * wm.y + a2 * (wm.z * wm.z);
    if den == 0.0 {
        // At the peak with a^2 underflowed to 0: the density exceeds f32::MAX.
        return f32::INFINITY;
    }
    c * (ieee::div(wm.length_squared(), den))
}

/// GTR2 NDF (Burley 2012, appendix B.2, GTR with gamma = 2; identical to isotropic GGX):
/// D = a^2 / (pi (1 + (a^2 - 1) cos^2)^2), evaluated as a^2 (|wm|^2 / (x^2 + y^2 + a^2 z^2))^2 / pi.
/// Same function as [`ggx_d`] with `alpha_x = alpha_y = alpha`, different rounding.
#[inline]
pub fn gtr2_d(wm: Vec3, alpha: f32) -> f32 {
    if !alpha_valid(alpha, alpha) || !wm.is_finite() {
        return f32::NAN;
    }
    if wm.z <= 0.0 || alpha == 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let wm = wm.pow2_rescaled();
    let den = wm.x * wm.x + wm.y * wm.y + a2 * (wm.z * wm.z);
    if den == 0.0 {
        return f32::INFINITY;
    }
    let r = ieee::div(wm.length_squared(), den);
    ieee::div(a2 * r * r, PI)
}

/// Disney anisotropy (Burley 2012, appendix B.2): aspect = sqrt(1 - 0.9 anisotropic),
/// alpha_x = r^2 / aspect, alpha_y = r^2 aspect (the 0.9 caps the ratio at 10:1).
/// `roughness` r >= 0 finite and `anisotropic` in [0, 1]; anything else gives (NaN, NaN).
#[inline]
pub fn disney_aniso_alphas(roughness: f32, anisotropic: f32) -> (f32, f32) {
    if !(roughness >= 0.0 && roughness < f32::INFINITY && anisotropic >= 0.0 && anisotropic <= 1.0) {
        return (f32::NAN, f32::NAN);
    }
    let aspect = ieee::sqrt(1.0 - 0.9 * anisotropic);
    let alpha = roughness * roughness;
    (ieee::div(alpha, aspect), alpha * aspect)
}

/// GGX in UE4's form (Karis 2013, "Real Shading in Unreal Engine 4", eq. 2; UE4 `D_GGX`):
/// d = (NoH a^2 - NoH) NoH + 1, D = a^2 / (pi d^2). Isotropic, from n.h alone, so it suffers the
/// cancellation in 1 - NoH^2 near the peak. NoH <= 0: 0; NoH > 1 is clamped to 1; alpha as [`ggx_d`].
#[inline]
pub fn ggx_d_ue4(n_dot_h: f32, alpha: f32) -> f32 {
    if !alpha_valid(alpha, alpha) || n_dot_h.is_nan() {
        return f32::NAN;
    }
    if n_dot_h <= 0.0 || alpha == 0.0 {
        return 0.0;
    }
    let c = if n_dot_h > 1.0 { 1.0 } else { n_dot_h };
    let a2 = alpha * alpha;
    let d = (c * a2 - c) * c + 1.0;
    ieee::div(a2, PI * d * d)
}

/// Filament's GGX (Filament PBR doc sec. 4.4.1, `D_GGX`) with 1 - NoH^2 evaluated naively (the
/// fp32 path, `MOBILE_GGX_USE_FP16 = 0`, of the seed's `GGX_Mobile`): k = a / ((1 - NoH^2) +
/// (NoH a)^2), D = k^2 / pi. NoH <= 0: 0; NoH > 1 clamped; alpha as [`ggx_d`].
#[inline]
pub fn ggx_d_mobile_naive(n_dot_h: f32, alpha: f32) -> f32 {
    if !alpha_valid(alpha, alpha) || n_dot_h.is_nan() {
        return f32::NAN;
    }
    if n_dot_h <= 0.0 || alpha == 0.0 {
        return 0.0;
    }
    let c = if n_dot_h > 1.0 { 1.0 } else { n_dot_h };
    let one_minus_noh2 = 1.0 - c * c;
    ggx_d_mobile_core(c, one_minus_noh2, alpha)
}

/// Filament's mobile GGX (Filament PBR doc sec. 4.4.1, the listing optimized for fp16: `D_GGX`
/// with `cross(n, h)`): 1 - NoH^2 taken from Lagrange's identity |n x h|^2 = 1 - (n.h)^2, which for
/// n = +z is wh.x^2 + wh.y^2, computed without cancellation. `wh` must be unit length (as in
/// Filament; the form is not scale invariant). wh.z <= 0: 0; non-finite wh or invalid alpha: NaN.
#[inline]
pub fn ggx_d_mobile(wh: Vec3, alpha: f32) -> f32 {
    if !alpha_valid(alpha, alpha) || !wh.is_finite() {
        return f32::NAN;
    }
    if wh.z <= 0.0 || alpha == 0.0 {
        return 0.0;
    }
    let nxh2 = wh.x * wh.x + wh.y * wh.y;
    ggx_d_mobile_core(wh.z, nxh2, alpha)
}

/// k = a / (sin^2 + (cos a)^2), D = k^2 / pi (Filament `D_GGX`); shared by the two mobile forms.
#[inline]
fn ggx_d_mobile_core(n_dot_h: f32, one_minus_noh2: f32, alpha: f32) -> f32 {
    let n = n_dot_h * alpha;
    let den = one_minus_noh2 + n * n;
    if den == 0.0 {
        return f32::INFINITY;
    }
    let k = ieee::div(alpha, den);
    k * k * (ieee::div(1.0, PI))
}
