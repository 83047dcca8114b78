//! Checks of a glTF document's JSON against the bounds of the glTF 2.0 specification (and of the
//! supported extensions), run before the `gltf` crate's own validation and before any index is
//! followed. Every fault names its JSON path (`materials[2].emissiveFactor[0]`) and the bound it
//! breaks; the loader refuses a document with any fault.
//!
//! Checked here:
//! - `asset.version` is 2.x and `asset.minVersion`, when given, is at most 2.0;
//! - a primitive's attribute accessor indices are in range (the `gltf` crate's validation indexes
//!   the `POSITION` one unchecked and would panic), and the accessors the loader reads have the
//!   types the specification gives them (`POSITION`, `NORMAL` float VEC3, `TANGENT` float VEC4,
//!   `TEXCOORD_n` VEC2, indices unsigned-integer SCALAR: the `gltf` crate's readers panic on
//!   others); a primitive's attributes of one count; every accessor's `count` >= 1; a sparse accessor's `count` within its accessor's
//!   and its indices unsigned integers;
//! - buffer views: `byteLength` >= 1, `byteStride` a multiple of 4, the view inside its buffer
//!   (`byteOffset` + `byteLength` <= the buffer's `byteLength`); accessors: `byteOffset` a
//!   multiple of the component size, and the last element inside the buffer view;
//! - materials: `baseColorFactor`, `metallicFactor`, `roughnessFactor`, `emissiveFactor`,
//!   `occlusionTexture.strength`, `transmissionFactor` in [0, 1]; `alphaCutoff` >= 0;
//!   `normalTexture.scale` finite; `emissiveStrength` finite and >= 0; `ior` finite and >= 1;
//!   `emissiveFactor` x `emissiveStrength` finite in f32;
//! - `KHR_lights_punctual`: `color` in [0, 1], `intensity` finite and >= 0, `range` > 0,
//!   0 <= `innerConeAngle` < `outerConeAngle` <= pi/2;
//! - cameras: perspective `yfov` in (0, pi), `znear` > 0, `zfar` > `znear`, `aspectRatio` > 0;
//!   orthographic `xmag`, `ymag` finite and non-zero, 0 <= `znear` < `zfar`;
//! - images: a `uri` or a `bufferView`, not both; a `bufferView` image has a `mimeType`;
//!   `mimeType` `image/png` or `image/jpeg`;
//! - texture coordinates: every primitive has the `TEXCOORD_n` attribute that each texture of
//!   its material reads (`texCoord` n; glTF 2.0 section 5.22 "A mesh primitive MUST have the
//!   corresponding texture coordinate attributes");
//! - nodes: `matrix`, `translation`, `scale` finite; `rotation` a unit quaternion; not both a
//!   `matrix` and TRS; the hierarchy a forest (no node with two parents, no cycle, scene roots
//!   without a parent, no node twice in a scene's `nodes`).

use gltf::json;
use std::fmt::Write as _;

/// The faults found in a document, each `(JSON path, what is wrong)`.
#[derive(Debug, Default)]
pub struct Faults {
    pub list: Vec<(String, String)>,
}

impl Faults {
    fn add(&mut self, path: impl Into<String>, what: impl Into<String>) {
        self.list.push((path.into(), what.into()));
    }

    /// `path` must hold a finite value in [lo, hi].
    fn range(&mut self, path: impl Fn() -> String, v: f32, lo: f32, hi: f32) {
        if !(v.is_finite() && v >= lo && v <= hi) {
            self.add(path(), format!("{v} is outside [{lo}, {hi}]"));
        }
    }

    /// Every component of `v` (at `path[k]`) must be finite and in [lo, hi].
    fn range_all(&mut self, path: &str, v: &[f32], lo: f32, hi: f32) {
        for (k, &x) in v.iter().enumerate() {
            self.range(|| format!("{path}[{k}]"), x, lo, hi);
        }
    }

    /// Every component of `v` must be finite.
    fn finite_all(&mut self, path: &str, v: &[f32]) {
        for (k, &x) in v.iter().enumerate() {
            if !x.is_finite() {
                self.add(format!("{path}[{k}]"), format!("{x} is not finite"));
            }
        }
    }

    /// The faults as one message (the first 12 of them, and how many more).
    pub fn message(&self) -> String {
        let mut s = String::new();
        for (i, (p, w)) in self.list.iter().take(12).enumerate() {
            if i > 0 {
                s.push_str("; ");
            }
            let _ = write!(s, "{p}: {w}");
        }
        if self.list.len() > 12 {
            let _ = write!(s, "; and {} more", self.list.len() - 12);
        }
        s
    }
}

/// Checks `root` (see the module's list). Returns the faults; empty = none.
pub fn check(root: &json::Root) -> Faults {
    let mut f = Faults::default();
    asset(root, &mut f);
    positions_in_range(root, &mut f);
    buffer_layout(root, &mut f);
    materials(root, &mut f);
    lights(root, &mut f);
    cameras(root, &mut f);
    nodes(root, &mut f);
    images(root, &mut f);
    texture_coordinates(root, &mut f);
    f
}

/// Images: one source, and a MIME type the specification allows (glTF 2.0 section 5.17).
fn images(root: &json::Root, f: &mut Faults) {
    for (i, im) in root.images.iter().enumerate() {
        let at = format!("images[{i}]");
        match (&im.uri, &im.buffer_view) {
            (Some(_), Some(_)) => f.add(at.clone(), "has both a uri and a bufferView: give one"),
            (None, None) => f.add(at.clone(), "has neither a uri nor a bufferView"),
            (None, Some(_)) if im.mime_type.is_none() => f.add(format!("{at}.mimeType"), "missing: an image in a bufferView needs image/png or image/jpeg"),
            _ => {}
        }
        if let Some(m) = &im.mime_type {
            if m.0 != "image/png" && m.0 != "image/jpeg" {
                f.add(format!("{at}.mimeType"), format!("{:?}: must be image/png or image/jpeg", m.0));
            }
        }
    }
}

/// The texture infos of a material: (JSON path below the material, texCoord).
fn texture_infos(m: &json::Material) -> Vec<(&'static str, u32)> {
    let pbr = &m.pbr_metallic_roughness;
    let mut v = Vec::new();
    if let Some(t) = &pbr.base_color_texture {
        v.push(("pbrMetallicRoughness.baseColorTexture", t.tex_coord));
    }
    if let Some(t) = &pbr.metallic_roughness_texture {
        v.push(("pbrMetallicRoughness.metallicRoughnessTexture", t.tex_coord));
    }
    if let Some(t) = &m.normal_texture {
        v.push(("normalTexture", t.tex_coord));
    }
    if let Some(t) = &m.occlusion_texture {
        v.push(("occlusionTexture", t.tex_coord));
    }
    if let Some(t) = &m.emissive_texture {
        v.push(("emissiveTexture", t.tex_coord));
    }
    if let Some(t) = m.extensions.as_ref().and_then(|e| e.transmission.as_ref()).and_then(|t| t.transmission_texture.as_ref()) {
        v.push(("extensions.KHR_materials_transmission.transmissionTexture", t.tex_coord));
    }
    v
}

/// Every texture a primitive's material reads has its `TEXCOORD_n` on the primitive.
fn texture_coordinates(root: &json::Root, f: &mut Faults) {
    use json::mesh::Semantic as S;
    use json::validation::Checked;
    for (mi, mesh) in root.meshes.iter().enumerate() {
        for (pi, p) in mesh.primitives.iter().enumerate() {
            let Some(k) = p.material.map(|m| m.value()).filter(|&k| k < root.materials.len()) else { continue };
            for (slot, n) in texture_infos(&root.materials[k]) {
                if !p.attributes.contains_key(&Checked::Valid(S::TexCoords(n))) {
                    f.add(
                        format!("meshes[{mi}].primitives[{pi}].attributes"),
                        format!("no TEXCOORD_{n}, which materials[{k}].{slot} reads (texCoord {n}): the primitive must have it"),
                    );
                }
            }
        }
    }
}

/// Whether `v` is "2" or "2.<digits>" (the major version the loader implements).
fn is_v2(v: &str) -> bool {
    match v.split_once('.') {
        Some((major, minor)) => major == "2" && !minor.is_empty() && minor.bytes().all(|b| b.is_ascii_digit()),
        None => false,
    }
}

fn asset(root: &json::Root, f: &mut Faults) {
    let v = &root.asset.version;
    if !is_v2(v) {
        f.add("asset.version", format!("{v:?}: this loader reads glTF 2.x only (glTF 1.0 files must be converted to 2.0)"));
    }
    if let Some(m) = &root.asset.min_version {
        let ok = is_v2(m) && m.split_once('.').map(|(_, minor)| minor.bytes().all(|b| b == b'0')).unwrap_or(false);
        if !ok {
            f.add("asset.minVersion", format!("{m:?}: the file requires a glTF version newer than the 2.0 this loader implements"));
        }
    }
}

fn positions_in_range(root: &json::Root, f: &mut Faults) {
    use json::accessor::{ComponentType as C, Type as T};
    use json::mesh::Semantic as S;
    use json::validation::Checked;
    let n = root.accessors.len();
    // (accessor index, JSON path of the reference, allowed (type, component types), float
    // required to be normalized when integer)
    let mut used: Vec<(usize, String, T, &[C])> = Vec::new();
    for (mi, mesh) in root.meshes.iter().enumerate() {
        for (pi, p) in mesh.primitives.iter().enumerate() {
            let at = format!("meshes[{mi}].primitives[{pi}]");
            // glTF 2.0 section 3.7.2.1: all attribute accessors of a primitive have one count
            let mut first_count: Option<(String, u64)> = None;
            for (sem, acc) in &p.attributes {
                let path = format!("{at}.attributes.{}", sem.to_string());
                if acc.value() >= n {
                    f.add(path, format!("accessor index {} is out of range: the file has {n} accessors", acc.value()));
                    continue;
                }
                let count = root.accessors[acc.value()].count.0;
                match &first_count {
                    None => first_count = Some((path.clone(), count)),
                    Some((other, c)) if *c != count => f.add(path.clone(), format!("accessor {} has {count} elements, {other} has {c}: a primitive's attributes must have one count", acc.value())),
                    Some(_) => {}
                }
                // the attributes the loader reads must have the types the specification gives them
                match sem {
                    Checked::Valid(S::Positions) | Checked::Valid(S::Normals) => used.push((acc.value(), path, T::Vec3, &[C::F32])),
                    Checked::Valid(S::Tangents) => used.push((acc.value(), path, T::Vec4, &[C::F32])),
                    Checked::Valid(S::TexCoords(_)) => used.push((acc.value(), path, T::Vec2, &[C::F32, C::U8, C::U16])),
                    _ => {}
                }
            }
            if let Some(i) = &p.indices {
                if i.value() < n {
                    used.push((i.value(), format!("{at}.indices"), T::Scalar, &[C::U8, C::U16, C::U32]));
                }
            }
        }
    }
    for (i, path, ty, comps) in used {
        let a = &root.accessors[i];
        let (Checked::Valid(t), Checked::Valid(c)) = (&a.type_, &a.component_type) else { continue };
        if *t != ty || !comps.contains(&c.0) {
            f.add(path, format!("accessor {i} is {t:?} of {:?}; this use needs {ty:?} of {}", c.0, comps.iter().map(|c| format!("{c:?}")).collect::<Vec<_>>().join(" or ")));
        }
    }
    for (i, a) in root.accessors.iter().enumerate() {
        if a.count.0 == 0 {
            f.add(format!("accessors[{i}].count"), "0: must be at least 1");
        }
        if let Some(sp) = &a.sparse {
            let at = format!("accessors[{i}].sparse");
            if sp.count.0 == 0 || sp.count.0 > a.count.0 {
                f.add(format!("{at}.count"), format!("{}: must be in [1, the accessor's count {}]", sp.count.0, a.count.0));
            }
            if let Checked::Valid(c) = &sp.indices.component_type {
                if !matches!(c.0, C::U8 | C::U16 | C::U32) {
                    f.add(format!("{at}.indices.componentType"), format!("{:?}: must be an unsigned integer type", c.0));
                }
            }
        }
    }
}

/// Buffer views inside their buffers, accessors inside their buffer views (glTF 2.0 sections
/// 3.6.2.4 "Data Alignment" and 3.6.2.1 "Overview": offsets aligned to the component size,
/// strides multiples of 4, every element within the view).
fn buffer_layout(root: &json::Root, f: &mut Faults) {
    use json::validation::Checked;
    for (i, v) in root.buffer_views.iter().enumerate() {
        let at = format!("bufferViews[{i}]");
        if v.byte_length.0 == 0 {
            f.add(format!("{at}.byteLength"), "0: must be at least 1");
        }
        if let Some(s) = v.byte_stride {
            if s.0 % 4 != 0 {
                f.add(format!("{at}.byteStride"), format!("{}: must be a multiple of 4", s.0));
            }
        }
        let offset = v.byte_offset.map_or(0, |o| o.0);
        if let Some(b) = root.buffers.get(v.buffer.value()) {
            if offset.saturating_add(v.byte_length.0) > b.byte_length.0 {
                f.add(
                    format!("{at}.byteLength"),
                    format!("byteOffset {offset} + byteLength {} runs past the end of buffer {} ({} bytes)", v.byte_length.0, v.buffer.value(), b.byte_length.0),
                );
            }
        }
    }
    for (i, a) in root.accessors.iter().enumerate() {
        let (Checked::Valid(t), Checked::Valid(c)) = (&a.type_, &a.component_type) else { continue };
        let at = format!("accessors[{i}]");
        let size = c.0.size() as u64;
        let offset = a.byte_offset.map_or(0, |o| o.0);
        if offset % size != 0 {
            f.add(format!("{at}.byteOffset"), format!("{offset}: must be a multiple of the component size {size}"));
        }
        let Some(view) = a.buffer_view.and_then(|v| root.buffer_views.get(v.value())) else { continue };
        let element = size * t.multiplicity() as u64;
        let stride = view.byte_stride.map_or(element, |s| s.0 as u64);
        let end = offset.saturating_add(stride.saturating_mul(a.count.0.saturating_sub(1))).saturating_add(element);
        if end > view.byte_length.0 {
            f.add(
                format!("{at}.count"),
                format!("{} elements of {element} bytes (stride {stride}) from byteOffset {offset} end at byte {end}, past bufferView {}'s byteLength {}", a.count.0, a.buffer_view.map_or(0, |v| v.value()), view.byte_length.0),
            );
        }
    }
}

fn materials(root: &json::Root, f: &mut Faults) {
    for (i, m) in root.materials.iter().enumerate() {
        let at = format!("materials[{i}]");
        let pbr = &m.pbr_metallic_roughness;
        f.range_all(&format!("{at}.pbrMetallicRoughness.baseColorFactor"), &pbr.base_color_factor.0, 0.0, 1.0);
        f.range(|| format!("{at}.pbrMetallicRoughness.metallicFactor"), pbr.metallic_factor.0, 0.0, 1.0);
        f.range(|| format!("{at}.pbrMetallicRoughness.roughnessFactor"), pbr.roughness_factor.0, 0.0, 1.0);
        f.range_all(&format!("{at}.emissiveFactor"), &m.emissive_factor.0, 0.0, 1.0);
        if let Some(c) = &m.alpha_cutoff {
            f.range(|| format!("{at}.alphaCutoff"), c.0, 0.0, f32::MAX);
        }
        if let Some(t) = &m.normal_texture {
            f.finite_all(&format!("{at}.normalTexture.scale"), &[t.scale]);
        }
        if let Some(t) = &m.occlusion_texture {
            f.range(|| format!("{at}.occlusionTexture.strength"), t.strength.0, 0.0, 1.0);
        }
        let Some(ext) = &m.extensions else { continue };
        if let Some(s) = &ext.emissive_strength {
            let s = s.emissive_strength.0;
            let path = format!("{at}.extensions.KHR_materials_emissive_strength.emissiveStrength");
            if !(s.is_finite() && s >= 0.0) {
                f.add(path, format!("{s}: must be finite and >= 0"));
            } else if let Some(k) = (0..3).find(|&k| !(m.emissive_factor.0[k] * s).is_finite()) {
                f.add(path, format!("{s} x emissiveFactor[{k}] {} overflows f32 (the emitted radiance must be finite)", m.emissive_factor.0[k]));
            }
        }
        if let Some(t) = &ext.transmission {
            f.range(|| format!("{at}.extensions.KHR_materials_transmission.transmissionFactor"), t.transmission_factor.0, 0.0, 1.0);
        }
        if let Some(ior) = &ext.ior {
            let v = ior.ior.0;
            if !(v.is_finite() && v >= 1.0) {
                f.add(format!("{at}.extensions.KHR_materials_ior.ior"), format!("{v}: must be finite and >= 1 (the special value 0 is not supported)"));
            }
        }
    }
}

fn lights(root: &json::Root, f: &mut Faults) {
    let Some(ls) = root.extensions.as_ref().and_then(|e| e.khr_lights_punctual.as_ref()) else { return };
    for (i, l) in ls.lights.iter().enumerate() {
        let at = format!("extensions.KHR_lights_punctual.lights[{i}]");
        f.range_all(&format!("{at}.color"), &l.color, 0.0, 1.0);
        if !(l.intensity.is_finite() && l.intensity >= 0.0) {
            f.add(format!("{at}.intensity"), format!("{}: must be finite and >= 0", l.intensity));
        }
        if let Some(r) = l.range {
            if !(r.is_finite() && r > 0.0) {
                f.add(format!("{at}.range"), format!("{r}: must be finite and > 0 (omit it for an infinite range)"));
            }
        }
        if let Some(s) = &l.spot {
            let (inner, outer) = (s.inner_cone_angle, s.outer_cone_angle);
            let half_pi = std::f32::consts::FRAC_PI_2;
            if !(inner.is_finite() && inner >= 0.0) {
                f.add(format!("{at}.spot.innerConeAngle"), format!("{inner}: must be finite and >= 0"));
            }
            if !(outer.is_finite() && outer > 0.0 && outer <= half_pi) {
                f.add(format!("{at}.spot.outerConeAngle"), format!("{outer}: must be in (0, pi/2]"));
            } else if inner.is_finite() && inner >= outer {
                f.add(format!("{at}.spot.innerConeAngle"), format!("{inner}: must be less than outerConeAngle {outer}"));
            }
        }
    }
}

fn cameras(root: &json::Root, f: &mut Faults) {
    for (i, c) in root.cameras.iter().enumerate() {
        let at = format!("cameras[{i}]");
        if let Some(p) = &c.perspective {
            if !(p.yfov.is_finite() && p.yfov > 0.0 && p.yfov < std::f32::consts::PI) {
                f.add(format!("{at}.perspective.yfov"), format!("{}: must be in (0, pi)", p.yfov));
            }
            if !(p.znear.is_finite() && p.znear > 0.0) {
                f.add(format!("{at}.perspective.znear"), format!("{}: must be finite and > 0", p.znear));
            }
            if let Some(z) = p.zfar {
                if !(z > p.znear) {
                    f.add(format!("{at}.perspective.zfar"), format!("{z}: must be greater than znear {}", p.znear));
                }
            }
            if let Some(a) = p.aspect_ratio {
                if !(a.is_finite() && a > 0.0) {
                    f.add(format!("{at}.perspective.aspectRatio"), format!("{a}: must be finite and > 0"));
                }
            }
        }
        if let Some(o) = &c.orthographic {
            for (name, v) in [("xmag", o.xmag), ("ymag", o.ymag)] {
                if !(v.is_finite() && v != 0.0) {
                    f.add(format!("{at}.orthographic.{name}"), format!("{v}: must be finite and non-zero"));
                }
            }
            if !(o.znear.is_finite() && o.znear >= 0.0) {
                f.add(format!("{at}.orthographic.znear"), format!("{}: must be finite and >= 0", o.znear));
            }
            if !(o.zfar.is_finite() && o.zfar > o.znear) {
                f.add(format!("{at}.orthographic.zfar"), format!("{}: must be finite and greater than znear {}", o.zfar, o.znear));
            }
        }
    }
}

fn nodes(root: &json::Root, f: &mut Faults) {
    let n = root.nodes.len();
    for (i, node) in root.nodes.iter().enumerate() {
        let at = format!("nodes[{i}]");
        if let Some(m) = &node.matrix {
            f.finite_all(&format!("{at}.matrix"), m);
            if node.translation.is_some() || node.rotation.is_some() || node.scale.is_some() {
                f.add(format!("{at}.matrix"), "a node has either a matrix or translation/rotation/scale, not both");
            }
        }
        if let Some(t) = &node.translation {
            f.finite_all(&format!("{at}.translation"), t);
        }
        if let Some(s) = &node.scale {
            f.finite_all(&format!("{at}.scale"), s);
        }
        if let Some(q) = &node.rotation {
            let q = q.0;
            let len = q.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt();
            if !((len - 1.0).abs() <= 1e-3) {
                f.add(format!("{at}.rotation"), format!("{q:?} is not a unit quaternion (length {len})"));
            }
        }
    }
    // the hierarchy: every node at most one parent, no cycles
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for (i, node) in root.nodes.iter().enumerate() {
        for (k, c) in node.children.iter().flatten().enumerate() {
            let c = c.value();
            if c >= n {
                continue; // the gltf crate's validation names it
            }
            if c == i {
                f.add(format!("nodes[{i}].children[{k}]"), format!("node {i} is its own child"));
            } else if let Some(p) = parent[c] {
                f.add(format!("nodes[{i}].children[{k}]"), format!("node {c} already has parent {p} (the node hierarchy must be a forest)"));
            } else {
                parent[c] = Some(i);
            }
        }
    }
    for start in 0..n {
        // walking up from any node ends at a root within n steps, unless there is a cycle
        let (mut at, mut steps) = (start, 0);
        while let Some(p) = parent[at] {
            at = p;
            steps += 1;
            if steps > n {
                f.add(format!("nodes[{start}]"), "the node hierarchy has a cycle through this node");
                break;
            }
        }
        if steps > n {
            break; // one report per cycle is enough
        }
    }
    for (s, scene) in root.scenes.iter().enumerate() {
        let mut seen = std::collections::HashSet::new();
        for (k, r) in scene.nodes.iter().enumerate() {
            let r = r.value();
            if r >= n {
                continue;
            }
            if let Some(p) = parent[r] {
                f.add(format!("scenes[{s}].nodes[{k}]"), format!("node {r} is a child of node {p}, not a root node"));
            }
            if !seen.insert(r) {
                f.add(format!("scenes[{s}].nodes[{k}]"), format!("node {r} is listed twice"));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn versions() {
        assert!(is_v2("2.0") && is_v2("2.1"));
        assert!(!is_v2("1.0") && !is_v2("2") && !is_v2("2.") && !is_v2("3.0") && !is_v2("2.0a"));
    }
}
