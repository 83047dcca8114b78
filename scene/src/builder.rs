//! The scene builder: world-space triangles, a BVH from `obvhs` (PLOC, Meister and Bittner 2018,
//! with SAH leaf collapsing and reinsertion), flattened depth first with skip pointers (Smits
//! 1998) into the scene buffer of `shader_core::pt::scene`.

use super::math::{normalize, Mat4};
use glam::DVec3;
use super::{Aabb, AlphaMode, Camera, LightKind, Material, MeshData, PunctualLight, Scene, SceneCounts, Texture, Wrap};
use anyhow::{bail, Result};
use shader_core::pt::scene as sc;
use std::time::{Duration, Instant};

/// One world-space triangle and its shading attributes.
#[derive(Clone, Debug)]
struct Tri {
    v: [[f32; 3]; 3],
    n: Option<[[f32; 3]; 3]>,
    uv: Option<[[f32; 2]; 3]>,
    t: Option<[[f32; 4]; 3]>,
    material: u32,
}

/// Collects materials, textures, meshes, lights and cameras, then [`build`](Self::build)s the
/// [`Scene`]. Used by the glTF loader and the built-in scenes.
#[derive(Clone, Debug, Default)]
pub struct SceneBuilder {
    source: String,
    materials: Vec<Material>,
    textures: Vec<Texture>,
    lights: Vec<PunctualLight>,
    cameras: Vec<Camera>,
    tris: Vec<Tri>,
    degenerate: usize,
    warnings: Vec<String>,
}

/// Rec. 709 luminance of linear RGB.
pub fn luminance(c: [f32; 3]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

impl SceneBuilder {
    /// An empty builder; `source` names the scene in messages and in [`Scene::source`].
    pub fn new(source: &str) -> SceneBuilder {
        SceneBuilder { source: source.into(), ..SceneBuilder::default() }
    }

    /// Adds a material; returns its index.
    pub fn material(&mut self, m: Material) -> u32 {
        self.materials.push(m);
        (self.materials.len() - 1) as u32
    }

    /// Adds a texture; returns its index. Fails when its texel count does not match its size.
    pub fn texture(&mut self, t: Texture) -> Result<u32> {
        if t.width == 0 || t.height == 0 || t.rgba.len() != t.width as usize * t.height as usize * 4 {
            bail!("texture '{}': {} bytes of texels for {}x{} RGBA8", t.name, t.rgba.len(), t.width, t.height);
        }
        self.textures.push(t);
        Ok((self.textures.len() - 1) as u32)
    }

    /// Adds a punctual light (world space).
    pub fn light(&mut self, l: PunctualLight) {
        self.lights.push(l);
    }

    /// Adds a camera (world space).
    pub fn camera(&mut self, c: Camera) {
        self.cameras.push(c);
    }

    /// Adds a warning to the scene's list.
    pub fn warn(&mut self, w: String) {
        if !self.warnings.contains(&w) {
            self.warnings.push(w);
        }
    }

    /// Number of materials so far.
    pub fn material_count(&self) -> usize {
        self.materials.len()
    }

    /// Number of triangles so far (degenerate ones dropped).
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Adds mesh `m` with material `material` under `transform` (local to world). Positions are
    /// transformed in f64 and rounded once (shared vertices stay bit-identical, so the mesh stays
    /// watertight), normals by the inverse transpose, tangents by the matrix (their sign flips
    /// with a mirroring transform, as does the winding). Zero-area triangles (collinear
    /// vertices in world space, f32) are dropped and counted. When the material has a normal
    /// texture and the mesh has no tangents, per-triangle tangents are computed from the
    /// texture coordinates (with a warning). Returns the number of triangles added.
    ///
    /// Errors: an index or attribute array out of range, a non-finite position, a triangle
    /// count that is not a multiple of 3, an unknown material.
    pub fn mesh(&mut self, m: &MeshData, material: u32, transform: &Mat4) -> Result<usize> {
        // messages name the mesh as given ("mesh 3 ('chair') primitive 0" from the loader)
        let name = if m.name.is_empty() { "mesh" } else { m.name.as_str() };
        let Some(mat) = self.materials.get(material as usize) else {
            bail!("{name}: material {material} does not exist ({} materials)", self.materials.len());
        };
        let nv = m.positions.len();
        for (attr, len) in [("NORMAL", m.normals.as_ref().map(|v| v.len())), ("TEXCOORD_0", m.uvs.as_ref().map(|v| v.len())), ("TANGENT", m.tangents.as_ref().map(|v| v.len()))] {
            if let Some(len) = len {
                if len != nv {
                    bail!("{name}: {attr} has {len} elements, POSITION has {nv}");
                }
            }
        }
        let indices: Vec<u32> = match &m.indices {
            Some(ix) => ix.clone(),
            None => (0..nv as u32).collect(),
        };
        if !indices.len().is_multiple_of(3) {
            bail!("{name}: {} indices is not a multiple of 3", indices.len());
        }
        if let Some((k, &i)) = indices.iter().enumerate().find(|(_, &i)| i as usize >= nv) {
            bail!("{name}: index {i} (element {k}) is out of range: the mesh has {nv} vertices");
        }
        // world-space vertices, once per vertex
        let mut world = Vec::with_capacity(nv);
        for (k, p) in m.positions.iter().enumerate() {
            if !p.iter().all(|x| x.is_finite()) {
                bail!("{name}: POSITION {k} is not finite: {p:?}");
            }
            let w = transform.point(*p).as_vec3().to_array();
            if !w.iter().all(|x| x.is_finite()) {
                bail!("{name}: POSITION {k} is not finite after its node transform: {w:?}");
            }
            world.push(w);
        }
        let normals: Option<Vec<Option<[f32; 3]>>> = m.normals.as_ref().map(|ns| ns.iter().map(|n| normalize(transform.normal(DVec3::from(n.map(|x| x as f64)))).map(|v| v.as_vec3().to_array())).collect());
        let det = transform.det3();
        let flip = det < 0.0;
        let tangents: Option<Vec<Option<[f32; 4]>>> = m.tangents.as_ref().map(|ts| {
            ts.iter()
                .map(|t| {
                    let w = if (t[3] < 0.0) != flip { -1.0 } else { 1.0 };
                    normalize(transform.vector(DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64))).map(|v| [v[0] as f32, v[1] as f32, v[2] as f32, w])
                })
                .collect()
        });
        let needs_tangents = mat.normal_texture.is_some() && m.tangents.is_none();
        let mat_name = mat.name.clone();
        if needs_tangents {
            if m.uvs.is_some() {
                self.warn(format!("{name}: no TANGENT for the normal texture of material '{mat_name}'; per-triangle tangents computed from TEXCOORD_0"));
            } else {
                self.warn(format!("{name}: the normal texture of material '{mat_name}' is ignored (no TANGENT and no TEXCOORD_0)"));
            }
        }
        let before = self.tris.len();
        for tri in indices.chunks_exact(3) {
            let mut ix = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
            if flip {
                ix.swap(1, 2);
            }
            let v = ix.map(|i| world[i]);
            let vd = v.map(|p| DVec3::from(p.map(|x| x as f64)));
            let area2 = (vd[1] - vd[0]).cross(vd[2] - vd[0]);
            if area2.dot(area2) == 0.0 {
                self.degenerate += 1;
                continue;
            }
            let n = normals.as_ref().and_then(|ns| Some([ns[ix[0]]?, ns[ix[1]]?, ns[ix[2]]?]));
            let uv = m.uvs.as_ref().map(|u| ix.map(|i| u[i]));
            let mut t = tangents.as_ref().and_then(|ts| Some([ts[ix[0]]?, ts[ix[1]]?, ts[ix[2]]?]));
            if needs_tangents {
                if let Some(uv) = uv {
                    t = triangle_tangent(vd, uv, area2).map(|t| [t; 3]);
                }
            }
            self.tris.push(Tri { v, n, uv, t, material });
        }
        Ok(self.tris.len() - before)
    }

    /// Builds the scene buffer: BVH, triangles in leaf order, shading records, materials,
    /// textures, lights and their selection CDF, sRGB table. Fails on an empty scene (no
    /// triangles) or one beyond the layout's limits (2^24 triangles).
    pub fn build(mut self) -> Result<Scene> {
        let start = Instant::now();
        if self.tris.is_empty() {
            if self.degenerate > 0 {
                bail!("{}: the scene has no triangles ({} degenerate zero-area triangles dropped)", self.source, self.degenerate);
            }
            bail!("{}: the scene has no triangles", self.source);
        }
        if self.tris.len() > sc::LEAF_MAX_FIRST as usize {
            bail!("{}: {} triangles, more than the scene buffer's limit of {}", self.source, self.tris.len(), sc::LEAF_MAX_FIRST);
        }
        for m in &self.materials {
            for t in [m.base_color_texture, m.metallic_roughness_texture, m.normal_texture, m.emissive_texture, m.transmission_texture].into_iter().flatten() {
                if t as usize >= self.textures.len() {
                    bail!("{}: material '{}' refers to texture {t}, but there are {} textures", self.source, m.name, self.textures.len());
                }
            }
        }
        if self.degenerate > 0 {
            let d = self.degenerate;
            self.warn(format!("{d} degenerate (zero-area) triangles dropped: a ray can never hit them"));
        }
        let mut bounds = Aabb::EMPTY;
        for t in &self.tris {
            for p in t.v {
                bounds.grow(p);
            }
        }
        // BVH
        let bvh_start = Instant::now();
        let (nodes, order, depth) = build_bvh(&self.tris);
        let bvh_seconds = bvh_start.elapsed().as_secs_f64();

        // lights: punctual first, then one per emissive triangle in BVH order
        let (_, radius) = bounds.bounding_sphere();
        let mut lights: Vec<[u32; sc::LIGHT_WORDS]> = Vec::new();
        let mut power: Vec<f64> = Vec::new();
        for l in &self.lights {
            let (w, p) = punctual_words(l, radius as f64);
            lights.push(w);
            power.push(p);
        }
        let mut tri_light = vec![sc::NONE; order.len()];
        for (k, &i) in order.iter().enumerate() {
            let t = &self.tris[i as usize];
            let m = &self.materials[t.material as usize];
            if m.is_emissive() {
                let vd = t.v.map(|p| DVec3::from(p.map(|x| x as f64)));
                let c = (vd[1] - vd[0]).cross(vd[2] - vd[0]);
                let area = 0.5 * c.length();
                let mut w = [0u32; sc::LIGHT_WORDS];
                w[sc::L_TYPE] = sc::LIGHT_TRIANGLE;
                w[sc::L_TRIANGLE] = k as u32;
                w[sc::L_AREA] = (area as f32).to_bits();
                // power of an emitter of constant radiance L over area A, one face: pi L A
                // (the emissive texture, at most 1, is not included: an upper bound)
                let sides = if m.double_sided { 2.0 } else { 1.0 };
                tri_light[k] = lights.len() as u32;
                lights.push(w);
                power.push(luminance(m.emissive) * area * std::f64::consts::PI * sides);
            }
        }
        let cdf = selection_cdf(&power);

        // the buffer
        let mut words = vec![0u32; sc::HEADER_WORDS];
        words[0] = sc::MAGIC;
        let section = |words: &mut Vec<u32>, off: usize| {
            let o = words.len() as u32;
            words[off] = o;
        };
        let extent = bounds.min.iter().chain(bounds.max.iter()).fold(0.0f32, |a, &x| a.max(x.abs()));
        // boxes grown by 2^-20 of the scene's largest coordinate: the slab test is
        // conservative for exact intersections, this also covers the rounding of the triangle test
        let pad = extent * (1.0 / 1_048_576.0);
        words[sc::H_NODES] = nodes.len() as u32;
        section(&mut words, sc::H_NODES_OFF);
        for nd in &nodes {
            for k in 0..3 {
                words.push((nd.bounds.min[k] - pad).to_bits());
            }
            for k in 0..3 {
                words.push((nd.bounds.max[k] + pad).to_bits());
            }
            words.push(nd.skip);
            words.push(nd.leaf);
        }
        words[sc::H_TRIS] = order.len() as u32;
        section(&mut words, sc::H_TRIS_OFF);
        for &i in &order {
            for p in self.tris[i as usize].v {
                words.extend(p.map(f32::to_bits));
            }
        }
        section(&mut words, sc::H_SHADING_OFF);
        for (k, &i) in order.iter().enumerate() {
            let t = &self.tris[i as usize];
            let mut s = [0u32; sc::SHADING_WORDS];
            let mut flags = 0;
            if let Some(n) = t.n {
                flags |= sc::SF_NORMALS;
                for (j, v) in n.iter().enumerate() {
                    for c in 0..3 {
                        s[sc::S_NORMALS + 3 * j + c] = v[c].to_bits();
                    }
                }
            }
            if let Some(uv) = t.uv {
                flags |= sc::SF_UVS;
                for (j, v) in uv.iter().enumerate() {
                    s[sc::S_UVS + 2 * j] = v[0].to_bits();
                    s[sc::S_UVS + 2 * j + 1] = v[1].to_bits();
                }
            }
            if let Some(tg) = t.t {
                flags |= sc::SF_TANGENTS;
                for (j, v) in tg.iter().enumerate() {
                    for c in 0..4 {
                        s[sc::S_TANGENTS + 4 * j + c] = v[c].to_bits();
                    }
                }
            }
            s[sc::S_MATERIAL] = t.material;
            s[sc::S_LIGHT] = tri_light[k];
            s[sc::S_FLAGS] = flags;
            words.extend_from_slice(&s);
        }
        words[sc::H_MATERIALS] = self.materials.len() as u32;
        section(&mut words, sc::H_MATERIALS_OFF);
        for m in &self.materials {
            words.extend_from_slice(&material_words(m));
        }
        words[sc::H_TEXTURES] = self.textures.len() as u32;
        section(&mut words, sc::H_TEXTURES_OFF);
        let mut texel_offset = 0u32;
        for t in &self.textures {
            let mut w = [0u32; sc::TEXTURE_WORDS];
            w[sc::T_TEXELS] = texel_offset;
            w[sc::T_WIDTH] = t.width;
            w[sc::T_HEIGHT] = t.height;
            w[sc::T_WRAP_S] = wrap_word(t.wrap_s);
            w[sc::T_WRAP_T] = wrap_word(t.wrap_t);
            w[sc::T_NEAREST] = t.nearest as u32;
            words.extend_from_slice(&w);
            texel_offset += t.width * t.height;
        }
        section(&mut words, sc::H_TEXELS_OFF);
        for t in &self.textures {
            words.extend(t.rgba.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])));
        }
        words[sc::H_LIGHTS] = lights.len() as u32;
        section(&mut words, sc::H_LIGHTS_OFF);
        for l in &lights {
            words.extend_from_slice(l);
        }
        section(&mut words, sc::H_LIGHT_CDF_OFF);
        words.extend(cdf.iter().map(|c| c.to_bits()));
        section(&mut words, sc::H_SRGB_OFF);
        words.extend((0..256).map(|i| shader_core::pt::texture::srgb_to_linear(i as f32 / 255.0).to_bits()));

        let leaves: Vec<&FlatNode> = nodes.iter().filter(|n| n.leaf != 0).collect();
        let counts = SceneCounts {
            triangles: order.len(),
            degenerate: self.degenerate,
            nodes: nodes.len(),
            leaves: leaves.len(),
            max_leaf_triangles: leaves.iter().map(|n| sc::leaf_range(n.leaf).1 as usize).max().unwrap_or(0),
            bvh_depth: depth,
            lights: lights.len(),
            punctual_lights: self.lights.len(),
            emissive_triangles: lights.len() - self.lights.len(),
            materials: self.materials.len(),
            textures: self.textures.len(),
            texel_bytes: texel_offset as usize * 4,
            words: words.len(),
        };
        Ok(Scene {
            source: self.source,
            words,
            cameras: self.cameras,
            bounds,
            warnings: self.warnings,
            counts,
            materials: self.materials,
            punctual_lights: self.lights,
            build_seconds: start.elapsed().as_secs_f64(),
            bvh_seconds,
        })
    }
}

/// Per-triangle tangent from positions and texture coordinates (Lengyel 2001, "Computing
/// tangent space basis vectors"), with glTF's v-down texture coordinates: the bitangent points
/// towards -v. `None` where the uv map is degenerate.
fn triangle_tangent(v: [DVec3; 3], uv: [[f32; 2]; 3], normal: DVec3) -> Option<[f32; 4]> {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let (du1, dv1) = (uv[1][0] as f64 - uv[0][0] as f64, uv[1][1] as f64 - uv[0][1] as f64);
    let (du2, dv2) = (uv[2][0] as f64 - uv[0][0] as f64, uv[2][1] as f64 - uv[0][1] as f64);
    let det = du1 * dv2 - du2 * dv1;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let t = DVec3::from([0, 1, 2].map(|k| (e1[k] * dv2 - e2[k] * dv1) / det));
    let b = DVec3::from([0, 1, 2].map(|k| -(e2[k] * du1 - e1[k] * du2) / det));
    let n = normalize(normal)?;
    let t = normalize(t - n * n.dot(t))?;
    let w = if n.cross(t).dot(b) < 0.0 { -1.0 } else { 1.0 };
    Some([t[0] as f32, t[1] as f32, t[2] as f32, w])
}

/// A node of the flattened BVH.
#[derive(Clone, Copy, Debug)]
struct FlatNode {
    bounds: Aabb,
    skip: u32,
    leaf: u32,
}

/// The BVH of `tris`: the `obvhs` PLOC build (`BvhBuildParams::medium_build`: no spatial
/// splits, so every triangle is in exactly one leaf; leaves of at most 4 triangles after SAH
/// collapsing), flattened depth first. Returns the nodes, the triangle order (BVH slot ->
/// input index) and the depth.
fn build_bvh(tris: &[Tri]) -> (Vec<FlatNode>, Vec<u32>, usize) {
    let tri_box = |t: &Tri| {
        let mut b = Aabb::EMPTY;
        for p in t.v {
            b.grow(p);
        }
        b
    };
    let mut nodes = Vec::new();
    let mut order = Vec::with_capacity(tris.len());
    if tris.len() == 1 {
        nodes.push(FlatNode { bounds: tri_box(&tris[0]), skip: 1, leaf: sc::leaf_word(0, 1) });
        order.push(0);
        return (nodes, order, 1);
    }
    let otris: Vec<obvhs::triangle::Triangle> = tris.iter().map(|t| obvhs::triangle::Triangle { v0: t.v[0].into(), v1: t.v[1].into(), v2: t.v[2].into() }).collect();
    // leaves of at most 4: measured 5-15% faster closest hits than obvhs's default 8 on the built-in
    // scene at 30k and 300k triangles (host/tests/render_scene.rs build_time_by_scene_size)
    let params = obvhs::BvhBuildParams { max_prims_per_leaf: 4, ..obvhs::BvhBuildParams::medium_build() };
    let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(&otris, params, &mut Duration::default());
    let mut depth = 0;
    // explicit stack: (obvhs node, depth, index of the parent's placeholder to finish)
    fn emit(bvh: &obvhs::bvh2::Bvh2, ni: usize, d: usize, tris: &[Tri], nodes: &mut Vec<FlatNode>, order: &mut Vec<u32>, depth: &mut usize, tri_box: &dyn Fn(&Tri) -> Aabb) -> Aabb {
        *depth = (*depth).max(d);
        let node = &bvh.nodes[ni];
        let me = nodes.len();
        nodes.push(FlatNode { bounds: Aabb::EMPTY, skip: 0, leaf: 0 });
        let mut b = Aabb::EMPTY;
        if node.is_leaf() {
            let first = order.len() as u32;
            for k in 0..node.prim_count as usize {
                let i = bvh.primitive_indices[node.first_index as usize + k];
                b.union(&tri_box(&tris[i as usize]));
                order.push(i);
            }
            nodes[me].leaf = sc::leaf_word(first, node.prim_count);
        } else {
            let l = emit(bvh, node.first_index as usize, d + 1, tris, nodes, order, depth, tri_box);
            let r = emit(bvh, node.first_index as usize + 1, d + 1, tris, nodes, order, depth, tri_box);
            b.union(&l);
            b.union(&r);
        }
        nodes[me].bounds = b;
        nodes[me].skip = nodes.len() as u32;
        b
    }
    emit(&bvh, 0, 1, tris, &mut nodes, &mut order, &mut depth, &tri_box);
    (nodes, order, depth)
}

/// Inclusive CDF of the selection probabilities proportional to `power` (f64 sums, rounded
/// once; last = 1). All-zero or non-finite powers select uniformly.
fn selection_cdf(power: &[f64]) -> Vec<f32> {
    if power.is_empty() {
        return Vec::new();
    }
    let ok = power.iter().all(|p| p.is_finite() && *p >= 0.0);
    let total: f64 = power.iter().sum();
    let p: Vec<f64> = if ok && total > 0.0 { power.to_vec() } else { vec![1.0; power.len()] };
    let total: f64 = p.iter().sum();
    let mut acc = 0.0;
    let mut cdf: Vec<f32> = p
        .iter()
        .map(|x| {
            acc += x;
            (acc / total) as f32
        })
        .collect();
    *cdf.last_mut().unwrap() = 1.0;
    cdf
}

/// The light words of a punctual light and its power estimate, which sets its selection
/// probability:
/// - point: 4 pi lum(I) (intensity I over the sphere);
/// - spot: 2 pi (1 - (cos_inner + cos_outer) / 2) lum(I) (the solid angle of a cone halfway
///   between the inner and outer angles);
/// - directional: lum(E) pi r^2, E the irradiance and r the scene's bounding-sphere radius (the
///   flux through the scene's cross-section).
fn punctual_words(l: &PunctualLight, radius: f64) -> ([u32; sc::LIGHT_WORDS], f64) {
    let mut w = [0u32; sc::LIGHT_WORDS];
    let pi = std::f64::consts::PI;
    let lum = luminance(l.intensity);
    let put3 = |w: &mut [u32; sc::LIGHT_WORDS], o: usize, v: [f32; 3]| {
        for k in 0..3 {
            w[o + k] = v[k].to_bits();
        }
    };
    put3(&mut w, sc::L_POSITION, l.position);
    put3(&mut w, sc::L_DIRECTION, l.direction);
    put3(&mut w, sc::L_INTENSITY, l.intensity);
    w[sc::L_RANGE] = l.range.to_bits();
    w[sc::L_TRIANGLE] = sc::NONE;
    let power = match l.kind {
        LightKind::Directional => {
            w[sc::L_TYPE] = sc::LIGHT_DIRECTIONAL;
            lum * pi * radius * radius
        }
        LightKind::Point => {
            w[sc::L_TYPE] = sc::LIGHT_POINT;
            4.0 * pi * lum
        }
        LightKind::Spot { inner_cone, outer_cone } => {
            w[sc::L_TYPE] = sc::LIGHT_SPOT;
            let (ci, co) = ((inner_cone as f64).cos(), (outer_cone as f64).cos());
            w[sc::L_COS_INNER] = (ci as f32).to_bits();
            w[sc::L_COS_OUTER] = (co as f32).to_bits();
            2.0 * pi * (1.0 - (ci + co) * 0.5) * lum
        }
    };
    (w, power)
}

fn wrap_word(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => sc::WRAP_REPEAT,
        Wrap::Clamp => sc::WRAP_CLAMP,
        Wrap::Mirror => sc::WRAP_MIRROR,
    }
}

/// The material words of `m` (layout `shader_core::pt::scene::M_*`).
pub fn material_words(m: &Material) -> [u32; sc::MATERIAL_WORDS] {
    let mut w = [0u32; sc::MATERIAL_WORDS];
    for k in 0..4 {
        w[sc::M_BASE + k] = m.base_color[k].to_bits();
    }
    w[sc::M_METALLIC] = m.metallic.to_bits();
    w[sc::M_ROUGHNESS] = m.roughness.to_bits();
    for k in 0..3 {
        w[sc::M_EMISSIVE + k] = m.emissive[k].to_bits();
    }
    w[sc::M_NORMAL_SCALE] = m.normal_scale.to_bits();
    match m.alpha_mode {
        AlphaMode::Opaque => {
            w[sc::M_ALPHA_MODE] = sc::ALPHA_OPAQUE;
            w[sc::M_ALPHA_CUTOFF] = 0.5f32.to_bits();
        }
        AlphaMode::Mask(c) => {
            w[sc::M_ALPHA_MODE] = sc::ALPHA_MASK;
            w[sc::M_ALPHA_CUTOFF] = c.to_bits();
        }
    }
    w[sc::M_DOUBLE_SIDED] = m.double_sided as u32;
    w[sc::M_TRANSMISSION] = m.transmission.to_bits();
    w[sc::M_IOR] = m.ior.to_bits();
    // Each texture slot's word with its transform, k = the slot's index from M_BASE_TEX.
    let slots = [
        (sc::M_BASE_TEX, m.base_color_texture, m.base_color_uv),
        (sc::M_MR_TEX, m.metallic_roughness_texture, m.metallic_roughness_uv),
        (sc::M_NORMAL_TEX, m.normal_texture, m.normal_uv),
        (sc::M_EMISSIVE_TEX, m.emissive_texture, m.emissive_uv),
        (sc::M_TRANSMISSION_TEX, m.transmission_texture, m.transmission_uv),
    ];
    for (slot, texture, uv) in slots {
        w[slot] = texture.unwrap_or(sc::NONE);
        let k = slot - sc::M_BASE_TEX;
        for (j, x) in uv.matrix().iter().enumerate() {
            w[sc::M_UV_TRANSFORMS + 6 * k + j] = x.to_bits();
        }
        if !uv.is_identity() {
            w[sc::M_UV_TRANSFORMED] |= 1 << k;
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdf_is_inclusive_and_ends_at_one() {
        assert_eq!(selection_cdf(&[1.0, 3.0]), vec![0.25, 1.0]);
        assert_eq!(selection_cdf(&[0.0, 0.0]), vec![0.5, 1.0]);
        assert!(selection_cdf(&[]).is_empty());
    }
}
