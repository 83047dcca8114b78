//! Numerical stress of every NDF, Lambda/G1, G2 and visibility function of `shader_core::{ndf,
//! masking}`: at least 10^6 inputs per function class, built from roughness {0, 1e-8, 1e-4 .. 1, > 1}
//! plus invalid values, cosines {-1 .. -1e-7, ±0, 1e-7 .. 1} plus out-of-range ones, unit,
//! unnormalized (denormal and huge components), degenerate, NaN and infinite vectors.
//!
//! For valid input every result must be finite and in range (D >= 0, Lambda >= 0, G1 and G2 in
//! [0, 1], V >= 0), except the documented infinities (Lambda at w.z = 0, or where the exact Lambda
//! exceeds f32::MAX, or where z is below 2^-149 of the largest component and vanishes in the exact
//! rescaling; V where its exact denominator vanishes; `ggx_d_ue4`'s cancellation at NoH = 1 for
//! alpha < 2^-12), which are asserted to be exactly those cases. Power-of-two scalings of a direction must give identical
//! bits (the functions are scale invariant and rescale exactly). Invalid input must give the
//! documented result (NaN, or 0 for D of a vector with z <= 0), checked for every such input.
//! The test prints how many inputs of each class were tried.
//!
//! Run: `cargo test --release -p crosscheck --test microfacet_stress -- --nocapture`.

use host::microfacet_ref as r64;
use shader_core::{masking, ndf, Vec3};
use std::collections::BTreeMap;

/// Valid roughness: 0 (both signs), tiny, the usual range, and rough (> 1).
const ALPHAS: [f32; 19] = [0.0, -0.0, 1e-8, 1e-6, 1e-4, 1e-3, 0.01, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0, 1.5, 4.0, 100.0, 1e4];
/// Invalid roughness: negative, infinite, NaN.
const BAD_ALPHAS: [f32; 6] = [-1e-30, -0.1, -1.0, f32::NEG_INFINITY, f32::INFINITY, f32::NAN];

/// Cosines in [-1, 1]: both signs, the signed zeros, tiny, near 1.
fn cosines() -> Vec<f32> {
    let pos = [
        1e-7f32, 1e-6, 1e-5, 1e-4, 1e-3, 0.01, 0.03, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99, 0.999, 0.9999,
        0.99999, 0.9999999, 1.0,
    ];
    let mut v = vec![0.0, -0.0];
    v.extend(pos);
    v.extend(pos.iter().map(|c| -c));
    v
}

/// Cosines outside [-1, 1]: clamped to 1 in magnitude by the visibility terms (documented).
const OUT_OF_RANGE_COS: [f32; 6] = [1.000_000_1, -1.000_000_1, 2.0, -5.0, 1e30, f32::INFINITY];

/// Unit directions from every cosine at 8 azimuths.
fn unit_dirs() -> Vec<Vec3> {
    let mut v = Vec::new();
    for &c in &cosines() {
        let s = (1.0 - (c as f64) * (c as f64)).max(0.0).sqrt();
        for j in 0..8 {
            let p = 0.3 + j as f64 * std::f64::consts::PI / 4.0;
            v.push(Vec3::new((s * p.cos()) as f32, (s * p.sin()) as f32, c));
        }
    }
    v
}

/// Scales applied to unit directions: exact powers of two (results must be bit-identical) and
/// others (denormal and huge components; results must be valid).
const POW2_SCALES: [f32; 2] = [1.0 / 1_267_650_600_228_229_401_496_703_205_376.0, 1_267_650_600_228_229_401_496_703_205_376.0]; // 2^-100, 2^100
const OTHER_SCALES: [f32; 5] = [1e-38, 3e-42, 1e-30, 7.3, 1e30];

/// Valid (finite, non-zero) directions: unit, scaled, and degenerate-but-valid ones.
fn valid_dirs() -> Vec<Vec3> {
    let units = unit_dirs();
    let mut v = units.clone();
    for &s in POW2_SCALES.iter().chain(OTHER_SCALES.iter()) {
        v.extend(units.iter().map(|&u| u * s));
    }
    let t = f32::from_bits(1);
    v.extend([
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(t, 0.0, 1.0),
        Vec3::new(0.0, 0.0, t),
        Vec3::new(t, t, t),
        Vec3::new(t, -t, -t),
        Vec3::new(f32::MAX, f32::MAX, f32::MAX),
        Vec3::new(-f32::MAX, 0.0, f32::MAX),
        Vec3::new(1e-30, 0.0, 0.0),
        Vec3::new(1.0, 1.0, t),
        Vec3::new(f32::MAX, 0.0, t),
    ]);
    v
}

/// Invalid directions: zero vectors and NaN or infinite components.
fn invalid_dirs() -> Vec<Vec3> {
    let (n, i) = (f32::NAN, f32::INFINITY);
    vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(-0.0, 0.0, -0.0),
        Vec3::new(n, 0.0, 1.0),
        Vec3::new(0.0, n, 1.0),
        Vec3::new(0.0, 0.0, n),
        Vec3::new(i, 0.0, 1.0),
        Vec3::new(0.0, -i, 1.0),
        Vec3::new(0.0, 0.0, i),
        Vec3::new(0.0, 0.0, -i),
        Vec3::new(i, i, i),
    ]
}

fn alpha_pairs() -> Vec<(f32, f32)> {
    let mut v: Vec<(f32, f32)> = ALPHAS.iter().map(|&a| (a, a)).collect();
    let sub = [0.0f32, 1e-8, 1e-4, 0.01, 0.1, 0.5, 1.0, 4.0];
    for &a in &sub {
        for &b in &sub {
            if a != b {
                v.push((a, b));
            }
        }
    }
    v
}

fn bad_alpha_pairs() -> Vec<(f32, f32)> {
    let mut v = Vec::new();
    for &b in &BAD_ALPHAS {
        v.push((b, b));
        v.push((b, 0.5));
        v.push((0.5, b));
    }
    v
}

/// Per-function counts, printed as a table.
#[derive(Default)]
struct Tally {
    class: &'static str,
    valid: usize,
    invalid: usize,
    documented_inf: usize,
    pow2_checked: usize,
}

struct Report(BTreeMap<&'static str, Tally>);

impl Report {
    fn new() -> Self {
        Report(BTreeMap::new())
    }
    fn t(&mut self, class: &'static str, name: &'static str) -> &mut Tally {
        self.0.entry(name).or_insert_with(|| Tally { class, ..Default::default() })
    }
    fn print(&self) {
        println!(
            "\n{:<10} {:<36} {:>10} {:>10} {:>10} {:>12} {:>11}",
            "class", "function", "inputs", "valid", "invalid", "exact +Inf", "2^k-scaled"
        );
        let mut per_class: BTreeMap<&str, usize> = BTreeMap::new();
        let mut rows: Vec<(&&str, &Tally)> = self.0.iter().collect();
        rows.sort_by_key(|(n, t)| (t.class, **n));
        for (name, t) in rows {
            let n = t.valid + t.invalid;
            *per_class.entry(t.class).or_default() += n;
            println!(
                "{:<10} {:<36} {:>10} {:>10} {:>10} {:>12} {:>11}",
                t.class, name, n, t.valid, t.invalid, t.documented_inf, t.pow2_checked
            );
        }
        println!();
        for (c, n) in &per_class {
            println!("class {c:<10} {n:>10} inputs");
        }
    }
}

fn check_range(name: &str, x: f32, lo: f32, hi: f32, ctx: &dyn Fn() -> String) {
    assert!(x.is_finite() && x >= lo && x <= hi, "{name}: {x} outside [{lo}, {hi}] for valid input {}", ctx());
}

type DirFn = fn(Vec3, f32, f32) -> f32;

#[test]
fn stress_every_microfacet_function() {
    let mut rep = Report::new();
    let dirs = valid_dirs();
    let bad_dirs = invalid_dirs();
    let pairs = alpha_pairs();
    let bad_pairs = bad_alpha_pairs();
    let units = unit_dirs();

    // ---- NDFs of a direction and (alpha_x, alpha_y) ----
    let d_aniso: [(&'static str, DirFn); 2] = [("ggx_d", ndf::ggx_d), ("beckmann_d", ndf::beckmann_d)];
    let d_iso: [(&'static str, DirFn); 3] = [
        ("gtr1_d", |w, a, _| ndf::gtr1_d(w, a)),
        ("gtr2_d", |w, a, _| ndf::gtr2_d(w, a)),
        ("blinn_phong_d (n from alpha)", |w, a, _| ndf::blinn_phong_d(w, ndf::blinn_phong_exponent_from_alpha(a))),
    ];
    for (name, f) in d_aniso.iter().chain(d_iso.iter()) {
        let iso = !name.starts_with("ggx") && !name.starts_with("beckmann");
        for &(ax, ay) in &pairs {
            if iso && ax != ay {
                continue;
            }
            // Blinn-Phong exists for alpha <= 1 only (n >= 0); alpha > 1 is its invalid input.
            let bp_invalid = name.starts_with("blinn") && ax > 1.0;
            for &w in &dirs {
                let d = f(w, ax, ay);
                let t = rep.t("D", name);
                if bp_invalid {
                    assert!(d.is_nan(), "{name}({w:?}, {ax}) = {d}, expected NaN (alpha > 1 maps to n < 0)");
                    t.invalid += 1;
                    continue;
                }
                t.valid += 1;
                check_range(name, d, 0.0, f32::MAX, &|| format!("{w:?} {ax} {ay}"));
                if w.z <= 0.0 || ax == 0.0 || ay == 0.0 {
                    assert_eq!(d, 0.0, "{name}({w:?}, {ax}, {ay}) must be 0");
                }
            }
            for &u in &units {
                for &s in &POW2_SCALES {
                    let (a, b) = (f(u * s, ax, ay), f(u, ax, ay));
                    assert!(a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()), "{name} not scale invariant at {u:?} * {s}");
                    rep.t("D", name).pow2_checked += 1;
                }
            }
            for &w in &bad_dirs {
                let d = f(w, ax, ay);
                if w.is_finite() && !bp_invalid {
                    assert_eq!(d, 0.0, "{name}(zero vector) must be 0 (z <= 0)");
                } else {
                    assert!(d.is_nan(), "{name}({w:?}) = {d}, expected NaN");
                }
                rep.t("D", name).invalid += 1;
            }
        }
        for &(ax, ay) in &bad_pairs {
            for &w in dirs.iter().step_by(7) {
                let d = f(w, ax, ay);
                // The isotropic ones read alpha_x only.
                if iso && ax.is_finite() && ax >= 0.0 {
                    continue;
                }
                assert!(d.is_nan(), "{name}({w:?}, {ax}, {ay}) = {d}, expected NaN");
                rep.t("D", name).invalid += 1;
            }
        }
    }
    // Blinn-Phong by exponent: n in [0, +Inf] valid (+Inf is a mirror: 0), n < 0 or NaN invalid.
    let exps = [0.0f32, 1e-6, 0.5, 1.0, 10.0, 1e3, 1e6, 2e8, 1e30, f32::INFINITY];
    for &n in &exps {
        for &w in &dirs {
            let d = ndf::blinn_phong_d(w, n);
            check_range("blinn_phong_d", d, 0.0, f32::MAX, &|| format!("{w:?} n={n}"));
            if n == f32::INFINITY {
                assert_eq!(d, 0.0);
            }
            rep.t("D", "blinn_phong_d").valid += 1;
        }
    }
    for &n in &[-1e-30f32, -0.5, -1.0, f32::NEG_INFINITY, f32::NAN] {
        for &w in &dirs {
            assert!(ndf::blinn_phong_d(w, n).is_nan());
            rep.t("D", "blinn_phong_d").invalid += 1;
        }
    }
    // The forms from n.h: valid n.h in [-1, 1] (n.h > 1 clamped), alpha as above.
    let mut cos_h = cosines();
    cos_h.extend([1.000_000_1f32, 2.0]);
    for i in 0..20_000 {
        cos_h.push(((i as f64 + 0.5) / 20_000.0) as f32);
    }
    let nh_forms: [(&'static str, fn(f32, f32) -> f32); 2] = [("ggx_d_ue4", ndf::ggx_d_ue4), ("ggx_d_mobile_naive", ndf::ggx_d_mobile_naive)];
    for (name, f) in nh_forms {
        for &a in &ALPHAS {
            for &c in &cos_h {
                let d = f(c, a);
                let t = rep.t("D", name);
                t.valid += 1;
                if d == f32::INFINITY {
                    // ggx_d_ue4: d = (c a^2 - c) c + 1 cancels to 0 at c = 1 once a^2 < 2^-24.
                    assert!(name == "ggx_d_ue4" && c >= 1.0 && a < 2.45e-4 && a > 0.0, "{name}({c}, {a}) = +Inf");
                    t.documented_inf += 1;
                    continue;
                }
                check_range(name, d, 0.0, f32::MAX, &|| format!("n.h={c} alpha={a}"));
            }
            assert!(f(f32::NAN, a).is_nan());
            rep.t("D", name).invalid += 1;
        }
        for &a in &BAD_ALPHAS {
            for &c in &cos_h {
                assert!(f(c, a).is_nan(), "{name}({c}, {a})");
                rep.t("D", name).invalid += 1;
            }
        }
    }
    for &a in &ALPHAS {
        for &w in &units {
            let d = ndf::ggx_d_mobile(w, a);
            check_range("ggx_d_mobile", d, 0.0, f32::MAX, &|| format!("{w:?} alpha={a}"));
            rep.t("D", "ggx_d_mobile").valid += 1;
        }
        for &w in &bad_dirs {
            let d = ndf::ggx_d_mobile(w, a);
            assert!(if w.is_finite() { d == 0.0 } else { d.is_nan() });
            rep.t("D", "ggx_d_mobile").invalid += 1;
        }
    }
    for &a in &BAD_ALPHAS {
        for &w in &units {
            assert!(ndf::ggx_d_mobile(w, a).is_nan());
            rep.t("D", "ggx_d_mobile").invalid += 1;
        }
    }

    // ---- Lambda and G1 ----
    let lambdas: [(&'static str, DirFn, bool); 6] = [
        ("ggx_lambda", masking::ggx_lambda, true),
        ("ggx_g1", masking::ggx_g1, false),
        ("beckmann_lambda", masking::beckmann_lambda, true),
        ("beckmann_g1", masking::beckmann_g1, false),
        ("beckmann_lambda_walter", masking::beckmann_lambda_walter, true),
        ("beckmann_g1_walter", masking::beckmann_g1_walter, false),
    ];
    for (name, f, is_lambda) in lambdas {
        for &(ax, ay) in &pairs {
            for &w in &dirs {
                let x = f(w, ax, ay);
                let t = rep.t("Lambda/G1", name);
                t.valid += 1;
                if w.z == 0.0 {
                    assert_eq!(x, if is_lambda { f32::INFINITY } else { 0.0 }, "{name}({w:?}) at grazing");
                    if is_lambda {
                        t.documented_inf += 1;
                    }
                    continue;
                }
                if is_lambda {
                    if x == f32::INFINITY {
                        // Documented: the exact Lambda exceeds f32::MAX, or z is below 2^-149 of the
                        // largest component (vanishes in the exact rescaling: treated as grazing).
                        let w64 = [w.x as f64, w.y as f64, w.z as f64];
                        let exact = if name.starts_with("ggx") {
                            r64::ggx_lambda(w64, ax as f64, ay as f64)
                        } else {
                            r64::beckmann_lambda(w64, ax as f64, ay as f64)
                        };
                        assert!(exact > f32::MAX as f64 || w.pow2_rescaled().z == 0.0, "{name}({w:?}, {ax}, {ay}) = +Inf, exact {exact:e}");
                        t.documented_inf += 1;
                        continue;
                    }
                    check_range(name, x, 0.0, f32::MAX, &|| format!("{w:?} {ax} {ay}"));
                    if ax == 0.0 && ay == 0.0 {
                        assert_eq!(x, 0.0);
                    }
                } else {
                    check_range(name, x, 0.0, 1.0, &|| format!("{w:?} {ax} {ay}"));
                }
            }
            for &u in &units {
                for &s in &POW2_SCALES {
                    assert_eq!(f(u * s, ax, ay).to_bits(), f(u, ax, ay).to_bits(), "{name} not scale invariant at {u:?} * {s}");
                    rep.t("Lambda/G1", name).pow2_checked += 1;
                }
            }
            for &w in &bad_dirs {
                assert!(f(w, ax, ay).is_nan(), "{name}({w:?}) expected NaN");
                rep.t("Lambda/G1", name).invalid += 1;
            }
        }
        for &(ax, ay) in &bad_pairs {
            for &w in &dirs {
                assert!(f(w, ax, ay).is_nan(), "{name}({w:?}, {ax}, {ay}) expected NaN");
                rep.t("Lambda/G1", name).invalid += 1;
            }
        }
    }

    // ---- G2 of (wo, wi) ----
    let g2s: [(&'static str, fn(Vec3, Vec3, f32, f32) -> f32); 5] = [
        ("ggx_g2_separable", masking::ggx_g2_separable),
        ("ggx_g2_height_correlated", masking::ggx_g2_height_correlated),
        ("ggx_g2_direction_correlated", masking::ggx_g2_direction_correlated),
        ("ggx_g2_height_direction_correlated", masking::ggx_g2_height_direction_correlated),
        ("beckmann_g2_height_correlated", masking::beckmann_g2_height_correlated),
    ];
    let g2_dirs: Vec<Vec3> = dirs.iter().step_by(13).copied().collect();
    let g2_alphas: Vec<(f32, f32)> = pairs.iter().step_by(2).copied().collect();
    for (name, f) in g2s {
        for &(ax, ay) in &g2_alphas {
            for &wo in &g2_dirs {
                for &wi in &g2_dirs {
                    let g = f(wo, wi, ax, ay);
                    check_range(name, g, 0.0, 1.0, &|| format!("{wo:?} {wi:?} {ax} {ay}"));
                    if wo.z == 0.0 || wi.z == 0.0 {
                        assert_eq!(g, 0.0, "{name} at grazing");
                    }
                    rep.t("G2", name).valid += 1;
                }
                for &b in &bad_dirs {
                    assert!(f(wo, b, ax, ay).is_nan() && f(b, wo, ax, ay).is_nan(), "{name}({wo:?}, {b:?})");
                    rep.t("G2", name).invalid += 2;
                }
            }
        }
        for &(ax, ay) in &bad_pairs {
            for &wo in g2_dirs.iter().step_by(3) {
                for &wi in g2_dirs.iter().step_by(3) {
                    assert!(f(wo, wi, ax, ay).is_nan());
                    rep.t("G2", name).invalid += 1;
                }
            }
        }
    }

    // ---- Visibility terms from cosines ----
    let mut cs = cosines();
    for i in 0..160 {
        cs.push((((i as f64 + 0.5) / 160.0) * 2.0 - 1.0) as f32);
    }
    // The visibility terms' roughness domain is [0, 1] (the engines'); alpha > 1 is invalid there.
    let v_alphas: Vec<f32> = ALPHAS.iter().copied().filter(|&a| a <= 1.0).collect();
    let v_bad_alphas: Vec<f32> = ALPHAS.iter().copied().filter(|&a| a > 1.0).chain(BAD_ALPHAS).collect();
    // (name, V, predicate for the documented exact +Inf given (nv, nl, alpha) as |cos|).
    type VFn = fn(f32, f32, f32) -> f32;
    let exact_inf = |nv: f32, nl: f32, a: f32| (nv == 0.0 && nl == 0.0) || (a == 0.0 && (nv == 0.0 || nl == 0.0));
    let never = |_: f32, _: f32, _: f32| false;
    let neumann_inf = |nv: f32, nl: f32, _: f32| nv == 0.0 && nl == 0.0;
    let vs: [(&'static str, VFn, &dyn Fn(f32, f32, f32) -> bool); 11] = [
        ("v_frostbite", masking::v_frostbite, &exact_inf),
        ("v_hdrp", masking::v_hdrp, &exact_inf),
        ("v_filament", masking::v_filament, &exact_inf),
        ("v_hdrp_approx", masking::v_hdrp_approx, &exact_inf),
        ("v_ue4", masking::v_ue4, &exact_inf),
        ("v_filament_fast", masking::v_filament_fast, &exact_inf),
        ("v_respawn", masking::v_respawn, &exact_inf),
        ("v_schlick_smith", masking::v_schlick_smith, &exact_inf),
        ("v_schlick_smith_remapped", masking::v_schlick_smith_remapped, &never),
        ("v_implicit", |v, l, _| masking::v_implicit(v, l), &never),
        ("v_neumann", |v, l, _| masking::v_neumann(v, l), &neumann_inf),
    ];
    for (name, f, inf_ok) in vs {
        for &a in &v_alphas {
            for &nv in cs.iter().chain(OUT_OF_RANGE_COS.iter()) {
                for &nl in cs.iter().chain(OUT_OF_RANGE_COS.iter()) {
                    let x = f(nv, nl, a);
                    let t = rep.t("V", name);
                    t.valid += 1;
                    let (cv, cl) = (nv.abs().min(1.0), nl.abs().min(1.0));
                    if x == f32::INFINITY {
                        assert!(inf_ok(cv, cl, a), "{name}({nv}, {nl}, {a}) = +Inf");
                        t.documented_inf += 1;
                        continue;
                    }
                    check_range(name, x, 0.0, f32::MAX, &|| format!("n.v={nv} n.l={nl} alpha={a}"));
                }
                assert!(f(nv, f32::NAN, a).is_nan() && f(f32::NAN, nv, a).is_nan(), "{name} NaN cosine");
                rep.t("V", name).invalid += 2;
            }
        }
        if !matches!(name, "v_implicit" | "v_neumann") {
            for &a in &v_bad_alphas {
                for &nv in &cs {
                    for &nl in &cs {
                        assert!(f(nv, nl, a).is_nan(), "{name}({nv}, {nl}, {a}) expected NaN");
                        rep.t("V", name).invalid += 1;
                    }
                }
            }
        }
    }
    // Kelemen (v.h) and Cook-Torrance (n.v, n.l, n.h, v.h).
    let fine: Vec<f32> = (0..400_000).map(|i| (((i as f64 + 0.5) / 400_000.0) * 2.0 - 1.0) as f32).chain(cs.iter().copied()).collect();
    for &vh in fine.iter().chain(OUT_OF_RANGE_COS.iter()) {
        let x = masking::v_kelemen(vh);
        let t = rep.t("V", "v_kelemen");
        t.valid += 1;
        if x == f32::INFINITY {
            assert_eq!(vh, 0.0);
            t.documented_inf += 1;
        } else {
            check_range("v_kelemen", x, 0.0, f32::MAX, &|| format!("v.h={vh}"));
        }
    }
    assert!(masking::v_kelemen(f32::NAN).is_nan());
    rep.t("V", "v_kelemen").invalid += 1;
    let ct: Vec<f32> = cs.iter().step_by(5).copied().chain([1.5f32, -1.000_000_1]).collect();
    for &nv in &ct {
        for &nl in &ct {
            for &nh in &ct {
                for &vh in &ct {
                    let x = masking::v_cook_torrance(nv, nl, nh, vh);
                    let t = rep.t("V", "v_cook_torrance");
                    t.valid += 1;
                    if x == f32::INFINITY {
                        assert!(nv == 0.0 || nl == 0.0, "v_cook_torrance({nv}, {nl}, {nh}, {vh}) = +Inf");
                        t.documented_inf += 1;
                        continue;
                    }
                    check_range("v_cook_torrance", x, 0.0, f32::MAX, &|| format!("{nv} {nl} {nh} {vh}"));
                }
                assert!(masking::v_cook_torrance(nv, nl, f32::NAN, 0.5).is_nan());
                rep.t("V", "v_cook_torrance").invalid += 1;
            }
        }
    }

    // ---- Parameterizations ----
    for &r in cs.iter().chain(ALPHAS.iter()) {
        for &k in &cs {
            let (ax, ay) = ndf::disney_aniso_alphas(r, k);
            let t = rep.t("param", "disney_aniso_alphas");
            if r >= 0.0 && (0.0..=1.0).contains(&k) {
                t.valid += 1;
                assert!(ax.is_finite() && ay.is_finite() && ax >= ay && ay >= 0.0, "disney({r}, {k}) = ({ax}, {ay})");
            } else {
                t.invalid += 1;
                assert!(ax.is_nan() && ay.is_nan(), "disney({r}, {k}) = ({ax}, {ay})");
            }
        }
    }
    for &a in ALPHAS.iter().chain(BAD_ALPHAS.iter()) {
        let n = ndf::blinn_phong_exponent_from_alpha(a);
        let t = rep.t("param", "blinn_phong_exponent_from_alpha");
        if a >= 0.0 && a.is_finite() {
            t.valid += 1;
            assert!(!n.is_nan() && n >= -2.0, "{a} -> {n}");
        } else {
            t.invalid += 1;
            assert!(n.is_nan());
        }
    }

    rep.print();
    let mut per_class: BTreeMap<&str, usize> = BTreeMap::new();
    for t in rep.0.values() {
        *per_class.entry(t.class).or_default() += t.valid + t.invalid;
    }
    for c in ["D", "Lambda/G1", "G2", "V"] {
        assert!(per_class[c] >= 1_000_000, "class {c}: only {} inputs", per_class[c]);
    }
}
