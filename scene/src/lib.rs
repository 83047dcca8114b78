//! Scenes for the path tracer: a host-side model (materials, textures, meshes, punctual lights,
//! cameras), the builder that flattens it into the scene buffer of `shader_core::pt::scene`
//! (with a BVH from the `obvhs` crate, laid out for the stackless traversal of
//! `shader_core::pt::bvh`), the glTF 2.0 loader ([`Scene::load`]) and the built-in Cornell box
//! ([`Scene::builtin`]).
//!
//! Conventions are glTF's: metres, right-handed, +Y up, counter-clockwise front faces, texture
//! coordinates with (0, 0) at the image's top-left, linear colour factors, sRGB colour textures.
//!
//! ```
//! // the built-in Cornell box, flattened for the kernels, with its camera
//! let cornell = scene::Scene::builtin(scene::DEFAULT_DETAIL);
//! assert!(cornell.counts.triangles > 0 && cornell.has_lights());
//! assert!(cornell.camera("0").is_some());
//! // a glTF file: the same buffer layout (`shader_core::pt::scene`)
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");
//! let loaded = scene::Scene::load(path)?;
//! assert_eq!(loaded.words.len(), loaded.counts.words);
//! # Ok::<(), anyhow::Error>(())
//! ```

mod builder;
mod builtin;
mod camera;
pub mod environment;
mod gltf_load;
pub mod image_file;
pub mod gltf_write;
mod math;
mod validate;

pub use builder::SceneBuilder;
pub use builder::{luminance, material_words};
pub use builtin::{builtin_detail_for_triangles, builtin_triangles, cornell_spheres_gltf, uv_sphere, DEFAULT_DETAIL};
pub use camera::{Camera, Projection};
pub use math::Mat4;

/// glTF `alphaMode`: how the base colour's alpha is used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Alpha ignored.
    Opaque,
    /// A hit is kept only where alpha >= the cutoff (glTF `MASK`, `alphaCutoff`).
    Mask(f32),
}

/// A glTF metal-rough material (glTF 2.0 section 3.9 and the `KHR_materials_emissive_strength`,
/// `KHR_materials_transmission`, `KHR_materials_ior` extensions). Texture fields are indices
/// returned by [`SceneBuilder::texture`]; all colour factors are linear.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name (for messages).
    pub name: String,
    /// `baseColorFactor`, linear RGBA.
    pub base_color: [f32; 4],
    /// `metallicFactor`.
    pub metallic: f32,
    /// `roughnessFactor` (perceptual roughness).
    pub roughness: f32,
    /// `emissiveFactor` times `emissive_strength` (linear RGB radiance).
    pub emissive: [f32; 3],
    /// `normalTexture.scale`.
    pub normal_scale: f32,
    /// `alphaMode` with its cutoff.
    pub alpha_mode: AlphaMode,
    /// `doubleSided` (an emissive double-sided material emits from both faces).
    pub double_sided: bool,
    /// `KHR_materials_transmission.transmissionFactor`.
    pub transmission: f32,
    /// `KHR_materials_ior.ior`.
    pub ior: f32,
    /// Base colour texture (sRGB; alpha in A).
    pub base_color_texture: Option<u32>,
    /// Metallic-roughness texture (roughness in G, metallic in B).
    pub metallic_roughness_texture: Option<u32>,
    /// Tangent-space normal texture.
    pub normal_texture: Option<u32>,
    /// Emissive texture (sRGB).
    pub emissive_texture: Option<u32>,
    /// Transmission texture (factor in R).
    pub transmission_texture: Option<u32>,
    /// `KHR_texture_transform` of the base colour texture.
    pub base_color_uv: UvTransform,
    /// `KHR_texture_transform` of the metallic-roughness texture.
    pub metallic_roughness_uv: UvTransform,
    /// `KHR_texture_transform` of the normal texture.
    pub normal_uv: UvTransform,
    /// `KHR_texture_transform` of the emissive texture.
    pub emissive_uv: UvTransform,
    /// `KHR_texture_transform` of the transmission texture.
    pub transmission_uv: UvTransform,
}

/// A texture reference's `KHR_texture_transform` (glTF extension spec): texture coordinates are
/// read as uv' = T R S uv, T the translation by `offset`, R the rotation by `rotation` radians
/// (counter-clockwise in UV space: R = [[cos, sin], [-sin, cos]]), S the scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    /// `offset` (u, v).
    pub offset: [f32; 2],
    /// `rotation` in radians.
    pub rotation: f32,
    /// `scale` (u, v).
    pub scale: [f32; 2],
}

impl Default for UvTransform {
    fn default() -> UvTransform {
        UvTransform::IDENTITY
    }
}

impl UvTransform {
    /// No transform (the extension's defaults).
    pub const IDENTITY: UvTransform = UvTransform { offset: [0.0, 0.0], rotation: 0.0, scale: [1.0, 1.0] };

    /// Whether texture coordinates pass unchanged.
    pub fn is_identity(&self) -> bool {
        *self == UvTransform::IDENTITY
    }

    /// T R S as the 2x3 matrix [m0 m1 m2; m3 m4 m5] the kernels apply:
    /// (u', v') = (m0 u + m1 v + m2, m3 u + m4 v + m5); computed in f64, rounded once to f32.
    pub fn matrix(&self) -> [f32; 6] {
        let (s, c) = (self.rotation as f64).sin_cos();
        let (sx, sy) = (self.scale[0] as f64, self.scale[1] as f64);
        [(c * sx) as f32, (s * sy) as f32, self.offset[0], (-s * sx) as f32, (c * sy) as f32, self.offset[1]]
    }
}

impl Default for Material {
    /// The glTF default material: base colour 1, metallic 1, roughness 1, no emission, opaque,
    /// single sided, no transmission, IOR 1.5.
    fn default() -> Material {
        Material {
            name: "default".into(),
            base_color: [1.0; 4],
            metallic: 1.0,
            roughness: 1.0,
            emissive: [0.0; 3],
            normal_scale: 1.0,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
            transmission: 0.0,
            ior: 1.5,
            base_color_texture: None,
            metallic_roughness_texture: None,
            normal_texture: None,
            emissive_texture: None,
            transmission_texture: None,
            base_color_uv: UvTransform::IDENTITY,
            metallic_roughness_uv: UvTransform::IDENTITY,
            normal_uv: UvTransform::IDENTITY,
            emissive_uv: UvTransform::IDENTITY,
            transmission_uv: UvTransform::IDENTITY,
        }
    }
}

impl Material {
    /// An opaque dielectric-or-metal material with the given linear base colour, metallic and
    /// roughness.
    pub fn pbr(name: &str, base: [f32; 3], metallic: f32, roughness: f32) -> Material {
        Material { name: name.into(), base_color: [base[0], base[1], base[2], 1.0], metallic, roughness, ..Material::default() }
    }

    /// Whether the material emits (any emissive component > 0).
    pub fn is_emissive(&self) -> bool {
        self.emissive.iter().any(|&e| e > 0.0)
    }
}

/// glTF sampler wrap mode (section 3.8.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    /// `REPEAT` (10497), the default.
    Repeat,
    /// `CLAMP_TO_EDGE` (33071).
    Clamp,
    /// `MIRRORED_REPEAT` (33648).
    Mirror,
}

/// An RGBA8 texture with its sampler.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Name (for messages).
    pub name: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Texels, RGBA8, rows top to bottom (`width * height * 4` bytes).
    pub rgba: Vec<u8>,
    /// Wrap mode in s (u).
    pub wrap_s: Wrap,
    /// Wrap mode in t (v).
    pub wrap_t: Wrap,
    /// Nearest magnification (glTF `magFilter` = `NEAREST`); otherwise bilinear.
    pub nearest: bool,
}

/// A triangle mesh in its local frame. Attributes are per vertex; `indices` (three per
/// triangle) index them, or, when `None`, vertices 0, 1, 2 form the first triangle and so on.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Name (for messages).
    pub name: String,
    /// Positions.
    pub positions: Vec<[f32; 3]>,
    /// Vertex normals (any length; normalised after the transform).
    pub normals: Option<Vec<[f32; 3]>>,
    /// Texture coordinates, glTF `TEXCOORD_0`.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Tangents xyz with the bitangent sign in w (glTF `TANGENT`).
    pub tangents: Option<Vec<[f32; 4]>>,
    /// Triangle vertex indices (three per triangle), or `None` for a non-indexed mesh.
    pub indices: Option<Vec<u32>>,
}

/// The kind of a punctual light (`KHR_lights_punctual`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// A sun: `direction` is where the light travels; `intensity` is irradiance (lux).
    Directional,
    /// A point light at `position`; `intensity` is radiant intensity (candela).
    Point,
    /// A spot light at `position` shining along `direction`, full within `inner_cone` and zero
    /// beyond `outer_cone` (angles from the axis, radians).
    Spot {
        /// Inner cone angle (radians).
        inner_cone: f32,
        /// Outer cone angle (radians).
        outer_cone: f32,
    },
}

/// A punctual light in world space.
#[derive(Clone, Debug, PartialEq)]
pub struct PunctualLight {
    /// Name (for messages).
    pub name: String,
    /// Type and cone.
    pub kind: LightKind,
    /// World position (point, spot).
    pub position: [f32; 3],
    /// Unit world direction the light travels towards (directional, spot).
    pub direction: [f32; 3],
    /// Colour times intensity (linear RGB).
    pub intensity: [f32; 3],
    /// glTF `range`; 0 = infinite.
    pub range: f32,
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub min: [f32; 3],
    /// Maximum corner.
    pub max: [f32; 3],
}

impl Aabb {
    /// The empty box (min = +inf, max = -inf).
    pub const EMPTY: Aabb = Aabb { min: [f32::INFINITY; 3], max: [f32::NEG_INFINITY; 3] };

    /// The box grown to contain `p`.
    pub fn grow(&mut self, p: [f32; 3]) {
        for k in 0..3 {
            self.min[k] = self.min[k].min(p[k]);
            self.max[k] = self.max[k].max(p[k]);
        }
    }

    /// The box grown to contain `o`.
    pub fn union(&mut self, o: &Aabb) {
        self.grow(o.min);
        self.grow(o.max);
    }

    /// Whether `p` lies inside (boundary included).
    pub fn contains(&self, p: [f32; 3]) -> bool {
        (0..3).all(|k| self.min[k] <= p[k] && p[k] <= self.max[k])
    }

    /// Centre and radius of the bounding sphere through the corners.
    pub fn bounding_sphere(&self) -> ([f32; 3], f32) {
        let c = [0, 1, 2].map(|k| 0.5 * (self.min[k] + self.max[k]));
        let r = (0..3).map(|k| ((self.max[k] - self.min[k]) as f64 * 0.5).powi(2)).sum::<f64>().sqrt();
        (c, r as f32)
    }
}

/// Sizes of a built scene.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SceneCounts {
    /// Triangles (after dropping degenerate ones).
    pub triangles: usize,
    /// Triangles dropped as degenerate (zero area).
    pub degenerate: usize,
    /// BVH nodes.
    pub nodes: usize,
    /// BVH leaves.
    pub leaves: usize,
    /// Most triangles in one leaf.
    pub max_leaf_triangles: usize,
    /// Depth of the BVH (root = 1).
    pub bvh_depth: usize,
    /// Lights in the buffer: punctual lights and emissive triangles.
    pub lights: usize,
    /// Punctual lights.
    pub punctual_lights: usize,
    /// Emissive triangles (each a light).
    pub emissive_triangles: usize,
    /// Materials.
    pub materials: usize,
    /// Textures.
    pub textures: usize,
    /// Bytes of texels (4 per texel).
    pub texel_bytes: usize,
    /// Words of the whole scene buffer.
    pub words: usize,
}

/// A scene ready for the kernels: the flat buffer of `shader_core::pt::scene` and what the host
/// needs beside it (cameras, bounds, warnings, sizes).
#[derive(Clone, Debug)]
pub struct Scene {
    /// Where it came from (a file path, or "builtin cornell box (detail N)").
    pub source: String,
    /// The scene buffer (see `shader_core::pt::scene` for the layout).
    pub words: Vec<u32>,
    /// Cameras, in file order (glTF: in node traversal order of the scene).
    pub cameras: Vec<Camera>,
    /// World bounds of all triangles.
    pub bounds: Aabb,
    /// Everything unsupported that the scene uses, and what was done instead.
    pub warnings: Vec<String>,
    /// Sizes.
    pub counts: SceneCounts,
    /// Materials as given (index = material word).
    pub materials: Vec<Material>,
    /// Punctual lights as given (they are the first lights of the buffer, in this order).
    pub punctual_lights: Vec<PunctualLight>,
    /// Wall-clock seconds of [`SceneBuilder::build`] (triangles, BVH, flattening).
    pub build_seconds: f64,
    /// Of which the `obvhs` BVH build.
    pub bvh_seconds: f64,
}

impl Scene {
    /// Whether the scene has any light of its own (punctual or emissive triangle); without one
    /// the renderer supplies default lighting.
    pub fn has_lights(&self) -> bool {
        self.counts.lights > 0
    }

    /// The camera named `name`, or with that index.
    pub fn camera(&self, name_or_index: &str) -> Option<&Camera> {
        if let Some(c) = self.cameras.iter().find(|c| c.name == name_or_index) {
            return Some(c);
        }
        name_or_index.parse::<usize>().ok().and_then(|i| self.cameras.get(i))
    }

    /// The built-in Cornell box with two rows of spheres (see [`builtin`](self::builtin));
    /// `detail` = latitude bands per sphere (>= 3; [`DEFAULT_DETAIL`];
    /// [`builtin_detail_for_triangles`] picks one for a target triangle count).
    pub fn builtin(detail: u32) -> Scene {
        builtin::cornell_spheres(detail)
    }

    /// Loads a glTF 2.0 scene (`.gltf` with external or data-URI buffers, or `.glb`).
    pub fn load(path: impl AsRef<std::path::Path>) -> anyhow::Result<Scene> {
        gltf_load::load(path.as_ref())
    }
}
