//! The foundation's CPU-vs-GPU comparison: GGX D, Lambda and G1 over a dense grid plus
//! adversarial inputs, 0 ULP required on every element.

use crosscheck::{compare_table, gpu_backend, inputs};

fn rows() -> Vec<f32> {
    let mut dirs = inputs::directions(180, 96);
    dirs.extend(inputs::adversarial_directions());
    inputs::direction_alpha_rows(&dirs, &inputs::alpha_pairs())
}

fn check(name: &str) {
    let Some(gpu) = gpu_backend() else { return };
    let cmp = compare_table(gpu, name, &rows());
    eprintln!("{}", cmp.report());
    assert!(cmp.rows > 500_000, "dense grid expected");
    assert_eq!(cmp.differing(), 0, "CPU and GPU differ:\n{}", cmp.report());
}

#[test]
fn ggx_d_cpu_matches_gpu_bit_for_bit() {
    check("ggx_d");
}

#[test]
fn ggx_lambda_cpu_matches_gpu_bit_for_bit() {
    check("ggx_lambda");
}

#[test]
fn ggx_g1_cpu_matches_gpu_bit_for_bit() {
    check("ggx_g1");
}

/// The premise of bit-exactness: + - * / sqrt and 1/sqrt round identically on both backends,
/// denormal operands and results included (lavapipe keeps denormals; if a driver flushed them
/// this test would say so, element by element).
#[test]
fn basic_arithmetic_is_bit_exact_including_denormals() {
    let Some(gpu) = gpu_backend() else { return };
    let mut vals = inputs::adversarial_scalars();
    // Dense sample of all float magnitudes, denormals included.
    let mut bits: u32 = 1;
    while bits < 0x7f80_0000 {
        vals.push(f32::from_bits(bits));
        bits = bits.wrapping_mul(5).wrapping_add(0x1_2345) % 0x7f80_0000;
        if vals.len() > 3000 {
            break;
        }
    }
    vals.extend([f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 3e-39, -7e-42]);
    let mut rows = Vec::new();
    for &a in &vals {
        for &b in vals.iter().step_by(7) {
            rows.extend_from_slice(&[a, b]);
        }
    }
    let cmp = compare_table(gpu, "arith_probe", &rows);
    eprintln!("{}", cmp.report());
    assert_eq!(cmp.differing(), 0, "{}", cmp.report());
}
