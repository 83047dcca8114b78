//! The project's own elementary functions (shader-core `math`) give the same bits on the CPU and
//! on the GPU: the point of owning them (the driver's sin is 1 ULP off, its exp 55 ULP).

use crosscheck::{compare_table, gpu_backend, inputs};

fn scalars() -> Vec<f32> {
    let mut v = inputs::adversarial_scalars();
    // Dense over the ranges where range reduction and polynomial switches happen.
    for i in 0..200_000 {
        let t = i as f32 / 200_000.0;
        v.push(-110.0 + 220.0 * t); // exp over/underflow, trig reduction
        v.push(-1.0 + 2.0 * t); // asin, acos, erf, log1p near the edges
    }
    for e in -40..=38 {
        for m in [1.0f32, 1.234_567, std::f32::consts::PI, 7.5] {
            v.push(m * 10f32.powi(e));
            v.push(-m * 10f32.powi(e));
        }
    }
    v.extend([f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e5, 12_345.678, 88.72, -103.9, 89.0]);
    v
}

#[test]
fn unary_elementary_functions_are_bit_exact() {
    let Some(gpu) = gpu_backend() else { return };
    let cmp = compare_table(gpu, "math_unary", &scalars());
    eprintln!("{}", cmp.report());
    assert_eq!(cmp.differing(), 0, "{}", cmp.report());
}

#[test]
fn binary_elementary_functions_are_bit_exact() {
    let Some(gpu) = gpu_backend() else { return };
    let s = scalars();
    let xs: Vec<f32> = s.iter().step_by(500).copied().collect();
    let mut rows = Vec::new();
    for &a in &xs {
        for &b in &xs {
            rows.extend_from_slice(&[a, b]);
        }
    }
    for i in 0..50_000 {
        let t = i as f32 / 50_000.0;
        rows.extend_from_slice(&[0.01 + 4.0 * t, -3.0 + 6.0 * t]);
        rows.extend_from_slice(&[(std::f32::consts::TAU * t).cos(), (std::f32::consts::TAU * t).sin()]);
    }
    let cmp = compare_table(gpu, "math_binary", &rows);
    eprintln!("{}", cmp.report());
    assert_eq!(cmp.differing(), 0, "{}", cmp.report());
}
