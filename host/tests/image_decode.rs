//! The `scene` crate decodes textures and environment maps without the `image` crate: its
//! pixels must be the bits `image` gives for the same files (PNG of every colour type and
//! depth, palettes with transparency, JPEG grey and colour, Radiance RGBE). One exception: a
//! grey PNG or JPEG read as an environment map is `v / 255` (or `v / 65535`) correctly rounded
//! here, where the image crate's grey-to-RGB float conversion is up to 1 ulp away.

use image::{DynamicImage, ImageBuffer, ImageFormat};
use scene::image_file::{decode_rgba8, read_rgb_f32};
use std::io::Cursor;

/// Deterministic bytes (SplitMix64).
fn noise(n: usize, seed: u64) -> Vec<u8> {
    let mut s = reference::splitmix::SplitMix64(seed);
    (0..n)
        .map(|_| s.next_u64() as u8)
        .collect()
}

fn encode(img: &DynamicImage, format: ImageFormat) -> Vec<u8> {
    let mut out = Cursor::new(Vec::new());
    img.write_to(&mut out, format).unwrap();
    out.into_inner()
}

fn same_rgba8(bytes: &[u8], what: &str) {
    let ours = decode_rgba8(bytes).unwrap_or_else(|e| panic!("{what}: {e:#}"));
    let theirs = image::load_from_memory(bytes).unwrap().to_rgba8();
    assert_eq!((ours.width, ours.height), theirs.dimensions(), "{what}");
    assert!(ours.rgba == theirs.into_raw(), "{what}: the RGBA8 bytes differ from the image crate's");
}

fn same_rgb_f32(bytes: &[u8], ext: &str, what: &str, grey: bool) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("map.{ext}"));
    std::fs::write(&path, bytes).unwrap();
    let (w, h, ours) = read_rgb_f32(&path).unwrap_or_else(|e| panic!("{what}: {e:#}"));
    let theirs = image::open(&path).unwrap().into_rgb32f();
    assert_eq!((w, h), theirs.dimensions(), "{what}");
    let theirs = theirs.into_raw();
    assert_eq!(ours.len(), theirs.len(), "{what}");
    let ulps = |a: f32, b: f32| (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs();
    if let Some(i) = (0..ours.len()).find(|&i| ulps(ours[i], theirs[i]) > grey as u64) {
        panic!("{what}: value {i} is {} here and {} in the image crate", ours[i], theirs[i]);
    }
    if grey {
        // ours is the quotient correctly rounded
        let img = image::open(&path).unwrap();
        let wide = img.color().bytes_per_pixel() / img.color().channel_count() == 2;
        let raw: Vec<f64> = if wide { img.to_luma16().into_raw().iter().map(|&v| v as f64 / 65535.0).collect() } else { img.to_luma8().into_raw().iter().map(|&v| v as f64 / 255.0).collect() };
        for (i, v) in raw.iter().enumerate() {
            assert_eq!(ours[3 * i], *v as f32, "{what}: texel {i} is not v / max correctly rounded");
        }
    }
}

#[test]
fn png_of_every_colour_type_and_depth_decodes_as_the_image_crate_does() {
    let (w, h) = (37u32, 11u32);
    let n = (w * h) as usize;
    let b = |k: usize, seed: u64| noise(k * n, seed);
    let w16 = |k: usize, seed: u64| -> Vec<u16> { b(2 * k, seed).chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect() };
    let images = [
        ("L8", DynamicImage::ImageLuma8(ImageBuffer::from_raw(w, h, b(1, 1)).unwrap())),
        ("La8", DynamicImage::ImageLumaA8(ImageBuffer::from_raw(w, h, b(2, 2)).unwrap())),
        ("Rgb8", DynamicImage::ImageRgb8(ImageBuffer::from_raw(w, h, b(3, 3)).unwrap())),
        ("Rgba8", DynamicImage::ImageRgba8(ImageBuffer::from_raw(w, h, b(4, 4)).unwrap())),
        ("L16", DynamicImage::ImageLuma16(ImageBuffer::from_raw(w, h, w16(1, 5)).unwrap())),
        ("La16", DynamicImage::ImageLumaA16(ImageBuffer::from_raw(w, h, w16(2, 6)).unwrap())),
        ("Rgb16", DynamicImage::ImageRgb16(ImageBuffer::from_raw(w, h, w16(3, 7)).unwrap())),
        ("Rgba16", DynamicImage::ImageRgba16(ImageBuffer::from_raw(w, h, w16(4, 8)).unwrap())),
    ];
    for (what, img) in &images {
        let png = encode(img, ImageFormat::Png);
        same_rgba8(&png, &format!("PNG {what}"));
        same_rgb_f32(&png, "png", &format!("PNG {what} as an environment map"), what.starts_with('L'));
    }
}

#[test]
fn palette_and_low_bit_png_decode_as_the_image_crate_does() {
    let (w, h) = (13u32, 5u32);
    let idx = noise((w * h) as usize, 9);
    let mut cases: Vec<(String, Vec<u8>)> = Vec::new();
    for (depth, bits) in [(png::BitDepth::Eight, 8u32), (png::BitDepth::Four, 4), (png::BitDepth::Two, 2), (png::BitDepth::One, 1)] {
        for (colour, trns) in [(png::ColorType::Indexed, true), (png::ColorType::Indexed, false), (png::ColorType::Grayscale, false)] {
            let levels = 1u32 << bits;
            let mut packed = Vec::new();
            for row in idx.chunks_exact(w as usize) {
                let mut acc = 0u32;
                let mut n = 0;
                for &v in row {
                    acc = (acc << bits) | (v as u32 % levels);
                    n += bits;
                    if n == 8 {
                        packed.push(acc as u8);
                        (acc, n) = (0, 0);
                    }
                }
                if n > 0 {
                    packed.push((acc << (8 - n)) as u8);
                }
            }
            let mut out = Vec::new();
            {
                let mut enc = png::Encoder::new(&mut out, w, h);
                enc.set_color(colour);
                enc.set_depth(depth);
                if colour == png::ColorType::Indexed {
                    enc.set_palette(noise(3 * levels as usize, 10));
                    if trns {
                        enc.set_trns(noise(levels as usize / 2 + 1, 11));
                    }
                }
                enc.write_header().unwrap().write_image_data(&packed).unwrap();
            }
            cases.push((format!("{colour:?} {bits}-bit{}", if trns { " with tRNS" } else { "" }), out));
        }
    }
    for (what, png) in &cases {
        same_rgba8(png, what);
        same_rgb_f32(png, "png", &format!("{what} as an environment map"), what.starts_with("Grayscale"));
    }
}

#[test]
fn jpeg_decodes_as_the_image_crate_does() {
    let (w, h) = (40u32, 24u32);
    // smooth content (JPEG's case) plus noise
    let n = noise((3 * w * h) as usize, 12);
    let rgb: Vec<u8> = (0..3 * w * h).map(|i| ((i % (3 * w)) as u8).wrapping_mul(3).wrapping_add(n[i as usize] / 8)).collect();
    let grey: Vec<u8> = rgb.iter().step_by(3).copied().collect();
    for (what, img) in [
        ("colour", DynamicImage::ImageRgb8(ImageBuffer::from_raw(w, h, rgb).unwrap())),
        ("grey", DynamicImage::ImageLuma8(ImageBuffer::from_raw(w, h, grey).unwrap())),
    ] {
        let jpg = encode(&img, ImageFormat::Jpeg);
        same_rgba8(&jpg, &format!("JPEG {what}"));
        same_rgb_f32(&jpg, "jpg", &format!("JPEG {what} as an environment map"), what == "grey");
    }
}

#[test]
fn radiance_rgbe_decodes_as_the_image_crate_does() {
    // widths that take the run-length scanlines (8..32767) and the flat ones (< 8)
    for (w, h) in [(64u32, 9u32), (5, 3)] {
        let bits = noise((12 * w * h) as usize, 13 + w as u64);
        // radiance from 1e-30 to 1e30, zeros and runs of equal texels
        let rgb: Vec<f32> = bits
            .chunks_exact(4)
            .enumerate()
            .map(|(i, c)| {
                let u = u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
                match i % 7 {
                    0 => 0.0,
                    1 | 2 => 1.0,
                    _ => 10f32.powf((u % 60_000) as f32 / 1000.0 - 30.0),
                }
            })
            .collect();
        let img = DynamicImage::ImageRgb32F(ImageBuffer::from_raw(w, h, rgb).unwrap());
        let hdr = encode(&img, ImageFormat::Hdr);
        same_rgb_f32(&hdr, "hdr", &format!("RGBE {w}x{h}"), false);
    }
}

/// CRC-32 of PNG chunks (ISO 3309, the polynomial 0xedb88320, bit by bit).
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xffff_ffffu32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { (c >> 1) ^ 0xedb8_8320 } else { c >> 1 };
        }
    }
    !c
}

/// Images whose headers declare a huge size are refused by that size, before any allocation
/// (a 100 kB file must not ask for 40 GB), naming the format, the size and the limit; an image
/// at the limit's side still decodes.
#[test]
fn declared_sizes_over_the_limit_are_refused_before_decoding() {
    use scene::image_file::{MAX_PIXELS, MAX_SIDE};
    let limit = format!("over the limit of {MAX_SIDE} per side and {MAX_PIXELS} in all");
    // PNG: a real 1x1 image with its IHDR width and height rewritten (and the chunk's CRC).
    let png = encode(&DynamicImage::ImageRgba8(ImageBuffer::from_raw(1, 1, vec![1, 2, 3, 4]).unwrap()), ImageFormat::Png);
    assert_eq!(&png[12..16], b"IHDR");
    for (w, h) in [(100_000u32, 100_000u32), (MAX_SIDE + 1, 1), (12_000, 12_000), (0, 5)] {
        let mut p = png.clone();
        p[16..20].copy_from_slice(&w.to_be_bytes());
        p[20..24].copy_from_slice(&h.to_be_bytes());
        let crc = crc32(&p[12..29]);
        p[29..33].copy_from_slice(&crc.to_be_bytes());
        let e = format!("{:#}", decode_rgba8(&p).expect_err("refused"));
        // (the png crate refuses an empty image itself)
        let want = if w == 0 { "PNG: Invalid image dimensions".to_string() } else { format!("PNG: the image declares {w}x{h} pixels, {limit}") };
        assert!(e.contains(&want), "{w}x{h}: {e}");
    }
    let wide = DynamicImage::ImageRgba8(ImageBuffer::from_raw(MAX_SIDE, 1, vec![7; 4 * MAX_SIDE as usize]).unwrap());
    assert_eq!(decode_rgba8(&encode(&wide, ImageFormat::Png)).unwrap().width, MAX_SIDE);
    // JPEG: the baseline frame header's height and width rewritten.
    let jpg = encode(&DynamicImage::ImageRgb8(ImageBuffer::from_raw(16, 16, noise(3 * 256, 5)).unwrap()), ImageFormat::Jpeg);
    let sof = jpg.windows(2).position(|m| m == [0xff, 0xc0]).expect("a baseline JPEG");
    let mut j = jpg.clone();
    j[sof + 5..sof + 7].copy_from_slice(&60_000u16.to_be_bytes());
    j[sof + 7..sof + 9].copy_from_slice(&50_000u16.to_be_bytes());
    let e = format!("{:#}", decode_rgba8(&j).expect_err("refused"));
    assert!(e.contains(&format!("JPEG: the image declares 50000x60000 pixels, {limit}")), "{e}");
    // Radiance RGBE: the resolution line.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("huge.hdr");
    std::fs::write(&p, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 9000 +X 18000\n\x02\x02\x46\x50").unwrap();
    let e = format!("{:#}", read_rgb_f32(&p).expect_err("refused"));
    assert!(e.contains(&format!("RGBE: the image declares 18000x9000 pixels, {limit}")), "{e}");
}
