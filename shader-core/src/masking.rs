//! Smith masking-shadowing: Lambda, G1 and the G2 forms, in the local frame (normal = +z).
//!
//! Conventions: directions need not be normalized (every form here is scale invariant); a
//! direction with `w.z == 0` is exactly grazing (Lambda = +inf, G1 = 0); Lambda and G1 use |w.z|
//! (the microsurface is seen from either side the same way; back-facing rejection belongs to the
//! caller that knows the geometry). Roughness conventions are those of [`crate::ndf`].

use crate::ndf::alpha_valid;
use crate::vector::Vec3;
use spirv_std::num_traits::Float;

/// alpha^2 tan^2(theta) of direction `w` for anisotropic roughness: (x^2 ax^2 + y^2 ay^2) / z^2
/// (Heitz 2014, eq. 80 with the projected roughness of eq. 77).
#[inline]
pub fn ggx_alpha2_tan2(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    let ax = w.x * alpha_x;
    let ay = w.y * alpha_y;
    (ax * ax + ay * ay) / (w.z * w.z)
}

/// GGX Smith Lambda (Heitz 2014, eq. 86): (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2, evaluated as
/// a2t2 / (2 (1 + sqrt(1 + a2t2))) to avoid cancellation near normal incidence.
#[inline]
pub fn ggx_lambda(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !alpha_valid(alpha_x, alpha_y) {
        return f32::NAN;
    }
    let a2t2 = ggx_alpha2_tan2(w, alpha_x, alpha_y);
    if a2t2 == f32::INFINITY {
        return f32::INFINITY;
    }
    a2t2 / (2.0 * (1.0 + Float::sqrt(1.0 + a2t2)))
}

/// GGX Smith G1 = 1 / (1 + Lambda) (Heitz 2014, eq. 43), evaluated as
/// 2 |z| / (|z| + sqrt(z^2 + x^2 ax^2 + y^2 ay^2)), which is finite everywhere and 0 at grazing.
#[inline]
pub fn ggx_g1(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !alpha_valid(alpha_x, alpha_y) {
        return f32::NAN;
    }
    let z = w.z.abs();
    let ax = w.x * alpha_x;
    let ay = w.y * alpha_y;
    let r = Float::sqrt(z * z + ax * ax + ay * ay);
    if r == 0.0 {
        // Degenerate direction (zero vector, or alpha = 0 with w = n scaled to 0): no defined angle.
        return f32::NAN;
    }
    2.0 * z / (z + r)
}
