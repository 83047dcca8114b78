//! The built-in scene: a Cornell box (Goral et al. 1984, "Modeling the interaction of light
//! between diffuse surfaces", the box's layout) with an area light under the ceiling and two rows
//! of six glTF metal-rough spheres, roughness 0 to 1: gold metal in front, blue plastic behind.
//!
//! glTF units: the box spans x in [-1, 1], y in [0, 2], z in [-1, 1], open towards +z; white
//! floor, ceiling and back wall, red left (x = -1) and green right (x = 1) walls. The light is a
//! 0.5 x 0.4 single-sided quad at y = 1.98 facing down, emission (17, 12, 4). Spheres of radius
//! 0.13 rest on the floor at x = -0.75 + 0.3 i (roughness 0.2 i); the camera "default" is at
//! (0, 1, 3.4) looking down -z with a 40 degree vertical field of view.

use super::math::Mat4;
use glam::DVec3;
use super::gltf_write::GltfWriter;
use super::{Camera, Material, MeshData, Projection, Scene, SceneBuilder};
use anyhow::{bail, Result};

/// Latitude bands per sphere of the default built-in scene (11.5k triangles).
pub const DEFAULT_DETAIL: u32 = 16;

/// Sphere radius.
const RADIUS: f32 = 0.13;

/// Triangles of the built-in scene at `detail`: 12 spheres of 4 d (d - 1) triangles, 10 for the
/// box, 2 for the light.
pub fn builtin_triangles(detail: u32) -> usize {
    let d = detail.max(3) as usize;
    12 * 4 * d * (d - 1) + 12
}

/// The detail whose built-in scene has the triangle count closest to `triangles` (for
/// benchmarks at 1k / 30k / 300k triangles).
pub fn builtin_detail_for_triangles(triangles: usize) -> u32 {
    (3..2000u32).min_by_key(|&d| (builtin_triangles(d) as i64 - triangles as i64).abs()).unwrap()
}

/// Two triangles of the quad p0 p1 p2 p3 (in order around it), wound to face `normal`.
fn quad(name: &str, p: [[f32; 3]; 4], normal: [f64; 3]) -> MeshData {
    let pd = p.map(|v| DVec3::from(v.map(|x| x as f64)));
    let c = (pd[1] - pd[0]).cross(pd[2] - pd[0]);
    let indices = if c.dot(DVec3::from(normal)) > 0.0 { vec![0, 1, 2, 0, 2, 3] } else { vec![0, 2, 1, 0, 3, 2] };
    let n = normal.map(|x| x as f32);
    MeshData {
        name: name.into(),
        positions: p.to_vec(),
        normals: Some(vec![n; 4]),
        uvs: Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
        tangents: None,
        indices: Some(indices),
    }
}

/// A UV sphere of `bands` latitude bands and 2 `bands` longitudes at the origin, radius `r`:
/// smooth normals, uvs (u = longitude / 2 pi, v = colatitude / pi), outward counter-clockwise
/// faces; seam and pole vertices repeat bit-identical positions so the mesh is watertight.
pub fn uv_sphere(name: &str, r: f32, bands: u32) -> MeshData {
    let nv = bands.max(3) as usize;
    let nu = 2 * nv;
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..=nv {
        let th = std::f64::consts::PI * j as f64 / nv as f64;
        for i in 0..=nu {
            let ph = 2.0 * std::f64::consts::PI * (i % nu) as f64 / nu as f64;
            let n = if j == 0 {
                [0.0, 1.0, 0.0]
            } else if j == nv {
                [0.0, -1.0, 0.0]
            } else {
                [th.sin() * ph.cos(), th.cos(), -th.sin() * ph.sin()]
            };
            positions.push(n.map(|x| (x * r as f64) as f32));
            normals.push(n.map(|x| x as f32));
            uvs.push([i as f32 / nu as f32, j as f32 / nv as f32]);
        }
    }
    let at = |j: usize, i: usize| (j * (nu + 1) + i) as u32;
    let mut indices = Vec::new();
    let mut push = |a: u32, b: u32, c: u32| {
        let p = |k: u32| DVec3::from(positions[k as usize].map(|x| x as f64));
        let n = (p(b) - p(a)).cross(p(c) - p(a));
        let centre = p(a) + p(b) + p(c);
        if n.dot(centre) >= 0.0 {
            indices.extend([a, b, c]);
        } else {
            indices.extend([a, c, b]);
        }
    };
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (at(j, i), at(j, i + 1), at(j + 1, i + 1), at(j + 1, i));
            if j == 0 {
                push(a, c, d);
            } else if j == nv - 1 {
                push(a, b, d);
            } else {
                push(a, b, c);
                push(a, c, d);
            }
        }
    }
    MeshData { name: name.into(), positions, normals: Some(normals), uvs: Some(uvs), tangents: None, indices: Some(indices) }
}

/// The built-in scene's pieces in build order: its materials, its meshes (each a geometry of
/// `geometry`, a material index and the local-to-world transform) and its camera. Both
/// [`cornell_spheres`] and [`cornell_spheres_gltf`] are made from them, so the two stay the
/// same scene.
struct Parts {
    materials: Vec<Material>,
    geometry: Vec<MeshData>,
    meshes: Vec<(usize, usize, Mat4)>,
    camera: Camera,
}

/// The pieces of the built-in scene at `detail` (>= 3) latitude bands per sphere.
fn parts(detail: u32) -> Parts {
    let mut materials = vec![
        Material::pbr("white", [0.73, 0.73, 0.73], 0.0, 1.0),
        Material::pbr("red", [0.65, 0.05, 0.05], 0.0, 1.0),
        Material::pbr("green", [0.12, 0.45, 0.15], 0.0, 1.0),
        Material { emissive: [17.0, 12.0, 4.0], ..Material::pbr("light", [0.78, 0.78, 0.78], 0.0, 1.0) },
    ];
    let (white, red, green, light) = (0, 1, 2, 3);
    let walls = [
        ("floor", [[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]], [0.0, 1.0, 0.0], white),
        ("ceiling", [[-1.0, 2.0, -1.0], [1.0, 2.0, -1.0], [1.0, 2.0, 1.0], [-1.0, 2.0, 1.0]], [0.0, -1.0, 0.0], white),
        ("back", [[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 2.0, -1.0], [-1.0, 2.0, -1.0]], [0.0, 0.0, 1.0], white),
        ("left", [[-1.0, 0.0, -1.0], [-1.0, 0.0, 1.0], [-1.0, 2.0, 1.0], [-1.0, 2.0, -1.0]], [1.0, 0.0, 0.0], red),
        ("right", [[1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [1.0, 2.0, 1.0], [1.0, 2.0, -1.0]], [-1.0, 0.0, 0.0], green),
        ("light", [[-0.25, 1.98, -0.2], [0.25, 1.98, -0.2], [0.25, 1.98, 0.2], [-0.25, 1.98, 0.2]], [0.0, -1.0, 0.0], light),
    ];
    let mut geometry = Vec::new();
    let mut meshes = Vec::new();
    for (name, p, n, m) in walls {
        geometry.push(quad(name, p, n));
        meshes.push((geometry.len() - 1, m, Mat4::IDENTITY));
    }
    geometry.push(uv_sphere("sphere", RADIUS, detail));
    let sphere = geometry.len() - 1;
    for i in 0..6 {
        let roughness = 0.2 * i as f32;
        let x = -0.75 + 0.3 * i as f64;
        materials.push(Material::pbr(&format!("gold {roughness:.1}"), [1.0, 0.78, 0.34], 1.0, roughness));
        materials.push(Material::pbr(&format!("blue plastic {roughness:.1}"), [0.05, 0.15, 0.6], 0.0, roughness));
        let (gold, blue) = (materials.len() - 2, materials.len() - 1);
        meshes.push((sphere, gold, Mat4::translation(DVec3::new(x, RADIUS as f64, 0.35))));
        meshes.push((sphere, blue, Mat4::translation(DVec3::new(x, RADIUS as f64, -0.3))));
    }
    let camera = Camera {
        name: "default".into(),
        position: [0.0, 1.0, 3.4],
        forward: [0.0, 0.0, -1.0],
        up: [0.0, 1.0, 0.0],
        projection: Projection::Perspective { yfov: 40f32.to_radians(), aspect: None },
    };
    Parts { materials, geometry, meshes, camera }
}

/// The built-in Cornell box with spheres (see the module doc) at `detail` latitude bands per
/// sphere.
pub fn cornell_spheres(detail: u32) -> Scene {
    let p = parts(detail.max(3));
    let mut b = SceneBuilder::new(&format!("builtin cornell box (detail {})", detail.max(3)));
    for m in p.materials {
        b.material(m);
    }
    for (g, m, t) in &p.meshes {
        b.mesh(&p.geometry[*g], *m as u32, t).expect("built-in mesh");
    }
    b.camera(p.camera);
    b.build().expect("the built-in scene builds")
}

/// The built-in scene at `detail` as a glTF document ([`GltfWriter::write`] puts it on disk),
/// with `camera` (default: the scene's own camera "default"), so that loading the file
/// renders the same image as [`cornell_spheres`]: meshes in the same order with the same
/// materials, positions moved to world space with the builder's arithmetic (f64, rounded
/// once to f32, so they load back bit-identical). Texture coordinates are not written (the
/// scene has no textures). Fails on an orthographic `camera` (the writer writes perspective
/// cameras only) or a camera whose up is parallel to its direction.
pub fn cornell_spheres_gltf(detail: u32, camera: Option<&Camera>) -> Result<GltfWriter> {
    let p = parts(detail.max(3));
    let mut w = GltfWriter::new();
    for m in &p.materials {
        w.material(m);
    }
    for (g, m, t) in &p.meshes {
        let local = &p.geometry[*g];
        let world = MeshData {
            positions: local.positions.iter().map(|&q| t.point(q).as_vec3().to_array()).collect(),
            normals: local.normals.as_ref().map(|ns| ns.iter().map(|n| t.normal(DVec3::from(n.map(|x| x as f64))).as_vec3().to_array()).collect()),
            uvs: None,
            ..local.clone()
        };
        w.mesh(&world, *m)?;
    }
    let c = camera.unwrap_or(&p.camera);
    let Projection::Perspective { yfov, .. } = c.projection else {
        bail!("camera {:?}: orthographic; the glTF writer writes perspective cameras only", c.name);
    };
    let eye = DVec3::from(c.position.map(|x| x as f64));
    let forward = DVec3::from(c.forward.map(|x| x as f64));
    w.camera(&c.name, eye, eye + forward, DVec3::from(c.up.map(|x| x as f64)), yfov)?;
    Ok(w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detail_sets_the_triangle_count() {
        for d in [3, 5, 16] {
            let s = cornell_spheres(d);
            assert_eq!(s.counts.triangles, builtin_triangles(d), "detail {d}");
            assert!(s.warnings.is_empty(), "{:?}", s.warnings);
        }
        assert_eq!(builtin_detail_for_triangles(1000), 5);
        assert!((builtin_triangles(builtin_detail_for_triangles(300_000)) as f64 / 3e5 - 1.0).abs() < 0.02);
    }
}
