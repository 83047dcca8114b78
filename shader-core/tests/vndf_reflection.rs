//! Domain behaviour of the reflection samplers of `shader_core::vndf` (docs/vndf.md): invalid
//! input, the smooth limit, degenerate and back-facing wi, samples below the horizon. Their
//! distributions are tested statistically in tests/tests/vndf_chi2.rs.

use shader_core::vndf::{self, ReflectionSample};
use shader_core::Vec3;

type Sampler = fn(Vec3, f32, f32, f32, f32) -> ReflectionSample;
type Pdf = fn(Vec3, Vec3, f32, f32) -> f32;

const SAMPLERS: [(&str, Sampler, Pdf); 4] = [
    ("ndf", vndf::sample_ndf, vndf::pdf_ndf),
    ("heitz", vndf::sample_vndf_heitz, vndf::pdf_vndf_heitz),
    ("caps", vndf::sample_vndf_caps, vndf::pdf_vndf_caps),
    ("bounded", vndf::sample_vndf_bounded, vndf::pdf_vndf_bounded),
];

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians() as f64, phi_deg.to_radians() as f64);
    Vec3::new((t.sin() * p.cos()) as f32, (t.sin() * p.sin()) as f32, t.cos() as f32)
}

fn is_nan_sample(s: ReflectionSample) -> bool {
    s.wo.x.is_nan() && s.wo.y.is_nan() && s.wo.z.is_nan() && s.pdf.is_nan()
}

fn us() -> Vec<(f32, f32)> {
    let mut v = Vec::new();
    for i in 0..16 {
        for j in 0..16 {
            v.push((i as f32 / 16.0 + 0.01, j as f32 / 16.0 + 0.02));
        }
    }
    v.extend([(0.0, 0.0), (0.0, 0.999_999_94), (0.999_999_94, 0.0), (0.999_999_94, 0.999_999_94), (0.5, 0.5)]);
    v
}

#[test]
fn invalid_input_gives_nan() {
    let wi = dir(30.0, 10.0);
    let wo = dir(40.0, 190.0);
    let bad_alpha = [-0.1f32, f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    let bad_wi = [Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0), Vec3::new(0.0, f32::INFINITY, 1.0)];
    for (name, sample, pdf) in SAMPLERS {
        for &a in &bad_alpha {
            assert!(is_nan_sample(sample(wi, a, 0.3, 0.4, 0.5)), "{name} alpha_x {a}");
            assert!(is_nan_sample(sample(wi, 0.3, a, 0.4, 0.5)), "{name} alpha_y {a}");
            assert!(pdf(wi, wo, a, 0.3).is_nan(), "{name} pdf alpha_x {a}");
            assert!(pdf(wi, wo, 0.3, a).is_nan(), "{name} pdf alpha_y {a}");
        }
        for &w in &bad_wi {
            assert!(is_nan_sample(sample(w, 0.3, 0.3, 0.4, 0.5)), "{name} wi {w:?}");
            assert!(pdf(w, wo, 0.3, 0.3).is_nan(), "{name} pdf wi {w:?}");
        }
        assert!(pdf(wi, Vec3::new(f32::NAN, 0.0, 1.0), 0.3, 0.3).is_nan(), "{name} pdf NaN wo");
    }
}

#[test]
fn valid_input_gives_finite_unit_directions() {
    let alphas = [(1e-4f32, 1e-4f32), (1e-3, 1e-3), (0.05, 1.0), (1.0, 0.05), (0.5, 0.5), (1.0, 1.0), (4.0, 4.0), (0.01, 0.2)];
    for (name, sample, _) in SAMPLERS {
        for &(ax, ay) in &alphas {
            for t in [0.0f32, 1e-3, 20.0, 60.0, 85.0, 89.0, 89.9, 90.0, 95.0, 140.0, 179.0] {
                let wi = dir(t, 33.0);
                for &(u1, u2) in &us() {
                    let s = sample(wi, ax, ay, u1, u2);
                    assert!(s.wo.is_finite() && s.pdf >= 0.0 && !s.pdf.is_nan(), "{name} theta {t} alpha ({ax}, {ay}) u ({u1}, {u2}): {s:?}");
                    if s.pdf > 0.0 {
                        assert!((s.wo.length() - 1.0).abs() < 1e-5, "{name} theta {t} alpha ({ax}, {ay}) u ({u1}, {u2}): {s:?}");
                    }
                }
            }
        }
    }
}

/// alpha = 0 is the smooth limit: the samplers return the limiting direction with pdf 0 and the
/// pdfs are 0 (as ggx_d): no finite density.
#[test]
fn zero_alpha_is_the_mirror_with_zero_density() {
    let wi = dir(35.0, 20.0);
    let mirror = Vec3::new(-wi.x, -wi.y, wi.z);
    for (name, sample, pdf) in SAMPLERS {
        for &(u1, u2) in &us() {
            let s = sample(wi, 0.0, 0.0, u1, u2);
            if u1 >= 0.999 && name == "ndf" {
                continue; // u1 -> 1 is the horizon of the stretched disk, undefined at alpha = 0
            }
            assert!((s.wo - mirror).length() < 1e-6, "{name} u ({u1}, {u2}): {s:?}");
            assert_eq!(s.pdf, 0.0, "{name}");
        }
        assert_eq!(pdf(wi, mirror, 0.0, 0.0), 0.0, "{name}");
        assert_eq!(pdf(wi, mirror, 0.0, 0.5), 0.0, "{name}");
    }
}

/// wi = -z: no normal of the upper microsurface is visible; the VNDF methods return NONE. NDF
/// sampling is independent of wi and still returns directions with a density.
#[test]
fn straight_from_below_has_no_visible_normal() {
    let wi = Vec3::new(0.0, 0.0, -1.0);
    for (name, sample, _) in SAMPLERS {
        for &(u1, u2) in &us() {
            let s = sample(wi, 0.3, 0.2, u1, u2);
            if name == "ndf" {
                assert!(s.wo.is_finite() && s.pdf > 0.0, "{name}: {s:?}");
            } else {
                assert_eq!(s, ReflectionSample::NONE, "{name}");
            }
        }
    }
}

/// Normal incidence: the Heitz basis is degenerate (Vh = z) and T1 = (1, 0, 0) is used; the
/// result must still be a proper VNDF sample with the same pdf as the pdf function.
#[test]
fn normal_incidence_uses_the_special_basis() {
    let wi = Vec3::Z;
    for &(u1, u2) in &us() {
        let s = vndf::sample_vndf_heitz(wi, 0.3, 0.1, u1, u2);
        assert!(s.wo.is_finite() && s.pdf > 0.0, "{s:?}");
        let q = vndf::pdf_vndf_heitz(wi, s.wo, 0.3, 0.1);
        assert!((s.pdf - q).abs() <= 1e-4 * q, "{} vs {q}", s.pdf);
    }
}

/// For wi.z <= 0 the bounded method is exactly the spherical-cap method (the paper's fallback).
#[test]
fn bounded_is_caps_for_back_facing_wi() {
    for t in [90.0f32, 91.0, 120.0, 170.0] {
        let wi = dir(t, 70.0);
        for &(u1, u2) in &us() {
            let a = vndf::sample_vndf_bounded(wi, 0.4, 0.1, u1, u2);
            let b = vndf::sample_vndf_caps(wi, 0.4, 0.1, u1, u2);
            assert_eq!(a, b, "theta {t}");
            assert_eq!(vndf::pdf_vndf_bounded(wi, b.wo, 0.4, 0.1).to_bits(), vndf::pdf_vndf_caps(wi, b.wo, 0.4, 0.1).to_bits());
        }
    }
}

/// Samples below the horizon are returned with their (positive) density; the estimator, not the
/// sampler, counts them as zero. At 80 degrees, alpha = 0.5, all four methods produce some.
#[test]
fn samples_below_the_horizon_keep_their_density() {
    let wi = dir(80.0, 0.0);
    for (name, sample, pdf) in SAMPLERS {
        let below: Vec<ReflectionSample> = us().iter().map(|&(u1, u2)| sample(wi, 0.5, 0.5, u1, u2)).filter(|s| s.wo.z < 0.0).collect();
        assert!(!below.is_empty(), "{name}");
        for s in below {
            assert!(s.pdf > 0.0);
            let q = pdf(wi, s.wo, 0.5, 0.5);
            assert!((s.pdf - q).abs() <= 1e-4 * q, "{name}: {} vs {q}", s.pdf);
        }
    }
}

/// The pdfs against the textbook formulas evaluated in f64.
#[test]
fn pdfs_match_the_formulas() {
    let (ax, ay) = (0.3f64, 0.12f64);
    let d = |m: [f64; 3]| {
        if m[2] <= 0.0 {
            return 0.0;
        }
        let q = m[0] * m[0] / (ax * ax) + m[1] * m[1] / (ay * ay) + m[2] * m[2];
        1.0 / (std::f64::consts::PI * ax * ay * q * q)
    };
    for (ti, po) in [(20.0f32, 40.0f32), (60.0, 200.0), (85.0, 170.0), (120.0, 10.0)] {
        let wi = dir(ti, 15.0);
        let wo = dir(po / 4.0, po);
        let i = [wi.x as f64, wi.y as f64, wi.z as f64];
        let o = [wo.x as f64, wo.y as f64, wo.z as f64];
        let h = [i[0] + o[0], i[1] + o[1], i[2] + o[2]];
        let l = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
        let mut m = [h[0] / l, h[1] / l, h[2] / l];
        let t = ((ax * i[0]).powi(2) + (ay * i[1]).powi(2) + i[2] * i[2]).sqrt();
        let vndf_ref = d(m) / (2.0 * (i[2] + t));
        if m[2] < 0.0 {
            m = [-m[0], -m[1], -m[2]];
        }
        let im = (i[0] * m[0] + i[1] * m[1] + i[2] * m[2]).abs();
        let ndf_ref = d(m) * m[2] / (4.0 * im);
        let got_ndf = vndf::pdf_ndf(wi, wo, ax as f32, ay as f32) as f64;
        let got_vndf = vndf::pdf_vndf(wi, wo, ax as f32, ay as f32) as f64;
        assert!((got_ndf - ndf_ref).abs() <= 1e-5 * ndf_ref, "ndf {got_ndf} vs {ndf_ref}");
        assert!((got_vndf - vndf_ref).abs() <= 1e-5 * vndf_ref.max(1e-30), "vndf {got_vndf} vs {vndf_ref}");
    }
}
