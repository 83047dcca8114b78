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

/// The Cornell box of `scenes/cornell_box/` (NVIDIA, BSD-3).
const CORNELL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");

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
    let mut r = reference::splitmix::SplitMix64(*state);
    let u = r.next_f32();
    *state = r.0;
    u
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
        // closest-hit rate of one thread (no shading): 128 x 128 camera rays, and as many rays
        // between random points inside the box (like secondary rays); best of 5 (shared machine)
        let cam = &s.cameras[0];
        let o = Vec3::new(cam.position[0], cam.position[1], cam.position[2]);
        let n = 128;
        let tan = (20f32).to_radians().tan();
        let camera: Vec<Ray> = (0..n * n)
            .map(|k| {
                let (x, y) = (k % n, k / n);
                let (u, v) = ((x as f32 + 0.5) / n as f32 * 2.0 - 1.0, 1.0 - (y as f32 + 0.5) / n as f32 * 2.0);
                Ray::new(o, Vec3::new(u * tan, v * tan, -1.0))
            })
            .collect();
        let mut st = 5u64;
        let inside: Vec<Ray> = (0..n * n)
            .map(|_| {
                let mut p = || Vec3::new(rnd(&mut st) * 1.9 - 0.95, rnd(&mut st) * 1.9 + 0.05, rnd(&mut st) * 1.9 - 0.95);
                let a = p();
                Ray::new(a, p() - a)
            })
            .collect();
        let rate = |rays: &[Ray]| {
            let mut best = 0.0f64;
            for _ in 0..5 {
                let t0 = std::time::Instant::now();
                let hits: u32 = rays.iter().map(|r| bvh::closest_hit(&s.words, r, f32::INFINITY).is_hit() as u32).sum();
                assert!(hits as usize > rays.len() / 2);
                best = best.max(rays.len() as f64 / t0.elapsed().as_secs_f64());
            }
            best * 1e-6
        };
        let (rc, ri) = (rate(&camera), rate(&inside));
        println!(
            "builtin detail {d}: {} triangles, {} nodes, {} leaves (max {} triangles), depth {}: build {:.3} s (obvhs {:.3} s); closest hit, one thread: {rc:.2} M camera rays/s, {ri:.2} M rays/s inside the box",
            s.counts.triangles, s.counts.nodes, s.counts.leaves, s.counts.max_leaf_triangles, s.counts.bvh_depth, s.build_seconds, s.bvh_seconds
        );
    }
}

// ---------------------------------------------------------------------------------------------
// glTF loading

use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Binary data and the accessors over it, for test-written glTF files.
#[derive(Default)]
struct Bin {
    data: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.data.len().is_multiple_of(4) {
            self.data.push(0);
        }
        self.views.push(json!({"buffer": 0, "byteOffset": self.data.len(), "byteLength": bytes.len()}));
        self.data.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// A float accessor of `n`-component elements (`ty` = "VEC3", ...).
    fn floats(&mut self, v: &[f32], ty: &str) -> usize {
        let n = match ty {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            _ => 4,
        };
        let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let mut a = json!({"bufferView": view, "componentType": 5126, "count": v.len() / n, "type": ty});
        if ty == "VEC3" {
            // f32::min / max skip NaN, so a NaN position still has the bounds glTF requires
            let min: Vec<f32> = (0..3).map(|k| v.iter().skip(k).step_by(3).cloned().fold(f32::INFINITY, f32::min)).collect();
            let max: Vec<f32> = (0..3).map(|k| v.iter().skip(k).step_by(3).cloned().fold(f32::NEG_INFINITY, f32::max)).collect();
            a["min"] = json!(min);
            a["max"] = json!(max);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn indices(&mut self, v: &[u16]) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessors.push(json!({"bufferView": view, "componentType": 5123, "count": v.len(), "type": "SCALAR"}));
        self.accessors.len() - 1
    }

    /// A quad in z = 0 ([-1, 1]^2) facing +z with normals, uvs, tangents: a primitive's attributes.
    fn quad(&mut self, z: f32, tangents: bool) -> Value {
        let pos = self.floats(&[-1.0, -1.0, z, 1.0, -1.0, z, 1.0, 1.0, z, -1.0, 1.0, z], "VEC3");
        let nrm = self.floats(&[0.0, 0.0, 1.0].repeat(4), "VEC3");
        let uv = self.floats(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0], "VEC2");
        let idx = self.indices(&[0, 1, 2, 0, 2, 3]);
        let mut attrs = json!({"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv});
        if tangents {
            attrs["TANGENT"] = json!(self.floats(&[1.0, 0.0, 0.0, 1.0].repeat(4), "VEC4"));
        }
        json!({"attributes": attrs, "indices": idx})
    }
}

/// Writes `doc` (with `bin`'s views and accessors, its buffer as `name`.bin) to `dir`/`name`.gltf.
fn write_gltf(dir: &Path, name: &str, mut doc: Value, bin: &Bin) -> PathBuf {
    doc["asset"] = json!({"version": "2.0"});
    doc["bufferViews"] = json!(bin.views);
    doc["accessors"] = json!(bin.accessors);
    if doc.get("buffers").is_none() {
        doc["buffers"] = json!([{"uri": format!("{name}.bin"), "byteLength": bin.data.len()}]);
    }
    std::fs::write(dir.join(format!("{name}.bin")), &bin.data).unwrap();
    let p = dir.join(format!("{name}.gltf"));
    std::fs::write(&p, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
    p
}

/// A minimal valid scene: one quad with the default material.
fn one_quad(bin: &mut Bin) -> Value {
    let prim = bin.quad(0.0, false);
    json!({"scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}], "meshes": [{"primitives": [prim]}]})
}

fn load_err(p: &Path) -> String {
    match Scene::load(p) {
        Ok(s) => panic!("{} loaded ({} triangles), expected an error", p.display(), s.counts.triangles),
        Err(e) => format!("{e:#}"),
    }
}

#[test]
#[allow(clippy::approx_constant)] // the glTF file's yfov, 0.7854, not pi/4
fn cornell_box_loads_with_its_camera_and_materials() {
    let s = Scene::load(CORNELL).expect("the Cornell box of `scenes/cornell_box/` loads");
    check_bvh(&s);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.counts.materials, 3);
    let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["white", "red", "green"]);
    assert_eq!(s.cameras.len(), 1);
    let c = &s.cameras[0];
    assert_eq!(c.position, [0.0, 1.0, 3.5]);
    assert_eq!(c.forward, [0.0, 0.0, -1.0]);
    assert_eq!(c.up, [0.0, 1.0, 0.0]);
    match c.projection {
        host::render::scene::Projection::Perspective { yfov, aspect } => {
            assert_eq!(yfov, 0.7854);
            assert_eq!(aspect, Some(1.0));
        }
        p => panic!("{p:?}"),
    }
    assert!(!s.has_lights(), "the file has no light of its own");
    assert!(s.counts.triangles >= 30, "{}", s.counts.triangles);
    check_traversal(&s, 20_000, 3);
    // the box is closed except its front: a ray from the camera hits the back wall
    let h = bvh::closest_hit(&s.words, &Ray::new(Vec3::new(0.0, 1.0, 3.5), Vec3::new(0.0, 0.0, -1.0)), f32::INFINITY);
    assert!(h.is_hit());
}

#[test]
fn feature_scene_loads_without_warnings_and_flattens_as_written() {
    let dir = tempfile::tempdir().unwrap();
    // textures: a 2x2 base colour (with alpha) and a 1x2 normal map
    let base_px: [[u8; 4]; 4] = [[255, 0, 0, 255], [0, 255, 0, 128], [0, 0, 255, 0], [10, 20, 30, 40]];
    let mut img = image::RgbaImage::new(2, 2);
    for (k, px) in base_px.iter().enumerate() {
        img.put_pixel(k as u32 % 2, k as u32 / 2, image::Rgba(*px));
    }
    img.save(dir.path().join("base.png")).unwrap();
    let mut nimg = image::RgbaImage::new(1, 2);
    nimg.put_pixel(0, 0, image::Rgba([128, 128, 255, 255]));
    nimg.put_pixel(0, 1, image::Rgba([200, 100, 220, 255]));
    nimg.save(dir.path().join("normal.png")).unwrap();

    let mut bin = Bin::default();
    let emissive_quad = bin.quad(0.0, true);
    let mut mask_quad = bin.quad(-1.0, false);
    mask_quad["material"] = json!(1);
    let mut em = emissive_quad.clone();
    em["material"] = json!(0);
    let doc = json!({
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
        "nodes": [
            {"mesh": 0, "translation": [0.0, 0.0, 0.5]},
            {"name": "cam node", "camera": 0, "translation": [0.0, 0.0, 5.0]},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [1.0, 2.0, 3.0]},
            {"extensions": {"KHR_lights_punctual": {"light": 1}}, "translation": [0.0, 4.0, 0.0], "rotation": [-0.70710677, 0.0, 0.0, 0.70710677]},
            {"extensions": {"KHR_lights_punctual": {"light": 2}}, "rotation": [-0.70710677, 0.0, 0.0, 0.70710677]}
        ],
        "cameras": [{"name": "closeup", "type": "perspective", "perspective": {"yfov": 0.6, "znear": 0.1}}],
        "meshes": [{"name": "quads", "primitives": [em, mask_quad]}],
        "materials": [
            {"name": "glow", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.6, 0.7, 1.0], "baseColorTexture": {"index": 0}, "metallicFactor": 0.25, "roughnessFactor": 0.75},
             "normalTexture": {"index": 1, "scale": 0.8}, "emissiveFactor": [1.0, 0.5, 0.25],
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}},
            {"name": "cutout", "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": true,
             "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
             "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5}, "KHR_materials_ior": {"ior": 1.33}}}
        ],
        "textures": [{"source": 0, "sampler": 0}, {"source": 1}],
        "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33648}],
        "images": [{"uri": "base.png"}, {"uri": "normal.png"}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "bulb", "type": "point", "color": [1.0, 0.5, 0.25], "intensity": 10.0, "range": 5.0},
            {"name": "spot", "type": "spot", "intensity": 20.0, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
            {"name": "sun", "type": "directional", "color": [1.0, 1.0, 0.5], "intensity": 3.0}
        ]}}
    });
    let p = write_gltf(dir.path(), "features", doc, &bin);
    let s = Scene::load(&p).expect("loads");
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    check_bvh(&s);
    let w = &s.words;
    let f = |i: usize| sc::float(w, i);
    // materials
    assert_eq!(s.counts.materials, 2);
    let m0 = |k: usize| sc::material(w, 0, k);
    assert_eq!([f(m0(sc::M_BASE)), f(m0(sc::M_BASE + 1)), f(m0(sc::M_BASE + 2)), f(m0(sc::M_BASE + 3))], [0.5, 0.6, 0.7, 1.0]);
    assert_eq!((f(m0(sc::M_METALLIC)), f(m0(sc::M_ROUGHNESS))), (0.25, 0.75));
    assert_eq!([f(m0(sc::M_EMISSIVE)), f(m0(sc::M_EMISSIVE + 1)), f(m0(sc::M_EMISSIVE + 2))], [4.0, 2.0, 1.0], "factor x strength");
    assert_eq!(f(m0(sc::M_NORMAL_SCALE)), 0.8);
    assert_eq!(word(w, m0(sc::M_ALPHA_MODE)), sc::ALPHA_OPAQUE);
    assert_eq!(word(w, m0(sc::M_BASE_TEX)), 0);
    assert_eq!(word(w, m0(sc::M_NORMAL_TEX)), 1);
    assert_eq!(word(w, m0(sc::M_MR_TEX)), sc::NONE);
    assert_eq!(word(w, m0(sc::M_DOUBLE_SIDED)), 0);
    assert_eq!(f(m0(sc::M_IOR)), 1.5);
    let m1 = |k: usize| sc::material(w, 1, k);
    assert_eq!(word(w, m1(sc::M_ALPHA_MODE)), sc::ALPHA_MASK);
    assert_eq!(f(m1(sc::M_ALPHA_CUTOFF)), 0.3);
    assert_eq!(word(w, m1(sc::M_DOUBLE_SIDED)), 1);
    assert_eq!((f(m1(sc::M_TRANSMISSION)), f(m1(sc::M_IOR))), (0.5, 1.33));
    assert_eq!(word(w, m1(sc::M_BASE_TEX)), 0, "the shared texture is decoded once");
    // textures and texels
    assert_eq!(s.counts.textures, 2);
    assert_eq!(s.counts.texel_bytes, 4 * (4 + 2));
    let t0 = |k: usize| word(w, sc::texture(w, 0, k));
    assert_eq!((t0(sc::T_WIDTH), t0(sc::T_HEIGHT)), (2, 2));
    assert_eq!((t0(sc::T_WRAP_S), t0(sc::T_WRAP_T), t0(sc::T_NEAREST)), (sc::WRAP_CLAMP, sc::WRAP_MIRROR, 1));
    let t1 = |k: usize| word(w, sc::texture(w, 1, k));
    assert_eq!((t1(sc::T_WRAP_S), t1(sc::T_WRAP_T), t1(sc::T_NEAREST), t1(sc::T_TEXELS)), (sc::WRAP_REPEAT, sc::WRAP_REPEAT, 0, 4));
    let texels = header(w, sc::H_TEXELS_OFF) as usize;
    for (k, px) in base_px.iter().enumerate() {
        assert_eq!(word(w, texels + k), u32::from_le_bytes(*px), "texel {k}");
    }
    assert_eq!(word(w, texels + 5), u32::from_le_bytes([200, 100, 220, 255]));
    // lights: the three punctual ones in node order, then the emissive quad's two triangles
    assert_eq!((s.counts.punctual_lights, s.counts.emissive_triangles, s.counts.lights), (3, 2, 5));
    let l = |i: u32, k: usize| sc::light(w, i, k);
    assert_eq!(word(w, l(0, sc::L_TYPE)), sc::LIGHT_POINT);
    assert_eq!(sc::vec3(w, l(0, sc::L_POSITION)), Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(sc::vec3(w, l(0, sc::L_INTENSITY)), Vec3::new(10.0, 5.0, 2.5));
    assert_eq!(f(l(0, sc::L_RANGE)), 5.0);
    assert_eq!(word(w, l(1, sc::L_TYPE)), sc::LIGHT_SPOT);
    let d = sc::vec3(w, l(1, sc::L_DIRECTION));
    assert!((d - Vec3::new(0.0, -1.0, 0.0)).length() < 1e-6, "the spot points down its node's -Z: {d:?}");
    assert_eq!((f(l(1, sc::L_COS_INNER)), f(l(1, sc::L_COS_OUTER))), (0.2f64.cos() as f32, 0.5f64.cos() as f32));
    assert_eq!(f(l(1, sc::L_RANGE)), 0.0, "no range: infinite");
    assert_eq!(word(w, l(2, sc::L_TYPE)), sc::LIGHT_DIRECTIONAL);
    assert_eq!(sc::vec3(w, l(2, sc::L_INTENSITY)), Vec3::new(3.0, 3.0, 1.5));
    for i in 3..5 {
        assert_eq!(word(w, l(i, sc::L_TYPE)), sc::LIGHT_TRIANGLE);
        let t = word(w, l(i, sc::L_TRIANGLE));
        assert_eq!(word(w, sc::shading(w, t, sc::S_LIGHT)), i);
        assert_eq!(word(w, sc::shading(w, t, sc::S_MATERIAL)), 0);
        assert_eq!(f(l(i, sc::L_AREA)), 2.0);
        let flags = word(w, sc::shading(w, t, sc::S_FLAGS));
        assert_eq!(flags, sc::SF_NORMALS | sc::SF_UVS | sc::SF_TANGENTS);
    }
    // the camera
    let c = s.camera("closeup").expect("named camera");
    assert_eq!((c.position, c.forward, c.up), ([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]));
    assert_eq!(c.projection, host::render::scene::Projection::Perspective { yfov: 0.6, aspect: None });
    // the mesh node's translation: the emissive quad at z = 0.5, the masked one at z = -0.5
    let h = bvh::closest_hit(w, &Ray::new(Vec3::new(0.1, 0.1, 5.0), Vec3::new(0.0, 0.0, -1.0)), f32::INFINITY);
    assert_eq!(h.t, 4.5);
    // the masked quad: alpha factor 1 x texel alpha; (u, v) = (0.75, 0.25) is texel (1, 0), alpha 128/255 >= 0.3
    // and (0.75, 0.75) is texel (1, 1), alpha 40/255 < 0.3: rays pass there (nearest sampling)
    let below = |x: f32, y: f32| bvh::closest_hit(w, &Ray::new(Vec3::new(x, y, 0.0), Vec3::new(0.0, 0.0, -1.0)), f32::INFINITY);
    assert!(below(0.5, 0.5).is_hit(), "uv (0.75, 0.25): kept");
    assert!(!below(0.5, -0.5).is_hit(), "uv (0.75, 0.75): cut out");

    // ...and renders through its own camera and lights: every pixel finite, most of them lit.
    let black = host::render::environment::build(&host::render::environment::EnvSpec::Black, 1.0, 0.0).unwrap();
    let lut = vec![0.0f32; shader_core::energy::LUT_HEADER];
    let camera = s.camera("closeup").unwrap().kernel(16, 16).unwrap();
    let p = shader_core::pt::integrator::RenderParams { width: 16, height: 16, spp: 1, sample_base: 0, seed: 1, max_depth: 4, rr_depth: 3, strategy: 0, compensation: shader_core::energy::COMP_NONE, sampler: shader_core::pt::sampler::SAMPLER_PCG, clamp: 0.0, p_env: 0.0, camera };
    let inputs = host::render::RenderInputs { scene: w, env: &black.words, lut: &lut };
    let (img, _) = host::render::render(&host::Backend::Cpu, &inputs, &p, 4, 4, |_| {}).unwrap();
    assert!(img.color.iter().all(|v| v.is_finite()), "non-finite pixels");
    let lit = img.color.chunks_exact(3).filter(|c| c[0] + c[1] + c[2] > 0.0).count();
    assert!(lit > 128, "only {lit} of 256 pixels lit");
}

#[test]
fn glb_and_data_uris_load() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = Bin::default();
    let mut doc = one_quad(&mut bin);
    doc["asset"] = json!({"version": "2.0"});
    doc["bufferViews"] = json!(bin.views);
    doc["accessors"] = json!(bin.accessors);
    // data URI
    let b64 = {
        const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut s = String::new();
        for c in bin.data.chunks(3) {
            let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
            for k in 0..4 {
                if k <= c.len() {
                    s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
                } else {
                    s.push('=');
                }
            }
        }
        s
    };
    let mut d = doc.clone();
    d["buffers"] = json!([{"uri": format!("data:application/octet-stream;base64,{b64}"), "byteLength": bin.data.len()}]);
    let p = dir.path().join("data.gltf");
    std::fs::write(&p, d.to_string()).unwrap();
    let s = Scene::load(&p).expect("data URI");
    assert_eq!(s.counts.triangles, 2);
    // GLB: header, JSON chunk, BIN chunk
    let mut d = doc.clone();
    d["buffers"] = json!([{"byteLength": bin.data.len()}]);
    let mut js = d.to_string().into_bytes();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    let mut data = bin.data.clone();
    while data.len() % 4 != 0 {
        data.push(0);
    }
    let total = 12 + 8 + js.len() + 8 + data.len();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((js.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&js);
    glb.extend((data.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&data);
    let p = dir.path().join("scene.glb");
    std::fs::write(&p, glb).unwrap();
    let s = Scene::load(&p).expect("GLB");
    assert_eq!(s.counts.triangles, 2);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn hierarchy_strips_fans_mirroring_and_default_material() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = Bin::default();
    let pos = bin.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0], "VEC3");
    let nrm = bin.floats(&[0.0, 0.0, 1.0].repeat(4), "VEC3");
    let fan_pos = bin.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let doc = json!({
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"translation": [10.0, 0.0, 0.0], "children": [1, 2]},
            {"mesh": 0, "matrix": [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0]},
            {"mesh": 1, "scale": [-1.0, 1.0, 1.0], "translation": [0.0, 0.0, -2.0]}
        ],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm}, "mode": 5}]},
            {"primitives": [{"attributes": {"POSITION": fan_pos, "NORMAL": nrm}, "mode": 6}]}
        ]
    });
    let p = write_gltf(dir.path(), "h", doc, &bin);
    let s = Scene::load(&p).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.counts.triangles, 4, "a 4-vertex strip and a 4-vertex fan: 2 triangles each");
    assert_eq!(s.counts.materials, 1, "the glTF default material");
    assert_eq!(s.materials[0], host::render::scene::Material::default());
    assert_eq!((s.materials[0].base_color, s.materials[0].metallic, s.materials[0].roughness), ([1.0; 4], 1.0, 1.0));
    // parent translation + child matrix: the strip at x in [10, 11], z = 1; the mirrored fan at x in [9, 10], z = -2
    assert_eq!(s.bounds.min, [9.0, 0.0, -2.0]);
    assert_eq!(s.bounds.max, [11.0, 1.0, 1.0]);
    let w = &s.words;
    for t in 0..4 {
        let (a, b, c) = sc::triangle(w, t);
        let ng = (b - a).cross(c - a);
        assert!(ng.z > 0.0, "triangle {t}: the winding (flipped for the mirrored node) keeps facing +z: {ng:?}");
        let n0 = sc::vec3(w, sc::shading(w, t, sc::S_NORMALS));
        assert_eq!(n0, Vec3::new(0.0, 0.0, 1.0), "normals through the inverse transpose");
    }
}

#[test]
fn unsupported_features_are_named_in_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = Bin::default();
    let mut prim = bin.quad(0.0, false);
    prim["material"] = json!(0);
    let pts = bin.floats(&[0.0, 0.0, 0.0, 1.0, 1.0, 1.0], "VEC3");
    let uv1 = bin.floats(&[0.0; 8], "VEC2");
    prim["attributes"]["TEXCOORD_1"] = json!(uv1);
    let mut png = image::RgbaImage::new(1, 1);
    png.put_pixel(0, 0, image::Rgba([1, 2, 3, 4]));
    png.save(dir.path().join("t.png")).unwrap();
    let doc = json!({
        "extensionsUsed": ["KHR_materials_volume", "KHR_materials_clearcoat"],
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim, {"attributes": {"POSITION": pts}, "mode": 0}]}],
        "materials": [{"name": "glass", "alphaMode": "BLEND", "occlusionTexture": {"index": 0},
                       "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}}],
        "textures": [{"source": 0}], "images": [{"uri": "t.png"}]
    });
    let p = write_gltf(dir.path(), "w", doc, &bin);
    let s = Scene::load(&p).unwrap();
    let all = s.warnings.join("\n");
    for needle in ["KHR_materials_volume", "KHR_materials_clearcoat", "BLEND", "occlusionTexture", "TEXCOORD_1", "Points"] {
        assert!(all.contains(needle), "no warning names {needle}:\n{all}");
    }
    let m = sc::material(&s.words, 0, sc::M_ALPHA_MODE);
    assert_eq!(word(&s.words, m), sc::ALPHA_MASK, "BLEND as MASK");
    assert_eq!(sc::float(&s.words, m + 1), 0.5);
}

#[test]
fn a_normal_map_without_tangents_gets_computed_ones_and_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = Bin::default();
    let mut prim = bin.quad(0.0, false);
    prim["material"] = json!(0);
    image::RgbaImage::new(1, 1).save(dir.path().join("n.png")).unwrap();
    let doc = json!({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim]}],
        "materials": [{"normalTexture": {"index": 0}}], "textures": [{"source": 0}], "images": [{"uri": "n.png"}]
    });
    let s = Scene::load(write_gltf(dir.path(), "n", doc, &bin)).unwrap();
    assert!(s.warnings.iter().any(|w| w.contains("tangents computed")), "{:?}", s.warnings);
    let w = &s.words;
    for t in 0..2 {
        assert_ne!(word(w, sc::shading(w, t, sc::S_FLAGS)) & sc::SF_TANGENTS, 0);
        let o = sc::shading(w, t, sc::S_TANGENTS);
        // u grows with x, v (downwards in the image) grows with -y: tangent +x, bitangent +y, w = +1
        assert_eq!(sc::vec3(w, o), Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(sc::float(w, o + 3), 1.0);
    }
}

#[test]
fn degenerate_triangles_are_dropped_with_their_count() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = Bin::default();
    let pos = bin.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 2.0, 0.0, 0.0], "VEC3");
    let idx = bin.indices(&[0, 1, 2, 0, 1, 3, 2, 2, 1]);
    let doc = json!({"scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                     "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}]});
    let s = Scene::load(write_gltf(dir.path(), "d", doc, &bin)).unwrap();
    assert_eq!(s.counts.triangles, 1);
    assert_eq!(s.counts.degenerate, 2);
    assert!(s.warnings.iter().any(|w| w.contains("2 degenerate")), "{:?}", s.warnings);
}

#[test]
fn bad_scenes_give_errors_naming_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // malformed JSON
    let p = d.join("bad.gltf");
    std::fs::write(&p, "{ \"asset\": { \"version\": \"2.0\" }, ").unwrap();
    let e = load_err(&p);
    assert!(e.contains("bad.gltf") && e.contains("malformed"), "{e}");
    // a missing file
    let e = load_err(&d.join("nope.gltf"));
    assert!(e.contains("nope.gltf"), "{e}");
    // missing buffer file
    let mut bin = Bin::default();
    let mut doc = one_quad(&mut bin);
    doc["buffers"] = json!([{"uri": "missing.bin", "byteLength": bin.data.len()}]);
    let e = load_err(&write_gltf(d, "nobuf", doc, &bin));
    assert!(e.contains("buffer 0") && e.contains("missing.bin"), "{e}");
    // a buffer shorter than its byteLength
    let mut bin = Bin::default();
    let mut doc = one_quad(&mut bin);
    doc["buffers"] = json!([{"uri": "short.bin", "byteLength": bin.data.len() + 100}]);
    let e = load_err(&write_gltf(d, "short", doc, &bin));
    assert!(e.contains("buffer 0") && e.contains("byteLength"), "{e}");
    // an index out of range
    let mut bin = Bin::default();
    let pos = bin.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let idx = bin.indices(&[0, 1, 7]);
    let doc = json!({"scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                     "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}]});
    let e = load_err(&write_gltf(d, "index", doc, &bin));
    assert!(e.contains("index 7") && e.contains("out of range") && e.contains("mesh 0 ('tri') primitive 0"), "{e}");
    // an accessor reading past its buffer view
    let mut bin = Bin::default();
    let mut doc = one_quad(&mut bin);
    bin.accessors[0]["count"] = json!(400);
    doc["x"] = json!(0);
    let e = load_err(&write_gltf(d, "acc", doc, &bin));
    assert!(e.contains("accessor 0") || e.contains("accessors[0]"), "{e}");
    // a JSON index out of range (a node's mesh)
    let mut bin = Bin::default();
    let mut doc = one_quad(&mut bin);
    doc["nodes"][0]["mesh"] = json!(5);
    let e = load_err(&write_gltf(d, "meshidx", doc, &bin));
    assert!(e.contains("nodes[0].mesh") && e.to_lowercase().contains("index"), "{e}");
    // NaN positions
    let mut bin = Bin::default();
    let pos = bin.floats(&[0.0, 0.0, 0.0, 1.0, f32::NAN, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let doc = json!({"scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                     "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}]});
    let e = load_err(&write_gltf(d, "nan", doc, &bin));
    assert!(e.contains("POSITION 1") && e.contains("not finite") && e.contains("mesh 0"), "{e}");
    // an unsupported required extension
    let mut bin = Bin::default();
    let mut doc = one_quad(&mut bin);
    doc["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let e = load_err(&write_gltf(d, "ext", doc, &bin));
    assert!(e.contains("extensionsRequired") && e.contains("KHR_draco_mesh_compression"), "{e}");
    // no triangles
    let bin = Bin::default();
    let doc = json!({"scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"name": "empty"}]});
    let e = load_err(&write_gltf(d, "empty", doc, &bin));
    assert!(e.contains("no triangles"), "{e}");
    // only degenerate triangles
    let mut bin = Bin::default();
    let pos = bin.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0], "VEC3");
    let doc = json!({"scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                     "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}]});
    let e = load_err(&write_gltf(d, "degen", doc, &bin));
    assert!(e.contains("no triangles") && e.contains("1 degenerate"), "{e}");
    // a missing image
    let mut bin = Bin::default();
    let mut doc = one_quad(&mut bin);
    doc["meshes"][0]["primitives"][0]["material"] = json!(0);
    doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    doc["textures"] = json!([{"source": 0}]);
    doc["images"] = json!([{"uri": "lost.png"}]);
    let e = load_err(&write_gltf(d, "img", doc, &bin));
    assert!(e.contains("image 0") && e.contains("lost.png"), "{e}");
    // an undecodable image
    std::fs::write(d.join("junk.png"), b"not a png").unwrap();
    let mut bin = Bin::default();
    let mut doc = one_quad(&mut bin);
    doc["meshes"][0]["primitives"][0]["material"] = json!(0);
    doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    doc["textures"] = json!([{"source": 0}]);
    doc["images"] = json!([{"uri": "junk.png"}]);
    let e = load_err(&write_gltf(d, "junk", doc, &bin));
    assert!(e.contains("image 0") && e.contains("decode"), "{e}");
}

/// Rewrites the glTF JSON at `p` through `edit`.
fn patch(p: &Path, edit: impl FnOnce(&mut Value)) {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
    edit(&mut v);
    std::fs::write(p, serde_json::to_string_pretty(&v).unwrap()).unwrap();
}

/// A quad scene as written by `one_quad`, then edited.
fn quad_with(d: &Path, name: &str, edit: impl FnOnce(&mut Value)) -> PathBuf {
    let mut bin = Bin::default();
    let doc = one_quad(&mut bin);
    let p = write_gltf(d, name, doc, &bin);
    patch(&p, edit);
    p
}

/// A primitive whose POSITION accessor index is out of range is a named error, not a panic
/// inside gltf-json's validation (which indexes the accessor list unchecked).
#[test]
fn a_position_accessor_out_of_range_is_named_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let p = quad_with(dir.path(), "pos99", |v| v["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(99));
    let e = std::panic::catch_unwind(|| load_err(&p)).expect("loading panicked");
    assert!(e.contains("meshes[0].primitives[0].attributes.POSITION") && e.contains("99") && e.contains("out of range"), "{e}");
}

/// Every bound of the specification the loader checks gives an error naming the JSON path.
#[test]
fn spec_bounds_are_refused_naming_the_json_path() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let light = |l: Value| {
        move |v: &mut Value| {
            v["extensionsUsed"] = json!(["KHR_lights_punctual"]);
            v["extensions"] = json!({"KHR_lights_punctual": {"lights": [l]}});
            v["nodes"].as_array_mut().unwrap().push(json!({"extensions": {"KHR_lights_punctual": {"light": 0}}}));
            v["scenes"][0]["nodes"] = json!([0, 1]);
        }
    };
    let material = |m: Value| {
        move |v: &mut Value| {
            v["extensionsUsed"] = json!(["KHR_materials_emissive_strength", "KHR_materials_ior", "KHR_materials_transmission"]);
            v["materials"] = json!([m]);
            v["meshes"][0]["primitives"][0]["material"] = json!(0);
        }
    };
    let camera = |c: Value| {
        move |v: &mut Value| {
            v["cameras"] = json!([c]);
            v["nodes"].as_array_mut().unwrap().push(json!({"camera": 0, "translation": [0, 0, 3]}));
            v["scenes"][0]["nodes"] = json!([0, 1]);
        }
    };
    type Edit = Box<dyn FnOnce(&mut Value)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        ("v1", Box::new(|v: &mut Value| v["asset"]["version"] = json!("1.0")), "asset.version"),
        ("minv", Box::new(|v: &mut Value| v["asset"]["minVersion"] = json!("2.1")), "asset.minVersion"),
        ("negpoint", Box::new(light(json!({"type": "point", "intensity": -5.0}))), "extensions.KHR_lights_punctual.lights[0].intensity"),
        ("range0", Box::new(light(json!({"type": "point", "range": 0.0}))), "lights[0].range"),
        ("cones", Box::new(light(json!({"type": "spot", "spot": {"innerConeAngle": 0.6, "outerConeAngle": 0.5}}))), "lights[0].spot.innerConeAngle"),
        ("wide", Box::new(light(json!({"type": "spot", "spot": {"outerConeAngle": 2.0}}))), "lights[0].spot.outerConeAngle"),
        ("colour", Box::new(light(json!({"type": "directional", "color": [2.0, 1.0, 1.0]}))), "lights[0].color[0]"),
        (
            "negstrength",
            Box::new(material(json!({"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": -3.0}}}))),
            "materials[0].extensions.KHR_materials_emissive_strength.emissiveStrength",
        ),
        ("emissive", Box::new(material(json!({"emissiveFactor": [1e30, 1, 1]}))), "materials[0].emissiveFactor[0]"),
        (
            "overflow",
            Box::new(material(json!({"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e39}}}))),
            "emissiveStrength",
        ),
        ("base", Box::new(material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.5]}}))), "materials[0].pbrMetallicRoughness.baseColorFactor[3]"),
        ("rough", Box::new(material(json!({"pbrMetallicRoughness": {"roughnessFactor": -0.1}}))), "materials[0].pbrMetallicRoughness.roughnessFactor"),
        ("ior", Box::new(material(json!({"extensions": {"KHR_materials_ior": {"ior": 0.5}}}))), "materials[0].extensions.KHR_materials_ior.ior"),
        ("trans", Box::new(material(json!({"extensions": {"KHR_materials_transmission": {"transmissionFactor": 2.0}}}))), "transmissionFactor"),
        ("yfov", Box::new(camera(json!({"type": "perspective", "perspective": {"yfov": 4.0, "znear": 0.1}}))), "cameras[0].perspective.yfov"),
        ("znear", Box::new(camera(json!({"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.0}}))), "cameras[0].perspective.znear"),
        ("xmag", Box::new(camera(json!({"type": "orthographic", "orthographic": {"xmag": 0.0, "ymag": 1.0, "znear": 0.0, "zfar": 10.0}}))), "cameras[0].orthographic.xmag"),
        ("counts", Box::new(|v: &mut Value| {
            let mut extra = v["accessors"][0].clone();
            extra["count"] = json!(1);
            extra.as_object_mut().unwrap().remove("min");
            extra.as_object_mut().unwrap().remove("max");
            v["accessors"].as_array_mut().unwrap().push(extra);
            let last = v["accessors"].as_array().unwrap().len() - 1;
            v["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = json!(last);
        }), "meshes[0].primitives[0].attributes."),
        ("imgboth", Box::new(|v: &mut Value| v["images"] = json!([{"uri": "x.png", "bufferView": 0}])), "images[0]: has both"),
        ("imgnone", Box::new(|v: &mut Value| v["images"] = json!([{"name": "nothing"}])), "images[0]: has neither"),
        ("imgmime", Box::new(|v: &mut Value| v["images"] = json!([{"bufferView": 0}])), "images[0].mimeType"),
        ("imggif", Box::new(|v: &mut Value| v["images"] = json!([{"uri": "x.gif", "mimeType": "image/gif"}])), "images[0].mimeType"),
        ("texcoord", Box::new(|v: &mut Value| {
            v["images"] = json!([{"uri": "x.png"}]);
            v["textures"] = json!([{"source": 0}]);
            v["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 3}}}]);
            v["meshes"][0]["primitives"][0]["material"] = json!(0);
        }), "meshes[0].primitives[0].attributes: no TEXCOORD_3"),
        ("stride", Box::new(|v: &mut Value| v["bufferViews"][0]["byteStride"] = json!(6)), "bufferViews[0].byteStride"),
        ("viewlen", Box::new(|v: &mut Value| v["bufferViews"][0]["byteLength"] = json!(1_000_000)), "bufferViews[0].byteLength"),
        ("accoff", Box::new(|v: &mut Value| v["accessors"][0]["byteOffset"] = json!(2)), "accessors[0].byteOffset"),
        ("acccount", Box::new(|v: &mut Value| v["accessors"][0]["count"] = json!(1_000_000)), "accessors[0].count"),
        ("quat", Box::new(|v: &mut Value| v["nodes"][0]["rotation"] = json!([0.0, 0.0, 0.0, 2.0])), "nodes[0].rotation"),
        ("both", Box::new(|v: &mut Value| {
            v["nodes"][0]["matrix"] = json!([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
            v["nodes"][0]["scale"] = json!([1, 1, 1]);
        }), "nodes[0].matrix"),
        ("cycle", Box::new(|v: &mut Value| {
            v["nodes"] = json!([{"mesh": 0, "children": [1]}, {"children": [2]}, {"children": [1]}]);
        }), "nodes[2].children[0]"),
        ("twoparents", Box::new(|v: &mut Value| {
            v["nodes"] = json!([{"children": [2]}, {"children": [2]}, {"mesh": 0}]);
            v["scenes"][0]["nodes"] = json!([0, 1]);
        }), "nodes[1].children[0]"),
        ("notroot", Box::new(|v: &mut Value| {
            v["nodes"] = json!([{"children": [1]}, {"mesh": 0}]);
            v["scenes"][0]["nodes"] = json!([0, 1]);
        }), "scenes[0].nodes[1]"),
    ];
    for (name, edit, want) in cases {
        let p = quad_with(d, name, edit);
        let e = std::panic::catch_unwind(|| load_err(&p)).unwrap_or_else(|_| panic!("{name}: loading panicked"));
        assert!(e.contains(want), "{name}: the error does not name {want}: {e}");
    }
    // within the bounds: loads
    let p = quad_with(d, "ok", |v| {
        light(json!({"type": "spot", "intensity": 0.0, "range": 2.0, "spot": {"innerConeAngle": 0.0, "outerConeAngle": std::f32::consts::FRAC_PI_2}}))(v);
        v["asset"]["version"] = json!("2.1");
        v["asset"]["minVersion"] = json!("2.0");
    });
    Scene::load(&p).unwrap_or_else(|e| panic!("{e:#}"));
}

/// A GLB with a wrong magic says so (not a JSON parse error at line 1, column 1); a binary file
/// with a .gltf name is named as neither JSON nor GLB.
#[test]
fn a_wrong_glb_magic_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.glb");
    let mut bytes = b"gLTF".to_vec();
    bytes.extend_from_slice(&2u32.to_le_bytes());
    bytes.extend_from_slice(&20u32.to_le_bytes());
    bytes.extend_from_slice(&[0; 8]);
    std::fs::write(&p, &bytes).unwrap();
    let e = load_err(&p);
    assert!(e.contains("not a GLB file") && e.contains("67 4c 54 46"), "{e}");
    let q = dir.path().join("bin.gltf");
    std::fs::write(&q, [0u8, 1, 2, 3, 4]).unwrap();
    let e = load_err(&q);
    assert!(e.contains("neither a glTF JSON document") && e.contains("00 01 02 03"), "{e}");
}

/// A scene whose meshes are only points and lines says that they are unsupported, not merely
/// that there are no triangles.
#[test]
fn points_and_lines_only_scenes_say_they_are_unsupported() {
    let dir = tempfile::tempdir().unwrap();
    for (mode, name) in [(0, "Points"), (1, "Lines"), (3, "LineStrip")] {
        let p = quad_with(dir.path(), &format!("m{mode}"), |v| v["meshes"][0]["primitives"][0]["mode"] = json!(mode));
        let e = load_err(&p);
        assert!(e.contains("points or lines") && e.contains(&format!("meshes[0].primitives[0].mode = {name}")) && e.contains("triangles"), "{e}");
    }
}

/// A directional or spot light whose node transform is singular has no direction: an error,
/// not a light pointing down -z.
#[test]
fn a_directed_light_under_a_singular_transform_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let p = quad_with(dir.path(), "sing", |v| {
        v["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        v["extensions"] = json!({"KHR_lights_punctual": {"lights": [{"type": "directional"}]}});
        v["nodes"].as_array_mut().unwrap().push(json!({"scale": [0, 0, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}}));
        v["scenes"][0]["nodes"] = json!([0, 1]);
    });
    let e = load_err(&p);
    assert!(e.contains("no direction") && e.contains("nodes[1]"), "{e}");
}

/// `KHR_texture_transform` against an independent reading of the extension spec: a ray's hit on a
/// quad textured by a 4x4 nearest-sampled REPEAT texture of distinct texels shows the texel at
/// uv' = T R S uv, T R S built in f64 from the spec's three matrices (glam), for points away
/// from texel edges; per slot (base colour and emissive differ), identity where absent; a
/// texCoord override is warned about; a bad value is an error naming the slot and the field.
#[test]
fn texture_transform_maps_uvs_as_the_extension_spec_says() {
    use glam::{DMat3, DVec3};
    use shader_core::pt::surface::surface_point;
    let dir = tempfile::tempdir().unwrap();
    let mut img = image::RgbaImage::new(4, 4);
    for k in 0..16u32 {
        img.put_pixel(k % 4, k / 4, image::Rgba([(16 * k) as u8, (255 - 16 * k) as u8, 0, 255]));
    }
    img.save(dir.path().join("grid.png")).unwrap();
    let scene_with = |name: &str, base_tt: Value, emissive_tt: Option<Value>| {
        let mut bin = Bin::default();
        let mut doc = one_quad(&mut bin);
        let mut base = json!({"index": 0});
        base["extensions"] = json!({"KHR_texture_transform": base_tt});
        let mut emissive = json!({"index": 0});
        if let Some(e) = emissive_tt {
            emissive["extensions"] = json!({"KHR_texture_transform": e});
        }
        doc["meshes"][0]["primitives"][0]["material"] = json!(0);
        doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": base}, "emissiveTexture": emissive, "emissiveFactor": [1.0, 1.0, 1.0]}]);
        doc["textures"] = json!([{"source": 0, "sampler": 0}]);
        doc["samplers"] = json!([{"magFilter": 9728, "wrapS": 10497, "wrapT": 10497}]);
        doc["images"] = json!([{"uri": "grid.png"}]);
        doc["extensionsUsed"] = json!(["KHR_texture_transform"]);
        write_gltf(dir.path(), name, doc, &bin)
    };
    // The spec's matrices, row-major as it writes them (glam takes columns: transpose).
    let spec = |offset: [f64; 2], rotation: f64, scale: [f64; 2]| {
        let t = DMat3::from_cols_array(&[1.0, 0.0, offset[0], 0.0, 1.0, offset[1], 0.0, 0.0, 1.0]).transpose();
        let r = DMat3::from_cols_array(&[rotation.cos(), rotation.sin(), 0.0, -rotation.sin(), rotation.cos(), 0.0, 0.0, 0.0, 1.0]).transpose();
        let s = DMat3::from_cols_array(&[scale[0], 0.0, 0.0, 0.0, scale[1], 0.0, 0.0, 0.0, 1.0]).transpose();
        t * r * s
    };
    let texel = |m: DMat3, u: f64, v: f64| -> Option<u32> {
        let p = m * DVec3::new(u, v, 1.0);
        let (x, y) = (p.x.rem_euclid(1.0) * 4.0, p.y.rem_euclid(1.0) * 4.0);
        let edge = |c: f64| (c - c.round()).abs() < 0.02;
        (!edge(x) && !edge(y)).then(|| (y.floor() as u32) * 4 + x.floor() as u32)
    };
    let cases = [([0.25, -0.5], 0.4, [1.5, 0.75]), ([0.0, 0.0], -1.1, [1.0, 1.0]), ([0.6, 0.3], 0.0, [3.0, -2.0])];
    for (i, (offset, rotation, scale)) in cases.into_iter().enumerate() {
        let tt = json!({"offset": offset, "rotation": rotation, "scale": scale});
        let p = scene_with(&format!("tt{i}"), tt, None);
        let s = Scene::load(&p).expect("loads");
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);
        let w = &s.words;
        let m = spec(offset, rotation, scale);
        let mut checked = 0;
        for j in 0..400 {
            let (x, y) = (-0.95 + 1.9 * ((j % 20) as f32 + 0.5) / 20.0, -0.95 + 1.9 * ((j / 20) as f32 + 0.5) / 20.0);
            let h = bvh::closest_hit(w, &Ray::new(Vec3::new(x, y, 1.0), Vec3::new(0.0, 0.0, -1.0)), f32::INFINITY);
            assert!(h.is_hit());
            let sp = surface_point(w, h.tri, h.b1, h.b2, Vec3::new(0.0, 0.0, -1.0));
            // the quad's uv: u = (x + 1) / 2, v = (1 - y) / 2
            let (u, v) = ((x as f64 + 1.0) / 2.0, (1.0 - y as f64) / 2.0);
            let decode = |c: f32| (shader_core::pt::texture::srgb_to_linear(c) * 255.0).round() as u32;
            if let Some(k) = texel(m, u, v) {
                let want = shader_core::pt::texture::srgb_to_linear((16 * k) as f32 / 255.0);
                assert!((sp.material.base.x - want).abs() < 1e-6, "case {i}, uv ({u}, {v}): base colour of texel {k} wanted, got red {}", sp.material.base.x);
                checked += 1;
            }
            // the emissive slot has no transform: its texel is read at uv itself
            if let Some(k) = texel(DMat3::IDENTITY, u, v) {
                let want = shader_core::pt::texture::srgb_to_linear((16 * k) as f32 / 255.0);
                assert!((sp.material.emission.x - want).abs() < 1e-6, "case {i}: emissive at uv ({u}, {v}), red {} (decoded {})", sp.material.emission.x, decode(sp.material.emission.x));
            }
        }
        assert!(checked > 300, "case {i}: only {checked} points away from texel edges");
    }
    // texCoord override: warned, set 0 used
    let s = Scene::load(scene_with("override", json!({"scale": [2.0, 2.0], "texCoord": 1}), None)).unwrap();
    assert!(s.warnings.iter().any(|w| w.contains("baseColorTexture uses TEXCOORD_1")), "{:?}", s.warnings);
    // bad values: named errors
    for (name, tt, what) in [
        ("bad_scale", json!({"scale": [1.0]}), "baseColorTexture.extensions.KHR_texture_transform: scale must be two finite numbers"),
        ("bad_offset", json!({"offset": ["a", 0.0]}), "offset must be two finite numbers"),
        ("bad_rotation", json!({"rotation": "x"}), "rotation must be a finite number"),
        ("huge_scale", json!({"scale": [1e39, 1.0]}), "scale must be two finite numbers"),
        ("bad_set", json!({"texCoord": -1}), "texCoord must be a non-negative integer"),
    ] {
        let e = load_err(&scene_with(name, tt, None));
        assert!(e.contains(what), "{name}: {e}");
    }
    let e = load_err(&scene_with("bad_emissive", json!({}), Some(json!({"rotation": null}))));
    assert!(e.contains("emissiveTexture.extensions.KHR_texture_transform: rotation"), "{e}");
}
