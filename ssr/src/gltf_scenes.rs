//! The glTF scenes of the SSR benchmark (`host bench ssr`), written as glTF 2.0 files by the
//! project ([`::scene::gltf_write`]) and rendered by the path tracer's G-buffer
//! export (`host render --gbuffer`, [`crate::render_gbuffer`]):
//!
//! - `cornell`: the Cornell box of `scenes/cornell_box/` (NVIDIA's RTXGI-era
//!   reference scene, BSD-3) with a glossy floor (perceptual roughness 0.1, dielectric) laid over
//!   its own and a point light under the ceiling; its own camera.
//! - `pillars`: thin objects over floor strips of four roughnesses (0, 0.08, 0.2, 0.35; metal and
//!   dielectric alternating): seven 4 cm poles, a 3 cm rail, a 1 cm sheet, three spheres and a
//!   wall of coloured panels behind them, under a sun and a sky.
//! - `orbit`: an animated camera: a ring of spheres (roughness 0 to 0.5) and boxes on a glossy
//!   metal floor, seen from a camera that turns about the vertical axis by [`ORBIT_DEGREES`] per
//!   frame (`host render --orbit`).
//!
//! Each scene also names its environment (a uniform sky radiance: the reference's fallback) and
//! its camera path; [`GltfScene::write`] writes the files, so `host render` can render them too.

use crate::camera::V3;
use ::scene::gltf_write::GltfWriter;
use ::scene::{uv_sphere, LightKind, Material, MeshData, PunctualLight};
use anyhow::{bail, Context, Result};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The repository's Cornell box (`scenes/cornell_box/cornell_box.gltf`, NVIDIA, BSD-3-Clause:
/// `scenes/cornell_box/LICENSE.txt`), built into the program so the `cornell` scene needs no
/// file beside it.
pub const CORNELL_GLTF: &str = include_str!("../../scenes/cornell_box/cornell_box.gltf");
/// Its buffer (`cornell_box.bin`, the `uri` of [`CORNELL_GLTF`]'s one buffer).
pub const CORNELL_BIN: &[u8] = include_bytes!("../../scenes/cornell_box/cornell_box.bin");

/// Degrees per frame of the `orbit` scene's camera path.
pub const ORBIT_DEGREES: f64 = 1.5;

/// The names [`GltfScene::by_name`] takes.
pub const NAMES: [&str; 3] = ["cornell", "pillars", "orbit"];

/// One of the benchmark's glTF scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GltfScene {
    Cornell,
    Pillars,
    Orbit,
}

impl GltfScene {
    /// The scene called `name` (one of [`NAMES`]), or `None`.
    pub fn by_name(name: &str) -> Option<GltfScene> {
        match name {
            "cornell" => Some(GltfScene::Cornell),
            "pillars" => Some(GltfScene::Pillars),
            "orbit" => Some(GltfScene::Orbit),
            _ => None,
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            GltfScene::Cornell => "cornell",
            GltfScene::Pillars => "pillars",
            GltfScene::Orbit => "orbit",
        }
    }

    /// The uniform environment radiance it is rendered under (and the SSR fallback).
    pub fn sky(self) -> [f32; 3] {
        match self {
            GltfScene::Cornell => [0.5, 0.5, 0.5],
            GltfScene::Pillars => [0.55, 0.65, 0.85],
            GltfScene::Orbit => [0.4, 0.45, 0.55],
        }
    }

    /// Degrees per frame of its camera path (`None`: a static camera).
    pub fn orbit(self) -> Option<f64> {
        match self {
            GltfScene::Orbit => Some(ORBIT_DEGREES),
            _ => None,
        }
    }

    /// Write the scene as `dir/<name>.gltf` (+ `.bin`; the Cornell box's own buffer is copied
    /// beside it) and return the path. The Cornell box is made from `cornell_source`, a `.gltf`
    /// with one external buffer, or, when `None`, from the copy of `scenes/cornell_box/` built
    /// into the program ([`CORNELL_GLTF`]).
    pub fn write(self, dir: &Path, cornell_source: Option<&Path>) -> Result<PathBuf> {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let path = dir.join(format!("{}.gltf", self.name()));
        match self {
            GltfScene::Cornell => write_cornell(cornell_source, &path)?,
            GltfScene::Pillars => pillars()?.write(&path)?,
            GltfScene::Orbit => orbit()?.write(&path)?,
        }
        Ok(path)
    }
}

/// An axis-aligned box with outward faces and flat normals (24 vertices).
pub fn cuboid(name: &str, lo: [f32; 3], hi: [f32; 3]) -> MeshData {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut indices = Vec::new();
    for axis in 0..3 {
        for side in [0usize, 1] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut n = [0.0f32; 3];
            n[axis] = if side == 1 { 1.0 } else { -1.0 };
            let base = positions.len() as u32;
            for (a, b) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
                let mut p = [0.0f32; 3];
                p[axis] = if side == 1 { hi[axis] } else { lo[axis] };
                p[u] = if a == 1 { hi[u] } else { lo[u] };
                p[v] = if b == 1 { hi[v] } else { lo[v] };
                positions.push(p);
                normals.push(n);
            }
            // (u, v) counter-clockwise seen from +axis: flip for the negative side.
            if side == 1 {
                indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
            } else {
                indices.extend_from_slice(&[base, base + 2, base + 1, base, base + 3, base + 2]);
            }
        }
    }
    MeshData { name: name.into(), positions, normals: Some(normals), uvs: None, tangents: None, indices: Some(indices) }
}

/// An upward-facing rectangle at height `y` over x in [x0, x1], z in [z0, z1].
pub fn floor_quad(name: &str, y: f32, x0: f32, x1: f32, z0: f32, z1: f32) -> MeshData {
    MeshData {
        name: name.into(),
        positions: vec![[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]],
        normals: Some(vec![[0.0, 1.0, 0.0]; 4]),
        uvs: None,
        tangents: None,
        indices: Some(vec![0, 2, 1, 0, 3, 2]),
    }
}

/// A UV sphere of radius `r` centred at `c` (48 bands: smooth at 1080p).
fn sphere(name: &str, c: [f32; 3], r: f32) -> MeshData {
    let mut m = uv_sphere(name, r, 48);
    for p in &mut m.positions {
        for k in 0..3 {
            p[k] += c[k];
        }
    }
    m
}

fn add(w: &mut GltfWriter, mesh: MeshData, m: &Material) -> Result<()> {
    let i = w.material(m);
    w.mesh(&mesh, i)
}

fn pillars() -> Result<GltfWriter> {
    let mut w = GltfWriter::new();
    let strips: [(f32, f32, [f32; 3]); 4] = [(0.0, 1.0, [0.9, 0.9, 0.92]), (0.08, 0.0, [0.05, 0.05, 0.06]), (0.2, 1.0, [0.95, 0.75, 0.5]), (0.35, 0.0, [0.1, 0.12, 0.15])];
    for (i, (r, metal, base)) in strips.iter().enumerate() {
        let x0 = -2.0 + i as f32;
        add(&mut w, floor_quad(&format!("floor strip {i}"), 0.0, x0, x0 + 1.0, -3.0, 2.5), &Material::pbr(&format!("floor r{r}"), *base, *metal, *r))?;
    }
    let panels = [[0.8, 0.1, 0.1], [0.1, 0.7, 0.15], [0.1, 0.2, 0.85], [0.9, 0.8, 0.1]];
    for (i, c) in panels.iter().enumerate() {
        let x0 = -2.0 + i as f32;
        add(&mut w, cuboid(&format!("panel {i}"), [x0, 0.0, -3.1], [x0 + 1.0, 2.0, -3.0]), &Material::pbr(&format!("panel {i}"), *c, 0.0, 0.8))?;
    }
    let pole = Material::pbr("pole", [0.9, 0.9, 0.9], 0.0, 0.6);
    for i in 0..7 {
        let x = -1.8 + 0.6 * i as f32;
        add(&mut w, cuboid(&format!("pole {i}"), [x - 0.02, 0.0, -1.22], [x + 0.02, 1.4, -1.18]), &pole)?;
    }
    add(&mut w, cuboid("rail", [-1.9, 0.985, -1.215], [1.9, 1.015, -1.185]), &Material::pbr("rail", [0.95, 0.5, 0.1], 0.0, 0.5))?;
    add(&mut w, cuboid("sheet", [0.2, 0.0, -0.405], [1.0, 0.8, -0.395]), &Material::pbr("sheet", [0.2, 0.6, 0.9], 0.0, 0.5))?;
    add(&mut w, sphere("white sphere", [-1.2, 0.3, -2.2], 0.3), &Material::pbr("white", [0.85, 0.85, 0.85], 0.0, 0.3))?;
    add(&mut w, sphere("gold sphere", [0.0, 0.3, -2.2], 0.3), &Material::pbr("gold", [1.0, 0.78, 0.34], 1.0, 0.1))?;
    add(&mut w, sphere("red sphere", [1.2, 0.3, -2.2], 0.3), &Material::pbr("red", [0.8, 0.1, 0.1], 0.0, 0.5))?;
    w.light(&PunctualLight { name: "sun".into(), kind: LightKind::Directional, position: [0.0; 3], direction: [-0.35, -0.8, -0.5], intensity: [2.8, 2.6, 2.3], range: 0.0 })?;
    w.camera("camera", V3::new(0.0, 1.1, 3.4), V3::new(0.0, 0.45, -1.2), V3::Y, 0.75)?;
    Ok(w)
}

fn orbit() -> Result<GltfWriter> {
    let mut w = GltfWriter::new();
    add(&mut w, floor_quad("floor", 0.0, -6.0, 6.0, -6.0, 6.0), &Material::pbr("brushed steel", [0.8, 0.8, 0.85], 1.0, 0.12))?;
    let colours = [[0.9, 0.2, 0.1], [0.95, 0.8, 0.3], [0.2, 0.7, 0.3], [0.2, 0.4, 0.9], [0.9, 0.9, 0.9], [0.6, 0.2, 0.7], [0.1, 0.1, 0.1], [0.9, 0.5, 0.1]];
    for (i, c) in colours.iter().enumerate() {
        let a = i as f32 / 8.0 * std::f32::consts::TAU;
        let r = 0.5 * i as f32 / 7.0;
        let metal = if i % 2 == 0 { 1.0 } else { 0.0 };
        add(&mut w, sphere(&format!("sphere {i}"), [1.6 * a.cos(), 0.35, 1.6 * a.sin()], 0.35), &Material::pbr(&format!("sphere r{r:.2}"), *c, metal, r))?;
    }
    add(&mut w, cuboid("tower", [-0.3, 0.0, -0.3], [0.3, 1.4, 0.3]), &Material::pbr("tower", [0.8, 0.15, 0.1], 0.0, 0.7))?;
    for (i, (x, z, c)) in [(-3.5f32, -3.0f32, [0.1, 0.5, 0.9]), (3.2, -3.4, [0.95, 0.85, 0.2]), (-3.0, 3.2, [0.2, 0.8, 0.3]), (3.4, 2.8, [0.9, 0.9, 0.9])].iter().enumerate() {
        add(&mut w, cuboid(&format!("block {i}"), [x - 0.5, 0.0, z - 0.5], [x + 0.5, 1.0, z + 0.5]), &Material::pbr(&format!("block {i}"), *c, 0.0, 0.6))?;
    }
    w.light(&PunctualLight { name: "sun".into(), kind: LightKind::Directional, position: [0.0; 3], direction: [0.4, -0.75, -0.3], intensity: [2.5, 2.4, 2.2], range: 0.0 })?;
    w.light(&PunctualLight { name: "lamp".into(), kind: LightKind::Point, position: [0.0, 2.6, 1.0], direction: [0.0, -1.0, 0.0], intensity: [6.0, 5.0, 4.0], range: 0.0 })?;
    w.camera("camera", V3::new(0.0, 1.5, 4.8), V3::new(0.0, 0.35, 0.0), V3::Y, 0.8)?;
    Ok(w)
}

/// The Cornell box (`source`, a `.gltf` with one external buffer; `None`: [`CORNELL_GLTF`])
/// with a glossy floor quad at 1 mm above its floor (y = 0, x and z in [-1, 1]) and a point light
/// under the ceiling, as `path`; the source's buffer is copied beside it.
fn write_cornell(source: Option<&Path>, path: &Path) -> Result<()> {
    let (label, text) = match source {
        Some(source) => (source.display().to_string(), std::fs::read_to_string(source).with_context(|| format!("reading the Cornell box {} (pass --cornell)", source.display()))?),
        None => ("the built-in Cornell box".to_string(), CORNELL_GLTF.to_string()),
    };
    let mut doc: Value = serde_json::from_str(&text).with_context(|| format!("parsing {label}"))?;
    let buffers = doc["buffers"].as_array().cloned().unwrap_or_default();
    if buffers.len() != 1 {
        bail!("{label}: expected one buffer, found {}", buffers.len());
    }
    let uri = buffers[0]["uri"].as_str().with_context(|| format!("{label}: buffer 0 has no uri"))?.to_string();
    if uri.starts_with("data:") {
        bail!("{label}: an embedded buffer is not supported here");
    }
    let bin_name = format!("{}.base.bin", path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());
    let bin_path = path.with_file_name(&bin_name);
    match source {
        Some(source) => {
            let src_bin = source.parent().unwrap_or(Path::new("")).join(&uri);
            std::fs::copy(&src_bin, &bin_path).with_context(|| format!("copying {}", src_bin.display()))?;
        }
        None => fileio::write_file(&bin_path, CORNELL_BIN)?,
    }
    doc["buffers"][0]["uri"] = json!(bin_name);
    // The floor and the light, written by the project's writer into a second buffer.
    let mut w = GltfWriter::new();
    add(&mut w, floor_quad("glossy floor", 0.001, -0.999, 0.999, -0.999, 0.999), &Material::pbr("glossy floor", [0.8, 0.8, 0.8], 0.0, 0.1))?;
    w.light(&PunctualLight { name: "ceiling lamp".into(), kind: LightKind::Point, position: [0.0, 1.85, 0.0], direction: [0.0, -1.0, 0.0], intensity: [3.0, 2.7, 2.2], range: 0.0 })?;
    let extra_path = path.with_file_name(format!("{}.extra.gltf", path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()));
    w.write(&extra_path)?;
    let extra: Value = serde_json::from_str(&std::fs::read_to_string(&extra_path)?)?;
    std::fs::remove_file(&extra_path).ok();
    merge(&mut doc, &extra)?;
    fileio::write_file(path, serde_json::to_string_pretty(&doc)? + "\n")
}

/// Append document `extra` (one buffer, as written by [`GltfWriter`]) to `doc`: its buffer,
/// views, accessors, materials, meshes, nodes (added to scene 0) and punctual lights, with
/// every index shifted.
fn merge(doc: &mut Value, extra: &Value) -> Result<()> {
    let len = |v: &Value, k: &str| v[k].as_array().map(|a| a.len()).unwrap_or(0);
    let (nb, nv, na, nm, nme, nn) = (len(doc, "buffers"), len(doc, "bufferViews"), len(doc, "accessors"), len(doc, "materials"), len(doc, "meshes"), len(doc, "nodes"));
    let nl = doc["extensions"]["KHR_lights_punctual"]["lights"].as_array().map(|a| a.len()).unwrap_or(0);
    let shift = |v: &mut Value, k: &str, by: usize| {
        if let Some(i) = v[k].as_u64() {
            v[k] = json!(i as usize + by);
        }
    };
    let push = |doc: &mut Value, k: &str, items: Vec<Value>| {
        if !doc[k].is_array() {
            doc[k] = json!([]);
        }
        doc[k].as_array_mut().expect("an array").extend(items);
    };
    let arr = |k: &str| extra[k].as_array().cloned().unwrap_or_default();
    push(doc, "buffers", arr("buffers"));
    push(doc, "bufferViews", arr("bufferViews").into_iter().map(|mut v| { shift(&mut v, "buffer", nb); v }).collect());
    push(doc, "accessors", arr("accessors").into_iter().map(|mut v| { shift(&mut v, "bufferView", nv); v }).collect());
    push(doc, "materials", arr("materials"));
    let meshes = arr("meshes")
        .into_iter()
        .map(|mut m| {
            if let Some(ps) = m["primitives"].as_array_mut() {
                for p in ps {
                    shift(p, "material", nm);
                    shift(p, "indices", na);
                    if let Some(a) = p["attributes"].as_object_mut() {
                        for (_, v) in a.iter_mut() {
                            *v = json!(v.as_u64().unwrap_or(0) as usize + na);
                        }
                    }
                }
            }
            m
        })
        .collect();
    push(doc, "meshes", meshes);
    let nodes: Vec<Value> = arr("nodes")
        .into_iter()
        .map(|mut n| {
            shift(&mut n, "mesh", nme);
            if n["extensions"]["KHR_lights_punctual"].is_object() {
                shift(&mut n["extensions"]["KHR_lights_punctual"], "light", nl);
            }
            n
        })
        .collect();
    let added = nodes.len();
    push(doc, "nodes", nodes);
    let scene = doc["scene"].as_u64().unwrap_or(0) as usize;
    let roots = doc["scenes"][scene]["nodes"].as_array_mut().context("the Cornell box's scene has no node list")?;
    roots.extend((nn..nn + added).map(|i| json!(i)));
    if let Some(lights) = extra["extensions"]["KHR_lights_punctual"]["lights"].as_array() {
        if !doc["extensions"].is_object() {
            doc["extensions"] = json!({});
        }
        if !doc["extensions"]["KHR_lights_punctual"].is_object() {
            doc["extensions"]["KHR_lights_punctual"] = json!({"lights": []});
        }
        doc["extensions"]["KHR_lights_punctual"]["lights"].as_array_mut().context("lights")?.extend(lights.iter().cloned());
        if !doc["extensionsUsed"].is_array() {
            doc["extensionsUsed"] = json!([]);
        }
        let used = doc["extensionsUsed"].as_array_mut().expect("an array");
        if !used.iter().any(|u| u == "KHR_lights_punctual") {
            used.push(json!("KHR_lights_punctual"));
        }
    }
    Ok(())
}
