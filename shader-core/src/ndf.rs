//! Microfacet normal distribution functions D(wm) in the local frame (normal = +z).
//!
//! Conventions shared by every NDF here:
//! * `wm` need not be normalized: each D is evaluated in a scale-invariant form, D(s wm) = D(wm).
//! * D(wm) = 0 for `wm.z <= 0` (the distribution is one-sided, chi+(wm.n) in Heitz 2014).
//! * Roughness `alpha_x`, `alpha_y` must be >= 0. `alpha = 0` is a perfectly smooth surface (a Dirac
//!   delta with no finite density): D returns 0. A negative or NaN alpha returns NaN.
//! * NaN components in `wm` propagate to NaN.

use crate::vector::Vec3;
use core::f32::consts::PI;

/// NaN unless both roughness values are valid (>= 0, not NaN).
#[inline]
pub(crate) fn alpha_valid(alpha_x: f32, alpha_y: f32) -> bool {
    alpha_x >= 0.0 && alpha_y >= 0.0
}

/// Anisotropic GGX / Trowbridge-Reitz NDF (Heitz 2014, "Understanding the Masking-Shadowing
/// Function", eq. 85), evaluated as |wm|^4 / (pi ax ay (x^2/ax^2 + y^2/ay^2 + z^2)^2).
#[inline]
pub fn ggx_d(wm: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !alpha_valid(alpha_x, alpha_y) {
        return f32::NAN;
    }
    if wm.z <= 0.0 || alpha_x == 0.0 || alpha_y == 0.0 {
        return 0.0;
    }
    let sx = wm.x / alpha_x;
    let sy = wm.y / alpha_y;
    let q = sx * sx + sy * sy + wm.z * wm.z;
    let len2 = wm.length_squared();
    // (len2 / q)^2 / (pi ax ay); written as a ratio first so neither q^2 nor len2^2 overflows early.
    let r = len2 / q;
    r * r / (PI * alpha_x * alpha_y)
}
