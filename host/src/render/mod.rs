//! `host render` and `host bench render`: the command line and benchmark of the `render` crate
//! (the path tracer driver), with its PNG preview; the scene model is the `scene` crate and the
//! G-buffer export for SSR the `ssr` crate's [`gbuffer`].

pub mod bench;
pub mod cli;

pub use ::render::*;
pub use ::scene::{self, environment};
pub use ::ssr::render_gbuffer as gbuffer;

/// Tone curves of the PNG preview (applied after the exposure scale, before the sRGB encoding).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ToneMap {
    /// Narkowicz 2015's fit of the ACES filmic curve: x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14).
    Aces,
    /// Reinhard 2002: x / (1 + x).
    Reinhard,
    /// No curve: values above 1 clip.
    Clamp,
}

/// The largest `--exposure` in stops either way: 2^64 times the largest f32 still squares
/// within f64 in the tone curve, and beyond it every pixel of any image is black or white.
pub const EXPOSURE_LIMIT: f32 = 64.0;

impl ToneMap {
    /// The curve at `x >= 0`, in [0, 1].
    pub fn apply(self, x: f32) -> f32 {
        self.apply_f64(x as f64) as f32
    }

    /// The curve at `x >= 0` (finite), in [0, 1], in f64 (no overflow for x up to 1e150).
    pub fn apply_f64(self, x: f64) -> f64 {
        let y = match self {
            ToneMap::Aces => (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14),
            ToneMap::Reinhard => x / (1.0 + x),
            ToneMap::Clamp => x,
        };
        y.clamp(0.0, 1.0)
    }
}

/// The 8-bit sRGB preview of linear `rgb` (interleaved): `2^ev` exposure, tone curve, sRGB OETF.
/// Non-finite values show as magenta.
///
/// The exposure scale and the curve are evaluated in f64, so any finite radiance with any
/// exposure within [`EXPOSURE_LIMIT`] stops maps to its tone value: no f32 overflow (a curve
/// of inf / inf) turns a bright pixel black.
pub fn preview(width: u32, height: u32, rgb: &[f32], ev: f32, tone: ToneMap) -> image::RgbImage {
    let scale = 2f64.powf(ev as f64);
    let mut img = image::RgbImage::new(width, height);
    for (i, p) in img.pixels_mut().enumerate() {
        let c = &rgb[3 * i..3 * i + 3];
        if c.iter().any(|v| !v.is_finite()) {
            *p = image::Rgb([255, 0, 255]);
            continue;
        }
        let enc = |v: f32| {
            let t = tone.apply_f64((v as f64 * scale).max(0.0)) as f32;
            let s = if t <= 0.003_130_8 { 12.92 * t } else { 1.055 * t.powf(1.0 / 2.4) - 0.055 };
            (s * 255.0).round().clamp(0.0, 255.0) as u8
        };
        *p = image::Rgb([enc(c[0]), enc(c[1]), enc(c[2])]);
    }
    img
}

