//! Unidirectional path tracing with next-event estimation and multiple importance sampling
//! (Veach 1997, chapter 9, the power heuristic with beta = 2; PBRT-v4 section 13.4
//! `PathIntegrator`), Russian roulette (PBRT-v4 section 13.1.7), the random numbers of each pixel
//! sample drawn from a [`Sampler`] (Owen-scrambled Sobol or PCG32; they depend only on (seed,
//! pixel, sample index), so a progressive render gives the same image however its samples are
//! split into launches).
//!
//! Estimators (`strategy`): [`STRATEGY_MIS`] combines light sampling and BSDF sampling with the
//! power heuristic; [`STRATEGY_BSDF`] only follows BSDF samples (punctual lights, which no ray can
//! hit, then contribute nothing); [`STRATEGY_LIGHT`] only samples lights at non-Dirac vertices
//! (emitters seen through Dirac lobes, e.g. in a mirror, are still counted). All three converge
//! to the same image on scenes without punctual lights.
//!
//! ```
//! use shader_core::pt::integrator::power_heuristic;
//! // The power heuristic weights of two strategies sum to 1; equal densities split evenly.
//! assert_eq!(power_heuristic(2.0, 2.0), 0.5);
//! assert!((power_heuristic(3.0, 1.0) + power_heuristic(1.0, 3.0) - 1.0).abs() < 1e-7);
//! ```

use super::bvh;
use super::camera::Camera;
use super::environment;
use super::light;
use super::material::Material;
use super::ray::{offset_origin, Ray};
use super::sampler::Sampler;
use super::scene::NONE;
use super::surface;
use crate::bxdf::SPECULAR;
use crate::ieee;
use crate::math;
use crate::vector::Vec3;

/// MIS: light and BSDF sampling, power heuristic.
pub const STRATEGY_MIS: u32 = 0;
/// BSDF sampling only.
pub const STRATEGY_BSDF: u32 = 1;
/// Light sampling only (BSDF sampling still extends the path).
pub const STRATEGY_LIGHT: u32 = 2;

/// Shadow rays towards area lights stop this fraction short of the sampled point.
pub const SHADOW_EPSILON: f32 = 1e-3;

/// What one pixel is rendered with: a `#[repr(C)]` record of 4-byte fields that the host
/// uploads as it is (inside `shader_kernels::render::RenderArgs`), so host and kernel share one
/// definition.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct RenderParams {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel in this launch.
    pub spp: u32,
    /// Index of this launch's first sample (earlier launches rendered 0..sample_base).
    pub sample_base: u32,
    /// Seed of the whole render.
    pub seed: u32,
    /// Longest path, in bounces (1 = direct lighting only).
    pub max_depth: u32,
    /// First bounce at which Russian roulette may end a path.
    pub rr_depth: u32,
    /// [`STRATEGY_MIS`], [`STRATEGY_BSDF`] or [`STRATEGY_LIGHT`].
    pub strategy: u32,
    /// Energy compensation (`shader_core::energy::COMP_*`).
    pub compensation: u32,
    /// The random numbers: [`super::sampler::SAMPLER_SOBOL`] or [`super::sampler::SAMPLER_PCG`].
    pub sampler: u32,
    /// Largest per-sample radiance component (0 = no clamping; clamping is biased).
    pub clamp: f32,
    /// Probability of sampling the environment in next-event estimation (the rest goes to the
    /// scene's lights; 1 when the scene has none, 0 for a black environment).
    pub p_env: f32,
    /// The camera.
    pub camera: Camera,
}

/// The sums over one launch's samples of one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelSums {
    /// Radiance.
    pub color: Vec3,
    /// First-hit base colour (0 for a miss).
    pub albedo: Vec3,
    /// First-hit world shading normal (0 for a miss).
    pub normal: Vec3,
    /// First-hit depth along the camera's forward axis (0 for a miss).
    pub depth: f32,
    /// Rays traced: closest-hit rays (primary and secondary) plus shadow rays.
    pub rays: f32,
}

impl PixelSums {
    /// f32 words of the record in a buffer: colour, albedo, normal (3 each), depth, rays.
    pub const WORDS: usize = 11;

    /// Write the record at `out[o..o + WORDS]` (the render kernel's output).
    #[inline]
    pub fn store(&self, out: &mut [f32], o: usize) {
        crate::buffer::store_vec3(out, o, self.color);
        crate::buffer::store_vec3(out, o + 3, self.albedo);
        crate::buffer::store_vec3(out, o + 6, self.normal);
        crate::buffer::store(out, o + 9, self.depth);
        crate::buffer::store(out, o + 10, self.rays);
    }

    /// The record at `buf[o..o + WORDS]` (the host reading a launch's output).
    #[inline]
    pub fn load(buf: &[f32], o: usize) -> PixelSums {
        PixelSums {
            color: crate::buffer::load_vec3(buf, o),
            albedo: crate::buffer::load_vec3(buf, o + 3),
            normal: crate::buffer::load_vec3(buf, o + 6),
            depth: crate::buffer::load(buf, o + 9),
            rays: crate::buffer::load(buf, o + 10),
        }
    }
}

/// Power heuristic weight of a sample with density `a` against `b` (beta = 2).
#[inline]
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if !(a2 < f32::INFINITY) {
        return 1.0;
    }
    if !(a2 + b2 > 0.0) {
        return 0.0;
    }
    ieee::div(a2, a2 + b2)
}

#[inline]
fn is_black(v: Vec3) -> bool {
    v.x == 0.0 && v.y == 0.0 && v.z == 0.0
}

#[inline]
fn max_component(v: Vec3) -> f32 {
    math::max(math::max(v.x, v.y), v.z)
}

/// Density with which next-event estimation picks direction `wi` towards the environment
/// (solid angle, selection included).
#[inline]
fn env_light_pdf(env: &[f32], p: &RenderParams, wi: Vec3) -> f32 {
    p.p_env * environment::pdf(env, wi)
}

/// One path from a primary ray: (radiance, first-hit sums).
#[inline]
pub fn trace_path(sc: &[u32], env: &[f32], lut: &[f32], p: &RenderParams, primary: Ray, sampler: &mut Sampler) -> PixelSums {
    let mut out = PixelSums::default();
    let mut ray = primary;
    let mut beta = Vec3::new(1.0, 1.0, 1.0);
    let mut l = Vec3::ZERO;
    let mut prev_specular = 1u32;
    let mut prev_pdf = 0.0f32;
    let mut prev_p = primary.o;
    let mut depth = 0u32;
    loop {
        let hit = bvh::closest_hit(sc, &ray, f32::INFINITY);
        out.rays = out.rays + 1.0;
        if hit.tri == NONE {
            let le = environment::radiance(env, ray.d);
            if !is_black(le) {
                let w = if prev_specular != 0 || p.strategy == STRATEGY_BSDF {
                    1.0
                } else if p.strategy == STRATEGY_LIGHT {
                    0.0
                } else {
                    power_heuristic(prev_pdf, env_light_pdf(env, p, ray.d))
                };
                l = l + beta.mul_elem(le) * w;
            }
            break;
        }
        let sp = surface::surface_point(sc, hit.tri, hit.b1, hit.b2, ray.d);
        if depth == 0 {
            out.albedo = sp.material.base;
            out.normal = sp.ns;
            out.depth = p.camera.depth(primary.d, hit.t);
        }
        let le = light::emitted(&sp);
        if !is_black(le) {
            let w = if prev_specular != 0 || p.strategy == STRATEGY_BSDF {
                1.0
            } else if p.strategy == STRATEGY_LIGHT || sp.light == NONE {
                0.0
            } else {
                let pl = (1.0 - p.p_env) * light::selection_pdf(sc, sp.light) * light::triangle_pdf(sc, sp.light, prev_p, sp.p, sp.ng);
                power_heuristic(prev_pdf, pl)
            };
            l = l + beta.mul_elem(le) * w;
        }
        if depth >= p.max_depth {
            break;
        }
        let wo = sp.to_local(-ray.d);
        let mat = Material::new(&sp.material, wo, lut, p.compensation);

        // Next-event estimation.
        let u_sel = sampler.next_1d();
        let (u0, u1) = sampler.next_2d();
        if p.strategy != STRATEGY_BSDF && !mat.is_specular() {
            let mut ls = light::LightSample::NONE;
            let mut p_sel = 0.0;
            if u_sel < p.p_env {
                let es = environment::sample(env, u0, u1);
                ls = light::LightSample { li: es.li, wi: es.wi, dist: f32::INFINITY, pdf: es.pdf, delta: 0 };
                p_sel = p.p_env;
            } else if light::count(sc) > 0 {
                let u = math::min(ieee::div(u_sel - p.p_env, 1.0 - p.p_env), 0.99999994);
                let (li, sel) = light::select(sc, u);
                ls = light::sample(sc, li, sp.p, u0, u1);
                p_sel = (1.0 - p.p_env) * sel;
            }
            let p_light = p_sel * ls.pdf;
            if p_light > 0.0 && !is_black(ls.li) {
                let wi = sp.to_local(ls.wi);
                let f = mat.f(wo, wi, lut);
                if !is_black(f) {
                    let t_max = if ls.delta != 0 || ls.dist == f32::INFINITY { ls.dist } else { ls.dist * (1.0 - SHADOW_EPSILON) };
                    let shadow = Ray::new(offset_origin(sp.p, sp.ng, ls.wi), ls.wi);
                    out.rays = out.rays + 1.0;
                    if !bvh::occluded(sc, &shadow, t_max) {
                        let w = if ls.delta != 0 || p.strategy == STRATEGY_LIGHT { 1.0 } else { power_heuristic(p_light, mat.pdf(wo, wi)) };
                        l = l + beta.mul_elem(f).mul_elem(ls.li) * ieee::div(wi.z.abs() * w, p_light);
                    }
                }
            }
        }

        // Continue the path by sampling the BSDF.
        let uc = sampler.next_1d();
        let (b0, b1) = sampler.next_2d();
        let bs = mat.sample(wo, uc, b0, b1, lut);
        if !bs.is_valid() || !(bs.pdf > 0.0) {
            break;
        }
        let wi = sp.to_world(bs.wi);
        beta = beta.mul_elem(bs.f) * ieee::div(bs.wi.z.abs(), bs.pdf);
        prev_specular = if bs.flags & SPECULAR != 0 { 1 } else { 0 };
        prev_pdf = bs.pdf;
        prev_p = sp.p;
        depth += 1;
        if depth >= p.rr_depth {
            let q = math::max(0.05, 1.0 - max_component(beta));
            if sampler.next_1d() < q {
                break;
            }
            beta = beta / (1.0 - q);
        }
        if is_black(beta) {
            break;
        }
        ray = Ray::new(offset_origin(sp.p, sp.ng, wi), wi);
    }
    if p.clamp > 0.0 {
        let m = max_component(l);
        if m > p.clamp {
            l = l * ieee::div(p.clamp, m);
        }
    }
    out.color = l;
    out
}

/// The sums over samples `sample_base .. sample_base + spp` of pixel `pixel` (row-major, from
/// the top-left): jittered primary rays through the pixel (box filter), one path each.
#[inline]
pub fn render_pixel(sc: &[u32], env: &[f32], lut: &[f32], p: &RenderParams, pixel: u32) -> PixelSums {
    let (x, y) = (pixel % p.width, pixel / p.width);
    let mut sums = PixelSums::default();
    let mut s = 0;
    while s < p.spp {
        let mut sampler = Sampler::new(p.sampler, p.seed, pixel, p.sample_base + s);
        let (jx, jy) = sampler.next_2d();
        let primary = p.camera.ray(x as f32 + jx, y as f32 + jy, p.width, p.height);
        let r = trace_path(sc, env, lut, p, primary, &mut sampler);
        sums.color = sums.color + r.color;
        sums.albedo = sums.albedo + r.albedo;
        sums.normal = sums.normal + r.normal;
        sums.depth = sums.depth + r.depth;
        sums.rays = sums.rays + r.rays;
        s += 1;
    }
    sums
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_heuristic_limits() {
        assert_eq!(power_heuristic(1.0, 0.0), 1.0);
        assert_eq!(power_heuristic(0.0, 1.0), 0.0);
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert_eq!(power_heuristic(f32::INFINITY, 1.0), 1.0);
        assert!((power_heuristic(1.0, 1.0) - 0.5).abs() < 1e-7);
        assert!((power_heuristic(2.0, 1.0) + power_heuristic(1.0, 2.0) - 1.0).abs() < 1e-6);
    }
}
