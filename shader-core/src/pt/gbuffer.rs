//! The inputs of screen-space reflections and their ground truth from the path tracer: the
//! first-hit G-buffer through pixel centres, and the normalized glossy reflection SSR estimates,
//! (1 / sum w) sum w L_i(l) over GGX visible-normal samples l (Heitz 2018, listing 1) with
//! w = G2 / G1 = (1 + Lambda(v)) / (1 + Lambda(v) + Lambda(l)) (height-correlated Smith, F = 1),
//! where L_i(l) is path traced ([`integrator::trace_path`]).
//!
//! Each sample is split two ways (the convention of the analytic SSR reference): "all geometry"
//! takes every ray's radiance; "on-screen" keeps it only where the ray escapes or its first hit
//! projects inside the image and is the surface visible there, and takes the fallback radiance
//! otherwise and for escaping rays (what a screen-space method composited over a uniform
//! fallback can at best return). The specular sums weight each sample by Schlick's Fresnel of the
//! glTF metal-rough F0 = mix(0.04, base colour, metallic), F90 = 1, and are divided by the sample
//! count: the specular integral that the reflection times the preintegrated FG term approximates.
//!
//! ```
//! use shader_core::pt::gbuffer::reflection_weight;
//! use shader_core::Vec3;
//! // The weight is 1 at normal incidence and reflection, and falls with grazing directions.
//! let v = Vec3::new(0.0, 0.0, 1.0);
//! assert_eq!(reflection_weight(v, v, 0.5), 1.0);
//! let l = Vec3::new(0.8, 0.0, 0.6);
//! assert!(reflection_weight(v, l, 0.5) < 1.0 && reflection_weight(v, l, 0.5) > 0.0);
//! ```

use super::bvh;
use super::camera::Camera;
use super::integrator::{trace_path, RenderParams, SHADOW_EPSILON};
use super::sampler::Sampler;
use super::ray::{offset_origin, Ray};
use super::scene::{self, NONE};
use super::surface;
use crate::fresnel::{reflect, schlick_rgb};
use crate::ieee;
use crate::masking::ggx_lambda;
use crate::vector::Vec3;
use crate::vndf::sample_vndf_heitz;

/// Mixed into the seed of the reference samples' random streams, so that they are independent
/// of the streams of a render with the same seed (whose image may be the G-buffer's colour).
pub const REFERENCE_SEED: u32 = 0x5bd1_e995;

/// What the G-buffer kernel runs with: a `#[repr(C)]` record of 4-byte fields shared by the
/// host and the kernel (inside `shader_kernels::render::GBufferArgs`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct GBufferParams {
    /// The path tracer's parameters for the reflected rays' radiance; `spp` = reference samples
    /// per pixel in this launch, `sample_base` its first sample index.
    pub render: RenderParams,
    /// Pixels with perceptual roughness above this get no reference samples.
    pub max_roughness: f32,
    /// The fallback radiance of the on-screen reference (the uniform environment SSR composites
    /// over).
    pub fallback: Vec3,
}

/// One pixel: its G-buffer values and the sums of one launch's reference samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GBufferPixel {
    /// Linear view depth (along the camera's forward axis), +inf for the sky.
    pub depth: f32,
    /// Far depth (`host::ssr::gbuffer`'s `depth_far`): the largest linear view depth among the
    /// primary rays through the [`crate::ssr::trace::FAR_DEPTH_GRID`]^2 grid over
    /// [-r, r]^2 px around the centre (r = [`crate::ssr::trace::FAR_DEPTH_RADIUS`]) that hit a
    /// triangle of the centre's material (the scene records no object ids; a material stands for
    /// the object) and at that material's outlines between grid points ([`far_depth`]), at
    /// least `depth`; +inf for the sky. Computed in the launch of sample 0 only (later launches
    /// return `depth` here).
    pub depth_far: f32,
    /// World shading normal (the sky: +y).
    pub normal: Vec3,
    /// Perceptual roughness (the sky: 1).
    pub roughness: f32,
    /// Metallic (the sky: 0).
    pub metallic: f32,
    /// Linear base colour (the sky: 0).
    pub base: Vec3,
    /// 1 when reference samples were taken (geometry, roughness <= the cut-off, facing the
    /// camera), else 0.
    pub glossy: u32,
    /// Sum of w L, all geometry.
    pub all: Vec3,
    /// Sum of w L, on-screen geometry only.
    pub onscreen: Vec3,
    /// Sum of w F L, all geometry.
    pub specular_all: Vec3,
    /// Sum of w F L, on-screen geometry only.
    pub specular_onscreen: Vec3,
    /// Sum of w.
    pub weight: f32,
    /// Sum of w over the samples that are the same both ways (escaped, or a visible on-screen hit).
    pub weight_same: f32,
    /// Samples taken (including those that contribute nothing, e.g. below the horizon).
    pub samples: f32,
    /// Rays traced.
    pub rays: f32,
}

impl GBufferPixel {
    /// f32 words of the record in a buffer: the G-buffer (depth, normal, roughness, metallic,
    /// base colour, glossy, far depth: the same in every launch), then the reference sums from
    /// [`GBufferPixel::FIRST_SUM`] on (added over launches: [`GBufferPixel::add_sums`]).
    pub const WORDS: usize = 27;
    /// Word of the first summed value (`all`).
    pub const FIRST_SUM: usize = 11;

    /// Write the record at `out[o..o + WORDS]` (the G-buffer kernel's output).
    #[inline]
    pub fn store(&self, out: &mut [f32], o: usize) {
        use crate::buffer::{store, store_vec3};
        store(out, o, self.depth);
        store_vec3(out, o + 1, self.normal);
        store(out, o + 4, self.roughness);
        store(out, o + 5, self.metallic);
        store_vec3(out, o + 6, self.base);
        store(out, o + 9, self.glossy as f32);
        store(out, o + 10, self.depth_far);
        store_vec3(out, o + 11, self.all);
        store_vec3(out, o + 14, self.onscreen);
        store_vec3(out, o + 17, self.specular_all);
        store_vec3(out, o + 20, self.specular_onscreen);
        store(out, o + 23, self.weight);
        store(out, o + 24, self.weight_same);
        store(out, o + 25, self.samples);
        store(out, o + 26, self.rays);
    }

    /// The record at `buf[o..o + WORDS]` (the host reading a launch's output).
    #[inline]
    pub fn load(buf: &[f32], o: usize) -> GBufferPixel {
        use crate::buffer::{load, load_vec3};
        GBufferPixel {
            depth: load(buf, o),
            normal: load_vec3(buf, o + 1),
            roughness: load(buf, o + 4),
            metallic: load(buf, o + 5),
            base: load_vec3(buf, o + 6),
            glossy: load(buf, o + 9) as u32,
            depth_far: load(buf, o + 10),
            all: load_vec3(buf, o + 11),
            onscreen: load_vec3(buf, o + 14),
            specular_all: load_vec3(buf, o + 17),
            specular_onscreen: load_vec3(buf, o + 20),
            weight: load(buf, o + 23),
            weight_same: load(buf, o + 24),
            samples: load(buf, o + 25),
            rays: load(buf, o + 26),
        }
    }

    /// Add `o`'s reference sums (the words from [`GBufferPixel::FIRST_SUM`] on) to this
    /// record's, keeping its G-buffer: two launches' samples of one pixel.
    #[inline]
    pub fn add_sums(&mut self, o: &GBufferPixel) {
        self.all = self.all + o.all;
        self.onscreen = self.onscreen + o.onscreen;
        self.specular_all = self.specular_all + o.specular_all;
        self.specular_onscreen = self.specular_onscreen + o.specular_onscreen;
        self.weight += o.weight;
        self.weight_same += o.weight_same;
        self.samples += o.samples;
        self.rays += o.rays;
    }
}

/// G2 / G1 of reflected direction `l` at view direction `v` (both local, `v.z > 0`, `l.z > 0`)
/// for GGX with isotropic `alpha`: the weight of a visible-normal sample in the normalized
/// reflection.
#[inline]
pub fn reflection_weight(v: Vec3, l: Vec3, alpha: f32) -> f32 {
    let lv = ggx_lambda(v, alpha, alpha);
    ieee::div(1.0 + lv, 1.0 + lv + ggx_lambda(l, alpha, alpha))
}

/// Whether world point `p` is the surface seen through its own image position: it projects in
/// front of the camera and inside the image, and nothing lies between the eye and it.
#[inline]
pub fn visible_on_screen(sc: &[u32], camera: &Camera, width: u32, height: u32, p: Vec3) -> bool {
    let (sx, sy, z) = camera.project(p, width, height);
    if !(z > 0.0 && sx >= 0.0 && sy >= 0.0 && sx < width as f32 && sy < height as f32) {
        return false;
    }
    let to = p - camera.origin;
    let dist = to.length();
    !bvh::occluded(sc, &Ray::new(camera.origin, to / dist), dist * (1.0 - SHADOW_EPSILON))
}

/// Bisection steps of [`far_depth`] towards an outline between two grid points (the analytic
/// scenes' `host::ssr::scene::FAR_DEPTH_BISECTIONS`).
pub const FAR_DEPTH_BISECTIONS: u32 = 16;

/// View depth of the first hit of the primary ray through screen point (sx, sy) when it is a
/// triangle of `material`, else -1.
#[inline]
fn far_sample(sc: &[u32], camera: &Camera, width: u32, height: u32, sx: f32, sy: f32, material: u32) -> f32 {
    let ray = camera.ray(sx, sy, width, height);
    let h = bvh::closest_hit(sc, &ray, f32::INFINITY);
    if h.tri != NONE && scene::word(sc, scene::shading(sc, h.tri, scene::S_MATERIAL)) == material {
        camera.depth(ray.d, h.t)
    } else {
        -1.0
    }
}

/// The depth at the outline of `material` between screen points (ax, ay), where the view depth
/// is `za` (-1: not on it), and (bx, by), where it is `zb`: bisection from the point on it
/// towards the other ([`FAR_DEPTH_BISECTIONS`] steps); -1 when both or neither are on it.
/// Also returns the rays cast.
#[allow(clippy::too_many_arguments)]
fn far_outline(sc: &[u32], camera: &Camera, width: u32, height: u32, ax: f32, ay: f32, za: f32, bx: f32, by: f32, zb: f32, material: u32) -> (f32, f32) {
    if (za >= 0.0) == (zb >= 0.0) {
        return (-1.0, 0.0);
    }
    let (mut ix, mut iy, mut ox, mut oy, mut z) = if za >= 0.0 { (ax, ay, bx, by, za) } else { (bx, by, ax, ay, zb) };
    let mut i = 0;
    while i < FAR_DEPTH_BISECTIONS {
        let mx = 0.5 * (ix + ox);
        let my = 0.5 * (iy + oy);
        let zm = far_sample(sc, camera, width, height, mx, my, material);
        if zm >= 0.0 {
            ix = mx;
            iy = my;
            z = zm;
        } else {
            ox = mx;
            oy = my;
        }
        i += 1;
    }
    (z, FAR_DEPTH_BISECTIONS as f32)
}

/// The far depth of pixel (x, y) whose centre ray hit triangle `tri` at depth `depth` (see
/// [`GBufferPixel::depth_far`]), and the number of rays it cast: the grid of
/// [`crate::ssr::trace::FAR_DEPTH_GRID`]^2 primary rays, and between neighbouring grid points of
/// which only one sees the centre's material, the outline found by `far_outline` (the
/// vertical neighbour is cast again rather than stored: kernels keep no indexed local arrays).
#[allow(clippy::too_many_arguments)]
pub fn far_depth(sc: &[u32], camera: &Camera, width: u32, height: u32, x: u32, y: u32, tri: u32, depth: f32) -> (f32, f32) {
    use crate::ssr::trace::{FAR_DEPTH_GRID, FAR_DEPTH_RADIUS};
    let material = scene::word(sc, scene::shading(sc, tri, scene::S_MATERIAL));
    let k = (FAR_DEPTH_GRID - 1) as f32;
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    let mut far = depth;
    let mut rays = 0.0;
    let mut b: u32 = 0;
    while b < FAR_DEPTH_GRID {
        let sy = cy + FAR_DEPTH_RADIUS * (ieee::div(2.0 * b as f32, k) - 1.0);
        let sy_up = cy + FAR_DEPTH_RADIUS * (ieee::div(2.0 * b as f32 - 2.0, k) - 1.0);
        let mut left = -1.0;
        let mut left_x = 0.0;
        let mut a: u32 = 0;
        while a < FAR_DEPTH_GRID {
            let sx = cx + FAR_DEPTH_RADIUS * (ieee::div(2.0 * a as f32, k) - 1.0);
            let z = far_sample(sc, camera, width, height, sx, sy, material);
            rays = rays + 1.0;
            if z > far {
                far = z;
            }
            if a > 0 {
                let (zo, n) = far_outline(sc, camera, width, height, left_x, sy, left, sx, sy, z, material);
                rays = rays + n;
                if zo > far {
                    far = zo;
                }
            }
            if b > 0 {
                let up = far_sample(sc, camera, width, height, sx, sy_up, material);
                rays = rays + 1.0;
                let (zo, n) = far_outline(sc, camera, width, height, sx, sy_up, up, sx, sy, z, material);
                rays = rays + n;
                if zo > far {
                    far = zo;
                }
            }
            left = z;
            left_x = sx;
            a += 1;
        }
        b += 1;
    }
    (far, rays)
}

/// Pixel `pixel` (row-major from the top-left): the first hit through its centre and
/// reference samples `sample_base .. sample_base + spp`.
#[inline]
pub fn gbuffer_pixel(sc: &[u32], env: &[f32], lut: &[f32], p: &GBufferParams, pixel: u32) -> GBufferPixel {
    let r = &p.render;
    let (x, y) = (pixel % r.width, pixel / r.width);
    let primary = r.camera.ray(x as f32 + 0.5, y as f32 + 0.5, r.width, r.height);
    let mut out = GBufferPixel {
        depth: f32::INFINITY,
        depth_far: f32::INFINITY,
        normal: Vec3::new(0.0, 1.0, 0.0),
        roughness: 1.0,
        rays: 1.0,
        ..GBufferPixel::default()
    };
    let hit = bvh::closest_hit(sc, &primary, f32::INFINITY);
    if hit.tri == NONE {
        return out;
    }
    let sp = surface::surface_point(sc, hit.tri, hit.b1, hit.b2, primary.d);
    out.depth = r.camera.depth(primary.d, hit.t);
    // The far depth's rays (about 45 per pixel) are cast in the launch of sample 0 only: every
    // launch returns the same first hit, and the host keeps the first launch's G-buffer.
    if r.sample_base == 0 {
        let (far, far_rays) = far_depth(sc, &r.camera, r.width, r.height, x, y, hit.tri, out.depth);
        out.depth_far = far;
        out.rays = out.rays + far_rays;
    } else {
        out.depth_far = out.depth;
    }
    out.normal = sp.ns;
    out.roughness = sp.material.roughness;
    out.metallic = sp.material.metallic;
    out.base = sp.material.base;
    let v = sp.to_local(-primary.d);
    if !(sp.material.roughness <= p.max_roughness) || !(v.z > 0.0) {
        return out;
    }
    out.glossy = 1;
    let alpha = sp.material.roughness * sp.material.roughness;
    let f0 = Vec3::new(0.04, 0.04, 0.04) + (sp.material.base - Vec3::new(0.04, 0.04, 0.04)) * sp.material.metallic;
    let one = Vec3::new(1.0, 1.0, 1.0);
    let mut s = 0;
    while s < r.spp {
        let mut sampler = Sampler::new(r.sampler, r.seed ^ REFERENCE_SEED, pixel, r.sample_base + s);
        let (u1, u2) = sampler.next_2d();
        s += 1;
        out.samples = out.samples + 1.0;
        let (l, w) = if sp.material.roughness == 0.0 {
            (reflect(v, Vec3::new(0.0, 0.0, 1.0)), 1.0)
        } else {
            let rs = sample_vndf_heitz(v, alpha, alpha, u1, u2);
            if !(rs.pdf > 0.0) || !(rs.wo.z > 0.0) {
                continue;
            }
            (rs.wo, reflection_weight(v, rs.wo, alpha))
        };
        if !(l.z > 0.0) || !(w > 0.0) {
            continue;
        }
        let f = schlick_rgb(v.dot((v + l).normalize()), f0, one);
        let lw = sp.to_world(l);
        let ray = Ray::new(offset_origin(sp.p, sp.ng, lw), lw);
        let first = bvh::closest_hit(sc, &ray, f32::INFINITY);
        out.rays = out.rays + 1.0;
        let li = trace_path(sc, env, lut, r, ray, &mut sampler);
        out.rays = out.rays + li.rays;
        let same = if first.tri == NONE {
            true
        } else {
            out.rays = out.rays + 1.0;
            visible_on_screen(sc, &r.camera, r.width, r.height, ray.at(first.t))
        };
        let on = if same && first.tri != NONE { li.color } else { p.fallback };
        out.all = out.all + li.color * w;
        out.onscreen = out.onscreen + on * w;
        out.specular_all = out.specular_all + f.mul_elem(li.color) * w;
        out.specular_onscreen = out.specular_onscreen + f.mul_elem(on) * w;
        out.weight = out.weight + w;
        if same {
            out.weight_same = out.weight_same + w;
        }
    }
    out
}
