//! The layouts of the buffers the SSR passes share (G-buffer texels, ray and hit records, output
//! and colour texels), and the G-buffer texel decoded ([`Surface`]).

use crate::vector::Vec3;

/// Floats per G-buffer texel ([`GBufferTexel`]): depth, normal (world) x y z, perceptual
/// roughness, metalness, motion x y (UV units).
pub const GBUF_STRIDE: usize = 8;

/// Word offsets of a [`GBufferTexel`]'s fields (depth is word 0): the passes read the fields
/// they need one by one.
pub mod gbuf {
    /// World normal x y z.
    pub const NORMAL: usize = 1;
    /// Perceptual roughness.
    pub const ROUGHNESS: usize = 4;
    /// Metalness.
    pub const METALNESS: usize = 5;
    /// Motion x y (UV units).
    pub const MOTION: usize = 6;
}

/// One G-buffer texel as the SSR passes read it ([`GBUF_STRIDE`] words at the offsets of
/// [`gbuf`]): written by the host (`ssr::GBuffer::packed`) through [`GBufferTexel::store`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GBufferTexel {
    /// Linear view depth (+inf for the sky).
    pub depth: f32,
    /// World normal.
    pub normal: Vec3,
    /// Perceptual roughness.
    pub roughness: f32,
    /// Metalness.
    pub metalness: f32,
    /// Motion vector (UV units): this frame's UV minus the previous frame's.
    pub motion: [f32; 2],
}

impl GBufferTexel {
    /// Write the texel at `buf[o..o + GBUF_STRIDE]`.
    #[inline]
    pub fn store(&self, buf: &mut [f32], o: usize) {
        use crate::buffer::{store, store_vec3};
        store(buf, o, self.depth);
        store_vec3(buf, o + gbuf::NORMAL, self.normal);
        store(buf, o + gbuf::ROUGHNESS, self.roughness);
        store(buf, o + gbuf::METALNESS, self.metalness);
        store(buf, o + gbuf::MOTION, self.motion[0]);
        store(buf, o + gbuf::MOTION + 1, self.motion[1]);
    }

    /// The texel at `buf[o..o + GBUF_STRIDE]`.
    #[inline]
    pub fn load(buf: &[f32], o: usize) -> GBufferTexel {
        use crate::buffer::{load, load_vec3};
        GBufferTexel {
            depth: load(buf, o),
            normal: load_vec3(buf, o + gbuf::NORMAL),
            roughness: load(buf, o + gbuf::ROUGHNESS),
            metalness: load(buf, o + gbuf::METALNESS),
            motion: [load(buf, o + gbuf::MOTION), load(buf, o + gbuf::MOTION + 1)],
        }
    }
}

/// A shaded pixel of the G-buffer in view space.
#[derive(Clone, Copy, Debug, Default)]
pub struct Surface {
    /// False for sky, invalid depth or normal, back-facing normals and pixels rougher than the cut-off.
    pub valid: bool,
    /// View-space position of the pixel's surface.
    pub pos: Vec3,
    /// Unit normal (view space).
    pub n: Vec3,
    /// Unit direction to the eye (view space).
    pub v: Vec3,
    /// Perceptual roughness of the surface, in [0, 1].
    pub perceptual_roughness: f32,
    /// Screen position of the pixel centre and its device depth.
    pub origin: Vec3,
}

/// Floats per ray record: hit x, hit y (pixel centre, screen units; -1 on a miss), hit device
/// depth, info bits (see [`info`]), ray pdf (solid angle; 0 for mirror rays), ray direction
/// (view space) x y z.
pub const RAY_STRIDE: usize = 8;
/// Offset of the info bits in a ray record.
pub const RAY_INFO: usize = 3;
/// Offset of the pdf in a ray record (the direction x y z follows it).
pub const RAY_PDF: usize = 4;

/// Packing of the info word of a ray record.
pub mod info {
    /// A ray was traced for this record.
    pub const VALID: u32 = 1;
    /// It found a hit (after validation).
    pub const HIT: u32 = 2;
    /// The hit was rejected by validation (back face or self hit).
    pub const REJECTED: u32 = 4;
    /// Steps (tracer iterations) are stored from this bit up.
    pub const STEPS_SHIFT: u32 = 8;
}

/// Floats per hit record (written by [`super::hits`], one per ray slot, in the ray records'
/// order): hit position (view space) x y z, the generating pixel's density at the direction to
/// it ([`HIT_PDF`]), previous-frame u v of the hit ([`HIT_UV`]), its edge-of-screen fade
/// ([`HIT_FADE`]), the filtered-importance-sampling cone's half-angle tangent ([`HIT_TAN_HALF`])
/// and the colour pyramid's sample at (u, v), r g b ([`HIT_COLOR`], where
/// [`hit_colors_stored`](super::resolve::hit_colors_stored): at mip 0, or with
/// [`FLAG_RAY_COLOR`](super::params::FLAG_RAY_COLOR) at the ray's own footprint). Only slots
/// whose ray hit are written, their UV and cone only where a resolve reads them
/// ([`hit_footprints_stored`](super::resolve::hit_footprints_stored)); the rest stay zero.
pub const HIT_STRIDE: usize = 11;
/// Offset of the pdf in a hit record (after the position).
pub const HIT_PDF: usize = 3;
/// Offset of the previous-frame (u, v) in a hit record.
pub const HIT_UV: usize = 4;
/// Offset of the edge-of-screen fade in a hit record.
pub const HIT_FADE: usize = 6;
/// Offset of the cone's half-angle tangent in a hit record.
pub const HIT_TAN_HALF: usize = 7;
/// Offset of the colour (r, g, b) in a hit record: [`sample_color`](super::resolve::sample_color)
/// at (u, v), at mip 0 or, with [`FLAG_RAY_COLOR`](super::params::FLAG_RAY_COLOR), at the mip of
/// the ray's footprint seen from its own pixel.
pub const HIT_COLOR: usize = 8;

/// Floats per output texel of a resolve: r, g, b (premultiplied), opacity.
pub const OUT_STRIDE: usize = 4;
/// Floats per colour texel: r, g, b.
pub const COLOR_STRIDE: usize = 3;
