//! Lights of the scene buffer: `KHR_lights_punctual` directional, point and spot lights (with the
//! extension's recommended range window and smooth spot falloff) and emissive triangles, each
//! picked in proportion to its power from the scene's light CDF (PBRT-v4 section 12.6
//! "Light sampling", `PowerLightSampler`); triangles are sampled uniformly by area and converted
//! to solid angle (PBRT-v4 section 12.3, eq. 12.8 / `Triangle::Sample` with 4.7's area measure).
//!
//! ```
//! use shader_core::pt::light::{select, spot_falloff};
//! use shader_core::pt::scene::HEADER_WORDS;
//! // Full inside the inner cone, zero outside the outer one, (t^2) between.
//! assert_eq!(spot_falloff(0.95, 0.9, 0.8), 1.0);
//! assert_eq!(spot_falloff(0.75, 0.9, 0.8), 0.0);
//! // A scene without lights selects nothing (probability 0).
//! assert_eq!(select(&vec![0u32; HEADER_WORDS], 0.5), (0, 0.0));
//! ```

use super::scene::{self, float, vec3, word, H_LIGHTS, H_LIGHT_CDF_OFF, LIGHT_DIRECTIONAL, LIGHT_POINT, LIGHT_SPOT, LIGHT_TRIANGLE, L_AREA, L_COS_INNER, L_COS_OUTER, L_DIRECTION, L_INTENSITY, L_POSITION, L_RANGE, L_TRIANGLE, L_TYPE};
use super::surface;
use crate::ieee;
use crate::math;
use crate::vector::Vec3;

/// A light sample as seen from a shading point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightSample {
    /// Incident radiance (area lights) or irradiance-like intensity (delta lights) towards the
    /// point, before the selection probability.
    pub li: Vec3,
    /// Unit direction from the point towards the light.
    pub wi: Vec3,
    /// Distance to the light sample (infinite for directional lights).
    pub dist: f32,
    /// Solid-angle density of `wi` for area lights; 1 for delta lights.
    pub pdf: f32,
    /// 1 for a delta (punctual) light, else 0.
    pub delta: u32,
}

impl LightSample {
    /// No contribution.
    pub const NONE: LightSample = LightSample { li: Vec3::ZERO, wi: Vec3::ZERO, dist: 0.0, pdf: 0.0, delta: 0 };
}

/// Number of lights.
#[inline]
pub fn count(sc: &[u32]) -> u32 {
    scene::header(sc, H_LIGHTS)
}

/// Selection CDF value of light `l` (inclusive).
#[inline]
fn cdf(sc: &[u32], l: u32) -> f32 {
    float(sc, scene::header(sc, H_LIGHT_CDF_OFF) as usize + l as usize)
}

/// Probability that [`select`] returns light `l`.
#[inline]
pub fn selection_pdf(sc: &[u32], l: u32) -> f32 {
    let lo = if l == 0 { 0.0 } else { cdf(sc, l - 1) };
    cdf(sc, l) - lo
}

/// The light whose CDF interval holds `u` in [0, 1) (binary search), and its probability;
/// (0, 0) without lights.
#[inline]
pub fn select(sc: &[u32], u: f32) -> (u32, f32) {
    let n = count(sc);
    if n == 0 {
        return (0, 0.0);
    }
    // Smallest l with u < cdf(l).
    let (mut lo, mut hi) = (0u32, n - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if u < cdf(sc, mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    (lo, selection_pdf(sc, lo))
}

/// glTF's recommended range window: (clamp(1 - (d / range)^4, 0, 1))^2, 1 for range 0.
#[inline]
fn range_window(d2: f32, range: f32) -> f32 {
    if !(range > 0.0) {
        return 1.0;
    }
    let r2 = ieee::div(d2, range * range);
    let w = math::clamp(1.0 - r2 * r2, 0.0, 1.0);
    w * w
}

/// Smooth spot falloff of `KHR_lights_punctual`: t^2 with t = clamp((cos - cos_outer) /
/// (cos_inner - cos_outer), 0, 1); a hard edge when the cones coincide.
#[inline]
pub fn spot_falloff(cos_theta: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let span = cos_inner - cos_outer;
    if !(span > 0.0) {
        return if cos_theta >= cos_outer { 1.0 } else { 0.0 };
    }
    let t = math::clamp(ieee::div(cos_theta - cos_outer, span), 0.0, 1.0);
    t * t
}

/// Emitted radiance of triangle light hit point `sp` towards direction `-d` (the ray's): the
/// material's emission on the front face, or on both faces when double sided.
#[inline]
pub fn emitted(sp: &surface::SurfacePoint) -> Vec3 {
    if sp.front != 0 || sp.material.double_sided != 0 {
        sp.material.emission
    } else {
        Vec3::ZERO
    }
}

/// Solid-angle density, from point `p`, of sampling point `q` (unit normal `nq`) on triangle
/// light `l` by area: dist^2 / (|cos_l| area) (without the selection probability).
#[inline]
pub fn triangle_pdf(sc: &[u32], l: u32, p: Vec3, q: Vec3, nq: Vec3) -> f32 {
    let v = q - p;
    let d2 = v.dot(v);
    let cos_l = ieee::div(nq.dot(v), ieee::sqrt(d2)).abs();
    let area = float(sc, scene::light(sc, l, L_AREA));
    if !(cos_l > 0.0) || !(area > 0.0) {
        return 0.0;
    }
    ieee::div(d2, cos_l * area)
}

/// Sample light `l` from point `p` with uniform numbers (u0, u1).
#[inline]
pub fn sample(sc: &[u32], l: u32, p: Vec3, u0: f32, u1: f32) -> LightSample {
    let kind = word(sc, scene::light(sc, l, L_TYPE));
    if kind == LIGHT_TRIANGLE {
        let t = word(sc, scene::light(sc, l, L_TRIANGLE));
        // Uniform barycentrics (PBRT-v4 SampleUniformTriangle's square-root form).
        let su0 = ieee::sqrt(u0);
        let (b1, b2) = (1.0 - su0, u1 * su0);
        let (v0, v1, v2) = scene::triangle(sc, t);
        let q = surface::interpolate(v0, v1, v2, b1, b2);
        let v = q - p;
        let d2 = v.dot(v);
        if !(d2 > 0.0) {
            return LightSample::NONE;
        }
        let dist = ieee::sqrt(d2);
        let wi = v / dist;
        let sp = surface::surface_point(sc, t, b1, b2, wi);
        let pdf = triangle_pdf(sc, l, p, q, sp.ng);
        let li = emitted(&sp);
        if !(pdf > 0.0) || (li.x == 0.0 && li.y == 0.0 && li.z == 0.0) {
            return LightSample::NONE;
        }
        return LightSample { li, wi, dist, pdf, delta: 0 };
    }
    let intensity = vec3(sc, scene::light(sc, l, L_INTENSITY));
    if kind == LIGHT_DIRECTIONAL {
        let wi = -vec3(sc, scene::light(sc, l, L_DIRECTION));
        return LightSample { li: intensity, wi, dist: f32::INFINITY, pdf: 1.0, delta: 1 };
    }
    if kind == LIGHT_POINT || kind == LIGHT_SPOT {
        let v = vec3(sc, scene::light(sc, l, L_POSITION)) - p;
        let d2 = v.dot(v);
        if !(d2 > 0.0) {
            return LightSample::NONE;
        }
        let dist = ieee::sqrt(d2);
        let wi = v / dist;
        let mut scale = ieee::div(range_window(d2, float(sc, scene::light(sc, l, L_RANGE))), d2);
        if kind == LIGHT_SPOT {
            let cos_theta = vec3(sc, scene::light(sc, l, L_DIRECTION)).dot(-wi);
            scale = scale * spot_falloff(cos_theta, float(sc, scene::light(sc, l, L_COS_INNER)), float(sc, scene::light(sc, l, L_COS_OUTER)));
        }
        return LightSample { li: intensity * scale, wi, dist, pdf: 1.0, delta: 1 };
    }
    LightSample::NONE
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spot_falloff_is_smooth_and_bounded() {
        assert_eq!(spot_falloff(1.0, 0.9, 0.8), 1.0);
        assert_eq!(spot_falloff(0.7, 0.9, 0.8), 0.0);
        let mid = spot_falloff(0.85, 0.9, 0.8);
        assert!((mid - 0.25).abs() < 1e-5, "{mid}");
        assert_eq!(spot_falloff(0.85, 0.8, 0.8), 1.0);
    }

    #[test]
    fn range_window_ends_at_the_range() {
        assert_eq!(range_window(4.0, 0.0), 1.0);
        assert_eq!(range_window(4.0, 2.0), 0.0);
        assert!(range_window(1.0, 2.0) > 0.8);
    }
}
