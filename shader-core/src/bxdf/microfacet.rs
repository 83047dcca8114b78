//! The Trowbridge-Reitz (GGX) microfacet distribution as the BxDFs use it (PBRT-v4
//! `TrowbridgeReitzDistribution`, section 9.6): D from [`crate::ndf::ggx_d`], Lambda and G1 from
//! [`crate::masking`], the height-correlated G, and visible-normal sampling from [`crate::vndf`].
//!
//! ```
//! use shader_core::bxdf::microfacet::{roughness_to_alpha, TrowbridgeReitz};
//! use shader_core::Vec3;
//! let tr = TrowbridgeReitz::new(roughness_to_alpha(0.5), roughness_to_alpha(0.5));
//! assert_eq!(tr.alpha_x, 0.25);
//! // The same values as the free functions it wraps.
//! assert_eq!(tr.d(Vec3::Z), shader_core::ndf::ggx_d(Vec3::Z, 0.25, 0.25));
//! // Height-correlated G: 1 along the normal, 0 at grazing.
//! assert_eq!(tr.g(Vec3::Z, Vec3::Z), 1.0);
//! assert_eq!(tr.g(Vec3::Z, Vec3::new(1.0, 0.0, 0.0)), 0.0);
//! assert!(!tr.effectively_smooth() && TrowbridgeReitz::new(1e-4, 5e-4).effectively_smooth());
//! assert!(!TrowbridgeReitz::new(-1.0, 0.1).is_valid());
//! ```

use crate::masking;
use crate::ndf;
use crate::vector::Vec3;
use crate::vndf;

use super::SMOOTH_ALPHA;

/// Anisotropic GGX with roughness `alpha_x`, `alpha_y` (valid: 0 <= alpha < inf).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrowbridgeReitz {
    /// Roughness alpha along the tangent (x) axis.
    pub alpha_x: f32,
    /// Roughness alpha along the bitangent (y) axis.
    pub alpha_y: f32,
}

impl TrowbridgeReitz {
    /// The distribution with these alphas, stored as given (check with [`TrowbridgeReitz::is_valid`]).
    #[inline]
    pub fn new(alpha_x: f32, alpha_y: f32) -> Self {
        TrowbridgeReitz { alpha_x, alpha_y }
    }

    /// Both alphas are finite and >= 0 (NaN, negative and infinite are invalid).
    #[inline]
    pub fn is_valid(&self) -> bool {
        ndf::alpha_valid(self.alpha_x, self.alpha_y)
    }

    /// max(alpha_x, alpha_y) < 1e-3: treat as a perfect mirror / perfect refractor (PBRT-v4
    /// `EffectivelySmooth`).
    #[inline]
    pub fn effectively_smooth(&self) -> bool {
        self.alpha_x < SMOOTH_ALPHA && self.alpha_y < SMOOTH_ALPHA
    }

    /// D(wm), Heitz 2014 eq. 85 ([`ndf::ggx_d`]); 0 for wm.z <= 0.
    #[inline]
    pub fn d(&self, wm: Vec3) -> f32 {
        ndf::ggx_d(wm, self.alpha_x, self.alpha_y)
    }

    /// Smith Lambda(w), Heitz 2014 eq. 86 ([`masking::ggx_lambda`]).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        masking::ggx_lambda(w, self.alpha_x, self.alpha_y)
    }

    /// Smith G1(w) = 1 / (1 + Lambda(w)), Heitz 2014 eq. 43 ([`masking::ggx_g1`]).
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        masking::ggx_g1(w, self.alpha_x, self.alpha_y)
    }

    /// Height-correlated Smith G2(wo, wi) = 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014 eq. 99;
    /// PBRT-v4 eq. 9.27). Lambda = inf at grazing gives 0.
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        masking::g2_height_correlated_from_lambda(self.lambda(wo), self.lambda(wi))
    }

    /// Visible-normal density D_w(wm) (PBRT-v4 eq. 9.23), [`vndf::ggx_visible_pdf`].
    #[inline]
    pub fn pdf(&self, w: Vec3, wm: Vec3) -> f32 {
        vndf::ggx_visible_pdf(w, wm, self.alpha_x, self.alpha_y)
    }

    /// Sample a visible normal (Heitz 2018, [`vndf::ggx_sample_visible_heitz2018`]).
    #[inline]
    pub fn sample_wm(&self, w: Vec3, u0: f32, u1: f32) -> Vec3 {
        vndf::ggx_sample_visible_heitz2018(w, self.alpha_x, self.alpha_y, u0, u1)
    }
}

/// glTF / Disney roughness remapping alpha = roughness^2 (glTF 2.0 spec, appendix B.3.2).
#[inline]
pub fn roughness_to_alpha(roughness: f32) -> f32 {
    roughness * roughness
}
