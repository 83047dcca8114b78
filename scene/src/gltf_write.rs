//! Writing glTF 2.0 files (the specification's JSON + binary-buffer form): triangle meshes with
//! normals, factor-only metal-rough materials, perspective cameras and `KHR_lights_punctual`
//! lights, so the project can make its own test and benchmark scenes and load them back through
//! the same loader as any other file ([`super::Scene::load`]).
//!
//! Everything is written in world space (node translations only for meshes; cameras and lights
//! carry the rotation that turns their local -Z to the given direction, glTF 2.0 section 3.10.1
//! and the extension's spec).

use glam::DVec3;
use super::{LightKind, Material, MeshData, PunctualLight};
use anyhow::{bail, Context, Result};
use serde_json::{json, Value};
use std::path::Path;

/// A glTF document being assembled; [`GltfWriter::write`] puts it on disk.
#[derive(Debug, Default)]
pub struct GltfWriter {
    bin: Vec<u8>,
    buffer_views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    nodes: Vec<Value>,
    materials: Vec<Value>,
    cameras: Vec<Value>,
    lights: Vec<Value>,
}

/// The unit quaternion (x, y, z, w) of the rotation with matrix columns `c0, c1, c2`
/// (Shepperd's method: the largest of the four candidates is divided by).
pub fn quaternion_from_columns(c0: DVec3, c1: DVec3, c2: DVec3) -> [f32; 4] {
    let m = |r: usize, c: usize| [c0, c1, c2][c][r];
    let tr = m(0, 0) + m(1, 1) + m(2, 2);
    let q = if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        [(m(2, 1) - m(1, 2)) / s, (m(0, 2) - m(2, 0)) / s, (m(1, 0) - m(0, 1)) / s, 0.25 * s]
    } else if m(0, 0) > m(1, 1) && m(0, 0) > m(2, 2) {
        let s = (1.0 + m(0, 0) - m(1, 1) - m(2, 2)).sqrt() * 2.0;
        [0.25 * s, (m(0, 1) + m(1, 0)) / s, (m(0, 2) + m(2, 0)) / s, (m(2, 1) - m(1, 2)) / s]
    } else if m(1, 1) > m(2, 2) {
        let s = (1.0 + m(1, 1) - m(0, 0) - m(2, 2)).sqrt() * 2.0;
        [(m(0, 1) + m(1, 0)) / s, 0.25 * s, (m(1, 2) + m(2, 1)) / s, (m(0, 2) - m(2, 0)) / s]
    } else {
        let s = (1.0 + m(2, 2) - m(0, 0) - m(1, 1)).sqrt() * 2.0;
        [(m(0, 2) + m(2, 0)) / s, (m(1, 2) + m(2, 1)) / s, 0.25 * s, (m(1, 0) - m(0, 1)) / s]
    };
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    q.map(|v| (v / n) as f32)
}

/// The node rotation whose local -Z is `forward` and whose local +Y is as close to `up` as
/// possible (`up` must not be parallel to `forward`).
pub fn look_rotation(forward: DVec3, up: DVec3) -> Result<[f32; 4]> {
    let f = forward / forward.length();
    let r = f.cross(up);
    let rn = r.length();
    if !(rn > 1e-9) || !f.is_finite() {
        bail!("look direction {forward:?} with up {up:?}: not a valid frame (zero or parallel)");
    }
    let r = r / rn;
    let u = r.cross(f);
    Ok(quaternion_from_columns(r, u, -f))
}

impl GltfWriter {
    /// An empty document.
    pub fn new() -> GltfWriter {
        GltfWriter::default()
    }

    /// Append `bytes` as a buffer view (4-byte aligned) and an accessor over it.
    fn accessor(&mut self, bytes: &[u8], component: u32, kind: &str, count: usize, target: u32, bounds: Option<([f32; 3], [f32; 3])>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let view = self.buffer_views.len();
        self.buffer_views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len(), "target": target}));
        self.bin.extend_from_slice(bytes);
        let mut a = json!({"bufferView": view, "componentType": component, "count": count, "type": kind});
        if let Some((lo, hi)) = bounds {
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// A metal-rough material from its factors (textures are not written); returns its index.
    pub fn material(&mut self, m: &Material) -> usize {
        let mut v = json!({
            "name": m.name,
            "pbrMetallicRoughness": {"baseColorFactor": m.base_color, "metallicFactor": m.metallic, "roughnessFactor": m.roughness},
        });
        if m.is_emissive() {
            let peak = m.emissive.iter().cloned().fold(0.0f32, f32::max);
            if peak > 1.0 {
                v["emissiveFactor"] = json!(m.emissive.map(|e| e / peak));
                v["extensions"] = json!({"KHR_materials_emissive_strength": {"emissiveStrength": peak}});
            } else {
                v["emissiveFactor"] = json!(m.emissive);
            }
        }
        if m.double_sided {
            v["doubleSided"] = json!(true);
        }
        self.materials.push(v);
        self.materials.len() - 1
    }

    /// A node holding `mesh` (positions, optional normals, indices) with `material`, in world
    /// space. Fails on an empty mesh or an index out of range.
    pub fn mesh(&mut self, mesh: &MeshData, material: usize) -> Result<()> {
        if mesh.positions.is_empty() {
            bail!("mesh {:?}: no vertices", mesh.name);
        }
        if material >= self.materials.len() {
            bail!("mesh {:?}: material {material} not written", mesh.name);
        }
        let n = mesh.positions.len();
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in &mesh.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let pos = self.accessor(bytemuck::cast_slice(&mesh.positions), 5126, "VEC3", n, 34962, Some((lo, hi)));
        let mut attributes = json!({"POSITION": pos});
        if let Some(nm) = &mesh.normals {
            if nm.len() != n {
                bail!("mesh {:?}: {} normals for {n} vertices", mesh.name, nm.len());
            }
            attributes["NORMAL"] = json!(self.accessor(bytemuck::cast_slice(nm), 5126, "VEC3", n, 34962, None));
        }
        let mut prim = json!({"attributes": attributes, "material": material});
        if let Some(ix) = &mesh.indices {
            if let Some(bad) = ix.iter().find(|&&i| i as usize >= n) {
                bail!("mesh {:?}: index {bad} out of range ({n} vertices)", mesh.name);
            }
            prim["indices"] = json!(self.accessor(bytemuck::cast_slice(ix), 5125, "SCALAR", ix.len(), 34963, None));
        }
        self.meshes.push(json!({"name": mesh.name, "primitives": [prim]}));
        self.nodes.push(json!({"name": mesh.name, "mesh": self.meshes.len() - 1}));
        Ok(())
    }

    /// A perspective camera at `eye` looking at `target` (vertical field of view `yfov`
    /// radians, no aspect ratio: the image's is used).
    pub fn camera(&mut self, name: &str, eye: DVec3, target: DVec3, up: DVec3, yfov: f32) -> Result<()> {
        let q = look_rotation(target - eye, up).with_context(|| format!("camera {name:?}"))?;
        self.cameras.push(json!({"name": name, "type": "perspective", "perspective": {"yfov": yfov, "znear": 0.01}}));
        self.nodes.push(json!({"name": name, "camera": self.cameras.len() - 1, "translation": eye.to_array(), "rotation": q}));
        Ok(())
    }

    /// A `KHR_lights_punctual` light (colour and intensity written as colour = intensity
    /// normalised to its largest component, intensity = that component).
    pub fn light(&mut self, l: &PunctualLight) -> Result<()> {
        let peak = l.intensity.iter().cloned().fold(0.0f32, f32::max);
        if !(peak > 0.0) || !peak.is_finite() {
            bail!("light {:?}: intensity {:?} must be finite and positive", l.name, l.intensity);
        }
        let mut v = json!({"name": l.name, "color": l.intensity.map(|c| c / peak), "intensity": peak});
        if l.range > 0.0 {
            v["range"] = json!(l.range);
        }
        v["type"] = json!(match l.kind {
            LightKind::Directional => "directional",
            LightKind::Point => "point",
            LightKind::Spot { .. } => "spot",
        });
        if let LightKind::Spot { inner_cone, outer_cone } = l.kind {
            v["spot"] = json!({"innerConeAngle": inner_cone, "outerConeAngle": outer_cone});
        }
        self.lights.push(v);
        let mut node = json!({"name": l.name, "extensions": {"KHR_lights_punctual": {"light": self.lights.len() - 1}}});
        if l.kind != LightKind::Point {
            let d = DVec3::from(l.direction.map(|x| x as f64));
            let up = if d[1].abs() > 0.9 { DVec3::X } else { DVec3::Y };
            node["rotation"] = json!(look_rotation(d, up).with_context(|| format!("light {:?}", l.name))?);
        }
        if l.kind != LightKind::Directional {
            node["translation"] = json!(l.position);
        }
        self.nodes.push(node);
        Ok(())
    }

    /// Write `path` (`.gltf`) and its buffer `<stem>.bin` beside it.
    pub fn write(&self, path: &Path) -> Result<()> {
        let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).context("a glTF path needs a file name")?;
        let bin_name = format!("{stem}.bin");
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": "host (this project's glTF writer)"},
            "scene": 0,
            "scenes": [{"nodes": (0..self.nodes.len()).collect::<Vec<_>>()}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "accessors": self.accessors,
            "bufferViews": self.buffer_views,
            "buffers": [{"uri": bin_name, "byteLength": self.bin.len()}],
        });
        if !self.cameras.is_empty() {
            doc["cameras"] = json!(self.cameras);
        }
        let mut used = Vec::new();
        if !self.lights.is_empty() {
            doc["extensions"] = json!({"KHR_lights_punctual": {"lights": self.lights}});
            used.push("KHR_lights_punctual");
        }
        if self.materials.iter().any(|m| m.get("extensions").is_some()) {
            used.push("KHR_materials_emissive_strength");
        }
        if !used.is_empty() {
            doc["extensionsUsed"] = json!(used);
        }
        fileio::write_file(path, serde_json::to_string_pretty(&doc)? + "\n")?;
        std::fs::write(path.with_file_name(&bin_name), &self.bin).with_context(|| format!("writing {}", path.with_file_name(&bin_name).display()))
    }
}
