//! Table rows for the Fresnel functions and BxDFs of `shader_core::fresnel` / `shader_core::bxdf`
//! (ids [`FIRST`]..=[`LAST`]; their [`crate::table::FunctionInfo`] entries are in
//! [`crate::table::FUNCTIONS`]). See docs/bxdf.md.
//!
//! Column conventions: directions `_x,_y,_z` in the local frame (normal = +z); RGB as `_r,_g,_b`;
//! `mode` is 1 for importance transport and anything else for radiance; `flags` is the
//! `BxDFFlags` bit set as a float (0 = no sample); `valid` is 1 or 0.

use shader_core::bxdf::{
    BSDFSample, BxDF, ConductorBxDF, DielectricBxDF, DiffuseBxDF, GltfMetalRoughBxDF, TrowbridgeReitz,
    MODE_IMPORTANCE, MODE_RADIANCE, SAMPLE_ALL,
};
use shader_core::{fresnel, vndf, Vec3};

pub const FRESNEL_DIELECTRIC: u32 = 200;
pub const FRESNEL_CONDUCTOR: u32 = 201;
pub const FRESNEL_SCHLICK: u32 = 202;
pub const GULBRANDSEN_NK: u32 = 203;
pub const GULBRANDSEN_RG: u32 = 204;
pub const REFRACT: u32 = 205;
pub const GGX_VNDF_SAMPLE: u32 = 206;
pub const GGX_VNDF_PDF: u32 = 207;
pub const LAMBERT_F: u32 = 208;
pub const LAMBERT_SAMPLE_F: u32 = 209;
pub const LAMBERT_PDF: u32 = 210;
pub const CONDUCTOR_F: u32 = 211;
pub const CONDUCTOR_SAMPLE_F: u32 = 212;
pub const CONDUCTOR_PDF: u32 = 213;
pub const DIELECTRIC_F: u32 = 214;
pub const DIELECTRIC_SAMPLE_F: u32 = 215;
pub const DIELECTRIC_PDF: u32 = 216;
pub const GLTF_F: u32 = 217;
pub const GLTF_SAMPLE_F: u32 = 218;
pub const GLTF_PDF: u32 = 219;

/// First and last id of this block.
pub const FIRST: u32 = FRESNEL_DIELECTRIC;
pub const LAST: u32 = GLTF_PDF;

#[inline]
fn v3(x: &[f32], b: usize) -> Vec3 {
    Vec3::new(x[b], x[b + 1], x[b + 2])
}

#[inline]
fn put3(y: &mut [f32], b: usize, v: Vec3) {
    y[b] = v.x;
    y[b + 1] = v.y;
    y[b + 2] = v.z;
}

/// wi, f (RGB), pdf, flags.
#[inline]
fn put_sample(y: &mut [f32], b: usize, s: BSDFSample) {
    put3(y, b, s.wi);
    put3(y, b + 3, s.f);
    y[b + 6] = s.pdf;
    y[b + 7] = s.flags as f32;
}

#[inline]
fn mode(m: f32) -> u32 {
    if m == 1.0 {
        MODE_IMPORTANCE
    } else {
        MODE_RADIANCE
    }
}

/// Evaluate one function of this block on the row at `x[xb]`, writing from `y[yb]`.
#[inline]
pub fn eval_row(id: u32, x: &[f32], xb: usize, y: &mut [f32], yb: usize) {
    match id {
        FRESNEL_DIELECTRIC => y[yb] = fresnel::dielectric(x[xb], x[xb + 1]),
        FRESNEL_CONDUCTOR => y[yb] = fresnel::conductor(x[xb], x[xb + 1], x[xb + 2]),
        FRESNEL_SCHLICK => y[yb] = fresnel::schlick(x[xb], x[xb + 1], x[xb + 2]),
        GULBRANDSEN_NK => {
            let nk = fresnel::gulbrandsen_nk(x[xb], x[xb + 1]);
            y[yb] = nk.re;
            y[yb + 1] = nk.im;
        }
        GULBRANDSEN_RG => {
            let rg = fresnel::gulbrandsen_r_g(x[xb], x[xb + 1]);
            y[yb] = rg.r;
            y[yb + 1] = rg.g;
        }
        REFRACT => {
            let r = fresnel::refract(v3(x, xb), v3(x, xb + 3), x[xb + 6]);
            put3(y, yb, r.wt);
            y[yb + 3] = r.etap;
            y[yb + 4] = r.valid as f32;
        }
        GGX_VNDF_SAMPLE => {
            let wm = vndf::ggx_sample_visible_heitz2018(v3(x, xb), x[xb + 3], x[xb + 4], x[xb + 5], x[xb + 6]);
            put3(y, yb, wm);
        }
        GGX_VNDF_PDF => y[yb] = vndf::ggx_visible_pdf(v3(x, xb), v3(x, xb + 3), x[xb + 6], x[xb + 7]),
        LAMBERT_F => {
            let b = DiffuseBxDF::new(v3(x, xb + 6));
            put3(y, yb, b.f(v3(x, xb), v3(x, xb + 3), MODE_RADIANCE));
        }
        LAMBERT_SAMPLE_F => {
            let b = DiffuseBxDF::new(v3(x, xb + 6));
            let s = b.sample_f(v3(x, xb), x[xb + 3], x[xb + 4], x[xb + 5], MODE_RADIANCE, SAMPLE_ALL);
            put_sample(y, yb, s);
        }
        LAMBERT_PDF => {
            let b = DiffuseBxDF::new(Vec3::new(1.0, 1.0, 1.0));
            y[yb] = b.pdf(v3(x, xb), v3(x, xb + 3), MODE_RADIANCE, SAMPLE_ALL);
        }
        CONDUCTOR_F => {
            let b = ConductorBxDF::new(TrowbridgeReitz::new(x[xb + 6], x[xb + 7]), v3(x, xb + 8), v3(x, xb + 11));
            put3(y, yb, b.f(v3(x, xb), v3(x, xb + 3), MODE_RADIANCE));
        }
        CONDUCTOR_SAMPLE_F => {
            let b = ConductorBxDF::new(TrowbridgeReitz::new(x[xb + 6], x[xb + 7]), v3(x, xb + 8), v3(x, xb + 11));
            let s = b.sample_f(v3(x, xb), x[xb + 3], x[xb + 4], x[xb + 5], MODE_RADIANCE, SAMPLE_ALL);
            put_sample(y, yb, s);
        }
        CONDUCTOR_PDF => {
            // The pdf does not depend on the Fresnel parameters: a perfect conductor stands in.
            let b = ConductorBxDF::new(TrowbridgeReitz::new(x[xb + 6], x[xb + 7]), Vec3::ZERO, Vec3::new(1.0, 1.0, 1.0));
            y[yb] = b.pdf(v3(x, xb), v3(x, xb + 3), MODE_RADIANCE, SAMPLE_ALL);
        }
        DIELECTRIC_F => {
            let b = DielectricBxDF::new(TrowbridgeReitz::new(x[xb + 6], x[xb + 7]), x[xb + 8]);
            y[yb] = b.f(v3(x, xb), v3(x, xb + 3), mode(x[xb + 9])).x;
        }
        DIELECTRIC_SAMPLE_F => {
            let b = DielectricBxDF::new(TrowbridgeReitz::new(x[xb + 6], x[xb + 7]), x[xb + 8]);
            let s = b.sample_f(v3(x, xb), x[xb + 3], x[xb + 4], x[xb + 5], mode(x[xb + 9]), SAMPLE_ALL);
            put3(y, yb, s.wi);
            y[yb + 3] = s.f.x;
            y[yb + 4] = s.pdf;
            y[yb + 5] = s.flags as f32;
            y[yb + 6] = s.eta;
        }
        DIELECTRIC_PDF => {
            let b = DielectricBxDF::new(TrowbridgeReitz::new(x[xb + 6], x[xb + 7]), x[xb + 8]);
            y[yb] = b.pdf(v3(x, xb), v3(x, xb + 3), mode(x[xb + 9]), SAMPLE_ALL);
        }
        GLTF_F => {
            let b = GltfMetalRoughBxDF::new(v3(x, xb + 6), x[xb + 9], x[xb + 10]);
            put3(y, yb, b.f(v3(x, xb), v3(x, xb + 3), MODE_RADIANCE));
        }
        GLTF_SAMPLE_F => {
            let b = GltfMetalRoughBxDF::new(v3(x, xb + 6), x[xb + 9], x[xb + 10]);
            let s = b.sample_f(v3(x, xb), x[xb + 3], x[xb + 4], x[xb + 5], MODE_RADIANCE, SAMPLE_ALL);
            put_sample(y, yb, s);
        }
        GLTF_PDF => {
            let b = GltfMetalRoughBxDF::new(v3(x, xb + 6), x[xb + 9], x[xb + 10]);
            y[yb] = b.pdf(v3(x, xb), v3(x, xb + 3), MODE_RADIANCE, SAMPLE_ALL);
        }
        _ => {}
    }
}
