//! Warps from the unit square to the disk and the hemisphere (PBRT-v4 section A.5), used by the
//! BxDF samplers. The angles go through the project's deterministic [`crate::math`] sin/cos.
//!
//! Conventions: `u0`, `u1` are expected in [0, 1); values outside are not clamped (the maps are
//! still defined, see each function), NaN propagates.
//!
//! ```
//! use shader_core::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere, sample_uniform_disk_concentric};
//! // The centre of the square maps to the centre of the disk.
//! let c = sample_uniform_disk_concentric(0.5, 0.5);
//! assert_eq!((c.x, c.y), (0.0, 0.0));
//! // ... and, lifted onto the hemisphere, to the normal, where the density is 1/pi.
//! let w = sample_cosine_hemisphere(0.5, 0.5);
//! assert_eq!((w.x, w.y, w.z), (0.0, 0.0, 1.0));
//! assert_eq!(cosine_hemisphere_pdf(w.z), core::f32::consts::FRAC_1_PI);
//! // Every sample lies in the upper hemisphere (z >= 0).
//! for i in 0..16 {
//!     let w = sample_cosine_hemisphere(i as f32 / 16.0, 0.3);
//!     assert!(w.z >= 0.0);
//! }
//! ```

use crate::ieee;
use crate::math;
use crate::vector::Vec3;
use core::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

/// A point on the unit disk.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Point2 {
    /// x coordinate, in [-1, 1] for inputs in [0, 1).
    pub x: f32,
    /// y coordinate, in [-1, 1] for inputs in [0, 1).
    pub y: f32,
}

/// Uniform disk by the polar map (PBRT-v4 `SampleUniformDiskPolar`): r = sqrt(u0), phi = 2 pi u1.
#[inline]
pub fn sample_uniform_disk_polar(u0: f32, u1: f32) -> Point2 {
    let r = ieee::sqrt(u0);
    let phi = 2.0 * PI * u1;
    Point2 { x: r * math::cos(phi), y: r * math::sin(phi) }
}

/// Uniform disk by Shirley & Chiu 1997, "A Low Distortion Map Between Disk and Square" (PBRT-v4
/// `SampleUniformDiskConcentric`): the square [-1,1]^2 is mapped wedge by wedge, r = max-norm.
#[inline]
pub fn sample_uniform_disk_concentric(u0: f32, u1: f32) -> Point2 {
    let ox = 2.0 * u0 - 1.0;
    let oy = 2.0 * u1 - 1.0;
    if ox == 0.0 && oy == 0.0 {
        return Point2 { x: 0.0, y: 0.0 };
    }
    let (r, theta) = if ox.abs() > oy.abs() {
        (ox, FRAC_PI_4 * (ieee::div(oy, ox)))
    } else {
        (oy, FRAC_PI_2 - FRAC_PI_4 * (ieee::div(ox, oy)))
    };
    Point2 { x: r * math::cos(theta), y: r * math::sin(theta) }
}

/// Cosine-weighted hemisphere by Malley's method (PBRT-v4 `SampleCosineHemisphere`): a concentric
/// disk point lifted to z = sqrt(max(0, 1 - x^2 - y^2)). Density [`cosine_hemisphere_pdf`].
#[inline]
pub fn sample_cosine_hemisphere(u0: f32, u1: f32) -> Vec3 {
    let d = sample_uniform_disk_concentric(u0, u1);
    let z2 = 1.0 - d.x * d.x - d.y * d.y;
    let z = if z2 > 0.0 { ieee::sqrt(z2) } else { 0.0 };
    Vec3::new(d.x, d.y, z)
}

/// Solid-angle density of [`sample_cosine_hemisphere`]: cos(theta) / pi (PBRT-v4 eq. A.22).
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta * FRAC_1_PI
}
