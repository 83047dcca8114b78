//! Stress test of `shader_core::fresnel`, `vndf` and `bxdf` over millions of inputs, adversarial
//! ones included: unnormalized, denormal, huge, zero, NaN and infinite directions; cos theta in
//! {-1 .. -1e-7, 0, 1e-7 .. 1}; alpha in {0, 1e-8, 1e-4 .. 1, > 1} plus invalid ones; eta near 1,
//! k = 0; NaN/Inf parameters. For valid input nothing may be NaN or infinite; for invalid input
//! the documented behaviour (docs/bxdf.md, "Invalid input") is asserted. Counts per class are
//! printed (`cargo test --release -p crosscheck --test bxdf_stress -- --nocapture`).

use shader_core::bxdf::{
    self, BSDFSample, BxDF, ConductorBxDF, DielectricBxDF, DiffuseBxDF, GltfMetalRoughBxDF, SpecularReflectionBxDF,
    TrowbridgeReitz, MODE_IMPORTANCE, MODE_RADIANCE, SAMPLE_ALL,
};
use shader_core::{fresnel, vndf, Vec3};
use std::collections::BTreeMap;

/// Per-class counters, printed at the end of each test.
#[derive(Default)]
struct Counts(BTreeMap<String, u64>);

impl Counts {
    fn add(&mut self, class: &str) {
        *self.0.entry(class.to_string()).or_default() += 1;
    }
    fn total(&self) -> u64 {
        self.0.values().sum()
    }
    fn print(&self, title: &str) {
        eprintln!("{title}: {} evaluations", self.total());
        for (k, v) in &self.0 {
            eprintln!("  {k:<58} {v:>10}");
        }
    }
}

/// The cosines of the test directions: both hemispheres, exactly grazing, and next to grazing.
fn cosines() -> Vec<f32> {
    let pos = [1e-7f32, 1e-5, 1e-3, 0.01, 0.05, 0.2, 0.5, 0.8, 0.95, 0.999, 1.0 - 1e-7, 1.0];
    let mut v = vec![0.0f32, -0.0];
    for c in pos {
        v.push(c);
        v.push(-c);
    }
    v
}

/// Unit directions (cos theta from [`cosines`], 5 azimuths), then unnormalized copies.
fn unit_dirs() -> Vec<Vec3> {
    let mut out = Vec::new();
    for c in cosines() {
        let s = (1.0 - (c as f64) * (c as f64)).max(0.0).sqrt();
        for k in 0..5 {
            let p = 2.0 * std::f64::consts::PI * (k as f64 + 0.13) / 5.0;
            out.push(Vec3::new((s * p.cos()) as f32, (s * p.sin()) as f32, c));
        }
    }
    out
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum DirClass {
    Unit,
    /// Finite, non-zero, not unit length (power-of-two scale: results must be bit-identical).
    ScaledPow2,
    /// Finite, non-zero, arbitrary scale (tiny, denormal, huge).
    Scaled,
    /// Zero vector or non-finite component: degenerate.
    Degenerate,
}

fn dirs() -> Vec<(Vec3, DirClass)> {
    let units = unit_dirs();
    let mut out: Vec<(Vec3, DirClass)> = units.iter().map(|&d| (d, DirClass::Unit)).collect();
    for (i, &d) in units.iter().enumerate() {
        // Every third direction scaled by 2^-100 (denormal-free after rescaling) and 2^60.
        if i % 3 == 0 {
            out.push((d * f32::from_bits(0x0d80_0000), DirClass::ScaledPow2)); // 2^-100
            out.push((d * f32::from_bits(0x5d80_0000), DirClass::ScaledPow2)); // 2^60
        }
        if i % 7 == 0 {
            out.push((d * 7.0, DirClass::Scaled));
            out.push((d * 1e-38, DirClass::Scaled)); // components denormal
            out.push((d * 3e38, DirClass::Scaled)); // squares overflow
        }
    }
    for d in [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(-0.0, 0.0, -0.0),
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, f32::NAN, 0.0),
        Vec3::new(f32::INFINITY, 0.0, 1.0),
        Vec3::new(0.0, 0.0, f32::NEG_INFINITY),
        Vec3::new(f32::INFINITY, f32::INFINITY, f32::INFINITY),
    ] {
        out.push((d, DirClass::Degenerate));
    }
    // Denormal-only and mixed extreme scales (valid, non-zero).
    out.push((Vec3::new(f32::from_bits(1), 0.0, f32::from_bits(3)), DirClass::Scaled));
    out.push((Vec3::new(1e-40, -1e-40, 1e-40), DirClass::Scaled));
    out.push((Vec3::new(1e30, 1e-30, -1e30), DirClass::Scaled));
    out
}

fn alphas_valid() -> Vec<f32> {
    vec![0.0, 1e-8, 1e-4, 9.9e-4, 1e-3, 0.01, 0.1, 0.3, 0.5, 1.0, 1.5, 4.0, 100.0]
}
fn alphas_invalid() -> Vec<f32> {
    vec![-0.1, f32::NAN, f32::INFINITY]
}
fn etas_valid() -> Vec<f32> {
    vec![1.0, 1.0 + 1.2e-7, 1.0 - 6e-8, 1.0001, 0.9999, 1.33, 1.5, 1.0 / 1.5, 2.4, 0.2, 1e-3, 1e3]
}
fn us() -> Vec<f32> {
    vec![0.0, 1e-7, 0.25, 0.5, 0.73, 0.999, 1.0 - f32::EPSILON / 2.0]
}

fn finite_nonneg(v: Vec3) -> bool {
    v.is_finite() && v.x >= 0.0 && v.y >= 0.0 && v.z >= 0.0
}
fn all_nan(v: Vec3) -> bool {
    v.x.is_nan() && v.y.is_nan() && v.z.is_nan()
}

/// Shared checks for a BxDF with valid parameters over every (wo, wi) pair and sample.
fn stress_bxdf(name: &str, b: &dyn BxDF, dirs: &[(Vec3, DirClass)], counts: &mut Counts) {
    let modes = [MODE_RADIANCE, MODE_IMPORTANCE];
    for &(wo, co) in dirs {
        for &(wi, ci) in dirs {
            for &mode in &modes[..if name.starts_with("dielectric") { 2 } else { 1 }] {
                let f = b.f(wo, wi, mode);
                let p = b.pdf(wo, wi, mode, SAMPLE_ALL);
                if co == DirClass::Degenerate || ci == DirClass::Degenerate {
                    assert!(f == Vec3::ZERO && p == 0.0, "{name}: degenerate ({wo:?}, {wi:?}) -> f {f:?} pdf {p}");
                    counts.add(&format!("{name} f/pdf degenerate direction -> 0"));
                    continue;
                }
                assert!(finite_nonneg(f), "{name}: f({wo:?}, {wi:?}) = {f:?}");
                assert!(p.is_finite() && p >= 0.0, "{name}: pdf({wo:?}, {wi:?}) = {p}");
                let class = match (co, ci) {
                    (DirClass::Unit, DirClass::Unit) => "unit",
                    (DirClass::ScaledPow2, _) | (_, DirClass::ScaledPow2) => "pow2-scaled",
                    _ => "scaled (tiny/denormal/huge)",
                };
                let zone = if wo.z == 0.0 || wi.z == 0.0 {
                    "grazing (z = 0)"
                } else if wo.z * wi.z > 0.0 {
                    "same side"
                } else {
                    "opposite sides"
                };
                counts.add(&format!("{name} f/pdf {class}, {zone}"));
                if wo.z == 0.0 || wi.z == 0.0 {
                    assert!(f == Vec3::ZERO && p == 0.0, "{name}: grazing must give 0: f {f:?} pdf {p}");
                }
            }
        }
    }
    // Power-of-two scaling is exact: f and pdf must be bit-identical to the unit inputs'.
    let units: Vec<Vec3> = dirs.iter().filter(|d| d.1 == DirClass::Unit).map(|d| d.0).collect();
    for (i, &wo) in units.iter().enumerate().step_by(3) {
        for &wi in units.iter().step_by(2) {
            for s in [f32::from_bits(0x0d80_0000), f32::from_bits(0x5d80_0000)] {
                assert_eq!(b.f(wo * s, wi, MODE_RADIANCE), b.f(wo, wi, MODE_RADIANCE), "{name}: scale {s:e} ({i})");
                assert_eq!(b.pdf(wo, wi * s, MODE_RADIANCE, SAMPLE_ALL), b.pdf(wo, wi, MODE_RADIANCE, SAMPLE_ALL));
                counts.add(&format!("{name} f/pdf 2^k scale invariance (bitwise)"));
            }
        }
    }
    let u = us();
    for &(wo, co) in dirs {
        for &uc in &u {
            for &u0 in &u {
                for &u1 in &u {
                    let s = b.sample_f(wo, uc, u0, u1, MODE_RADIANCE, SAMPLE_ALL);
                    if co == DirClass::Degenerate || wo.z == 0.0 {
                        assert_eq!(s, BSDFSample::NONE, "{name}: sample for degenerate/grazing wo {wo:?}");
                        counts.add(&format!("{name} sample_f degenerate or grazing wo -> none"));
                        continue;
                    }
                    if !s.is_valid() {
                        assert_eq!(s, BSDFSample::NONE, "{name}: an invalid sample is all zero");
                        counts.add(&format!("{name} sample_f no sample (rejected)"));
                        continue;
                    }
                    assert!(s.pdf > 0.0 && s.pdf.is_finite(), "{name}: {wo:?} {uc} {u0} {u1} -> {s:?}");
                    assert!(finite_nonneg(s.f), "{name}: {wo:?} {uc} {u0} {u1} -> {s:?}");
                    assert!(s.wi.is_finite() && s.wi.z != 0.0, "{name}: {s:?}");
                    let len = s.wi.length();
                    assert!((len - 1.0).abs() < 1e-3, "{name}: |wi| = {len}: {s:?}");
                    assert!(s.eta.is_finite() && s.eta > 0.0);
                    assert_eq!(s.flags & !b.flags(), 0, "{name}: sample flags {} not in {}", s.flags, b.flags());
                    let weight = s.f * (s.wi.z.abs() / s.pdf);
                    assert!(weight.is_finite(), "{name}: f cos / pdf not finite: {s:?}");
                    counts.add(&format!(
                        "{name} sample_f valid ({})",
                        if s.flags & bxdf::SPECULAR != 0 { "specular" } else if s.flags & bxdf::TRANSMISSION != 0 { "transmission" } else { "reflection" }
                    ));
                }
            }
        }
    }
}

/// Invalid parameters: f and pdf are NaN, sample_f has flags 0 and NaN f / pdf.
fn stress_invalid(name: &str, b: &dyn BxDF, dirs: &[(Vec3, DirClass)], counts: &mut Counts) {
    for &(wo, _) in dirs.iter().step_by(4) {
        for &(wi, _) in dirs.iter().step_by(5) {
            let f = b.f(wo, wi, MODE_RADIANCE);
            let p = b.pdf(wo, wi, MODE_RADIANCE, SAMPLE_ALL);
            assert!(all_nan(f) && p.is_nan(), "{name}: invalid parameters must give NaN: f {f:?} pdf {p}");
            counts.add(&format!("{name} invalid parameters f/pdf -> NaN"));
        }
        let s = b.sample_f(wo, 0.3, 0.4, 0.6, MODE_RADIANCE, SAMPLE_ALL);
        assert!(s.flags == 0 && s.pdf.is_nan() && all_nan(s.f), "{name}: {s:?}");
        counts.add(&format!("{name} invalid parameters sample_f -> flags 0, NaN"));
    }
}

#[test]
fn bxdfs_never_produce_nan_or_inf_for_valid_input() {
    let d = dirs();
    let mut counts = Counts::default();
    let gold = (Vec3::new(0.18836, 0.54836, 1.3319), Vec3::new(3.4034, 2.2309, 1.8693));
    stress_bxdf("lambert", &DiffuseBxDF::new(Vec3::new(0.2, 0.5, 1.0)), &d, &mut counts);
    stress_bxdf("mirror", &SpecularReflectionBxDF::new(Vec3::new(1.0, 0.5, 0.0)), &d, &mut counts);
    for a in alphas_valid() {
        for (eta, k) in [gold, (Vec3::new(1.5, 1.0, 0.2), Vec3::ZERO), (Vec3::ZERO, Vec3::new(1.0, 1e-3, 100.0))] {
            stress_bxdf("conductor", &ConductorBxDF::new(TrowbridgeReitz::new(a, a * 0.5), eta, k), &d, &mut counts);
        }
    }
    for a in alphas_valid() {
        for eta in etas_valid() {
            stress_bxdf("dielectric", &DielectricBxDF::new(TrowbridgeReitz::new(a, a), eta), &d, &mut counts);
        }
    }
    for r in [0.0f32, 0.01, 0.0316, 0.05, 0.3, 1.0, 2.0, -1.0] {
        for m in [0.0f32, 0.5, 1.0] {
            for base in [Vec3::ZERO, Vec3::new(0.9, 0.5, 0.1), Vec3::new(1.0, 1.0, 1.0), Vec3::new(2.0, -1.0, 0.5)] {
                stress_bxdf("gltf", &GltfMetalRoughBxDF::new(base, m, r), &d, &mut counts);
            }
        }
    }
    // Invalid parameters.
    for a in alphas_invalid() {
        stress_invalid("conductor", &ConductorBxDF::new(TrowbridgeReitz::new(a, 0.1), gold.0, gold.1), &d, &mut counts);
        stress_invalid("dielectric", &DielectricBxDF::new(TrowbridgeReitz::new(0.1, a), 1.5), &d, &mut counts);
    }
    for (eta, k) in [(-1.0f32, 1.0f32), (1.0, -1.0), (0.0, 0.0), (f32::NAN, 1.0), (1.0, f32::INFINITY)] {
        stress_invalid("conductor", &ConductorBxDF::new(TrowbridgeReitz::new(0.1, 0.1), Vec3::new(1.0, eta, 1.0), Vec3::new(1.0, k, 1.0)), &d, &mut counts);
    }
    for eta in [0.0f32, -1.5, f32::NAN, f32::INFINITY] {
        stress_invalid("dielectric", &DielectricBxDF::new(TrowbridgeReitz::new(0.1, 0.1), eta), &d, &mut counts);
    }
    stress_invalid("lambert", &DiffuseBxDF::new(Vec3::new(f32::NAN, 0.5, 0.5)), &d, &mut counts);
    stress_invalid("gltf", &GltfMetalRoughBxDF::new(Vec3::new(0.5, 0.5, 0.5), f32::NAN, 0.5), &d, &mut counts);
    stress_invalid("gltf", &GltfMetalRoughBxDF::new(Vec3::new(0.5, 0.5, 0.5), 0.5, f32::NAN), &d, &mut counts);
    counts.print("BxDF stress");
    assert!(counts.total() >= 1_000_000, "at least 10^6 inputs");
}

#[test]
fn fresnel_stress() {
    let mut counts = Counts::default();
    let mut cos = cosines();
    cos.extend([1.0 + 1e-6, -1.0 - 1e-6, 2.0, -7.0, f32::INFINITY, f32::NEG_INFINITY]);
    // Dense cosines as well.
    for i in 0..=2000 {
        cos.push(-1.0 + i as f32 / 1000.0);
    }
    let mut etas = etas_valid();
    etas.extend([1e-30, 1e30, f32::from_bits(1), f32::MAX, 1.0 + 1e-3, 0.5, 3.0]);
    for i in 1..400 {
        etas.push(0.05 * i as f32);
    }
    for &c in &cos {
        for &eta in &etas {
            let f = fresnel::dielectric(c, eta);
            assert!((0.0..=1.0).contains(&f), "dielectric({c}, {eta}) = {f}");
            counts.add(if c.abs() > 1.0 { "dielectric |cos| > 1 (clamped)" } else if c < 0.0 { "dielectric inside (cos < 0)" } else { "dielectric outside (cos >= 0)" });
            if eta == 1.0 && c.abs() <= 1.0 && c != 0.0 {
                assert_eq!(f, 0.0, "index-matched interface reflects nothing");
            }
            for k in [0.0f32, 1e-3, 0.5, 3.4, 100.0, 1e6] {
                let fc = fresnel::conductor(c, eta, k);
                assert!((0.0..=1.0 + 1e-6).contains(&fc), "conductor({c}, {eta}, {k}) = {fc}");
                counts.add(if k == 0.0 { "conductor k = 0" } else { "conductor k > 0" });
            }
            let s = fresnel::schlick(c, fresnel::f0_from_eta(eta), 1.0);
            assert!(s.is_finite() && (0.0..=1.0).contains(&s), "schlick {c} {eta} {s}");
            counts.add("schlick");
        }
        for eta in [0.0f32, -1.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert!(fresnel::dielectric(c, eta).is_nan());
            assert!(fresnel::conductor(c, eta, 1.0).is_nan() || eta == 0.0);
            counts.add("invalid eta -> NaN");
        }
        assert!(fresnel::conductor(c, 0.0, 0.0).is_nan());
        assert!(fresnel::conductor(c, 1.0, -1.0).is_nan());
        assert!(fresnel::conductor(c, 1.0, f32::NAN).is_nan());
        counts.add("invalid k -> NaN");
    }
    assert!(fresnel::dielectric(f32::NAN, 1.5).is_nan() && fresnel::conductor(f32::NAN, 1.5, 1.0).is_nan());
    assert!(fresnel::schlick(f32::NAN, 0.04, 1.0).is_nan());
    // Gulbrandsen over the whole square, out of range (clamped) and NaN.
    for i in -20..=120 {
        for j in -20..=120 {
            let (r, g) = (i as f32 / 100.0, j as f32 / 100.0);
            let nk = fresnel::gulbrandsen_nk(r, g);
            assert!(nk.re.is_finite() && nk.re > 0.0 && nk.im.is_finite() && nk.im >= 0.0, "({r}, {g}) -> {nk:?}");
            let back = fresnel::gulbrandsen_r_g(nk.re, nk.im);
            assert!(back.r.is_finite() && back.g.is_finite());
            counts.add(if (0.0..=0.99).contains(&r) && (0.0..=1.0).contains(&g) { "gulbrandsen in range" } else { "gulbrandsen clamped" });
        }
    }
    assert!(fresnel::gulbrandsen_nk(f32::NAN, 0.5).re.is_nan());
    assert!(fresnel::gulbrandsen_r_g(-1.0, 0.5).r.is_nan());
    // refract over unit directions, normals and etas.
    let ud = unit_dirs();
    for &wi in &ud {
        for n in [Vec3::Z, -Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, -0.28, 0.96)] {
            for &eta in &etas {
                let r = fresnel::refract(wi, n, eta);
                if r.valid == 1 {
                    assert!(r.wt.is_finite() && (r.wt.length() - 1.0).abs() < 1e-5, "{wi:?} {n:?} {eta} -> {r:?}");
                    assert!(r.wt.dot(n) * wi.dot(n) <= 0.0, "refracted to the same side: {wi:?} {n:?} {eta} -> {r:?}");
                    counts.add("refract transmitted");
                } else {
                    assert_eq!(r.wt, Vec3::ZERO);
                    counts.add("refract total internal reflection");
                }
            }
            for eta in [0.0f32, -1.0, f32::NAN, f32::INFINITY] {
                let r = fresnel::refract(wi, n, eta);
                assert!(r.valid == 0 && r.wt == Vec3::ZERO && r.etap.is_nan());
                counts.add("refract invalid eta -> valid 0, etap NaN");
            }
        }
    }
    counts.print("Fresnel stress");
    assert!(counts.total() >= 1_000_000);
}

#[test]
fn vndf_sampler_stress() {
    let mut counts = Counts::default();
    let ud = unit_dirs();
    let mut u = us();
    for i in 0..40 {
        u.push((i as f32 + 0.5) / 40.0);
    }
    for &w in &ud {
        for a in [1e-3f32, 1e-2, 0.1, 0.5, 1.0, 4.0, 100.0] {
            for ay in [a, a * 0.1] {
                for &u0 in &u {
                    for &u1 in &u {
                        let wm = vndf::ggx_sample_visible_heitz2018(w, a, ay, u0, u1);
                        assert!(wm.is_finite(), "{w:?} {a} {ay} {u0} {u1} -> {wm:?}");
                        assert!(wm.z > 0.0 && (wm.length() - 1.0).abs() < 1e-5, "{w:?} {a} {u0} {u1} -> {wm:?}");
                        let p = vndf::ggx_visible_pdf(w, wm, a, ay);
                        if w.z == 0.0 {
                            // Exactly grazing: G1 = 0 and |w.z| = 0 give 0/0 (documented: NaN).
                            assert!(p.is_nan() || p == 0.0);
                            counts.add("vndf grazing w (pdf undefined)");
                        } else {
                            assert!(p.is_finite() && p >= 0.0, "pdf {w:?} {wm:?} {a} -> {p}");
                            counts.add("vndf valid");
                        }
                    }
                }
            }
        }
    }
    // Documented invalid input: zero w -> NaN components.
    let wm = vndf::ggx_sample_visible_heitz2018(Vec3::ZERO, 0.5, 0.5, 0.3, 0.3);
    assert!(wm.x.is_nan() || wm.y.is_nan() || wm.z.is_nan());
    counts.print("VNDF stress");
    assert!(counts.total() >= 100_000);
}
