//! Watertight ray-triangle intersection (Woop, Benthin, Wald 2013, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1), section 3 and listing 1), in single precision without the double
//! precision fallback.
//!
//! The ray is sheared so that it becomes the +z axis of a permuted frame ([`precompute`], once
//! per ray); the triangle's vertices are translated to the ray origin, sheared the same way, and
//! the three 2D edge functions U, V, W of the origin decide coverage. Because an edge shared by
//! two triangles yields the same edge function with opposite sign in both (products commute,
//! `a - b = -(b - a)` exactly), a ray through a shared edge always hits at least one of them.
//!
//! **Exact zeros.** Where the paper recomputes an edge function that is exactly 0 in double
//! precision, this version keeps it as 0 and counts 0 as *inside* (a hit is rejected only when
//! the edge functions have strictly opposite signs). A ray exactly through an edge or a vertex
//! therefore hits every triangle sharing it (the closest-hit search keeps one of them), never
//! none. A triangle whose edge functions sum to 0 (degenerate, or seen exactly edge-on) is never
//! hit.
//!
//! ```
//! use shader_core::pt::triangle::{intersect, precompute};
//! use shader_core::Vec3;
//! let (v0, v1, v2) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
//! let (o, d) = (Vec3::new(0.25, 0.25, 2.0), Vec3::new(0.0, 0.0, -1.0));
//! let h = intersect(o, &precompute(d), v0, v1, v2, f32::INFINITY);
//! assert!(h.hit);
//! assert_eq!((h.t, h.b1, h.b2), (2.0, 0.25, 0.25)); // p = (1 - b1 - b2) v0 + b1 v1 + b2 v2
//! // Only hits with t < t_max count.
//! assert!(!intersect(o, &precompute(d), v0, v1, v2, 1.5).hit);
//! ```

use crate::ieee;
use crate::vector::Vec3;

/// The per-ray part of the test (Woop et al. 2013, section 3, "precalculations"): the axis `kz`
/// of the largest |d| component, the two others `kx`, `ky` (swapped when d\[kz\] < 0 so the
/// winding is kept), and the shear constants `sx = d[kx] / d[kz]`, `sy = d[ky] / d[kz]`,
/// `sz = 1 / d[kz]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayPrecompute {
    /// First permuted axis (0 = x, 1 = y, 2 = z).
    pub kx: u32,
    /// Second permuted axis.
    pub ky: u32,
    /// The axis of the largest |d| component.
    pub kz: u32,
    /// Shear in x: d\[kx\] / d\[kz\].
    pub sx: f32,
    /// Shear in y: d\[ky\] / d\[kz\].
    pub sy: f32,
    /// Scale in z: 1 / d\[kz\].
    pub sz: f32,
}

/// Component `k` (0, 1, 2) of `v`, by selection (no run-time indexing).
#[inline(always)]
fn component(v: Vec3, k: u32) -> f32 {
    if k == 0 {
        v.x
    } else if k == 1 {
        v.y
    } else {
        v.z
    }
}

/// The shear constants of direction `d` (Woop et al. 2013, section 3). Ties in |d| pick the
/// lowest axis. A zero or NaN direction gives NaN constants, with which [`intersect`] never hits.
#[inline]
pub fn precompute(d: Vec3) -> RayPrecompute {
    let (ax, ay, az) = (d.x.abs(), d.y.abs(), d.z.abs());
    let kz: u32 = if ax >= ay && ax >= az {
        0
    } else if ay >= az {
        1
    } else {
        2
    };
    let mut kx = if kz == 2 { 0 } else { kz + 1 };
    let mut ky = if kx == 2 { 0 } else { kx + 1 };
    let dz = component(d, kz);
    if dz < 0.0 {
        let k = kx;
        kx = ky;
        ky = k;
    }
    RayPrecompute {
        kx,
        ky,
        kz,
        sx: ieee::div(component(d, kx), dz),
        sy: ieee::div(component(d, ky), dz),
        sz: ieee::div(1.0, dz),
    }
}

/// The result of [`intersect`]: on a hit, p = (1 - b1 - b2) v0 + b1 v1 + b2 v2 = o + t d.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter of the hit (units of |d|); 0 on a miss.
    pub t: f32,
    /// Barycentric weight of v1; 0 on a miss.
    pub b1: f32,
    /// Barycentric weight of v2; 0 on a miss.
    pub b2: f32,
    /// Whether the ray hits the triangle with 0 < t < t_max.
    pub hit: bool,
}

/// `x` with its sign flipped where `sign_of` is negative (the paper's `xorf(x, sign_mask(det))`).
#[inline(always)]
fn xor_sign(x: f32, sign_of: f32) -> f32 {
    f32::from_bits(x.to_bits() ^ (sign_of.to_bits() & 0x8000_0000))
}

/// The ray o + t d (with `pre = precompute(d)`) against triangle (v0, v1, v2), both faces
/// (Woop et al. 2013, listing 1, without back-face culling): a hit only when 0 < t < `t_max`.
///
/// The scaled distance T is compared with `t_max * det` (signs folded by det's sign) before any
/// division, so farther triangles cost no division; a hit then divides once for t, b1, b2 and
/// checks 0 < t < t_max again on the rounded t (so a hit is never at or beyond `t_max`). Exact
/// zero edge functions count as inside (see the module doc); det = 0 never hits; NaN anywhere
/// (vertices, origin, direction, `t_max`) never hits. `t_max` may be +inf.
#[inline]
pub fn intersect(o: Vec3, pre: &RayPrecompute, v0: Vec3, v1: Vec3, v2: Vec3, t_max: f32) -> TriangleHit {
    // single exit (no early returns): each early return of an inlined function nests the rest
    // of a kernel one level deeper under Mesa (see `crate::buffer`)
    let mut out = TriangleHit { t: 0.0, b1: 0.0, b2: 0.0, hit: false };
    let a = v0 - o;
    let b = v1 - o;
    let c = v2 - o;
    let (a_z, b_z, c_z) = (component(a, pre.kz), component(b, pre.kz), component(c, pre.kz));
    let ax = component(a, pre.kx) - pre.sx * a_z;
    let ay = component(a, pre.ky) - pre.sy * a_z;
    let bx = component(b, pre.kx) - pre.sx * b_z;
    let by = component(b, pre.ky) - pre.sy * b_z;
    let cx = component(c, pre.kx) - pre.sx * c_z;
    let cy = component(c, pre.ky) - pre.sy * c_z;
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    // outside only when the edge functions have strictly opposite signs (0 counts as inside)
    let outside = (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0);
    let det = u + v + w;
    // det = 0 (degenerate or edge-on) or NaN: no hit
    if !outside && det != 0.0 {
        let t_scaled = u * (pre.sz * a_z) + v * (pre.sz * b_z) + w * (pre.sz * c_z);
        let t_signed = xor_sign(t_scaled, det);
        let det_abs = xor_sign(det, det);
        // 0 < T / det < t_max without dividing: the division is only paid for closer hits
        if t_signed > 0.0 && t_signed < t_max * det_abs {
            let rcp = ieee::div(1.0, det);
            let t = t_scaled * rcp;
            if t > 0.0 && t < t_max {
                out = TriangleHit { t, b1: v * rcp, b2: w * rcp, hit: true };
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn v(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z)
    }

    fn hit(o: Vec3, d: Vec3, t: [Vec3; 3], t_max: f32) -> TriangleHit {
        intersect(o, &precompute(d), t[0], t[1], t[2], t_max)
    }

    const TRI: [Vec3; 3] = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];

    #[test]
    fn hits_inside_with_barycentrics_and_both_faces() {
        for &dz in &[-1.0f32, 1.0] {
            let o = v(0.25, 0.5, -dz * 2.0);
            let h = hit(o, v(0.0, 0.0, dz), TRI, f32::INFINITY);
            assert!(h.hit, "dz {dz}");
            assert_eq!(h.t, 2.0);
            assert!((h.b1 - 0.25).abs() < 1e-6 && (h.b2 - 0.5).abs() < 1e-6, "{h:?}");
            let p = TRI[0] * (1.0 - h.b1 - h.b2) + TRI[1] * h.b1 + TRI[2] * h.b2;
            assert!((p - v(0.25, 0.5, 0.0)).length() < 1e-6);
        }
        // an oblique ray, every permutation of the dominant axis
        let tri = [v(1.0, 2.0, 3.0), v(-2.0, 1.0, 0.5), v(0.5, -1.5, -2.0)];
        let target = tri[0] * 0.2 + tri[1] * 0.3 + tri[2] * 0.5;
        for &o in &[v(5.0, 0.1, 0.2), v(0.1, -6.0, 0.3), v(-0.2, 0.3, 7.0), v(3.0, 3.0, 3.0)] {
            let d = target - o;
            let h = hit(o, d, tri, f32::INFINITY);
            assert!(h.hit, "{o:?}");
            assert!((h.t - 1.0).abs() < 1e-5, "{h:?}");
            assert!((h.b1 - 0.3).abs() < 1e-5 && (h.b2 - 0.5).abs() < 1e-5, "{h:?}");
        }
    }

    #[test]
    fn misses_outside_behind_beyond_and_degenerate() {
        let d = v(0.0, 0.0, -1.0);
        assert!(!hit(v(0.6, 0.6, 1.0), d, TRI, f32::INFINITY).hit, "outside the hypotenuse");
        assert!(!hit(v(-0.1, 0.5, 1.0), d, TRI, f32::INFINITY).hit, "outside x = 0");
        assert!(!hit(v(0.2, 0.2, -1.0), d, TRI, f32::INFINITY).hit, "behind the origin");
        assert!(!hit(v(0.2, 0.2, 1.0), d, TRI, 1.0).hit, "t = t_max is excluded");
        assert!(hit(v(0.2, 0.2, 1.0), d, TRI, 1.000_001).hit);
        assert!(!hit(v(0.2, 0.2, 0.0), d, TRI, f32::INFINITY).hit, "t = 0 is excluded");
        let line = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0)];
        assert!(!hit(v(0.5, 0.0, 1.0), d, line, f32::INFINITY).hit, "degenerate");
        assert!(!hit(v(0.5, 0.0, 1.0), v(0.0, 0.0, 0.0), TRI, f32::INFINITY).hit, "zero direction");
        assert!(!hit(v(0.2, 0.2, 1.0), v(f32::NAN, 0.0, -1.0), TRI, f32::INFINITY).hit, "NaN direction");
        assert!(!hit(v(0.2, 0.2, 1.0), d, TRI, f32::NAN).hit, "NaN t_max");
        // parallel to the plane (edge-on)
        assert!(!hit(v(-1.0, 0.2, 0.0), v(1.0, 0.0, 0.0), TRI, f32::INFINITY).hit);
    }

    #[test]
    fn exact_edge_and_vertex_hits_count_as_inside() {
        let d = v(0.0, 0.0, -1.0);
        for &(x, y) in &[(0.0f32, 0.0f32), (1.0, 0.0), (0.0, 1.0), (0.5, 0.0), (0.0, 0.5), (0.5, 0.5)] {
            assert!(hit(v(x, y, 1.0), d, TRI, f32::INFINITY).hit, "({x}, {y})");
        }
    }

    /// Xorshift32 in [0, 1).
    fn rnd(s: &mut u32) -> f32 {
        *s ^= *s << 13;
        *s ^= *s >> 17;
        *s ^= *s << 5;
        (*s >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// A ray through every point of a grid over a tessellated quad (shared diagonals and
    /// edges included) hits at least one of its triangles: no ray falls through a crack.
    #[test]
    fn tessellated_quad_is_watertight() {
        let n = 7;
        // a slightly bent, irregular grid so edges are not axis aligned
        let p = |i: usize, j: usize| {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            v(x * 1.3 + 0.11 * y * y, y * 0.9 + 0.07 * x, 0.2 * x * y - 0.1 * x)
        };
        let mut tris = Vec::new();
        for i in 0..n {
            for j in 0..n {
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        let mut seed = 0x1234_5678;
        let mut rays = 0;
        // rays aimed exactly at points on shared edges (interior vertices and edge points)
        // interior points only: rays at the outer boundary may miss by rounding, legitimately
        for i in 1..n - 1 {
            for j in 1..n - 1 {
                for s in 0..5 {
                    let f = s as f32 * 0.25;
                    let targets = [p(i, j), p(i, j) * (1.0 - f) + p(i + 1, j) * f, p(i, j) * (1.0 - f) + p(i, j + 1) * f, p(i, j) * (1.0 - f) + p(i + 1, j + 1) * f];
                    for target in targets {
                        for _ in 0..4 {
                            let o = v(rnd(&mut seed) * 4.0 - 2.0, rnd(&mut seed) * 4.0 - 2.0, 1.0 + rnd(&mut seed) * 3.0);
                            let d = target - o;
                            let pre = precompute(d);
                            let any = tris.iter().any(|t| intersect(o, &pre, t[0], t[1], t[2], f32::INFINITY).hit);
                            assert!(any, "ray from {o:?} to {target:?} fell through");
                            rays += 1;
                        }
                    }
                }
            }
        }
        assert!(rays > 1500);
    }

    /// Rays from inside a closed indexed mesh (a bumpy latitude-longitude sphere: shared
    /// vertices are bit-identical) towards its vertices and edge midpoints always hit it.
    #[test]
    fn closed_mesh_from_inside_is_watertight() {
        let (nu, nv) = (24usize, 12usize);
        let mut verts = Vec::new();
        verts.push(v(0.0, 0.0, 1.0));
        for j in 1..nv {
            for i in 0..nu {
                let th = core::f32::consts::PI * j as f32 / nv as f32;
                let ph = 2.0 * core::f32::consts::PI * i as f32 / nu as f32;
                let r = 1.0 + 0.1 * ((i * 7 + j * 3) % 5) as f32;
                verts.push(v(r * th.sin() * ph.cos(), r * th.sin() * ph.sin(), r * th.cos()));
            }
        }
        verts.push(v(0.0, 0.0, -1.0));
        let ring = |j: usize, i: usize| 1 + (j - 1) * nu + i % nu;
        let mut idx: Vec<[usize; 3]> = Vec::new();
        for i in 0..nu {
            idx.push([0, ring(1, i), ring(1, i + 1)]);
            idx.push([verts.len() - 1, ring(nv - 1, i + 1), ring(nv - 1, i)]);
            for j in 1..nv - 1 {
                idx.push([ring(j, i), ring(j + 1, i), ring(j + 1, i + 1)]);
                idx.push([ring(j, i), ring(j + 1, i + 1), ring(j, i + 1)]);
            }
        }
        let tris: Vec<[Vec3; 3]> = idx.iter().map(|t| [verts[t[0]], verts[t[1]], verts[t[2]]]).collect();
        let mut points: Vec<Vec3> = verts.clone();
        for t in &idx {
            points.push((verts[t[0]] + verts[t[1]]) * 0.5);
            points.push((verts[t[1]] + verts[t[2]]) * 0.5);
        }
        let mut seed = 0x9e37_79b9;
        let mut rays = 0;
        for target in points {
            for _ in 0..3 {
                let o = v(rnd(&mut seed) * 0.4 - 0.2, rnd(&mut seed) * 0.4 - 0.2, rnd(&mut seed) * 0.4 - 0.2);
                let d = target - o;
                let pre = precompute(d);
                let any = tris.iter().any(|t| intersect(o, &pre, t[0], t[1], t[2], f32::INFINITY).hit);
                assert!(any, "ray from {o:?} to {target:?} escaped");
                rays += 1;
            }
        }
        assert!(rays > 3000);
    }

    #[test]
    fn t_orders_hits_along_the_ray() {
        let d = v(0.1, -0.05, -1.0);
        let o = v(0.2, 0.3, 5.0);
        let mut last = 0.0;
        for k in 0..10 {
            let z = 4.0 - k as f32 * 0.7;
            let tri = [v(-5.0, -5.0, z), v(5.0, -5.0, z), v(0.0, 5.0, z)];
            let h = hit(o, d, tri, f32::INFINITY);
            assert!(h.hit && h.t > last, "{k}: {h:?}");
            last = h.t;
            assert!(!hit(o, d, tri, h.t).hit, "t_max = t excludes");
        }
    }
}
