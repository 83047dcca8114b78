//! Texture sampling as glTF 2.0 defines it (section 3.8.4 "Samplers"; sRGB decode of IEC
//! 61966-2-1): wrap modes `REPEAT` / `CLAMP_TO_EDGE` / `MIRRORED_REPEAT`, bilinear or nearest
//! filtering of RGBA8 texels, colour textures decoded from sRGB per texel before filtering.
//!
//! Texture coordinates follow glTF: (0, 0) is the top-left corner of the image, v grows
//! downwards. Texel centres are at (i + 1/2) / width. A NaN or infinite coordinate reads the
//! texel at 0. There is no mip-mapping.

use super::scene::{self, float, word, H_SRGB_OFF, H_TEXELS_OFF, T_HEIGHT, T_NEAREST, T_TEXELS, T_WIDTH, T_WRAP_S, T_WRAP_T, WRAP_CLAMP, WRAP_MIRROR};
use crate::math;

/// An RGBA value, linear.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rgba {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
    /// Alpha (coverage).
    pub a: f32,
}

impl Rgba {
    /// The four components.
    #[inline]
    pub const fn new(r: f32, g: f32, b: f32, a: f32) -> Rgba {
        Rgba { r, g, b, a }
    }

    #[inline]
    fn scaled_add(self, o: Rgba, w: f32) -> Rgba {
        Rgba::new(self.r + o.r * w, self.g + o.g * w, self.b + o.b * w, self.a + o.a * w)
    }
}

/// The linear value of an sRGB-encoded component `c` in [0, 1] (IEC 61966-2-1):
/// `c / 12.92` up to 0.04045, else `((c + 0.055) / 1.055)^2.4`.
///
/// ```
/// use shader_core::pt::texture::srgb_to_linear;
/// assert_eq!(srgb_to_linear(0.0), 0.0);
/// assert_eq!(srgb_to_linear(1.0), 1.0);
/// assert!((srgb_to_linear(0.5) - 0.21404).abs() < 1e-5);
/// ```
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        crate::ieee::div(c, 12.92)
    } else {
        math::pow(crate::ieee::div(c + 0.055, 1.055), 2.4)
    }
}

/// Texel coordinate in [0, n) of integer position `i` under wrap mode `wrap`.
#[inline]
pub fn wrap_index(i: i32, n: u32, wrap: u32) -> u32 {
    let n = n as i32;
    let r = if wrap == WRAP_CLAMP {
        if i < 0 {
            0
        } else if i >= n {
            n - 1
        } else {
            i
        }
    } else if wrap == WRAP_MIRROR {
        let p = 2 * n;
        let m = ((i % p) + p) % p;
        if m >= n {
            p - 1 - m
        } else {
            m
        }
    } else {
        ((i % n) + n) % n
    };
    r as u32
}

/// `u` reduced to the range the wrap mode repeats ([0, 1) repeat, [0, 2) mirror, [0, 1]
/// clamp), so texel positions stay small integers; non-finite `u` becomes 0.
#[inline]
fn reduce(u: f32, wrap: u32) -> f32 {
    if !math::is_finite(u) {
        return 0.0;
    }
    if wrap == WRAP_CLAMP {
        math::clamp(u, 0.0, 1.0)
    } else if wrap == WRAP_MIRROR {
        u - 2.0 * math::floor(u * 0.5)
    } else {
        u - math::floor(u)
    }
}

/// Channel `k` (0 = R) of packed RGBA8 texel `v` as a float: through the sRGB table at `table`
/// when `srgb`, else k / 255.
#[inline]
fn channel(sc: &[u32], table: usize, v: u32, k: u32, srgb: bool) -> f32 {
    let byte = (v >> (8 * k)) & 255;
    if srgb {
        float(sc, table + byte as usize)
    } else {
        (byte as f32) * INV_255
    }
}

/// 1 / 255 rounded once by the compiler (a constant, so no division reaches the SPIR-V).
const INV_255: f32 = 1.0 / 255.0;

/// Texel (x, y) of texture `t`, decoded (`srgb`: colour channels through the sRGB table).
#[inline]
fn texel(sc: &[u32], t: u32, x: u32, y: u32, srgb: bool) -> Rgba {
    let w = word(sc, scene::texture(sc, t, T_WIDTH));
    let base = scene::header(sc, H_TEXELS_OFF) as usize + word(sc, scene::texture(sc, t, T_TEXELS)) as usize;
    let v = word(sc, base + (y as usize) * (w as usize) + x as usize);
    let table = scene::header(sc, H_SRGB_OFF) as usize;
    Rgba::new(channel(sc, table, v, 0, srgb), channel(sc, table, v, 1, srgb), channel(sc, table, v, 2, srgb), channel(sc, table, v, 3, false))
}

/// Texture `t` at glTF coordinates (u, v): bilinear (or nearest, per the texture's sampler) with
/// its wrap modes; `srgb` decodes the colour channels (base colour and emissive textures).
#[inline]
pub fn sample(sc: &[u32], t: u32, u: f32, v: f32, srgb: bool) -> Rgba {
    let w = word(sc, scene::texture(sc, t, T_WIDTH));
    let h = word(sc, scene::texture(sc, t, T_HEIGHT));
    let ws = word(sc, scene::texture(sc, t, T_WRAP_S));
    let wt = word(sc, scene::texture(sc, t, T_WRAP_T));
    let x = reduce(u, ws) * (w as f32) - 0.5;
    let y = reduce(v, wt) * (h as f32) - 0.5;
    if word(sc, scene::texture(sc, t, T_NEAREST)) != 0 {
        let xi = math::floor(x + 0.5) as i32;
        let yi = math::floor(y + 0.5) as i32;
        return texel(sc, t, wrap_index(xi, w, ws), wrap_index(yi, h, wt), srgb);
    }
    let (x0, y0) = (math::floor(x), math::floor(y));
    let (fx, fy) = (x - x0, y - y0);
    let (xi, yi) = (x0 as i32, y0 as i32);
    let (xa, xb) = (wrap_index(xi, w, ws), wrap_index(xi + 1, w, ws));
    let (ya, yb) = (wrap_index(yi, h, wt), wrap_index(yi + 1, h, wt));
    let zero = Rgba::default();
    let s = zero.scaled_add(texel(sc, t, xa, ya, srgb), (1.0 - fx) * (1.0 - fy));
    let s = s.scaled_add(texel(sc, t, xb, ya, srgb), fx * (1.0 - fy));
    let s = s.scaled_add(texel(sc, t, xa, yb, srgb), (1.0 - fx) * fy);
    s.scaled_add(texel(sc, t, xb, yb, srgb), fx * fy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pt::scene::WRAP_REPEAT;

    #[test]
    fn wrap_modes_follow_gltf() {
        let r: [u32; 7] = core::array::from_fn(|k| wrap_index(k as i32 - 3, 3, WRAP_REPEAT));
        assert_eq!(r, [0, 1, 2, 0, 1, 2, 0]);
        let c: [u32; 7] = core::array::from_fn(|k| wrap_index(k as i32 - 3, 3, WRAP_CLAMP));
        assert_eq!(c, [0, 0, 0, 0, 1, 2, 2]);
        let m: [u32; 9] = core::array::from_fn(|k| wrap_index(k as i32 - 3, 3, WRAP_MIRROR));
        assert_eq!(m, [2, 1, 0, 0, 1, 2, 2, 1, 0]);
    }

    #[test]
    fn srgb_is_continuous_at_the_knee_and_monotonic() {
        let mut prev = -1.0;
        for i in 0..=255 {
            let l = srgb_to_linear(i as f32 / 255.0);
            assert!(l > prev, "{i}");
            prev = l;
        }
        let a = 0.04045f32 / 12.92;
        let b = math::pow((0.04045f32 + 0.055) / 1.055, 2.4);
        assert!((a - b).abs() < 1e-6);
    }
}
