//! The registry of functions that can be evaluated over a table of rows (`host eval`), and the
//! per-row kernel shared by the CPU and GPU backends.
//!
//! Column conventions: directions are split into `_x,_y,_z` columns in the local shading frame
//! (normal = +z); every NDF and masking function takes `alpha_x, alpha_y`.

use shader_core::{masking, ndf, Vec3};
use spirv_std::num_traits::Float;

/// One evaluable function: its id (the value the kernel dispatches on), name and columns.
#[derive(Clone, Copy, Debug)]
pub struct FunctionInfo {
    pub id: u32,
    pub name: &'static str,
    pub summary: &'static str,
    pub inputs: &'static [&'static str],
    pub outputs: &'static [&'static str],
}

pub const GGX_D: u32 = 1;
pub const GGX_LAMBDA: u32 = 2;
pub const GGX_G1: u32 = 3;
pub const ARITH_PROBE: u32 = 4;

/// Every function [`eval_row`] knows, in id order.
pub const FUNCTIONS: &[FunctionInfo] = &[
    FunctionInfo {
        id: GGX_D,
        name: "ggx_d",
        summary: "GGX/Trowbridge-Reitz NDF D(wm), anisotropic (Heitz 2014 eq. 85)",
        inputs: &["wm_x", "wm_y", "wm_z", "alpha_x", "alpha_y"],
        outputs: &["d"],
    },
    FunctionInfo {
        id: GGX_LAMBDA,
        name: "ggx_lambda",
        summary: "GGX Smith Lambda(w) (Heitz 2014 eq. 86)",
        inputs: &["w_x", "w_y", "w_z", "alpha_x", "alpha_y"],
        outputs: &["lambda"],
    },
    FunctionInfo {
        id: GGX_G1,
        name: "ggx_g1",
        summary: "GGX Smith masking G1(w) = 1 / (1 + Lambda(w))",
        inputs: &["w_x", "w_y", "w_z", "alpha_x", "alpha_y"],
        outputs: &["g1"],
    },
    FunctionInfo {
        id: ARITH_PROBE,
        name: "arith_probe",
        summary: "The basic operations every kernel is built from: a+b, a-b, a*b, a/b, sqrt(a), 1/sqrt(a)",
        inputs: &["a", "b"],
        outputs: &["sum", "difference", "product", "quotient", "sqrt", "rsqrt"],
    },
];

#[inline]
fn v3(x: &[f32], b: usize) -> Vec3 {
    Vec3::new(x[b], x[b + 1], x[b + 2])
}

/// Evaluate function `id` on the row starting at `x[xb]`, writing its outputs from `y[yb]`.
/// An unknown id writes nothing.
#[inline]
pub fn eval_row(id: u32, x: &[f32], xb: usize, y: &mut [f32], yb: usize) {
    match id {
        GGX_D => y[yb] = ndf::ggx_d(v3(x, xb), x[xb + 3], x[xb + 4]),
        GGX_LAMBDA => y[yb] = masking::ggx_lambda(v3(x, xb), x[xb + 3], x[xb + 4]),
        GGX_G1 => y[yb] = masking::ggx_g1(v3(x, xb), x[xb + 3], x[xb + 4]),
        ARITH_PROBE => {
            let (a, b) = (x[xb], x[xb + 1]);
            y[yb] = a + b;
            y[yb + 1] = a - b;
            y[yb + 2] = a * b;
            y[yb + 3] = a / b;
            y[yb + 4] = Float::sqrt(a);
            y[yb + 5] = 1.0 / Float::sqrt(a);
        }
        _ => {}
    }
}
