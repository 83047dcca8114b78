//! Image files the scenes read: glTF textures (PNG, JPEG; glTF 2.0 section 3.9.2) as 8-bit RGBA,
//! and environment maps (Radiance RGBE, Ward 1991 "Real Pixels", PNG, JPEG) as linear RGB f32.
//!
//! Decoding follows the `image` crate's conventions (which the CLI tests check bit for bit):
//! PNG palettes, transparency chunks and sub-8-bit samples are expanded, 16-bit samples
//! become 8-bit as `round(v * 255 / 65535)` or float as `v / 65535`, 8-bit samples become
//! float as `v / 255`; grey replicates into R, G and B; a missing alpha is 255.

use anyhow::{anyhow, bail, Context, Result};
use std::io::Cursor;
use std::path::Path;

/// A decoded 8-bit RGBA image, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Rgba8 {
    pub width: u32,
    pub height: u32,
    /// `4 * width * height` bytes.
    pub rgba: Vec<u8>,
}

/// Samples of a decoded image before the conversion to RGBA8 or RGB f32.
#[derive(Debug)]
struct Decoded {
    width: u32,
    height: u32,
    /// Channels per pixel: 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA.
    channels: usize,
    samples: Samples,
}

#[derive(Debug)]
enum Samples {
    U8(Vec<u8>),
    U16(Vec<u16>),
    F32(Vec<f32>),
}

const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

/// The largest image side read (textures and environment maps), checked on the size a file
/// declares before anything is allocated: 16384, the largest 2D image every desktop Vulkan driver
/// takes.
pub const MAX_SIDE: u32 = 16384;
/// The most pixels an image may have: 2^27, a 16384 x 8192 environment map (1.5 GiB as RGB f32).
pub const MAX_PIXELS: u64 = 1 << 27;

/// The size a file declares, refused when empty or over [`MAX_SIDE`] / [`MAX_PIXELS`].
fn check_size(kind: &str, width: u64, height: u64) -> Result<()> {
    if width == 0 || height == 0 {
        bail!("{kind}: the image is {width}x{height}: empty");
    }
    if width > MAX_SIDE as u64 || height > MAX_SIDE as u64 || width * height > MAX_PIXELS {
        bail!("{kind}: the image declares {width}x{height} pixels, over the limit of {MAX_SIDE} per side and {MAX_PIXELS} in all");
    }
    Ok(())
}

/// Decode a PNG or JPEG held in memory to RGBA8.
pub fn decode_rgba8(bytes: &[u8]) -> Result<Rgba8> {
    let d = decode_ldr(bytes)?;
    let samples = match d.samples {
        Samples::U8(v) => v,
        Samples::U16(v) => v.iter().map(|&s| ((s as u32 + 128) / 257) as u8).collect(),
        Samples::F32(_) => unreachable!("PNG and JPEG decode to integers"),
    };
    let rgba = samples
        .chunks_exact(d.channels)
        .flat_map(|px| match d.channels {
            1 => [px[0], px[0], px[0], 255],
            2 => [px[0], px[0], px[0], px[1]],
            3 => [px[0], px[1], px[2], 255],
            _ => [px[0], px[1], px[2], px[3]],
        })
        .collect();
    Ok(Rgba8 { width: d.width, height: d.height, rgba })
}

/// Read an environment map that is not EXR: Radiance `.hdr` (linear radiance) or PNG / JPEG
/// (values / 255 or / 65535, taken as linear). Returns (width, height, interleaved RGB).
pub fn read_rgb_f32(path: &Path) -> Result<(u32, u32, Vec<f32>)> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    let d = if bytes.starts_with(b"#?") { decode_rgbe(&bytes) } else { decode_ldr(&bytes) }.with_context(|| format!("decoding {}", path.display()))?;
    let values: Vec<f32> = match d.samples {
        Samples::U8(v) => v.iter().map(|&s| s as f32 / 255.0).collect(),
        Samples::U16(v) => v.iter().map(|&s| s as f32 / 65535.0).collect(),
        Samples::F32(v) => v,
    };
    let rgb = values
        .chunks_exact(d.channels)
        .flat_map(|px| match d.channels {
            1 | 2 => [px[0]; 3],
            _ => [px[0], px[1], px[2]],
        })
        .collect();
    Ok((d.width, d.height, rgb))
}

/// PNG or JPEG, told apart by their signatures.
fn decode_ldr(bytes: &[u8]) -> Result<Decoded> {
    if bytes.starts_with(PNG_SIGNATURE) {
        decode_png(bytes)
    } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
        decode_jpeg(bytes)
    } else {
        bail!("not a PNG or JPEG image (its first bytes are {:02x?})", &bytes[..bytes.len().min(8)])
    }
}

fn decode_png(bytes: &[u8]) -> Result<Decoded> {
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(|e| anyhow!("PNG: {e}"))?;
    check_size("PNG", reader.info().width as u64, reader.info().height as u64)?;
    let size = reader.output_buffer_size().ok_or_else(|| anyhow!("PNG: the image is too large"))?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(|e| anyhow!("PNG: {e}"))?;
    buf.truncate(info.buffer_size());
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => bail!("PNG: a palette image was not expanded"),
    };
    let samples = match info.bit_depth {
        png::BitDepth::Eight => Samples::U8(buf),
        png::BitDepth::Sixteen => Samples::U16(buf.chunks_exact(2).map(|b| u16::from_be_bytes([b[0], b[1]])).collect()),
        d => bail!("PNG: {d:?}-bit samples were not expanded to 8 bits"),
    };
    Ok(Decoded { width: info.width, height: info.height, channels, samples })
}

fn decode_jpeg(bytes: &[u8]) -> Result<Decoded> {
    use zune_core::colorspace::ColorSpace;
    let options = zune_core::options::DecoderOptions::default().set_strict_mode(false).set_max_width(usize::MAX).set_max_height(usize::MAX);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(zune_core::bytestream::ZCursor::new(bytes), options);
    decoder.decode_headers().map_err(|e| anyhow!("JPEG: {e:?}"))?;
    let (width, height) = decoder.dimensions().ok_or_else(|| anyhow!("JPEG: no dimensions after the headers"))?;
    check_size("JPEG", width as u64, height as u64)?;
    let input = decoder.input_colorspace().ok_or_else(|| anyhow!("JPEG: no colour space after the headers"))?;
    // grey and RGB(A) stay as they are; YCbCr, CMYK and the rest become RGB
    let out = match input {
        ColorSpace::RGB | ColorSpace::RGBA | ColorSpace::Luma | ColorSpace::LumaA => input,
        _ => ColorSpace::RGB,
    };
    decoder.set_options(decoder.options().jpeg_set_out_colorspace(out));
    let pixels = decoder.decode().map_err(|e| anyhow!("JPEG: {e:?}"))?;
    let channels = out.num_components();
    let (width, height) = (u32::try_from(width)?, u32::try_from(height)?);
    if pixels.len() != channels * width as usize * height as usize {
        bail!("JPEG: {} bytes decoded for {width}x{height} with {channels} channels", pixels.len());
    }
    Ok(Decoded { width, height, channels, samples: Samples::U8(pixels) })
}

/// Radiance RGBE (`#?RADIANCE` / `#?RGBE`, `FORMAT=32-bit_rle_rgbe`, resolution line `-Y h +X w`),
/// flat or with the per-channel run-length scanlines (Ward 1991). A texel (r, g, b, e) is
/// `c * 2^(e - 136)` per channel, 0 where e = 0.
fn decode_rgbe(bytes: &[u8]) -> Result<Decoded> {
    let mut pos = 0;
    let mut line = || -> Result<&[u8]> {
        let rest = &bytes[pos..];
        let n = rest.iter().position(|&b| b == b'\n').ok_or_else(|| anyhow!("RGBE: the header ends without a resolution line"))?;
        pos += n + 1;
        Ok(&rest[..n])
    };
    let mut format_ok = true;
    loop {
        let l = line()?;
        if l.is_empty() {
            break;
        }
        if let Some(f) = l.strip_prefix(b"FORMAT=") {
            format_ok = f == b"32-bit_rle_rgbe";
        }
    }
    if !format_ok {
        bail!("RGBE: only FORMAT=32-bit_rle_rgbe is read (not XYZE)");
    }
    let res = String::from_utf8_lossy(line()?).to_string();
    let f: Vec<&str> = res.split_whitespace().collect();
    let (height, width) = match f.as_slice() {
        ["-Y", h, "+X", w] => (h.parse::<u32>().ok(), w.parse::<u32>().ok()),
        _ => (None, None),
    };
    let (Some(height), Some(width)) = (height, width) else { bail!("RGBE: resolution line '{res}' is not '-Y <height> +X <width>'") };
    check_size("RGBE", width as u64, height as u64)?;
    let (w, h) = (width as usize, height as usize);
    let data = &bytes[pos..];
    let mut at = 0;
    let mut take = |n: usize| -> Result<&[u8]> {
        let s = data.get(at..at + n).ok_or_else(|| anyhow!("RGBE: the pixel data ends early"))?;
        at += n;
        Ok(s)
    };
    let mut rgbe = vec![0u8; 4 * w * h];
    let mut row = vec![0u8; 4 * w];
    for y in 0..h {
        let head = take(4)?;
        if head[0] == 2 && head[1] == 2 && head[2] & 0x80 == 0 {
            if ((head[2] as usize) << 8 | head[3] as usize) != w {
                bail!("RGBE: scanline {y} says width {} for a {w}-wide image", (head[2] as usize) << 8 | head[3] as usize);
            }
            // new RLE: the four channels one after another, runs (count > 128) or literals
            for c in 0..4 {
                let mut x = 0;
                while x < w {
                    let n = take(1)?[0] as usize;
                    let (count, run) = if n > 128 { (n - 128, true) } else { (n, false) };
                    if count == 0 || x + count > w {
                        bail!("RGBE: scanline {y} has a bad run length");
                    }
                    if run {
                        let v = take(1)?[0];
                        (x..x + count).for_each(|i| row[4 * i + c] = v);
                    } else {
                        let lit = take(count)?;
                        (0..count).for_each(|i| row[4 * (x + i) + c] = lit[i]);
                    }
                    x += count;
                }
            }
        } else {
            // flat pixels, where (1, 1, 1, n) repeats the previous pixel n times (n * 256^k for
            // the k-th marker in a row): the original RLE
            let mut x = 0;
            let mut pixel = [head[0], head[1], head[2], head[3]];
            let mut shift = 0;
            loop {
                if pixel[..3] == [1, 1, 1] {
                    if x == 0 {
                        bail!("RGBE: scanline {y} starts with a run marker");
                    }
                    let count = (pixel[3] as usize) << shift;
                    if count == 0 || x + count > w || shift > 16 {
                        bail!("RGBE: scanline {y} has a bad run length");
                    }
                    let prev: [u8; 4] = row[4 * (x - 1)..4 * x].try_into().unwrap();
                    (x..x + count).for_each(|i| row[4 * i..4 * i + 4].copy_from_slice(&prev));
                    x += count;
                    shift += 8;
                } else {
                    row[4 * x..4 * x + 4].copy_from_slice(&pixel);
                    x += 1;
                    shift = 0;
                }
                if x == w {
                    break;
                }
                pixel = take(4)?.try_into().unwrap();
            }
        }
        rgbe[4 * w * y..4 * w * (y + 1)].copy_from_slice(&row);
    }
    let rgb = rgbe
        .chunks_exact(4)
        .flat_map(|p| {
            if p[3] == 0 {
                return [0.0; 3];
            }
            // 2^(e - 136) as a float: e - 136 >= -135 is at worst subnormal, so exact
            let scale = f32::from_bits(if p[3] > 1 { ((p[3] - 1) as u32) << 23 } else { 1 << 22 }) * (1.0 / 256.0);
            [p[0] as f32 * scale, p[1] as f32 * scale, p[2] as f32 * scale]
        })
        .collect();
    Ok(Decoded { width, height, channels: 3, samples: Samples::F32(rgb) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgbe_texels_decode_to_c_times_2_to_the_e_minus_136() {
        let mut f = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 3\n".to_vec();
        f.extend_from_slice(&[128, 64, 0, 129, 255, 1, 2, 1, 9, 9, 9, 0]);
        let p = std::env::temp_dir().join(format!("scene_rgbe_{}.hdr", std::process::id()));
        std::fs::write(&p, &f).unwrap();
        let (w, h, rgb) = read_rgb_f32(&p).unwrap();
        let _ = std::fs::remove_file(&p);
        assert_eq!((w, h), (3, 1));
        let e = |c: f64, e: i32| (c * 2f64.powi(e - 136)) as f32;
        assert_eq!(rgb, [e(128.0, 129), e(64.0, 129), 0.0, e(255.0, 1), e(1.0, 1), e(2.0, 1), 0.0, 0.0, 0.0]);
    }

    #[test]
    fn run_length_scanlines_decode_like_flat_ones() {
        // 8 pixels wide: channel runs and literals
        let mut f = b"#?RGBE\n\n-Y 1 +X 8\n".to_vec();
        f.extend_from_slice(&[2, 2, 0, 8]);
        f.extend_from_slice(&[136, 7]); // R: run of 8
        f.extend_from_slice(&[4, 1, 2, 3, 4, 132, 5]); // G: 4 literals, run of 4
        f.extend_from_slice(&[8, 0, 1, 0, 1, 0, 1, 0, 1]); // B: 8 literals
        f.extend_from_slice(&[136, 130]); // E: run of 8
        let d = decode_rgbe(&f).unwrap();
        let Samples::F32(v) = d.samples else { panic!() };
        let s = 4.0 / 256.0;
        let g = [1.0, 2.0, 3.0, 4.0, 5.0, 5.0, 5.0, 5.0];
        for x in 0..8 {
            assert_eq!(v[3 * x..3 * x + 3], [7.0 * s, g[x] * s, (x % 2) as f32 * s], "pixel {x}");
        }
    }

    #[test]
    fn original_run_markers_repeat_the_previous_pixel() {
        // 1 + 2 + 256 pixels: a pixel, a marker of 2 and at once a marker of 1 (1 * 256: a chain)
        let mut f = b"#?RADIANCE\n\n-Y 1 +X 260\n".to_vec();
        f.extend_from_slice(&[10, 20, 30, 128, 1, 1, 1, 2, 1, 1, 1, 1]);
        f.extend_from_slice(&[40, 50, 60, 128]);
        let d = decode_rgbe(&f).unwrap();
        let Samples::F32(v) = d.samples else { panic!() };
        let s = 1.0 / 256.0;
        assert!((0..259).all(|x| v[3 * x..3 * x + 3] == [10.0 * s, 20.0 * s, 30.0 * s]));
        assert_eq!(v[3 * 259..], [40.0 * s, 50.0 * s, 60.0 * s]);
        assert!(decode_rgbe(b"#?RADIANCE\n\n-Y 1 +X 2\n\x01\x01\x01\x01\0\0\0\0").is_err(), "a marker first");
    }

    #[test]
    fn bad_files_are_named_errors() {
        assert!(format!("{:#}", decode_rgba8(b"GIF89a....").unwrap_err()).contains("not a PNG or JPEG"));
        assert!(format!("{:#}", decode_rgbe(b"#?RADIANCE\n\n-Y 2 +X 2\n\x01\x02").unwrap_err()).contains("ends early"));
        assert!(format!("{:#}", decode_rgbe(b"#?RADIANCE\n\n+X 2 -Y 2\n").unwrap_err()).contains("resolution line"));
        assert!(format!("{:#}", decode_rgbe(b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n\0\0\0\0").unwrap_err()).contains("XYZE"));
        assert!(decode_rgba8(PNG_SIGNATURE).is_err());
    }
}
