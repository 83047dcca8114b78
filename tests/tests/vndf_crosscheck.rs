//! CPU vs GPU (lavapipe) comparison of the reflection samplers and their densities registered in
//! `shader_kernels::eval::vndf`: a dense grid of wi, alpha and (u1, u2) for the
//! samplers and of (wi, wo, alpha) for the densities, plus adversarial values (signed zeros,
//! denormals, huge, grazing, unnormalized and degenerate directions, invalid alphas, NaN), 0 ULP
//! required on every output element (two NaNs of any payload count as equal).
//!
//! `cargo test --release -p crosscheck --test vndf_crosscheck -- --nocapture` prints one table per
//! function.

use crosscheck::{compare_table, gpu_backend, inputs};

/// Front- and back-facing directions on a sphere grid with the grazing band, plus adversarial ones.
fn dirs(n_theta: usize, n_phi: usize, adversarial_step: usize) -> Vec<[f32; 3]> {
    let mut d = inputs::directions(n_theta, n_phi);
    d.extend(inputs::adversarial_directions().into_iter().step_by(adversarial_step));
    d.push([f32::NAN, 0.0, 1.0]);
    d.push([0.0, 0.0, f32::INFINITY]);
    d
}

fn alpha_pairs() -> Vec<(f32, f32)> {
    vec![
        (0.0, 0.0),
        (1e-4, 1e-4),
        (1e-3, 1e-3),
        (0.02, 0.02),
        (0.2, 0.2),
        (0.6, 0.6),
        (1.0, 1.0),
        (2.5, 2.5),
        (0.05, 1.0),
        (1.0, 0.05),
        (0.01, 0.2),
        (0.0, 0.5),
        (-0.1, 0.2),
        (f32::NAN, 0.2),
        (0.3, f32::INFINITY),
    ]
}

/// (u1, u2) pairs: a 9 x 9 grid including 0, 1e-7, 0.5 and 1 - 2^-24, plus out-of-range values.
fn us() -> Vec<[f32; 2]> {
    let u = [0.0f32, 1e-7, 0.1, 0.25, 0.5, 0.61, 0.9, 0.999, 1.0 - f32::EPSILON / 2.0];
    let mut out = Vec::new();
    for &a in &u {
        for &b in &u {
            out.push([a, b]);
        }
    }
    out.extend([[1.0, 0.5], [0.5, 1.0], [-0.1, 0.3], [0.3, 7.0], [f32::NAN, 0.5]]);
    out
}

fn sample_rows() -> Vec<f32> {
    let mut rows = Vec::new();
    for d in dirs(36, 12, 7) {
        for &(ax, ay) in &alpha_pairs() {
            for u in us() {
                rows.extend([d[0], d[1], d[2], ax, ay, u[0], u[1]]);
            }
        }
    }
    rows
}

fn pdf_rows() -> Vec<f32> {
    let wis = dirs(18, 6, 23);
    let wos = dirs(24, 8, 41);
    let mut rows = Vec::new();
    for wi in &wis {
        for wo in &wos {
            for &(ax, ay) in &alpha_pairs() {
                rows.extend([wi[0], wi[1], wi[2], wo[0], wo[1], wo[2], ax, ay]);
            }
        }
    }
    rows
}

fn run(name: &str, rows: &[f32]) {
    let Some(gpu) = gpu_backend() else { return };
    let cmp = compare_table(gpu, name, rows);
    eprintln!("{}", cmp.report());
    assert!(cmp.rows >= 100_000, "{name}: too few rows ({})", cmp.rows);
    assert_eq!(cmp.differing(), 0, "CPU and GPU differ:\n{}", cmp.report());
}

#[test]
fn samplers_cpu_match_gpu() {
    let rows = sample_rows();
    for name in ["sample_ndf", "sample_vndf_heitz", "sample_vndf_caps", "sample_vndf_bounded"] {
        run(name, &rows);
    }
}

#[test]
fn pdfs_cpu_match_gpu() {
    let rows = pdf_rows();
    for name in ["pdf_ndf", "pdf_vndf_heitz", "pdf_vndf_caps", "pdf_vndf_bounded"] {
        run(name, &rows);
    }
}
