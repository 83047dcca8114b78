//! Distant environment lighting: a uniform radiance, or an equirectangular (latitude-longitude)
//! map importance-sampled by a piecewise-constant 2D distribution over its texels weighted by
//! luminance x sin(theta) (PBRT-v4 section 12.5.2 "Image infinite lights" and A.4.5
//! `PiecewiseConstant2D`; the solid-angle density is p(u, v) / (2 pi^2 sin theta), eq. 12.7).
//!
//! The environment buffer (`&[f32]`, written by the host) is a header of [`ENV_HEADER`] floats,
//! then for a map of `w x h` texels: the RGB texels (3 w h, row 0 = the top, +y), the texels'
//! density p(u, v) (w h), the inclusive marginal CDF over rows (h) and the inclusive conditional
//! CDF of each row (h x w); every CDF ends at 1.
//!
//! Directions: y is up; theta = acos(y) from +y, phi = atan2(x, -z), so the map's centre column
//! (u = 1/2) is the -z direction and u grows towards +x. The map is turned about +y by the
//! rotation whose cos / sin the header holds.
//!
//! ```
//! use shader_core::pt::environment::{direction_to_uv, pdf, radiance, sample, E_COLOR, E_KIND, ENV_HEADER, KIND_UNIFORM};
//! use shader_core::Vec3;
//! // -z is the centre of the map; +y its top row.
//! let (u, v, _) = direction_to_uv(Vec3::new(0.0, 0.0, -1.0));
//! assert_eq!((u, v), (0.5, 0.5));
//! // A uniform environment: the same radiance everywhere, sampled uniformly over the sphere.
//! let mut env = vec![0.0f32; ENV_HEADER];
//! env[E_KIND] = KIND_UNIFORM as f32;
//! env[E_COLOR..E_COLOR + 3].copy_from_slice(&[0.5, 1.0, 2.0]);
//! let s = sample(&env, 0.3, 0.7);
//! assert_eq!(s.li, Vec3::new(0.5, 1.0, 2.0));
//! assert_eq!(s.pdf, pdf(&env, s.wi));
//! assert!((s.pdf - 1.0 / (4.0 * std::f32::consts::PI)).abs() < 1e-7);
//! assert_eq!(radiance(&env, Vec3::new(0.0, 1.0, 0.0)), s.li);
//! ```

use crate::buffer::load;
use crate::ieee;
use crate::math;
use crate::vector::Vec3;
use core::f32::consts::PI;

/// Header floats.
pub const ENV_HEADER: usize = 16;
/// Header float: [`KIND_BLACK`], [`KIND_UNIFORM`] or [`KIND_MAP`].
pub const E_KIND: usize = 0;
/// Header floats: uniform radiance, or the map's RGB scale (3 floats).
pub const E_COLOR: usize = 1;
/// Header float: map width.
pub const E_WIDTH: usize = 4;
/// Header float: map height.
pub const E_HEIGHT: usize = 5;
/// Header float: cos of the map's rotation about +y.
pub const E_ROT_COS: usize = 6;
/// Header float: sin of the map's rotation about +y.
pub const E_ROT_SIN: usize = 7;
/// No environment (black).
pub const KIND_BLACK: u32 = 0;
/// Uniform radiance from every direction.
pub const KIND_UNIFORM: u32 = 1;
/// Equirectangular map.
pub const KIND_MAP: u32 = 2;

/// The environment's kind.
#[inline]
pub fn kind(env: &[f32]) -> u32 {
    load(env, E_KIND) as u32
}

#[inline]
fn dims(env: &[f32]) -> (u32, u32) {
    (load(env, E_WIDTH) as u32, load(env, E_HEIGHT) as u32)
}

#[inline]
fn scale(env: &[f32]) -> Vec3 {
    Vec3::new(load(env, E_COLOR), load(env, E_COLOR + 1), load(env, E_COLOR + 2))
}

/// World direction -> map direction (the inverse of the map's rotation).
#[inline]
fn to_map(env: &[f32], d: Vec3) -> Vec3 {
    let (c, s) = (load(env, E_ROT_COS), load(env, E_ROT_SIN));
    Vec3::new(c * d.x + s * d.z, d.y, c * d.z - s * d.x)
}

/// Map direction -> world direction.
#[inline]
fn to_world(env: &[f32], d: Vec3) -> Vec3 {
    let (c, s) = (load(env, E_ROT_COS), load(env, E_ROT_SIN));
    Vec3::new(c * d.x - s * d.z, d.y, c * d.z + s * d.x)
}

/// Map coordinates (u, v) in [0, 1]^2 of unit map direction `d`, and sin(theta) = sqrt(x^2 +
/// z^2) (from x and z, so it stays accurate near the poles).
#[inline]
pub fn direction_to_uv(d: Vec3) -> (f32, f32, f32) {
    let sin_theta = ieee::sqrt(d.x * d.x + d.z * d.z);
    let theta = math::atan2(sin_theta, d.y);
    let phi = math::atan2(d.x, -d.z);
    (phi * (0.5 * core::f32::consts::FRAC_1_PI) + 0.5, theta * core::f32::consts::FRAC_1_PI, sin_theta)
}

/// The unit map direction at map coordinates (u, v).
#[inline]
pub fn uv_to_direction(u: f32, v: f32) -> Vec3 {
    let (sin_t, cos_t) = math::sin_cos(v * PI);
    let (sin_p, cos_p) = math::sin_cos((u - 0.5) * (2.0 * PI));
    Vec3::new(sin_t * sin_p, cos_t, -(sin_t * cos_p))
}

#[inline]
fn cell(u: f32, n: u32) -> u32 {
    let i = math::floor(u * n as f32);
    if !(i >= 0.0) {
        0
    } else if i >= n as f32 {
        n - 1
    } else {
        i as u32
    }
}

#[inline]
fn texel(env: &[f32], i: u32, j: u32, w: u32) -> Vec3 {
    let o = ENV_HEADER + 3 * (i as usize * w as usize + j as usize);
    Vec3::new(load(env, o), load(env, o + 1), load(env, o + 2))
}

#[inline]
fn density_uv(env: &[f32], i: u32, j: u32, w: u32, h: u32) -> f32 {
    load(env, ENV_HEADER + 3 * (w as usize * h as usize) + i as usize * w as usize + j as usize)
}

/// Radiance arriving from world direction `d` (unit).
#[inline]
pub fn radiance(env: &[f32], d: Vec3) -> Vec3 {
    let k = kind(env);
    if k == KIND_UNIFORM {
        return scale(env);
    }
    if k != KIND_MAP {
        return Vec3::ZERO;
    }
    let (w, h) = dims(env);
    let (u, v, _) = direction_to_uv(to_map(env, d));
    texel(env, cell(v, h), cell(u, w), w).mul_elem(scale(env))
}

/// Solid-angle density of [`sample`] at world direction `d` (unit).
#[inline]
pub fn pdf(env: &[f32], d: Vec3) -> f32 {
    let k = kind(env);
    if k == KIND_UNIFORM {
        return 0.25 * core::f32::consts::FRAC_1_PI;
    }
    if k != KIND_MAP {
        return 0.0;
    }
    let (w, h) = dims(env);
    let (u, v, sin_theta) = direction_to_uv(to_map(env, d));
    if !(sin_theta > 0.0) {
        return 0.0;
    }
    ieee::div(density_uv(env, cell(v, h), cell(u, w), w, h), (2.0 * PI * PI) * sin_theta)
}

/// Smallest k in [0, n) with u < cdf[k] (inclusive CDF of n floats at `off`), and the
/// remapped position of u inside that interval, in [0, 1).
#[inline]
fn search(env: &[f32], off: usize, n: u32, u: f32) -> (u32, f32) {
    let (mut lo, mut hi) = (0u32, n - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if u < load(env, off + mid as usize) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    let a = if lo == 0 { 0.0 } else { load(env, off + lo as usize - 1) };
    let b = load(env, off + lo as usize);
    let t = if b > a { ieee::div(u - a, b - a) } else { 0.5 };
    (lo, math::clamp(t, 0.0, 0.99999994))
}

/// A sampled environment direction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnvSample {
    /// Unit world direction towards the environment.
    pub wi: Vec3,
    /// Radiance from `wi`.
    pub li: Vec3,
    /// Solid-angle density (0: no sample).
    pub pdf: f32,
}

/// Sample a direction with uniform numbers (u0, u1): uniform over the sphere for a uniform
/// environment, by the texel distribution for a map.
#[inline]
pub fn sample(env: &[f32], u0: f32, u1: f32) -> EnvSample {
    let k = kind(env);
    if k == KIND_UNIFORM {
        let z = 1.0 - 2.0 * u0;
        let r = ieee::sqrt(math::max(0.0, 1.0 - z * z));
        let (s, c) = math::sin_cos(2.0 * PI * u1);
        return EnvSample { wi: Vec3::new(r * c, r * s, z), li: scale(env), pdf: 0.25 * core::f32::consts::FRAC_1_PI };
    }
    if k != KIND_MAP {
        return EnvSample::default();
    }
    let (w, h) = dims(env);
    let n = w as usize * h as usize;
    let marginal = ENV_HEADER + 4 * n;
    let (i, fv) = search(env, marginal, h, u0);
    let (j, fu) = search(env, marginal + h as usize + i as usize * w as usize, w, u1);
    let u = ieee::div(j as f32 + fu, w as f32);
    let v = ieee::div(i as f32 + fv, h as f32);
    let dm = uv_to_direction(u, v);
    let sin_theta = ieee::sqrt(dm.x * dm.x + dm.z * dm.z);
    if !(sin_theta > 0.0) {
        return EnvSample::default();
    }
    let p = ieee::div(density_uv(env, i, j, w, h), (2.0 * PI * PI) * sin_theta);
    EnvSample { wi: to_world(env, dm), li: texel(env, i, j, w).mul_elem(scale(env)), pdf: p }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_and_direction_round_trip() {
        for &(u, v) in &[(0.5f32, 0.5f32), (0.1, 0.3), (0.9, 0.8), (0.25, 0.05)] {
            let d = uv_to_direction(u, v);
            let (u2, v2, s) = direction_to_uv(d);
            assert!((u - u2).abs() < 1e-5 && (v - v2).abs() < 1e-5, "{u} {v} -> {u2} {v2}");
            assert!((s - (v * PI).sin()).abs() < 1e-5);
        }
        let f = uv_to_direction(0.5, 0.5);
        assert!((f.z + 1.0).abs() < 1e-6, "centre column looks down -z: {f:?}");
    }
}
