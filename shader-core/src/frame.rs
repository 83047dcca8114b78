//! An orthonormal basis around a unit normal (Duff et al. 2017, "Building an Orthonormal Basis,
//! Revisited", JCGT 6(1), listing 3): the one frame construction of the path tracer's shading
//! frames and the SSR samplers.
//!
//! ```
//! use shader_core::frame::orthonormal_basis;
//! use shader_core::Vec3;
//! let n = Vec3::new(0.0, 0.6, 0.8);
//! let (t, b) = orthonormal_basis(n);
//! for (u, v) in [(t, b), (t, n), (b, n)] {
//!     assert!(u.dot(v).abs() < 1e-6);
//! }
//! assert!((t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
//! ```

use crate::ieee;
use crate::Vec3;

/// The tangent and bitangent (t, b) of the right-handed frame (t, b, n) around unit `n`, the
/// sign of the construction chosen by `n.z < 0`.
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z < 0.0 { -1.0 } else { 1.0 };
    let a = ieee::div(-1.0, s + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bb = Vec3::new(b, s + n.y * n.y * a, -n.y);
    (t, bb)
}
