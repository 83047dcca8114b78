//! The GGX NDF and Smith masking the `grid` command maps, the basic arithmetic every kernel is
//! built from, and the project's own elementary functions (shader-core/MATH.md).

use shader_core::{ieee, masking, math, ndf};

crate::evaluable! { group = "basic";
    ggx_d "GGX/Trowbridge-Reitz NDF D(wm), anisotropic (Heitz 2014 eq. 85)"
        (wm: Vec3, alpha_x: f32, alpha_y: f32) -> (d: f32) { ndf::ggx_d(wm, alpha_x, alpha_y) }
    ggx_lambda "GGX Smith Lambda(w) (Heitz 2014 eq. 86)"
        (w: Vec3, alpha_x: f32, alpha_y: f32) -> (lambda: f32) { masking::ggx_lambda(w, alpha_x, alpha_y) }
    ggx_g1 "GGX Smith masking G1(w) = 1 / (1 + Lambda(w))"
        (w: Vec3, alpha_x: f32, alpha_y: f32) -> (g1: f32) { masking::ggx_g1(w, alpha_x, alpha_y) }
    arith_probe "The basic operations every kernel is built from: a+b, a-b, a*b, and the correctly rounded a/b, sqrt(a), 1/sqrt(a) of shader_core::ieee"
        (a: f32, b: f32) -> (sum: f32, difference: f32, product: f32, quotient: f32, sqrt: f32, rsqrt: f32) {
            (a + b, a - b, a * b, ieee::div(a, b), ieee::sqrt(a), ieee::rsqrt(a))
        }
    math_unary "The project's own one-argument elementary functions (shader-core math, shader-core/MATH.md)"
        (x: f32) -> (sin: f32, cos: f32, tan: f32, atan: f32, asin: f32, acos: f32, exp: f32, exp2: f32,
                     expm1: f32, log: f32, log2: f32, log1p: f32, erf: f32, erfc: f32) {
            (
                math::sin(x), math::cos(x), math::tan(x), math::atan(x), math::asin(x), math::acos(x),
                math::exp(x), math::exp2(x), math::expm1(x), math::log(x), math::log2(x), math::log1p(x),
                math::erf(x), math::erfc(x),
            )
        }
    math_binary "The project's own two-argument elementary functions: atan2(y, x) and pow(x, y)"
        (x: f32, y: f32) -> (atan2: f32, pow: f32) { (math::atan2(y, x), math::pow(x, y)) }
}
