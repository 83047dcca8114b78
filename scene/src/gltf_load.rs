//! glTF 2.0 loading (Khronos, "glTF 2.0 Specification", sections 3.5 scenes and nodes, 3.6
//! binary data, 3.7 meshes, 3.8 textures, 3.9 materials, 3.10 cameras; `KHR_lights_punctual`,
//! `KHR_materials_emissive_strength`, `KHR_materials_transmission`, `KHR_materials_ior`,
//! `KHR_texture_transform`)
//! through the `gltf` crate, into a [`SceneBuilder`].
//!
//! Handled: `.gltf` with external or data-URI buffers and images, `.glb`; the default scene (or
//! scene 0) and its node hierarchy (matrix or TRS); `TRIANGLES`, `TRIANGLE_STRIP` and
//! `TRIANGLE_FAN` primitives, indexed or not; `POSITION`, `NORMAL`, `TEXCOORD_0`, `TANGENT`;
//! metal-rough materials with their textures (PNG, JPEG), samplers' wrap modes and
//! magnification filter, and each texture reference's `KHR_texture_transform` (offset, rotation,
//! scale; a non-finite value is an error); cameras; punctual lights.
//!
//! Documented handling (each a warning naming it): `POINTS` / `LINES*` primitives skipped;
//! `alphaMode` `BLEND` treated as `MASK` at 0.5; texture sets other than 0 read as set 0;
//! unsupported extensions ignored (an error when listed in `extensionsRequired`); skins and
//! morph targets ignored (bind pose), animations ignored (rest pose); occlusion textures
//! ignored; zero-area triangles dropped (with their count). Errors name the file and the
//! element: malformed JSON, a `.glb` without the GLB magic, a missing or short buffer, a missing
//! or undecodable image, an accessor or index out of range, a non-finite position, no triangles
//! (points and lines only: named as unsupported), a directional or spot light without a
//! direction. Before the `gltf` crate's validation, [`super::validate`] checks the document
//! against the specification's bounds, naming the JSON path of each fault.

use super::math::{normalize, Mat4};
use glam::DVec3;
use super::{AlphaMode, Camera, LightKind, Material, MeshData, Projection, PunctualLight, Scene, SceneBuilder, Texture, UvTransform, Wrap};
use anyhow::{anyhow, bail, Context, Result};
use gltf::mesh::Mode;
use std::collections::HashMap;
use std::path::Path;

/// Extensions whose content the loader uses.
const SUPPORTED: &[&str] = &["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior", TEXTURE_TRANSFORM];
const TEXTURE_TRANSFORM: &str = "KHR_texture_transform";

/// A `KHR_texture_transform` object (glTF extension spec: `offset` and `scale` two numbers,
/// `rotation` a number, `texCoord` a set index overriding the reference's; every number finite)
/// and the texture coordinate set it reads (`tex_coord`, the reference's own, unless overridden).
fn uv_transform(v: &serde_json::Value, tex_coord: u32) -> std::result::Result<(UvTransform, u32), String> {
    let obj = v.as_object().ok_or("must be an object")?;
    let pair = |key: &str, default: [f32; 2]| -> std::result::Result<[f32; 2], String> {
        match obj.get(key) {
            None => Ok(default),
            Some(x) => match x.as_array().map(|a| a.iter().map(|e| e.as_f64()).collect::<Vec<_>>()).as_deref() {
                Some([Some(a), Some(b)]) if (*a as f32).is_finite() && (*b as f32).is_finite() => Ok([*a as f32, *b as f32]),
                _ => Err(format!("{key} must be two finite numbers, not {x}")),
            },
        }
    };
    let rotation = match obj.get("rotation") {
        None => 0.0,
        Some(x) => match x.as_f64() {
            Some(r) if (r as f32).is_finite() => r as f32,
            _ => return Err(format!("rotation must be a finite number, not {x}")),
        },
    };
    let set = match obj.get("texCoord") {
        None => tex_coord,
        Some(x) => x.as_u64().and_then(|n| u32::try_from(n).ok()).ok_or_else(|| format!("texCoord must be a non-negative integer, not {x}"))?,
    };
    let t = UvTransform { offset: pair("offset", [0.0, 0.0])?, rotation, scale: pair("scale", [1.0, 1.0])? };
    if t.matrix().iter().any(|m| !m.is_finite()) {
        return Err(format!("offset {:?}, rotation {}, scale {:?} overflow f32", t.offset, t.rotation, t.scale));
    }
    Ok((t, set))
}

/// Loads `path` (.gltf or .glb) into a [`Scene`].
pub fn load(path: &Path) -> Result<Scene> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).with_context(|| format!("{file}: cannot read the glTF file"))?;
    check_container(&file, path, &bytes)?;
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes).map_err(|e| anyhow!("{file}: malformed glTF: {e}"))?;
    let blob = gltf.blob.clone();
    let root = gltf.document.into_json();
    for ext in &root.extensions_required {
        if !SUPPORTED.contains(&ext.as_str()) {
            bail!("{file}: extensionsRequired lists '{ext}', which this loader does not support (supported: {})", SUPPORTED.join(", "));
        }
    }
    // Our checks first: the gltf crate's validation follows a primitive's POSITION index
    // unchecked, and it does not check the bounds the specification puts on values.
    let faults = super::validate::check(&root);
    if !faults.list.is_empty() {
        bail!("{file}: invalid glTF: {}", faults.message());
    }
    let doc = gltf::Document::from_json(root).map_err(|e| match e {
        gltf::Error::Validation(errs) => {
            let list: Vec<String> = errs.iter().map(|(p, e)| format!("{p}: {e}")).collect();
            anyhow!("{file}: invalid glTF: {}", list.join("; "))
        }
        e => anyhow!("{file}: invalid glTF: {e}"),
    })?;
    let base = path.parent().unwrap_or(Path::new("."));
    Loader { file: file.clone(), base, doc: &doc, blob, buffers: Vec::new(), textures: HashMap::new(), b: SceneBuilder::new(&file), default_material: None, skipped: Vec::new() }.run()
}

/// A `.glb` must start with the GLB magic `glTF`; any other file must be JSON (start with `{`,
/// after whitespace or a byte-order mark) or a GLB. Says which of the two the file is not,
/// instead of a JSON parse error at line 1, column 1.
fn check_container(file: &str, path: &Path, bytes: &[u8]) -> Result<()> {
    let head: Vec<String> = bytes.iter().take(4).map(|b| format!("{b:02x}")).collect();
    let glb_ext = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if bytes.starts_with(b"glTF") {
        return Ok(());
    }
    if glb_ext {
        bail!("{file}: not a GLB file: it starts with the bytes {} where a GLB has the magic 'glTF' (67 6c 54 46)", head.join(" "));
    }
    let body = bytes.strip_prefix(b"\xef\xbb\xbf".as_slice()).unwrap_or(bytes);
    match body.iter().find(|b| !b.is_ascii_whitespace()) {
        Some(b'{') => Ok(()),
        None => bail!("{file}: the file is empty"),
        Some(_) => bail!("{file}: neither a glTF JSON document (which starts with '{{') nor a GLB (magic 'glTF'): it starts with the bytes {}", head.join(" ")),
    }
}

struct Loader<'a> {
    file: String,
    base: &'a Path,
    doc: &'a gltf::Document,
    blob: Option<Vec<u8>>,
    buffers: Vec<Vec<u8>>,
    textures: HashMap<usize, u32>,
    b: SceneBuilder,
    default_material: Option<u32>,
    /// Points and lines primitives skipped: (JSON path, mode).
    skipped: Vec<(String, Mode)>,
}

/// Decodes RFC 4648 base64 (whitespace ignored, padding optional).
fn base64(s: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(s.len() * 3 / 4);
    let (mut acc, mut bits) = (0u32, 0);
    for c in s.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' | b' ' | b'\n' | b'\r' | b'\t' => continue,
            _ => return None,
        };
        acc = (acc << 6) | v as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
        }
    }
    Some(out)
}

/// Decodes %XX escapes of a relative URI.
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let Some(v) = std::str::from_utf8(&b[i + 1..i + 3]).ok().and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

impl<'a> Loader<'a> {
    /// Reads a URI: a `data:` URI (base64) or a file relative to the glTF file.
    fn read_uri(&self, what: &str, uri: &str) -> Result<Vec<u8>> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let (_, data) = rest.split_once(";base64,").ok_or_else(|| anyhow!("{}: {what}: a data URI that is not base64", self.file))?;
            return base64(data).ok_or_else(|| anyhow!("{}: {what}: invalid base64 in its data URI", self.file));
        }
        let p = self.base.join(percent_decode(uri));
        std::fs::read(&p).with_context(|| format!("{}: {what}: cannot read '{uri}' ({})", self.file, p.display()))
    }

    fn load_buffers(&mut self) -> Result<()> {
        for buf in self.doc.buffers() {
            let what = format!("buffer {}", buf.index());
            let data = match buf.source() {
                gltf::buffer::Source::Bin => self.blob.take().ok_or_else(|| anyhow!("{}: {what} refers to the GLB binary chunk, which is missing", self.file))?,
                gltf::buffer::Source::Uri(uri) => self.read_uri(&what, uri)?,
            };
            if data.len() < buf.length() {
                bail!("{}: {what}: {} bytes, but its byteLength is {}", self.file, data.len(), buf.length());
            }
            self.buffers.push(data);
        }
        Ok(())
    }

    /// glTF texture `t` as a builder texture (decoded once).
    fn texture(&mut self, t: gltf::Texture) -> Result<u32> {
        if let Some(&i) = self.textures.get(&t.index()) {
            return Ok(i);
        }
        let img = t.source();
        let what = format!("image {}{}", img.index(), img.name().map(|n| format!(" ('{n}')")).unwrap_or_default());
        let bytes = match img.source() {
            gltf::image::Source::View { view, .. } => {
                let data = &self.buffers[view.buffer().index()];
                data.get(view.offset()..view.offset() + view.length()).ok_or_else(|| anyhow!("{}: {what}: buffer view {} is out of range of its buffer", self.file, view.index()))?.to_vec()
            }
            gltf::image::Source::Uri { uri, .. } => self.read_uri(&what, uri)?,
        };
        let decoded = crate::image_file::decode_rgba8(&bytes).map_err(|e| anyhow!("{}: {what}: cannot decode: {e:#}", self.file))?;
        let s = t.sampler();
        let wrap = |w: gltf::texture::WrappingMode| match w {
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
            gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
        };
        let tex = Texture {
            name: t.name().or(img.name()).map(str::to_string).unwrap_or_else(|| format!("texture {}", t.index())),
            width: decoded.width,
            height: decoded.height,
            rgba: decoded.rgba,
            wrap_s: wrap(s.wrap_s()),
            wrap_t: wrap(s.wrap_t()),
            nearest: s.mag_filter() == Some(gltf::texture::MagFilter::Nearest),
        };
        let i = self.b.texture(tex)?;
        self.textures.insert(t.index(), i);
        Ok(i)
    }

    /// A texture reference of material `mname` with its `KHR_texture_transform` (`ext`, the
    /// reference's extension value), warning on a texture coordinate set other than 0.
    fn tex_ref(&mut self, mname: &str, slot: &str, tex: gltf::Texture, tex_coord: u32, ext: Option<&serde_json::Value>) -> Result<(Option<u32>, UvTransform)> {
        let (transform, set) = match ext {
            None => (UvTransform::IDENTITY, tex_coord),
            Some(v) => uv_transform(v, tex_coord).map_err(|e| anyhow!("{}: material '{mname}': {slot}.extensions.KHR_texture_transform: {e}", self.file))?,
        };
        if set != 0 {
            self.b.warn(format!("material '{mname}': {slot} uses TEXCOORD_{set}; TEXCOORD_0 is used instead"));
        }
        Ok((Some(self.texture(tex)?), transform))
    }

    fn materials(&mut self) -> Result<()> {
        for m in self.doc.materials() {
            let name = m.name().map(str::to_string).unwrap_or_else(|| format!("material {}", m.index().unwrap_or(0)));
            let pbr = m.pbr_metallic_roughness();
            let mut mat = Material {
                name: name.clone(),
                base_color: pbr.base_color_factor(),
                metallic: pbr.metallic_factor(),
                roughness: pbr.roughness_factor(),
                double_sided: m.double_sided(),
                ..Material::default()
            };
            let strength = m.emissive_strength().unwrap_or(1.0);
            mat.emissive = m.emissive_factor().map(|e| e * strength);
            mat.alpha_mode = match m.alpha_mode() {
                gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                gltf::material::AlphaMode::Mask => AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5)),
                gltf::material::AlphaMode::Blend => {
                    self.b.warn(format!("material '{name}': alphaMode BLEND is treated as MASK with cutoff 0.5"));
                    AlphaMode::Mask(0.5)
                }
            };
            if let Some(t) = pbr.base_color_texture() {
                let ext = t.extension_value(TEXTURE_TRANSFORM);
                (mat.base_color_texture, mat.base_color_uv) = self.tex_ref(&name, "baseColorTexture", t.texture(), t.tex_coord(), ext)?;
            }
            if let Some(t) = pbr.metallic_roughness_texture() {
                let ext = t.extension_value(TEXTURE_TRANSFORM);
                (mat.metallic_roughness_texture, mat.metallic_roughness_uv) = self.tex_ref(&name, "metallicRoughnessTexture", t.texture(), t.tex_coord(), ext)?;
            }
            if let Some(t) = m.normal_texture() {
                mat.normal_scale = t.scale();
                let ext = t.extension_value(TEXTURE_TRANSFORM);
                (mat.normal_texture, mat.normal_uv) = self.tex_ref(&name, "normalTexture", t.texture(), t.tex_coord(), ext)?;
            }
            if let Some(t) = m.emissive_texture() {
                let ext = t.extension_value(TEXTURE_TRANSFORM);
                (mat.emissive_texture, mat.emissive_uv) = self.tex_ref(&name, "emissiveTexture", t.texture(), t.tex_coord(), ext)?;
            }
            if m.occlusion_texture().is_some() {
                self.b.warn(format!("material '{name}': occlusionTexture is ignored (the path tracer computes occlusion)"));
            }
            if let Some(tr) = m.transmission() {
                mat.transmission = tr.transmission_factor();
                if let Some(t) = tr.transmission_texture() {
                    let ext = t.extension_value(TEXTURE_TRANSFORM);
                    (mat.transmission_texture, mat.transmission_uv) = self.tex_ref(&name, "transmissionTexture", t.texture(), t.tex_coord(), ext)?;
                }
            }
            if let Some(ior) = m.ior() {
                mat.ior = ior;
            }
            self.b.material(mat);
        }
        Ok(())
    }

    fn material_index(&mut self, m: gltf::Material) -> u32 {
        match m.index() {
            Some(i) => i as u32,
            None => *self.default_material.get_or_insert_with(|| self.b.material(Material::default())),
        }
    }

    fn primitive(&mut self, mesh: &gltf::Mesh, p: &gltf::Primitive, world: &Mat4) -> Result<()> {
        let what = format!("mesh {}{} primitive {}", mesh.index(), mesh.name().map(|n| format!(" ('{n}')")).unwrap_or_default(), p.index());
        let mode = p.mode();
        if matches!(mode, Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip) {
            self.b.warn(format!("{}: {what}: {mode:?} primitives are skipped (only triangles are rendered)", self.file));
            self.skipped.push((format!("meshes[{}].primitives[{}].mode", mesh.index(), p.index()), mode));
            return Ok(());
        }
        if p.morph_targets().len() > 0 {
            self.b.warn(format!("{}: {what}: morph targets are ignored (base shape rendered)", self.file));
        }
        let buffers = &self.buffers;
        let reader = p.reader(|b| buffers.get(b.index()).map(|v| v.as_slice()));
        let acc_err = |sem: &str, acc: Option<gltf::Accessor>| match acc {
            Some(a) => anyhow!("{}: {what}: {sem} accessor {} reads outside its buffer view or buffer", self.file, a.index()),
            None => anyhow!("{}: {what}: no {sem} attribute", self.file),
        };
        let positions: Vec<[f32; 3]> = reader.read_positions().ok_or_else(|| acc_err("POSITION", p.get(&gltf::Semantic::Positions)))?.collect();
        let normals = match p.get(&gltf::Semantic::Normals) {
            Some(a) => Some(reader.read_normals().ok_or_else(|| acc_err("NORMAL", Some(a)))?.collect::<Vec<_>>()),
            None => None,
        };
        let uvs = match p.get(&gltf::Semantic::TexCoords(0)) {
            Some(a) => Some(reader.read_tex_coords(0).ok_or_else(|| acc_err("TEXCOORD_0", Some(a)))?.into_f32().collect::<Vec<_>>()),
            None => None,
        };
        let tangents = match p.get(&gltf::Semantic::Tangents) {
            Some(a) => Some(reader.read_tangents().ok_or_else(|| acc_err("TANGENT", Some(a)))?.collect::<Vec<_>>()),
            None => None,
        };
        for (sem, _) in p.attributes() {
            if let gltf::Semantic::TexCoords(n) = sem {
                if n > 0 {
                    self.b.warn(format!("{}: {what}: TEXCOORD_{n} is ignored (only TEXCOORD_0 is used)", self.file));
                }
            }
        }
        let idx: Vec<u32> = match p.indices() {
            Some(a) => reader.read_indices().ok_or_else(|| acc_err("indices", Some(a)))?.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        let indices = match mode {
            Mode::TriangleStrip => (0..idx.len().saturating_sub(2)).flat_map(|i| [idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]]).collect(),
            Mode::TriangleFan => (0..idx.len().saturating_sub(2)).flat_map(|i| [idx[i + 1], idx[i + 2], idx[0]]).collect(),
            _ => idx,
        };
        if mode == Mode::Triangles && indices.len() % 3 != 0 {
            bail!("{}: {what}: {} indices is not a multiple of 3", self.file, indices.len());
        }
        let data = MeshData { name: what.clone(), positions, normals, uvs, tangents, indices: Some(indices) };
        let material = self.material_index(p.material());
        self.b.mesh(&data, material, world).map_err(|e| {
            let acc = p.get(&gltf::Semantic::Positions).map(|a| format!("POSITION accessor {}", a.index()));
            let ind = p.indices().map(|a| format!(", indices accessor {}", a.index()));
            anyhow!("{}: {e} ({}{})", self.file, acc.unwrap_or_default(), ind.unwrap_or_default())
        })?;
        Ok(())
    }

    fn node(&mut self, node: gltf::Node, parent: &Mat4, depth: usize) -> Result<()> {
        if depth > 256 {
            bail!("{}: node {} is nested more than 256 deep (a cycle in the node hierarchy?)", self.file, node.index());
        }
        let world = parent.mul(&Mat4::from_cols_f32(node.transform().matrix()));
        let nname = node.name().map(|n| format!(" ('{n}')")).unwrap_or_default();
        if node.skin().is_some() {
            self.b.warn(format!("{}: node {}{nname}: skins are ignored (the mesh is rendered unskinned)", self.file, node.index()));
        }
        if let Some(mesh) = node.mesh() {
            for p in mesh.primitives() {
                self.primitive(&mesh, &p, &world)?;
            }
        }
        let origin = world.point([0.0; 3]).as_vec3().to_array();
        let axis = |v: DVec3| normalize(world.vector(v));
        if let Some(cam) = node.camera() {
            if !origin.iter().all(|x| x.is_finite()) {
                bail!("{}: node {}{nname}: its camera is at a non-finite position {origin:?} after the node transforms (nodes[{}])", self.file, node.index(), node.index());
            }
            let f = axis(DVec3::NEG_Z).ok_or_else(|| anyhow!("{}: node {}{nname}: its camera's transform is singular", self.file, node.index()))?;
            let u0 = world.vector(DVec3::Y);
            let d = u0.dot(f);
            let up = normalize(u0 - f * d).ok_or_else(|| anyhow!("{}: node {}{nname}: its camera's transform is singular", self.file, node.index()))?;
            let projection = match cam.projection() {
                gltf::camera::Projection::Perspective(p) => Projection::Perspective { yfov: p.yfov(), aspect: p.aspect_ratio() },
                gltf::camera::Projection::Orthographic(o) => Projection::Orthographic { xmag: o.xmag(), ymag: o.ymag() },
            };
            let name = cam.name().or(node.name()).map(str::to_string).unwrap_or_else(|| format!("camera {}", cam.index()));
            self.b.camera(Camera { name, position: origin, forward: f.as_vec3().to_array(), up: up.as_vec3().to_array(), projection });
        }
        if let Some(light) = node.light() {
            let directed = !matches!(light.kind(), gltf::khr_lights_punctual::Kind::Point);
            let dir = match axis(DVec3::NEG_Z) {
                Some(d) => d.as_vec3().to_array(),
                // a point light has no direction: the word is unused
                None if !directed => [0.0, 0.0, -1.0],
                None => bail!("{}: node {}{nname}: its light {} has no direction: the node's transform is singular (nodes[{}])", self.file, node.index(), light.index(), node.index()),
            };
            if !origin.iter().all(|x| x.is_finite()) {
                bail!("{}: node {}{nname}: its light {} is at a non-finite position {origin:?} after the node transforms (nodes[{}])", self.file, node.index(), light.index(), node.index());
            }
            let kind = match light.kind() {
                gltf::khr_lights_punctual::Kind::Directional => LightKind::Directional,
                gltf::khr_lights_punctual::Kind::Point => LightKind::Point,
                gltf::khr_lights_punctual::Kind::Spot { inner_cone_angle, outer_cone_angle } => LightKind::Spot { inner_cone: inner_cone_angle, outer_cone: outer_cone_angle },
            };
            let c = light.color();
            let i = light.intensity();
            self.b.light(PunctualLight {
                name: light.name().or(node.name()).map(str::to_string).unwrap_or_else(|| format!("light {}", light.index())),
                kind,
                position: origin,
                direction: dir,
                intensity: [c[0] * i, c[1] * i, c[2] * i],
                range: light.range().unwrap_or(0.0),
            });
        }
        for child in node.children() {
            self.node(child, &world, depth + 1)?;
        }
        Ok(())
    }

    fn run(mut self) -> Result<Scene> {
        for ext in self.doc.extensions_used() {
            if !SUPPORTED.contains(&ext) {
                self.b.warn(format!("{}: extension {ext} is used but not supported: ignored", self.file));
            }
        }
        if self.doc.animations().count() > 0 {
            self.b.warn(format!("{}: {} animations are ignored (rest pose rendered)", self.file, self.doc.animations().count()));
        }
        self.load_buffers()?;
        self.materials()?;
        let scene = self.doc.default_scene().or_else(|| self.doc.scenes().next()).ok_or_else(|| anyhow!("{}: the file has no scene", self.file))?;
        for n in scene.nodes() {
            self.node(n, &Mat4::IDENTITY, 0)?;
        }
        if self.b.triangle_count() == 0 && !self.skipped.is_empty() {
            let list: Vec<String> = self.skipped.iter().take(4).map(|(p, m)| format!("{p} = {m:?}")).collect();
            bail!(
                "{}: the scene's only primitives are points or lines ({}{}), which the path tracer does not render: it renders triangles (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN) only",
                self.file,
                list.join(", "),
                if self.skipped.len() > 4 { format!(" and {} more", self.skipped.len() - 4) } else { String::new() }
            );
        }
        self.b.build()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_and_percent_decoding() {
        assert_eq!(base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64("aGVsbG8").unwrap(), b"hello");
        assert!(base64("a*b").is_none());
        assert_eq!(percent_decode("my%20file.bin"), "my file.bin");
        assert_eq!(percent_decode("a%2"), "a%2");
    }
}
