//! The shading point of a ray-triangle hit (PBRT-v4 section 6.5 "Triangle meshes",
//! `SurfaceInteraction`; glTF 2.0 section 3.9 "Materials": textures, normal maps, alpha mask).
//!
//! Barycentrics: p = (1 - b1 - b2) v0 + b1 v1 + b2 v2. The geometric normal is
//! normalize((v1 - v0) x (v2 - v0)): counter-clockwise triangles face it (glTF front face).
//! The shading normal is the interpolated vertex normal (the geometric normal where the mesh has
//! none), perturbed by the normal texture where the mesh has tangents, and turned to the
//! geometric normal's side.
//!
//! ```
//! use shader_core::pt::surface::{interpolate, orthonormal_tangent};
//! use shader_core::Vec3;
//! let (a, b, c) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
//! // (b1, b2) weight v1 and v2; v0 gets 1 - b1 - b2.
//! assert_eq!(interpolate(a, b, c, 0.25, 0.5), Vec3::new(0.25, 0.5, 0.0));
//! let n = Vec3::new(0.0, 0.6, 0.8);
//! assert!(orthonormal_tangent(n).dot(n).abs() < 1e-7);
//! ```

use super::scene::{self, float, vec3, word, ALPHA_MASK, M_ALPHA_CUTOFF, M_ALPHA_MODE, M_BASE, M_BASE_TEX, M_DOUBLE_SIDED, M_EMISSIVE, M_EMISSIVE_TEX, M_IOR, M_METALLIC, M_MR_TEX, M_NORMAL_SCALE, M_NORMAL_TEX, M_ROUGHNESS, M_TRANSMISSION, M_TRANSMISSION_TEX, M_UV_TRANSFORMED, M_UV_TRANSFORMS, NONE, SF_NORMALS, SF_TANGENTS, SF_UVS, S_FLAGS, S_LIGHT, S_MATERIAL, S_NORMALS, S_TANGENTS, S_UVS};
use super::texture::{self, Rgba};
use crate::vector::Vec3;

/// Barycentric interpolation of three values.
#[inline]
pub fn interpolate(a: Vec3, b: Vec3, c: Vec3, b1: f32, b2: f32) -> Vec3 {
    a * (1.0 - b1 - b2) + b * b1 + c * b2
}

/// Texture coordinates of triangle `t` at (b1, b2) (zero when the mesh has none).
#[inline]
pub fn uv(sc: &[u32], t: u32, b1: f32, b2: f32) -> (f32, f32) {
    if word(sc, scene::shading(sc, t, S_FLAGS)) & SF_UVS == 0 {
        return (0.0, 0.0);
    }
    let o = scene::shading(sc, t, S_UVS);
    let b0 = 1.0 - b1 - b2;
    let u = float(sc, o) * b0 + float(sc, o + 2) * b1 + float(sc, o + 4) * b2;
    let v = float(sc, o + 1) * b0 + float(sc, o + 3) * b1 + float(sc, o + 5) * b2;
    (u, v)
}

/// (u, v) as texture slot `w` (a `M_*_TEX` word) of material `m` reads them: mapped by the slot's
/// `KHR_texture_transform` (glTF extension spec: uv' = T R S uv, offset x rotation x scale,
/// stored as a 2x3 matrix) where it has one, else unchanged.
#[inline]
pub fn slot_uv(sc: &[u32], m: u32, w: usize, u: f32, v: f32) -> (f32, f32) {
    let slot = (w - M_BASE_TEX) as u32;
    if word(sc, scene::material(sc, m, M_UV_TRANSFORMED)) & (1 << slot) == 0 {
        return (u, v);
    }
    let o = scene::material(sc, m, M_UV_TRANSFORMS + 6 * slot as usize);
    ((float(sc, o) * u + float(sc, o + 1) * v) + float(sc, o + 2), (float(sc, o + 3) * u + float(sc, o + 4) * v) + float(sc, o + 5))
}

/// Material texture `w` (a `M_*_TEX` word) of material `m` at (u, v) (through the slot's texture
/// transform), or `fallback` without one.
#[inline]
fn material_texture(sc: &[u32], m: u32, w: usize, u: f32, v: f32, srgb: bool, fallback: Rgba) -> Rgba {
    let t = word(sc, scene::material(sc, m, w));
    if t == NONE {
        fallback
    } else {
        let (u, v) = slot_uv(sc, m, w, u, v);
        texture::sample(sc, t, u, v, srgb)
    }
}

/// Whether a hit on triangle `t` at (b1, b2) is kept: always, except for a glTF `MASK`
/// material whose alpha (factor x base colour texture) is below its cutoff.
#[inline]
pub fn alpha_passes(sc: &[u32], t: u32, b1: f32, b2: f32) -> bool {
    let m = word(sc, scene::shading(sc, t, S_MATERIAL));
    if word(sc, scene::material(sc, m, M_ALPHA_MODE)) != ALPHA_MASK {
        return true;
    }
    let (u, v) = uv(sc, t, b1, b2);
    let one = Rgba::new(1.0, 1.0, 1.0, 1.0);
    let tex = material_texture(sc, m, M_BASE_TEX, u, v, true, one);
    let alpha = float(sc, scene::material(sc, m, M_BASE + 3)) * tex.a;
    alpha >= float(sc, scene::material(sc, m, M_ALPHA_CUTOFF))
}

/// The material parameters at a shading point, textures applied (glTF metal-rough).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialPoint {
    /// Linear base colour.
    pub base: Vec3,
    /// Metallic in [0, 1] (factor x texture B).
    pub metallic: f32,
    /// Perceptual roughness in [0, 1] (factor x texture G).
    pub roughness: f32,
    /// Emitted radiance (emissive factor x strength x texture).
    pub emission: Vec3,
    /// Transmission factor x texture R.
    pub transmission: f32,
    /// Index of refraction of the transmissive part.
    pub ior: f32,
    /// 1 when it emits from both faces, else 0 (u32: no bool in structs for SPIR-V).
    pub double_sided: u32,
}

/// A shading point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfacePoint {
    /// Position.
    pub p: Vec3,
    /// Unit geometric normal (the triangle's front side).
    pub ng: Vec3,
    /// Unit shading normal, on the side of `ng`.
    pub ns: Vec3,
    /// Unit tangent, orthogonal to `ns`.
    pub ts: Vec3,
    /// Unit bitangent, `ns x ts`.
    pub bs: Vec3,
    /// 1 when the ray arrived at the front face (against `ng`), else 0.
    pub front: u32,
    /// The triangle's emissive-triangle light, or [`NONE`].
    pub light: u32,
    /// Material parameters at the point.
    pub material: MaterialPoint,
}

impl SurfacePoint {
    /// `w` in the local shading frame (normal = +z).
    #[inline]
    pub fn to_local(&self, w: Vec3) -> Vec3 {
        Vec3::new(w.dot(self.ts), w.dot(self.bs), w.dot(self.ns))
    }

    /// A local-frame direction back in world space.
    #[inline]
    pub fn to_world(&self, w: Vec3) -> Vec3 {
        self.ts * w.x + self.bs * w.y + self.ns * w.z
    }
}

/// A unit vector orthogonal to unit `n`: the tangent of `frame::orthonormal_basis` (Duff et al.
/// 2017).
#[inline]
pub fn orthonormal_tangent(n: Vec3) -> Vec3 {
    crate::frame::orthonormal_basis(n).0
}

/// The shading point of triangle `t` hit at (b1, b2) by a ray with direction `d`.
#[inline]
pub fn surface_point(sc: &[u32], t: u32, b1: f32, b2: f32, d: Vec3) -> SurfacePoint {
    let (v0, v1, v2) = scene::triangle(sc, t);
    let p = interpolate(v0, v1, v2, b1, b2);
    let ng = (v1 - v0).cross(v2 - v0).normalize_or_zero();
    let flags = word(sc, scene::shading(sc, t, S_FLAGS));
    let mut ns = ng;
    if flags & SF_NORMALS != 0 {
        let o = scene::shading(sc, t, S_NORMALS);
        let n = interpolate(vec3(sc, o), vec3(sc, o + 3), vec3(sc, o + 6), b1, b2).normalize_or_zero();
        if n.dot(n) > 0.0 {
            ns = n;
        }
    }
    if ns.dot(ng) < 0.0 {
        ns = -ns;
    }
    let (u, v) = uv(sc, t, b1, b2);
    let m = word(sc, scene::shading(sc, t, S_MATERIAL));
    let one = Rgba::new(1.0, 1.0, 1.0, 1.0);

    // Tangent frame: the mesh's tangent (Gram-Schmidt against ns) or an arbitrary one.
    let mut ts = orthonormal_tangent(ns);
    if flags & SF_TANGENTS != 0 {
        let o = scene::shading(sc, t, S_TANGENTS);
        let tv = interpolate(vec3(sc, o), vec3(sc, o + 4), vec3(sc, o + 8), b1, b2);
        let tv = (tv - ns * ns.dot(tv)).normalize_or_zero();
        if tv.dot(tv) > 0.0 {
            ts = tv;
            let tangent_sign = if float(sc, o + 3) < 0.0 { -1.0 } else { 1.0 };
            // Normal map (glTF 3.9.3): n = normalize((2 c - 1) * (scale, scale, 1)) in (T, B, N).
            let nt = word(sc, scene::material(sc, m, M_NORMAL_TEX));
            if nt != NONE && flags & SF_UVS != 0 {
                let (nu, nv) = slot_uv(sc, m, M_NORMAL_TEX, u, v);
                let c = texture::sample(sc, nt, nu, nv, false);
                let scale = float(sc, scene::material(sc, m, M_NORMAL_SCALE));
                let (x, y, z) = ((2.0 * c.r - 1.0) * scale, (2.0 * c.g - 1.0) * scale, 2.0 * c.b - 1.0);
                let bt = ns.cross(ts) * tangent_sign;
                let n = (ts * x + bt * y + ns * z).normalize_or_zero();
                if n.dot(ng) > 0.0 {
                    ns = n;
                    ts = (ts - ns * ns.dot(ts)).normalize_or_zero();
                    if !(ts.dot(ts) > 0.0) {
                        ts = orthonormal_tangent(ns);
                    }
                }
            }
        }
    }
    let bs = ns.cross(ts);

    let base_tex = material_texture(sc, m, M_BASE_TEX, u, v, true, one);
    let mr_tex = material_texture(sc, m, M_MR_TEX, u, v, false, one);
    let em_tex = material_texture(sc, m, M_EMISSIVE_TEX, u, v, true, one);
    let tr_tex = material_texture(sc, m, M_TRANSMISSION_TEX, u, v, false, one);
    let base = Vec3::new(base_tex.r, base_tex.g, base_tex.b).mul_elem(vec3(sc, scene::material(sc, m, M_BASE)));
    let emission = Vec3::new(em_tex.r, em_tex.g, em_tex.b).mul_elem(vec3(sc, scene::material(sc, m, M_EMISSIVE)));
    let material = MaterialPoint {
        base,
        metallic: float(sc, scene::material(sc, m, M_METALLIC)) * mr_tex.b,
        roughness: float(sc, scene::material(sc, m, M_ROUGHNESS)) * mr_tex.g,
        emission,
        transmission: float(sc, scene::material(sc, m, M_TRANSMISSION)) * tr_tex.r,
        ior: float(sc, scene::material(sc, m, M_IOR)),
        double_sided: if word(sc, scene::material(sc, m, M_DOUBLE_SIDED)) != 0 { 1 } else { 0 },
    };
    SurfacePoint {
        p,
        ng,
        ns,
        ts,
        bs,
        front: if d.dot(ng) < 0.0 { 1 } else { 0 },
        light: word(sc, scene::shading(sc, t, S_LIGHT)),
        material,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orthonormal_tangent_is_unit_and_orthogonal() {
        for &(x, y, z) in &[(0.0f32, 0.0, 1.0), (0.0, 0.0, -1.0), (0.6, 0.0, 0.8), (0.48, -0.6, -0.64), (1.0, 0.0, 0.0)] {
            let n = Vec3::new(x, y, z);
            let t = orthonormal_tangent(n);
            assert!(t.dot(n).abs() < 1e-6, "{n:?}");
            assert!((t.length() - 1.0).abs() < 1e-6, "{n:?}");
        }
    }
}
