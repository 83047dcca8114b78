//! Debug images of `host ssr` that read without the docs: the false-colour image with a legend
//! strip below it (title, a colour bar with its values on a fixed scale, and one swatch per
//! special value or class).

use crate::io::{colormap, write_atomic};
use anyhow::{anyhow, Result};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Colour of pixels a debug view has no value for (no ray traced, not measured).
pub const NO_VALUE: [u8; 3] = [70, 70, 70];
/// Colour of non-finite values.
pub const NON_FINITE: [u8; 3] = [255, 0, 255];

/// The legend of a debug image.
#[derive(Clone, Debug)]
pub struct Legend {
    pub title: String,
    /// A colour bar from `lo` to `hi` (the [`colormap`] ramp) with these tick values, if any.
    pub bar: Option<(f32, f32, Vec<f32>)>,
    /// Swatches (colour, label): special values and, for classified images, one per class.
    pub swatches: Vec<([u8; 3], String)>,
}

/// The ramp colour of `v` on the scale [lo, hi] (clamped; non-finite values magenta).
pub fn ramp(v: f32, lo: f32, hi: f32) -> [u8; 3] {
    if v.is_finite() {
        colormap((v - lo) / (hi - lo))
    } else {
        NON_FINITE
    }
}

/// Width of the image with its legend: at least `MIN_WIDTH` so the labels fit.
pub const MIN_WIDTH: usize = 480;

/// Font size of the legend for an image `w` pixels wide.
fn font_size(w: usize) -> u32 {
    (w / 70).clamp(13, 28) as u32
}

/// Height of the legend strip for an image `w` pixels wide.
pub fn strip_height(w: usize) -> usize {
    font_size(w) as usize * 5
}

/// Make the legend's font ("ssr-legend", DejaVu Sans, embedded) available to plotters.
pub fn register_font() {
    static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("ssr-legend", FontStyle::Normal, FONT);
    });
}

fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("drawing the legend: {e}")
}

/// A tick label: integers without decimals, others with up to 3 significant decimals.
fn label(v: f32) -> String {
    if v == v.round() && v.abs() < 1e6 {
        format!("{}", v as i64)
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// The integer factor an image `w` pixels wide is enlarged by (nearest neighbour) so that it is
/// at least [`MIN_WIDTH`] wide and fills the legend's width: 1 from `MIN_WIDTH` up.
pub fn scale(w: usize) -> usize {
    MIN_WIDTH.div_ceil(w.max(1))
}

/// Render `pixels` (w x h RGB, row-major) with `legend` below: an RGB buffer of
/// (k w) x (k h + [`strip_height`]`(k w)`), k = [`scale`]`(w)`: the image enlarged k times
/// (each pixel a k x k block), so that it spans the legend's whole width.
pub fn render(w: usize, h: usize, pixels: &[[u8; 3]], legend: &Legend) -> Result<(usize, usize, Vec<u8>)> {
    anyhow::ensure!(pixels.len() == w * h, "debug image has {} pixels, expected {}", pixels.len(), w * h);
    register_font();
    let k = scale(w);
    let (tw, ih) = (w * k, h * k);
    let sh = strip_height(tw);
    let th = ih + sh;
    let mut buf = vec![255u8; tw * th * 3];
    for y in 0..ih {
        for x in 0..tw {
            let c = pixels[(y / k) * w + x / k];
            buf[(y * tw + x) * 3..(y * tw + x) * 3 + 3].copy_from_slice(&c);
        }
    }
    let h = ih;
    {
        let root = BitMapBackend::with_buffer(&mut buf, (tw as u32, th as u32)).into_drawing_area();
        let fs = font_size(tw) as i32;
        let text = |p: Pos| ("ssr-legend", fs as u32).into_font().color(&BLACK).pos(p);
        let top = h as i32;
        let left = Pos::new(HPos::Left, VPos::Top);
        root.draw(&Text::new(legend.title.clone(), (8, top + fs / 3), text(left))).map_err(err)?;
        // Row of swatches and the bar.
        let row = top + fs * 3 / 2 + fs / 3;
        let mut x = 8;
        for (c, l) in &legend.swatches {
            root.draw(&Rectangle::new([(x, row), (x + fs, row + fs)], RGBColor(c[0], c[1], c[2]).filled())).map_err(err)?;
            root.draw(&Rectangle::new([(x - 1, row - 1), (x + fs + 1, row + fs + 1)], BLACK)).map_err(err)?;
            root.draw(&Text::new(l.clone(), (x + fs + 4, row), text(left))).map_err(err)?;
            x += fs + 4 + (l.chars().count() as i32 * fs * 6 / 10) + fs;
        }
        if let Some((lo, hi, ticks)) = &legend.bar {
            let x0 = x + fs;
            let x1 = tw as i32 - 2 * fs;
            if x1 > x0 + 10 {
                for px in x0..=x1 {
                    let t = (px - x0) as f32 / (x1 - x0) as f32;
                    let c = colormap(t);
                    root.draw(&PathElement::new(vec![(px, row), (px, row + fs)], RGBColor(c[0], c[1], c[2]))).map_err(err)?;
                }
                // Outline outside the bar, so its end colours stay visible.
                root.draw(&Rectangle::new([(x0 - 1, row - 1), (x1 + 1, row + fs + 1)], BLACK)).map_err(err)?;
                for &v in ticks {
                    let t = ((v - lo) / (hi - lo)).clamp(0.0, 1.0);
                    let px = x0 + (t * (x1 - x0) as f32).round() as i32;
                    root.draw(&PathElement::new(vec![(px, row + fs), (px, row + fs + fs / 3)], BLACK)).map_err(err)?;
                    root.draw(&Text::new(label(v), (px, row + fs + fs / 3 + 1), text(Pos::new(HPos::Center, VPos::Top)))).map_err(err)?;
                }
            }
        }
        root.present().map_err(err)?;
    }
    Ok((tw, th, buf))
}

/// [`render`] and write it as PNG (atomically).
pub fn write_png(path: &Path, w: usize, h: usize, pixels: &[[u8; 3]], legend: &Legend) -> Result<()> {
    let (tw, th, buf) = render(w, h, pixels, legend)?;
    write_atomic(path, |tmp| {
        image::save_buffer_with_format(tmp, &buf, tw as u32, th as u32, image::ColorType::Rgb8, image::ImageFormat::Png).map_err(anyhow::Error::from)
    })
}

/// Evenly spaced ticks lo, lo + (hi - lo)/n, ..., hi.
pub fn ticks(lo: f32, hi: f32, n: u32) -> Vec<f32> {
    (0..=n).map(|k| lo + (hi - lo) * k as f32 / n as f32).collect()
}
