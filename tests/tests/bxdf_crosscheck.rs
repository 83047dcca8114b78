//! CPU vs GPU (lavapipe) comparison of every Fresnel / BxDF function registered in
//! `shader_kernels::eval::bxdf`: a dense grid plus adversarial values (signed zeros,
//! denormals, huge, grazing, unnormalized and degenerate directions, NaN / Inf parameters), 0 ULP
//! required on every output element (two NaNs of any payload count as equal).
//!
//! `cargo test --release -p crosscheck --test bxdf_crosscheck -- --nocapture` prints one table per
//! function (rows, differing elements, max ULP, NaN/Inf counts per backend).

use crosscheck::{compare_table, function, gpu_backend, inputs};

/// Directions for pair functions (f, pdf): a coarse sphere grid (grazing band included) plus
/// every 9th adversarial direction (zero, denormal, huge, mixed scales).
fn pair_dirs() -> Vec<[f32; 3]> {
    let mut d = inputs::directions(8, 4);
    d.extend(inputs::adversarial_directions().into_iter().step_by(29));
    d.push([f32::NAN, 0.0, 1.0]);
    d.push([0.0, 0.0, f32::INFINITY]);
    d
}

/// Directions for samplers: denser sphere grid plus adversarial directions.
fn sample_dirs() -> Vec<[f32; 3]> {
    let mut d = inputs::directions(18, 6);
    d.extend(inputs::adversarial_directions().into_iter().step_by(13));
    d.push([f32::NAN, 0.0, 1.0]);
    d
}

/// (uc, u0, u1) triples: a 5 x 7 x 7 grid including 0 and 1 - 2^-24.
fn us() -> Vec<[f32; 3]> {
    let u = [0.0f32, 1e-7, 0.2, 0.5, 0.77, 0.999, 1.0 - f32::EPSILON / 2.0];
    let uc = [0.0f32, 0.03, 0.5, 0.9, 1.0 - f32::EPSILON / 2.0];
    let mut out = Vec::new();
    for &c in &uc {
        for &a in &u {
            for &b in &u {
                out.push([c, a, b]);
            }
        }
    }
    out
}

fn alpha_pairs() -> Vec<(f32, f32)> {
    vec![(0.0, 0.0), (1e-4, 1e-4), (1e-3, 1e-3), (0.02, 0.02), (0.2, 0.2), (0.6, 0.6), (1.0, 1.0), (2.5, 2.5), (0.05, 0.5), (0.5, 0.05), (-0.1, 0.2), (f32::NAN, 0.2)]
}

fn run(name: &str, rows: &[f32]) {
    let Some(gpu) = gpu_backend() else { return };
    let f = function(name);
    assert_eq!(rows.len() % f.inputs.len(), 0);
    let cmp = compare_table(gpu, name, rows);
    eprintln!("{}", cmp.report());
    assert!(cmp.rows >= 10_000, "{name}: too few rows ({})", cmp.rows);
    assert_eq!(cmp.differing(), 0, "CPU and GPU differ:\n{}", cmp.report());
}

fn scalars_signed() -> Vec<f32> {
    let mut v = inputs::adversarial_scalars();
    v.extend([f32::NAN, f32::INFINITY, f32::NEG_INFINITY]);
    v
}

#[test]
fn fresnel_dielectric_cpu_matches_gpu() {
    let mut cos: Vec<f32> = (0..=2000).map(|i| -1.0 + i as f32 / 1000.0).collect();
    cos.extend(scalars_signed());
    let mut etas: Vec<f32> = (0..=60).map(|i| 0.1 * 1.06f32.powi(i)).collect();
    etas.extend([1.0, 1.0 + 1.2e-7, 1.0 - 6e-8, 1.5, 1.0 / 1.5, 1.33]);
    etas.extend(scalars_signed());
    let mut rows = Vec::new();
    for &c in &cos {
        for &e in &etas {
            rows.extend([c, e]);
        }
    }
    run("fresnel_dielectric", &rows);
}

#[test]
fn fresnel_conductor_cpu_matches_gpu() {
    let mut cos: Vec<f32> = (0..=500).map(|i| -0.2 + i as f32 / 400.0).collect();
    cos.extend(scalars_signed());
    let mut etas = vec![0.0f32, 0.05, 0.18836, 0.5, 0.9, 1.0, 1.1, 1.4303, 2.4, 10.0, 1e-30, 1e30];
    etas.extend([-1.0, f32::NAN, f32::INFINITY]);
    let mut ks = vec![0.0f32, 1e-3, 0.5, 1.8693, 3.4034, 7.5081, 100.0, 1e20];
    ks.extend([-1.0, f32::NAN, f32::INFINITY]);
    let mut rows = Vec::new();
    for &c in &cos {
        for &e in &etas {
            for &k in &ks {
                rows.extend([c, e, k]);
            }
        }
    }
    run("fresnel_conductor", &rows);
}

#[test]
fn fresnel_schlick_cpu_matches_gpu() {
    let mut cos: Vec<f32> = (0..=2000).map(|i| -1.0 + i as f32 / 1000.0).collect();
    cos.extend(scalars_signed());
    let f0s = [0.0f32, 0.02, 0.04, 0.5, 0.9, 1.0, f32::NAN];
    let f90s = [1.0f32, 0.5, 0.0, 2.0];
    let mut rows = Vec::new();
    for &c in &cos {
        for &a in &f0s {
            for &b in &f90s {
                rows.extend([c, a, b]);
            }
        }
    }
    run("fresnel_schlick", &rows);
}

#[test]
fn gulbrandsen_cpu_matches_gpu() {
    let mut rows = Vec::new();
    let mut vals: Vec<f32> = (-10..=110).map(|i| i as f32 / 100.0).collect();
    vals.extend(scalars_signed());
    for &r in &vals {
        for &g in &vals {
            rows.extend([r, g]);
        }
    }
    run("gulbrandsen_nk", &rows);
    let mut rows = Vec::new();
    let mut ns: Vec<f32> = (0..=150).map(|i| i as f32 / 20.0).collect();
    ns.extend(scalars_signed());
    for &n in &ns {
        for &k in &ns {
            rows.extend([n, k]);
        }
    }
    run("gulbrandsen_rg", &rows);
}

#[test]
fn refract_cpu_matches_gpu() {
    let mut dirs = inputs::directions(36, 12);
    dirs.extend(inputs::adversarial_directions().into_iter().step_by(11));
    let normals = [[0.0f32, 0.0, 1.0], [0.0, 0.0, -1.0], [0.6, 0.0, 0.8], [0.0, -0.28, 0.96]];
    let etas = [1.0f32, 1.0 + 1.2e-7, 1.33, 1.5, 1.0 / 1.5, 2.4, 0.01, 100.0, 0.0, -1.0, f32::NAN, f32::INFINITY];
    let mut rows = Vec::new();
    for d in &dirs {
        for n in &normals {
            for &e in &etas {
                rows.extend([d[0], d[1], d[2], n[0], n[1], n[2], e]);
            }
        }
    }
    run("refract", &rows);
}

#[test]
fn ggx_vndf_cpu_matches_gpu() {
    let dirs = sample_dirs();
    let mut rows = Vec::new();
    for d in &dirs {
        for &(ax, ay) in &[(1e-3f32, 1e-3f32), (0.1, 0.1), (0.5, 0.5), (1.0, 1.0), (0.05, 0.6), (3.0, 0.3)] {
            for u in us().iter().step_by(7) {
                rows.extend([d[0], d[1], d[2], ax, ay, u[1], u[2]]);
            }
        }
    }
    run("ggx_vndf_sample", &rows);
    let pd = pair_dirs();
    let mut rows = Vec::new();
    for w in &pd {
        for wm in inputs::directions(12, 6).iter().step_by(2) {
            for &(ax, ay) in &[(1e-3f32, 1e-3f32), (0.3, 0.3), (1.0, 0.2), (0.0, 0.0)] {
                rows.extend([w[0], w[1], w[2], wm[0], wm[1], wm[2], ax, ay]);
            }
        }
    }
    run("ggx_vndf_pdf", &rows);
}

/// Rows `[wo, wi, params...]` for every pair of `dirs` and every parameter row.
fn pair_rows(dirs: &[[f32; 3]], params: &[Vec<f32>]) -> Vec<f32> {
    let mut rows = Vec::new();
    for wo in dirs {
        for wi in dirs {
            for p in params {
                rows.extend_from_slice(wo);
                rows.extend_from_slice(wi);
                rows.extend_from_slice(p);
            }
        }
    }
    rows
}

/// Rows `[wo, uc, u0, u1, params...]`.
fn sample_rows(dirs: &[[f32; 3]], params: &[Vec<f32>]) -> Vec<f32> {
    let mut rows = Vec::new();
    let u = us();
    // Thin the (u, parameter) grid, differently per direction, to about 3 * 10^5 rows.
    let thin = (dirs.len() * u.len() * params.len()).div_ceil(300_000);
    for (k, wo) in dirs.iter().enumerate() {
        for (i, uu) in u.iter().enumerate() {
            for (j, p) in params.iter().enumerate() {
                if !(i + j * u.len() + k).is_multiple_of(thin) {
                    continue;
                }
                rows.extend_from_slice(wo);
                rows.extend_from_slice(uu);
                rows.extend_from_slice(p);
            }
        }
    }
    rows
}

#[test]
fn lambert_cpu_matches_gpu() {
    let params = vec![vec![0.2f32, 0.5, 0.8], vec![1.0, 1.0, 1.0], vec![f32::NAN, 0.0, 1.0]];
    run("lambert_f", &pair_rows(&pair_dirs(), &params));
    run("lambert_pdf", &pair_rows(&pair_dirs(), &[vec![]]));
    run("lambert_sample_f", &sample_rows(&sample_dirs(), &params));
}

fn conductor_params(with_fresnel: bool) -> Vec<Vec<f32>> {
    let mut out = Vec::new();
    for (ax, ay) in alpha_pairs() {
        if with_fresnel {
            out.push(vec![ax, ay, 0.18836, 0.54836, 1.3319, 3.4034, 2.2309, 1.8693]);
            out.push(vec![ax, ay, 1.5, 1.0, 0.0, 0.0, 0.0, 1.0]);
        } else {
            out.push(vec![ax, ay]);
        }
    }
    out.push(vec![0.3, 0.3, -1.0, 1.0, 1.0, 1.0, 1.0, 1.0][..if with_fresnel { 8 } else { 2 }].to_vec());
    out
}

#[test]
fn conductor_cpu_matches_gpu() {
    run("conductor_f", &pair_rows(&pair_dirs(), &conductor_params(true)));
    run("conductor_pdf", &pair_rows(&pair_dirs(), &conductor_params(false)));
    run("conductor_sample_f", &sample_rows(&sample_dirs(), &conductor_params(true)));
}

fn dielectric_params() -> Vec<Vec<f32>> {
    let mut out = Vec::new();
    for (ax, ay) in alpha_pairs() {
        for eta in [1.5f32, 1.0 / 1.5, 1.0, 1.0 + 1.2e-7] {
            for mode in [0.0f32, 1.0] {
                out.push(vec![ax, ay, eta, mode]);
            }
        }
    }
    out.push(vec![0.3, 0.3, 0.0, 0.0]);
    out.push(vec![0.3, 0.3, f32::NAN, 1.0]);
    out
}

#[test]
fn dielectric_cpu_matches_gpu() {
    let d: Vec<[f32; 3]> = pair_dirs().into_iter().step_by(2).collect();
    run("dielectric_f", &pair_rows(&d, &dielectric_params()));
    run("dielectric_pdf", &pair_rows(&d, &dielectric_params()));
    run("dielectric_sample_f", &sample_rows(&sample_dirs(), &dielectric_params()));
}

fn gltf_params() -> Vec<Vec<f32>> {
    let mut out = Vec::new();
    for r in [0.0f32, 0.02, 0.1, 0.5, 1.0, 1.5] {
        for m in [0.0f32, 0.5, 1.0] {
            out.push(vec![0.9, 0.6, 0.3, m, r]);
        }
    }
    out.push(vec![0.0, 0.0, 0.0, 0.0, 0.5]);
    out.push(vec![0.5, 0.5, 0.5, f32::NAN, 0.5]);
    out
}

#[test]
fn gltf_cpu_matches_gpu() {
    let d: Vec<[f32; 3]> = pair_dirs().into_iter().step_by(2).collect();
    run("gltf_f", &pair_rows(&d, &gltf_params()));
    run("gltf_pdf", &pair_rows(&d, &gltf_params()));
    run("gltf_sample_f", &sample_rows(&sample_dirs(), &gltf_params()));
}
