//! A ray o + t d (PBRT-v4 section 3.1) and the offset that keeps a spawned ray off its own surface.
//!
//! ```
//! use shader_core::pt::ray::{offset_origin, Ray};
//! use shader_core::Vec3;
//! let r = Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.0, -2.0));
//! assert_eq!(r.at(0.5), Vec3::new(1.0, 2.0, 2.0)); // t is in units of |d|
//! // A ray leaving towards -n starts below the surface, one towards +n above it.
//! let n = Vec3::new(0.0, 1.0, 0.0);
//! assert!(offset_origin(Vec3::ZERO, n, -n).y < 0.0);
//! assert!(offset_origin(Vec3::ZERO, n, n).y > 0.0);
//! ```

use crate::vector::Vec3;

/// A ray with origin `o` and direction `d` (not necessarily unit; `t` is in units of `|d|`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ray {
    /// Origin.
    pub o: Vec3,
    /// Direction.
    pub d: Vec3,
}

impl Ray {
    /// The ray from `o` along `d`.
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Ray {
        Ray { o, d }
    }

    /// The point o + t d.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// Relative size of the spawn offset: a new ray starts `SPAWN_EPSILON * (1 + max |p_i|)` along
/// the geometric normal, on the side it leaves towards, so it cannot re-hit its own triangle.
pub const SPAWN_EPSILON: f32 = 1e-4;

/// The origin of a ray leaving point `p` with geometric normal `ng` towards `w`: `p` moved by
/// `SPAWN_EPSILON * (1 + max |p_i|)` along `ng` (or `-ng` when `w` is below it).
#[inline]
pub fn offset_origin(p: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    let m = crate::math::max(crate::math::max(p.x.abs(), p.y.abs()), p.z.abs());
    let e = SPAWN_EPSILON * (1.0 + m);
    if ng.dot(w) < 0.0 {
        p - ng * e
    } else {
        p + ng * e
    }
}
