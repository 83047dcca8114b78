//! The camera model of glTF 2.0 (section 3.10 "Cameras"): a pinhole perspective camera with a
//! vertical field of view, or an orthographic one with half extents `xmag`, `ymag`; primary rays
//! through jittered pixel positions (box filter over the pixel, PBRT-v4 section 5.2).
//!
//! Image convention: pixel (0, 0) is the top-left, x grows right and y down; the camera looks
//! along `forward` with `up` towards the top of the image and `right` = forward x up.

use super::ray::Ray;
use crate::vector::Vec3;

/// Perspective projection.
pub const PERSPECTIVE: u32 = 0;
/// Orthographic projection.
pub const ORTHOGRAPHIC: u32 = 1;

/// A camera (unit, orthonormal `right`, `up`, `forward`); a `#[repr(C)]` record of 4-byte
/// fields, part of [`super::integrator::RenderParams`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct Camera {
    /// [`PERSPECTIVE`] or [`ORTHOGRAPHIC`].
    pub kind: u32,
    /// Eye position.
    pub origin: Vec3,
    /// Image-right direction.
    pub right: Vec3,
    /// Image-up direction.
    pub up: Vec3,
    /// Viewing direction.
    pub forward: Vec3,
    /// Perspective: tan(yfov / 2) times the aspect ratio (width / height); orthographic: xmag.
    pub scale_x: f32,
    /// Perspective: tan(yfov / 2); orthographic: ymag.
    pub scale_y: f32,
}

impl Camera {
    /// The ray through image position (x, y) in pixels (pixel centres at k + 1/2) of a
    /// `width` x `height` image; perspective directions are unit.
    ///
    /// ```
    /// use shader_core::pt::camera::{Camera, PERSPECTIVE};
    /// use shader_core::Vec3;
    /// let c = Camera { kind: PERSPECTIVE, origin: Vec3::ZERO, right: Vec3::new(1.0, 0.0, 0.0),
    ///     up: Vec3::new(0.0, 1.0, 0.0), forward: Vec3::new(0.0, 0.0, -1.0), scale_x: 1.0, scale_y: 1.0 };
    /// // The image centre looks straight ahead; the top-left corner up and to the left.
    /// assert_eq!(c.ray(2.0, 2.0, 4, 4).d, Vec3::new(0.0, 0.0, -1.0));
    /// let d = c.ray(0.0, 0.0, 4, 4).d;
    /// assert!(d.x < 0.0 && d.y > 0.0);
    /// ```
    #[inline]
    pub fn ray(&self, x: f32, y: f32, width: u32, height: u32) -> Ray {
        let sx = crate::ieee::div(2.0 * x, width as f32) - 1.0;
        let sy = 1.0 - crate::ieee::div(2.0 * y, height as f32);
        if self.kind == ORTHOGRAPHIC {
            let o = self.origin + self.right * (sx * self.scale_x) + self.up * (sy * self.scale_y);
            return Ray::new(o, self.forward);
        }
        let d = self.forward + self.right * (sx * self.scale_x) + self.up * (sy * self.scale_y);
        Ray::new(self.origin, d.normalize())
    }

    /// Depth of a point at distance `t` along unit primary direction `d`: its distance along
    /// `forward` (view-space z), the `depth.Z` AOV.
    #[inline]
    pub fn depth(&self, d: Vec3, t: f32) -> f32 {
        t * d.dot(self.forward)
    }

    /// The image position (x, y) in pixels of world point `p`, and its depth along `forward`
    /// (the inverse of [`Camera::ray`]; depth <= 0 means behind a perspective camera).
    #[inline]
    pub fn project(&self, p: Vec3, width: u32, height: u32) -> (f32, f32, f32) {
        let v = p - self.origin;
        let z = v.dot(self.forward);
        let (sx, sy) = if self.kind == ORTHOGRAPHIC {
            (crate::ieee::div(v.dot(self.right), self.scale_x), crate::ieee::div(v.dot(self.up), self.scale_y))
        } else {
            (crate::ieee::div(v.dot(self.right), z * self.scale_x), crate::ieee::div(v.dot(self.up), z * self.scale_y))
        };
        ((sx + 1.0) * 0.5 * width as f32, (1.0 - sy) * 0.5 * height as f32, z)
    }
}
