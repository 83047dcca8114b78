//! Stackless BVH traversal with skip pointers (Smits 1998, "Efficiency issues for ray tracing",
//! JGT 3(2), section 5: nodes in depth-first order, a miss or a finished leaf jumps to the
//! node's skip index) and the robust slab test of PBRT-v4 section 6.1.2 (`Bounds3::IntersectP`,
//! far distance scaled by 1 + 2 gamma(3)).
//!
//! The node layout is [`super::scene`]'s: an inner node's first child is the next node, its
//! second child is the first child's skip target; traversal ends at index = node count. Nodes
//! are visited in a fixed order (no front-to-back sorting), so the work per ray depends only on
//! the ray and the scene: the same on both backends. Hits on triangles whose glTF `MASK`
//! material rejects them ([`super::surface::alpha_passes`]) are skipped.
//!
//! ```
//! use shader_core::pt::bvh::{closest_hit, occluded};
//! use shader_core::pt::ray::Ray;
//! use shader_core::pt::scene::{HEADER_WORDS, MAGIC, NONE};
//! use shader_core::Vec3;
//! // A scene without nodes: nothing is ever hit.
//! let mut empty = vec![0u32; HEADER_WORDS];
//! empty[0] = MAGIC;
//! let r = Ray::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0));
//! assert_eq!(closest_hit(&empty, &r, f32::INFINITY).tri, NONE);
//! assert!(!occluded(&empty, &r, f32::INFINITY));
//! ```

use super::ray::Ray;
use super::scene::{self, header, leaf_range, vec3, word, H_NODES, NONE, N_LEAF, N_SKIP};
use super::surface::alpha_passes;
use super::triangle::{self, RayPrecompute};
use crate::ieee;
use crate::vector::Vec3;

/// 1 + 2 gamma(3) rounded up to f32, gamma(n) = n u / (1 - n u), u = 2^-24 (PBRT-v4 eq. 6.19
/// and section 6.8.1): 1 + 3 * 2^-23, the factor that makes the slab test conservative.
pub const SLAB_FAR_SCALE: f32 = f32::from_bits(0x3F80_0003);

/// The closest hit of a ray.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (units of |d|); `t_max` on a miss.
    pub t: f32,
    /// Triangle hit (BVH order, the index of [`scene::triangle`]), or [`NONE`] on a miss.
    pub tri: u32,
    /// Barycentric weight of v1 (0 on a miss).
    pub b1: f32,
    /// Barycentric weight of v2 (0 on a miss).
    pub b2: f32,
}

impl Hit {
    /// Whether a triangle was hit.
    #[inline]
    pub fn is_hit(&self) -> bool {
        self.tri != NONE
    }
}

/// The per-ray constants of the traversal: the triangle test's shear and 1 / d per axis
/// (`ieee::div`, so +-inf for a zero component).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraversalRay {
    /// Origin.
    pub o: Vec3,
    /// 1 / d, per component.
    pub inv_d: Vec3,
    /// [`triangle::precompute`] of d.
    pub pre: RayPrecompute,
}

impl TraversalRay {
    /// The constants of `ray`, computed once.
    #[inline]
    pub fn new(ray: &Ray) -> TraversalRay {
        let d = ray.d;
        TraversalRay {
            o: ray.o,
            inv_d: Vec3::new(ieee::div(1.0, d.x), ieee::div(1.0, d.y), ieee::div(1.0, d.z)),
            pre: triangle::precompute(d),
        }
    }
}

/// One axis of the slab test: (t0, t1) narrowed by the slab [lo, hi] (PBRT-v4 section 6.1.2).
/// NaN distances (0 * inf, a ray in the slab's plane) leave the interval unchanged.
#[inline(always)]
fn slab(lo: f32, hi: f32, o: f32, inv_d: f32, t0: f32, t1: f32) -> (f32, f32) {
    let mut t_near = (lo - o) * inv_d;
    let mut t_far = (hi - o) * inv_d;
    if t_near > t_far {
        let t = t_near;
        t_near = t_far;
        t_far = t;
    }
    t_far = t_far * SLAB_FAR_SCALE;
    let t0 = if t_near > t0 { t_near } else { t0 };
    let t1 = if t_far < t1 { t_far } else { t1 };
    (t0, t1)
}

/// Whether the ray meets box [lo, hi] at some t in [0, t_max] (PBRT-v4 `Bounds3::IntersectP`,
/// robust: the far distance is scaled by [`SLAB_FAR_SCALE`]; t = t_max counts as a meeting).
#[inline]
pub fn box_hit(lo: Vec3, hi: Vec3, r: &TraversalRay, t_max: f32) -> bool {
    // No early exit after an empty axis: t0 only grows and t1 only shrinks, so an empty
    // interval stays empty (and NaNs never enter t0, t1), the same answer as PBRT's early outs
    // without the nesting each return costs under Mesa.
    let (t0, t1) = slab(lo.x, hi.x, r.o.x, r.inv_d.x, 0.0, t_max);
    let (t0, t1) = slab(lo.y, hi.y, r.o.y, r.inv_d.y, t0, t1);
    let (t0, t1) = slab(lo.z, hi.z, r.o.z, r.inv_d.z, t0, t1);
    t0 <= t1
}

/// The traversal loop shared by [`closest_hit`] and [`occluded`]: with `any`, it stops at the
/// first accepted hit. A corrupt skip index (not after its node) ends the traversal, so the
/// loop always terminates.
#[inline]
fn traverse(sc: &[u32], ray: &Ray, t_max: f32, any: bool) -> Hit {
    let r = TraversalRay::new(ray);
    let nodes = header(sc, H_NODES);
    let mut best = Hit { t: t_max, tri: NONE, b1: 0.0, b2: 0.0 };
    let mut idx = 0u32;
    let mut done = false;
    while idx < nodes && !done {
        let o = scene::node(sc, idx, 0);
        let skip = word(sc, o + N_SKIP);
        let skip = if skip > idx { skip } else { nodes };
        let mut next = skip;
        if box_hit(vec3(sc, o), vec3(sc, o + 3), &r, best.t) {
            let (first, count) = leaf_range(word(sc, o + N_LEAF));
            if count == 0 {
                next = idx + 1;
            } else {
                let mut i = 0u32;
                while i < count && !done {
                    let tri = first + i;
                    let (v0, v1, v2) = scene::triangle(sc, tri);
                    let h = triangle::intersect(r.o, &r.pre, v0, v1, v2, best.t);
                    if h.hit && alpha_passes(sc, tri, h.b1, h.b2) {
                        best = Hit { t: h.t, tri, b1: h.b1, b2: h.b2 };
                        done = any;
                    }
                    i += 1;
                }
            }
        }
        idx = next;
    }
    best
}

/// The closest hit with 0 < t < `t_max` of `ray` in scene `sc` (both faces; `MASK` materials
/// applied), or a [`Hit`] with `tri` = [`NONE`] and t = `t_max`. An empty scene (0 nodes)
/// never hits. Among hits at exactly the same t the first one visited is kept.
#[inline]
pub fn closest_hit(sc: &[u32], ray: &Ray, t_max: f32) -> Hit {
    traverse(sc, ray, t_max, false)
}

/// Whether any triangle (that its `MASK` material keeps) is hit with 0 < t < `t_max`: the
/// shadow-ray query, stopping at the first such hit.
#[inline]
pub fn occluded(sc: &[u32], ray: &Ray, t_max: f32) -> bool {
    traverse(sc, ray, t_max, true).tri != NONE
}

#[cfg(test)]
pub(crate) mod tests {
    extern crate std;
    use super::*;
    use crate::pt::scene::*;
    use std::vec;
    use std::vec::Vec;

    /// A scene buffer of `tris` (one material per triangle: `alpha[i]` < 0 opaque, else a MASK
    /// material with that alpha factor and cutoff 0.5) with a median-split BVH of leaves of at
    /// most `leaf` triangles, laid out as scene.rs says. Test-only (the host builds the real ones).
    pub(crate) fn build(tris: &[[Vec3; 3]], alpha: &[f32], leaf: usize) -> Vec<u32> {
        let n = tris.len();
        let mut order: Vec<usize> = (0..n).collect();
        let mut nodes: Vec<[u32; 8]> = Vec::new();
        fn bounds(tris: &[[Vec3; 3]], idx: &[usize]) -> ([f32; 3], [f32; 3]) {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for &i in idx {
                for p in tris[i] {
                    for (k, c) in [p.x, p.y, p.z].into_iter().enumerate() {
                        lo[k] = lo[k].min(c);
                        hi[k] = hi[k].max(c);
                    }
                }
            }
            (lo, hi)
        }
        fn rec(tris: &[[Vec3; 3]], idx: &mut [usize], first: usize, leaf: usize, nodes: &mut Vec<[u32; 8]>) {
            let (lo, hi) = bounds(tris, idx);
            let me = nodes.len();
            let mut w = [0u32; 8];
            for k in 0..3 {
                w[k] = lo[k].to_bits();
                w[3 + k] = hi[k].to_bits();
            }
            nodes.push(w);
            if idx.len() <= leaf {
                nodes[me][N_LEAF] = leaf_word(first as u32, idx.len() as u32);
            } else {
                let axis = (0..3).max_by(|&a, &b| (hi[a] - lo[a]).partial_cmp(&(hi[b] - lo[b])).unwrap()).unwrap();
                let c = |i: usize| {
                    let t = tris[i];
                    let p = t[0] + t[1] + t[2];
                    [p.x, p.y, p.z][axis]
                };
                idx.sort_by(|&a, &b| c(a).partial_cmp(&c(b)).unwrap());
                let mid = idx.len() / 2;
                let (l, r) = idx.split_at_mut(mid);
                rec(tris, l, first, leaf, nodes);
                rec(tris, r, first + mid, leaf, nodes);
            }
            let end = nodes.len() as u32;
            nodes[me][N_SKIP] = end;
        }
        if n > 0 {
            rec(tris, &mut order, 0, leaf, &mut nodes);
        }
        let mut h = vec![0u32; HEADER_WORDS];
        h[0] = MAGIC;
        let mut body: Vec<u32> = Vec::new();
        let off = |body: &Vec<u32>| (HEADER_WORDS + body.len()) as u32;
        h[H_NODES] = nodes.len() as u32;
        h[H_NODES_OFF] = off(&body);
        for nd in &nodes {
            body.extend_from_slice(nd);
        }
        h[H_TRIS] = n as u32;
        h[H_TRIS_OFF] = off(&body);
        for &i in &order {
            for p in tris[i] {
                body.extend_from_slice(&[p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]);
            }
        }
        h[H_SHADING_OFF] = off(&body);
        for &i in &order {
            let mut s = [0u32; SHADING_WORDS];
            s[S_MATERIAL] = i as u32;
            s[S_LIGHT] = NONE;
            body.extend_from_slice(&s);
        }
        h[H_MATERIALS] = n as u32;
        h[H_MATERIALS_OFF] = off(&body);
        for i in 0..n {
            let mut m = [0u32; MATERIAL_WORDS];
            let a = alpha.get(i).copied().unwrap_or(-1.0);
            for k in 0..4 {
                m[M_BASE + k] = 1.0f32.to_bits();
            }
            if a >= 0.0 {
                m[M_ALPHA_MODE] = ALPHA_MASK;
                m[M_BASE + 3] = a.to_bits();
                m[M_ALPHA_CUTOFF] = 0.5f32.to_bits();
            }
            for w in [M_BASE_TEX, M_MR_TEX, M_NORMAL_TEX, M_EMISSIVE_TEX, M_TRANSMISSION_TEX] {
                m[w] = NONE;
            }
            body.extend_from_slice(&m);
        }
        for w in [H_TEXTURES_OFF, H_TEXELS_OFF, H_LIGHTS_OFF, H_LIGHT_CDF_OFF, H_SRGB_OFF] {
            h[w] = off(&body);
        }
        h.extend_from_slice(&body);
        h
    }

    fn v(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z)
    }

    fn rnd(s: &mut u32) -> f32 {
        *s ^= *s << 13;
        *s ^= *s >> 17;
        *s ^= *s << 5;
        (*s >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Brute force: every triangle in index order, the closest accepted hit.
    fn brute(sc: &[u32], ray: &Ray, t_max: f32) -> Hit {
        let pre = triangle::precompute(ray.d);
        let mut best = Hit { t: t_max, tri: NONE, b1: 0.0, b2: 0.0 };
        for tri in 0..header(sc, H_TRIS) {
            let (a, b, c) = scene::triangle(sc, tri);
            let h = triangle::intersect(ray.o, &pre, a, b, c, best.t);
            if h.hit && alpha_passes(sc, tri, h.b1, h.b2) {
                best = Hit { t: h.t, tri, b1: h.b1, b2: h.b2 };
            }
        }
        best
    }

    fn random_soup(count: usize, seed: &mut u32) -> Vec<[Vec3; 3]> {
        (0..count)
            .map(|_| {
                let c = v(rnd(seed) * 4.0 - 2.0, rnd(seed) * 4.0 - 2.0, rnd(seed) * 4.0 - 2.0);
                let mut e = || v(rnd(seed) - 0.5, rnd(seed) - 0.5, rnd(seed) - 0.5) * 0.6;
                [c + e(), c + e(), c + e()]
            })
            .collect()
    }

    #[test]
    fn empty_scene_never_hits() {
        let sc = build(&[], &[], 4);
        let ray = Ray::new(v(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0));
        assert_eq!(closest_hit(&sc, &ray, f32::INFINITY).tri, NONE);
        assert!(!occluded(&sc, &ray, f32::INFINITY));
        assert_eq!(closest_hit(&[], &ray, f32::INFINITY).tri, NONE, "not even a header");
    }

    #[test]
    fn closest_hit_equals_brute_force_on_a_triangle_soup() {
        let mut seed = 0xdead_beef;
        let tris = random_soup(600, &mut seed);
        let alpha: Vec<f32> = (0..tris.len()).map(|i| if i % 7 == 0 { 0.25 } else if i % 7 == 1 { 0.75 } else { -1.0 }).collect();
        for leaf in [1usize, 3, 8] {
            let sc = build(&tris, &alpha, leaf);
            let mut hits = 0;
            for k in 0..3000 {
                let o = v(rnd(&mut seed) * 6.0 - 3.0, rnd(&mut seed) * 6.0 - 3.0, rnd(&mut seed) * 6.0 - 3.0);
                let target = v(rnd(&mut seed) * 3.0 - 1.5, rnd(&mut seed) * 3.0 - 1.5, rnd(&mut seed) * 3.0 - 1.5);
                let mut d = target - o;
                // some axis-parallel directions (zero components: infinite 1/d)
                if k % 5 == 0 {
                    d.x = 0.0;
                }
                if k % 9 == 0 {
                    d.y = 0.0;
                }
                let t_max = if k % 3 == 0 { 2.0 } else { f32::INFINITY };
                let ray = Ray::new(o, d);
                let b = brute(&sc, &ray, t_max);
                let h = closest_hit(&sc, &ray, t_max);
                assert_eq!(h.t.to_bits(), b.t.to_bits(), "ray {k}: {h:?} vs {b:?}");
                assert_eq!(h.tri, b.tri, "ray {k}");
                assert_eq!((h.b1.to_bits(), h.b2.to_bits()), (b.b1.to_bits(), b.b2.to_bits()));
                assert_eq!(occluded(&sc, &ray, t_max), b.tri != NONE, "ray {k}");
                hits += (b.tri != NONE) as u32;
            }
            assert!(hits > 1000, "too few hits to mean anything: {hits}");
        }
    }

    #[test]
    fn alpha_mask_lets_rays_through() {
        // two parallel squares; the nearer one is MASK with alpha 0.25 < cutoff 0.5
        let sq = |z: f32| [[v(-1.0, -1.0, z), v(1.0, -1.0, z), v(1.0, 1.0, z)], [v(-1.0, -1.0, z), v(1.0, 1.0, z), v(-1.0, 1.0, z)]];
        let mut tris = Vec::new();
        tris.extend(sq(1.0));
        tris.extend(sq(2.0));
        let ray = Ray::new(v(0.1, 0.2, 0.0), v(0.0, 0.0, 1.0));
        let sc = build(&tris, &[0.25, 0.25, -1.0, -1.0], 1);
        let h = closest_hit(&sc, &ray, f32::INFINITY);
        assert_eq!(h.t, 2.0);
        assert!(!occluded(&sc, &ray, 1.5), "the masked square does not occlude");
        assert!(occluded(&sc, &ray, 2.5));
        let sc = build(&tris, &[0.75, 0.75, -1.0, -1.0], 1);
        assert_eq!(closest_hit(&sc, &ray, f32::INFINITY).t, 1.0, "alpha above the cutoff is kept");
        assert!(occluded(&sc, &ray, 1.5));
    }

    #[test]
    fn t_max_bounds_hits_and_misses_report_t_max() {
        let tris = [[v(-1.0, -1.0, 3.0), v(1.0, -1.0, 3.0), v(0.0, 1.0, 3.0)]];
        let sc = build(&tris, &[], 4);
        let ray = Ray::new(v(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0));
        let h = closest_hit(&sc, &ray, f32::INFINITY);
        assert!(h.is_hit() && h.t == 3.0 && h.tri == 0);
        let h = closest_hit(&sc, &ray, 3.0);
        assert!(!h.is_hit() && h.t == 3.0);
        assert!(!occluded(&sc, &ray, 3.0));
        assert!(occluded(&sc, &ray, 3.0001));
        let back = Ray::new(v(0.0, 0.0, 0.0), v(0.0, 0.0, -1.0));
        assert!(!closest_hit(&sc, &back, f32::INFINITY).is_hit());
    }

    #[test]
    fn shared_edges_of_a_tessellated_grid_are_never_missed() {
        // a 16 x 16 quad grid in z = 0, rays aimed exactly at vertices and edge midpoints
        let n = 16;
        let p = |i: usize, j: usize| v(i as f32 * 0.125 - 1.0, j as f32 * 0.125 - 1.0, 0.0);
        let mut tris = Vec::new();
        for i in 0..n {
            for j in 0..n {
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        let sc = build(&tris, &[], 4);
        let mut seed = 77;
        // interior vertices and edges (a ray at the outer boundary may miss by rounding)
        for i in 1..n {
            for j in 1..n {
                for target in [p(i, j), (p(i, j) + p(i + 1, j)) * 0.5, (p(i, j) + p(i, j + 1)) * 0.5, (p(i, j) + p(i - 1, j - 1)) * 0.5] {
                    let o = v(rnd(&mut seed) * 2.0 - 1.0, rnd(&mut seed) * 2.0 - 1.0, 1.0 + rnd(&mut seed));
                    let ray = Ray::new(o, target - o);
                    let h = closest_hit(&sc, &ray, f32::INFINITY);
                    assert!(h.is_hit(), "ray to {target:?} missed");
                    assert!((h.t - 1.0).abs() < 1e-5);
                    assert!(occluded(&sc, &ray, f32::INFINITY));
                }
            }
        }
    }

    #[test]
    fn corrupt_skip_indices_terminate() {
        let tris = [[v(-1.0, -1.0, 3.0), v(1.0, -1.0, 3.0), v(0.0, 1.0, 3.0)]];
        let mut sc = build(&tris, &[], 4);
        let o = header(&sc, H_NODES_OFF) as usize;
        sc[o + N_SKIP] = 0; // points back at itself
        let ray = Ray::new(v(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0));
        assert!(closest_hit(&sc, &ray, f32::INFINITY).is_hit());
    }
}
