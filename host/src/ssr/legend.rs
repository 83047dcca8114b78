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
    /// Tick marks with values along the image's edges (maps of a function over two
    /// parameters), if any.
    pub axes: Option<Axes>,
}

/// The ticks of a map's two axes: each tick is (position across the image in [0, 1], from the
/// left or the top edge, 1 = the far edge; its label).
#[derive(Clone, Debug, Default)]
pub struct Axes {
    pub x: Vec<(f32, String)>,
    pub y: Vec<(f32, String)>,
}

impl Axes {
    /// Ticks at the centres of `count` cells spread evenly over `0..n` (the first and the last
    /// included), each labelled with `value(cell)`: the parameter the map was evaluated at there.
    pub fn cells(n: usize, count: usize, value: impl Fn(usize) -> f64) -> Vec<(f32, String)> {
        let count = count.clamp(1, n.max(1));
        let mut cells: Vec<usize> = (0..count).map(|k| if count == 1 { 0 } else { (k * (n - 1) + (count - 1) / 2) / (count - 1) }).collect();
        cells.dedup();
        cells.into_iter().map(|c| ((c as f32 + 0.5) / n as f32, label(value(c) as f32))).collect()
    }
}

/// Where [`render`] puts things: the enlargement `k`, the image's top-left corner (`left`, 0)
/// and size (`k w` x `k h`), and the whole picture's size (image, axes, legend strip).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    pub k: usize,
    pub left: usize,
    pub image_w: usize,
    pub image_h: usize,
    pub width: usize,
    pub height: usize,
}

/// The [`Layout`] of a `w` x `h` image, with or without axes: axes add a left margin for the y
/// labels, a bottom margin for the x labels and a right margin for the last x label.
pub fn layout(w: usize, h: usize, axes: bool) -> Layout {
    let k = scale(w);
    let (image_w, image_h) = (w * k, h * k);
    let fs = font_size(image_w) as usize;
    let (left, right, bottom) = if axes { (fs * 4, fs * 2, fs * 2) } else { (0, 0, 0) };
    let width = left + image_w + right;
    Layout { k, left, image_w, image_h, width, height: image_h + bottom + strip_height(width) }
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

/// Render `pixels` (w x h RGB, row-major) with `legend` below: an RGB buffer of the size
/// [`layout`] gives: the image enlarged k = [`scale`]`(w)` times (each pixel a k x k block), so
/// that it spans the legend's width, with its axes' ticks and labels when the legend has axes.
pub fn render(w: usize, h: usize, pixels: &[[u8; 3]], legend: &Legend) -> Result<(usize, usize, Vec<u8>)> {
    anyhow::ensure!(pixels.len() == w * h, "debug image has {} pixels, expected {}", pixels.len(), w * h);
    register_font();
    let l = layout(w, h, legend.axes.is_some());
    let (k, tw, th) = (l.k, l.width, l.height);
    let mut buf = vec![255u8; tw * th * 3];
    for y in 0..l.image_h {
        for x in 0..l.image_w {
            let c = pixels[(y / k) * w + x / k];
            let o = (y * tw + l.left + x) * 3;
            buf[o..o + 3].copy_from_slice(&c);
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut buf, (tw as u32, th as u32)).into_drawing_area();
        let fs = font_size(l.image_w) as i32;
        let text = |p: Pos| ("ssr-legend", fs as u32).into_font().color(&BLACK).pos(p);
        let left = Pos::new(HPos::Left, VPos::Top);
        if let Some(axes) = &legend.axes {
            let (x0, iw, ih) = (l.left as i32, l.image_w as i32, l.image_h as i32);
            root.draw(&Rectangle::new([(x0 - 1, -1), (x0 + iw, ih)], BLACK)).map_err(err)?;
            for (t, s) in &axes.x {
                let px = x0 + ((t.clamp(0.0, 1.0) * iw as f32) as i32).min(iw - 1);
                root.draw(&PathElement::new(vec![(px, ih), (px, ih + fs / 3)], BLACK)).map_err(err)?;
                root.draw(&Text::new(s.clone(), (px, ih + fs / 3 + 1), text(Pos::new(HPos::Center, VPos::Top)))).map_err(err)?;
            }
            for (t, s) in &axes.y {
                let py = ((t.clamp(0.0, 1.0) * ih as f32) as i32).min(ih - 1);
                root.draw(&PathElement::new(vec![(x0 - fs / 3, py), (x0 - 1, py)], BLACK)).map_err(err)?;
                // the label centred on its tick, kept inside the picture at the top edge
                root.draw(&Text::new(s.clone(), (x0 - fs / 3 - 2, py.max(fs / 2 + 1)), text(Pos::new(HPos::Right, VPos::Center)))).map_err(err)?;
            }
        }
        let top = (th - strip_height(tw)) as i32;
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
