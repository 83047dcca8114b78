//! A tiny f32 4x4 matrix and 4-vector with a fixed evaluation order (row · column summed left to
//! right), so products round identically on the CPU and in SPIR-V.
//!
//! Matrices are row-major and act on column vectors: `p' = M p`. Only constant indices are used
//! (rows are named fields), as the project's rules require for rust-gpu.
//!
//! ```
//! use shader_core::ssr::mat4::{Mat4, Vec4};
//! use shader_core::Vec3;
//! // Row-major, acting on column vectors: a translation lives in the last column.
//! let t = Mat4::from_rows([1.0, 0.0, 0.0, 2.0, 0.0, 1.0, 0.0, 3.0, 0.0, 0.0, 1.0, 4.0, 0.0, 0.0, 0.0, 1.0]);
//! assert_eq!(t.transform_point(Vec3::new(1.0, 1.0, 1.0)), Vec3::new(3.0, 4.0, 5.0));
//! assert_eq!(t.transform_dir(Vec3::Z), Vec3::Z); // directions ignore the translation
//! assert_eq!(t.mul_vec4(Vec4::new(0.0, 0.0, 0.0, 1.0)), Vec4::new(2.0, 3.0, 4.0, 1.0));
//! assert_eq!(Mat4::IDENTITY.mul_mat(&t), t);
//! let (inv, det) = t.inverse_and_det();
//! assert_eq!(det, 1.0);
//! assert_eq!(inv.transform_point(Vec3::new(3.0, 4.0, 5.0)), Vec3::new(1.0, 1.0, 1.0));
//! assert_eq!(Mat4::from_rows(t.to_rows()), t);
//! ```

use crate::ieee;
use crate::vector::Vec3;

/// A homogeneous point or plane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct Vec4 {
    /// x component.
    pub x: f32,
    /// y component.
    pub y: f32,
    /// z component.
    pub z: f32,
    /// w component (1 for points, 0 for directions).
    pub w: f32,
}

impl Vec4 {
    /// The vector `(x, y, z, w)`.
    #[inline]
    pub const fn new(x: f32, y: f32, z: f32, w: f32) -> Self {
        Vec4 { x, y, z, w }
    }

    /// `x*x' + y*y' + z*z' + w*w'`, summed left to right.
    #[inline]
    pub fn dot(self, o: Vec4) -> f32 {
        self.x * o.x + self.y * o.y + self.z * o.z + self.w * o.w
    }

    /// The first three components (no division by w).
    #[inline]
    pub fn xyz(self) -> Vec3 {
        Vec3::new(self.x, self.y, self.z)
    }
}

/// A row-major 4x4 matrix: `r0..r3` are its rows.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct Mat4 {
    /// Row 0.
    pub r0: Vec4,
    /// Row 1.
    pub r1: Vec4,
    /// Row 2.
    pub r2: Vec4,
    /// Row 3 (`(0, 0, 0, 1)` for an affine transform).
    pub r3: Vec4,
}

impl Mat4 {
    /// The identity matrix.
    pub const IDENTITY: Mat4 = Mat4 {
        r0: Vec4::new(1.0, 0.0, 0.0, 0.0),
        r1: Vec4::new(0.0, 1.0, 0.0, 0.0),
        r2: Vec4::new(0.0, 0.0, 1.0, 0.0),
        r3: Vec4::new(0.0, 0.0, 0.0, 1.0),
    };

    /// Build from 16 values in row-major order.
    #[inline]
    pub const fn from_rows(m: [f32; 16]) -> Mat4 {
        Mat4 {
            r0: Vec4::new(m[0], m[1], m[2], m[3]),
            r1: Vec4::new(m[4], m[5], m[6], m[7]),
            r2: Vec4::new(m[8], m[9], m[10], m[11]),
            r3: Vec4::new(m[12], m[13], m[14], m[15]),
        }
    }

    /// The 16 values in row-major order.
    #[inline]
    pub fn to_rows(&self) -> [f32; 16] {
        [
            self.r0.x, self.r0.y, self.r0.z, self.r0.w, self.r1.x, self.r1.y, self.r1.z, self.r1.w, self.r2.x,
            self.r2.y, self.r2.z, self.r2.w, self.r3.x, self.r3.y, self.r3.z, self.r3.w,
        ]
    }

    /// `M v` (each row dotted with v, left to right).
    #[inline]
    pub fn mul_vec4(&self, v: Vec4) -> Vec4 {
        Vec4::new(self.r0.dot(v), self.r1.dot(v), self.r2.dot(v), self.r3.dot(v))
    }

    /// `M (p, 1)`: a point, without the perspective divide.
    #[inline]
    pub fn transform_point4(&self, p: Vec3) -> Vec4 {
        self.mul_vec4(Vec4::new(p.x, p.y, p.z, 1.0))
    }

    /// The upper 3x3 block times `d` (a direction: translation ignored).
    #[inline]
    pub fn transform_dir(&self, d: Vec3) -> Vec3 {
        Vec3::new(
            self.r0.x * d.x + self.r0.y * d.y + self.r0.z * d.z,
            self.r1.x * d.x + self.r1.y * d.y + self.r1.z * d.z,
            self.r2.x * d.x + self.r2.y * d.y + self.r2.z * d.z,
        )
    }

    /// `M (p, 1)` for an affine M (the last row is assumed to be (0, 0, 0, 1)).
    #[inline]
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        let v = Vec4::new(p.x, p.y, p.z, 1.0);
        Vec3::new(self.r0.dot(v), self.r1.dot(v), self.r2.dot(v))
    }

    /// Column `c` (0..4) as a vector; only called with constant `c`.
    #[inline]
    fn col(&self, c: u32) -> Vec4 {
        match c {
            0 => Vec4::new(self.r0.x, self.r1.x, self.r2.x, self.r3.x),
            1 => Vec4::new(self.r0.y, self.r1.y, self.r2.y, self.r3.y),
            2 => Vec4::new(self.r0.z, self.r1.z, self.r2.z, self.r3.z),
            _ => Vec4::new(self.r0.w, self.r1.w, self.r2.w, self.r3.w),
        }
    }

    /// `self * o` (row i of self dotted with column j of o, left to right).
    #[inline]
    pub fn mul_mat(&self, o: &Mat4) -> Mat4 {
        let (c0, c1, c2, c3) = (o.col(0), o.col(1), o.col(2), o.col(3));
        let row = |r: Vec4| Vec4::new(r.dot(c0), r.dot(c1), r.dot(c2), r.dot(c3));
        Mat4 { r0: row(self.r0), r1: row(self.r1), r2: row(self.r2), r3: row(self.r3) }
    }

    /// The transpose.
    #[inline]
    pub fn transpose(&self) -> Mat4 {
        Mat4 { r0: self.col(0), r1: self.col(1), r2: self.col(2), r3: self.col(3) }
    }

    /// The inverse by cofactor expansion (2x2 sub-determinants, Laplace along the first two rows)
    /// and the determinant. When the determinant is 0 or not finite the returned matrix is NaN or
    /// infinite: callers check `det` (see [`Mat4::try_inverse`]).
    pub fn inverse_and_det(&self) -> (Mat4, f32) {
        let (a, b, c, d) = (self.r0, self.r1, self.r2, self.r3);
        // 2x2 minors of rows 0,1 and rows 2,3.
        let s0 = a.x * b.y - b.x * a.y;
        let s1 = a.x * b.z - b.x * a.z;
        let s2 = a.x * b.w - b.x * a.w;
        let s3 = a.y * b.z - b.y * a.z;
        let s4 = a.y * b.w - b.y * a.w;
        let s5 = a.z * b.w - b.z * a.w;
        let c5 = c.z * d.w - d.z * c.w;
        let c4 = c.y * d.w - d.y * c.w;
        let c3 = c.y * d.z - d.y * c.z;
        let c2 = c.x * d.w - d.x * c.w;
        let c1 = c.x * d.z - d.x * c.z;
        let c0 = c.x * d.y - d.x * c.y;
        let det = s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0;
        let k = ieee::div(1.0, det);
        let inv = Mat4 {
            r0: Vec4::new(
                (b.y * c5 - b.z * c4 + b.w * c3) * k,
                (-a.y * c5 + a.z * c4 - a.w * c3) * k,
                (d.y * s5 - d.z * s4 + d.w * s3) * k,
                (-c.y * s5 + c.z * s4 - c.w * s3) * k,
            ),
            r1: Vec4::new(
                (-b.x * c5 + b.z * c2 - b.w * c1) * k,
                (a.x * c5 - a.z * c2 + a.w * c1) * k,
                (-d.x * s5 + d.z * s2 - d.w * s1) * k,
                (c.x * s5 - c.z * s2 + c.w * s1) * k,
            ),
            r2: Vec4::new(
                (b.x * c4 - b.y * c2 + b.w * c0) * k,
                (-a.x * c4 + a.y * c2 - a.w * c0) * k,
                (d.x * s4 - d.y * s2 + d.w * s0) * k,
                (-c.x * s4 + c.y * s2 - c.w * s0) * k,
            ),
            r3: Vec4::new(
                (-b.x * c3 + b.y * c1 - b.z * c0) * k,
                (a.x * c3 - a.y * c1 + a.z * c0) * k,
                (-d.x * s3 + d.y * s1 - d.z * s0) * k,
                (c.x * s3 - c.y * s1 + c.z * s0) * k,
            ),
        };
        (inv, det)
    }

    /// The inverse, or `None` when the determinant is not finite or |det| <= `min_abs_det`, or
    /// an entry of the inverse is not finite (a singular or NaN matrix).
    pub fn try_inverse(&self, min_abs_det: f32) -> Option<Mat4> {
        let (inv, det) = self.inverse_and_det();
        let finite = inv.r0.x.is_finite()
            && inv.r0.y.is_finite()
            && inv.r0.z.is_finite()
            && inv.r0.w.is_finite()
            && inv.r1.x.is_finite()
            && inv.r1.y.is_finite()
            && inv.r1.z.is_finite()
            && inv.r1.w.is_finite()
            && inv.r2.x.is_finite()
            && inv.r2.y.is_finite()
            && inv.r2.z.is_finite()
            && inv.r2.w.is_finite()
            && inv.r3.x.is_finite()
            && inv.r3.y.is_finite()
            && inv.r3.z.is_finite()
            && inv.r3.w.is_finite();
        if det.is_finite() && det.abs() > min_abs_det && finite {
            Some(inv)
        } else {
            None
        }
    }
}
