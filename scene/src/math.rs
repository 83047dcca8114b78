//! Host-side affine transforms of glTF nodes (glTF 2.0 section 3.5.3 "Transformations"),
//! in f64 (glam's `DVec3`, the host's one f64 vector); results are rounded to f32 once, when the
//! scene buffer is written.

use glam::DVec3;

/// A 4x4 matrix, column-major as glTF stores it: `m[c][r]` is row `r` of column `c`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mat4(pub [[f64; 4]; 4]);

impl Default for Mat4 {
    fn default() -> Mat4 {
        Mat4::IDENTITY
    }
}

impl Mat4 {
    /// The identity.
    pub const IDENTITY: Mat4 = Mat4([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]);

    /// From glTF's column-major f32 matrix.
    pub fn from_cols_f32(m: [[f32; 4]; 4]) -> Mat4 {
        Mat4(m.map(|c| c.map(|x| x as f64)))
    }

    /// A translation.
    pub fn translation(t: DVec3) -> Mat4 {
        let mut m = Mat4::IDENTITY;
        m.0[3] = [t.x, t.y, t.z, 1.0];
        m
    }

    /// A uniform scale.
    pub fn scale(s: f64) -> Mat4 {
        Mat4([[s, 0.0, 0.0, 0.0], [0.0, s, 0.0, 0.0], [0.0, 0.0, s, 0.0], [0.0, 0.0, 0.0, 1.0]])
    }

    /// T * R * S of glTF's TRS (rotation a unit quaternion x, y, z, w).
    pub fn from_trs(t: [f32; 3], q: [f32; 4], s: [f32; 3]) -> Mat4 {
        let (x, y, z, w) = (q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64);
        let r = [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + z * w), 2.0 * (x * z - y * w)],
            [2.0 * (x * y - z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + x * w)],
            [2.0 * (x * z + y * w), 2.0 * (y * z - x * w), 1.0 - 2.0 * (x * x + y * y)],
        ];
        let mut m = Mat4::IDENTITY;
        for c in 0..3 {
            for row in 0..3 {
                m.0[c][row] = r[c][row] * s[c] as f64;
            }
        }
        m.0[3] = [t[0] as f64, t[1] as f64, t[2] as f64, 1.0];
        m
    }

    /// self * o.
    pub fn mul(&self, o: &Mat4) -> Mat4 {
        let mut m = [[0.0; 4]; 4];
        for c in 0..4 {
            for r in 0..4 {
                m[c][r] = (0..4).map(|k| self.0[k][r] * o.0[c][k]).sum();
            }
        }
        Mat4(m)
    }

    /// The affine image of point `p`.
    pub fn point(&self, p: [f32; 3]) -> DVec3 {
        let m = &self.0;
        let p = p.map(|x| x as f64);
        DVec3::from([0, 1, 2].map(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r]))
    }

    /// The image of direction `v` (upper 3x3).
    pub fn vector(&self, v: DVec3) -> DVec3 {
        let m = &self.0;
        DVec3::from([0, 1, 2].map(|r| m[0][r] * v[0] + m[1][r] * v[1] + m[2][r] * v[2]))
    }

    /// Determinant of the upper 3x3 (negative: the transform mirrors, flipping the winding).
    pub fn det3(&self) -> f64 {
        let m = &self.0;
        m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2]) - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2]) + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
    }

    /// The normal matrix, the inverse transpose of the upper 3x3, as a function of a normal
    /// (computed from the cofactors, so it is the inverse transpose times det: normalise after).
    /// Multiplied by sign(det) so normals keep their side under mirroring transforms.
    pub fn normal(&self, n: DVec3) -> DVec3 {
        let m = &self.0;
        let a = |c: usize, r: usize| m[c][r];
        // cofactor matrix C (C = det * inverse transpose)
        let c00 = a(1, 1) * a(2, 2) - a(2, 1) * a(1, 2);
        let c01 = -(a(0, 1) * a(2, 2) - a(2, 1) * a(0, 2));
        let c02 = a(0, 1) * a(1, 2) - a(1, 1) * a(0, 2);
        let c10 = -(a(1, 0) * a(2, 2) - a(2, 0) * a(1, 2));
        let c11 = a(0, 0) * a(2, 2) - a(2, 0) * a(0, 2);
        let c12 = -(a(0, 0) * a(1, 2) - a(1, 0) * a(0, 2));
        let c20 = a(1, 0) * a(2, 1) - a(2, 0) * a(1, 1);
        let c21 = -(a(0, 0) * a(2, 1) - a(2, 0) * a(0, 1));
        let c22 = a(0, 0) * a(1, 1) - a(1, 0) * a(0, 1);
        // cRC is the cofactor of row R, column C; (M^-T n)_r = sum_c cRc n_c / det
        let s = if self.det3() < 0.0 { -1.0 } else { 1.0 };
        DVec3::new(c00 * n[0] + c01 * n[1] + c02 * n[2], c10 * n[0] + c11 * n[1] + c12 * n[2], c20 * n[0] + c21 * n[1] + c22 * n[2]) * s
    }
}

/// `v / |v|` (each component divided by the length, unlike glam's `try_normalize`, which
/// multiplies by its reciprocal), or `None` for a zero or non-finite vector.
pub fn normalize(v: DVec3) -> Option<DVec3> {
    let l = v.length();
    if l > 0.0 && l.is_finite() {
        Some(v / l)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_matrix_is_the_inverse_transpose() {
        let m = Mat4::from_trs([1.0, 2.0, 3.0], [0.2, 0.3, -0.1, 0.927_361_8], [2.0, 0.5, -3.0]);
        // a tangent t of a surface with normal n stays orthogonal to the transformed normal
        let n = DVec3::new(0.3, -0.4, 0.866);
        let t = normalize(n.cross(DVec3::X)).unwrap();
        let nn = m.normal(n);
        assert!(nn.dot(m.vector(t)).abs() < 1e-12);
        // keeps its side for a mirroring transform: same side as the transformed geometric normal
        let u = n.cross(t);
        let geo = m.vector(t).cross(m.vector(u));
        assert!(m.det3() < 0.0);
        assert!(nn.dot(geo) < 0.0, "mirrored: the winding flips, the normal keeps its side of the surface");
    }
}
