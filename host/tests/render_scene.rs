//! The path tracer's scenes: the flattened BVH's invariants, traversal against brute force, the
//! built-in scene, the glTF loader's values, warnings and errors.

use host::render::scene::{Scene, DEFAULT_DETAIL};
use rayon::prelude::*;
use shader_core::pt::bvh;
use shader_core::pt::ray::Ray;
use shader_core::pt::scene::{self as sc, header, word};
use shader_core::pt::surface::alpha_passes;
use shader_core::pt::triangle;
use shader_core::Vec3;

/// The shared Cornell box (`shared/` lies beside the repository).
#[allow(dead_code)]
const CORNELL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/scenes/cornell_box/cornell_box.gltf");

/// Checks the flattened BVH: header, skip indices, leaf ranges covering every triangle exactly
/// once, every node's box containing its triangles and its children's boxes.
fn check_bvh(s: &Scene) {
    let w = &s.words;
    assert_eq!(w[0], sc::MAGIC);
    let nodes = header(w, sc::H_NODES);
    let tris = header(w, sc::H_TRIS);
    assert_eq!(nodes as usize, s.counts.nodes);
    assert_eq!(tris as usize, s.counts.triangles);
    assert!(nodes >= 1 && tris >= 1);
    let node_box = |n: u32| {
        let o = sc::node(w, n, 0);
        (sc::vec3(w, o), sc::vec3(w, o + 3))
    };
    let inside = |p: Vec3, b: (Vec3, Vec3)| b.0.x <= p.x && p.x <= b.1.x && b.0.y <= p.y && p.y <= b.1.y && b.0.z <= p.z && p.z <= b.1.z;
    let mut seen = vec![0u32; tris as usize];
    // the subtree of node n is n .. skip(n); an inner node's children are n + 1 and skip(n + 1)
    for n in 0..nodes {
        let skip = word(w, sc::node(w, n, sc::N_SKIP));
        assert!(skip > n && skip <= nodes, "node {n}: skip {skip} of {nodes}");
        let (first, count) = sc::leaf_range(word(w, sc::node(w, n, sc::N_LEAF)));
        let b = node_box(n);
        if count == 0 {
            let l = n + 1;
            let r = word(w, sc::node(w, l, sc::N_SKIP));
            assert!(r < skip, "inner node {n} needs two children");
            assert_eq!(word(w, sc::node(w, r, sc::N_SKIP)), skip, "node {n}: the second child's subtree ends where the parent's does");
            for c in [l, r] {
                let cb = node_box(c);
                assert!(inside(cb.0, b) && inside(cb.1, b), "node {n} does not contain child {c}");
            }
        } else {
            assert_eq!(skip, n + 1, "leaf {n} has no descendants");
            assert!(count <= sc::LEAF_MAX_TRIS);
            for t in first..first + count {
                assert!(t < tris, "leaf {n}: triangle {t} of {tris}");
                seen[t as usize] += 1;
                let (a, bb, c) = sc::triangle(w, t);
                for p in [a, bb, c] {
                    assert!(inside(p, b), "leaf {n} does not contain triangle {t}");
                }
            }
        }
    }
    assert_eq!(word(w, sc::node(w, 0, sc::N_SKIP)), nodes, "the root spans all nodes");
    assert!(seen.iter().all(|&c| c == 1), "every triangle in exactly one leaf");
    // the light CDF ends at 1 and grows
    let lights = header(w, sc::H_LIGHTS) as usize;
    assert_eq!(lights, s.counts.lights);
    let cdf: Vec<f32> = (0..lights).map(|i| sc::float(w, header(w, sc::H_LIGHT_CDF_OFF) as usize + i)).collect();
    if lights > 0 {
        assert_eq!(*cdf.last().unwrap(), 1.0);
        assert!(cdf.windows(2).all(|p| p[0] <= p[1]));
    }
    // the sRGB table
    let srgb = header(w, sc::H_SRGB_OFF) as usize;
    assert_eq!(w.len(), srgb + 256, "the sRGB table ends the buffer");
    assert_eq!(sc::float(w, srgb + 255), 1.0);
}

/// SplitMix-style hash to [0, 1).
fn rnd(state: &mut u64) -> f32 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 40) as f32 * (1.0 / 16_777_216.0)
}

/// Brute force: every triangle in buffer order, the closest accepted hit.
fn brute(w: &[u32], ray: &Ray, t_max: f32) -> bvh::Hit {
    let pre = triangle::precompute(ray.d);
    let mut best = bvh::Hit { t: t_max, tri: sc::NONE, b1: 0.0, b2: 0.0 };
    for t in 0..header(w, sc::H_TRIS) {
        let (a, b, c) = sc::triangle(w, t);
        let h = triangle::intersect(ray.o, &pre, a, b, c, best.t);
        if h.hit && alpha_passes(w, t, h.b1, h.b2) {
            best = bvh::Hit { t: h.t, tri: t, b1: h.b1, b2: h.b2 };
        }
    }
    best
}

/// `closest_hit` and `occluded` against brute force on `n` random rays from inside and around
/// the scene's bounds; returns the number of hits.
fn check_traversal(s: &Scene, n: usize, seed: u64) -> usize {
    let w = &s.words;
    let (lo, hi) = (s.bounds.min, s.bounds.max);
    let results: Vec<(bool, bool)> = (0..n)
        .into_par_iter()
        .map(|k| {
            let mut st = seed ^ (k as u64).wrapping_mul(0x2545_f491_4f6c_dd1d);
            let mut r = || rnd(&mut st);
            let o = Vec3::new(
                lo[0] + (hi[0] - lo[0]) * (r() * 1.4 - 0.2),
                lo[1] + (hi[1] - lo[1]) * (r() * 1.4 - 0.2),
                lo[2] + (hi[2] - lo[2]) * (r() * 1.4 - 0.2),
            );
            let mut d = Vec3::new(r() * 2.0 - 1.0, r() * 2.0 - 1.0, r() * 2.0 - 1.0);
            if k % 17 == 0 {
                d.y = 0.0; // axis-parallel components: infinite 1/d
            }
            if k % 29 == 0 {
                d = Vec3::new(0.0, -1.0, 0.0);
            }
            let t_max = if k % 4 == 0 { r() * 2.0 } else { f32::INFINITY };
            let ray = Ray::new(o, d);
            let b = brute(w, &ray, t_max);
            let h = bvh::closest_hit(w, &ray, t_max);
            assert_eq!(h.t.to_bits(), b.t.to_bits(), "ray {k} {ray:?}: bvh {h:?}, brute force {b:?}");
            let tie = h.tri != b.tri;
            if tie {
                // the same t on two triangles (a ray through a shared edge): both must report it
                let (a0, a1, a2) = sc::triangle(w, h.tri);
                let th = triangle::intersect(ray.o, &triangle::precompute(ray.d), a0, a1, a2, f32::INFINITY);
                assert_eq!(th.t.to_bits(), b.t.to_bits(), "ray {k}: different triangles {} / {} at different t", h.tri, b.tri);
            } else {
                assert_eq!((h.b1.to_bits(), h.b2.to_bits()), (b.b1.to_bits(), b.b2.to_bits()), "ray {k}");
            }
            assert_eq!(bvh::occluded(w, &ray, t_max), b.tri != sc::NONE, "ray {k}: occluded disagrees");
            (b.tri != sc::NONE, tie)
        })
        .collect();
    let hits = results.iter().filter(|r| r.0).count();
    let ties = results.iter().filter(|r| r.1).count();
    assert!(ties * 100 <= n, "{ties} ties in {n} rays");
    hits
}

#[test]
fn builtin_scene_bvh_invariants_and_contents() {
    for detail in [3, DEFAULT_DETAIL] {
        let s = Scene::builtin(detail);
        check_bvh(&s);
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);
        assert!(s.has_lights());
        assert_eq!(s.counts.emissive_triangles, 2, "the area light quad");
        assert_eq!(s.counts.punctual_lights, 0);
        assert_eq!(s.counts.materials, 4 + 12);
        let cam = s.camera("default").expect("default camera");
        assert_eq!(cam.position, [0.0, 1.0, 3.4]);
        assert_eq!(cam.forward, [0.0, 0.0, -1.0]);
        assert!((s.bounds.min[0] + 1.0).abs() < 1e-6 && (s.bounds.max[1] - 2.0).abs() < 1e-6);
        // each light triangle points at its light and back
        let w = &s.words;
        for l in 0..s.counts.lights as u32 {
            assert_eq!(word(w, sc::light(w, l, sc::L_TYPE)), sc::LIGHT_TRIANGLE);
            let t = word(w, sc::light(w, l, sc::L_TRIANGLE));
            assert_eq!(word(w, sc::shading(w, t, sc::S_LIGHT)), l);
            let area = sc::float(w, sc::light(w, l, sc::L_AREA));
            assert!((area - 0.1).abs() < 1e-6, "half of the 0.5 x 0.4 quad: {area}");
        }
        let lit = (0..s.counts.triangles as u32).filter(|&t| word(w, sc::shading(w, t, sc::S_LIGHT)) != sc::NONE).count();
        assert_eq!(lit, 2);
    }
}

#[test]
fn builtin_closest_hit_equals_brute_force() {
    let s = Scene::builtin(5);
    let hits = check_traversal(&s, 100_000, 1);
    assert!(hits > 35_000, "{hits} hits");
    let s = Scene::builtin(DEFAULT_DETAIL);
    let hits = check_traversal(&s, 5_000, 2);
    assert!(hits > 1_500, "{hits} hits");
}

#[test]
fn builtin_camera_rays_hit_the_box() {
    let s = Scene::builtin(8);
    let cam = &s.cameras[0];
    let o = Vec3::new(cam.position[0], cam.position[1], cam.position[2]);
    // the centre ray hits the back wall at z = -1
    let h = bvh::closest_hit(&s.words, &Ray::new(o, Vec3::new(0.0, 0.0, -1.0)), f32::INFINITY);
    assert!(h.is_hit() && (h.t - 4.4).abs() < 1e-5, "{h:?}");
    // straight up from the floor's centre below the light: the light quad at y = 1.98
    let h = bvh::closest_hit(&s.words, &Ray::new(Vec3::new(0.0, 0.01, 0.0), Vec3::new(0.0, 1.0, 0.0)), f32::INFINITY);
    assert!(h.is_hit() && (h.t - 1.97).abs() < 1e-5, "{h:?}");
    assert_ne!(word(&s.words, sc::shading(&s.words, h.tri, sc::S_LIGHT)), sc::NONE);
}

#[test]
fn build_time_by_scene_size() {
    // prints the build times (docs quote them); fails only if the BVH is broken
    for target in [1_000usize, 30_000, 300_000] {
        let d = host::render::scene::builtin_detail_for_triangles(target);
        let s = Scene::builtin(d);
        check_bvh(&s);
        println!(
            "builtin detail {d}: {} triangles, {} nodes, {} leaves (max {} triangles), depth {}: build {:.3} s (obvhs {:.3} s)",
            s.counts.triangles, s.counts.nodes, s.counts.leaves, s.counts.max_leaf_triangles, s.counts.bvh_depth, s.build_seconds, s.bvh_seconds
        );
    }
}
