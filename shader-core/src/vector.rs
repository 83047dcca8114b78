//! Three-component vectors with a fixed evaluation order (no fused or reassociated arithmetic), so
//! every operation rounds identically on the CPU and in SPIR-V.
//!
//! Conventions: components are `f32`; directions in the local shading frame have the normal along
//! +z (`Vec3::Z`), tangent +x, bitangent +y. Nothing is clamped or normalized implicitly; NaN
//! components propagate through every operation (comparison-based functions document their own
//! rule). Sums are evaluated left to right, never fused.
//!
//! ```
//! use shader_core::Vec3;
//! let a = Vec3::new(1.0, 2.0, 3.0);
//! let b = Vec3::new(4.0, -5.0, 6.0);
//! // The dot product is summed left to right: (x*x' + y*y') + z*z', bit for bit.
//! assert_eq!(a.dot(b).to_bits(), ((1.0f32 * 4.0 + 2.0 * -5.0) + 3.0 * 6.0).to_bits());
//! // Right-handed cross product: x cross y = z.
//! assert_eq!(Vec3::new(1.0, 0.0, 0.0).cross(Vec3::new(0.0, 1.0, 0.0)), Vec3::Z);
//! // Normalizing the zero vector gives NaN; normalize_or_zero gives zero.
//! assert!(Vec3::ZERO.normalize().x.is_nan());
//! assert_eq!(Vec3::ZERO.normalize_or_zero(), Vec3::ZERO);
//! assert_eq!(Vec3::new(0.0, 3.0, 4.0).length(), 5.0);
//! ```

use crate::ieee;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// A direction or point in the local shading frame (normal = +z) or in world space.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct Vec3 {
    /// x component (tangent direction in the local shading frame).
    pub x: f32,
    /// y component (bitangent direction in the local shading frame).
    pub y: f32,
    /// z component (the normal direction in the local shading frame: `z = cos(theta)` for a unit vector).
    pub z: f32,
}

impl Vec3 {
    /// The zero vector (all components +0).
    pub const ZERO: Vec3 = Vec3::new(0.0, 0.0, 0.0);
    /// The unit +z axis: the surface normal of the local shading frame.
    pub const Z: Vec3 = Vec3::new(0.0, 0.0, 1.0);

    /// The vector `(x, y, z)`, stored as given (no normalization).
    #[inline]
    pub const fn new(x: f32, y: f32, z: f32) -> Self {
        Vec3 { x, y, z }
    }

    /// `x*x' + y*y' + z*z'`, summed left to right.
    #[inline]
    pub fn dot(self, o: Vec3) -> f32 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Right-handed cross product `self x o`: `(y z' - z y', z x' - x z', x y' - y x')`, each
    /// component two rounded products and one rounded difference (no fma).
    #[inline]
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }

    /// `dot(v, v)` = x^2 + y^2 + z^2, summed left to right; may overflow to +inf above ~1.8e19 or
    /// underflow for tiny components (see [`Vec3::pow2_rescaled`]).
    #[inline]
    pub fn length_squared(self) -> f32 {
        self.dot(self)
    }

    /// `sqrt(dot(v, v))` (correctly rounded sqrt; no hypot scaling, so |v| must be below ~1e19).
    #[inline]
    pub fn length(self) -> f32 {
        ieee::sqrt(self.length_squared())
    }

    /// `v / |v|` componentwise; the zero vector maps to NaN, see [`Vec3::normalize_or_zero`].
    #[inline]
    pub fn normalize(self) -> Vec3 {
        let len = self.length();
        Vec3::new(ieee::div(self.x, len), ieee::div(self.y, len), ieee::div(self.z, len))
    }

    /// `v / |v|`, or the zero vector when |v| is 0 or not finite.
    #[inline]
    pub fn normalize_or_zero(self) -> Vec3 {
        let len = self.length();
        if len > 0.0 && len < f32::INFINITY {
            Vec3::new(ieee::div(self.x, len), ieee::div(self.y, len), ieee::div(self.z, len))
        } else {
            Vec3::ZERO
        }
    }

    /// Componentwise product.
    #[inline]
    pub fn mul_elem(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }

    /// True when every component is finite (neither NaN nor infinite).
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }

    /// The same direction scaled by an exact power of two so that its largest component magnitude
    /// lies in [1, 2). Scale-invariant functions call this first so that any finite non-zero
    /// vector (denormal or huge components included) can be squared and summed without underflow
    /// or overflow; for vectors whose squares stay normal the scaling commutes with every
    /// correctly rounded operation, so results are bit-identical to the unscaled evaluation.
    /// Zero vectors and vectors with an infinite component are returned unchanged (NaN stays NaN).
    #[inline]
    pub fn pow2_rescaled(self) -> Vec3 {
        let (ax, ay, az) = (self.x.abs(), self.y.abs(), self.z.abs());
        let mut m = if ax > ay { ax } else { ay };
        if az > m {
            m = az;
        }
        if !(m > 0.0 && m < f32::INFINITY) {
            return self;
        }
        let mut v = self;
        if m < 1.0e-20 {
            let s = f32::from_bits(0x5f80_0000); // 2^64
            v = v * s;
            m *= s;
        }
        if m > 1.0e20 {
            let s = f32::from_bits(0x1f80_0000); // 2^-64
            v = v * s;
            m *= s;
        }
        // m is now a normal number with biased exponent e in [42, 194]; 2^(127 - e) is normal.
        let e = (m.to_bits() >> 23) & 0xff;
        v * f32::from_bits((254 - e) << 23)
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    #[inline]
    fn add(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl Sub for Vec3 {
    type Output = Vec3;
    #[inline]
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl Neg for Vec3 {
    type Output = Vec3;
    #[inline]
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}

impl Mul<f32> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn mul(self, s: f32) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}

impl Div<f32> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn div(self, s: f32) -> Vec3 {
        Vec3::new(ieee::div(self.x, s), ieee::div(self.y, s), ieee::div(self.z, s))
    }
}
