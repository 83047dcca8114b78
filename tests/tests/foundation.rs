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
