//! Accuracy of `shader_core::math` against the f64 functions of std (and the C library's `erf`,
//! `erfc`, which std does not expose on stable) rounded to f32.
//!
//! Every function is swept over at least 10^6 inputs of its documented domain: a dense uniform
//! grid, log-spaced magnitudes of both signs, hard cases (for sin/cos/tan: the floats nearest to
//! each multiple of pi/2 up to 2^16 pi/2) and special values. The error of one output is its
//! distance in ULPs (adjacent f32 differ by 1) from the f64 result rounded to f32. The bounds
//! asserted are the documented ones (see MATH.md); run
//! `cargo test -p shader-core --release --test math_accuracy -- --nocapture` for the table.

use shader_core::math;
use std::fmt::Write as _;

extern "C" {
    fn erf(x: f64) -> f64;
    fn erfc(x: f64) -> f64;
}

fn erf64(x: f64) -> f64 {
    // SAFETY: pure C library function on a plain f64.
    unsafe { erf(x) }
}

fn erfc64(x: f64) -> f64 {
    // SAFETY: pure C library function on a plain f64.
    unsafe { erfc(x) }
}

/// Order-preserving integer image of an f32 (-0 and +0 both map to 0).
fn ordered(x: f32) -> i64 {
    let b = x.to_bits() as i32;
    if b < 0 {
        i64::from(i32::MIN) - i64::from(b)
    } else {
        i64::from(b)
    }
}

/// ULP distance; 0 for two NaNs, a huge value for NaN vs number.
fn ulps(a: f32, b: f32) -> u64 {
    match (a.is_nan(), b.is_nan()) {
        (true, true) => 0,
        (false, false) => (ordered(a) - ordered(b)).unsigned_abs(),
        _ => 1 << 40,
    }
}

/// Deterministic generator (SplitMix64).
struct Rng(reference::splitmix::SplitMix64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0.next_u64()
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn uniform(&mut self, a: f64, b: f64) -> f32 {
        (a + (b - a) * self.unit()) as f32
    }
    /// |x| log-uniform in [lo, hi], random sign when `signed`.
    fn log_uniform(&mut self, lo: f64, hi: f64, signed: bool) -> f32 {
        let v = (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp() as f32;
        if signed && self.next() & 1 == 1 {
            -v
        } else {
            v
        }
    }
}

/// Special values every unary sweep includes.
fn specials() -> Vec<f32> {
    let mut v = vec![
        0.0,
        -0.0,
        f32::from_bits(1),
        -f32::from_bits(1),
        f32::MIN_POSITIVE,
        -f32::MIN_POSITIVE,
        f32::from_bits(0x007f_ffff),
        1.0,
        -1.0,
        0.5,
        -0.5,
        2.0,
        f32::EPSILON,
        1.0 + f32::EPSILON,
        1.0 - f32::EPSILON / 2.0,
        1.0e5,
        -1.0e5,
        1.0e10,
        1.0e30,
        f32::MAX,
        f32::MIN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        core::f32::consts::PI,
        core::f32::consts::FRAC_PI_2,
        core::f32::consts::FRAC_PI_4,
    ];
    let more: Vec<f32> = v
        .iter()
        .flat_map(|&x| {
            [
                f32::from_bits(x.to_bits().wrapping_add(1)),
                f32::from_bits(x.to_bits().wrapping_sub(1)),
            ]
        })
        .filter(|x| !x.is_nan())
        .collect();
    v.extend(more);
    v
}

#[derive(Clone)]
struct Row {
    name: &'static str,
    domain: &'static str,
    samples: u64,
    /// max distance in ULPs from the f64 result rounded to f32
    max_ulp: u64,
    /// mean of that distance
    mean_ulp: f64,
    /// max |got - exact| / ulp(exact), the exact value being the f64 result (finite results only)
    max_err: f64,
    worst: String,
    bound: Bound,
}

/// Asserted limits: max ULP distance, max error vs the f64 value (in ULPs), mean ULP distance.
/// The last two are set about 10% / 1.6x above the measured values so that a wrong coefficient
/// or a lost correction term fails even when the error stays below 1 ULP.
#[derive(Clone, Copy)]
struct Bound(u64, f64, f64);

/// Error of `got` against the (f64) exact value in units of the f32 ulp at that value.
fn frac_ulps(got: f32, exact: f64) -> f64 {
    let r = exact as f32;
    if !got.is_finite() || !r.is_finite() || exact.is_nan() {
        return 0.0;
    }
    let e = if r == 0.0 {
        -149
    } else {
        (((r.abs().to_bits() >> 23) as i32) - 150).max(-149)
    };
    (f64::from(got) - exact).abs() / 2f64.powi(e)
}

/// Sweep a unary function over `inputs` restricted to `keep`.
fn sweep1(
    name: &'static str,
    domain: &'static str,
    bound: Bound,
    inputs: &[f32],
    f: fn(f32) -> f32,
    reference: fn(f64) -> f64,
) -> Row {
    let mut max = 0u64;
    let mut sum = 0f64;
    let mut max_err = 0f64;
    let mut worst = String::new();
    for &x in inputs {
        let got = f(x);
        let exact = reference(f64::from(x));
        let want = exact as f32;
        max_err = max_err.max(frac_ulps(got, exact));
        let d = ulps(got, want);
        sum += d as f64;
        if d > max || worst.is_empty() {
            max = d.max(max);
            worst = format!(
                "x={x:e} ({:#010x}): got {got:e}, want {want:e}",
                x.to_bits()
            );
        }
    }
    Row {
        name,
        domain,
        samples: inputs.len() as u64,
        max_ulp: max,
        mean_ulp: sum / inputs.len() as f64,
        max_err,
        worst,
        bound,
    }
}

/// Sweep a binary function over pairs.
fn sweep2(
    name: &'static str,
    domain: &'static str,
    bound: Bound,
    inputs: &[(f32, f32)],
    f: fn(f32, f32) -> f32,
    reference: fn(f64, f64) -> f64,
) -> Row {
    let mut max = 0u64;
    let mut sum = 0f64;
    let mut max_err = 0f64;
    let mut worst = String::new();
    for &(a, b) in inputs {
        let got = f(a, b);
        let exact = reference(f64::from(a), f64::from(b));
        let want = exact as f32;
        max_err = max_err.max(frac_ulps(got, exact));
        let d = ulps(got, want);
        sum += d as f64;
        if d > max || worst.is_empty() {
            max = d.max(max);
            worst = format!("({a:e}, {b:e}): got {got:e}, want {want:e}");
        }
    }
    Row {
        name,
        domain,
        samples: inputs.len() as u64,
        max_ulp: max,
        mean_ulp: sum / inputs.len() as f64,
        max_err,
        worst,
        bound,
    }
}

/// n uniform samples in [a, b], n log-uniform magnitudes in [lo, hi] (signed or not), plus `extra`.
#[allow(clippy::too_many_arguments)]
fn mix(
    seed: u64,
    n_uniform: usize,
    a: f64,
    b: f64,
    n_log: usize,
    lo: f64,
    hi: f64,
    signed: bool,
) -> Vec<f32> {
    let mut r = Rng(reference::splitmix::SplitMix64(seed));
    let mut v = Vec::with_capacity(n_uniform + n_log + 64);
    for i in 0..n_uniform {
        // half a regular grid, half random
        if i % 2 == 0 {
            v.push((a + (b - a) * (i as f64 / n_uniform as f64)) as f32);
        } else {
            v.push(r.uniform(a, b));
        }
    }
    for _ in 0..n_log {
        v.push(r.log_uniform(lo, hi, signed));
    }
    v
}

/// The f32 neighbours (3 on each side) of the f32 nearest to k pi/2, for k = 1 .. 2^16 - 1 and
/// both signs: the hardest inputs for the Cody-Waite reduction (largest cancellation).
fn near_multiples_of_pio2() -> Vec<f32> {
    let mut v = Vec::new();
    for k in 1..65_535u32 {
        let c = (f64::from(k) * std::f64::consts::FRAC_PI_2) as f32;
        if c > math::TRIG_CODY_WAITE_MAX {
            break;
        }
        for d in -3i32..=3 {
            let x = f32::from_bits((c.to_bits() as i32 + d) as u32);
            v.push(x);
            v.push(-x);
        }
    }
    v
}

/// Floats with |x| above the Cody-Waite range, log-spaced up to f32::MAX, plus large floats
/// nearest to multiples of pi/2 found by continued steps of the exponent.
fn large_args() -> Vec<f32> {
    let mut r = Rng(reference::splitmix::SplitMix64(77));
    let mut v: Vec<f32> = (0..1_000_000)
        .map(|_| r.log_uniform(1.03e5, 3.4e38, true))
        .collect();
    v.push(f32::MAX);
    v.push(f32::MIN);
    v.push(102_901.0);
    v.push(16_777_216.0);
    v
}

fn rows() -> Vec<Row> {
    use std::thread;
    let trig_main = || {
        let mut v = mix(1, 1_000_000, -7.0, 7.0, 500_000, 1e-40, 1.03e5, true);
        v.extend(mix(2, 1_000_000, -102_900.0, 102_900.0, 0, 1.0, 1.0, false));
        v.extend(near_multiples_of_pio2());
        v.extend(
            specials()
                .into_iter()
                .filter(|x| x.is_nan() || x.abs() <= math::TRIG_CODY_WAITE_MAX),
        );
        v
    };
    let atan_in = || {
        let mut v = mix(3, 1_000_000, -4.0, 4.0, 1_000_000, 1e-45, 3.4e38, true);
        v.extend(specials());
        v
    };
    let asin_in = || {
        let mut v = mix(4, 1_000_000, -1.0, 1.0, 500_000, 1e-45, 1.0, true);
        let mut r = Rng(reference::splitmix::SplitMix64(5));
        for _ in 0..300_000 {
            // close to +-1
            let d = r.log_uniform(6e-8, 0.5, false);
            v.push(1.0 - d);
            v.push(-(1.0 - d));
        }
        v.extend(specials());
        v
    };
    let exp_in = || {
        let mut v = mix(6, 1_000_000, -104.0, 89.0, 500_000, 1e-45, 104.0, true);
        v.extend(specials());
        v.extend([88.72283, 88.72284, -103.97, -103.98, -87.33655, -87.33654]);
        v
    };
    let exp2_in = || {
        let mut v = mix(7, 1_000_000, -151.0, 128.0, 500_000, 1e-45, 151.0, true);
        v.extend(specials());
        v.extend((-151..=128).map(|i| i as f32));
        v
    };
    let expm1_in = || {
        let mut v = mix(8, 1_000_000, -18.0, 89.0, 1_000_000, 1e-45, 18.0, true);
        v.extend(specials());
        v
    };
    let log_in = || {
        let mut v = mix(9, 1_000_000, 0.5, 2.0, 1_000_000, 1e-45, 3.4e38, false);
        v.extend(specials());
        v.extend((-149..=127).map(pow2));
        v
    };
    let log1p_in = || {
        let mut v = mix(10, 1_000_000, -1.0, 2.0, 1_000_000, 1e-45, 3.4e38, false);
        let mut r = Rng(reference::splitmix::SplitMix64(11));
        for _ in 0..200_000 {
            v.push(-r.log_uniform(1e-45, 1.0, false));
        }
        v.extend(specials());
        v
    };
    let erf_in = || {
        let mut v = mix(12, 1_000_000, -4.5, 4.5, 500_000, 1e-45, 3.4e38, true);
        v.extend(specials());
        v
    };
    let erfc_in = || {
        let mut v = mix(13, 1_000_000, -4.5, 10.1, 500_000, 1e-45, 3.4e38, true);
        v.extend(specials());
        v
    };
    let atan2_in = || {
        let mut r = Rng(reference::splitmix::SplitMix64(14));
        let mut v = Vec::with_capacity(2_100_000);
        for _ in 0..1_000_000 {
            // direction uniform in angle, radius log-uniform
            let t = r.unit() * std::f64::consts::TAU - std::f64::consts::PI;
            let rad = f64::from(r.log_uniform(1e-30, 1e30, false));
            v.push(((rad * t.sin()) as f32, (rad * t.cos()) as f32));
        }
        for _ in 0..1_000_000 {
            v.push((
                r.log_uniform(1e-45, 3.4e38, true),
                r.log_uniform(1e-45, 3.4e38, true),
            ));
        }
        let s = specials();
        for &a in &s {
            for &b in &s {
                v.push((a, b));
            }
        }
        v
    };
    let pow_main = || {
        // x > 0 anywhere, y such that |y log2 x| <= 150 (results from denormal to overflow)
        let mut r = Rng(reference::splitmix::SplitMix64(15));
        let mut v = Vec::with_capacity(2_000_000);
        for i in 0..2_000_000 {
            let x = if i % 2 == 0 {
                r.log_uniform(1e-45, 3.4e38, false)
            } else {
                r.uniform(0.5, 2.0)
            };
            let t = r.unit() * 280.0 - 152.0;
            let l = f64::from(x).log2();
            let y = if l == 0.0 {
                r.uniform(-1e6, 1e6)
            } else {
                (t / l) as f32
            };
            v.push((x, y));
        }
        for _ in 0..200_000 {
            // integer exponents, both signs of base
            let x = r.log_uniform(1e-3, 1e3, true);
            let y = (r.unit() * 60.0 - 30.0).round() as f32;
            v.push((x, y));
        }
        for _ in 0..200_000 {
            // base near 1, huge exponents
            let x = 1.0 + (r.unit() * 2e-3 - 1e-3) as f32;
            let y = r.log_uniform(1.0, 1e9, true);
            v.push((x, y));
        }
        v
    };
    let pow_special = || {
        let s = specials();
        let mut v = Vec::new();
        for &a in &s {
            for &b in &s {
                v.push((a, b));
            }
            for y in [-3.0f32, -2.0, -1.0, 0.5, 1.0, 2.0, 3.0, 1e10, -1e10] {
                v.push((a, y));
            }
        }
        v
    };

    thread::scope(|sc| {
        let jobs: Vec<thread::ScopedJoinHandle<'_, Vec<Row>>> = vec![
            sc.spawn(move || {
                let main = trig_main();
                let large = large_args();
                vec![
                    sweep1(
                        "sin",
                        "abs(x) <= 102900",
                        Bound(1, 0.8, 0.014),
                        &main,
                        math::sin,
                        f64::sin,
                    ),
                    sweep1(
                        "sin",
                        "102900 < abs(x) <= f32::MAX",
                        Bound(1, 0.8, 0.023),
                        &large,
                        math::sin,
                        f64::sin,
                    ),
                    sweep1(
                        "cos",
                        "abs(x) <= 102900",
                        Bound(1, 0.82, 0.014),
                        &main,
                        math::cos,
                        f64::cos,
                    ),
                    sweep1(
                        "cos",
                        "102900 < abs(x) <= f32::MAX",
                        Bound(1, 0.82, 0.023),
                        &large,
                        math::cos,
                        f64::cos,
                    ),
                    sweep1(
                        "tan",
                        "abs(x) <= 102900",
                        Bound(1, 0.93, 0.021),
                        &main,
                        math::tan,
                        f64::tan,
                    ),
                    sweep1(
                        "tan",
                        "102900 < abs(x) <= f32::MAX",
                        Bound(1, 0.92, 0.035),
                        &large,
                        math::tan,
                        f64::tan,
                    ),
                ]
            }),
            sc.spawn(move || {
                let a = atan_in();
                let b = asin_in();
                vec![
                    sweep1(
                        "atan",
                        "all f32",
                        Bound(1, 1.19, 0.031),
                        &a,
                        math::atan,
                        f64::atan,
                    ),
                    sweep1(
                        "asin",
                        "[-1, 1]",
                        Bound(1, 0.7, 0.011),
                        &b,
                        math::asin,
                        f64::asin,
                    ),
                    sweep1(
                        "acos",
                        "[-1, 1]",
                        Bound(1, 0.68, 0.0055),
                        &b,
                        math::acos,
                        f64::acos,
                    ),
                    sweep2(
                        "atan2",
                        "all f32 pairs",
                        Bound(1, 1.17, 0.024),
                        &atan2_in(),
                        math::atan2,
                        f64::atan2,
                    ),
                ]
            }),
            sc.spawn(move || {
                vec![
                    sweep1(
                        "exp",
                        "[-104, 89] (all f32)",
                        Bound(1, 0.68, 0.013),
                        &exp_in(),
                        math::exp,
                        f64::exp,
                    ),
                    sweep1(
                        "exp2",
                        "[-151, 128] (all f32)",
                        Bound(1, 0.69, 0.013),
                        &exp2_in(),
                        math::exp2,
                        f64::exp2,
                    ),
                    sweep1(
                        "expm1",
                        "[-18, 89] (all f32)",
                        Bound(1, 1.18, 0.014),
                        &expm1_in(),
                        math::expm1,
                        f64::exp_m1,
                    ),
                    sweep1(
                        "log",
                        "all f32",
                        Bound(1, 0.94, 0.032),
                        &log_in(),
                        math::log,
                        f64::ln,
                    ),
                    sweep1(
                        "log2",
                        "all f32",
                        Bound(1, 1.0, 0.021),
                        &log_in(),
                        math::log2,
                        f64::log2,
                    ),
                    sweep1(
                        "log1p",
                        "all f32",
                        Bound(1, 0.96, 0.021),
                        &log1p_in(),
                        math::log1p,
                        f64::ln_1p,
                    ),
                ]
            }),
            sc.spawn(move || {
                vec![
                    sweep2(
                        "pow",
                        "x > 0 with abs(y log2 x) <= 152; x < 0 with integer y",
                        Bound(1, 0.69, 0.019),
                        &pow_main(),
                        math::pow,
                        f64::powf,
                    ),
                    sweep2(
                        "pow",
                        "special values x all pairs",
                        Bound(1, 0.63, 0.004),
                        &pow_special(),
                        math::pow,
                        f64::powf,
                    ),
                    sweep1(
                        "erf",
                        "all f32",
                        Bound(1, 0.86, 0.045),
                        &erf_in(),
                        math::erf,
                        erf64,
                    ),
                    sweep1(
                        "erfc",
                        "all f32",
                        Bound(1, 0.97, 0.088),
                        &erfc_in(),
                        math::erfc,
                        erfc64,
                    ),
                    sweep1(
                        "sqrt",
                        "all f32",
                        Bound(0, 0.5, 0.0),
                        &log_in(),
                        math::sqrt,
                        f64::sqrt,
                    ),
                    sweep1(
                        "rsqrt",
                        "all f32",
                        Bound(1, 1.55, 0.29),
                        &log_in(),
                        math::rsqrt,
                        |x| 1.0 / x.sqrt(),
                    ),
                ]
            }),
        ];
        jobs.into_iter().flat_map(|j| j.join().unwrap()).collect()
    })
}

#[test]
fn accuracy_table() {
    let rows = rows();
    let mut out = String::new();
    writeln!(out, "\n| function | domain | samples | max ULP | mean ULP | max err vs f64 (ULP) | bounds (max ULP / max err / mean) |").unwrap();
    writeln!(out, "| --- | --- | ---: | ---: | ---: | ---: | ---: |").unwrap();
    for r in &rows {
        let Bound(u, e, m) = r.bound;
        writeln!(
            out,
            "| {} | {} | {} | {} | {:.4} | {:.3} | {u} / {e} / {m} |",
            r.name, r.domain, r.samples, r.max_ulp, r.mean_ulp, r.max_err
        )
        .unwrap();
    }
    writeln!(out, "\nworst cases:").unwrap();
    for r in &rows {
        writeln!(out, "  {:6} {:28} {}", r.name, r.domain, r.worst).unwrap();
    }
    println!("{out}");
    let failed: Vec<String> = rows
        .iter()
        .filter(|r| {
            let Bound(u, e, m) = r.bound;
            r.max_ulp > u || r.max_err > e || r.mean_ulp > m || (r.samples < 1_000_000 && !r.domain.starts_with("special"))
        })
        .map(|r| {
            let Bound(u, e, m) = r.bound;
            format!(
                "{} on {}: max {} ULP (bound {u}), max err {:.3} (bound {e}), mean {:.4} (bound {m}), {} samples; worst {}",
                r.name, r.domain, r.max_ulp, r.max_err, r.mean_ulp, r.samples, r.worst
            )
        })
        .collect();
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// 2^k exactly (k in -149..=127).
fn pow2(k: i32) -> f32 {
    2f64.powi(k) as f32
}

/// Same bits, or both NaN.
fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

#[track_caller]
fn check(got: f32, want: f32, what: &str) {
    assert!(
        same(got, want),
        "{what}: got {got:e} ({:#010x}), want {want:e} ({:#010x})",
        got.to_bits(),
        want.to_bits()
    );
}

#[test]
fn special_values_of_unary_functions_are_exact() {
    use core::f32::consts::{FRAC_PI_2, PI};
    let (inf, nan) = (f32::INFINITY, f32::NAN);
    let tiny = f32::from_bits(1);
    for (f, name) in [
        (math::sin as fn(f32) -> f32, "sin"),
        (math::tan, "tan"),
        (math::atan, "atan"),
        (math::asin, "asin"),
        (math::erf, "erf"),
        (math::expm1, "expm1"),
        (math::log1p, "log1p"),
    ] {
        check(f(0.0), 0.0, name);
        check(f(-0.0), -0.0, name);
        check(f(nan), nan, name);
        if name != "erf" {
            check(f(tiny), tiny, name);
            check(f(-tiny), -tiny, name);
        }
    }
    for f in [math::sin, math::cos, math::tan] {
        check(f(inf), nan, "trig(inf)");
        check(f(-inf), nan, "trig(-inf)");
    }
    check(math::cos(0.0), 1.0, "cos 0");
    check(math::cos(-0.0), 1.0, "cos -0");
    check(math::atan(inf), FRAC_PI_2, "atan inf");
    check(math::atan(-inf), -FRAC_PI_2, "atan -inf");
    check(math::asin(1.0), FRAC_PI_2, "asin 1");
    check(math::asin(-1.0), -FRAC_PI_2, "asin -1");
    check(math::acos(1.0), 0.0, "acos 1");
    check(math::acos(-1.0), PI, "acos -1");
    check(math::acos(0.0), FRAC_PI_2, "acos 0");
    for f in [math::asin, math::acos] {
        check(f(1.000_000_1), nan, "asin/acos > 1");
        check(f(-1.000_000_1), nan, "asin/acos < -1");
        check(f(inf), nan, "asin/acos inf");
    }
    check(math::exp(0.0), 1.0, "exp 0");
    check(math::exp(-0.0), 1.0, "exp -0");
    check(math::exp(inf), inf, "exp inf");
    check(math::exp(-inf), 0.0, "exp -inf");
    check(math::exp(88.722_84), inf, "exp overflow");
    check(
        math::exp(88.722_83),
        f64::from(88.722_83f32).exp() as f32,
        "exp just below overflow",
    );
    assert!(math::exp(88.722_83).is_finite());
    check(math::exp(-104.0), 0.0, "exp underflow");
    check(math::exp(-103.972), tiny, "exp smallest denormal");
    check(math::exp(1.0), core::f32::consts::E, "exp 1");
    check(math::exp2(inf), inf, "exp2 inf");
    check(math::exp2(-inf), 0.0, "exp2 -inf");
    check(math::exp2(128.0), inf, "exp2 128");
    check(math::exp2(-150.0), 0.0, "exp2 -150 (tie to even)");
    for k in -149..=127 {
        check(math::exp2(k as f32), pow2(k), "exp2 integer");
    }
    check(math::expm1(inf), inf, "expm1 inf");
    check(math::expm1(-inf), -1.0, "expm1 -inf");
    for f in [math::log, math::log2] {
        check(f(0.0), -inf, "log 0");
        check(f(-0.0), -inf, "log -0");
        check(f(-1.0), nan, "log -1");
        check(f(-tiny), nan, "log -tiny");
        check(f(inf), inf, "log inf");
        check(f(-inf), nan, "log -inf");
        check(f(1.0), 0.0, "log 1");
        check(f(nan), nan, "log nan");
    }
    for k in -149..=127 {
        check(math::log2(pow2(k)), k as f32, "log2 power of two");
    }
    check(math::log1p(-1.0), -inf, "log1p -1");
    check(math::log1p(-1.5), nan, "log1p -1.5");
    check(math::log1p(inf), inf, "log1p inf");
    check(math::erf(inf), 1.0, "erf inf");
    check(math::erf(-inf), -1.0, "erf -inf");
    check(math::erf(4.0), 1.0, "erf 4");
    check(math::erfc(inf), 0.0, "erfc inf");
    check(math::erfc(-inf), 2.0, "erfc -inf");
    check(math::erfc(0.0), 1.0, "erfc 0");
    check(math::erfc(-0.0), 1.0, "erfc -0");
    check(math::erfc(nan), nan, "erfc nan");
    check(math::erfc(11.0), 0.0, "erfc underflow");
    check(math::sqrt(-0.0), -0.0, "sqrt -0");
    check(math::sqrt(-1.0), nan, "sqrt -1");
    check(math::rsqrt(0.0), inf, "rsqrt 0");
    check(math::rsqrt(-0.0), -inf, "rsqrt -0");
    check(math::rsqrt(inf), 0.0, "rsqrt inf");
    check(math::rsqrt(4.0), 0.5, "rsqrt 4");
}

#[test]
fn special_values_of_atan2_and_pow_match_c99_bit_for_bit() {
    let mut s = specials();
    s.extend([3.0f32, -3.0, 0.25, -0.25, 1e-30, -1e-30]);
    let mut ys = s.clone();
    ys.extend([
        -3.0f32,
        -2.0,
        -1.0,
        0.5,
        -0.5,
        1.0,
        2.0,
        3.0,
        1e10,
        -1e10,
        pow2(24) + 2.0,
        pow2(23) + 1.0,
        -(pow2(23) + 1.0),
    ]);
    for &y in &s {
        for &x in &s {
            if x.is_finite() && y.is_finite() && x != 0.0 && y != 0.0 {
                continue; // ordinary values: covered by the ULP sweep
            }
            check(
                math::atan2(y, x),
                f64::from(y).atan2(f64::from(x)) as f32,
                &format!("atan2({y:e}, {x:e})"),
            );
        }
    }
    for &x in &s {
        for &y in &ys {
            let want = f64::from(x).powf(f64::from(y)) as f32;
            let got = math::pow(x, y);
            let special = !x.is_finite()
                || !y.is_finite()
                || x == 0.0
                || y == 0.0
                || x == 1.0
                || !want.is_normal();
            if special {
                check(got, want, &format!("pow({x:e}, {y:e})"));
            } else {
                // ordinary value (negative bases included): sign exact, magnitude within 1 ULP
                assert!(
                    got.is_sign_negative() == want.is_sign_negative() && ulps(got, want) <= 1,
                    "pow({x:e}, {y:e}): got {got:e}, want {want:e}"
                );
            }
        }
    }
    check(math::pow(-2.0, 3.0), -8.0, "pow(-2, 3)");
    check(math::pow(-2.0, -3.0), -0.125, "pow(-2, -3)");
    check(math::pow(-2.0, 0.5), f32::NAN, "pow(-2, 0.5)");
    check(
        math::pow(2.0, 0.5),
        core::f32::consts::SQRT_2,
        "pow(2, 0.5)",
    );
    check(math::pow(f32::NAN, 0.0), 1.0, "pow(nan, 0)");
    check(math::pow(1.0, f32::NAN), 1.0, "pow(1, nan)");
    check(math::pow(-1.0, f32::INFINITY), 1.0, "pow(-1, inf)");
    check(math::pow(2.0, 128.0), f32::INFINITY, "pow(2, 128)");
    check(math::pow(2.0, -149.0), f32::from_bits(1), "pow(2, -149)");
    check(math::pow(2.0, -150.0), 0.0, "pow(2, -150)");
    check(math::pow(-0.5, 149.0), -f32::from_bits(1), "pow(-0.5, 149)");
    for k in -149..=127 {
        check(math::pow(2.0, k as f32), pow2(k), "pow(2, k)");
    }
}

#[test]
fn rounding_helpers_match_std_bit_for_bit() {
    let mut r = Rng(reference::splitmix::SplitMix64(99));
    let mut v = specials();
    for i in -40..=40 {
        v.push(i as f32 * 0.25);
    }
    v.extend([
        0.49999997f32,
        -0.49999997,
        8_388_607.5,
        -8_388_607.5,
        8_388_609.0,
        2_147_483_520.0,
        -2_147_483_648.0,
        2_147_483_648.0,
        1e20,
        -1e20,
    ]);
    for _ in 0..200_000 {
        v.push(r.log_uniform(1e-3, 1e8, true));
    }
    for &x in &v {
        check(math::floor(x), x.floor(), &format!("floor {x:e}"));
        check(math::ceil(x), x.ceil(), &format!("ceil {x:e}"));
        check(math::trunc(x), x.trunc(), &format!("trunc {x:e}"));
        check(math::round(x), x.round(), &format!("round {x:e}"));
        check(math::abs(x), x.abs(), &format!("abs {x:e}"));
        check(
            math::copysign(1.5, x),
            1.5f32.copysign(x),
            &format!("copysign {x:e}"),
        );
        assert_eq!(
            math::round_to_int(x),
            x.round() as i32,
            "round_to_int {x:e}"
        ); // `as` saturates, NaN -> 0
        assert_eq!(math::is_nan(x), x.is_nan());
        assert_eq!(math::is_finite(x), x.is_finite());
    }
}

#[test]
fn min_max_clamp_semantics() {
    let nan = f32::NAN;
    check(math::min(1.0, nan), 1.0, "min(1, nan)");
    check(math::min(nan, 1.0), 1.0, "min(nan, 1)");
    check(math::max(nan, -1.0), -1.0, "max(nan, -1)");
    check(math::max(2.0, nan), 2.0, "max(2, nan)");
    check(math::min(nan, nan), nan, "min(nan, nan)");
    check(math::min(0.0, -0.0), -0.0, "min(0, -0)");
    check(math::min(-0.0, 0.0), -0.0, "min(-0, 0)");
    check(math::max(0.0, -0.0), 0.0, "max(0, -0)");
    check(math::max(-0.0, 0.0), 0.0, "max(-0, 0)");
    check(math::min(-3.0, 2.0), -3.0, "min");
    check(math::max(-3.0, 2.0), 2.0, "max");
    check(
        math::min(f32::NEG_INFINITY, 2.0),
        f32::NEG_INFINITY,
        "min -inf",
    );
    check(math::clamp(nan, 0.0, 1.0), nan, "clamp nan");
    check(math::clamp(-2.0, -1.0, 1.0), -1.0, "clamp low");
    check(math::clamp(2.0, -1.0, 1.0), 1.0, "clamp high");
    check(math::clamp(0.25, -1.0, 1.0), 0.25, "clamp inside");
    check(math::clamp(0.25, nan, nan), 0.25, "clamp nan bounds");
    check(math::saturate(-0.0), -0.0, "saturate -0");
    check(math::saturate(1.5), 1.0, "saturate 1.5");
    check(math::saturate(-1.5), 0.0, "saturate -1.5");
    check(math::saturate(nan), nan, "saturate nan");
}

#[test]
fn sin_cos_is_bit_identical_to_sin_and_cos() {
    let mut v = mix(21, 200_000, -10.0, 10.0, 200_000, 1e-40, 3.4e38, true);
    v.extend(specials());
    v.extend(near_multiples_of_pio2().into_iter().step_by(7));
    for &x in &v {
        let (s, c) = math::sin_cos(x);
        check(s, math::sin(x), &format!("sin_cos.0 {x:e}"));
        check(c, math::cos(x), &format!("sin_cos.1 {x:e}"));
    }
}

/// Every `MATH_STRIDE`-th f32 bit pattern (default 127, i.e. 33.8 M inputs spread over the whole
/// float line, both signs) through each unary function. Slow (about a minute on two cores):
/// `cargo test -p shader-core --release --test math_accuracy -- --ignored --nocapture`.
#[test]
#[ignore]
fn all_bit_patterns_strided() {
    let stride: u64 = std::env::var("MATH_STRIDE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(127);
    type F = (&'static str, fn(f32) -> f32, fn(f64) -> f64, Bound);
    let fns: Vec<F> = vec![
        ("sin", math::sin, f64::sin, Bound(1, 0.80, 1.0)),
        ("cos", math::cos, f64::cos, Bound(1, 0.82, 1.0)),
        ("tan", math::tan, f64::tan, Bound(1, 0.93, 1.0)),
        ("atan", math::atan, f64::atan, Bound(1, 1.19, 1.0)),
        ("asin", math::asin, f64::asin, Bound(1, 0.70, 1.0)),
        ("acos", math::acos, f64::acos, Bound(1, 0.68, 1.0)),
        ("exp", math::exp, f64::exp, Bound(1, 0.68, 1.0)),
        ("exp2", math::exp2, f64::exp2, Bound(1, 0.69, 1.0)),
        ("expm1", math::expm1, f64::exp_m1, Bound(1, 1.18, 1.0)),
        ("log", math::log, f64::ln, Bound(1, 0.94, 1.0)),
        ("log2", math::log2, f64::log2, Bound(1, 1.0, 1.0)),
        ("log1p", math::log1p, f64::ln_1p, Bound(1, 0.96, 1.0)),
        ("erf", math::erf, erf64, Bound(1, 0.86, 1.0)),
        ("erfc", math::erfc, erfc64, Bound(1, 0.97, 1.0)),
    ];
    let rows: Vec<Row> = std::thread::scope(|sc| {
        let handles: Vec<_> = fns
            .chunks(fns.len().div_ceil(2))
            .map(|chunk| {
                sc.spawn(move || {
                    chunk
                        .iter()
                        .map(|&(name, f, reference, bound)| {
                            let inputs: Vec<f32> = (0..(1u64 << 32))
                                .step_by(stride as usize)
                                .map(|b| f32::from_bits(b as u32))
                                .collect();
                            sweep1(
                                name,
                                "every stride-th bit pattern",
                                bound,
                                &inputs,
                                f,
                                reference,
                            )
                        })
                        .collect::<Vec<Row>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    });
    println!("\nstride {stride}:\n| function | samples | max ULP | mean ULP | max err vs f64 (ULP) |\n| --- | ---: | ---: | ---: | ---: |");
    for r in &rows {
        println!(
            "| {} | {} | {} | {:.4} | {:.3} |",
            r.name, r.samples, r.max_ulp, r.mean_ulp, r.max_err
        );
    }
    for r in &rows {
        println!("  {:6} {}", r.name, r.worst);
    }
    let failed: Vec<String> = rows
        .iter()
        .filter(|r| r.max_ulp > r.bound.0 || r.max_err > r.bound.1)
        .map(|r| {
            format!(
                "{}: {} ULP, err {:.3}; {}",
                r.name, r.max_ulp, r.max_err, r.worst
            )
        })
        .collect();
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// Every f32 in [2^-12, 102900] (the whole Cody-Waite range; negative arguments are exact
/// mirrors) through sin, cos and tan: 2.4e8 inputs each, about a minute on two cores.
/// `cargo test -p shader-core --release --test math_accuracy trig_exhaustive -- --ignored --nocapture`
#[test]
#[ignore]
fn trig_exhaustive_cody_waite_range() {
    let lo = 2f32.powi(-12).to_bits();
    let hi = math::TRIG_CODY_WAITE_MAX.to_bits();
    let inputs: Vec<f32> = (lo..=hi).map(f32::from_bits).collect();
    let rows: Vec<Row> = std::thread::scope(|sc| {
        let a = sc.spawn(|| {
            vec![
                sweep1(
                    "sin",
                    "every f32 in [2^-12, 102900]",
                    Bound(1, 0.80, 1.0),
                    &inputs,
                    math::sin,
                    f64::sin,
                ),
                sweep1(
                    "cos",
                    "every f32 in [2^-12, 102900]",
                    Bound(1, 0.82, 1.0),
                    &inputs,
                    math::cos,
                    f64::cos,
                ),
            ]
        });
        let b = sc.spawn(|| {
            vec![sweep1(
                "tan",
                "every f32 in [2^-12, 102900]",
                Bound(1, 0.93, 1.0),
                &inputs,
                math::tan,
                f64::tan,
            )]
        });
        let mut v = a.join().unwrap();
        v.extend(b.join().unwrap());
        v
    });
    for r in &rows {
        println!(
            "| {} | {} | {} | {} | {:.4} | {:.3} |  worst {}",
            r.name, r.domain, r.samples, r.max_ulp, r.mean_ulp, r.max_err, r.worst
        );
    }
    let failed: Vec<String> = rows
        .iter()
        .filter(|r| r.max_ulp > r.bound.0 || r.max_err > r.bound.1)
        .map(|r| {
            format!(
                "{}: {} ULP, err {:.3}; {}",
                r.name, r.max_ulp, r.max_err, r.worst
            )
        })
        .collect();
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
