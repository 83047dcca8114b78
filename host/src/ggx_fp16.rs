//! The "mobile" GGX D evaluated in emulated half precision (`half::f16`, every operation rounded to
//! fp16), next to the same formulas in f32 (`shader_core::ndf::ggx_d_mobile*`). This lives on the
//! host because `shader-core` is f32-only; it exists to measure what fp16 does to the two ways of
//! getting 1 - (n.h)^2 (Filament PBR doc sec. 4.4.1; the seed's `GGX_Mobile`):
//!
//! * naive: `1 - NoH * NoH`. Near the peak NoH is within 2^-11 of 1, where fp16 has only 2^-11
//!   spacing: 1 - NoH^2 is quantized to multiples of ~1e-3 and is 0 for every NoH that rounds to 1.
//! * Lagrange: |n x h|^2 = h.x^2 + h.y^2 (n = +z), computed from the small components directly.
//!
//! Each operation is done in f32 and rounded to fp16 (a product of two fp16 is exact in f32; a sum
//! or quotient may be rounded twice, which changes a result in rare ties only). As Filament's
//! `saturateMediump`, the result is clamped to the largest fp16, 65504.

use half::f16;

/// Largest finite fp16 (`MEDIUMP_FLT_MAX`).
pub const MEDIUMP_FLT_MAX: f32 = 65504.0;

#[inline]
fn h(x: f32) -> f16 {
    f16::from_f32(x)
}

#[inline]
fn add(a: f16, b: f16) -> f16 {
    h(a.to_f32() + b.to_f32())
}

#[inline]
fn sub(a: f16, b: f16) -> f16 {
    h(a.to_f32() - b.to_f32())
}

#[inline]
fn mul(a: f16, b: f16) -> f16 {
    h(a.to_f32() * b.to_f32())
}

#[inline]
fn div(a: f16, b: f16) -> f16 {
    h(a.to_f32() / b.to_f32())
}

/// Filament `D_GGX` core in fp16: k = a / (one_minus_noh2 + (NoH a)^2), D = min(k k / pi, 65504).
fn core(n_dot_h: f16, one_minus_noh2: f16, alpha: f16) -> f32 {
    let n = mul(n_dot_h, alpha);
    let k = div(alpha, add(one_minus_noh2, mul(n, n)));
    let d = mul(mul(k, k), h(std::f32::consts::FRAC_1_PI));
    d.to_f32().min(MEDIUMP_FLT_MAX)
}

/// fp16 GGX D with the naive 1 - NoH^2 (inputs rounded to fp16 first). NoH <= 0 gives 0.
pub fn ggx_d_mobile_naive_fp16(n_dot_h: f32, alpha: f32) -> f32 {
    let (c, a) = (h(n_dot_h), h(alpha));
    if c.to_f32() <= 0.0 {
        return 0.0;
    }
    core(c, sub(h(1.0), mul(c, c)), a)
}

/// fp16 GGX D with Lagrange's identity |n x h|^2 = h.x^2 + h.y^2 (`wh` unit, rounded to fp16 first).
pub fn ggx_d_mobile_fp16(wh: [f32; 3], alpha: f32) -> f32 {
    let (x, y, z, a) = (h(wh[0]), h(wh[1]), h(wh[2]), h(alpha));
    if z.to_f32() <= 0.0 {
        return 0.0;
    }
    let nxh2 = add(mul(x, x), mul(y, y));
    core(z, nxh2, a)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn naive_form_loses_the_peak_shape_in_fp16() {
        // alpha = 0.05: at theta_h = 1 degree the exact 1 - NoH^2 = 3.05e-4 is below fp16's
        // spacing at 1, so the naive form sees the peak value; the Lagrange form does not.
        let alpha = 0.05f64;
        let t = 1.0f64.to_radians();
        let exact = crate::microfacet_ref::ggx_d_cos(t.cos(), alpha);
        let wh = [t.sin() as f32, 0.0, t.cos() as f32];
        let naive = ggx_d_mobile_naive_fp16(t.cos() as f32, alpha as f32) as f64;
        let lagrange = ggx_d_mobile_fp16(wh, alpha as f32) as f64;
        assert!((lagrange / exact - 1.0).abs() < 0.01, "lagrange {lagrange} exact {exact}");
        assert!((naive / exact - 1.0).abs() > 0.1, "naive {naive} exact {exact}");
    }
}
