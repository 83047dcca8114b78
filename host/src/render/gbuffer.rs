//! `host render --gbuffer`: the SSR inputs of a glTF scene (the G-buffer `host ssr --input`
//! reads, [`crate::ssr::gbuffer`]) and the path-traced reference SSR is judged against
//! (`shader_core::pt::gbuffer`), from the kernel `render::pt_gbuffer` on either backend.
//!
//! World convention: glTF is right-handed (the camera looks down its -z with x right, y up);
//! the SSR pipelines use a left-handed world (view space x right, y up, +z forward, and a
//! world-to-view rotation with determinant +1). The G-buffer therefore holds the glTF world
//! mirrored in x: normals (-x, y, z), and cameras built from the mirrored eye and axes. Depth,
//! roughness, colours, motion vectors and the reference are image quantities and unaffected.
//!
//! Camera path: with `--orbit DEG` the camera of frame k is the scene's camera turned by k DEG
//! degrees about the vertical axis (+y) through the scene's bounding-sphere centre. The
//! G-buffer is frame `--frame`; its colour buffer (the previous frame's colour) is frame
//! `--frame - 1` rendered with the same settings, and its motion vectors reproject each pixel's
//! first hit (for the sky, its direction) into that frame.

use super::{CameraSpec, RenderInputs};
use crate::ssr::camera::Camera as SsrCamera;
use crate::ssr::gbuffer::{GBuffer, ReferenceFile};
use crate::ssr::reference::Reference;
use anyhow::{bail, Context, Result};
use runner::{Backend, Timing, TimingSource};
use shader_core::pt::camera::{Camera, ORTHOGRAPHIC};
use shader_core::pt::gbuffer::GBufferParams;
use shader_kernels::render::{GBufferArgs, GBUFFER_STRIDE};

/// The kernel's entry point.
pub const ENTRY: &str = "render::pt_gbuffer";

/// Values per pixel that are the G-buffer itself (the same in every launch); the rest are sums.
const GBUFFER_VALUES: usize = 11;

/// One launch: the G-buffer and reference samples `p.render.sample_base .. + p.render.spp` of
/// every pixel; `GBUFFER_STRIDE` floats per pixel.
pub fn launch(backend: &Backend, inputs: &RenderInputs<'_>, p: &GBufferParams) -> Result<(Vec<f32>, Timing)> {
    let pixels = p.render.width as usize * p.render.height as usize;
    let bufs: [&[u8]; 3] = [bytemuck::cast_slice(inputs.scene), bytemuck::cast_slice(inputs.env), bytemuck::cast_slice(inputs.lut)];
    backend.launch(ENTRY, GBufferArgs::new(p), &bufs, pixels, GBUFFER_STRIDE, |a, i, out| {
        let mut one = *a;
        one.first_pixel = a.first_pixel + i;
        shader_kernels::render::gbuffer_pixel(0, &one, inputs.scene, inputs.env, inputs.lut, out);
    })
}

/// The kernel's output over all launches: `GBUFFER_STRIDE` values per pixel, the reference
/// columns summed over launches.
#[derive(Clone, Debug, PartialEq)]
pub struct GBufferSums {
    pub width: u32,
    pub height: u32,
    /// Reference samples per glossy pixel.
    pub samples: u32,
    pub values: Vec<f32>,
}

/// The G-buffer and `samples` reference samples per glossy pixel in launches of at most
/// `per_pass` samples (`samples` = 0: one launch, G-buffer only); `progress(samples done)`
/// after each launch.
pub fn render_gbuffer(backend: &Backend, inputs: &RenderInputs<'_>, base: &GBufferParams, samples: u32, per_pass: u32, mut progress: impl FnMut(u32)) -> Result<(GBufferSums, Timing)> {
    if per_pass == 0 {
        bail!("reference samples per pass must be at least 1");
    }
    let mut sums: Option<Vec<f32>> = None;
    let mut time: Option<Timing> = None;
    let mut done = 0;
    while sums.is_none() || done < samples {
        let n = (samples - done).min(per_pass);
        let mut p = *base;
        p.render.spp = n;
        p.render.sample_base = base.render.sample_base + done;
        let (out, t) = launch(backend, inputs, &p).with_context(|| format!("G-buffer launch at reference sample {done}"))?;
        match &mut sums {
            None => sums = Some(out),
            Some(s) => {
                for (a, b) in s.chunks_exact_mut(GBUFFER_STRIDE).zip(out.chunks_exact(GBUFFER_STRIDE)) {
                    for k in GBUFFER_VALUES..GBUFFER_STRIDE {
                        a[k] += b[k];
                    }
                }
            }
        }
        time = Some(match time { Some(a) => a.add(t), None => t });
        done += n;
        progress(done);
    }
    let values = sums.expect("at least one launch");
    Ok((GBufferSums { width: base.render.width, height: base.render.height, samples, values }, time.unwrap_or(Timing { seconds: 0.0, source: TimingSource::WallClock })))
}

/// A glTF-world vector in the G-buffer's (x-mirrored) world.
pub fn mirror(v: [f64; 3]) -> [f64; 3] {
    [-v[0], v[1], v[2]]
}

/// The SSR camera of a perspective kernel camera, in the mirrored world, with near plane `near`.
pub fn ssr_camera(c: &Camera, near: f32) -> Result<SsrCamera> {
    if c.kind == ORTHOGRAPHIC {
        bail!("--gbuffer needs a perspective camera (the SSR pipelines project perspectively); the chosen camera is orthographic");
    }
    let v = |a: shader_core::Vec3| mirror([a.x as f64, a.y as f64, a.z as f64]);
    let eye = v(c.origin);
    let rows = [v(c.right), v(c.up), v(c.forward)];
    let mut m = [0.0f32; 16];
    for (i, r) in rows.iter().enumerate() {
        for k in 0..3 {
            m[4 * i + k] = r[k] as f32;
        }
        m[4 * i + 3] = -(r[0] * eye[0] + r[1] * eye[1] + r[2] * eye[2]) as f32;
    }
    m[15] = 1.0;
    let cam = SsrCamera { world_to_view: m, fov_y_degrees: (2.0 * (c.scale_y as f64).atan()).to_degrees() as f32, near };
    cam.validate("camera")?;
    Ok(cam)
}

/// `spec` turned by `degrees` about +y through `pivot`.
pub fn orbit(spec: &CameraSpec, pivot: [f32; 3], degrees: f64) -> CameraSpec {
    let (s, c) = degrees.to_radians().sin_cos();
    let rot = |a: [f32; 3]| -> [f32; 3] {
        let (x, z) = (a[0] as f64, a[2] as f64);
        [(c * x + s * z) as f32, a[1], (-s * x + c * z) as f32]
    };
    let rel = [spec.position[0] - pivot[0], spec.position[1] - pivot[1], spec.position[2] - pivot[2]];
    let r = rot(rel);
    CameraSpec {
        position: [r[0] + pivot[0], r[1] + pivot[1], r[2] + pivot[2]],
        forward: rot(spec.forward),
        up: rot(spec.up),
        ..spec.clone()
    }
}

/// What [`to_ssr`] needs besides the kernel output.
pub struct Frames {
    /// SSR cameras of this and the previous frame.
    pub ssr_camera: SsrCamera,
    pub ssr_previous: SsrCamera,
    /// The previous frame's colour (interleaved RGB).
    pub color: Vec<f32>,
    /// The on-screen reference's fallback radiance.
    pub fallback: [f32; 3],
}

/// The G-buffer (and, with reference samples, the reference) of the kernel output `g`.
/// `reference` names the reference entry the G-buffer's JSON will carry.
pub fn to_ssr(g: &GBufferSums, f: Frames, reference: Option<ReferenceFile>) -> Result<(GBuffer, Option<Reference>)> {
    let (w, h) = (g.width as usize, g.height as usize);
    let n = w * h;
    if f.color.len() != 3 * n {
        bail!("colour buffer has {} values for {w}x{h}", f.color.len());
    }
    let mut gb = GBuffer {
        width: w,
        height: h,
        depth: Vec::with_capacity(n),
        depth_far: Some(Vec::with_capacity(n)),
        normal: Vec::with_capacity(3 * n),
        roughness: Vec::with_capacity(n),
        metalness: Vec::with_capacity(n),
        base_color: Vec::with_capacity(3 * n),
        color: f.color,
        motion: Vec::with_capacity(2 * n),
        camera: f.ssr_camera,
        previous_camera: f.ssr_previous,
        fallback: f.fallback,
        reference: if g.samples > 0 { reference } else { None },
    };
    let mut r = Reference {
        width: w,
        height: h,
        all: Vec::with_capacity(3 * n),
        onscreen: Vec::with_capacity(3 * n),
        specular_all: Vec::with_capacity(3 * n),
        specular_onscreen: Vec::with_capacity(3 * n),
        onscreen_fraction: Vec::with_capacity(n),
        glossy: Vec::with_capacity(n),
        mirror_hit: vec![f32::NAN; 2 * n],
        samples: g.samples,
    };
    for (i, px) in g.values.chunks_exact(GBUFFER_STRIDE).enumerate() {
        let (sx, sy) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
        let depth = px[0];
        gb.depth.push(depth);
        let nm = mirror([px[1] as f64, px[2] as f64, px[3] as f64]);
        gb.normal.extend(nm.map(|v| v as f32));
        gb.roughness.push(px[4]);
        gb.metalness.push(px[5]);
        gb.base_color.extend_from_slice(&px[6..9]);
        let point = depth.is_finite().then(|| f.ssr_camera.unproject(w, h, sx, sy, depth as f64));
        gb.motion.extend(f.ssr_camera.motion(&f.ssr_previous, w, h, sx, sy, point));
        let glossy = px[9] != 0.0;
        gb.depth_far.as_mut().expect("allocated above").push(px[10]);
        let (weight, same, samples) = (px[23], px[24], px[25]);
        if !glossy || !(weight > 0.0) {
            r.all.extend_from_slice(&f.fallback);
            r.onscreen.extend_from_slice(&f.fallback);
            r.specular_all.extend_from_slice(&[0.0; 3]);
            r.specular_onscreen.extend_from_slice(&[0.0; 3]);
            r.onscreen_fraction.push(if glossy { 1.0 } else { 0.0 });
        } else {
            r.all.extend(px[11..14].iter().map(|v| v / weight));
            r.onscreen.extend(px[14..17].iter().map(|v| v / weight));
            r.specular_all.extend(px[17..20].iter().map(|v| v / samples));
            r.specular_onscreen.extend(px[20..23].iter().map(|v| v / samples));
            r.onscreen_fraction.push(same / weight);
        }
        r.glossy.push(glossy);
    }
    gb.validate().context("the exported G-buffer")?;
    Ok((gb, (g.samples > 0).then_some(r)))
}
