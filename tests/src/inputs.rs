//! Input sets for cross-checks: dense grids plus adversarial values.

/// Scalars that break careless formulas: signed zeros, denormals, the smallest normal, values
/// next to 1, huge values, and both signs.
pub fn adversarial_scalars() -> Vec<f32> {
    let pos = [
        0.0,
        f32::from_bits(1), // smallest denormal
        1e-40,             // denormal
        f32::MIN_POSITIVE,
        1e-30,
        1e-7,
        1e-4,
        0.1,
        0.5,
        1.0 - f32::EPSILON / 2.0,
        1.0,
        1.0 + f32::EPSILON,
        2.0,
        10.0,
        1e4,
        1e19,
        1e30,
        f32::MAX,
    ];
    let mut v: Vec<f32> = pos.to_vec();
    v.extend(pos.iter().map(|x| -x));
    v
}

/// Unit directions on a (theta, phi) grid over the whole sphere, with theta refined towards
/// grazing (89, 89.9, 89.99 degrees and exactly 90) and the poles included exactly.
pub fn directions(n_theta: usize, n_phi: usize) -> Vec<[f32; 3]> {
    let mut thetas: Vec<f64> = (0..=n_theta).map(|i| 180.0 * i as f64 / n_theta as f64).collect();
    thetas.extend([89.0, 89.9, 89.99, 89.999, 90.0, 90.001, 90.1, 0.01, 179.99]);
    let mut out = Vec::new();
    for &t in &thetas {
        let t = t.to_radians();
        for j in 0..n_phi {
            let p = 2.0 * std::f64::consts::PI * j as f64 / n_phi as f64;
            out.push([(t.sin() * p.cos()) as f32, (t.sin() * p.sin()) as f32, t.cos() as f32]);
        }
    }
    out.push([0.0, 0.0, 1.0]);
    out.push([0.0, 0.0, -1.0]);
    out.push([1.0, 0.0, 0.0]);
    out.push([0.0, 1.0, 0.0]);
    out
}

/// Degenerate and unnormalized directions: zero, denormal, huge, single-axis, mixed scales.
pub fn adversarial_directions() -> Vec<[f32; 3]> {
    let s = [0.0f32, -0.0, 1e-40, 1e-30, 1e-7, 0.3, 1.0, -1.0, 7.0, 1e19, -1e19, 1e30];
    let mut out = Vec::new();
    for &x in &s {
        for &y in &s {
            for &z in &s {
                out.push([x, y, z]);
            }
        }
    }
    out
}

/// Roughness values from a perfect mirror to very rough, including invalid ones.
pub fn alphas() -> Vec<f32> {
    vec![0.0, 1e-8, 1e-4, 1e-3, 0.01, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.8, 1.0, 1.5, 4.0, -0.1, f32::NAN]
}

/// (alpha_x, alpha_y) pairs: isotropic, anisotropic up to 20:1 both ways, and adversarial.
pub fn alpha_pairs() -> Vec<(f32, f32)> {
    let mut v: Vec<(f32, f32)> = alphas().into_iter().map(|a| (a, a)).collect();
    for &(a, r) in &[(0.05f32, 20.0f32), (0.02, 10.0), (0.1, 4.0), (0.3, 2.0), (0.01, 20.0), (0.5, 2.0)] {
        v.push((a, a * r));
        v.push((a * r, a));
    }
    v.push((0.0, 0.5));
    v.push((1e-8, 1.0));
    v
}

/// Rows `[x, y, z, alpha_x, alpha_y]` for every direction and alpha pair.
pub fn direction_alpha_rows(dirs: &[[f32; 3]], alphas: &[(f32, f32)]) -> Vec<f32> {
    let mut rows = Vec::with_capacity(dirs.len() * alphas.len() * 5);
    for d in dirs {
        for &(ax, ay) in alphas {
            rows.extend_from_slice(&[d[0], d[1], d[2], ax, ay]);
        }
    }
    rows
}
