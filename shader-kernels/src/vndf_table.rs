//! The reflection samplers of `shader_core::vndf` as evaluable functions (ids [`FIRST`]..=[`LAST`];
//! their [`crate::table::FunctionInfo`] entries are in [`crate::table::FUNCTIONS`]; docs/vndf.md).
//!
//! `sample_*`: inputs wi_x, wi_y, wi_z, alpha_x, alpha_y, u1, u2 -> wo_x, wo_y, wo_z, pdf.
//! `pdf_*`: inputs wi_x, wi_y, wi_z, wo_x, wo_y, wo_z, alpha_x, alpha_y -> pdf.

use shader_core::vndf::{self, ReflectionSample};
use shader_core::Vec3;

pub const SAMPLE_NDF: u32 = 400;
pub const SAMPLE_VNDF_HEITZ: u32 = 401;
pub const SAMPLE_VNDF_CAPS: u32 = 402;
pub const SAMPLE_VNDF_BOUNDED: u32 = 403;
pub const PDF_NDF: u32 = 404;
pub const PDF_VNDF_HEITZ: u32 = 405;
pub const PDF_VNDF_CAPS: u32 = 406;
pub const PDF_VNDF_BOUNDED: u32 = 407;

/// The id range evaluated here.
pub const FIRST: u32 = SAMPLE_NDF;
pub const LAST: u32 = PDF_VNDF_BOUNDED;

/// Input columns of the `sample_*` functions.
pub const SAMPLE_INPUTS: &[&str] = &["wi_x", "wi_y", "wi_z", "alpha_x", "alpha_y", "u1", "u2"];
/// Output columns of the `sample_*` functions.
pub const SAMPLE_OUTPUTS: &[&str] = &["wo_x", "wo_y", "wo_z", "pdf"];
/// Input columns of the `pdf_*` functions.
pub const PDF_INPUTS: &[&str] = &["wi_x", "wi_y", "wi_z", "wo_x", "wo_y", "wo_z", "alpha_x", "alpha_y"];
/// Output column of the `pdf_*` functions.
pub const PDF_OUTPUTS: &[&str] = &["pdf"];

#[inline]
fn v3(x: &[f32], b: usize) -> Vec3 {
    Vec3::new(x[b], x[b + 1], x[b + 2])
}

#[inline]
fn put(s: ReflectionSample, y: &mut [f32], yb: usize) {
    y[yb] = s.wo.x;
    y[yb + 1] = s.wo.y;
    y[yb + 2] = s.wo.z;
    y[yb + 3] = s.pdf;
}

/// Evaluate sampler / density `id` on the row at `x[xb]`, writing from `y[yb]`.
#[inline]
pub fn eval_row(id: u32, x: &[f32], xb: usize, y: &mut [f32], yb: usize) {
    let wi = v3(x, xb);
    match id {
        SAMPLE_NDF => put(vndf::sample_ndf(wi, x[xb + 3], x[xb + 4], x[xb + 5], x[xb + 6]), y, yb),
        SAMPLE_VNDF_HEITZ => put(vndf::sample_vndf_heitz(wi, x[xb + 3], x[xb + 4], x[xb + 5], x[xb + 6]), y, yb),
        SAMPLE_VNDF_CAPS => put(vndf::sample_vndf_caps(wi, x[xb + 3], x[xb + 4], x[xb + 5], x[xb + 6]), y, yb),
        SAMPLE_VNDF_BOUNDED => put(vndf::sample_vndf_bounded(wi, x[xb + 3], x[xb + 4], x[xb + 5], x[xb + 6]), y, yb),
        PDF_NDF => y[yb] = vndf::pdf_ndf(wi, v3(x, xb + 3), x[xb + 6], x[xb + 7]),
        PDF_VNDF_HEITZ => y[yb] = vndf::pdf_vndf_heitz(wi, v3(x, xb + 3), x[xb + 6], x[xb + 7]),
        PDF_VNDF_CAPS => y[yb] = vndf::pdf_vndf_caps(wi, v3(x, xb + 3), x[xb + 6], x[xb + 7]),
        PDF_VNDF_BOUNDED => y[yb] = vndf::pdf_vndf_bounded(wi, v3(x, xb + 3), x[xb + 6], x[xb + 7]),
        _ => {}
    }
}
