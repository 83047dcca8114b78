//! CPU vs GPU (lavapipe) for every registered microfacet function (`shader-kernels/src/eval/
//! microfacet.rs`, plus the GGX D/Lambda/G1 of `foundation.rs`): a dense grid plus the
//! adversarial inputs of `crosscheck::inputs` (signed zeros, denormals, 1 ± ulp, huge, grazing,
//! degenerate vectors, NaN, invalid roughness), 0 ULP required on every element.
//!
//! Run: `cargo test --release -p crosscheck --test microfacet_crosscheck -- --nocapture`.

use crosscheck::{compare_table, gpu_backend, inputs, Comparison};

/// Run `names` over `rows`, print every report, and fail listing every function that differs.
fn check_all(names: &[&str], rows: &[f32]) {
    let Some(gpu) = gpu_backend() else { return };
    let mut bad: Vec<Comparison> = Vec::new();
    for &name in names {
        let cmp = compare_table(gpu, name, rows);
        eprintln!("{}", cmp.report());
        if cmp.differing() != 0 {
            bad.push(cmp);
        }
    }
    assert!(bad.is_empty(), "CPU and GPU differ:\n{}", bad.iter().map(|c| c.report()).collect::<String>());
}

fn dirs() -> Vec<[f32; 3]> {
    let mut d = inputs::directions(90, 48);
    d.extend(inputs::adversarial_directions());
    d
}

/// A few more denormal/huge/non-finite directions than `inputs::adversarial_directions`.
fn extra_dirs() -> Vec<[f32; 3]> {
    let t = f32::from_bits(1);
    vec![
        [t, 0.0, 1.0],
        [1.0, 1.0, t],
        [f32::MAX, 0.0, t],
        [f32::MAX, f32::MAX, f32::MAX],
        [f32::NAN, 0.0, 1.0],
        [0.0, 0.0, f32::INFINITY],
        [f32::NEG_INFINITY, 0.0, 1.0],
    ]
}

/// Cosines: dense in [-1, 1] plus the adversarial scalars (which include |x| > 1 and NaN-free
/// extremes) and NaN, +-Inf.
fn cosines(n: usize) -> Vec<f32> {
    let mut c: Vec<f32> = (0..=n).map(|i| (2.0 * i as f64 / n as f64 - 1.0) as f32).collect();
    c.extend(inputs::adversarial_scalars());
    c.extend([f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e-7, -1e-7, 0.999_999_9]);
    c
}

fn alphas() -> Vec<f32> {
    let mut a = inputs::alphas();
    a.extend([f32::INFINITY, f32::NEG_INFINITY, 1e-30, 1e4]);
    a
}

#[test]
fn ndf_and_lambda_of_a_direction_and_two_alphas() {
    let mut d = dirs();
    d.extend(extra_dirs());
    let mut pairs = inputs::alpha_pairs();
    pairs.extend([(f32::INFINITY, 0.5), (1e-30, 1e-30), (1e4, 1e4)]);
    let rows = inputs::direction_alpha_rows(&d, &pairs);
    check_all(
        &["ggx_d", "beckmann_d", "ggx_lambda", "ggx_g1", "beckmann_lambda", "beckmann_g1", "beckmann_lambda_walter", "beckmann_g1_walter"],
        &rows,
    );
}

#[test]
fn isotropic_ndfs_of_a_direction_and_one_parameter() {
    let mut d = dirs();
    d.extend(extra_dirs());
    let mut rows = Vec::new();
    for v in &d {
        for a in alphas() {
            rows.extend_from_slice(&[v[0], v[1], v[2], a]);
        }
    }
    check_all(&["gtr1_d", "gtr2_d", "ggx_d_mobile"], &rows);
    let mut rows = Vec::new();
    let exps = [0.0f32, 1e-6, 0.5, 1.0, 2.0, 10.0, 100.0, 1e3, 1e5, 2e6, 1e30, f32::INFINITY, -0.5, -1.0, f32::NAN];
    for v in &d {
        for &n in &exps {
            rows.extend_from_slice(&[v[0], v[1], v[2], n]);
        }
    }
    check_all(&["blinn_phong_d"], &rows);
}

#[test]
fn ndfs_of_n_dot_h() {
    let mut rows = Vec::new();
    for c in cosines(4096) {
        for a in alphas() {
            rows.extend_from_slice(&[c, a]);
        }
    }
    check_all(&["ggx_d_ue4", "ggx_d_mobile_naive"], &rows);
}

#[test]
fn roughness_parameterizations() {
    let mut s = inputs::adversarial_scalars();
    s.extend(alphas());
    s.extend((0..=2000).map(|i| i as f32 / 1000.0));
    check_all(&["blinn_phong_exponent", "blinn_phong_alpha"], &s);
    let mut rows = Vec::new();
    let k: Vec<f32> = cosines(200);
    for &r in s.iter().step_by(3) {
        for &a in &k {
            rows.extend_from_slice(&[r, a]);
        }
    }
    check_all(&["disney_aniso_alpha"], &rows);
}

#[test]
fn g2_forms() {
    let mut d = inputs::directions(12, 8);
    d.extend(inputs::adversarial_directions().into_iter().step_by(83));
    d.extend(extra_dirs());
    let pairs: Vec<(f32, f32)> = inputs::alpha_pairs().into_iter().step_by(3).collect();
    let mut rows = Vec::new();
    for o in &d {
        for i in &d {
            for &(ax, ay) in &pairs {
                rows.extend_from_slice(&[o[0], o[1], o[2], i[0], i[1], i[2], ax, ay]);
            }
        }
    }
    check_all(
        &["ggx_g2_separable", "ggx_g2_height_correlated", "ggx_g2_direction_correlated", "ggx_g2_height_direction_correlated", "beckmann_g2_height_correlated"],
        &rows,
    );
}

#[test]
fn visibility_terms() {
    let c = cosines(120);
    let mut rows = Vec::new();
    for &v in &c {
        for &l in &c {
            for a in alphas() {
                rows.extend_from_slice(&[v, l, a]);
            }
        }
    }
    check_all(
        &["v_frostbite", "v_hdrp", "v_hdrp_approx", "v_ue4", "v_filament", "v_filament_fast", "v_respawn", "v_schlick_smith", "v_schlick_smith_remapped"],
        &rows,
    );
    let c2 = cosines(600);
    let mut rows = Vec::new();
    for &v in &c2 {
        for &l in &c2 {
            rows.extend_from_slice(&[v, l]);
        }
    }
    check_all(&["v_implicit", "v_neumann"], &rows);
    check_all(&["v_kelemen"], &cosines(200_000));
    let c4: Vec<f32> = cosines(10).into_iter().step_by(2).collect();
    let mut rows = Vec::new();
    for &a in &c4 {
        for &b in &c4 {
            for &h in &c4 {
                for &v in &c4 {
                    rows.extend_from_slice(&[a, b, h, v]);
                }
            }
        }
    }
    check_all(&["v_cook_torrance"], &rows);
}

#[test]
fn issue_3_functions_are_registered_for_host_eval() {
    // The names `host eval --list` must show (issue #3); `host/tests/cli.rs` checks that every
    // registered function is listed.
    let required = [
        "ggx_d",
        "ggx_lambda",
        "ggx_g1",
        "ggx_g2_height_correlated",
        "beckmann_d",
        "beckmann_g1",
        "fresnel_dielectric",
        "fresnel_conductor",
        "conductor_f",
    ];
    let missing: Vec<&str> = required.iter().copied().filter(|n| shader_kernels::eval::find(n).is_none()).collect();
    assert!(missing.is_empty(), "not registered for `host eval`: {missing:?}");
}
