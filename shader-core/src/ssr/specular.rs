//! The specular term of a reflection: the resolved, BRDF-normalized reflection times the
//! preintegrated FG term (Stachowiak 2015, "ratio estimator ... x preintegrated FG"; Karis 2013
//! split sum), FG = E''(n.v, r) = f0 (E - E') + f90 E' from the energy tables (`crate::energy`,
//! Filament section 5.3.4.3), with the glTF metal-rough f0 = mix(0.04, base colour, metalness).
//!
//! ```
//! use shader_core::ssr::specular::metal_rough_f0;
//! // glTF: a dielectric reflects 4 % at normal incidence, a metal its base colour.
//! assert_eq!(metal_rough_f0(0.9, 0.0), 0.04);
//! assert_eq!(metal_rough_f0(0.9, 1.0), 0.9);
//! ```

use super::layout::GBUF_STRIDE;
use super::params::SsrParams;
use super::trace::load_surface;
use crate::buffer::{load, load4, store};
use crate::energy::{lut_e_and_e_prime, schlick_albedo, DIELECTRIC_F0};
use crate::vector::Vec3;

/// Values per pixel of the specular output: premultiplied RGB and the reflection's opacity.
pub const SPECULAR_STRIDE: usize = 4;

/// glTF metal-rough f0 of one channel: 0.04 + (base - 0.04) metalness.
#[inline]
pub fn metal_rough_f0(base: f32, metalness: f32) -> f32 {
    DIELECTRIC_F0 + (base - DIELECTRIC_F0) * metalness
}

/// The FG term of pixel (x, y) per channel (f90 = 1): E''(n.v, r) with f0 from base colour and
/// metalness. 0 where the pixel has no valid surface (sky, back-facing, rougher than the fade end).
pub fn fg_pixel(p: &SsrParams, gbuf: &[f32], base_color: &[f32], lut: &[f32], x: u32, y: u32) -> Vec3 {
    let s = load_surface(p, gbuf, x, y);
    if !s.valid {
        return Vec3::ZERO;
    }
    let i = (y * p.width + x) as usize;
    let metalness = load(gbuf, i * GBUF_STRIDE + super::layout::gbuf::METALNESS);
    let mu = s.n.dot(s.v);
    let (e, ep) = lut_e_and_e_prime(lut, mu, s.perceptual_roughness);
    // A dielectric's f0 is 0.04 whatever its base colour (0.04 + (base - 0.04) * 0 for a finite
    // base), so its base colour is not read.
    let f0 = if metalness == 0.0 {
        Vec3::new(DIELECTRIC_F0, DIELECTRIC_F0, DIELECTRIC_F0)
    } else {
        let b = i * 3;
        Vec3::new(
            metal_rough_f0(load(base_color, b), metalness),
            metal_rough_f0(load(base_color, b + 1), metalness),
            metal_rough_f0(load(base_color, b + 2), metalness),
        )
    };
    Vec3::new(schlick_albedo(e, ep, f0.x, 1.0), schlick_albedo(e, ep, f0.y, 1.0), schlick_albedo(e, ep, f0.z, 1.0))
}

/// The specular pass for pixel (x, y): the reflection (premultiplied RGB, opacity; 4 values per
/// pixel) with its RGB multiplied by [`fg_pixel`]; the opacity is kept. Where the reflection's
/// RGB is zero (no ray hit, or a black hit) it is written as it is, without reading the surface
/// or the LUT: FG is finite and >= +0, so the product would be that zero, sign included.
#[allow(clippy::too_many_arguments)]
pub fn specular_pixel(p: &SsrParams, gbuf: &[f32], base_color: &[f32], lut: &[f32], reflection: &[f32], x: u32, y: u32, out: &mut [f32], ob: usize) {
    let [r, g, b, a] = load4(reflection, ((y * p.width + x) as usize) * 4);
    let fg = if r == 0.0 && g == 0.0 && b == 0.0 { Vec3::new(1.0, 1.0, 1.0) } else { fg_pixel(p, gbuf, base_color, lut, x, y) };
    store(out, ob, r * fg.x);
    store(out, ob + 1, g * fg.y);
    store(out, ob + 2, b * fg.z);
    store(out, ob + 3, a);
}
