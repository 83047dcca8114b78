//! The Trowbridge-Reitz (GGX) microfacet distribution as the BxDFs use it (PBRT-v4
//! `TrowbridgeReitzDistribution`, section 9.6): D from [`crate::ndf::ggx_d`], Lambda and G1 from
//! [`crate::masking`], the height-correlated G, and visible-normal sampling from [`crate::vndf`].

use crate::masking;
use crate::ndf;
use crate::vector::Vec3;
use crate::vndf;

use super::SMOOTH_ALPHA;

/// Anisotropic GGX with roughness `alpha_x`, `alpha_y` (valid: 0 <= alpha < inf).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrowbridgeReitz {
    pub alpha_x: f32,
    pub alpha_y: f32,
}

impl TrowbridgeReitz {
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
