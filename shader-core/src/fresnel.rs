//! Fresnel reflectance and the law of refraction (PBRT-v4 section 9.3), Schlick's approximation,
//! and Gulbrandsen's artist-friendly conductor parameterization.
//!
//! Conventions (PBRT-v4): `cos_theta_i` is the cosine between the incident direction and the
//! surface normal; `eta` is the *relative* index of refraction eta_t / eta_i of the medium below the
//! surface (the side the normal points away from) over the medium above. Directions point away from
//! the surface. Every function here is built from `+ - * /`, `sqrt` and comparisons only.
//!
//! Invalid input (documented per function, asserted by the project's BxDF stress tests): NaN
//! inputs propagate to NaN; a non-positive or non-finite relative IOR gives NaN.
//!
//! ```
//! use shader_core::fresnel::{dielectric, f0_from_eta, reflect, refract, schlick};
//! use shader_core::Vec3;
//! // Reflecting the normal about itself gives the normal; both vectors point away from the surface.
//! assert_eq!(reflect(Vec3::Z, Vec3::Z), Vec3::Z);
//! assert_eq!(reflect(Vec3::new(0.6, 0.0, 0.8), Vec3::Z), Vec3::new(-0.6, 0.0, 0.8));
//! // Schlick at normal incidence is F0 exactly; eta = 1.5 gives F0 = 0.04.
//! assert_eq!(schlick(1.0, 0.04, 1.0), 0.04);
//! assert!((f0_from_eta(1.5) - 0.04).abs() < 1e-8);
//! // The exact dielectric Fresnel agrees with F0 at normal incidence and is 1 at grazing.
//! assert!((dielectric(1.0, 1.5) - 0.04).abs() < 1e-7);
//! assert_eq!(dielectric(0.0, 1.5), 1.0);
//! // Invalid IOR: NaN.
//! assert!(dielectric(0.5, -1.0).is_nan());
//! // Normal incidence refracts straight through (the transmitted direction points down).
//! let t = refract(Vec3::Z, Vec3::Z, 1.5);
//! assert_eq!(t.valid, 1);
//! assert_eq!(t.wt, Vec3::new(0.0, 0.0, -1.0));
//! ```

use crate::ieee;
use crate::complex::Complex;
use crate::vector::Vec3;

/// `(1 - c)^5` for `c = min(|cos_theta|, 1)`, the weight of Schlick's approximation.
#[inline]
pub fn schlick_weight(cos_theta: f32) -> f32 {
    let c = cos_theta.abs();
    let c = if c > 1.0 { 1.0 } else { c };
    let m = 1.0 - c;
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's approximation (Schlick 1994, "An Inexpensive BRDF Model for Physically-based
/// Rendering", eq. 24 with F90 generalized): F = F0 + (F90 - F0)(1 - |cos_theta|)^5.
/// |cos_theta| is clamped to 1; a negative cosine is treated as its absolute value (as glTF's
/// `abs(VdotH)`); NaN propagates.
#[inline]
pub fn schlick(cos_theta: f32, f0: f32, f90: f32) -> f32 {
    f0 + (f90 - f0) * schlick_weight(cos_theta)
}

/// [`schlick`] per RGB channel.
#[inline]
pub fn schlick_rgb(cos_theta: f32, f0: Vec3, f90: Vec3) -> Vec3 {
    let w = schlick_weight(cos_theta);
    Vec3::new(
        f0.x + (f90.x - f0.x) * w,
        f0.y + (f90.y - f0.y) * w,
        f0.z + (f90.z - f0.z) * w,
    )
}

/// Normal-incidence reflectance of a dielectric interface, F0 = ((eta - 1) / (eta + 1))^2
/// (Schlick 1994, eq. 24; eta = 1.5 gives the glTF dielectric F0 of 0.04).
#[inline]
pub fn f0_from_eta(eta: f32) -> f32 {
    let r = ieee::div(eta - 1.0, eta + 1.0);
    r * r
}

/// cos(theta_t) of Snell's law for 0 <= c = cos(theta_i) <= 1 and relative IOR eta > 0, or -1 for
/// total internal reflection (cos^2 theta_t <= 0 with eta < 1).
///
/// cos^2 theta_t = 1 - (1 - c^2) / eta^2 (PBRT-v4 eq. 9.4) is evaluated without cancellation as
/// (c / eta)^2 + (1 - 1/eta)(1 + 1/eta) for eta >= 1 (bounded terms; exactly c^2 at eta = 1) and
/// as (c^2 - (1 - eta)(1 + eta)) / eta^2 for eta < 1 (TIR iff the numerator is <= 0). The textbook
/// form rounds 1 - c^2 to 1 for c < 2^-12 and turns eta = 1 + tiny into spurious total reflection.
#[inline]
pub fn cos_transmitted(c: f32, eta: f32) -> f32 {
    if eta >= 1.0 {
        let ie = ieee::div(1.0, eta);
        let ci = c * ie;
        ieee::sqrt(ci * ci + (1.0 - ie) * (1.0 + ie))
    } else {
        let num = c * c - (1.0 - eta) * (1.0 + eta);
        if num <= 0.0 {
            -1.0
        } else {
            ieee::sqrt(ieee::div(ieee::div(num, eta), eta))
        }
    }
}

/// Unpolarized Fresnel reflectance of a dielectric interface (PBRT-v4 eq. 9.5 / `FrDielectric`):
/// a negative `cos_theta_i` means the ray arrives from inside (below), and eta is inverted;
/// total internal reflection returns 1, exactly grazing incidence (cos = 0) returns 1 for every
/// eta. `cos_theta_i` is clamped to [-1, 1]. cos theta_t comes from [`cos_transmitted`].
///
/// Invalid input: eta <= 0, eta = inf or NaN, or NaN cos_theta_i -> NaN. A subnormal eta whose
/// inverse overflows (inside case) returns the mirror limit 1.
#[inline]
pub fn dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    if !(eta > 0.0 && eta < f32::INFINITY) || cos_theta_i.is_nan() {
        return f32::NAN;
    }
    let mut c = if cos_theta_i > 1.0 {
        1.0
    } else if cos_theta_i < -1.0 {
        -1.0
    } else {
        cos_theta_i
    };
    let mut eta = eta;
    if c < 0.0 {
        eta = ieee::div(1.0, eta);
        c = -c;
        if eta == f32::INFINITY {
            return 1.0;
        }
    }
    if c == 0.0 {
        // Exactly grazing: F = 1 for every eta (PBRT-v4 returns 1 here too: TIR for eta <= 1,
        // r_parl = r_perp = -1 for eta > 1); avoids 0/0 at eta = 1.
        return 1.0;
    }
    let cos_t = cos_transmitted(c, eta);
    if cos_t < 0.0 {
        return 1.0;
    }
    let r_parl = ieee::div(eta * c - cos_t, eta * c + cos_t);
    let r_perp = ieee::div(c - eta * cos_t, c + eta * cos_t);
    ieee::div(r_parl * r_parl + r_perp * r_perp, 2.0)
}

/// Unpolarized Fresnel reflectance of a conductor with complex IOR eta + i k (PBRT-v4 eq. 9.6 /
/// `FrComplex`), with complex arithmetic on real operations ([`Complex`]). `cos_theta_i` is
/// clamped to [0, 1] as in PBRT (a conductor is never entered); at exactly grazing incidence
/// (cos = 0) it returns the limit 1. With k = 0 this is [`dielectric`] for cos >= 0.
///
/// Invalid input: eta < 0, k < 0, eta = k = 0, a non-finite eta or k, or NaN cos -> NaN.
/// |eta + i k| below ~1e-19 (cos^2 theta_t overflows) returns the limit 1.
#[inline]
pub fn conductor(cos_theta_i: f32, eta: f32, k: f32) -> f32 {
    if !(eta >= 0.0 && eta < f32::INFINITY && k >= 0.0 && k < f32::INFINITY)
        || (eta == 0.0 && k == 0.0)
        || cos_theta_i.is_nan()
    {
        return f32::NAN;
    }
    let c = if cos_theta_i > 1.0 {
        1.0
    } else if cos_theta_i < 0.0 {
        0.0
    } else {
        cos_theta_i
    };
    if c == 0.0 {
        return 1.0;
    }
    let e = Complex::new(eta, k);
    // cos^2 theta_t = 1 - (1 - c^2) / eta^2 without cancellation (see [`cos_transmitted`]):
    // (c / eta)^2 + (1 - 1/eta)(1 + 1/eta) for |eta| >= 1, (c^2 - (1 - eta)(1 + eta)) / eta^2 below.
    let one = Complex::real(1.0);
    let cos2_t = if e.norm() >= 1.0 {
        let ie = one / e;
        let ci = ie.scale(c);
        ci * ci + (one - ie) * (one + ie)
    } else {
        (Complex::real(c * c) - (one - e) * (one + e)) / e / e
    };
    let cos_t = cos2_t.sqrt();
    if !(cos_t.re.is_finite() && cos_t.im.is_finite()) {
        // |eta + i k| so small that cos^2 theta_t overflows: the total-reflection limit.
        return 1.0;
    }
    let ec = e.scale(c);
    let r_parl = (ec - cos_t) / (ec + cos_t);
    let ect = e * cos_t;
    let ci = Complex::real(c);
    let r_perp = (ci - ect) / (ci + ect);
    ieee::div(r_parl.norm() + r_perp.norm(), 2.0)
}

/// [`conductor`] per RGB channel.
#[inline]
pub fn conductor_rgb(cos_theta_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    Vec3::new(
        conductor(cos_theta_i, eta.x, k.x),
        conductor(cos_theta_i, eta.y, k.y),
        conductor(cos_theta_i, eta.z, k.z),
    )
}

/// Largest reflectivity [`gulbrandsen_nk`] accepts (Cycles' clamp): r = 1 would need n = inf.
pub const GULBRANDSEN_R_MAX: f32 = 0.99;

/// Gulbrandsen 2014, "Artist Friendly Metallic Fresnel" (JCGT 3(4)), eqs. 8-9: reflectivity r
/// (= F0) and edge tint g -> complex IOR (n, k), returned as `Complex { re: n, im: k }`:
/// n = g n_min(r) + (1 - g) n_max(r), n_min = (1 - r)/(1 + r), n_max = (1 + sqrt r)/(1 - sqrt r),
/// k = sqrt((r (n + 1)^2 - (n - 1)^2) / (1 - r)) (evaluated in an equivalent cancellation-free form). r is clamped to [0, 0.99] and g to [0, 1];
/// NaN propagates. F0 of the result ([`conductor`] at cos = 1) equals r.
#[inline]
pub fn gulbrandsen_nk(r: f32, g: f32) -> Complex {
    let r = if r > GULBRANDSEN_R_MAX {
        GULBRANDSEN_R_MAX
    } else if r < 0.0 {
        0.0
    } else {
        r
    };
    let g = if g > 1.0 {
        1.0
    } else if g < 0.0 {
        0.0
    } else {
        g
    };
    let sr = ieee::sqrt(r);
    let n_min = ieee::div(1.0 - r, 1.0 + r);
    let n_max = ieee::div(1.0 + sr, 1.0 - sr);
    let n = g * n_min + (1.0 - g) * n_max;
    // k^2 = (r (n + 1)^2 - (n - 1)^2) / (1 - r), factored without cancellation: with
    // sqrt(r)(n + 1) - (n - 1) = (1 - sqrt r)(n_max - n) and n_max - n = g (n_max - n_min),
    // k^2 = g (n_max - n_min) (sqrt(r)(n + 1) + (n - 1)) / (1 + sqrt r) (exactly 0 at g = 0).
    let k2 = ieee::div(g * (n_max - n_min) * (sr * (n + 1.0) + (n - 1.0)), 1.0 + sr);
    // k2 >= 0 in exact arithmetic for r in [0, 1), g in [0, 1]; clamp the rounding.
    let k = if k2 > 0.0 {
        ieee::sqrt(k2)
    } else if k2.is_nan() {
        f32::NAN
    } else {
        0.0
    };
    Complex::new(n, k)
}

/// Reflectivity and edge tint of [`gulbrandsen_r_g`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReflectivityEdgeTint {
    /// Reflectivity r: the normal-incidence reflectance, in [0, 1) for a valid (n, k).
    pub r: f32,
    /// Edge tint g: in [0, 1] inside the model's image (not clamped).
    pub g: f32,
}

/// Inverse of [`gulbrandsen_nk`] (Gulbrandsen 2014, eqs. 5 and 8 solved for r and g):
/// r = ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2) (the normal-incidence reflectance),
/// g = (n_max(r) - n) / (n_max(r) - n_min(r)). g is not clamped: (n, k) outside the model's image
/// give g outside [0, 1]. When n_max = n_min (r = 0, i.e. n = 1, k = 0) g is 0.
/// Invalid input: n < 0, k < 0 or NaN -> NaN.
#[inline]
pub fn gulbrandsen_r_g(n: f32, k: f32) -> ReflectivityEdgeTint {
    if !(n >= 0.0 && k >= 0.0) {
        return ReflectivityEdgeTint { r: f32::NAN, g: f32::NAN };
    }
    let nm = n - 1.0;
    let np = n + 1.0;
    let k2 = k * k;
    let r = ieee::div(nm * nm + k2, np * np + k2);
    let sr = ieee::sqrt(r);
    let n_min = ieee::div(1.0 - r, 1.0 + r);
    let n_max = ieee::div(1.0 + sr, 1.0 - sr);
    let span = n_max - n_min;
    let g = if span == 0.0 { 0.0 } else { ieee::div(n_max - n, span) };
    ReflectivityEdgeTint { r, g }
}

/// The result of [`refract`]: `valid` is 1 when a transmitted direction exists, 0 for total
/// internal reflection or invalid input (then `wt` is zero).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Refraction {
    /// The transmitted direction (a unit vector pointing away from the surface, into the other side),
    /// or the zero vector when `valid` is 0.
    pub wt: Vec3,
    /// The relative IOR actually used: eta, or 1/eta when `wi` was on the side `n` points away from.
    pub etap: f32,
    /// 1 when a transmitted direction exists, 0 otherwise (a `u32`, not a `bool`, so the record can
    /// cross a GPU buffer).
    pub valid: u32,
}

/// Snell's law (PBRT-v4 eq. 9.4 / `Refract`): the refracted direction of `wi` (pointing away from
/// the surface) about normal `n`, with eta = eta_t / eta_i relative to the side `n` points to.
/// wt = -wi / eta' + (cos_i / eta' - cos_t) n'. `wi` and `n` must be unit vectors (the result is
/// then a unit vector). If dot(n, wi) < 0, n is flipped and eta inverted (`etap` reports which).
///
/// Invalid input: eta <= 0, inf or NaN, or NaN components -> valid = 0, wt = 0, etap = NaN.
/// Total internal reflection -> valid = 0, wt = 0, etap = the inverted-or-not eta.
#[inline]
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Refraction {
    let mut cos_i = n.dot(wi);
    if !(eta > 0.0 && eta < f32::INFINITY) || cos_i.is_nan() {
        return Refraction { wt: Vec3::ZERO, etap: f32::NAN, valid: 0 };
    }
    let mut eta = eta;
    let mut n = n;
    if cos_i < 0.0 {
        eta = ieee::div(1.0, eta);
        cos_i = -cos_i;
        n = -n;
    }
    if eta == f32::INFINITY {
        return Refraction { wt: Vec3::ZERO, etap: eta, valid: 0 };
    }
    // wt = -wi / eta + (cos_i / eta - cos_t) n, written as -wi_perp / eta - cos_t n with
    // wi_perp = wi - cos_i n (the tangential part, sin_t = |wi_perp| / eta): no cancellation of
    // two large terms when eta << 1, and |wt| = 1 by construction.
    let wi_perp = wi - n * cos_i;
    let c = if cos_i > 1.0 { 1.0 } else { cos_i };
    let cos_t = if eta >= 1.0 || c * c < 0.5 {
        cos_transmitted(c, eta)
    } else {
        // eta < 1 near normal incidence: sin^2 theta_i from the tangential part, exact there
        // (1 - cos^2 is not; matters when eta is small and the critical angle is near 0).
        let sin2_t = ieee::div(ieee::div(wi_perp.length_squared(), eta), eta);
        if sin2_t >= 1.0 {
            -1.0
        } else {
            ieee::sqrt(1.0 - sin2_t)
        }
    };
    if cos_t < 0.0 {
        return Refraction { wt: Vec3::ZERO, etap: eta, valid: 0 };
    }
    let wt = -(wi_perp / eta) - n * cos_t;
    Refraction { wt, etap: eta, valid: 1 }
}

/// Mirror reflection of `wo` about `n` (PBRT-v4 eq. 9.1 / `Reflect`): -wo + 2 dot(wo, n) n.
/// Both point away from the surface (unlike GLSL's `reflect`, whose incident vector points in).
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    -wo + n * (2.0 * wo.dot(n))
}
