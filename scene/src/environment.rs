//! The environment buffer of `shader_core::pt::environment`: a uniform colour, or an
//! equirectangular EXR / Radiance HDR map with its importance-sampling tables (density and CDFs
//! over luminance x sin(theta)), built here once per render.

use crate::luminance;
use anyhow::{bail, Context, Result};
use shader_core::pt::environment::{ENV_HEADER, E_COLOR, E_HEIGHT, E_KIND, E_ROT_COS, E_ROT_SIN, E_WIDTH, KIND_BLACK, KIND_MAP, KIND_UNIFORM};
use std::path::{Path, PathBuf};

/// What `--env` names.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvSpec {
    /// No environment light.
    Black,
    /// Uniform radiance (linear RGB).
    Uniform([f32; 3]),
    /// An equirectangular map (`.exr` with R, G, B channels, or `.hdr`).
    Map(PathBuf),
}

impl EnvSpec {
    /// Parse `--env`: `black`, one number (grey), `r,g,b`, or a path to an `.exr` / `.hdr` map.
    pub fn parse(s: &str) -> Result<EnvSpec, String> {
        if s == "black" || s == "none" {
            return Ok(EnvSpec::Black);
        }
        let lower = s.to_ascii_lowercase();
        if lower.ends_with(".exr") || lower.ends_with(".hdr") {
            return Ok(EnvSpec::Map(PathBuf::from(s)));
        }
        let parts: Vec<&str> = s.split(',').collect();
        let vals: Result<Vec<f32>, _> = parts.iter().map(|p| p.trim().parse::<f32>()).collect();
        let vals = vals.map_err(|_| format!("--env {s:?}: expected black, a number, r,g,b, or an .exr/.hdr map"))?;
        let rgb = match vals.as_slice() {
            [g] => [*g; 3],
            [r, g, b] => [*r, *g, *b],
            _ => return Err(format!("--env {s:?}: give one value or three (r,g,b)")),
        };
        if rgb.iter().any(|v| !v.is_finite() || *v < 0.0) {
            return Err(format!("--env {s:?}: radiance must be finite and >= 0"));
        }
        Ok(if rgb == [0.0; 3] { EnvSpec::Black } else { EnvSpec::Uniform(rgb) })
    }
}

/// An environment ready for the kernel.
#[derive(Clone, Debug)]
pub struct Environment {
    /// The buffer the kernel reads.
    pub words: Vec<f32>,
    /// A one-line description.
    pub label: String,
    /// Mean radiance over the sphere (luminance), for the light-selection estimate.
    pub mean_luminance: f64,
    /// Mean radiance over the sphere per RGB channel (the uniform fallback of SSR).
    pub mean_radiance: [f32; 3],
}

impl Environment {
    /// The environment's kind (`KIND_*`).
    pub fn kind(&self) -> u32 {
        self.words[E_KIND] as u32
    }

    /// True when it emits nothing.
    pub fn is_black(&self) -> bool {
        self.kind() == KIND_BLACK
    }
}

fn header(kind: u32, rgb: [f32; 3], w: u32, h: u32, rotation_deg: f32) -> Vec<f32> {
    let mut v = vec![0.0f32; ENV_HEADER];
    v[E_KIND] = kind as f32;
    v[E_COLOR..E_COLOR + 3].copy_from_slice(&rgb);
    v[E_WIDTH] = w as f32;
    v[E_HEIGHT] = h as f32;
    let r = (rotation_deg as f64).to_radians();
    v[E_ROT_COS] = r.cos() as f32;
    v[E_ROT_SIN] = r.sin() as f32;
    v
}

/// Build the environment of `spec`, its radiance multiplied by `scale`, the map turned by
/// `rotation_deg` about +y.
pub fn build(spec: &EnvSpec, scale: f32, rotation_deg: f32) -> Result<Environment> {
    if !scale.is_finite() || scale < 0.0 {
        bail!("--env-scale {scale}: must be finite and >= 0");
    }
    if !rotation_deg.is_finite() {
        bail!("--env-rotation {rotation_deg}: must be finite");
    }
    match spec {
        EnvSpec::Black => Ok(Environment { words: header(KIND_BLACK, [0.0; 3], 0, 0, 0.0), label: "black".into(), mean_luminance: 0.0, mean_radiance: [0.0; 3] }),
        EnvSpec::Uniform(c) => {
            let rgb = [c[0] * scale, c[1] * scale, c[2] * scale];
            if rgb == [0.0; 3] {
                return build(&EnvSpec::Black, 1.0, 0.0);
            }
            Ok(Environment {
                words: header(KIND_UNIFORM, rgb, 0, 0, 0.0),
                label: format!("uniform radiance ({}, {}, {})", rgb[0], rgb[1], rgb[2]),
                mean_luminance: luminance(rgb),
                mean_radiance: rgb,
            })
        }
        EnvSpec::Map(path) => {
            let (w, h, rgb) = read_map(path)?;
            let mut env = from_map(w, h, &rgb, scale, rotation_deg).with_context(|| format!("environment map {}", path.display()))?;
            env.label = format!("{} ({w}x{h}, x{scale}, rotated {rotation_deg} deg)", path.display());
            Ok(env)
        }
    }
}

/// Read an equirectangular map: (width, height, interleaved RGB, top row first).
pub fn read_map(path: &Path) -> Result<(u32, u32, Vec<f32>)> {
    let lower = path.to_string_lossy().to_ascii_lowercase();
    if lower.ends_with(".exr") {
        let img = fileio::read_exr(path).with_context(|| format!("reading environment map {}", path.display()))?;
        let (r, g, b) = (img.channel("R")?, img.channel("G")?, img.channel("B")?);
        let rgb = (0..img.width * img.height).flat_map(|i| [r[i], g[i], b[i]]).collect();
        Ok((img.width as u32, img.height as u32, rgb))
    } else {
        crate::image_file::read_rgb_f32(path).with_context(|| format!("reading environment map {}", path.display()))
    }
}

/// The environment of a `w x h` RGB map (row 0 = +y), with the density and CDFs of
/// `shader_core::pt::environment`. Errors on an empty or all-black map and on negative, NaN or
/// infinite texels (naming the first).
pub fn from_map(w: u32, h: u32, rgb: &[f32], scale: f32, rotation_deg: f32) -> Result<Environment> {
    let (wu, hu) = (w as usize, h as usize);
    if w == 0 || h == 0 {
        bail!("the map is empty ({w}x{h})");
    }
    if w > 1 << 14 || h > 1 << 14 {
        bail!("the map is {w}x{h}; at most 16384 texels per side");
    }
    if rgb.len() != 3 * wu * hu {
        bail!("{} values for a {w}x{h} RGB map", rgb.len());
    }
    if let Some(i) = rgb.iter().position(|v| !v.is_finite() || *v < 0.0) {
        bail!("texel ({}, {}) channel {} is {}: radiance must be finite and >= 0", (i / 3) % wu, (i / 3) / wu, i % 3, rgb[i]);
    }
    // f_ij = luminance x sin(theta_i) at the row centre; p_ij = f_ij / mean(f).
    let mut f = vec![0.0f64; wu * hu];
    let mut lum_sum = 0.0f64;
    let mut sin_sum = 0.0f64;
    let mut rgb_sum = [0.0f64; 3];
    for i in 0..hu {
        let s = (std::f64::consts::PI * (i as f64 + 0.5) / hu as f64).sin();
        for j in 0..wu {
            let k = i * wu + j;
            let l = luminance([rgb[3 * k], rgb[3 * k + 1], rgb[3 * k + 2]]);
            f[k] = l * s;
            lum_sum += l * s;
            for (c, acc) in rgb_sum.iter_mut().enumerate() {
                *acc += rgb[3 * k + c] as f64 * s;
            }
            sin_sum += s;
        }
    }
    let total: f64 = f.iter().sum();
    if !(total > 0.0) {
        bail!("the map is black (every texel 0): use --env black instead");
    }
    let mean = total / (wu * hu) as f64;
    let mut words = header(KIND_MAP, [scale; 3], w, h, rotation_deg);
    words.extend_from_slice(rgb);
    words.extend(f.iter().map(|v| (v / mean) as f32));
    // Marginal CDF over rows, then each row's conditional CDF; every one ends at exactly 1.
    let rows: Vec<f64> = (0..hu).map(|i| f[i * wu..(i + 1) * wu].iter().sum()).collect();
    let mut acc = 0.0;
    for (i, r) in rows.iter().enumerate() {
        acc += r;
        words.push(if i + 1 == hu { 1.0 } else { (acc / total) as f32 });
    }
    for (i, r) in rows.iter().enumerate() {
        let mut acc = 0.0;
        for j in 0..wu {
            acc += f[i * wu + j];
            let c = if *r > 0.0 { acc / r } else { (j + 1) as f64 / wu as f64 };
            words.push(if j + 1 == wu { 1.0 } else { c as f32 });
        }
    }
    debug_assert_eq!(words.len(), ENV_HEADER + 5 * wu * hu + hu);
    let mean_radiance = rgb_sum.map(|v| (scale as f64 * v / sin_sum) as f32);
    Ok(Environment { words, label: format!("map {w}x{h}"), mean_luminance: scale as f64 * lum_sum / sin_sum, mean_radiance })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_accepts_the_documented_forms_and_names_bad_ones() {
        assert_eq!(EnvSpec::parse("black").unwrap(), EnvSpec::Black);
        assert_eq!(EnvSpec::parse("0.5").unwrap(), EnvSpec::Uniform([0.5; 3]));
        assert_eq!(EnvSpec::parse("1,2,3").unwrap(), EnvSpec::Uniform([1.0, 2.0, 3.0]));
        assert_eq!(EnvSpec::parse("sky.EXR").unwrap(), EnvSpec::Map("sky.EXR".into()));
        assert!(EnvSpec::parse("1,2").unwrap_err().contains("three"));
        assert!(EnvSpec::parse("-1").unwrap_err().contains(">= 0"));
        assert!(EnvSpec::parse("nan").unwrap_err().contains("finite"));
        assert!(EnvSpec::parse("sky.png").is_err());
    }

    #[test]
    fn map_tables_are_normalized() {
        let (w, h) = (8u32, 4u32);
        let rgb: Vec<f32> = (0..w * h * 3).map(|i| (i % 7) as f32 * 0.25).collect();
        let e = from_map(w, h, &rgb, 1.0, 0.0).unwrap();
        let n = (w * h) as usize;
        let dens = &e.words[ENV_HEADER + 3 * n..ENV_HEADER + 4 * n];
        let mean: f64 = dens.iter().map(|&d| d as f64).sum::<f64>() / n as f64;
        assert!((mean - 1.0).abs() < 1e-6, "{mean}");
        let marginal = &e.words[ENV_HEADER + 4 * n..ENV_HEADER + 4 * n + h as usize];
        assert_eq!(*marginal.last().unwrap(), 1.0);
        assert!(marginal.windows(2).all(|p| p[0] <= p[1]));
        assert!(from_map(2, 1, &[0.0; 6], 1.0, 0.0).unwrap_err().to_string().contains("black"));
        assert!(from_map(2, 1, &[1.0, f32::NAN, 0.0, 0.0, 0.0, 0.0], 1.0, 0.0).unwrap_err().to_string().contains("(0, 0) channel 1"));
    }
}
