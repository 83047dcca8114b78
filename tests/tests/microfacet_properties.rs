//! Microfacet properties, by f64 numerical integration of the f32 `shader_core` functions:
//!
//! 1. every NDF is normalized as projected area, ∫ D(m) cos θm dωm = 1 (|error| < 1e-3), for
//!    roughness 1e-3 .. 1, isotropic and anisotropic up to 20:1;
//! 2. the Smith G1 identity ∫ D(m) G1(v, m) max(0, v·m) dωm = v·n for GGX and Beckmann, view angles
//!    up to 89.9 degrees (and the unclamped projected-area identity ∫ D(m) (v·m) dωm = v·n);
//! 3. G1 and every G2 form lie in [0, 1]; every G2 form and every symmetric visibility term is
//!    reciprocal, G2(wo, wi) == G2(wi, wo) to the bit.
//!
//! Quadrature: the integral is taken in the slope domain, m ∝ (x, y, 1) with dωm = dx dy / N^3,
//! N = |(x, y, 1)|, so ∫ D cos θm dωm = ∫∫ D / N^4 dx dy. The slopes are scaled by the roughness,
//! (x, y) = (αx ρ cos φ, αy ρ sin φ), so the peak has unit width whatever α is (this is what makes
//! α = 1e-3 as easy as α = 1), and ρ = e^s resolves both the peak and the heavy tails (GTR1's tail
//! reaches ρ ~ 1/α). s ∈ [-14, 14 + ln(1/α)] by composite 8-point Gauss-Legendre (panels of 1/8),
//! φ by the trapezoid rule (periodic: spectrally accurate). Each integral is also computed with
//! half the panel width and twice the φ nodes; the difference is printed as the quadrature error.
//! The kink of max(0, v·m) is where the integration stops: along each φ the integrand vanishes for
//! ρ > v_z / (-c(φ)), c(φ) = αx vx cos φ + αy vy sin φ < 0, so the s-integral ends there exactly.
//!
//! Negative controls (`*_detects_*`) feed deliberately wrong functions (a normalization off by
//! 0.2 %, D scaled by α, a Lambda off by 1 %) through the same checks and assert they fail.
//!
//! Run: `cargo test --release -p crosscheck --test microfacet_properties -- --nocapture`.

use host::microfacet_ref as r64;
use shader_core::{masking, ndf, Vec3};
use std::f64::consts::PI;

const TOL: f64 = 1e-3;

const GL_X: [f64; 4] = [0.183_434_642_495_649_8, 0.525_532_409_916_329, 0.796_666_477_413_626_7, 0.960_289_856_497_536_3];
const GL_W: [f64; 4] = [0.362_683_783_378_362, 0.313_706_645_877_887_3, 0.222_381_034_453_374_5, 0.101_228_536_290_376_3];

/// ∫_a^b f by composite 8-point Gauss-Legendre with panels no wider than `h`.
fn gauss_legendre(a: f64, b: f64, h: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
    if b <= a {
        return 0.0;
    }
    let n = ((b - a) / h).ceil().max(1.0) as usize;
    let w = (b - a) / n as f64;
    let mut sum = 0.0;
    for p in 0..n {
        let c = a + (p as f64 + 0.5) * w;
        let mut panel = 0.0;
        for k in 0..4 {
            let dx = 0.5 * w * GL_X[k];
            panel += GL_W[k] * (f(c - dx) + f(c + dx));
        }
        sum += 0.5 * w * panel;
    }
    sum
}

/// What to integrate against D.
#[derive(Clone, Copy)]
enum Weight {
    /// cos θm: the projected-area normalization.
    Cos,
    /// v·m, signed (projected area seen from v).
    View([f64; 3]),
    /// max(0, v·m): the visible projected area, to compare with v_z / G1(v).
    ViewClamped([f64; 3]),
}

/// φ nodes and weights over [0, 2π): the trapezoid rule (spectrally accurate for a smooth periodic
/// integrand), except for max(0, v·m), whose φ-integrand is only C^1 where c(φ) changes sign: there
/// [0, 2π) is split at the two zeros of c(φ) = R cos(φ - φ0) and each half gets composite
/// Gauss-Legendre panels (16 nodes per panel pair, `n_phi / 16` panels per half).
fn phi_nodes(weight: Weight, ax: f64, ay: f64, n_phi: usize) -> Vec<(f64, f64)> {
    if let Weight::ViewClamped(v) = weight {
        let (a, b) = (v[0] * ax, v[1] * ay);
        if a != 0.0 || b != 0.0 {
            let phi0 = b.atan2(a);
            let mut nodes = Vec::with_capacity(n_phi);
            for half in 0..2 {
                let lo = phi0 - PI / 2.0 + half as f64 * PI;
                let panels = (n_phi / 16).max(1);
                let w = PI / panels as f64;
                for p in 0..panels {
                    let c = lo + (p as f64 + 0.5) * w;
                    for k in 0..4 {
                        let dx = 0.5 * w * GL_X[k];
                        nodes.push((c - dx, 0.5 * w * GL_W[k]));
                        nodes.push((c + dx, 0.5 * w * GL_W[k]));
                    }
                }
            }
            return nodes;
        }
    }
    (0..n_phi).map(|j| (2.0 * PI * (j as f64 + 0.5) / n_phi as f64, 2.0 * PI / n_phi as f64)).collect()
}

/// ∫ D(m) weight(m) dωm in the slope domain (see the module comment). `d` receives the slope-space
/// vector (x, y, 1) (not normalized) and returns D in f64.
fn integrate(d: &(dyn Fn([f64; 3]) -> f64 + Sync), ax: f64, ay: f64, weight: Weight, h: f64, n_phi: usize) -> f64 {
    let s_lo = -14.0;
    let s_hi = 14.0 + (1.0 / ax.min(ay)).ln().max(0.0);
    let nodes = phi_nodes(weight, ax, ay, n_phi);
    let per_phi = |&(phi, wphi): &(f64, f64)| -> f64 {
        let (sp, cp) = phi.sin_cos();
        let (ex, ey) = (ax * cp, ay * sp);
        let mut upper = s_hi;
        if let Weight::ViewClamped(v) = weight {
            let c = v[0] * ex + v[1] * ey;
            if c < 0.0 {
                upper = upper.min((v[2] / -c).ln());
            }
        }
        wphi * gauss_legendre(s_lo, upper, h, |s| {
            let rho = s.exp();
            let (x, y) = (ex * rho, ey * rho);
            let n2 = 1.0 + x * x + y * y;
            let g = match weight {
                Weight::Cos => 1.0,
                Weight::View(v) | Weight::ViewClamped(v) => v[0] * x + v[1] * y + v[2],
            };
            d([x, y, 1.0]) * g / (n2 * n2) * ax * ay * rho * rho
        })
    };
    // Two threads (the test machine has 2 cores); the sum is in a fixed order.
    let (first, second) = nodes.split_at(nodes.len() / 2);
    let (a, b) = std::thread::scope(|sc| {
        let t = sc.spawn(|| first.iter().map(per_phi).collect::<Vec<f64>>());
        let b: Vec<f64> = second.iter().map(per_phi).collect();
        (t.join().unwrap(), b)
    });
    a.iter().chain(b.iter()).sum()
}

/// The integral at the working resolution and the difference to the refined one.
fn integrate_checked(d: &(dyn Fn([f64; 3]) -> f64 + Sync), ax: f64, ay: f64, weight: Weight, n_phi: usize) -> (f64, f64) {
    let i1 = integrate(d, ax, ay, weight, 0.125, n_phi);
    let i2 = integrate(d, ax, ay, weight, 0.0625, 2 * n_phi);
    (i2, (i2 - i1).abs())
}

fn v3(m: [f64; 3]) -> Vec3 {
    Vec3::new(m[0] as f32, m[1] as f32, m[2] as f32)
}

/// The unit f32 vector nearest to m (for the forms that need |h| = 1).
fn unit32(m: [f64; 3]) -> Vec3 {
    v3(r64::normalize(m))
}

const ALPHAS: [f64; 12] = [1e-3, 2e-3, 5e-3, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0];

/// Anisotropic pairs up to 20:1, both orientations.
fn aniso_pairs() -> Vec<(f64, f64)> {
    let mut v = Vec::new();
    for &(a, r) in &[(1e-3, 20.0), (1e-3, 5.0), (0.01, 20.0), (0.01, 2.0), (0.05, 20.0), (0.1, 5.0), (0.3, 2.0), (0.5, 2.0)] {
        v.push((a, a * r));
        v.push((a * r, a));
    }
    v
}

struct Row {
    what: String,
    alpha: String,
    value: f64,
    expected: f64,
    quad_err: f64,
}

impl Row {
    fn err(&self) -> f64 {
        (self.value - self.expected).abs() / self.expected.abs()
    }
}

fn print_rows(title: &str, rows: &[Row]) {
    println!("\n{title}");
    println!("  {:<34} {:>18} {:>14} {:>12} {:>11} {:>10}", "function", "alpha_x, alpha_y", "integral", "expected", "|rel err|", "quad rel");
    for r in rows {
        println!(
            "  {:<34} {:>18} {:>14.9} {:>12.6e} {:>11.3e} {:>10.1e}{}",
            r.what,
            r.alpha,
            r.value,
            r.expected,
            r.err(),
            r.quad_err,
            if r.err() < TOL { "" } else { "  <-- FAIL" }
        );
    }
    let worst = rows.iter().map(Row::err).fold(0.0, f64::max);
    println!("  {} integrals, worst |rel err| {:.3e} (tolerance {TOL:e})", rows.len(), worst);
}

type Ndf = Box<dyn Fn([f64; 3]) -> f64 + Sync>;

/// Every NDF with the roughness pairs it is tested at: (name, alpha_x, alpha_y, D).
fn ndfs() -> Vec<(String, f64, f64, Ndf)> {
    let mut v: Vec<(String, f64, f64, Ndf)> = Vec::new();
    let mut pairs: Vec<(f64, f64)> = ALPHAS.iter().map(|&a| (a, a)).collect();
    pairs.extend(aniso_pairs());
    for &(ax, ay) in &pairs {
        let (fx, fy) = (ax as f32, ay as f32);
        v.push(("ggx_d".into(), ax, ay, Box::new(move |m| ndf::ggx_d(v3(m), fx, fy) as f64)));
        v.push(("beckmann_d".into(), ax, ay, Box::new(move |m| ndf::beckmann_d(v3(m), fx, fy) as f64)));
    }
    for &a in &ALPHAS {
        let f = a as f32;
        let n = ndf::blinn_phong_exponent_from_alpha(f);
        v.push((format!("blinn_phong_d (n = {n:.4e})"), a, a, Box::new(move |m| ndf::blinn_phong_d(v3(m), n) as f64)));
        v.push(("gtr1_d".into(), a, a, Box::new(move |m| ndf::gtr1_d(v3(m), f) as f64)));
        v.push(("gtr2_d".into(), a, a, Box::new(move |m| ndf::gtr2_d(v3(m), f) as f64)));
        v.push(("ggx_d_mobile (unit h)".into(), a, a, Box::new(move |m| ndf::ggx_d_mobile(unit32(m), f) as f64)));
    }
    v
}

/// The reduced-precision forms, reported (not asserted): their error is the point of the bench.
fn ndfs_reported() -> Vec<(String, f64, f64, Ndf)> {
    let mut v: Vec<(String, f64, f64, Ndf)> = Vec::new();
    for &a in &ALPHAS {
        let f = a as f32;
        v.push(("ggx_d_ue4 (f32 n.h)".into(), a, a, Box::new(move |m| ndf::ggx_d_ue4(unit32(m).z, f) as f64)));
        v.push(("ggx_d_mobile_naive (f32 n.h)".into(), a, a, Box::new(move |m| ndf::ggx_d_mobile_naive(unit32(m).z, f) as f64)));
        v.push((
            "fp16 mobile naive (emulated)".into(),
            a,
            a,
            Box::new(move |m| host::ggx_fp16::ggx_d_mobile_naive_fp16(r64::normalize(m)[2] as f32, f) as f64),
        ));
        v.push((
            "fp16 mobile Lagrange (emulated)".into(),
            a,
            a,
            Box::new(move |m| {
                let u = r64::normalize(m);
                host::ggx_fp16::ggx_d_mobile_fp16([u[0] as f32, u[1] as f32, u[2] as f32], f) as f64
            }),
        ));
    }
    v
}

fn fmt_alpha(ax: f64, ay: f64) -> String {
    format!("{ax:.0e}, {ay:.0e}")
}

#[test]
fn every_ndf_integrates_to_one_as_projected_area() {
    let mut rows = Vec::new();
    for (name, ax, ay, d) in ndfs() {
        let (i, q) = integrate_checked(&*d, ax, ay, Weight::Cos, 64);
        rows.push(Row { what: name, alpha: fmt_alpha(ax, ay), value: i, expected: 1.0, quad_err: q });
    }
    print_rows("∫ D(m) cos θm dωm = 1 (projected-area normalization)", &rows);
    let mut reported = Vec::new();
    for (name, ax, ay, d) in ndfs_reported() {
        let (i, q) = integrate_checked(&*d, ax, ay, Weight::Cos, 64);
        reported.push(Row { what: name, alpha: fmt_alpha(ax, ay), value: i, expected: 1.0, quad_err: q });
    }
    print_rows("Reported only (reduced-precision forms fed n.h or an fp16 h; not asserted)", &reported);
    let bad: Vec<&Row> = rows.iter().filter(|r| !(r.err() < TOL)).collect();
    assert!(bad.is_empty(), "{} NDF normalizations off by more than {TOL}: first {} at {}", bad.len(), bad[0].what, bad[0].alpha);
}

#[test]
fn normalization_check_detects_wrong_constants() {
    // The same integrator and tolerance reject D * 1.002 and a 1/(pi alpha) normalization.
    let a = 0.05f32;
    let off: Ndf = Box::new(move |m| 1.002 * ndf::ggx_d(v3(m), a, a) as f64);
    let (i, _) = integrate_checked(&*off, 0.05, 0.05, Weight::Cos, 64);
    println!("GGX * 1.002 integrates to {i:.9}");
    assert!((i - 1.0).abs() > TOL, "a 0.2% normalization error must be detected");
    let wrong: Ndf = Box::new(move |m| a as f64 * ndf::ggx_d(v3(m), a, a) as f64);
    let (i, _) = integrate_checked(&*wrong, 0.05, 0.05, Weight::Cos, 64);
    println!("GGX / (pi alpha) integrates to {i:.9}");
    assert!((i - 1.0).abs() > TOL);
    // Beckmann with tan^2/alpha instead of tan^2/alpha^2 in the exponent.
    let bad_exp: Ndf = Box::new(move |m| {
        let c2 = 1.0 / (1.0 + m[0] * m[0] + m[1] * m[1]);
        let t2 = (m[0] * m[0] + m[1] * m[1]) / (a as f64);
        (-t2).exp() / (PI * (a * a) as f64 * c2 * c2)
    });
    let (i, _) = integrate_checked(&*bad_exp, 0.05, 0.05, Weight::Cos, 64);
    println!("Beckmann with tan^2/alpha integrates to {i:.9}");
    assert!((i - 1.0).abs() > TOL);
}

const THETAS_DEG: [f64; 8] = [0.0, 30.0, 60.0, 75.0, 80.0, 85.0, 89.0, 89.9];

/// (name, D, G1, Lambda) of the two NDFs with a closed-form Smith Lambda.
type Smith = (&'static str, fn(Vec3, f32, f32) -> f32, fn(Vec3, f32, f32) -> f32);

fn smith_pairs() -> [Smith; 2] {
    [("ggx", ndf::ggx_d, masking::ggx_g1), ("beckmann", ndf::beckmann_d, masking::beckmann_g1)]
}

fn g1_pairs() -> Vec<(f64, f64)> {
    let mut v: Vec<(f64, f64)> = [1e-3, 0.01, 0.1, 0.3, 0.6, 1.0].iter().map(|&a| (a, a)).collect();
    v.extend([(1e-3, 2e-2), (2e-2, 1e-3), (0.05, 1.0), (1.0, 0.05), (0.1, 0.5)]);
    v
}

/// Rows of the G1 identity for one Smith pair, G1 given as a function (so a wrong one can be fed).
fn g1_identity_rows(name: &str, d: fn(Vec3, f32, f32) -> f32, g1: &dyn Fn(Vec3, f32, f32) -> f32, pairs: &[(f64, f64)], thetas: &[f64]) -> Vec<Row> {
    let mut rows = Vec::new();
    for &(ax, ay) in pairs {
        let phis: &[f64] = if ax == ay { &[0.0] } else { &[0.0, 40.0, 90.0] };
        for &t in thetas {
            for &p in phis {
                if t == 0.0 && p != 0.0 {
                    continue;
                }
                let v = r64::dir(t.to_radians(), p.to_radians());
                let (fx, fy) = (ax as f32, ay as f32);
                let dd = move |m: [f64; 3]| d(v3(m), fx, fy) as f64;
                let (i, q) = integrate_checked(&dd, ax, ay, Weight::ViewClamped(v), 128);
                let g = g1(v3(v), fx, fy) as f64;
                rows.push(Row {
                    what: format!("{name} θv={t}° φv={p}°"),
                    alpha: fmt_alpha(ax, ay),
                    value: g * i,
                    expected: v[2],
                    quad_err: g * q / v[2],
                });
            }
        }
    }
    rows
}

#[test]
fn smith_g1_identity_holds_for_ggx_and_beckmann() {
    let mut all = Vec::new();
    for (name, d, g1) in smith_pairs() {
        let rows = g1_identity_rows(name, d, &g1, &g1_pairs(), &THETAS_DEG);
        print_rows(&format!("∫ D(m) G1(v) max(0, v·m) dωm = v·n ({name}; value = G1 · integral)"), &rows);
        all.extend(rows);
    }
    // Walter's rational approximation, reported: its error is what the bench measures.
    let walter = g1_identity_rows("beckmann (Walter G1)", ndf::beckmann_d, &masking::beckmann_g1_walter, &g1_pairs(), &THETAS_DEG);
    print_rows("Reported only: Beckmann with Walter's rational G1 (not asserted)", &walter);
    let bad: Vec<&Row> = all.iter().filter(|r| !(r.err() < TOL)).collect();
    assert!(bad.is_empty(), "{} G1 identities off by more than {TOL}: first {} at {}", bad.len(), bad[0].what, bad[0].alpha);
}

#[test]
fn g1_identity_check_detects_a_wrong_lambda() {
    // Lambda scaled by 1.01 breaks the identity at grazing angles: the check must see it.
    let wrong = |w: Vec3, ax: f32, ay: f32| 1.0 / (1.0 + 1.01 * masking::ggx_lambda(w, ax, ay));
    let rows = g1_identity_rows("ggx, Lambda * 1.01", ndf::ggx_d, &wrong, &[(0.3, 0.3)], &[85.0, 89.0]);
    print_rows("Negative control", &rows);
    assert!(rows.iter().all(|r| r.err() > TOL));
}

#[test]
fn projected_area_is_conserved_from_every_view() {
    // ∫ D(m) (v·m) dωm = v·n with the signed cosine (backfacing microfacets cancel the excess).
    let mut rows = Vec::new();
    for (name, d, _) in smith_pairs() {
        for &(ax, ay) in &[(1e-3, 1e-3), (0.1, 0.1), (1.0, 1.0), (0.05, 1.0)] {
            for &t in &[30.0, 80.0, 89.9] {
                let v = r64::dir(f64::to_radians(t), 0.5);
                let (fx, fy) = (ax as f32, ay as f32);
                let dd = move |m: [f64; 3]| d(v3(m), fx, fy) as f64;
                let (i, q) = integrate_checked(&dd, ax, ay, Weight::View(v), 64);
                rows.push(Row { what: format!("{name} θv={t}°"), alpha: fmt_alpha(ax, ay), value: i, expected: v[2], quad_err: q / v[2] });
            }
        }
    }
    print_rows("∫ D(m) (v·m) dωm = v·n (signed)", &rows);
    assert!(rows.iter().all(|r| r.err() < TOL));
}

/// Unit directions on a grid (theta to 89.99 degrees and exactly 90), upper and lower hemisphere.
fn grid_dirs() -> Vec<Vec3> {
    let mut v = Vec::new();
    let thetas = [0.0, 5.0, 20.0, 45.0, 60.0, 75.0, 85.0, 89.0, 89.9, 89.99, 90.0];
    for &t in &thetas {
        for j in 0..7 {
            let d = r64::dir(f64::to_radians(t), 0.9 * j as f64);
            v.push(v3(d));
            v.push(v3([d[0], d[1], -d[2]]));
        }
    }
    v
}

fn grid_alphas() -> Vec<(f32, f32)> {
    let mut v: Vec<(f32, f32)> = [0.0, 1e-4, 1e-3, 0.01, 0.1, 0.3, 0.5, 1.0, 2.0].iter().map(|&a| (a, a)).collect();
    v.extend([(1e-3, 2e-2), (0.05, 1.0), (1.0, 0.05), (0.0, 0.5)]);
    v
}

type G2 = (&'static str, fn(Vec3, Vec3, f32, f32) -> f32);

fn g2_forms() -> [G2; 5] {
    [
        ("ggx_g2_separable", masking::ggx_g2_separable),
        ("ggx_g2_height_correlated", masking::ggx_g2_height_correlated),
        ("ggx_g2_direction_correlated", masking::ggx_g2_direction_correlated),
        ("ggx_g2_height_direction_correlated", masking::ggx_g2_height_direction_correlated),
        ("beckmann_g2_height_correlated", masking::beckmann_g2_height_correlated),
    ]
}

#[test]
fn g1_and_g2_lie_in_unit_interval_and_g2_is_reciprocal() {
    let dirs = grid_dirs();
    let alphas = grid_alphas();
    println!("\nG1, G2 range [0, 1] and reciprocity G2(wo, wi) == G2(wi, wo) (bits), {} directions x {} alpha pairs", dirs.len(), alphas.len());
    let g1s: [(&str, fn(Vec3, f32, f32) -> f32); 3] =
        [("ggx_g1", masking::ggx_g1), ("beckmann_g1", masking::beckmann_g1), ("beckmann_g1_walter", masking::beckmann_g1_walter)];
    for (name, g1) in g1s {
        let (mut n, mut min, mut max) = (0usize, f32::INFINITY, f32::NEG_INFINITY);
        for &w in &dirs {
            for &(ax, ay) in &alphas {
                let g = g1(w, ax, ay);
                assert!((0.0..=1.0).contains(&g), "{name}({w:?}, {ax}, {ay}) = {g}");
                min = min.min(g);
                max = max.max(g);
                n += 1;
            }
        }
        println!("  {name:<36} {n:>9} values in [{min}, {max}]");
    }
    for (name, g2) in g2_forms() {
        let (mut n, mut min, mut max, mut asym) = (0usize, f32::INFINITY, f32::NEG_INFINITY, 0usize);
        for &wo in &dirs {
            for &wi in &dirs {
                for &(ax, ay) in &alphas {
                    let a = g2(wo, wi, ax, ay);
                    let b = g2(wi, wo, ax, ay);
                    assert!((0.0..=1.0).contains(&a), "{name}({wo:?}, {wi:?}, {ax}, {ay}) = {a}");
                    if a.to_bits() != b.to_bits() {
                        asym += 1;
                    }
                    min = min.min(a);
                    max = max.max(a);
                    n += 1;
                }
            }
        }
        println!("  {name:<36} {n:>9} values in [{min}, {max}], {asym} not reciprocal to the bit");
        assert_eq!(asym, 0, "{name} is not reciprocal");
    }
}

#[test]
fn visibility_terms_are_reciprocal_except_hdrp_approx() {
    let cosines: Vec<f32> = [0.0, 1e-7, 1e-4, 1e-3, 0.01, 0.05, 0.1, 0.2, 0.4, 0.6, 0.8, 0.95, 0.999, 1.0].to_vec();
    let alphas = [0.0f32, 1e-4, 1e-3, 0.01, 0.1, 0.3, 0.5, 0.8, 1.0];
    type V = (&'static str, fn(f32, f32, f32) -> f32);
    let forms: [V; 10] = [
        ("v_frostbite", masking::v_frostbite),
        ("v_hdrp", masking::v_hdrp),
        ("v_filament", masking::v_filament),
        ("v_ue4", masking::v_ue4),
        ("v_filament_fast", masking::v_filament_fast),
        ("v_respawn", masking::v_respawn),
        ("v_schlick_smith", masking::v_schlick_smith),
        ("v_schlick_smith_remapped", masking::v_schlick_smith_remapped),
        ("v_neumann", |v, l, _| masking::v_neumann(v, l)),
        ("v_hdrp_approx", masking::v_hdrp_approx),
    ];
    println!("\nVisibility reciprocity V(n.v, n.l) == V(n.l, n.v) (bits), {} cosine pairs x {} alphas", cosines.len().pow(2), alphas.len());
    for (name, v) in forms {
        let (mut asym, mut worst) = (0usize, 0.0f64);
        for &a in &cosines {
            for &b in &cosines {
                for &al in &alphas {
                    let x = v(a, b, al);
                    let y = v(b, a, al);
                    assert!(x >= 0.0, "{name}({a}, {b}, {al}) = {x}");
                    if x.to_bits() != y.to_bits() {
                        asym += 1;
                        if x.is_finite() && y.is_finite() {
                            worst = worst.max(((x - y) / x.max(y)).abs() as f64);
                        }
                    }
                }
            }
        }
        println!("  {name:<26} {asym:>5} asymmetric (worst relative difference {worst:.3e})");
        if name == "v_hdrp_approx" {
            assert!(asym > 0, "v_hdrp_approx approximates only the view term: it is expected to be asymmetric");
        } else {
            assert_eq!(asym, 0, "{name} is not reciprocal");
        }
    }
}

#[test]
fn roughness_parameterizations() {
    // Disney: alpha_x alpha_y = r^4 and the aspect ratio alpha_x / alpha_y = 1 / (1 - 0.9 k) <= 10.
    for &r in &[0.0f32, 0.1, 0.5, 1.0] {
        for &k in &[0.0f32, 0.25, 0.5, 1.0] {
            let (ax, ay) = ndf::disney_aniso_alphas(r, k);
            let r4 = (r as f64).powi(4);
            assert!(((ax as f64 * ay as f64) - r4).abs() <= 1e-6 * r4.max(1e-30), "{r} {k}: {ax} {ay}");
            if r > 0.0 {
                let ratio = ax as f64 / ay as f64;
                assert!((ratio - 1.0 / (1.0 - 0.9 * k as f64)).abs() < 1e-5 && ratio <= 10.0 + 1e-4, "{ratio}");
            }
        }
    }
    assert!(ndf::disney_aniso_alphas(0.5, 1.5).0.is_nan());
    // Blinn-Phong <-> Beckmann: n = 2/alpha^2 - 2 and back.
    for &a in &[1e-3f32, 0.01, 0.1, 0.5, 1.0] {
        let n = ndf::blinn_phong_exponent_from_alpha(a);
        let back = ndf::blinn_phong_alpha_from_exponent(n);
        assert!(((back - a) / a).abs() < 1e-6, "{a} -> {n} -> {back}");
    }
    assert_eq!(ndf::blinn_phong_exponent_from_alpha(1.0), 0.0);
    assert_eq!(ndf::blinn_phong_exponent_from_alpha(0.0), f32::INFINITY);
}

