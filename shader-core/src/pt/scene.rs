//! The flat scene buffer the path tracer reads (one `&[u32]` storage buffer; floats stored as
//! their bits): a header of section offsets, the BVH nodes, the triangles in BVH leaf order, their
//! shading attributes, the materials, the textures and their texels, and the lights.
//!
//! The host writes it (`host::render::scene`), the kernels read it through the accessors below,
//! so the layout has exactly one definition. Every read goes through
//! [`crate::buffer::load_u32`]: an out-of-range index reads 0 on both backends.
//!
//! | section | words per element | contents |
//! |---|---|---|
//! | header | [`HEADER_WORDS`] | [`MAGIC`], then the `H_*` counts and offsets |
//! | nodes | [`NODE_WORDS`] | AABB min xyz, max xyz, skip index, leaf word ([`leaf_word`]) |
//! | triangles | [`TRI_WORDS`] | world-space v0, v1, v2 |
//! | shading | [`SHADING_WORDS`] | see the `S_*` offsets |
//! | materials | [`MATERIAL_WORDS`] | see the `M_*` offsets |
//! | textures | [`TEXTURE_WORDS`] | see the `T_*` offsets |
//! | texels | 1 | RGBA8, R in the low byte, rows top to bottom |
//! | lights | [`LIGHT_WORDS`] | see the `L_*` offsets |
//! | light CDF | 1 | inclusive CDF (f32) of the lights' selection probabilities, last = 1 |
//! | sRGB table | 1 | 256 floats: the linear value of each 8-bit sRGB code |
//!
//! ```
//! use shader_core::pt::scene::{leaf_range, leaf_word};
//! // A leaf's word packs its first triangle and count; an inner node's word is 0.
//! assert_eq!(leaf_range(leaf_word(1234, 4)), (1234, 4));
//! assert_eq!(leaf_range(0).1, 0);
//! ```

use crate::buffer::load_u32;
use crate::vector::Vec3;

/// First header word: "PTS1".
pub const MAGIC: u32 = 0x3153_5450;
/// Words in the header.
pub const HEADER_WORDS: usize = 32;
/// Header word: number of BVH nodes.
pub const H_NODES: usize = 1;
/// Header word: offset of the first node.
pub const H_NODES_OFF: usize = 2;
/// Header word: number of triangles.
pub const H_TRIS: usize = 3;
/// Header word: offset of the triangle positions.
pub const H_TRIS_OFF: usize = 4;
/// Header word: offset of the per-triangle shading attributes.
pub const H_SHADING_OFF: usize = 5;
/// Header word: number of materials.
pub const H_MATERIALS: usize = 6;
/// Header word: offset of the materials.
pub const H_MATERIALS_OFF: usize = 7;
/// Header word: number of textures.
pub const H_TEXTURES: usize = 8;
/// Header word: offset of the texture table.
pub const H_TEXTURES_OFF: usize = 9;
/// Header word: offset of the texel pool.
pub const H_TEXELS_OFF: usize = 10;
/// Header word: number of lights (punctual lights and emissive triangles).
pub const H_LIGHTS: usize = 11;
/// Header word: offset of the lights.
pub const H_LIGHTS_OFF: usize = 12;
/// Header word: offset of the lights' selection CDF (`H_LIGHTS` floats).
pub const H_LIGHT_CDF_OFF: usize = 13;
/// Header word: offset of the 256-entry sRGB decode table (floats,
/// `texture::srgb_to_linear(i / 255)` written by the host with the kernels' own function).
pub const H_SRGB_OFF: usize = 14;

/// Words per BVH node.
pub const NODE_WORDS: usize = 8;
/// Node word: index of the node to visit next when this node is missed or is a leaf (the next
/// node in depth-first order that is not a descendant; `nodes` = end of traversal).
pub const N_SKIP: usize = 6;
/// Node word: 0 for an inner node (its first child is the next node), else [`leaf_word`].
pub const N_LEAF: usize = 7;
/// Largest triangle count of one leaf.
pub const LEAF_MAX_TRIS: u32 = 255;
/// Largest first-triangle index of a leaf.
pub const LEAF_MAX_FIRST: u32 = (1 << 24) - 1;

/// The leaf word of a leaf holding triangles `first .. first + count` (1 <= count <= 255,
/// first < 2^24): `count << 24 | first`.
#[inline]
pub const fn leaf_word(first: u32, count: u32) -> u32 {
    (count << 24) | first
}

/// (first triangle, count) of a leaf word; count 0 for an inner node.
#[inline]
pub fn leaf_range(word: u32) -> (u32, u32) {
    (word & LEAF_MAX_FIRST, word >> 24)
}

/// Words per triangle position record (v0, v1, v2).
pub const TRI_WORDS: usize = 9;

/// Words per shading record.
pub const SHADING_WORDS: usize = 32;
/// Shading word: vertex normals n0, n1, n2 (9 words; world space, unit).
pub const S_NORMALS: usize = 0;
/// Shading word: texture coordinates uv0, uv1, uv2 (6 words; glTF convention, v down).
pub const S_UVS: usize = 9;
/// Shading word: vertex tangents t0, t1, t2 as xyzw (12 words; w = bitangent sign).
pub const S_TANGENTS: usize = 15;
/// Shading word: material index.
pub const S_MATERIAL: usize = 27;
/// Shading word: index of the emissive-triangle light of this triangle, or [`NONE`].
pub const S_LIGHT: usize = 28;
/// Shading word: [`SF_NORMALS`] | [`SF_UVS`] | [`SF_TANGENTS`].
pub const S_FLAGS: usize = 29;
/// Shading flag: the vertex normals are given (else the geometric normal is used).
pub const SF_NORMALS: u32 = 1;
/// Shading flag: the texture coordinates are given (else all zero).
pub const SF_UVS: u32 = 2;
/// Shading flag: the tangents are given (else a normal map is ignored).
pub const SF_TANGENTS: u32 = 4;

/// "No index" (no texture, no light).
pub const NONE: u32 = u32::MAX;

/// Words per material.
pub const MATERIAL_WORDS: usize = 52;
/// Material word: base colour factor, linear RGBA (4 words).
pub const M_BASE: usize = 0;
/// Material word: metallic factor.
pub const M_METALLIC: usize = 4;
/// Material word: perceptual roughness factor.
pub const M_ROUGHNESS: usize = 5;
/// Material word: emissive factor times `KHR_materials_emissive_strength` (3 words).
pub const M_EMISSIVE: usize = 6;
/// Material word: normal texture scale.
pub const M_NORMAL_SCALE: usize = 9;
/// Material word: [`ALPHA_OPAQUE`] or [`ALPHA_MASK`].
pub const M_ALPHA_MODE: usize = 10;
/// Material word: alpha cutoff of [`ALPHA_MASK`].
pub const M_ALPHA_CUTOFF: usize = 11;
/// Material word: 1 when double sided (emits from both faces), else 0.
pub const M_DOUBLE_SIDED: usize = 12;
/// Material word: `KHR_materials_transmission` factor.
pub const M_TRANSMISSION: usize = 13;
/// Material word: `KHR_materials_ior` (1.5 by default).
pub const M_IOR: usize = 14;
/// Material word: base colour texture (sRGB; alpha in A) or [`NONE`].
pub const M_BASE_TEX: usize = 15;
/// Material word: metallic-roughness texture (linear; roughness in G, metallic in B) or [`NONE`].
pub const M_MR_TEX: usize = 16;
/// Material word: tangent-space normal texture (linear) or [`NONE`].
pub const M_NORMAL_TEX: usize = 17;
/// Material word: emissive texture (sRGB) or [`NONE`].
pub const M_EMISSIVE_TEX: usize = 18;
/// Material word: transmission texture (linear; factor in R) or [`NONE`].
pub const M_TRANSMISSION_TEX: usize = 19;
/// Material word: the `KHR_texture_transform` of each texture slot ([`M_BASE_TEX`] ..
/// [`M_TRANSMISSION_TEX`], in that order), 6 words each: the affine map
/// (u', v') = (m0 u + m1 v + m2, m3 u + m4 v + m5) of the extension's offset x rotation x scale.
pub const M_UV_TRANSFORMS: usize = 20;
/// Material word: bit k set when texture slot k ([`M_BASE_TEX`] + k) has a transform other than
/// the identity (else its texture coordinates are used as they are).
pub const M_UV_TRANSFORMED: usize = 50;
/// Alpha mode: opaque (alpha ignored).
pub const ALPHA_OPAQUE: u32 = 0;
/// Alpha mode: a hit is kept only where alpha >= cutoff (glTF `MASK`).
pub const ALPHA_MASK: u32 = 1;

/// Words per texture table entry.
pub const TEXTURE_WORDS: usize = 8;
/// Texture word: offset of the first texel in the texel pool (relative to `H_TEXELS_OFF`).
pub const T_TEXELS: usize = 0;
/// Texture word: width in texels.
pub const T_WIDTH: usize = 1;
/// Texture word: height in texels.
pub const T_HEIGHT: usize = 2;
/// Texture word: wrap mode in s ([`WRAP_REPEAT`], [`WRAP_CLAMP`], [`WRAP_MIRROR`]).
pub const T_WRAP_S: usize = 3;
/// Texture word: wrap mode in t.
pub const T_WRAP_T: usize = 4;
/// Texture word: 1 for nearest magnification (glTF `NEAREST`), 0 for bilinear.
pub const T_NEAREST: usize = 5;
/// Wrap mode: glTF `REPEAT` (10497).
pub const WRAP_REPEAT: u32 = 0;
/// Wrap mode: glTF `CLAMP_TO_EDGE` (33071).
pub const WRAP_CLAMP: u32 = 1;
/// Wrap mode: glTF `MIRRORED_REPEAT` (33648).
pub const WRAP_MIRROR: u32 = 2;

/// Words per light.
pub const LIGHT_WORDS: usize = 16;
/// Light word: [`LIGHT_DIRECTIONAL`], [`LIGHT_POINT`], [`LIGHT_SPOT`] or [`LIGHT_TRIANGLE`].
pub const L_TYPE: usize = 0;
/// Light word: world position of a point or spot light (3 words).
pub const L_POSITION: usize = 1;
/// Light word: unit world direction the light shines towards (directional, spot; 3 words).
pub const L_DIRECTION: usize = 4;
/// Light word: colour times intensity, RGB (3 words): irradiance at normal incidence for a
/// directional light, radiant intensity for point and spot lights (glTF's lux and candela taken
/// as radiometric units), unused for triangles (their material's emission).
pub const L_INTENSITY: usize = 7;
/// Light word: glTF `range` (0 = infinite): beyond it the light contributes nothing.
pub const L_RANGE: usize = 10;
/// Light word: cos of the spot's inner cone angle.
pub const L_COS_INNER: usize = 11;
/// Light word: cos of the spot's outer cone angle.
pub const L_COS_OUTER: usize = 12;
/// Light word: the triangle of a [`LIGHT_TRIANGLE`].
pub const L_TRIANGLE: usize = 13;
/// Light word: the triangle's area (world space) of a [`LIGHT_TRIANGLE`].
pub const L_AREA: usize = 14;
/// Light type: directional (glTF `directional`, a sun).
pub const LIGHT_DIRECTIONAL: u32 = 0;
/// Light type: point.
pub const LIGHT_POINT: u32 = 1;
/// Light type: spot.
pub const LIGHT_SPOT: u32 = 2;
/// Light type: an emissive triangle.
pub const LIGHT_TRIANGLE: u32 = 3;

/// Word `i` of the scene.
#[inline(always)]
pub fn word(scene: &[u32], i: usize) -> u32 {
    load_u32(scene, i)
}

/// Float word `i` of the scene.
#[inline(always)]
pub fn float(scene: &[u32], i: usize) -> f32 {
    f32::from_bits(load_u32(scene, i))
}

/// Three float words starting at `i`.
#[inline(always)]
pub fn vec3(scene: &[u32], i: usize) -> Vec3 {
    Vec3::new(float(scene, i), float(scene, i + 1), float(scene, i + 2))
}

/// Header word `h` (one of the `H_*` constants).
#[inline(always)]
pub fn header(scene: &[u32], h: usize) -> u32 {
    word(scene, h)
}

/// Offset of word `w` of element `i` of the section starting at header word `off_word`.
#[inline(always)]
pub fn element(scene: &[u32], off_word: usize, stride: usize, i: u32, w: usize) -> usize {
    header(scene, off_word) as usize + i as usize * stride + w
}

/// The three vertices of triangle `t` (BVH order).
#[inline]
pub fn triangle(scene: &[u32], t: u32) -> (Vec3, Vec3, Vec3) {
    let o = element(scene, H_TRIS_OFF, TRI_WORDS, t, 0);
    (vec3(scene, o), vec3(scene, o + 3), vec3(scene, o + 6))
}

/// Offset of shading word `w` of triangle `t`.
#[inline(always)]
pub fn shading(scene: &[u32], t: u32, w: usize) -> usize {
    element(scene, H_SHADING_OFF, SHADING_WORDS, t, w)
}

/// Offset of word `w` of material `m`.
#[inline(always)]
pub fn material(scene: &[u32], m: u32, w: usize) -> usize {
    element(scene, H_MATERIALS_OFF, MATERIAL_WORDS, m, w)
}

/// Offset of word `w` of texture `t`.
#[inline(always)]
pub fn texture(scene: &[u32], t: u32, w: usize) -> usize {
    element(scene, H_TEXTURES_OFF, TEXTURE_WORDS, t, w)
}

/// Offset of word `w` of light `l`.
#[inline(always)]
pub fn light(scene: &[u32], l: u32, w: usize) -> usize {
    element(scene, H_LIGHTS_OFF, LIGHT_WORDS, l, w)
}

/// Offset of word `w` of BVH node `n`.
#[inline(always)]
pub fn node(scene: &[u32], n: u32, w: usize) -> usize {
    element(scene, H_NODES_OFF, NODE_WORDS, n, w)
}
