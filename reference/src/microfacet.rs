//! f64 reference twins of the microfacet functions of `shader_core::{ndf, masking}`, written
//! directly from the papers' formulas (no rearrangement for f32 robustness), for the property tests
//! (`tests/tests/microfacet_properties.rs`) and `host bench microfacet`.
//!
//! Directions are `[x, y, z]` in the local frame (normal = +z) and need not be normalized.

use std::f64::consts::PI;

/// tan^2(theta) of `w` scaled by the projected roughness: (x^2 ax^2 + y^2 ay^2) / z^2.
pub fn alpha2_tan2(w: [f64; 3], ax: f64, ay: f64) -> f64 {
    ((w[0] * ax).powi(2) + (w[1] * ay).powi(2)) / (w[2] * w[2])
}

/// Anisotropic GGX D (Heitz 2014 eq. 85): 1 / (pi ax ay cos^4 (1 + tan^2 (cos^2 phi/ax^2 + sin^2 phi/ay^2))^2).
pub fn ggx_d(m: [f64; 3], ax: f64, ay: f64) -> f64 {
    if m[2] <= 0.0 {
        return 0.0;
    }
    let l2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    let c2 = m[2] * m[2] / l2;
    let t = (m[0] / ax).powi(2) + (m[1] / ay).powi(2);
    let s = 1.0 + t / (m[2] * m[2]);
    1.0 / (PI * ax * ay * c2 * c2 * s * s)
}

/// Isotropic GGX D from cos(theta_m) (Walter 2007 eq. 33).
pub fn ggx_d_cos(cos_m: f64, alpha: f64) -> f64 {
    if cos_m <= 0.0 {
        return 0.0;
    }
    let c2 = cos_m * cos_m;
    let t2 = (1.0 - c2) / c2;
    let a2 = alpha * alpha;
    a2 / (PI * c2 * c2 * (a2 + t2).powi(2))
}

/// Anisotropic Beckmann D (Walter 2007 eq. 25, anisotropic as Heitz 2014 sec. 5.4).
pub fn beckmann_d(m: [f64; 3], ax: f64, ay: f64) -> f64 {
    if m[2] <= 0.0 {
        return 0.0;
    }
    let l2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    let c2 = m[2] * m[2] / l2;
    let t = ((m[0] / ax).powi(2) + (m[1] / ay).powi(2)) / (m[2] * m[2]);
    (-t).exp() / (PI * ax * ay * c2 * c2)
}

/// Normalized Blinn-Phong D (Walter 2007 eq. 30): (n + 2) / (2 pi) cos^n.
pub fn blinn_phong_d(m: [f64; 3], n: f64) -> f64 {
    if m[2] <= 0.0 {
        return 0.0;
    }
    let c = m[2] / (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
    (n + 2.0) / (2.0 * PI) * c.powf(n)
}

/// GTR1 (Burley 2012 B.2): (a^2 - 1) / (pi ln(a^2) (1 + (a^2 - 1) cos^2)), 1/pi at a = 1.
pub fn gtr1_d(m: [f64; 3], alpha: f64) -> f64 {
    if m[2] <= 0.0 {
        return 0.0;
    }
    let c2 = m[2] * m[2] / (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    let a2 = alpha * alpha;
    if (a2 - 1.0).abs() < 1e-12 {
        return 1.0 / PI;
    }
    (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * c2))
}

/// GGX Smith Lambda (Heitz 2014 eq. 86).
pub fn ggx_lambda(w: [f64; 3], ax: f64, ay: f64) -> f64 {
    if w[2] == 0.0 {
        return f64::INFINITY;
    }
    let a2t2 = alpha2_tan2(w, ax, ay);
    a2t2 / (2.0 * (1.0 + (1.0 + a2t2).sqrt()))
}

/// Isotropic GGX Lambda from cos(theta).
pub fn ggx_lambda_cos(cos: f64, alpha: f64) -> f64 {
    let c = cos.abs();
    if c == 0.0 {
        return f64::INFINITY;
    }
    let a2t2 = alpha * alpha * (1.0 - c * c) / (c * c);
    a2t2 / (2.0 * (1.0 + (1.0 + a2t2).sqrt()))
}

/// Beckmann a = 1 / (alpha_o tan theta).
pub fn beckmann_a(w: [f64; 3], ax: f64, ay: f64) -> f64 {
    w[2].abs() / ((w[0] * ax).powi(2) + (w[1] * ay).powi(2)).sqrt()
}

/// Beckmann Lambda as a function of a (Walter 2007 eq. 26): (erf(a) - 1)/2 + exp(-a^2)/(2 a sqrt(pi)),
/// evaluated as (exp(-a^2)/(a sqrt(pi)) - erfc(a))/2 (relative error about 2 a^2 * 1e-16).
pub fn beckmann_lambda_a(a: f64) -> f64 {
    if a == 0.0 {
        return f64::INFINITY;
    }
    if a == f64::INFINITY {
        return 0.0;
    }
    ((-a * a).exp() / (a * PI.sqrt()) - libm::erfc(a)) / 2.0
}

/// Beckmann Smith Lambda, anisotropic through the projected roughness.
pub fn beckmann_lambda(w: [f64; 3], ax: f64, ay: f64) -> f64 {
    beckmann_lambda_a(beckmann_a(w, ax, ay))
}

/// Walter's rational G1 for Beckmann (Walter 2007 eq. 27), in f64.
pub fn beckmann_g1_walter_a(a: f64) -> f64 {
    if a < 1.6 {
        (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
    } else {
        1.0
    }
}

/// Height-correlated G2 (Heitz 2014 eq. 99).
pub fn g2_height_correlated(lo: f64, li: f64) -> f64 {
    1.0 / (1.0 + lo + li)
}

/// Exact isotropic height-correlated Smith-GGX visibility G2 / (4 n.v n.l), from the cosines.
pub fn v_smith_ggx_correlated(nv: f64, nl: f64, alpha: f64) -> f64 {
    let g2 = g2_height_correlated(ggx_lambda_cos(nv, alpha), ggx_lambda_cos(nl, alpha));
    g2 / (4.0 * nv.abs() * nl.abs())
}

/// Unit vector from polar angle theta and azimuth phi (radians).
pub fn dir(theta: f64, phi: f64) -> [f64; 3] {
    [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()]
}

/// Normalize a vector.
pub fn normalize(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

/// Dot product.
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beckmann_lambda_matches_known_values() {
        // Lambda(a) at a = 1: (erf(1) - 1)/2 + exp(-1)/(2 sqrt(pi)) = 0.0251272708300061...
        assert!((beckmann_lambda_a(1.0) - 0.025_127_270_830_006_1).abs() < 1e-15);
        assert!((beckmann_lambda_a(3.0) / 5.591_724_962_696_005e-7 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn ggx_forms_agree() {
        let m = normalize([0.3, -0.2, 0.9]);
        let d = ggx_d(m, 0.4, 0.4);
        assert!((d / ggx_d_cos(m[2], 0.4) - 1.0).abs() < 1e-13);
        let v = v_smith_ggx_correlated(0.3, 0.8, 0.5);
        let a2: f64 = 0.25;
        let lagarde = 0.5 / (0.8 * (0.09 * (1.0 - a2) + a2).sqrt() + 0.3 * (0.64 * (1.0 - a2) + a2).sqrt());
        assert!((v / lagarde - 1.0).abs() < 1e-13);
    }
}
