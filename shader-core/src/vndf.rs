//! Sampling the GGX distribution of visible normals (VNDF), D_w(wm) = G1(w) max(0, w.wm) D(wm) / w.z
//! (Heitz 2014, "Understanding the Masking-Shadowing Function", eq. 38).
//!
//! At the top: the BxDFs' normal sampler, Heitz 2018 ("Sampling the GGX Distribution of Visible
//! Normals", JCGT 7(4), listing 1) in the form of PBRT-v4 `TrowbridgeReitzDistribution::Sample_wm`
//! (two-sided, `(w, alpha_x, alpha_y, u0, u1) -> wm`), and its density.
//!
//! Conventions of those two: local frame (normal = +z); `w` is a unit direction pointing away from the surface,
//! either hemisphere (a `w` below the surface samples the visible normals of `-w`: PBRT's two-sided
//! microsurface); alpha_x, alpha_y > 0 (the smooth case alpha < 1e-3 is handled by the BxDFs as a
//! Dirac delta and never sampled here). The result is a unit normal with wm.z >= 1e-6 scale.
//! Invalid input: w = 0, w.z = 0 with alpha = 0, alpha <= 0 or NaN -> NaN components.
//!
//! Below them: four reflection samplers (`sample_ndf`, `sample_vndf_heitz`, `sample_vndf_caps`,
//! `sample_vndf_bounded`), each returning wo = reflect(wi, wm) with its density on the sphere in a
//! [`ReflectionSample`], and the matching `pdf_*`.
//!
//! Shared conventions of the `sample_*` / `pdf_*` reflection samplers:
//! * Local frame (normal = +z). `wi` (the direction the sample is reflected from, pointing away
//!   from the surface) and `wo` must be unit vectors: the densities assume |wi| = |wo| = 1 and
//!   nothing is renormalized. `u1`, `u2` in [0, 1).
//! * The density is the density of wo on the whole sphere and integrates to 1 there. A sample may
//!   land below the horizon (wo.z <= 0); it is returned as is, with its density, and a
//!   reflection estimator counts it as zero. The fraction of such samples is a measure of a
//!   sampler's efficiency.
//! * wm.z <= 0 has no density (D = 0): `pdf_*` returns 0 wherever the half vector that would
//!   reflect wi to wo lies below the surface.
//! * alpha = 0 (either axis) is the smooth limit (a Dirac): the samplers return the limiting
//!   direction (the mirror direction for alpha_x = alpha_y = 0) with pdf 0, and `pdf_*` returns 0,
//!   as [`ndf::ggx_d`] does. alpha must be finite.
//! * Invalid input - alpha negative, NaN or infinite, wi zero or not finite - gives NaN in every
//!   output. `pdf_*` also gives NaN for a NaN wo.
//! * Back-facing wi (wi.z < 0): per method, see each function. No method flips wi (unlike the
//!   two-sided [`ggx_sample_visible_heitz2018`]). A wi for which no normal of the upper
//!   microsurface is visible (wi = -z exactly, or alpha = 0 with wi.z <= 0) gives the "no sample"
//!   result wo = (0, 0, 0), pdf = 0 from the VNDF samplers.
//!
//! ```
//! use shader_core::vndf::{ggx_sample_visible_heitz2018, ggx_visible_pdf, pdf_vndf_heitz, sample_vndf_heitz};
//! use shader_core::Vec3;
//! let wi = Vec3::new(0.6, 0.0, 0.8);
//! // A sampled visible normal is a unit vector in the upper hemisphere ...
//! let wm = ggx_sample_visible_heitz2018(wi, 0.3, 0.3, 0.25, 0.75);
//! assert!(wm.z > 0.0 && (wm.length() - 1.0).abs() < 1e-6);
//! assert!(ggx_visible_pdf(wi, wm, 0.3, 0.3) > 0.0);
//! // ... and a reflection sampler's density matches its pdf function.
//! let s = sample_vndf_heitz(wi, 0.3, 0.3, 0.25, 0.75);
//! let p = pdf_vndf_heitz(wi, s.wo, 0.3, 0.3);
//! assert!((s.pdf - p).abs() <= 1e-5 * p, "{} vs {}", s.pdf, p);
//! // Invalid roughness: NaN in every output.
//! assert!(sample_vndf_heitz(wi, -1.0, 0.3, 0.25, 0.75).pdf.is_nan());
//! ```

use crate::fresnel::reflect;
use crate::ieee;
use crate::masking;
use crate::math;
use crate::ndf;
use crate::vector::Vec3;
use crate::warp;

/// Heitz 2018 VNDF sample (JCGT 7(4) listing 1; PBRT-v4 eqs. 9.25-9.27): stretch `w` to the
/// hemisphere configuration, sample the projected disk with the lower half squeezed onto the visible
/// part (t2 = lerp((1 + wh.z)/2, sqrt(1 - t1^2), t2)), lift to the hemisphere, unstretch.
#[inline]
pub fn ggx_sample_visible_heitz2018(w: Vec3, alpha_x: f32, alpha_y: f32, u0: f32, u1: f32) -> Vec3 {
    let mut wh = Vec3::new(alpha_x * w.x, alpha_y * w.y, w.z).normalize();
    if wh.z < 0.0 {
        wh = -wh;
    }
    let t1 = if wh.z < 0.99999 {
        Vec3::new(-wh.y, wh.x, 0.0).normalize()
    } else {
        Vec3::new(1.0, 0.0, 0.0)
    };
    let t2 = wh.cross(t1);
    let p = warp::sample_uniform_disk_polar(u0, u1);
    let h = ieee::sqrt(1.0 - p.x * p.x);
    let s = ieee::div(1.0 + wh.z, 2.0);
    let py = (1.0 - s) * h + s * p.y;
    let pz2 = 1.0 - p.x * p.x - py * py;
    let pz = if pz2 > 0.0 { ieee::sqrt(pz2) } else { 0.0 };
    let nh = t1 * p.x + t2 * py + wh * pz;
    let nz = if nh.z > 1e-6 { nh.z } else { 1e-6 };
    Vec3::new(alpha_x * nh.x, alpha_y * nh.y, nz).normalize()
}

/// Density of visible normals D_w(wm) = G1(w) / |w.z| * D(wm) * |w.wm| (Heitz 2018 eq. 2; PBRT-v4
/// eq. 9.23, `TrowbridgeReitzDistribution::PDF`), the solid-angle density in wm of
/// [`ggx_sample_visible_heitz2018`]. `w`, `wm` unit; 0 for wm.z <= 0.
#[inline]
pub fn ggx_visible_pdf(w: Vec3, wm: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    let g1 = masking::ggx_g1(w, alpha_x, alpha_y);
    let d = ndf::ggx_d(wm, alpha_x, alpha_y);
    ieee::div(g1, w.z.abs()) * d * w.dot(wm).abs()
}

// ---------------------------------------------------------------------------------------------
// Reflection samplers: NDF, Heitz 2018 ellipsoid, Dupuy & Benyoub 2023 spherical caps, Eto &
// Tokuyoshi 2023 bounded VNDF, each returning the reflected direction wo = reflect(wi, wm) and its
// solid-angle density, with a matching `pdf_*` over the whole sphere of wo.
//
// Their shared conventions are listed in the module documentation.

/// A sampled reflection direction and its solid-angle density on the sphere of directions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReflectionSample {
    /// The sampled direction (a unit vector, possibly below the horizon; zero for "no sample", NaN
    /// for invalid input).
    pub wo: Vec3,
    /// Its solid-angle density on the whole sphere of directions (per steradian); 0 for "no sample"
    /// and for the smooth limit, NaN for invalid input.
    pub pdf: f32,
}

impl ReflectionSample {
    /// The result of invalid input.
    pub const INVALID: ReflectionSample = ReflectionSample { wo: Vec3::new(f32::NAN, f32::NAN, f32::NAN), pdf: f32::NAN };
    /// No direction can be sampled (no visible normal): wo = 0, pdf = 0.
    pub const NONE: ReflectionSample = ReflectionSample { wo: Vec3::ZERO, pdf: 0.0 };
}

/// Valid input of the reflection samplers: finite alphas >= 0 and a finite non-zero wi.
#[inline]
fn reflection_input_valid(wi: Vec3, alpha_x: f32, alpha_y: f32) -> bool {
    ndf::alpha_valid(alpha_x, alpha_y)
        && wi.is_finite()
        && wi.length_squared() > 0.0
}


/// (sin, cos) of 2 pi u through the project's deterministic [`crate::math`].
#[inline]
fn sin_cos_2pi(u: f32) -> (f32, f32) {
    let phi = 2.0 * core::f32::consts::PI * u;
    math::sin_cos(phi)
}

/// |A wi|^2 - wi.z^2 = (alpha_x wi.x)^2 + (alpha_y wi.y)^2, the squared length of the stretched
/// tangential part of wi (Heitz 2018 section 3; Eto & Tokuyoshi 2023 listing 2 `len2`).
#[inline]
fn stretched_tangential_len2(wi: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    let ax = alpha_x * wi.x;
    let ay = alpha_y * wi.y;
    ax * ax + ay * ay
}

/// Density of the reflected direction under visible-normal sampling, from D(wm) (Heitz 2018
/// eq. 2 times the reflection Jacobian 1 / (4 |wi.wm|)): D / (2 (wi.z + t)) with
/// t = |(alpha_x wi.x, alpha_y wi.y, wi.z)|, and for wi.z < 0 the cancellation-free form
/// D (t - wi.z) / (2 len2) (Eto & Tokuyoshi 2023, listing 2).
#[inline]
fn vndf_reflection_pdf(d: f32, wi: Vec3, len2: f32) -> f32 {
    let t = ieee::sqrt(len2 + wi.z * wi.z);
    if wi.z >= 0.0 {
        ieee::div(d, 2.0 * (wi.z + t))
    } else {
        ieee::div(d * (t - wi.z), 2.0 * len2)
    }
}

/// Classic NDF sampling of GGX (Walter et al. 2007 eqs. 35-36, anisotropic form): wm with density
/// D(wm) wm.z, drawn as a cosine-weighted direction in the stretched (alpha = 1) configuration,
/// (r cos phi, r sin phi, sqrt(1 - u1)) with r = sqrt(u1), phi = 2 pi u2, then unstretched to
/// normalize(alpha_x x, alpha_y y, z) - the same distribution as tan(theta_m) = alpha sqrt(u1 / (1 - u1)).
#[inline]
pub fn sample_wm_ndf(alpha_x: f32, alpha_y: f32, u1: f32, u2: f32) -> Vec3 {
    let r = ieee::sqrt(u1);
    let (s, c) = sin_cos_2pi(u2);
    let z2 = 1.0 - u1;
    let z = if z2 > 0.0 { ieee::sqrt(z2) } else { 0.0 };
    Vec3::new(alpha_x * (r * c), alpha_y * (r * s), z).normalize()
}

/// Classic NDF sampling of a GGX reflection (Walter et al. 2007, eqs. 35-36 and 38): wm from D(wm)
/// wm.z ([`sample_wm_ndf`]), wo = reflect(wi, wm), pdf = D(wm) wm.z / (4 |wi.wm|).
///
/// Independent of wi, so defined for every wi, back-facing included; a sampled wm with wi.wm < 0
/// (for wi.z > 0 this is what the VNDF methods avoid) reflects below the horizon. wi.wm = 0
/// (probability zero) gives pdf = +inf.
#[inline]
pub fn sample_ndf(wi: Vec3, alpha_x: f32, alpha_y: f32, u1: f32, u2: f32) -> ReflectionSample {
    if !reflection_input_valid(wi, alpha_x, alpha_y) {
        return ReflectionSample::INVALID;
    }
    let wm = sample_wm_ndf(alpha_x, alpha_y, u1, u2);
    let wo = reflect(wi, wm);
    let d = ndf::ggx_d(wm, alpha_x, alpha_y);
    let pdf = if d == 0.0 { 0.0 } else { ieee::div(d * wm.z, 4.0 * wi.dot(wm).abs()) };
    ReflectionSample { wo, pdf }
}

/// Density of [`sample_ndf`] at wo (Walter et al. 2007 eq. 38): D(wm) wm.z / (4 |wi.wm|) with wm
/// the half vector +-normalize(wi + wo) turned to the upper hemisphere (a back-facing sampled
/// normal is the negated half vector). 0 where the half vector is horizontal or zero (wo = -wi),
/// or alpha = 0.
///
/// |wi.wm| is the cosine of half the angle between wi and wo, sqrt((1 + cos) / 2), with 1 + cos
/// taken as sin^2 / (1 - cos) from |wi x wo| when the angle exceeds 90 degrees: near wo = -wi
/// (every reflection at grazing incidence) the plain 1 + wi.wo cancels, and the f32 rounding of
/// |wo| alone (6e-8) would be a 1 % error at theta_i = 89.9 degrees.
#[inline]
pub fn pdf_ndf(wi: Vec3, wo: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !reflection_input_valid(wi, alpha_x, alpha_y) {
        return f32::NAN;
    }
    let mut h = wi + wo;
    if h.z < 0.0 {
        h = -h;
    }
    let d = ndf::ggx_d(h, alpha_x, alpha_y);
    if d == 0.0 || d.is_nan() {
        return d;
    }
    let lw = wi.length() * wo.length();
    let c = wi.dot(wo);
    let one_plus_cos = if c >= 0.0 {
        1.0 + ieee::div(c, lw)
    } else {
        ieee::div(wi.cross(wo).length_squared(), lw * (lw - c))
    };
    let cos_half = ieee::sqrt(0.5 * one_plus_cos);
    ieee::div(d * (ieee::div(h.z, h.length())), 4.0 * cos_half)
}

/// Heitz 2018 ellipsoid VNDF sampling ("Sampling the GGX Distribution of Visible Normals", JCGT
/// 7(4), listing 1), reflected: wi is stretched to the hemisphere configuration
/// Vh = normalize(alpha_x wi.x, alpha_y wi.y, wi.z), the projected disk is sampled
/// (r = sqrt(u1), phi = 2 pi u2) with its lower half squeezed by s = (1 + Vh.z) / 2, lifted onto
/// the hemisphere and unstretched. When Vh is the normal (wi.x = wi.y = 0, or alpha = 0) the basis
/// T1 = Vh x z / |.| is undefined and T1 = (1, 0, 0) is used (the listing's special case).
/// pdf = D(wm) / (2 (wi.z + t)) (Heitz 2018 eq. 2 over 4 wi.wm), see [`pdf_vndf_heitz`].
///
/// Back-facing wi: the listing is applied as written (no flip). With Vh.z < 0 the squeezed region
/// is the crescent of the disk covered by the upper hemisphere's normals that face wi
/// (Vh.N > 0, N.z > 0), so it samples the visible normals of the upper microsurface seen from
/// below, D(wm) max(0, wi.wm) / (projected area); the same distribution as the spherical caps and
/// the bounded method for wi.z < 0. wi = -z (nothing visible) gives [`ReflectionSample::NONE`].
#[inline]
pub fn sample_vndf_heitz(wi: Vec3, alpha_x: f32, alpha_y: f32, u1: f32, u2: f32) -> ReflectionSample {
    if !reflection_input_valid(wi, alpha_x, alpha_y) {
        return ReflectionSample::INVALID;
    }
    let len2 = stretched_tangential_len2(wi, alpha_x, alpha_y);
    if len2 == 0.0 && wi.z <= 0.0 {
        return ReflectionSample::NONE;
    }
    let vh = Vec3::new(alpha_x * wi.x, alpha_y * wi.y, wi.z).normalize();
    // Orthonormal basis, with the special case when the cross product with z is zero.
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 {
        let inv = ieee::div(1.0, ieee::sqrt(lensq));
        Vec3::new(-vh.y * inv, vh.x * inv, 0.0)
    } else {
        Vec3::new(1.0, 0.0, 0.0)
    };
    let t2 = vh.cross(t1);
    // Parameterization of the projected area.
    let r = ieee::sqrt(u1);
    let (sp, cp) = sin_cos_2pi(u2);
    let p1 = r * cp;
    let p2 = r * sp;
    let s = 0.5 * (1.0 + vh.z);
    let w2 = 1.0 - p1 * p1;
    let w = if w2 > 0.0 { ieee::sqrt(w2) } else { 0.0 };
    let p2 = (1.0 - s) * w + s * p2;
    // Reprojection onto the hemisphere.
    let q = 1.0 - p1 * p1 - p2 * p2;
    let pz = if q > 0.0 { ieee::sqrt(q) } else { 0.0 };
    let nh = t1 * p1 + t2 * p2 + vh * pz;
    // Back to the ellipsoid configuration.
    let nz = if nh.z > 0.0 { nh.z } else { 0.0 };
    let wm = Vec3::new(alpha_x * nh.x, alpha_y * nh.y, nz).normalize();
    let wo = reflect(wi, wm);
    let d = ndf::ggx_d(wm, alpha_x, alpha_y);
    let pdf = if d == 0.0 { 0.0 } else { vndf_reflection_pdf(d, wi, len2) };
    ReflectionSample { wo, pdf }
}

/// Density of the reflected direction under visible-normal sampling (Heitz 2018 eq. 2 with the
/// Jacobian 1 / (4 wi.wm); Eto & Tokuyoshi 2023 eq. 7): D(wm) / (2 (wi.z + t)),
/// t = sqrt((alpha_x wi.x)^2 + (alpha_y wi.y)^2 + wi.z^2), wm = normalize(wi + wo), and for
/// wi.z < 0 the stable form D (t - wi.z) / (2 len2). Exact for [`sample_vndf_heitz`] and
/// [`sample_vndf_caps`] (one distribution), both hemispheres of wi. 0 where wm.z <= 0.
#[inline]
pub fn pdf_vndf(wi: Vec3, wo: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !reflection_input_valid(wi, alpha_x, alpha_y) {
        return f32::NAN;
    }
    // wi.(wi + wo) = 1 + wi.wo >= 0 for unit vectors: the half vector always faces wi.
    let d = ndf::ggx_d(wi + wo, alpha_x, alpha_y);
    if d == 0.0 || d.is_nan() {
        return d;
    }
    vndf_reflection_pdf(d, wi, stretched_tangential_len2(wi, alpha_x, alpha_y))
}

/// Density of [`sample_vndf_heitz`] at wo: [`pdf_vndf`].
#[inline]
pub fn pdf_vndf_heitz(wi: Vec3, wo: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    pdf_vndf(wi, wo, alpha_x, alpha_y)
}

/// Density of [`sample_vndf_caps`] at wo: [`pdf_vndf`].
#[inline]
pub fn pdf_vndf_caps(wi: Vec3, wo: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    pdf_vndf(wi, wo, alpha_x, alpha_y)
}

/// Spherical-cap sampling of the reflection in the stretched configuration, shared by the caps
/// and the bounded method: wi_std = normalize(alpha_x wi.x, alpha_y wi.y, wi.z), o_std uniform on
/// the cap z in (-b, 1] (phi = 2 pi u1, z = (1 - u2)(1 + b) - b), wm = unstretched
/// normalize(wi_std + o_std), wo = reflect(wi, wm). Returns (wo, wm).
#[inline]
fn sample_cap_reflection(wi: Vec3, alpha_x: f32, alpha_y: f32, len2: f32, b_scale: f32, u1: f32, u2: f32) -> (Vec3, Vec3) {
    let t = ieee::sqrt(len2 + wi.z * wi.z);
    let i_std = Vec3::new(ieee::div(alpha_x * wi.x, t), ieee::div(alpha_y * wi.y, t), ieee::div(wi.z, t));
    let b = b_scale * i_std.z;
    let (sp, cp) = sin_cos_2pi(u1);
    let z = (1.0 - u2) * (1.0 + b) - b;
    let st2 = 1.0 - z * z;
    let sin_theta = if st2 > 0.0 { if st2 < 1.0 { ieee::sqrt(st2) } else { 1.0 } } else { 0.0 };
    let o_std = Vec3::new(sin_theta * cp, sin_theta * sp, z);
    let m_std = i_std + o_std;
    let wm = Vec3::new(alpha_x * m_std.x, alpha_y * m_std.y, m_std.z).normalize();
    (reflect(wi, wm), wm)
}

/// Dupuy & Benyoub 2023 spherical-cap VNDF sampling ("Sampling Visible GGX Normals with Spherical
/// Caps", listing 3) with the ellipsoid stretch and unstretch the listing omits: in the stretched
/// configuration the mirror reflections of wi_std off the visible hemisphere are uniform on the cap
/// z in (-wi_std.z, 1]; phi = 2 pi u1, z = (1 - u2)(1 + wi_std.z) - wi_std.z; the half vector
/// wi_std + o_std is unstretched to wm and wo = reflect(wi, wm). Same distribution and pdf as
/// [`sample_vndf_heitz`] ([`pdf_vndf_caps`]).
///
/// Back-facing wi: the cap (|wi_std.z|, 1] holds the reflections off the normals visible from
/// below (as for the Heitz method); wi = -z gives [`ReflectionSample::NONE`].
#[inline]
pub fn sample_vndf_caps(wi: Vec3, alpha_x: f32, alpha_y: f32, u1: f32, u2: f32) -> ReflectionSample {
    if !reflection_input_valid(wi, alpha_x, alpha_y) {
        return ReflectionSample::INVALID;
    }
    let len2 = stretched_tangential_len2(wi, alpha_x, alpha_y);
    if len2 == 0.0 && wi.z <= 0.0 {
        return ReflectionSample::NONE;
    }
    let (wo, wm) = sample_cap_reflection(wi, alpha_x, alpha_y, len2, 1.0, u1, u2);
    let d = ndf::ggx_d(wm, alpha_x, alpha_y);
    let pdf = if d == 0.0 { 0.0 } else { vndf_reflection_pdf(d, wi, len2) };
    ReflectionSample { wo, pdf }
}

/// The bound k of Eto & Tokuyoshi 2023 ("Bounded VNDF Sampling for Smith-GGX Reflections",
/// eq. 5 with the anisotropic rule of eq. 6): a = min(alpha_x, alpha_y, 1), s = 1 + |wi.xy|,
/// k = (1 - a^2) s^2 / (s^2 + a^2 wi.z^2), in [0, 1]; the cap of reflections in the stretched
/// configuration is z in (-k wi_std.z, 1] for wi.z > 0.
#[inline]
pub fn bounded_vndf_k(wi: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    bounded_vndf_k_pair(wi, alpha_x, alpha_y).0
}

/// (k, 1 - k) of [`bounded_vndf_k`], with 1 - k = a^2 (s^2 + wi.z^2) / (s^2 + a^2 wi.z^2) computed
/// without the cancellation of 1 - k for small alpha (k = 1 - 1e-6 at alpha = 1e-3).
#[inline]
pub fn bounded_vndf_k_pair(wi: Vec3, alpha_x: f32, alpha_y: f32) -> (f32, f32) {
    let a = if alpha_x < alpha_y { alpha_x } else { alpha_y };
    let a = if a > 1.0 { 1.0 } else if a < 0.0 { 0.0 } else { a };
    let s = 1.0 + ieee::sqrt(wi.x * wi.x + wi.y * wi.y);
    let a2 = a * a;
    let s2 = s * s;
    let z2 = wi.z * wi.z;
    let den = s2 + a2 * z2;
    (ieee::div((1.0 - a2) * s2, den), ieee::div(a2 * (s2 + z2), den))
}

/// Eto & Tokuyoshi 2023 bounded VNDF sampling (listing 1, `SampleGGXReflection`): the spherical
/// cap of [`sample_vndf_caps`] shrunk to z in (-k wi_std.z, 1] ([`bounded_vndf_k`]) for wi.z > 0,
/// which drops only reflections that fall below the horizon. pdf = D(wm) / (2 (k wi.z + t))
/// (eq. 8 times 1 / (4 wi.wm)), see [`pdf_vndf_bounded`].
///
/// Back-facing wi (wi.z <= 0): the paper's fallback to the full cap, i.e. exactly
/// [`sample_vndf_caps`]; wi = -z gives [`ReflectionSample::NONE`].
#[inline]
pub fn sample_vndf_bounded(wi: Vec3, alpha_x: f32, alpha_y: f32, u1: f32, u2: f32) -> ReflectionSample {
    if !reflection_input_valid(wi, alpha_x, alpha_y) {
        return ReflectionSample::INVALID;
    }
    let len2 = stretched_tangential_len2(wi, alpha_x, alpha_y);
    if len2 == 0.0 && wi.z <= 0.0 {
        return ReflectionSample::NONE;
    }
    let k = if wi.z > 0.0 { bounded_vndf_k(wi, alpha_x, alpha_y) } else { 1.0 };
    let (wo, wm) = sample_cap_reflection(wi, alpha_x, alpha_y, len2, k, u1, u2);
    let d = ndf::ggx_d(wm, alpha_x, alpha_y);
    let pdf = if d == 0.0 {
        0.0
    } else if wi.z >= 0.0 {
        let t = ieee::sqrt(len2 + wi.z * wi.z);
        ieee::div(d, 2.0 * (k * wi.z + t))
    } else {
        vndf_reflection_pdf(d, wi, len2)
    };
    ReflectionSample { wo, pdf }
}

/// Density of [`sample_vndf_bounded`] at wo (Eto & Tokuyoshi 2023, listing 2 `GGXReflectionPDF`,
/// eq. 8 times 1 / (4 wi.wm)): for wi.z >= 0, D(wm) / (2 (k wi.z + t)) times the indicator
/// chi+(k wi_std.z + o_std.z) that the stretched reflection lies in the shrunk cap; for wi.z < 0 the
/// stable caps form D (t - wi.z) / (2 len2). wm = normalize(wi + wo).
///
/// The indicator is written without normalizations: with h = wi + wo and h_std = (h.x / alpha_x,
/// h.y / alpha_y, h.z), o_std.z + k wi_std.z > 0  <=>  2 (wi.h) h.z > (1 - k) wi.z |h_std|^2. It is
/// tested only for wo.z < 0: the paper's bound says every wo with wo.z >= 0 is inside the cap (checked
/// on a dense grid by the project's chi-square tests), and skipping it there keeps the returned density of
/// an upper-hemisphere sample from flipping to 0 by rounding at the cap's edge.
#[inline]
pub fn pdf_vndf_bounded(wi: Vec3, wo: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    if !reflection_input_valid(wi, alpha_x, alpha_y) {
        return f32::NAN;
    }
    let h = wi + wo;
    let d = ndf::ggx_d(h, alpha_x, alpha_y);
    if d == 0.0 || d.is_nan() {
        return d;
    }
    let len2 = stretched_tangential_len2(wi, alpha_x, alpha_y);
    if wi.z < 0.0 {
        return vndf_reflection_pdf(d, wi, len2);
    }
    let (k, one_minus_k) = bounded_vndf_k_pair(wi, alpha_x, alpha_y);
    if wo.z < 0.0 && !bounded_cap_contains(wi, h, alpha_x, alpha_y, one_minus_k) {
        return 0.0;
    }
    let t = ieee::sqrt(len2 + wi.z * wi.z);
    ieee::div(d, 2.0 * (k * wi.z + t))
}

/// Whether the stretched reflection of wi off the half vector h = wi + wo lies in the bounded cap
/// z > -k wi_std.z (Eto & Tokuyoshi 2023 eq. 8's chi+): 2 (wi.h) h.z > (1 - k) wi.z |h_std|^2 with
/// h_std = (h.x / alpha_x, h.y / alpha_y, h.z); `one_minus_k` from [`bounded_vndf_k_pair`].
/// alpha > 0 and h.z > 0 are the caller's.
#[inline]
pub fn bounded_cap_contains(wi: Vec3, h: Vec3, alpha_x: f32, alpha_y: f32, one_minus_k: f32) -> bool {
    let sx = ieee::div(h.x, alpha_x);
    let sy = ieee::div(h.y, alpha_y);
    let hs2 = sx * sx + sy * sy + h.z * h.z;
    2.0 * wi.dot(h) * h.z > one_minus_k * wi.z * hs2
}
