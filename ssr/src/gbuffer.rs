//! The SSR inputs: a G-buffer (linear depth, world normal, perceptual roughness, metalness, base
//! colour, the scene colour reflections sample, motion vectors) and the cameras of this and the
//! previous frame.
//!
//! On disk: one EXR with the channels [`CHANNELS`] plus a JSON file beside it (same stem,
//! `.json`) holding `{"width", "height", "camera", "previous_camera"}` (see [`Camera`]), and
//! optionally `"fallback"` (the uniform radiance reflections fall back to; default black) and
//! `"reference"` (a reference EXR beside it, [`ReferenceFile`]; `host render --gbuffer` writes
//! one).
//! Depth is linear view depth (> 0; `+inf` = sky); normals are world-space unit vectors; the
//! colour is the previous frame's HDR colour (what HDRP's colour pyramid holds when SSR runs);
//! motion vectors are UV(current) - UV(previous); base colour and metalness give the glTF
//! metal-rough F0 = mix(0.04, base colour, metalness) of the specular (FG) pass.
//!
//! Optional channel [`DEPTH_FAR_CHANNEL`]: the far depth, the largest linear view depth that the
//! object seen at the pixel centre shows within one pixel of it (the maximum over primary rays
//! through a 5x5 grid of points in [-1, 1]^2 px around the centre that hit the same object; at
//! least `depth`; `+inf` for the sky): the depth extent of the texel's visible surface. The
//! tracers' mip-0 slab then ends where that surface does (`shader_core::ssr::trace::slab_base`);
//! G-buffers without it keep HDRP's constant slab.

use shader_core::ssr::trace::{GBufferTexel, GBUF_STRIDE};
use super::camera::Camera;
use fileio::{read_exr, write_exr};
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// EXR channel names, in the order of the fields they fill (the optional [`DEPTH_FAR_CHANNEL`]
/// follows them when present).
pub const CHANNELS: [&str; 14] = [
    "depth", "normal.X", "normal.Y", "normal.Z", "roughness", "metalness", "basecolor.R", "basecolor.G", "basecolor.B",
    "color.R", "color.G", "color.B", "motion.X", "motion.Y",
];

/// EXR channel of the optional far depth ([`GBuffer::depth_far`]).
pub const DEPTH_FAR_CHANNEL: &str = "depth_far";

/// A G-buffer and its cameras. Per-pixel vectors are interleaved; rows top to bottom.
#[derive(Clone, Debug)]
pub struct GBuffer {
    pub width: usize,
    pub height: usize,
    pub depth: Vec<f32>,
    /// Optional far depth per pixel (see the module doc): >= `depth`, `+inf` where `depth` is.
    pub depth_far: Option<Vec<f32>>,
    /// World-space normal, 3 per pixel.
    pub normal: Vec<f32>,
    pub roughness: Vec<f32>,
    pub metalness: Vec<f32>,
    /// glTF base colour (linear, in [0, 1]), RGB per pixel.
    pub base_color: Vec<f32>,
    /// Scene colour (previous frame), RGB per pixel.
    pub color: Vec<f32>,
    /// UV(current) - UV(previous), 2 per pixel.
    pub motion: Vec<f32>,
    pub camera: Camera,
    pub previous_camera: Camera,
    /// Radiance of the fallback environment (what a reflection that finds nothing returns).
    pub fallback: [f32; 3],
    /// The reference EXR beside the G-buffer, if there is one.
    pub reference: Option<ReferenceFile>,
}

/// The JSON beside the EXR.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CameraFile {
    pub width: usize,
    pub height: usize,
    pub camera: Camera,
    pub previous_camera: Camera,
    #[serde(default)]
    pub fallback: [f32; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<ReferenceFile>,
}

/// A reference of the G-buffer's frame (`super::reference::Reference::save`'s EXR).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceFile {
    /// File name, relative to the G-buffer EXR's directory.
    pub file: String,
    /// Samples per glossy pixel.
    pub samples: u32,
    /// Pixels with perceptual roughness <= this have reference values (the `glossy` channel).
    pub max_roughness: f32,
    /// How it was made (e.g. "path traced, max depth 8").
    pub method: String,
    /// Its own relative noise (standard error over RMS value, glossy pixels), measured from two
    /// halves of its samples; errors against it cannot be read below this.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_rel: Option<f64>,
}

/// The JSON path of an EXR path.
pub fn camera_path(exr: &Path) -> PathBuf {
    exr.with_extension("json")
}

/// The channels [`GBuffer::save`] writes and [`GBuffer::load`] needs (the optional far depth
/// aside).
pub const GBUFFER_CHANNELS: &[&str] = &[
    "depth", "normal.X", "normal.Y", "normal.Z", "roughness", "metalness", "basecolor.R", "basecolor.G", "basecolor.B", "color.R", "color.G", "color.B", "motion.X", "motion.Y",
];

impl GBuffer {
    /// A `width` x `height` G-buffer with its colour, cameras and fallback and empty per-pixel
    /// channels (a far-depth channel included) sized for the pixels a producer pushes in order.
    pub fn empty(width: usize, height: usize, color: Vec<f32>, camera: Camera, previous_camera: Camera, fallback: [f32; 3]) -> GBuffer {
        let n = width * height;
        GBuffer {
            width,
            height,
            depth: Vec::with_capacity(n),
            depth_far: Some(Vec::with_capacity(n)),
            normal: Vec::with_capacity(3 * n),
            roughness: Vec::with_capacity(n),
            metalness: Vec::with_capacity(n),
            base_color: Vec::with_capacity(3 * n),
            color,
            motion: Vec::with_capacity(2 * n),
            camera,
            previous_camera,
            fallback,
            reference: None,
        }
    }

    /// This frame as the first frame after a camera cut from `before` (the last frame of another
    /// view): what a renderer hands SSR then. The previous camera is `before`'s camera, the
    /// motion vectors reproject each pixel's point into it (the sky: its direction), and the
    /// previous frame's colour is `before`'s image; depth, normals and materials are this frame's.
    pub fn after_cut(&self, before: &GBuffer) -> Result<GBuffer> {
        if (before.width, before.height) != (self.width, self.height) {
            bail!("camera cut from a {}x{} frame to a {}x{} one", before.width, before.height, self.width, self.height);
        }
        let (w, h) = (self.width, self.height);
        let mut g = self.clone();
        g.previous_camera = before.camera;
        g.color = before.color.clone();
        g.motion.clear();
        for (i, &depth) in self.depth.iter().enumerate() {
            let (sx, sy) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
            g.motion.extend(self.camera.motion_at_depth(&before.camera, w, h, sx, sy, depth));
        }
        g.validate()?;
        Ok(g)
    }

    /// Check sizes, values and cameras; the error names the first problem (channel, pixel).
    pub fn validate(&self) -> Result<()> {
        let n = self.width * self.height;
        if n == 0 {
            bail!("G-buffer is empty ({}x{})", self.width, self.height);
        }
        if self.width > 8192 || self.height > 8192 {
            bail!("G-buffer {}x{} is larger than 8192x8192", self.width, self.height);
        }
        let sizes = [
            ("depth", self.depth.len(), n),
            ("normal", self.normal.len(), 3 * n),
            ("roughness", self.roughness.len(), n),
            ("metalness", self.metalness.len(), n),
            ("base color", self.base_color.len(), 3 * n),
            ("color", self.color.len(), 3 * n),
            ("motion", self.motion.len(), 2 * n),
        ];
        for (name, have, want) in sizes {
            if have != want {
                bail!(
                    "G-buffer size mismatch: {name} has {have} values, expected {want} for {}x{}",
                    self.width,
                    self.height
                );
            }
        }
        let at = |i: usize| format!("pixel ({}, {})", i % self.width, i / self.width);
        for (i, &z) in self.depth.iter().enumerate() {
            if z.is_nan() {
                bail!("G-buffer depth is NaN at {}", at(i));
            }
            if !(z > 0.0) {
                bail!("G-buffer depth must be > 0 (linear view depth; +inf for sky), got {z} at {}", at(i));
            }
            if z.is_finite() {
                let nn = &self.normal[3 * i..3 * i + 3];
                if nn.iter().any(|v| !v.is_finite()) {
                    bail!("G-buffer normal is not finite at {}: {nn:?}", at(i));
                }
                let l2: f32 = nn.iter().map(|v| v * v).sum();
                if !(l2 > 0.25 && l2 < 4.0) {
                    bail!("G-buffer normal at {} is not a unit vector: {nn:?}", at(i));
                }
            }
        }
        if let Some(far) = &self.depth_far {
            if far.len() != n {
                bail!("G-buffer size mismatch: depth_far has {} values, expected {n} for {}x{}", far.len(), self.width, self.height);
            }
            for (i, (&zf, &z)) in far.iter().zip(&self.depth).enumerate() {
                if !(zf >= z) {
                    bail!("G-buffer depth_far must be >= depth (+inf for the sky), got {zf} for depth {z} at {}", at(i));
                }
            }
        }
        for (name, data) in [("roughness", &self.roughness), ("metalness", &self.metalness)] {
            if let Some((i, v)) = data.iter().enumerate().find(|(_, v)| !(**v >= 0.0 && **v <= 1.0)) {
                bail!("G-buffer {name} must be in [0, 1], got {v} at {}", at(i));
            }
        }
        if let Some((i, v)) = self.base_color.iter().enumerate().find(|(_, v)| !(**v >= 0.0 && **v <= 1.0)) {
            bail!("G-buffer base color must be in [0, 1], got {v} at {}", at(i / 3));
        }
        if let Some((i, v)) = self.color.iter().enumerate().find(|(_, v)| !v.is_finite() || **v < 0.0) {
            bail!("G-buffer color must be finite and >= 0, got {v} at {}", at(i / 3));
        }
        if let Some((i, v)) = self.motion.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            bail!("G-buffer motion vector is not finite ({v}) at {}", at(i / 2));
        }
        self.camera.validate("camera")?;
        self.previous_camera.validate("previous_camera")?;
        if self.fallback.iter().any(|v| !v.is_finite() || *v < 0.0) {
            bail!("G-buffer fallback radiance must be finite and >= 0, got {:?}", self.fallback);
        }
        if let Some(r) = &self.reference {
            if !(r.max_roughness >= 0.0 && r.max_roughness <= 1.0) || r.samples == 0 || r.file.is_empty() {
                bail!("G-buffer reference entry is invalid (file {:?}, {} samples, max_roughness {}): needs a file, samples >= 1, max_roughness in [0, 1]", r.file, r.samples, r.max_roughness);
            }
        }
        Ok(())
    }

    /// The depth input of the depth pyramid (`super::pipeline::Runner::depth_pyramid`): the
    /// depth, followed by the far depth when the G-buffer has one.
    pub fn depth_layers(&self) -> Vec<f32> {
        let mut d = self.depth.clone();
        if let Some(far) = &self.depth_far {
            d.extend_from_slice(far);
        }
        d
    }

    /// Pack depth, normal, roughness, metalness and motion into the kernels' G-buffer layout
    /// (`shader_core::ssr::layout::GBufferTexel`, `GBUF_STRIDE` floats per pixel).
    pub fn packed(&self) -> Vec<f32> {
        let n = self.width * self.height;
        let mut g = vec![0.0; n * GBUF_STRIDE];
        for i in 0..n {
            let texel = GBufferTexel {
                depth: self.depth[i],
                normal: shader_core::Vec3::new(self.normal[3 * i], self.normal[3 * i + 1], self.normal[3 * i + 2]),
                roughness: self.roughness[i],
                metalness: self.metalness[i],
                motion: [self.motion[2 * i], self.motion[2 * i + 1]],
            };
            texel.store(&mut g, i * GBUF_STRIDE);
        }
        g
    }

    /// Write the EXR (channels [`CHANNELS`]) and the camera JSON beside it.
    pub fn save(&self, exr: &Path) -> Result<()> {
        let n = self.width * self.height;
        let comp = |v: &[f32], k: usize, s: usize| -> Vec<f32> { (0..n).map(|i| v[s * i + k]).collect() };
        let chans: Vec<(&str, Vec<f32>)> = vec![
            ("depth", self.depth.clone()),
            ("normal.X", comp(&self.normal, 0, 3)),
            ("normal.Y", comp(&self.normal, 1, 3)),
            ("normal.Z", comp(&self.normal, 2, 3)),
            ("roughness", self.roughness.clone()),
            ("metalness", self.metalness.clone()),
            ("basecolor.R", comp(&self.base_color, 0, 3)),
            ("basecolor.G", comp(&self.base_color, 1, 3)),
            ("basecolor.B", comp(&self.base_color, 2, 3)),
            ("color.R", comp(&self.color, 0, 3)),
            ("color.G", comp(&self.color, 1, 3)),
            ("color.B", comp(&self.color, 2, 3)),
            ("motion.X", comp(&self.motion, 0, 2)),
            ("motion.Y", comp(&self.motion, 1, 2)),
        ];
        let mut chans = chans;
        if let Some(far) = &self.depth_far {
            chans.push((DEPTH_FAR_CHANNEL, far.clone()));
        }
        let refs: Vec<(&str, &[f32])> = chans.iter().map(|(n, d)| (*n, d.as_slice())).collect();
        write_exr(exr, self.width, self.height, &refs)?;
        let cams = CameraFile {
            width: self.width,
            height: self.height,
            camera: self.camera,
            previous_camera: self.previous_camera,
            fallback: self.fallback,
            reference: self.reference.clone(),
        };
        let json = serde_json::to_string_pretty(&cams)?;
        fileio::write_file(&camera_path(exr), json)
    }

    /// The reference EXR's path, for a G-buffer loaded from `exr`.
    pub fn reference_path(&self, exr: &Path) -> Option<PathBuf> {
        self.reference.as_ref().map(|r| exr.parent().unwrap_or(Path::new("")).join(&r.file))
    }

    /// Read an EXR written by [`GBuffer::save`] (or by another tool with the same channels) and
    /// the camera JSON beside it, and validate the result.
    pub fn load(exr: &Path) -> Result<GBuffer> {
        let img = read_exr(exr)?;
        // The channels first: an EXR of another kind (a `host render` image, whose JSON summary
        // sits where the camera file would) is named as such, not as a bad camera file.
        let missing: Vec<&str> = GBUFFER_CHANNELS.iter().copied().filter(|c| !img.channels.iter().any(|(n, _)| n == c)).collect();
        if !missing.is_empty() {
            let have: Vec<&str> = img.channels.iter().map(|(n, _)| n.as_str()).collect();
            let render = ["R", "G", "B", "depth.Z"].iter().all(|c| have.contains(c));
            bail!(
                "{} is not a G-buffer: it lacks the channels {} (it has {}){}",
                exr.display(),
                missing.join(", "),
                have.join(", "),
                if render { ". It looks like a `host render` image: `host render SCENE --gbuffer g.exr` writes the G-buffer `host ssr --input` reads" } else { "" }
            );
        }
        let json_path = camera_path(exr);
        let text = std::fs::read_to_string(&json_path)
            .with_context(|| format!("reading the camera file {} (expected beside the EXR)", json_path.display()))?;
        let cams: CameraFile =
            serde_json::from_str(&text).with_context(|| format!("parsing the camera file {}", json_path.display()))?;
        if cams.width != img.width || cams.height != img.height {
            bail!(
                "size mismatch: {} is {}x{} but {} says {}x{}",
                exr.display(),
                img.width,
                img.height,
                json_path.display(),
                cams.width,
                cams.height
            );
        }
        let n = img.width * img.height;
        let get = |name: &str| -> Result<Vec<f32>> {
            let c = img.channel(name).with_context(|| format!("in {}", exr.display()))?;
            if c.len() != n {
                bail!("channel {name} has {} values, expected {n}", c.len());
            }
            Ok(c.to_vec())
        };
        let inter = |names: &[&str]| -> Result<Vec<f32>> {
            let cs: Vec<Vec<f32>> = names.iter().map(|n| get(n)).collect::<Result<_>>()?;
            Ok((0..n).flat_map(|i| cs.iter().map(move |c| c[i])).collect())
        };
        let g = GBuffer {
            width: img.width,
            height: img.height,
            depth: get("depth")?,
            depth_far: match img.channels.iter().any(|(c, _)| c == DEPTH_FAR_CHANNEL) {
                true => Some(get(DEPTH_FAR_CHANNEL)?),
                false => None,
            },
            normal: inter(&["normal.X", "normal.Y", "normal.Z"])?,
            roughness: get("roughness")?,
            metalness: get("metalness")?,
            base_color: inter(&["basecolor.R", "basecolor.G", "basecolor.B"])?,
            color: inter(&["color.R", "color.G", "color.B"])?,
            motion: inter(&["motion.X", "motion.Y"])?,
            camera: cams.camera,
            previous_camera: cams.previous_camera,
            fallback: cams.fallback,
            reference: cams.reference,
        };
        g.validate().with_context(|| format!("invalid G-buffer {}", exr.display()))?;
        Ok(g)
    }
}
