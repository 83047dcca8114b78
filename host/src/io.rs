//! Image files: multi-channel float EXR in and out, and PNG previews.

use anyhow::{anyhow, bail, Context, Result};
use exr::prelude::*;
use std::path::Path;

/// Write one layer of named f32 channels (each `width * height`, row-major, top row first).
pub fn write_exr(path: &Path, width: usize, height: usize, channels: &[(&str, &[f32])]) -> Result<()> {
    let mut list = smallvec::SmallVec::<[AnyChannel<FlatSamples>; 4]>::new();
    for (name, data) in channels {
        if data.len() != width * height {
            bail!("channel {name} has {} values, expected {width}x{height}", data.len());
        }
        list.push(AnyChannel::new(*name, FlatSamples::F32(data.to_vec())));
    }
    let layer = Layer::new(
        (width, height),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(list),
    );
    create_parent_dir(path)?;
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .with_context(|| format!("writing {}", path.display()))
}

/// Create the directory a file is about to be written to.
pub fn create_parent_dir(path: &Path) -> Result<()> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => {
            std::fs::create_dir_all(dir).with_context(|| format!("creating directory {}", dir.display()))
        }
        _ => Ok(()),
    }
}

/// A temporary path in the same directory as `path` (so a rename onto `path` is atomic), for
/// writers that must not leave a half-written file or remove an existing one on failure.
pub fn temp_beside(path: &Path) -> std::path::PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// A float image read from an EXR file: its size and named channels.
#[derive(Debug, Clone)]
pub struct ExrImage {
    pub width: usize,
    pub height: usize,
    pub channels: Vec<(String, Vec<f32>)>,
}

impl ExrImage {
    /// The channel called `name`; the error lists the channels present.
    pub fn channel(&self, name: &str) -> Result<&[f32]> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, d)| d.as_slice())
            .ok_or_else(|| {
                let have: Vec<&str> = self.channels.iter().map(|(n, _)| n.as_str()).collect();
                anyhow!("EXR has no channel {name:?} (channels: {})", have.join(", "))
            })
    }
}

/// Read the first layer of an EXR file, every channel converted to f32.
pub fn read_exr(path: &Path) -> Result<ExrImage> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .with_context(|| format!("reading EXR {}", path.display()))?;
    let layer = image.layer_data;
    let (width, height) = (layer.size.width(), layer.size.height());
    let channels = layer
        .channel_data
        .list
        .into_iter()
        .map(|c| {
            let data: Vec<f32> = c.sample_data.values_as_f32().collect();
            (c.name.to_string(), data)
        })
        .collect();
    Ok(ExrImage { width, height, channels })
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
    create_parent_dir(path)?;
    img.save(path).with_context(|| format!("writing {}", path.display()))
}

/// Tone-map linear HDR RGB (interleaved) to an 8-bit sRGB PNG with exposure `2^ev` and Reinhard.
pub fn write_rgb_preview_png(path: &Path, width: usize, height: usize, rgb: &[f32], ev: f32) -> Result<()> {
    let scale = 2f32.powf(ev);
    let mut img = image::RgbImage::new(width as u32, height as u32);
    for (i, p) in img.pixels_mut().enumerate() {
        let mut px = [0u8; 3];
        for k in 0..3 {
            let v = rgb[3 * i + k] * scale;
            let v = if v.is_finite() { v.max(0.0) } else { 0.0 };
            let t = v / (1.0 + v);
            let s = if t <= 0.003_130_8 { 12.92 * t } else { 1.055 * t.powf(1.0 / 2.4) - 0.055 };
            px[k] = (s * 255.0).round().clamp(0.0, 255.0) as u8;
        }
        *p = image::Rgb(px);
    }
    create_parent_dir(path)?;
    img.save(path).with_context(|| format!("writing {}", path.display()))
}
