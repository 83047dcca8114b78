//! The CLI's image outputs: PNG previews, heat maps and the colour ramp; the float EXR and
//! atomic-write layer is the `fileio` crate, re-exported here.

use anyhow::Result;
use std::path::Path;

pub use fileio::*;

/// Save an RGB image as PNG atomically ([`write_atomic`]).
pub fn write_png(path: &Path, img: &image::RgbImage) -> Result<()> {
    write_atomic(path, |tmp| img.save_with_format(tmp, image::ImageFormat::Png).map_err(anyhow::Error::from))
}

/// A perceptually ordered colour ramp (dark blue -> teal -> yellow) for t in [0, 1].
pub fn colormap(t: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [0.267, 0.005, 0.329],
        [0.229, 0.322, 0.546],
        [0.128, 0.567, 0.551],
        [0.369, 0.789, 0.383],
        [0.993, 0.906, 0.144],
    ];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * 4.0;
    let i = (x as usize).min(3);
    let f = x - i as f32;
    let c = |k: usize| ((STOPS[i][k] + (STOPS[i + 1][k] - STOPS[i][k]) * f) * 255.0).round() as u8;
    [c(0), c(1), c(2)]
}

/// Write a false-colour PNG of `data` mapped linearly from [lo, hi]; non-finite values are magenta.
pub fn write_heatmap_png(path: &Path, width: usize, height: usize, data: &[f32], lo: f32, hi: f32) -> Result<()> {
    let mut img = image::RgbImage::new(width as u32, height as u32);
    for (i, p) in img.pixels_mut().enumerate() {
        let v = data[i];
        *p = if v.is_finite() { image::Rgb(colormap((v - lo) / (hi - lo))) } else { image::Rgb([255, 0, 255]) };
    }
    write_png(path, &img)
}

/// Tone-map linear HDR RGB (interleaved) to an 8-bit sRGB PNG with exposure `2^ev` and Reinhard
/// ([`crate::render::preview`], the one preview encoder; non-finite pixels are magenta).
pub fn write_rgb_preview_png(path: &Path, width: usize, height: usize, rgb: &[f32], ev: f32) -> Result<()> {
    write_png(path, &crate::render::preview(width as u32, height as u32, rgb, ev, crate::render::ToneMap::Reinhard))
}
