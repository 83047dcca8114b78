//! The microfacet functions behind `host eval` (ids 100..=199): NDFs and roughness
//! parameterizations, Beckmann Lambda/G1, G2 forms and visibility terms of
//! `shader_core::{ndf, masking}` (GGX D, Lambda and G1 keep their ids 1..=3 in [`crate::table`]).
//! Their `FunctionInfo` entries are in [`crate::table::FUNCTIONS`]; `docs/microfacet.md` documents
//! every function, its source and its invalid-input behaviour.

use shader_core::{masking, ndf, Vec3};

pub const FIRST: u32 = 100;
pub const BECKMANN_D: u32 = 100;
pub const BLINN_PHONG_D: u32 = 101;
pub const BLINN_PHONG_EXPONENT: u32 = 102;
pub const BLINN_PHONG_ALPHA: u32 = 103;
pub const GTR1_D: u32 = 104;
pub const GTR2_D: u32 = 105;
pub const DISNEY_ANISO_ALPHA: u32 = 106;
pub const GGX_D_UE4: u32 = 107;
pub const GGX_D_MOBILE_NAIVE: u32 = 108;
pub const GGX_D_MOBILE: u32 = 109;
pub const BECKMANN_LAMBDA: u32 = 120;
pub const BECKMANN_G1: u32 = 121;
pub const BECKMANN_LAMBDA_WALTER: u32 = 122;
pub const BECKMANN_G1_WALTER: u32 = 123;
pub const GGX_G2_SEPARABLE: u32 = 130;
pub const GGX_G2_HEIGHT_CORRELATED: u32 = 131;
pub const GGX_G2_DIRECTION_CORRELATED: u32 = 132;
pub const GGX_G2_HEIGHT_DIRECTION_CORRELATED: u32 = 133;
pub const BECKMANN_G2_HEIGHT_CORRELATED: u32 = 134;
pub const V_FROSTBITE: u32 = 150;
pub const V_HDRP: u32 = 151;
pub const V_HDRP_APPROX: u32 = 152;
pub const V_UE4: u32 = 153;
pub const V_FILAMENT: u32 = 154;
pub const V_FILAMENT_FAST: u32 = 155;
pub const V_RESPAWN: u32 = 156;
pub const V_IMPLICIT: u32 = 157;
pub const V_NEUMANN: u32 = 158;
pub const V_KELEMEN: u32 = 159;
pub const V_SCHLICK_SMITH: u32 = 160;
pub const V_SCHLICK_SMITH_REMAPPED: u32 = 161;
pub const V_COOK_TORRANCE: u32 = 162;
pub const LAST: u32 = 199;

#[inline]
fn v3(x: &[f32], b: usize) -> Vec3 {
    Vec3::new(x[b], x[b + 1], x[b + 2])
}

/// Evaluate microfacet function `id` (in `FIRST..=LAST`) on the row at `x[xb]`, writing from `y[yb]`.
/// An unknown id writes nothing.
#[inline]
pub fn eval_row(id: u32, x: &[f32], xb: usize, y: &mut [f32], yb: usize) {
    match id {
        BECKMANN_D => y[yb] = ndf::beckmann_d(v3(x, xb), x[xb + 3], x[xb + 4]),
        BLINN_PHONG_D => y[yb] = ndf::blinn_phong_d(v3(x, xb), x[xb + 3]),
        BLINN_PHONG_EXPONENT => y[yb] = ndf::blinn_phong_exponent_from_alpha(x[xb]),
        BLINN_PHONG_ALPHA => y[yb] = ndf::blinn_phong_alpha_from_exponent(x[xb]),
        GTR1_D => y[yb] = ndf::gtr1_d(v3(x, xb), x[xb + 3]),
        GTR2_D => y[yb] = ndf::gtr2_d(v3(x, xb), x[xb + 3]),
        DISNEY_ANISO_ALPHA => {
            let (ax, ay) = ndf::disney_aniso_alphas(x[xb], x[xb + 1]);
            y[yb] = ax;
            y[yb + 1] = ay;
        }
        GGX_D_UE4 => y[yb] = ndf::ggx_d_ue4(x[xb], x[xb + 1]),
        GGX_D_MOBILE_NAIVE => y[yb] = ndf::ggx_d_mobile_naive(x[xb], x[xb + 1]),
        GGX_D_MOBILE => y[yb] = ndf::ggx_d_mobile(v3(x, xb), x[xb + 3]),
        BECKMANN_LAMBDA => y[yb] = masking::beckmann_lambda(v3(x, xb), x[xb + 3], x[xb + 4]),
        BECKMANN_G1 => y[yb] = masking::beckmann_g1(v3(x, xb), x[xb + 3], x[xb + 4]),
        BECKMANN_LAMBDA_WALTER => y[yb] = masking::beckmann_lambda_walter(v3(x, xb), x[xb + 3], x[xb + 4]),
        BECKMANN_G1_WALTER => y[yb] = masking::beckmann_g1_walter(v3(x, xb), x[xb + 3], x[xb + 4]),
        GGX_G2_SEPARABLE => y[yb] = masking::ggx_g2_separable(v3(x, xb), v3(x, xb + 3), x[xb + 6], x[xb + 7]),
        GGX_G2_HEIGHT_CORRELATED => y[yb] = masking::ggx_g2_height_correlated(v3(x, xb), v3(x, xb + 3), x[xb + 6], x[xb + 7]),
        GGX_G2_DIRECTION_CORRELATED => y[yb] = masking::ggx_g2_direction_correlated(v3(x, xb), v3(x, xb + 3), x[xb + 6], x[xb + 7]),
        GGX_G2_HEIGHT_DIRECTION_CORRELATED => {
            y[yb] = masking::ggx_g2_height_direction_correlated(v3(x, xb), v3(x, xb + 3), x[xb + 6], x[xb + 7])
        }
        BECKMANN_G2_HEIGHT_CORRELATED => {
            y[yb] = masking::beckmann_g2_height_correlated(v3(x, xb), v3(x, xb + 3), x[xb + 6], x[xb + 7])
        }
        V_FROSTBITE => y[yb] = masking::v_frostbite(x[xb], x[xb + 1], x[xb + 2]),
        V_HDRP => y[yb] = masking::v_hdrp(x[xb], x[xb + 1], x[xb + 2]),
        V_HDRP_APPROX => y[yb] = masking::v_hdrp_approx(x[xb], x[xb + 1], x[xb + 2]),
        V_UE4 => y[yb] = masking::v_ue4(x[xb], x[xb + 1], x[xb + 2]),
        V_FILAMENT => y[yb] = masking::v_filament(x[xb], x[xb + 1], x[xb + 2]),
        V_FILAMENT_FAST => y[yb] = masking::v_filament_fast(x[xb], x[xb + 1], x[xb + 2]),
        V_RESPAWN => y[yb] = masking::v_respawn(x[xb], x[xb + 1], x[xb + 2]),
        V_IMPLICIT => y[yb] = masking::v_implicit(x[xb], x[xb + 1]),
        V_NEUMANN => y[yb] = masking::v_neumann(x[xb], x[xb + 1]),
        V_KELEMEN => y[yb] = masking::v_kelemen(x[xb]),
        V_SCHLICK_SMITH => y[yb] = masking::v_schlick_smith(x[xb], x[xb + 1], x[xb + 2]),
        V_SCHLICK_SMITH_REMAPPED => y[yb] = masking::v_schlick_smith_remapped(x[xb], x[xb + 1], x[xb + 2]),
        V_COOK_TORRANCE => y[yb] = masking::v_cook_torrance(x[xb], x[xb + 1], x[xb + 2], x[xb + 3]),
        _ => {}
    }
}
