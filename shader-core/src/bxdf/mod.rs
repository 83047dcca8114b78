//! PBRT-v4 style BxDFs (Pharr, Jakob, Humphreys, "Physically Based Rendering", 4th ed., chapter 9)
//! behind one interface, [`BxDF`]: `f(wo, wi)`, `sample_f(wo, uc, u) -> BSDFSample`, `pdf(wo, wi)`.
//!
//! Conventions (all BxDFs):
//! * Local shading frame, normal = +z. `wo` (towards the viewer) and `wi` (towards the light) both
//!   point away from the surface. Inputs need not be unit vectors: every entry point rescales and
//!   normalizes them ([`unit_or_zero`]); a zero, infinite or NaN direction is *degenerate*.
//! * `f` is the BxDF value without the cosine; `pdf` is per unit solid angle of `wi`.
//! * Reflection BxDFs are two-sided: they reflect in whichever hemisphere `wo` is in
//!   (`same_hemisphere(wo, wi)` = wo.z * wi.z > 0).
//! * Exactly grazing directions (wo.z == 0 or wi.z == 0) give f = 0, pdf = 0 and no sample, as in
//!   PBRT-v4's `BSDF::Sample_f` (which also rejects samples with pdf = 0 or wi.z = 0).
//! * A sample that does not exist has `flags == 0` ([`BSDFSample::is_valid`]); nothing crosses a
//!   buffer as `bool` or `Option`.
//! * Roughness: `alpha = roughness^2` is the glTF / Disney convention used by [`gltf`];
//!   conductor and dielectric take `alpha_x, alpha_y` directly (PBRT-v4's `RoughnessToAlpha` is
//!   `sqrt(roughness)`: callers coming from PBRT scenes must convert). alpha < 1e-3 in both
//!   directions is *effectively smooth* (PBRT-v4 `EffectivelySmooth`): the lobe becomes a Dirac
//!   delta, `f` and `pdf` return 0 and `sample_f` returns the specular direction with pdf = 1
//!   (the discrete probability of the choice).
//! * Degenerate directions -> f = 0, pdf = 0, invalid sample (all zero). Invalid material
//!   parameters (NaN, alpha < 0 or inf, eta <= 0, ...) -> f and pdf NaN, sample flags 0 with NaN
//!   f and pdf.
//!
//! ```
//! use shader_core::bxdf::{BxDF, DiffuseBxDF, MODE_RADIANCE, SAMPLE_ALL, DIFFUSE_REFLECTION};
//! use shader_core::Vec3;
//! let lambert = DiffuseBxDF::new(Vec3::new(0.5, 0.5, 0.5));
//! let (wo, wi) = (Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.8, 0.0, 0.6));
//! // f has no cosine: R / pi.
//! assert_eq!(lambert.f(wo, wi, MODE_RADIANCE), Vec3::new(0.5, 0.5, 0.5) * core::f32::consts::FRAC_1_PI);
//! // Opposite hemispheres: no reflection. Degenerate (zero) direction: f = 0.
//! assert_eq!(lambert.f(wo, -wi, MODE_RADIANCE), Vec3::ZERO);
//! assert_eq!(lambert.f(Vec3::ZERO, wi, MODE_RADIANCE), Vec3::ZERO);
//! // A sample carries its flags and its solid-angle density, which pdf() reproduces.
//! let s = lambert.sample_f(wo, 0.5, 0.3, 0.7, MODE_RADIANCE, SAMPLE_ALL);
//! assert!(s.is_valid() && s.flags == DIFFUSE_REFLECTION && s.wi.z > 0.0);
//! assert!((s.pdf - lambert.pdf(wo, s.wi, MODE_RADIANCE, SAMPLE_ALL)).abs() < 1e-6);
//! // Invalid parameters: NaN.
//! assert!(DiffuseBxDF::new(Vec3::new(f32::NAN, 0.0, 0.0)).f(wo, wi, MODE_RADIANCE).x.is_nan());
//! ```

pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod gltf;
pub mod microfacet;
pub mod specular;

pub use conductor::ConductorBxDF;
pub use dielectric::DielectricBxDF;
pub use diffuse::DiffuseBxDF;
pub use gltf::GltfMetalRoughBxDF;
pub use microfacet::TrowbridgeReitz;
pub use specular::SpecularReflectionBxDF;

use crate::ieee;
use crate::vector::Vec3;

/// BxDF flag bit (PBRT-v4 `BxDFFlags`): the lobe reflects (wi on wo's side).
pub const REFLECTION: u32 = 1;
/// BxDF flag bit: the lobe transmits (wi on the other side of the surface).
pub const TRANSMISSION: u32 = 2;
/// BxDF flag bit: a diffuse lobe.
pub const DIFFUSE: u32 = 4;
/// BxDF flag bit: a glossy (rough microfacet) lobe.
pub const GLOSSY: u32 = 8;
/// BxDF flag bit: a Dirac delta (perfectly specular) lobe.
pub const SPECULAR: u32 = 16;
/// [`DIFFUSE`] | [`REFLECTION`].
pub const DIFFUSE_REFLECTION: u32 = DIFFUSE | REFLECTION;
/// [`GLOSSY`] | [`REFLECTION`].
pub const GLOSSY_REFLECTION: u32 = GLOSSY | REFLECTION;
/// [`SPECULAR`] | [`REFLECTION`].
pub const SPECULAR_REFLECTION: u32 = SPECULAR | REFLECTION;
/// [`DIFFUSE`] | [`TRANSMISSION`].
pub const DIFFUSE_TRANSMISSION: u32 = DIFFUSE | TRANSMISSION;
/// [`GLOSSY`] | [`TRANSMISSION`].
pub const GLOSSY_TRANSMISSION: u32 = GLOSSY | TRANSMISSION;
/// [`SPECULAR`] | [`TRANSMISSION`].
pub const SPECULAR_TRANSMISSION: u32 = SPECULAR | TRANSMISSION;

/// Which halves `sample_f` / `pdf` may use (PBRT-v4 `BxDFReflTransFlags`): reflection.
pub const SAMPLE_REFLECTION: u32 = 1;
/// `sample_f` / `pdf` may use the transmission half.
pub const SAMPLE_TRANSMISSION: u32 = 2;
/// Both halves: [`SAMPLE_REFLECTION`] | [`SAMPLE_TRANSMISSION`].
pub const SAMPLE_ALL: u32 = 3;

/// Transport mode (PBRT-v4 `TransportMode`): what the path carries. Only the dielectric's
/// transmission depends on it (radiance is scaled by 1/eta'^2, importance is not). This one:
/// radiance (paths traced from the camera).
pub const MODE_RADIANCE: u32 = 0;
/// Transport mode: importance (paths traced from the lights); no 1/eta'^2 scaling.
pub const MODE_IMPORTANCE: u32 = 1;

/// Largest alpha (in both directions) treated as a perfectly smooth surface (PBRT-v4
/// `TrowbridgeReitzDistribution::EffectivelySmooth`: max(alpha_x, alpha_y) < 1e-3).
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// The result of [`BxDF::sample_f`] (PBRT-v4 `BSDFSample`). `flags == 0` means no sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BSDFSample {
    /// BxDF value f(wo, wi) (RGB; for a Dirac delta lobe, the delta's weight F / |cos|).
    pub f: Vec3,
    /// Sampled direction (pointing away from the surface).
    pub wi: Vec3,
    /// Solid-angle density of `wi` (for specular samples: the discrete probability of the lobe).
    pub pdf: f32,
    /// [`REFLECTION`] / [`TRANSMISSION`] | [`DIFFUSE`] / [`GLOSSY`] / [`SPECULAR`]; 0 = no sample.
    pub flags: u32,
    /// Relative IOR eta' along the sampled path (1 for reflection).
    pub eta: f32,
}

impl BSDFSample {
    /// No sample (all zeros, eta = 1).
    pub const NONE: BSDFSample = BSDFSample { f: Vec3::ZERO, wi: Vec3::ZERO, pdf: 0.0, flags: 0, eta: 1.0 };
    /// No sample because a material parameter is invalid: f and pdf are NaN.
    pub const INVALID_PARAMS: BSDFSample = BSDFSample {
        f: Vec3::new(f32::NAN, f32::NAN, f32::NAN),
        wi: Vec3::ZERO,
        pdf: f32::NAN,
        flags: 0,
        eta: f32::NAN,
    };

    /// A sample with the given fields, unchecked (see [`BSDFSample::checked`]).
    #[inline]
    pub fn new(f: Vec3, wi: Vec3, pdf: f32, flags: u32, eta: f32) -> Self {
        BSDFSample { f, wi, pdf, flags, eta }
    }

    /// True when a sample exists.
    #[inline]
    pub fn is_valid(&self) -> bool {
        self.flags != 0
    }

    /// PBRT-v4 `BSDF::Sample_f`'s final filter: a sample with pdf <= 0 (or NaN) or wi.z == 0 is
    /// dropped; so is one whose pdf or f is not finite (rounding overflow, e.g. the dielectric's
    /// transmission lobe for eta within ~1e-7 of 1).
    /// The components of `wi` that are zero are returned as +0 ([`positive_zero`]).
    #[inline]
    pub fn checked(self) -> BSDFSample {
        if !(self.pdf > 0.0 && self.pdf < f32::INFINITY) || self.wi.z == 0.0 || !self.f.is_finite() {
            BSDFSample::NONE
        } else {
            BSDFSample { wi: positive_zero(self.wi), ..self }
        }
    }
}

/// The PBRT-v4 BxDF interface. `mode` is [`MODE_RADIANCE`] or [`MODE_IMPORTANCE`];
/// `sample_flags` a combination of [`SAMPLE_REFLECTION`] and [`SAMPLE_TRANSMISSION`].
pub trait BxDF {
    /// The lobes this BxDF has ([`REFLECTION`] | ... ).
    fn flags(&self) -> u32;
    /// f(wo, wi), RGB, without the cosine.
    fn f(&self, wo: Vec3, wi: Vec3, mode: u32) -> Vec3;
    /// Sample wi given wo and three uniform numbers: `uc` picks a lobe, `(u0, u1)` the direction.
    fn sample_f(&self, wo: Vec3, uc: f32, u0: f32, u1: f32, mode: u32, sample_flags: u32) -> BSDFSample;
    /// The density with which `sample_f` produces `wi` (0 for Dirac delta lobes).
    fn pdf(&self, wo: Vec3, wi: Vec3, mode: u32, sample_flags: u32) -> f32;
}

/// Both directions strictly on the same side of the surface (PBRT `SameHemisphere`).
#[inline]
pub fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// The cosine between a reflection half vector `wm` and the directions, |wo.wm| = |wi.wm| in
/// exact arithmetic, evaluated symmetrically as the mean of the two rounded dot products so that
/// every BxDF `f` using it is reciprocal to the bit (PBRT-v4 eq. 9.33 evaluates |wo.wm|).
#[inline]
pub fn half_vector_cos(wo: Vec3, wi: Vec3, wm: Vec3) -> f32 {
    0.5 * (wo.dot(wm) + wi.dot(wm))
}

/// `v` flipped, if needed, into the hemisphere of `n` (PBRT `FaceForward`: dot(v, n) < 0 -> -v).
#[inline]
pub fn face_forward(v: Vec3, n: Vec3) -> Vec3 {
    if v.dot(n) < 0.0 {
        -v
    } else {
        v
    }
}

/// `v / |v|` computed after dividing by the largest |component| (so neither tiny nor huge vectors
/// under/overflow in the squares); the zero vector and vectors with a non-finite component map to
/// the zero vector (degenerate).
#[inline]
pub fn unit_or_zero(v: Vec3) -> Vec3 {
    if !v.is_finite() {
        return Vec3::ZERO;
    }
    let ax = v.x.abs();
    let ay = v.y.abs();
    let az = v.z.abs();
    let m = if ax >= ay { ax } else { ay };
    let m = if m >= az { m } else { az };
    if m == 0.0 {
        return Vec3::ZERO;
    }
    let s = v / m;
    let len = ieee::sqrt(s.length_squared());
    s / len
}

/// `v` with every zero component (+0 or -0) replaced by +0, decided on the bits (integer
/// operations), so that the sign of a zero direction component cannot differ between backends:
/// GPU drivers may apply algebraic simplifications that do not preserve the sign of zero
/// (e.g. `0 - a` -> `-a`), which the CPU does not.
#[inline]
pub fn positive_zero(v: Vec3) -> Vec3 {
    Vec3::new(positive_zero_f32(v.x), positive_zero_f32(v.y), positive_zero_f32(v.z))
}

#[inline]
fn positive_zero_f32(x: f32) -> f32 {
    let b = x.to_bits();
    if b << 1 == 0 {
        f32::from_bits(0)
    } else {
        x
    }
}

/// True for the zero vector (what [`unit_or_zero`] returns for degenerate input).
#[inline]
pub fn is_zero(v: Vec3) -> bool {
    v.x == 0.0 && v.y == 0.0 && v.z == 0.0
}

/// Mean of the three channels, (r + g + b) / 3.
#[inline]
pub fn mean(v: Vec3) -> f32 {
    ieee::div(v.x + v.y + v.z, 3.0)
}

/// A vector with all three components `s`.
#[inline]
pub fn splat(s: f32) -> Vec3 {
    Vec3::new(s, s, s)
}
